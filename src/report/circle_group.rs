//! The circle tests of a report grouped as metrologists compare them: the cw and the ccw test
//! of one plane, circle centre, radius and acceleration together (the pairs of
//! [`crate::measured::suite::Suite::bidirectional`], whose G(b) they carry), a test without a
//! partner alone. Per group a polar plot of both paths ([`super::polar`]), beside it the ISO
//! 230-4 figures of every path exactly as `eij evaluate` computes them, and the out-of-plane
//! deviation over the phase.

use std::fmt::Write as _;

use super::diagnosis_html::{breakdown_html, READING_NOTE};
use super::labels::{feed_mm_min, folder_and_name, position_label};
use super::page::{escape, Figure, Page};
use super::polar::{self, PolarFigure, PolarPath, PolarScale};
use super::{short, ReportError};
use crate::measured::suite::diagnose::SuiteDiagnosis;
use crate::measured::suite::{Bidirectional, EvaluatedTest, Suite};
use crate::rtest::iso230::PathFigures;

/// One group: its tests (cw before ccw) and their G(b) where they pair.
pub(crate) struct CircleGroup<'a> {
    /// The tests.
    pub tests: Vec<&'a EvaluatedTest>,
    /// Their indices in the suite.
    pub indices: Vec<usize>,
    /// G(b) of the pair.
    pub bidirectional: Option<&'a Bidirectional>,
    /// The paths in polar form: external, internal.
    paths: [Vec<PolarPath>; 2],
}

/// `xy · 5 m/s² · circle centre [150, -100, 0] mm`.
fn group_title(t: &EvaluatedTest) -> String {
    let r = &t.result;
    let centre =
        t.input
            .test
            .position_mm
            .as_deref()
            .map_or("circle centre not stated".into(), |p| {
                format!(
                    "circle centre [{}] mm",
                    position_label(p).replace(',', ", ")
                )
            });
    format!(
        "Circle plot {} · {} m/s² · {centre}",
        r.plane,
        short(r.accel_m_s2, 1)
    )
}

/// The group of the tests `idx` of `suite`.
fn group<'a>(
    suite: &'a Suite,
    idx: Vec<usize>,
    pair: Option<&'a Bidirectional>,
) -> Result<CircleGroup<'a>, ReportError> {
    let tests: Vec<&EvaluatedTest> = idx.iter().map(|&i| &suite.tests[i]).collect();
    let polar = |ext| {
        polar::polar_paths(&tests, ext).ok_or_else(|| ReportError::BadInput {
            source_name: tests[0].input.name(),
            message: "no circle can be fitted to its path".into(),
        })
    };
    let paths = [polar(true)?, polar(false)?];
    Ok(CircleGroup {
        tests,
        indices: idx,
        bidirectional: pair,
        paths,
    })
}

/// The groups of a suite, ordered by plane, circle centre and acceleration.
pub(crate) fn groups(suite: &Suite) -> Result<Vec<CircleGroup<'_>>, ReportError> {
    let mut used = vec![false; suite.tests.len()];
    let mut out = Vec::new();
    for b in &suite.bidirectional {
        used[b.tests[0]] = true;
        used[b.tests[1]] = true;
        out.push(group(suite, b.tests.to_vec(), Some(b))?);
    }
    for (i, _) in used.iter().enumerate().filter(|(_, u)| !**u) {
        out.push(group(suite, vec![i], None)?);
    }
    // Circle centres in the order the inputs first name them.
    let centre_rank = |g: &CircleGroup| {
        let p = &g.tests[0].input.test.position_mm;
        suite
            .tests
            .iter()
            .position(|t| t.input.test.position_mm == *p)
            .unwrap_or(0)
    };
    out.sort_by_key(|g| {
        let r = &g.tests[0].result;
        (r.plane, centre_rank(g), (r.accel_m_s2 * 1e3).round() as i64)
    });
    Ok(out)
}

