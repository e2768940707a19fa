//! Identification figure from the report of `eij identify` ([`IdentReport`]): measured vs
//! simulated EIJ before and after, one panel per parameter with one row per test (labels
//! horizontal, with the circle centre, so that tests at two positions are told apart), and the
//! cost over the iterations (log scale).

use plotters::prelude::*;

use super::svg::{self, Entry, Mark};
use super::{short, ReportError};
use crate::axes::Eij;
use crate::ident::report::{IdentReport, TestReport};

/// Short label of a test with its circle centre where known, e.g. `zx ccw 4 @ 150,-100,0`:
/// tests at two positions must be told apart.
pub(crate) fn test_label(t: &TestReport) -> String {
    let base = format!("{} {} {}", t.plane, t.direction, short(t.accel_m_s2, 1));
    match &t.position_mm {
        Some(p) => format!("{base} @ {}", super::labels::position_label(p)),
        None => base,
    }
}

/// The identification figure from the report JSON of `eij identify`: per EIJ one panel with
/// the measured values (± 2 standard errors) and the simulated values before and after, one
/// row per test labelled with its conditions and circle centre; and the cost over the
/// iterations on a log scale.
pub fn identification_svg(rep: &IdentReport) -> Result<String, ReportError> {
    let params = rep.eij_parameters();
    let cols = 3usize;
    let cells = params.len() + 1;
    let rows = cells.div_ceil(cols);
    let most = params
        .iter()
        .map(|p| {
            rep.tests
                .iter()
                .filter(|t| t.measured.contains_key(p))
                .count()
        })
        .max()
        .unwrap_or(1);
    let (cell_w, cell_h) = (450u32, (ROW_PX * most as u32 + 100).max(260));
    let title = "Identification: measured vs simulated EIJ before and after, cost";
    let mut lines = vec![format!(
        "{} tests  ·  {} parameters  ·  cost {} → {} in {} iterations (sum of squared weighted residuals)",
        rep.tests.len(),
        rep.parameters.len(),
        short(rep.cost_initial, 4),
        short(rep.cost_final, 4),
        rep.cost_history.len().saturating_sub(1)
    )];
    if let Some(h0) = rep.cost_history.first() {
        if (h0 - rep.cost_initial).abs() > 0.01 * rep.cost_initial.abs() {
            lines.push(format!(
                "note: the cost history starts at {} (cost_history[0]), not at cost_initial = {}",
                short(*h0, 4),
                short(rep.cost_initial, 4)
            ));
        }
    }
    let what = "tests labelled plane, direction, set acceleration / (m/s²) @ circle centre / mm";
    lines.push(match &rep.machine {
        Some(m) => format!("machine: {m}  ·  {what}"),
        None => what.to_string(),
    });
    let legend = [
        Entry::new("measured ± 2 std err", svg::SET, Mark::DotBar),
        Entry::new("simulated, initial", svg::INITIAL, Mark::Ring),
        Entry::new("simulated, identified", svg::FIT, Mark::Dot),
        Entry::new("cost per iteration", svg::INTERNAL, Mark::Line),
    ];
    let header_px = 16 + 30 + 22 * lines.len() as u32 + 6;
    let legend_px = 44u32;
    svg::render(
        (
            cols as u32 * cell_w,
            header_px + legend_px + rows as u32 * cell_h,
        ),
        |root| {
            let body = svg::header(root, title, &lines)?;
            let (strip, grid) = body.split_vertically(legend_px);
            for (area, e) in strip.split_evenly((1, legend.len())).iter().zip(&legend) {
                svg::side_panel(area, std::slice::from_ref(e), &[])?;
            }
            let areas = grid.split_evenly((rows, cols));
            for (area, p) in areas.iter().zip(&params) {
                parameter_panel(area, rep, *p)?;
            }
            cost_panel(&areas[params.len()], &rep.cost_history)
        },
    )
}

/// Height of one test's row in a parameter panel, px.
const ROW_PX: u32 = 17;

