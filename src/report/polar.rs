//! Circle plots as metrologists read them (ISO 230-4 style): the radial deviation of each path
//! from the set circle drawn on a polar µm scale, cw and ccw overlaid, the start point and the
//! direction of travel marked; and the out-of-plane deviation of the same tests over the phase.
//!
//! A point at angle θ about the centre with radius ρ is drawn at angle θ and drawn radius
//! 1 + (ρ − r)/U, r the set radius and U the µm per unit of drawn radius of a [`PolarScale`]:
//! the nominal circle is the unit circle, the rings are whole multiples of the ring step. The
//! centre is the least-squares centre of the paths drawn together (cw and ccw: as for the
//! bi-directional circular deviation G(b)), so that the radial band drawn is what G and G(b)
//! measure. One scale serves every plot of a page, so that plots compare at a glance.

use std::f64::consts::TAU;

use plotters::prelude::*;

use super::svg::{self, Entry, Mark};
use super::{short, ReportError};
use crate::axes::Direction;
use crate::measured::suite::EvaluatedTest;
use crate::rtest::normalise::circle_centre;
use crate::rtest::{CircleSeries, EvalOptions};

/// Colour of clockwise paths.
pub(crate) const CW: RGBColor = RGBColor(0, 114, 178);
/// Colour of counter-clockwise paths.
pub(crate) const CCW: RGBColor = RGBColor(213, 94, 0);
/// Points per drawn path at most.
const MAX_POINTS: usize = 1500;
/// Out-of-plane points per test at most.
const MAX_SCATTER: usize = 500;
/// Drawn radius of the innermost and outermost ring: the scale spans ±this about the nominal
/// circle.
const HALF_SPAN: f64 = 0.5;

/// The colour of a direction.
pub(crate) fn direction_color(d: Direction) -> RGBColor {
    match d {
        Direction::Cw => CW,
        Direction::Ccw => CCW,
    }
}

/// The polar µm scale shared by the plots of a page.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PolarScale {
    /// Radial deviation between two rings, µm (1-2-5 sequence).
    pub ring_um: f64,
    /// Rings on each side of the nominal circle.
    pub rings: usize,
}

impl PolarScale {
    /// The scale whose outermost rings enclose `max_dev_um` (the largest |ρ − r| of any path of
    /// the page) with two to five rings a side.
    pub(crate) fn enclosing(max_dev_um: f64) -> PolarScale {
        if !(max_dev_um.is_finite() && max_dev_um > 0.0) {
            return PolarScale {
                ring_um: 1.0,
                rings: 1,
            };
        }
        let ring_um = svg::nice_floor(max_dev_um / 2.0);
        PolarScale {
            ring_um,
            rings: (max_dev_um / ring_um).ceil().max(1.0) as usize,
        }
    }

    /// What the rings mean, for a figure's header: `rings every 2 µm from -4 µm (inner) to
    /// +4 µm (outer) · bold ring: the set circle (0)`; numbers with the ASCII minus, as every
    /// number eij prints on the console and the page.
    pub(crate) fn rings_key(&self) -> String {
        let outer = self.ring_um * self.rings as f64;
        format!(
            "rings every {} µm from -{} µm (inner) to +{} µm (outer) · bold ring: the set circle (0)",
            short(self.ring_um, 3),
            short(outer, 3),
            short(outer, 3)
        )
    }

    /// µm per unit of drawn radius.
    fn um_per_unit(&self) -> f64 {
        self.ring_um * self.rings as f64 / HALF_SPAN
    }

    /// The drawn radius of a radial deviation, clamped to the plot (a deviation beyond the scale
    /// stays visible at its edge).
    fn drawn(&self, dev_um: f64) -> f64 {
        (1.0 + dev_um / self.um_per_unit()).clamp(0.05, 1.0 + 1.2 * HALF_SPAN)
    }
}

/// One path of a test in polar form about a centre: angle (rad) and radial deviation (µm) per
/// sample of the steady revolutions, in time order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PolarPath {
    /// Angle of each sample about the centre, rad.
    pub angle: Vec<f64>,
    /// ρ − r per sample, µm.
    pub dev_um: Vec<f64>,
    /// Sense of travel.
    pub direction: Direction,
}

