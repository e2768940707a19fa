//! The circle diagnosis on the report page (docs/diagnosis.md): per test the verdict first,
//! then its breakdown into named terms by source — the axes' own readings, the structure
//! (external − internal), the TCP as a ballbar sees it — one column each, the terms ranked by
//! their share of the circular deviation G.
//!
//! One verdict, one colour, everywhere on the page: the CSS classes [`PASS`], [`FAIL`] and
//! [`NOT_JUDGED`] (green, red, grey) colour the badges, the judged cells and the certificate.

use std::fmt::Write as _;

use super::page::escape;
use crate::rtest::diagnosis::tolerance::Verdict;
use crate::rtest::diagnosis::{CircleDiagnosis, Figure, Source, SourceDiagnosis, Term};
use crate::text::unit_symbol;

/// CSS class of a passed test or term.
pub(crate) const PASS: &str = "v-pass";
/// CSS class of a failed test or term.
pub(crate) const FAIL: &str = "v-fail";
/// CSS class of a test without tolerances.
pub(crate) const NOT_JUDGED: &str = "v-none";

/// The CSS class of a verdict (`pass`, `fail`, none).
pub(crate) fn verdict_class(verdict: Option<&str>) -> &'static str {
    match verdict {
        Some("pass") => PASS,
        Some(_) => FAIL,
        None => NOT_JUDGED,
    }
}

/// A verdict as a coloured badge: `PASS`, `FAIL` or `not judged`.
pub(crate) fn badge(verdict: Option<&str>) -> String {
    let text = match verdict {
        Some(v) => v.to_uppercase(),
        None => "not judged".into(),
    };
    format!(
        "<span class=\"badge {}\">{text}</span>",
        verdict_class(verdict)
    )
}

/// The failed checks of a verdict, each as `tcp G 13.15 > 12 µm` (G: the circular deviation).
pub(crate) fn failed_checks(v: &Verdict) -> Vec<String> {
    v.checks
        .iter()
        .filter(|c| c.verdict != "pass")
        .map(|c| {
            let name = if c.name == "circular_deviation" {
                "G"
            } else {
                &c.name
            };
            format!(
                "{} {name} {:.2} > {} {}",
                c.source.name(),
                c.value,
                super::short(c.limit, 4),
                unit_symbol(c.unit)
            )
        })
        .collect()
}

/// Column heads of the three sources.
fn source_head(s: Source) -> &'static str {
    match s {
        Source::Internal => "axes<br><small>internal</small>",
        Source::Structure => "structure<br><small>external − internal</small>",
        Source::Tcp => "TCP<br><small>as a ballbar sees it</small>",
    }
}

/// The rows of the breakdown: every term that stands out in some source (or has a limit),
/// in-plane terms first, each group by its largest share over the sources, descending.
fn rows(d: &CircleDiagnosis) -> Vec<(String, Figure, f64)> {
    let mut rows: Vec<(String, Figure, f64)> = Vec::new();
    for s in &d.sources {
        for t in s.terms.iter().filter(|t| t.stands_out()) {
            match rows.iter_mut().find(|(n, _, _)| *n == t.name) {
                Some(row) => row.2 = row.2.max(t.contribution_um),
                None => rows.push((t.name.clone(), t.figure, t.contribution_um)),
            }
        }
    }
    let order = |f: Figure| match f {
        Figure::CircularDeviation => 0,
        Figure::OutOfPlane => 1,
    };
    rows.sort_by(|a, b| order(a.1).cmp(&order(b.1)).then(b.2.total_cmp(&a.2)));
    rows
}

/// `value ± std_err` with the standard error to two significant digits (1 to 6 decimals).
pub(crate) fn value_se(value: f64, std_err: f64) -> String {
    let d = if std_err.is_finite() && std_err > 0.0 {
        (1.0 - std_err.log10().floor()).clamp(1.0, 6.0) as usize
    } else {
        3
    };
    format!("{value:.d$} ± {std_err:.d$}")
}

/// One cell: value ± standard error, its share of G (or of the out-of-plane range) and the
/// values at the reversal points, coloured by its verdict; grey where within its noise.
fn cell(t: Option<&Term>) -> String {
    let Some(t) = t else {
        return "<td class=\"ns\">–</td>".into();
    };
    let mut class = String::from(match t.verdict {
        Some(v) => verdict_class(Some(v)),
        None => "",
    });
    if !t.stands_out() {
        class.push_str(" ns");
    }
    let share = match t.figure {
        Figure::CircularDeviation => "G",
        Figure::OutOfPlane => "p–v",
    };
    let mut h = format!(
        "<td class=\"{}\">{}<br><small>{share} {:.2}",
        class.trim(),
        value_se(t.value, t.std_err),
        t.contribution_um
    );
    if let Some(l) = t.limit {
        let _ = write!(h, " · limit {}", super::short(l, 4));
    }
    if let Some(p) = t.phase_deg {
        let _ = write!(h, " · at {p:.0}°");
    }
    for c in &t.crossings {
        let _ = write!(
            h,
            "<br>{} {:.2} ± {:.2}",
            escape(&c.side),
            c.value,
            c.std_err
        );
    }
    h.push_str("</small></td>");
    h
}

