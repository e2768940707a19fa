//! EIJ maps over the workspace: each EIJ of the plane over the first gridded axis, one line per
//! value of the second gridded axis (compensation table of `eij map`).

use super::svg::{self, Entry, Mark};
use super::{short, ReportError};
use crate::axes::Axis;
use crate::map::{MapPoint, MapSpec};
use plotters::prelude::*;

const PALETTE: [RGBColor; 10] = [
    svg::INTERNAL,
    svg::EXTERNAL,
    svg::FIT,
    svg::SECOND,
    svg::ELLIPSE_EXT,
    svg::SET,
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    svg::ELLIPSE_INT,
];

/// The map figure, titled by `machine` and the circles' conditions. `axes` are the machine's
/// axes in its order (to read positions); the gridded axis with the most points is drawn on
/// the abscissa (the fastest-varying one among equals), one line per position of the next.
pub fn map_svg(
    machine: &str,
    axes: &[Axis],
    spec: &MapSpec,
    points: &[MapPoint],
) -> Result<String, ReportError> {
    if points.is_empty() {
        return Err(ReportError::BadInput {
            source_name: "map".into(),
            message: "no grid points".into(),
        });
    }
    // Which axes vary, in the order of the grid (first = slowest).
    let varying: Vec<usize> = (0..axes.len())
        .filter(|&i| {
            points
                .iter()
                .any(|p| (p.position_m[i] - points[0].position_m[i]).abs() > 1e-12)
        })
        .collect();
    let distinct = |i: usize| {
        let mut v: Vec<i64> = points
            .iter()
            .map(|p| (p.position_m[i] * 1e6).round() as i64)
            .collect();
        v.sort_unstable();
        v.dedup();
        v.len()
    };
    let x_axis = varying
        .iter()
        .copied()
        .max_by_key(|&i| (distinct(i), i))
        .unwrap_or(0);
    let group_axis = varying.iter().rev().copied().find(|&i| i != x_axis);
    let mut groups: Vec<(f64, Vec<&MapPoint>)> = Vec::new();
    for p in points {
        let key = group_axis.map_or(0.0, |g| p.position_m[g]);
        match groups.iter_mut().find(|(k, _)| (*k - key).abs() < 1e-12) {
            Some((_, v)) => v.push(p),
            None => groups.push((key, vec![p])),
        }
    }
    let params = spec.plane.parameters();
    let title = format!(
        "EIJ map of {machine}: {} {} circles, r = {} mm, {} m/s², over {}",
        spec.plane,
        spec.direction,
        short(spec.radius_m * 1e3, 3),
        short(spec.accel_m_s2, 3),
        axes[x_axis].letter()
    );
    let fixed: Vec<String> = (0..axes.len())
        .filter(|i| !varying.contains(i))
        .map(|i| {
            format!(
                "{} = {} mm",
                axes[i].letter(),
                short(points[0].position_m[i] * 1e3, 1)
            )
        })
        .collect();
    let ranges = shared_ranges(
        &params
            .iter()
            .map(|e| points.iter().map(|p| p.eij[e]).collect::<Vec<f64>>())
            .collect::<Vec<_>>(),
    );
    let span = ranges.first().map_or(0.0, |(lo, hi)| hi - lo);
    let lines = vec![
        format!(
            "harmonic steady state, same evaluation as measured data · other axes: {}",
            if fixed.is_empty() {
                "none".to_string()
            } else {
                fixed.join(", ")
            }
        ),
        format!(
            "one scale in every panel: each spans {} µm·s²/m about its own middle, so that slopes compare",
            short(span, 3)
        ),
    ];
    let xs: Vec<f64> = points.iter().map(|p| p.position_m[x_axis] * 1e3).collect();
    let (x0, x1) = svg::padded_range(xs.iter().copied(), 0.02);
    let header_px = 16 + 30 + 22 * lines.len() as u32 + 6;
    let (cols, rows) = (3usize, 2usize);
    // 3 × 380 + 200 px: drawn at full size on the report page (1350 px wide).
    let panel = (380u32, 300u32);
    svg::render(
        (
            cols as u32 * panel.0 + 200,
            header_px + rows as u32 * panel.1,
        ),
        |root| {
            let body = svg::header(root, &title, &lines)?;
            let (grid, side) = body.split_horizontally(cols as u32 * panel.0);
            let cells = grid.split_evenly((rows, cols));
            let mut legend = Vec::new();
            for (g, (key, _)) in groups.iter().enumerate() {
                let label = match group_axis {
                    Some(a) => format!("{} = {} mm", axes[a].letter(), short(key * 1e3, 1)),
                    None => "EIJ".to_string(),
                };
                legend.push(Entry::new(label, PALETTE[g % PALETTE.len()], Mark::Line));
            }
            for ((cell, e), &(lo, hi)) in cells.iter().zip(params.iter()).zip(&ranges) {
                let mut chart = ChartBuilder::on(cell)
                    .margin(10)
                    .caption(format!("{e} / (µm·s²/m)"), (svg::FONT, svg::TEXT_SIZE))
                    .x_label_area_size(45)
                    .y_label_area_size(70)
                    .build_cartesian_2d(x0..x1, lo..hi)?;
                svg::mesh(
                    &mut chart,
                    &format!("{} / mm", axes[x_axis].letter()),
                    "",
                    svg::decimals_for(x1 - x0),
                    svg::decimals_for(hi - lo),
                )?;
                for (g, (_, pts)) in groups.iter().enumerate() {
                    let color = PALETTE[g % PALETTE.len()];
                    let series: Vec<(f64, f64)> = pts
                        .iter()
                        .map(|p| (p.position_m[x_axis] * 1e3, p.eij[e]))
                        .collect();
                    chart.draw_series(LineSeries::new(series.clone(), color.stroke_width(2)))?;
                    chart.draw_series(
                        series
                            .into_iter()
                            .map(|q| Circle::new(q, 3, color.filled())),
                    )?;
                }
            }
            svg::side_panel(&side, &legend, &[])?;
            Ok(())
        },
    )
}