/// The in-plane coordinates (a, b) of a test's internal or external path over its steady
/// revolutions, mm.
pub(crate) fn steady_path(t: &EvaluatedTest, external: bool) -> (Vec<f64>, Vec<f64>) {
    let (a, b) = t.result.plane.axes();
    let s: &CircleSeries = &t.series;
    let col = |ax| {
        let v = if external { s.ext_mm(ax) } else { s.int_mm(ax) };
        v[t.result.steady.clone()].to_vec()
    };
    (col(a), col(b))
}

/// The paths of `tests` (internal or external) in polar form about the least-squares centre
/// of all of them together; `None` when no centre can be fitted.
pub(crate) fn polar_paths(tests: &[&EvaluatedTest], external: bool) -> Option<Vec<PolarPath>> {
    let paths: Vec<(Vec<f64>, Vec<f64>)> = tests.iter().map(|t| steady_path(t, external)).collect();
    let all_a: Vec<f64> = paths.iter().flat_map(|p| p.0.iter().copied()).collect();
    let all_b: Vec<f64> = paths.iter().flat_map(|p| p.1.iter().copied()).collect();
    if all_a.len() < 4 {
        return None;
    }
    let c = circle_centre(&all_a, &all_b)?;
    Some(
        tests
            .iter()
            .zip(paths)
            .map(|(t, (a, b))| {
                let r = t.result.radius_mm;
                let (angle, dev_um) = a
                    .iter()
                    .zip(&b)
                    .map(|(x, y)| {
                        let (u, v) = (x - c[0], y - c[1]);
                        (v.atan2(u), (u.hypot(v) - r) * 1e3)
                    })
                    .unzip();
                PolarPath {
                    angle,
                    dev_um,
                    direction: t.result.direction,
                }
            })
            .collect(),
    )
}

/// The largest |ρ − r| of the paths, µm.
pub(crate) fn max_deviation_um(paths: &[PolarPath]) -> f64 {
    paths
        .iter()
        .flat_map(|p| p.dev_um.iter())
        .fold(0.0, |m, d| m.max(d.abs()))
}

/// What a polar figure shows: title, condition lines, the paths of the two panels (external,
/// internal) and the legend labels of the tests.
#[derive(Debug, Clone)]
pub(crate) struct PolarFigure {
    /// Title.
    pub title: String,
    /// Condition lines under the title.
    pub lines: Vec<String>,
    /// The in-plane axes' names (a, b), e.g. `x`, `y`.
    pub axes: (String, String),
    /// External (TCP) paths, one per test.
    pub external: Vec<PolarPath>,
    /// Internal (scale) paths, one per test.
    pub internal: Vec<PolarPath>,
    /// Legend label per test.
    pub labels: Vec<String>,
}

/// The figure: the TCP (R-Test) panel and the scales panel side by side on `scale`.
pub(crate) fn polar_svg(fig: &PolarFigure, scale: &PolarScale) -> Result<String, ReportError> {
    let panel = 430u32;
    let header_px = 16 + 30 + 22 * fig.lines.len() as u32 + 6;
    let legend_px = 20 + 24 * (fig.labels.len() + 1).div_ceil(2) as u32;
    svg::render((2 * panel + 20, header_px + panel + legend_px), |root| {
        let body = svg::header(root, &fig.title, &fig.lines)?;
        let (panels, legend) = body.split_vertically(panel);
        let (left, right) = panels.split_horizontally(panel + 10);
        polar_panel(
            &left,
            "TCP: R-Test, external path",
            fig,
            &fig.external,
            scale,
        )?;
        polar_panel(
            &right,
            "axes' scales, internal path",
            fig,
            &fig.internal,
            scale,
        )?;
        let mut entries: Vec<Entry> = fig
            .labels
            .iter()
            .zip(&fig.external)
            .map(|(l, p)| Entry::new(l.clone(), direction_color(p.direction), Mark::Line))
            .collect();
        entries.push(Entry::new(
            "start (dot) and direction of travel (arrow)",
            svg::SET,
            Mark::Dot,
        ));
        let cols = legend.split_evenly((1, 2));
        let half = entries.len().div_ceil(2);
        svg::side_panel(&cols[0], &entries[..half], &[])?;
        svg::side_panel(&cols[1], &entries[half..], &[])
    })
}