/// The scale every polar plot of the page shares.
pub(crate) fn page_scale(groups: &[CircleGroup]) -> PolarScale {
    let max = groups
        .iter()
        .flat_map(|g| g.paths.iter())
        .map(|p| polar::max_deviation_um(p))
        .fold(0.0, f64::max);
    PolarScale::enclosing(max)
}

/// `cw: pos-a/xy_cw_5.csv`.
fn test_label(t: &EvaluatedTest) -> String {
    format!(
        "{}: {}",
        t.result.direction,
        folder_and_name(t.input.primary_file())
    )
}

/// The polar figure and the out-of-plane figure of a group, the `number`th of the page.
pub(crate) fn figures(
    g: &CircleGroup,
    number: usize,
    scale: &PolarScale,
) -> Result<[Figure; 2], ReportError> {
    let t0 = g.tests[0];
    let r = &t0.result;
    let title = group_title(t0);
    let dirs: Vec<String> = g
        .tests
        .iter()
        .map(|t| t.result.direction.to_string())
        .collect();
    let revs: Vec<String> = g
        .tests
        .iter()
        .map(|t| t.result.revolutions.to_string())
        .collect();
    let conditions = format!(
        "set radius r = {} mm · feed {} mm/min ({} Hz) · {} · {} steady revolutions",
        short(r.radius_mm, 4),
        short(feed_mm_min(r), 0),
        short(r.freq_hz, 3),
        dirs.join(" and "),
        revs.join(" / ")
    );
    let lines = vec![
        conditions.clone(),
        "radial deviation ρ − r about the least-squares centre of cw and ccw together · one \
         scale in every circle plot"
            .to_string(),
        scale.rings_key(),
    ];
    let (a, b) = r.plane.axes();
    let fig = PolarFigure {
        title: title.clone(),
        lines,
        axes: (a.to_string(), b.to_string()),
        external: g.paths[0].clone(),
        internal: g.paths[1].clone(),
        labels: g.tests.iter().map(|t| test_label(t)).collect(),
    };
    // By number: titles of two centres differ only in signs, which anchors drop.
    let id = format!("circle-plot-{number}");
    let polar_fig = Figure {
        id: id.clone(),
        caption: format!("{title}: {conditions}; radial deviations on a polar µm scale"),
        svg: polar::polar_svg(&fig, scale)?,
    };
    let k = r.plane.normal();
    let oop_title = format!("Out-of-plane deviation d{k} = {k}_ext − {k}_int");
    let labelled: Vec<(&EvaluatedTest, String)> =
        g.tests.iter().map(|t| (*t, test_label(t))).collect();
    let oop = Figure {
        id: format!("{id}-out-of-plane"),
        caption: format!(
            "Out-of-plane deviation {}: over the phase with the fitted plane",
            title.trim_start_matches("Circle plot ")
        ),
        svg: polar::out_of_plane_svg(
            &oop_title,
            &[title.trim_start_matches("Circle plot ").to_string()],
            &labelled,
        )?,
    };
    Ok([polar_fig, oop])
}

/// A µm value of the ISO table (2 decimals; `–` where there is none).
pub(crate) fn fmt_um(v: Option<f64>) -> String {
    v.filter(|v| v.is_finite())
        .map_or("–".into(), |v| format!("{v:.2}"))
}

