//! What `eij evaluate --diagnose` prints: per test and source the terms ranked by their
//! contribution to G, the tolerances checked, and what the tests of a plane told together.

use std::fmt::Write as _;

use eij::measured::suite::diagnose::SuiteDiagnosis;
use eij::rtest::diagnosis::{Figure, Source, SourceDiagnosis, STANDS_OUT_SE, STANDS_OUT_UM};

/// Raised when a judged test fails its tolerances: `main` exits with [`EXIT_CODE`] after the
/// output is written.
#[derive(Debug, thiserror::Error)]
#[error("verdict: fail: {} of {judged} judged test(s) out of tolerance: {}", failed.len(), failed.join(", "))]
pub struct OutOfTolerance {
    /// The names of the failed tests.
    pub failed: Vec<String>,
    /// How many tests were judged.
    pub judged: usize,
}

/// Exit code of a run whose tests fail their tolerances (1 is an error, 2 a usage error).
pub const EXIT_CODE: u8 = 3;

impl OutOfTolerance {
    /// The failure of `d`, if any test failed.
    pub fn of(d: &SuiteDiagnosis) -> Option<OutOfTolerance> {
        let failed: Vec<String> = d
            .failed()
            .into_iter()
            .map(|i| d.tests[i].name.clone())
            .collect();
        (!failed.is_empty()).then(|| OutOfTolerance {
            failed,
            judged: d.verdicts.iter().flatten().count(),
        })
    }
}

fn what(source: Source) -> &'static str {
    match source {
        Source::Internal => "the axes' own readings",
        Source::Structure => "external − internal, the structure",
        Source::Tcp => "the TCP, as a ballbar sees it",
    }
}

/// The diagnosis of test `i`.
pub fn render_test(out: &mut String, d: &SuiteDiagnosis, i: usize) {
    let test = &d.tests[i];
    let verdict = d.verdicts[i].as_ref().map_or(String::new(), |v| {
        format!("   verdict: {}", v.verdict.to_uppercase())
    });
    let _ = writeln!(
        out,
        "  diagnosis at {:.0} mm/min (terms ranked by their share of G, µm unless stated){verdict}",
        test.feed_mm_min
    );
    let _ = writeln!(
        out,
        "    {:<10} {:>9} {:>9} {:>9}",
        "source", "G", "terms G", "residual"
    );
    for s in &test.sources {
        let _ = writeln!(
            out,
            "    {:<10} {:>9.3} {:>9.3} {:>9.3}",
            s.source.name(),
            s.circular_deviation_um,
            s.circular_deviation_terms_um,
            s.residual_um
        );
    }
    for s in &test.sources {
        render_source(out, s);
    }
    if let Some(v) = &d.verdicts[i] {
        for c in &v.checks {
            let se = c.std_err.map_or(String::new(), |s| format!(" ± {s:.3}"));
            let _ = writeln!(
                out,
                "    tolerance {} {}: {:.3}{se} {} {} {} {}",
                c.source.name(),
                c.name,
                c.value,
                if c.value <= c.limit { "≤" } else { ">" },
                c.limit,
                c.unit,
                c.verdict.to_uppercase()
            );
        }
        for u in &v.unchecked {
            let _ = writeln!(out, "    tolerance {u}: not measured in this test");
        }
    }
}

fn render_source(out: &mut String, s: &SourceDiagnosis) {
    let _ = writeln!(out, "    {} — {}", s.source.name(), what(s.source));
    let mut hidden = 0;
    for (rank, t) in s.terms.iter().enumerate() {
        if !t.stands_out() {
            hidden += 1;
            continue;
        }
        let share = match t.figure {
            Figure::CircularDeviation => format!("G {:.3}", t.contribution_um),
            Figure::OutOfPlane => format!("out of plane {:.3}", t.contribution_um),
        };
        let phase = t
            .phase_deg
            .map_or(String::new(), |p| format!(" at {p:.0}°"));
        let limit = match (t.limit, t.verdict) {
            (Some(l), Some(v)) => format!("  limit {l} {}", v.to_uppercase()),
            _ => String::new(),
        };
        let _ = writeln!(
            out,
            "      {:>2} {:<22} {:>10.4} ± {:<8.4} {:<8} {share}{phase}{limit}",
            rank + 1,
            t.name,
            t.value,
            t.std_err,
            t.unit
        );
        for c in &t.crossings {
            let _ = writeln!(
                out,
                "         {:<22} {:>10.4} ± {:<8.4} at {:.0}°",
                c.side, c.value, c.std_err, c.at_deg
            );
        }
        for n in &t.notes {
            let _ = writeln!(out, "         note: {n}");
        }
    }
    if hidden > 0 {
        let _ = writeln!(
            out,
            "         ({hidden} more within {STANDS_OUT_SE} standard errors of 0 or below \
             {STANDS_OUT_UM} µm)"
        );
    }
    for n in &s.notes {
        let _ = writeln!(out, "      note: {n}");
    }
}

/// What the tests of each plane and circle centre told together.
pub fn render_groups(out: &mut String, d: &SuiteDiagnosis) {
    for g in &d.groups {
        let at = g
            .position_mm
            .map_or(String::new(), |p| format!(" at {p:?} mm"));
        let _ = writeln!(
            out,
            "diagnosis of {} tests in plane {}{at} (accelerations {} m/s²)",
            g.tests.len(),
            g.plane,
            super::evaluate::accelerations(&g.accelerations_m_s2)
        );
        for n in &g.notes {
            let _ = writeln!(out, "  note: {n}");
        }
        for (source, terms) in &g.sources {
            for t in terms {
                let servo = t.servo_mismatch_ms.map(|v| {
                    format!(
                        ", servo mismatch {v:.4} ± {:.4} ms",
                        t.servo_mismatch_std_err_ms.unwrap_or(f64::NAN)
                    )
                });
                let slope = t.per_m_s2.map(|k| {
                    format!(
                        ", {k:.4} ± {:.4} {} per m/s² (grows with acceleration)",
                        t.per_m_s2_std_err.unwrap_or(f64::NAN),
                        t.unit
                    )
                });
                if servo.is_none() && slope.is_none() {
                    continue;
                }
                let _ = writeln!(
                    out,
                    "  {source:<9} {:<20} at no acceleration {:.4} ± {:.4} {}{}{}",
                    t.name,
                    t.geometric,
                    t.geometric_std_err,
                    t.unit,
                    servo.unwrap_or_default(),
                    slope.unwrap_or_default()
                );
            }
        }
    }
}
