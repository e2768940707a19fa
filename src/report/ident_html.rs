//! The details of one identification in the report: correlation matrix, identified stiffness,
//! the identification figure and the per-test table of measured against simulated EIJ.

use std::fmt::Write as _;
use std::path::Path;

use super::ident_plot::test_label;
use super::labels::{fmt_eij, folder_and_name};
use super::page::{anchor, escape, Figure, Page};
use super::verdict::LoadedIdent;
use super::{identification_svg, short, ReportError};

/// The identification figure of `id`.
pub(crate) fn figure(id: &LoadedIdent) -> Result<Figure, ReportError> {
    Ok(Figure {
        id: anchor(&format!("identification-figure-{}", id.letter)),
        caption: format!(
            "Identification {}: measured EIJ (± 2 std err) and simulated with the start and the identified factors per test; cost per iteration",
            id.title()
        ),
        svg: identification_svg(&id.report)?,
    })
}

/// The details section of one identification.
pub(crate) fn details(page: &mut Page, id: &LoadedIdent, fig: &Figure) {
    let rep = &id.report;
    page.heading(
        3,
        &anchor(&format!("identification-{}", id.letter)),
        &format!("Identification {}", id.title()),
    );
    let mut h = String::new();
    if !rep.measured_inputs.is_empty() {
        let folders = super::labels::folders_of(rep.measured_inputs.iter().map(Path::new));
        let _ = writeln!(
            h,
            "<p class=\"note\">Measured inputs: {} file(s) in {}.</p>",
            rep.measured_inputs.len(),
            escape(&folders.join(", "))
        );
    }
    let _ = writeln!(
        h,
        "<h4>Correlation of the identified parameters</h4>\n<table>\n<tr><th></th>"
    );
    for p in &rep.parameters {
        let _ = write!(h, "<th>{}</th>", escape(&p.name));
    }
    let _ = writeln!(h, "</tr>");
    for (p, row) in rep.parameters.iter().zip(&rep.correlation) {
        let _ = write!(h, "<tr><th class=\"l\">{}</th>", escape(&p.name));
        for c in row {
            let _ = write!(h, "<td>{c:.3}</td>");
        }
        let _ = writeln!(h, "</tr>");
    }
    let _ = writeln!(h, "</table>");
    h.push_str(&super::stiffness_html(
        rep.stiffness.as_deref().unwrap_or_default(),
    ));
    h.push_str(&super::stiffness::elastic_bodies_html(&rep.elastic_bodies));
    page.push(&h);
    page.figure(fig);
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<h4>Per test: measured vs simulated EIJ before and after (µm·s²/m)</h4>\n<table>\n\
         <tr><th>#</th><th class=\"l\">test (plane, direction, set acceleration / (m/s²) @ circle centre / mm)</th>\
         <th class=\"l\">source</th><th>parameter</th>\
         <th>measured</th><th>± s.e.</th><th>simulated initial</th><th>simulated identified</th>\
         <th>identified − measured</th></tr>"
    );
    for (i, t) in rep.tests.iter().enumerate() {
        let source = t
            .source
            .as_deref()
            .map(|s| folder_and_name(Path::new(s)))
            .unwrap_or_default();
        for (p, m) in &t.measured {
            let fin = t.simulated_final.get(p).copied().unwrap_or(f64::NAN);
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{p}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                i + 1,
                escape(&test_label(t)),
                escape(&source),
                fmt_eij(*m),
                fmt_eij(t.measured_std_err.get(p).copied().unwrap_or(f64::NAN)),
                fmt_eij(t.simulated_initial.get(p).copied().unwrap_or(f64::NAN)),
                fmt_eij(fin),
                fmt_eij(fin - m)
            );
        }
    }
    let _ = writeln!(h, "</table>");
    let _ = writeln!(
        h,
        "<p class=\"note\">Cost: {} (Σr² {} → {}).</p>",
        escape(if rep.cost_definition.is_empty() {
            "sum of squared weighted residuals"
        } else {
            &rep.cost_definition
        }),
        short(rep.cost_initial, 6),
        short(rep.cost_final, 6)
    );
    page.push(&h);
}
