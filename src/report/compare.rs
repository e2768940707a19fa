//! Several identifications side by side (before and after a repair, two machines, two dates):
//! the fit, the parameters with the change against the first report and its significance, the
//! warnings, and the measured EIJ of the tests the reports share.
//!
//! A change Δ = p_B − p_A of a parameter is given with z = Δ/√(σ_A² + σ_B²): |z| > 3 is a change
//! beyond the two standard errors (the reports are independent measurements).

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::ident_plot::test_label;
use super::labels::fmt_eij;
use super::page::{escape, Page};
use super::verdict::{fit_quality, headline, status_html, LoadedIdent};
use crate::axes::Eij;
use crate::ident::report::TestReport;

/// A change counts as beyond the standard errors above this |z|.
const SIGNIFICANT_Z: f64 = 3.0;

/// `Δ (z)` of `b` against `a`, each a value with an optional standard error.
fn change(a: f64, sa: Option<f64>, b: f64, sb: Option<f64>) -> String {
    let d = b - a;
    match (sa, sb) {
        (Some(sa), Some(sb)) if sa.hypot(sb) > 0.0 => {
            let z = d / sa.hypot(sb);
            let class = if z.abs() > SIGNIFICANT_Z {
                " class=\"bad\""
            } else {
                ""
            };
            format!("<span{class}>{d:+.4} (z = {z:+.1})</span>")
        }
        _ => format!("{d:+.4}"),
    }
}

/// The comparison section (for two or more reports).
pub(crate) fn comparison(page: &mut Page, ids: &[LoadedIdent]) {
    page.heading(2, "comparison", "Comparison of the identifications");
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<p class=\"note\">Columns: the identify reports in the order given; changes are against {} \
         with z = Δ/√(σ₁² + σ₂²) (independent measurements); |z| &gt; {SIGNIFICANT_Z} in red: a change \
         beyond the standard errors.</p>",
        escape(&ids[0].letter)
    );
    fit_table(&mut h, ids);
    parameter_table(&mut h, ids);
    let _ = writeln!(h, "<h4>Warnings</h4>\n<table>");
    for id in ids {
        let w = &id.report.warnings;
        let text = if w.is_empty() {
            "none".to_string()
        } else {
            w.iter().map(|w| escape(w)).collect::<Vec<_>>().join("<br>")
        };
        let _ = writeln!(
            h,
            "<tr><th class=\"l\">{}</th><td class=\"w\">{text}</td></tr>",
            escape(&id.letter)
        );
    }
    let _ = writeln!(h, "</table>");
    eij_table(&mut h, ids);
    page.push(&h);
}

fn header_row(h: &mut String, first: &str, ids: &[LoadedIdent], per: &[&str]) {
    let _ = write!(h, "<tr><th class=\"l\">{first}</th>");
    for (k, id) in ids.iter().enumerate() {
        for p in per {
            let _ = write!(h, "<th>{} {p}</th>", escape(&id.letter));
        }
        if k > 0 {
            let _ = write!(
                h,
                "<th>{} − {}</th>",
                escape(&id.letter),
                escape(&ids[0].letter)
            );
        }
    }
    let _ = writeln!(h, "</tr>");
}

fn fit_table(h: &mut String, ids: &[LoadedIdent]) {
    let _ = writeln!(h, "<h4>Fit</h4>\n<table>");
    let _ = write!(h, "<tr><th class=\"l\"></th>");
    for id in ids {
        let _ = write!(h, "<th class=\"l\">{}</th>", escape(&id.letter));
    }
    let _ = writeln!(h, "</tr>");
    type Cell = Box<dyn Fn(&LoadedIdent) -> String>;
    let rows: Vec<(&str, Cell)> = vec![
        (
            "report",
            Box::new(|i| escape(&i.path.display().to_string())),
        ),
        (
            "machine",
            Box::new(|i| escape(i.report.machine.as_deref().unwrap_or("–"))),
        ),
        ("date", Box::new(|i| escape(&i.report.date))),
        ("eij version", Box::new(|i| escape(&i.report.eij_version))),
        (
            "verdict",
            Box::new(|i| {
                let v = headline(i);
                format!("<span class=\"{}\">{}</span>", v.class, escape(&v.text))
            }),
        ),
        ("status", Box::new(status_html)),
        (
            "tests (values)",
            Box::new(|i| {
                format!(
                    "{} ({})",
                    i.report.tests.len(),
                    i.report.residuals.map_or("–".into(), |m| m.to_string())
                )
            }),
        ),
        (
            "residual std s",
            Box::new(|i| {
                i.report
                    .residual_std
                    .map_or("–".into(), |s| format!("{s:.3}"))
            }),
        ),
        (
            "χ² test",
            Box::new(|i| {
                let r = &i.report;
                escape(&r.chi2().map_or_else(|| fit_quality(r), |c| c.describe()))
            }),
        ),
        (
            "cost Σr² final",
            Box::new(|i| format!("{:.4e}", i.report.cost_final)),
        ),
        (
            "warnings",
            Box::new(|i| i.report.warnings.len().to_string()),
        ),
    ];
    for (name, cell) in rows {
        let _ = write!(h, "<tr><th class=\"l\">{name}</th>");
        for id in ids {
            let _ = write!(h, "<td class=\"w\">{}</td>", cell(id));
        }
        let _ = writeln!(h, "</tr>");
    }
    let _ = writeln!(h, "</table>");
}