/// The ISO 230-4 table of a group: per path (TCP and scales) and test G, F max, F min and
/// the mean radius deviation, G(b) of the pair, and the test's conditions.
pub(crate) fn iso_table(g: &CircleGroup) -> String {
    let mut h =
        String::from("<table class=\"iso\">\n<tr><th class=\"l\">ISO 230-4, µm</th><th colspan=\"");
    let n = g.tests.len();
    let _ = write!(
        h,
        "{n}\">TCP (R-Test)</th><th colspan=\"{n}\">scales</th></tr>\n<tr><th></th>"
    );
    for _ in 0..2 {
        for t in &g.tests {
            let _ = write!(h, "<th>{}</th>", t.result.direction);
        }
    }
    let _ = writeln!(h, "</tr>");
    let figure = |t: &EvaluatedTest, ext: bool| -> Option<PathFigures> {
        t.result
            .iso230
            .map(|f| if ext { f.external } else { f.internal })
    };
    type Value = fn(&PathFigures) -> f64;
    let rows: [(&str, Value); 4] = [
        ("circular deviation G", |f| f.circular_deviation_um),
        ("radial deviation F max", |f| f.radial_deviation_max_um),
        ("radial deviation F min", |f| f.radial_deviation_min_um),
        ("mean radius − r", |f| f.mean_radius_deviation_um),
    ];
    for (name, value) in rows {
        let _ = write!(h, "<tr><th class=\"l\">{name}</th>");
        for ext in [true, false] {
            for t in &g.tests {
                let _ = write!(h, "<td>{}</td>", fmt_um(figure(t, ext).map(|f| value(&f))));
            }
        }
        let _ = writeln!(h, "</tr>");
    }
    if let Some(b) = g.bidirectional {
        let _ = writeln!(
            h,
            "<tr><th class=\"l\">bi-directional G(b)</th><td colspan=\"{n}\">{}</td><td colspan=\"{n}\">{}</td></tr>",
            fmt_um(Some(b.external_um)),
            fmt_um(Some(b.internal_um))
        );
    }
    let _ = write!(h, "<tr><th class=\"l\">feed / (mm/min)</th>");
    for _ in 0..2 {
        for t in &g.tests {
            let _ = write!(h, "<td>{:.0}</td>", feed_mm_min(&t.result));
        }
    }
    let _ = writeln!(h, "</tr>\n</table>");
    let _ = writeln!(
        h,
        "<p class=\"note\">G: largest minus smallest radius about the path's least-squares centre; \
         F: largest and smallest radius minus the set radius r (over the steady revolutions); \
         G(b): the range of the cw and ccw paths together about their common least-squares centre. \
         Files: {}.</p>",
        escape(
            &g.tests
                .iter()
                .map(|t| test_label(t))
                .collect::<Vec<_>>()
                .join(", ")
        )
    );
    h
}

/// The circle plots of the page: per plane a heading, per group the polar plot with, beside
/// it, each test's verdict and breakdown by source (where `diagnosis` is given), the ISO table
/// and the out-of-plane plot.
pub(crate) fn section(
    page: &mut Page,
    groups: &[CircleGroup],
    figures: &[[Figure; 2]],
    scale: &PolarScale,
    diagnosis: Option<&SuiteDiagnosis>,
) {
    page.push(&format!(
        "<p class=\"note\">cw (blue) and ccw (orange) of one plane, acceleration and circle centre \
         in one plot, the TCP path (R-Test) on the left and the axes' own readings (scales) on the \
         right; radial deviation from the set circle on a polar scale with rings every {} µm, the \
         same for every plot. A dot marks where the steady revolutions start, an arrow the \
         direction of travel. Beside each plot its ISO 230-4 figures and the out-of-plane \
         deviation over the phase with the fitted plane (its amplitude is the out-of-plane EIJ). A \
         single test with its fitted ellipses (paper Fig. 5, 8): <code>eij evaluate FILE --plot F.svg</code>.</p>\n",
        short(scale.ring_um, 3)
    ));
    if diagnosis.is_some() {
        page.push(&format!("<p class=\"note\">{}</p>\n", escape(READING_NOTE)));
    }
    let mut plane = None;
    for (g, [polar_fig, oop]) in groups.iter().zip(figures) {
        let p = g.tests[0].result.plane;
        if plane != Some(p) {
            page.heading(
                3,
                &format!("circle-plots-{p}"),
                &format!("Circle plots, plane {p}"),
            );
            plane = Some(p);
        }
        let mut beside = String::new();
        if let Some(d) = diagnosis {
            for (&i, t) in g.indices.iter().zip(&g.tests) {
                beside.push_str(&breakdown_html(
                    &d.tests[i],
                    d.verdicts[i].as_ref(),
                    &test_label(t),
                ));
            }
        }
        beside.push_str(&iso_table(g));
        beside.push_str(&super::page::figure_html(oop));
        page.figure_beside(polar_fig, &beside);
    }
}
