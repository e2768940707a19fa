//! Identification figure from the report of `eij identify` ([`IdentReport`]): measured vs
//! simulated EIJ before and after, one panel per parameter with one column per test, and the
//! cost over the iterations (log scale).

use plotters::prelude::*;

use super::svg::{self, Entry, Mark};
use super::{short, ReportError};
use crate::axes::Eij;
use crate::ident::report::{IdentReport, TestReport};

/// Short label of a test, e.g. `zx ccw 4`.
pub fn test_label(t: &TestReport) -> String {
    format!("{} {} {}", t.plane, t.direction, short(t.accel_m_s2, 2))
}

/// The identification figure from the report JSON of `eij identify`: per EIJ one panel with
/// the measured values (± 2 standard errors) and the simulated values before and after, per
/// test; and the cost over the iterations on a log scale.
pub fn identification_svg(rep: &IdentReport) -> Result<String, ReportError> {
    let params = rep.eij_parameters();
    let cols = 3usize;
    let cells = params.len() + 1;
    let rows = cells.div_ceil(cols);
    let (cell_w, cell_h) = (520u32, 380u32);
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
    if let Some(m) = &rep.machine {
        lines.push(format!(
            "machine: {m}  ·  tests labelled plane, direction, set acceleration / (m/s²)"
        ));
    } else {
        lines.push("tests labelled plane, direction, set acceleration / (m/s²)".into());
    }
    let legend = vec![
        Entry::new("measured ± 2 std err", svg::SET, Mark::DotBar),
        Entry::new("simulated, initial", svg::INITIAL, Mark::Ring),
        Entry::new("simulated, identified", svg::FIT, Mark::Dot),
        Entry::new("cost per iteration", svg::INTERNAL, Mark::Line),
    ];
    let header_px = 16 + 30 + 22 * lines.len() as u32 + 6;
    let side_px = 260u32;
    svg::render(
        (
            cols as u32 * cell_w + side_px,
            header_px + rows as u32 * cell_h,
        ),
        |root| {
            let body = svg::header(root, title, &lines)?;
            let (grid, side) = body.split_horizontally(cols as u32 * cell_w);
            let areas = grid.split_evenly((rows, cols));
            for (area, p) in areas.iter().zip(&params) {
                parameter_panel(area, rep, *p)?;
            }
            cost_panel(&areas[params.len()], &rep.cost_history)?;
            svg::side_panel(&side, &legend, &[])
        },
    )
}

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
    let label_of = move |v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(i) | SegmentValue::Exact(i) => {
            labels.get(*i).cloned().unwrap_or_default()
        }
        SegmentValue::Last => String::new(),
    };
    let dec = svg::decimals_for(hi - lo);
    let yf = move |v: &f64| short(*v, dec);
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .caption(
            format!("{p} / (µm·s²/m)"),
            (svg::FONT, svg::DESC_SIZE + 2.0),
        )
        .x_label_area_size(78)
        .y_label_area_size(62)
        .build_cartesian_2d((0..n).into_segmented(), lo..hi)?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(225, 225, 225))
        .disable_x_mesh()
        .x_labels(n + 1)
        .y_labels(8)
        .x_label_formatter(&label_of)
        .y_label_formatter(&yf)
        .x_label_style(
            (svg::FONT, svg::LABEL_SIZE - 2.0)
                .into_font()
                .transform(FontTransform::Rotate90),
        )
        .y_label_style((svg::FONT, svg::LABEL_SIZE))
        .draw()?;
    for (i, t) in tests.iter().enumerate() {
        let m = t.measured[&p];
        let x = || SegmentValue::CenterOf(i);
        let s = se(t);
        if s > 0.0 {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(x(), m - 2.0 * s), (x(), m + 2.0 * s)],
                svg::ERROR_BAR.stroke_width(1),
            )))?;
        }
        chart.draw_series(std::iter::once(Circle::new((x(), m), 4, svg::SET.filled())))?;
        if let Some(v) = t.simulated_initial.get(&p).filter(|v| v.is_finite()) {
            chart.draw_series(std::iter::once(Circle::new(
                (x(), *v),
                5,
                svg::INITIAL.stroke_width(2),
            )))?;
        }
        if let Some(v) = t.simulated_final.get(&p).filter(|v| v.is_finite()) {
            chart.draw_series(std::iter::once(Circle::new(
                (x(), *v),
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
