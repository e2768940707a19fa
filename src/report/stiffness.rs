//! The identified stiffness set in the HTML report: one small table
//! ([`crate::machine::stiffness`], docs/stiffness-table.md).

use super::page::escape;
use crate::machine::stiffness::StiffnessRow;
use std::fmt::Write;

/// The stiffness rows as an HTML section: per axis, element and direction the file value, the
/// factor, the value and its standard error (N/µm per element), then where each screw value
/// holds. Empty for no rows (a report from a version without the table).
pub fn stiffness_html(rows: &[StiffnessRow]) -> String {
    let mut h = String::new();
    if rows.is_empty() {
        return h;
    }
    let _ = writeln!(
        h,
        "<h3>Identified stiffness (N/µm per element; value = file × factor)</h3>\n<table>\n\
         <tr><th class=\"l\">axis</th><th class=\"l\">element</th><th class=\"l\">direction</th>\
         <th>count</th><th>file</th><th>factor</th><th>value</th><th>± std err</th>\
         <th class=\"l\">parameter</th></tr>"
    );
    for r in rows {
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td>\
             <td>{:.1}</td><td>{:.4}</td><td>{:.1}</td><td>{}</td><td class=\"l\">{}</td></tr>",
            r.axis,
            r.element,
            r.direction,
            r.count,
            r.file_n_per_um,
            r.factor,
            r.value_n_per_um,
            r.std_err_n_per_um.map_or("–".into(), |s| format!("{s:.1}")),
            r.parameter.as_deref().map_or("–".into(), escape)
        );
    }
    let _ = writeln!(h, "</table>");
    let screws: Vec<String> = rows
        .iter()
        .filter_map(|r| r.screw.map(|p| (r.axis, p)))
        .map(|(axis, p)| p.describe(axis))
        .collect();
    if !screws.is_empty() {
        let _ = writeln!(
            h,
            "<p class=\"note\">Screw shafts E·A/l₁ at the reference position (the value follows the nut): {}.</p>",
            screws.join("; ")
        );
    }
    h
}

/// The elastic bodies of an identification as an HTML section: per body the elastic
/// coordinates kept, the first elastic frequencies with the identified factor, the factor with
/// its standard error and 3σ interval. Empty for none (a rigid machine, or an older report).
pub fn elastic_bodies_html(bodies: &[crate::ident::stiffness::ElasticBodyReport]) -> String {
    /// Frequencies listed per body (the rest are counted).
    const LISTED: usize = 6;
    let mut h = String::new();
    if bodies.is_empty() {
        return h;
    }
    let _ = writeln!(
        h,
        "<h3>Elastic bodies</h3>\n<table>\n<tr><th class=\"l\">body</th><th>modes kept</th>\
         <th class=\"l\">elastic free-free frequencies (Hz, with the factor)</th><th>stiffness factor</th>\
         <th>± std err</th><th>3σ interval (in 1/p)</th><th class=\"l\">parameter</th></tr>"
    );
    for b in bodies {
        let mut f: Vec<String> = b
            .frequencies_hz
            .iter()
            .take(LISTED)
            .map(|x| format!("{x:.0}"))
            .collect();
        if b.frequencies_hz.len() > LISTED {
            f.push(format!("… ({} in all)", b.frequencies_hz.len()));
        }
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td>{}</td><td class=\"l\">{}</td><td>{:.4}</td><td>{}</td>\
             <td>{}</td><td class=\"l\">{}</td></tr>",
            escape(&b.body),
            b.modes,
            escape(&f.join(", ")),
            b.factor,
            b.std_err.map_or("–".into(), |s| format!("{s:.4}")),
            b.interval_3sigma
                .map_or("–".into(), crate::ident::verdict::format_interval),
            b.parameter.as_deref().map_or("not identified".into(), escape)
        );
    }
    let _ = writeln!(
        h,
        "</table>\n<p class=\"note\">The factor scales the body's whole FE stiffness (E and G alike); \
         every frequency scales with its square root. A factor far from 1 says the FE model or the \
         joints that hold the body are wrong.</p>"
    );
    h
}