fn polar_panel(
    area: &svg::Area,
    caption: &str,
    fig: &PolarFigure,
    paths: &[PolarPath],
    scale: &PolarScale,
) -> Result<(), ReportError> {
    let lim = 1.0 + HALF_SPAN + 0.27;
    let mut chart = ChartBuilder::on(area)
        .margin(6)
        .caption(caption, (svg::FONT, svg::DESC_SIZE + 1.0))
        .build_cartesian_2d(-lim..lim, -lim..lim)?;
    let ring = |radius: f64| -> Vec<(f64, f64)> {
        (0..=240)
            .map(|i| {
                let t = TAU * i as f64 / 240.0;
                (radius * t.cos(), radius * t.sin())
            })
            .collect()
    };
    let grey = RGBColor(200, 200, 200);
    for k in 0..12 {
        let t = TAU * k as f64 / 12.0;
        let (r0, r1) = (1.0 - HALF_SPAN, 1.0 + HALF_SPAN);
        chart.draw_series(LineSeries::new(
            vec![(r0 * t.cos(), r0 * t.sin()), (r1 * t.cos(), r1 * t.sin())],
            grey.stroke_width(1),
        ))?;
    }
    // The rings carry no numbers: any angle of the band between the inner and the outer ring
    // is crossed by the paths (and the set circle by all of them), so a label there sits on a
    // trace. The step is written in the free corner beyond the outer ring (and in the
    // figure's header with the range: rings_key).
    let n = scale.rings as i64;
    for k in -n..=n {
        let r = scale.drawn(k as f64 * scale.ring_um);
        let style = if k == 0 {
            RGBColor(60, 60, 60).stroke_width(2)
        } else {
            grey.stroke_width(1)
        };
        chart.draw_series(LineSeries::new(ring(r), style))?;
    }
    chart.draw_series(std::iter::once(Text::new(
        format!("ring = {} µm", short(scale.ring_um, 3)),
        (0.95, lim - 0.04),
        svg::text(svg::LABEL_SIZE - 1.0, RGBColor(90, 90, 90)),
    )))?;
    let (a, b) = &fig.axes;
    let out = 1.0 + HALF_SPAN + 0.08;
    for (text, x, y) in [
        (format!("+{a}"), out, 0.0),
        (format!("+{b}"), -0.05, out + 0.08),
        (format!("-{a}"), -out - 0.17, 0.0),
        (format!("-{b}"), -0.05, -out - 0.02),
    ] {
        chart.draw_series(std::iter::once(Text::new(
            text,
            (x, y),
            svg::text(svg::TEXT_SIZE, svg::SET),
        )))?;
    }
    for p in paths {
        let color = direction_color(p.direction);
        let pts: Vec<(f64, f64)> = svg::decimate(p.angle.len(), MAX_POINTS)
            .map(|i| {
                let r = scale.drawn(p.dev_um[i]);
                (r * p.angle[i].cos(), r * p.angle[i].sin())
            })
            .collect();
        chart.draw_series(LineSeries::new(pts, color.stroke_width(1)))?;
    }
    for p in paths {
        start_and_arrow(&mut chart, p, scale)?;
    }
    Ok(())
}

