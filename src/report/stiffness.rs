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