fn parameter_panel(area: &svg::Area, rep: &IdentReport, p: Eij) -> Result<(), ReportError> {
    let tests: Vec<&TestReport> = rep
        .tests
        .iter()
        .filter(|t| t.measured.contains_key(&p))
        .collect();
    let n = tests.len();
    let se = |t: &TestReport| t.measured_std_err.get(&p).copied().unwrap_or(0.0);
    let values = tests.iter().flat_map(|t| {
        let m = t.measured[&p];
        [
            m - 2.0 * se(t),
            m + 2.0 * se(t),
            t.simulated_initial.get(&p).copied().unwrap_or(f64::NAN),
            t.simulated_final.get(&p).copied().unwrap_or(f64::NAN),
        ]
    });
    let (lo, hi) = svg::padded_range(values, 0.08);
    let labels: Vec<String> = tests.iter().map(|t| test_label(t)).collect();
    // Row i of the list is drawn at n − 1 − i: the tests read from the top, as in the tables.
    let label_of = move |v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(i) | SegmentValue::Exact(i) if *i < n => {
            labels.get(n - 1 - i).cloned().unwrap_or_default()
        }
        _ => String::new(),
    };
    let dec = svg::decimals_for(hi - lo);
    let xf = move |v: &f64| short(*v, dec);
    // The panel's own height beyond its rows stays empty below the x axis.
    let used = (ROW_PX * n as u32 + 100).min(area.dim_in_pixel().1);
    let (area, _) = area.split_vertically(used);
    let mut chart = ChartBuilder::on(&area)
        .margin(8)
        .margin_right(16)
        .caption(
            format!("{p} / (µm·s²/m)"),
            (svg::FONT, svg::DESC_SIZE + 2.0),
        )
        .x_label_area_size(34)
        .y_label_area_size(178)
        .build_cartesian_2d(lo..hi, (0..n).into_segmented())?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(225, 225, 225))
        .disable_y_mesh()
        .y_labels(n + 1)
        .x_labels(5)
        .y_label_formatter(&label_of)
        .x_label_formatter(&xf)
        .label_style((svg::FONT, svg::LABEL_SIZE - 1.0))
        .draw()?;
    for (i, t) in tests.iter().enumerate() {
        let m = t.measured[&p];
        let y = || SegmentValue::CenterOf(n - 1 - i);
        let s = se(t);
        if s > 0.0 {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(m - 2.0 * s, y()), (m + 2.0 * s, y())],
                svg::ERROR_BAR.stroke_width(1),
            )))?;
        }
        chart.draw_series(std::iter::once(Circle::new((m, y()), 4, svg::SET.filled())))?;
        if let Some(v) = t.simulated_initial.get(&p).filter(|v| v.is_finite()) {
            chart.draw_series(std::iter::once(Circle::new(
                (*v, y()),
                5,
                svg::INITIAL.stroke_width(2),
            )))?;
        }
        if let Some(v) = t.simulated_final.get(&p).filter(|v| v.is_finite()) {
            chart.draw_series(std::iter::once(Circle::new(
                (*v, y()),
                3,
                svg::FIT.filled(),
            )))?;
        }
    }
    Ok(())
}

fn cost_panel(area: &svg::Area, history: &[f64]) -> Result<(), ReportError> {
    let positive: Vec<f64> = history
        .iter()
        .copied()
        .filter(|c| c.is_finite() && *c > 0.0)
        .collect();
    let lo = positive.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = positive.iter().copied().fold(0.0, f64::max);
    let (lo, hi) = if lo.is_finite() && hi > 0.0 {
        (lo / 2.0, hi * 2.0)
    } else {
        (1e-3, 1.0)
    };
    let last = history.len().saturating_sub(1).max(1) as f64;
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .caption(
            "cost over iterations (log scale)",
            (svg::FONT, svg::DESC_SIZE + 2.0),
        )
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.2..last + 0.2, (lo..hi).log_scale())?;
    let xf = |v: &f64| short(*v, 1);
    let yf = |v: &f64| format!("{v:.1e}");
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(225, 225, 225))
        .x_desc("iteration")
        .y_desc("cost (dimensionless)")
        .x_labels(history.len().clamp(2, 10))
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style((svg::FONT, svg::LABEL_SIZE))
        .axis_desc_style((svg::FONT, svg::DESC_SIZE))
        .draw()?;
    let pts: Vec<(f64, f64)> = history
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_finite() && **c > 0.0)
        .map(|(i, c)| (i as f64, *c))
        .collect();
    chart.draw_series(LineSeries::new(pts.clone(), svg::INTERNAL.stroke_width(2)))?;
    chart.draw_series(
        pts.into_iter()
            .map(|p| Circle::new(p, 3, svg::INTERNAL.filled())),
    )?;
    Ok(())
}