type PolarChart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// A dot on the first sample and an arrowhead a little further on, pointing along the travel.
fn start_and_arrow(
    chart: &mut PolarChart,
    p: &PolarPath,
    scale: &PolarScale,
) -> Result<(), ReportError> {
    let Some(&a0) = p.angle.first() else {
        return Ok(());
    };
    let color = direction_color(p.direction);
    let at = |angle: f64, dev: f64| {
        let r = scale.drawn(dev);
        (r * angle.cos(), r * angle.sin())
    };
    let start = at(a0, p.dev_um[0]);
    chart.draw_series(std::iter::once(Circle::new(start, 5, color.filled())))?;
    chart.draw_series(std::iter::once(Circle::new(
        start,
        5,
        svg::SET.stroke_width(1),
    )))?;
    // The arrow sits 12° along the travel on the nominal circle, pointing along the tangent.
    let sign = if p.direction == Direction::Ccw {
        1.0
    } else {
        -1.0
    };
    let t = a0 + sign * 12f64.to_radians();
    let (cx, cy) = (t.cos(), t.sin());
    let (dx, dy) = (-sign * t.sin(), sign * t.cos());
    let (len, half) = (0.11, 0.05);
    let tip = (cx + dx * len, cy + dy * len);
    let left = (cx - dy * half, cy + dx * half);
    let right = (cx + dy * half, cy - dx * half);
    chart.draw_series(std::iter::once(Polygon::new(
        vec![tip, left, right],
        color.filled(),
    )))?;
    Ok(())
}

/// The out-of-plane deviation d_k of each test over the phase with its fitted plane
/// d_k = E_ka ä_a + E_kb ä_b + c_k, cw and ccw overlaid.
pub(crate) fn out_of_plane_svg(
    title: &str,
    lines: &[String],
    tests: &[(&EvaluatedTest, String)],
) -> Result<String, ReportError> {
    struct Series {
        points: Vec<(f64, f64)>,
        plane: Vec<(f64, f64)>,
        color: RGBColor,
        label: String,
        fit: String,
    }
    let mut series = Vec::new();
    let mut k_axis = String::new();
    for (t, label) in tests {
        let opts = EvalOptions {
            plane: Some(t.result.plane),
            radius_mm: Some(t.result.radius_mm),
        };
        let view = super::CircleView::new(&t.series, &opts)?;
        k_axis = view.norm.plane.normal().to_string();
        let oop = view.out_of_plane(MAX_SCATTER);
        let (eka, ekb) = (
            view.joint.eij[&oop.e_ka].value,
            view.joint.eij[&oop.e_kb].value,
        );
        let (points, plane) = (oop.points, oop.plane);
        series.push(Series {
            points,
            plane,
            color: direction_color(t.result.direction),
            label: label.clone(),
            fit: format!(
                "{} {} = {eka:.4}, {} = {ekb:.4}",
                t.result.direction, oop.e_ka, oop.e_kb
            ),
        });
    }
    let (lo, hi) = svg::padded_range(
        series
            .iter()
            .flat_map(|s| s.points.iter().chain(&s.plane).map(|p| p.1)),
        0.08,
    );
    let header_px = 16 + 30 + 22 * lines.len() as u32 + 6;
    let dec = svg::decimals_for(hi - lo);
    let legend_px = 24 * (series.len() as u32 + 1) + 30;
    svg::render((500, header_px + 300 + legend_px), |root| {
        let body = svg::header(root, title, lines)?;
        let (top, bottom) = body.split_vertically(300);
        let mut chart = ChartBuilder::on(&top)
            .margin(10)
            .x_label_area_size(46)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..360.0, lo..hi)?;
        svg::mesh(
            &mut chart,
            "phase φ of the set point / °",
            &format!("d{k_axis} / µm"),
            0,
            dec,
        )?;
        for s in &series {
            let light = s.color.mix(0.35);
            chart.draw_series(s.points.iter().map(|p| Circle::new(*p, 2, light.filled())))?;
        }
        for s in &series {
            chart.draw_series(LineSeries::new(s.plane.clone(), s.color.stroke_width(3)))?;
        }
        let mut legend = Vec::new();
        let mut notes = vec!["joint fit, µm·s²/m:".to_string()];
        for s in &series {
            legend.push(Entry::new(s.label.clone(), s.color, Mark::Dot));
            notes.push(s.fit.clone());
        }
        legend.push(Entry::new("fitted plane (joint fit)", svg::SET, Mark::Line));
        let (l, r) = bottom.split_horizontally(250);
        svg::side_panel(&l, &legend, &[])?;
        svg::side_panel(&r, &[], &notes)
    })
}