/// The value range of each panel: one span for all (the largest spread of any panel, padded
/// by 10 % a side), each about the middle of its own values, so that a panel whose values
/// barely change draws flat instead of stretched to the panel's height.
pub(crate) fn shared_ranges(panels: &[Vec<f64>]) -> Vec<(f64, f64)> {
    let extent = |v: &[f64]| {
        v.iter()
            .filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x), hi.max(x))
            })
    };
    let spread = panels
        .iter()
        .map(|v| extent(v))
        .filter(|(lo, hi)| lo.is_finite() && hi.is_finite())
        .map(|(lo, hi)| hi - lo)
        .fold(0.0, f64::max);
    let largest = panels
        .iter()
        .flat_map(|v| v.iter())
        .filter(|x| x.is_finite())
        .fold(0.0, |m: f64, x| m.max(x.abs()));
    // All panels constant: a span of a fifth of the largest value (or 1) shows them flat.
    let span = if spread > 1e-12 * largest.max(1.0) {
        spread * 1.2
    } else if largest > 0.0 {
        0.2 * largest
    } else {
        2.0
    };
    panels
        .iter()
        .map(|v| {
            let (lo, hi) = extent(v);
            let mid = if lo.is_finite() { 0.5 * (lo + hi) } else { 0.0 };
            (mid - 0.5 * span, mid + 0.5 * span)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::shared_ranges;

    #[test]
    fn panels_share_one_span_and_hold_their_values() {
        // Issue 29 item 9: EZZ spanning −0.3437…−0.3441 beside EXX spanning 0.05 looked like a
        // strong trend on its own scale. One span for all: the largest spread, padded.
        let ezz = vec![-0.3437, -0.3439, -0.3441];
        let exx = vec![-0.53, -0.51, -0.48];
        let r = shared_ranges(&[ezz.clone(), exx.clone()]);
        let span = 0.05 * 1.2;
        for (v, (lo, hi)) in [ezz, exx].iter().zip(&r) {
            assert!((hi - lo - span).abs() < 1e-12, "{lo}…{hi}");
            assert!(v.iter().all(|x| lo < x && x < hi));
        }
        // EZZ's 0.0004 fill 0.7 % of its panel's height, not all of it.
        assert!(0.0004 / (r[0].1 - r[0].0) < 0.01);
        // Constant panels get a span of their own size, never zero.
        let c = shared_ranges(&[vec![0.5, 0.5], vec![0.0]]);
        assert!(c.iter().all(|(lo, hi)| (hi - lo - 0.1).abs() < 1e-12));
    }
}