fn parameter_table(h: &mut String, ids: &[LoadedIdent]) {
    let mut names: Vec<String> = Vec::new();
    for id in ids {
        for p in &id.report.parameters {
            if !names.contains(&p.name) {
                names.push(p.name.clone());
            }
        }
    }
    let _ = writeln!(
        h,
        "<h4>Parameters (identified ± std err, standing)</h4>\n<table>"
    );
    header_row(h, "parameter", ids, &["identified ± std err", "standing"]);
    let a = ids[0].report.parameters.iter();
    let first: BTreeMap<&str, _> = a.map(|p| (p.name.as_str(), p)).collect();
    for name in &names {
        let _ = write!(h, "<tr><td class=\"l\">{}</td>", escape(name));
        for (k, id) in ids.iter().enumerate() {
            let p = id.report.parameters.iter().find(|p| &p.name == name);
            match p {
                Some(p) => {
                    let s = id.report.standing(p);
                    let _ = write!(
                        h,
                        "<td>{:.4} ± {}</td><td class=\"l\">{}</td>",
                        p.identified,
                        p.std_err.map_or("–".into(), |s| format!("{s:.4}")),
                        s.label()
                    );
                }
                None => {
                    let _ = write!(h, "<td>–</td><td>–</td>");
                }
            }
            if k > 0 {
                let cell = match (first.get(name.as_str()), p) {
                    (Some(a), Some(b)) => change(a.identified, a.std_err, b.identified, b.std_err),
                    _ => "–".into(),
                };
                let _ = write!(h, "<td>{cell}</td>");
            }
        }
        let _ = writeln!(h, "</tr>");
    }
    let _ = writeln!(h, "</table>");
}

/// Tests matched across reports by their label (plane, direction, acceleration, circle
/// centre).
fn by_label(tests: &[TestReport]) -> BTreeMap<String, &TestReport> {
    tests.iter().map(|t| (test_label(t), t)).collect()
}

/// The measured EIJ of the tests the reports share: the mean per EIJ in the open, every
/// test's values in a folded table.
fn eij_table(h: &mut String, ids: &[LoadedIdent]) {
    let maps: Vec<BTreeMap<String, &TestReport>> =
        ids.iter().map(|i| by_label(&i.report.tests)).collect();
    let shared: Vec<&String> = maps[0]
        .keys()
        .filter(|k| maps.iter().all(|m| m.contains_key(*k)))
        .collect();
    if shared.is_empty() {
        let _ = writeln!(
            h,
            "<p class=\"note\">The reports share no test (same plane, direction, acceleration and circle centre): no EIJ to compare.</p>"
        );
        return;
    }
    // Per EIJ over the shared tests: mean measured and its standard error per report.
    let mut params: Vec<Eij> = shared
        .iter()
        .flat_map(|k| maps[0][*k].measured.keys().copied())
        .collect();
    params.sort();
    params.dedup();
    let mean = |m: &BTreeMap<String, &TestReport>, e: Eij| -> Option<(f64, f64, usize)> {
        let vals: Vec<(f64, f64)> = shared
            .iter()
            .filter_map(|k| {
                let t = m[*k];
                Some((
                    *t.measured.get(&e)?,
                    t.measured_std_err.get(&e).copied().unwrap_or(0.0),
                ))
            })
            .collect();
        let n = vals.len();
        (n > 0).then(|| {
            let v = vals.iter().map(|v| v.0).sum::<f64>() / n as f64;
            let se = vals.iter().map(|v| v.1 * v.1).sum::<f64>().sqrt() / n as f64;
            (v, se, n)
        })
    };
    let _ = writeln!(
        h,
        "<h4>Measured EIJ, mean over the {} tests the reports share (µm·s²/m ± standard error of the mean)</h4>\n<table>",
        shared.len()
    );
    header_row(h, "EIJ", ids, &["mean ± s.e."]);
    for e in &params {
        let _ = write!(h, "<tr><td class=\"l\">{e}</td>");
        let a = mean(&maps[0], *e);
        for (k, m) in maps.iter().enumerate() {
            let b = mean(m, *e);
            let _ = write!(
                h,
                "<td>{}</td>",
                b.map_or("–".into(), |(v, se, n)| format!(
                    "{} ± {} ({n})",
                    fmt_eij(v),
                    fmt_eij(se)
                ))
            );
            if k > 0 {
                let cell = match (a, b) {
                    (Some(a), Some(b)) => change(a.0, Some(a.1), b.0, Some(b.1)),
                    _ => "–".into(),
                };
                let _ = write!(h, "<td>{cell}</td>");
            }
        }
        let _ = writeln!(h, "</tr>");
    }
    let _ = writeln!(h, "</table>");
    let _ = writeln!(
        h,
        "<details><summary>Every shared test (measured EIJ ± standard error, µm·s²/m)</summary>\n<table>"
    );
    header_row(h, "test, EIJ", ids, &["measured ± s.e."]);
    for key in &shared {
        for e in maps[0][*key].measured.keys() {
            let _ = write!(h, "<tr><td class=\"l\">{} {e}</td>", escape(key));
            let val = |m: &BTreeMap<String, &TestReport>| {
                let t = m[*key];
                t.measured
                    .get(e)
                    .map(|v| (*v, t.measured_std_err.get(e).copied()))
            };
            let a = val(&maps[0]);
            for (k, m) in maps.iter().enumerate() {
                let b = val(m);
                let _ = write!(
                    h,
                    "<td>{}</td>",
                    b.map_or("–".into(), |(v, s)| format!(
                        "{} ± {}",
                        fmt_eij(v),
                        s.map_or("–".into(), fmt_eij)
                    ))
                );
                if k > 0 {
                    let cell = match (a, b) {
                        (Some(a), Some(b)) => change(a.0, a.1, b.0, b.1),
                        _ => "–".into(),
                    };
                    let _ = write!(h, "<td>{cell}</td>");
                }
            }
            let _ = writeln!(h, "</tr>");
        }
    }
    let _ = writeln!(h, "</table></details>");
}