/// The breakdown of test `d` with its verdict first; `label` names the test (`cw: pos-a/…`).
pub(crate) fn breakdown_html(
    d: &CircleDiagnosis,
    verdict: Option<&Verdict>,
    label: &str,
) -> String {
    let v = verdict.map(|v| v.verdict);
    let mut h = format!(
        "<div class=\"diag\">\n<p class=\"diag-head\">{} <b>{}</b> — {:.0} mm/min; breakdown by \
         source, ranked by share of G</p>\n",
        badge(v),
        escape(label),
        super::labels::shown_feed(d.feed_mm_min)
    );
    if let Some(v) = verdict {
        let failed = failed_checks(v);
        if !failed.is_empty() {
            let _ = writeln!(
                h,
                "<p class=\"{FAIL}\">out of tolerance: {}</p>",
                escape(&failed.join("; "))
            );
        }
        for u in &v.unchecked {
            let _ = writeln!(
                h,
                "<p class=\"warn\">tolerance {}: not measured in this test</p>",
                escape(u)
            );
        }
    }
    h.push_str("<table class=\"diag\">\n<tr><th class=\"l\">term</th><th class=\"l\">unit</th>");
    for s in Source::ALL {
        let _ = write!(h, "<th>{}</th>", source_head(s));
    }
    h.push_str("</tr>\n<tr><th class=\"l\">circular deviation G</th><td class=\"l\">µm</td>");
    for s in &d.sources {
        let judged = verdict.and_then(|v| {
            v.checks
                .iter()
                .find(|c| c.source == s.source && c.name == "circular_deviation")
        });
        let (class, limit) = judged.map_or((String::new(), String::new()), |c| {
            (
                verdict_class(Some(c.verdict)).to_string(),
                format!("<br><small>limit {}</small>", super::short(c.limit, 4)),
            )
        });
        let _ = write!(
            h,
            "<td class=\"{class}\"><b>{:.3}</b>{limit}</td>",
            s.circular_deviation_um
        );
    }
    h.push_str("</tr>\n");
    for (name, _, _) in rows(d) {
        let unit_of = d
            .sources
            .iter()
            .find_map(|s| s.term(&name))
            .map_or("", |t| t.unit);
        let _ = write!(
            h,
            "<tr><th class=\"l\">{}</th><td class=\"l\">{}</td>",
            escape(&name),
            unit_symbol(unit_of)
        );
        for s in &d.sources {
            h.push_str(&cell(s.term(&name)));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("<tr><th class=\"l\">residual (RMS radial)</th><td class=\"l\">µm</td>");
    for s in &d.sources {
        let _ = write!(h, "<td>{:.3}</td>", s.residual_um);
    }
    h.push_str("</tr>\n</table>\n");
    h.push_str(&notes_html(&d.sources));
    h.push_str("</div>\n");
    h
}

/// The notes of the terms shown (what a value may also be, what other tests told), once each.
fn notes_html(sources: &[SourceDiagnosis]) -> String {
    let mut notes: Vec<String> = Vec::new();
    for s in sources {
        let own = s.notes.iter().map(|n| format!("{}: {n}", s.source.name()));
        let terms = s.terms.iter().filter(|t| t.stands_out()).flat_map(|t| {
            t.notes
                .iter()
                .map(move |n| format!("{} {}: {n}", s.source.name(), t.name))
        });
        for n in own.chain(terms) {
            if !notes.contains(&n) {
                notes.push(n);
            }
        }
    }
    if notes.is_empty() {
        return String::new();
    }
    let mut h = String::from("<ul class=\"notes\">\n");
    for n in notes {
        let _ = writeln!(h, "<li>{}</li>", escape(&n));
    }
    h.push_str("</ul>\n");
    h
}

/// The note above the circle plots: how to read the breakdowns.
pub(crate) const READING_NOTE: &str = "Beside each plot, per test: its verdict against the \
    folder's [tolerances] (green PASS, red FAIL, grey not judged), then its deviation broken \
    down into named terms per source — the axes' own readings (what the drives and the control \
    did), external − internal (what the structure did), and the TCP (what a ballbar sees; to \
    first order the sum of the other two). Each cell: value ± standard error, below it the \
    term's share of G (the ISO 230-4 G of that term alone, µm; p–v: its out-of-plane \
    peak-to-valley) and, for backlash and reversal spikes, the value at each reversal point. \
    Rows are the terms beyond 3 standard errors in some source (or with a limit), ranked by \
    their largest share; grey cells are within their noise. Formulas: docs/diagnosis.md.";
