//! The clock offsets of the circle tests on the report page: per clock (a folder, or a
//! `clock = "…"` group of its entries), the offset found between the internal and the external
//! recording, its standard error, how it was found and whether the tests were evaluated with it.
//! Sign: internal clock minus external clock, ms (docs/measurement-files.md): negative when the
//! external readings are stamped after they were taken (a lagging logger).

use std::fmt::Write as _;

use super::page::escape;
use crate::measured::suite::Suite;

/// The clock table, where the evaluation estimated any offset.
pub(crate) fn section(h: &mut String, suite: &Suite) {
    if suite.clocks.is_empty() {
        return;
    }
    let _ = writeln!(
        h,
        "<h3 id=\"clocks\">Clock offsets</h3>\n<p class=\"note\">Offset = internal clock − \
         external clock, ms (negative: the external readings are stamped late). Tests recorded \
         by two systems are always evaluated at their clock's offset; the lag of single files is \
         reported, and applied only by <code>eij evaluate --fit-time-offset</code>. An offset \
         the tests cannot separate from the antisymmetric cross-talk stays the trajectory \
         alignment, and that cross-talk is not measured.</p>\n<table>\n<tr><th class=\"l\">clock</th>\
         <th>tests</th><th class=\"l\">recorded by</th><th>offset / ms</th><th>± s.e. / ms</th>\
         <th class=\"l\">found by</th><th>applied</th><th class=\"l\">remarks</th></tr>"
    );
    for c in &suite.clocks {
        let found = match (c.two_systems, c.separable) {
            (true, true) => "joint fit over the tests",
            (true, false) => "trajectory alignment (not separable from cross-talk)",
            (false, _) => "joint fit of the external lag",
        };
        let remarks: Vec<String> = c.notes.iter().map(ToString::to_string).collect();
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td>{}</td><td class=\"l\">{}</td><td>{:+.4}</td>\
             <td>{}</td><td class=\"l\">{found}</td><td>{}</td><td class=\"l\">{}</td></tr>",
            escape(&c.clock),
            c.tests.len(),
            if c.two_systems {
                "two systems"
            } else {
                "one logger"
            },
            c.offset_ms,
            c.std_err_ms.map_or("–".into(), |s| format!("{s:.4}")),
            if c.applied { "yes" } else { "no" },
            escape(&remarks.join("; "))
        );
    }
    h.push_str("</table>\n");
}
