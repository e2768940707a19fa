//! Circle-test figures: the magnified paths with the set circle and the fitted ellipses (paper
//! Fig. 5 and 8) and the out-of-plane deviation over the phase with the fitted plane (Fig. 4
//! and 7).
//!
//! Magnification follows the circular-test convention of ISO 230-4: each point is drawn at its
//! own angle about the centre of the internal path, at radius r + M·(ρ − r), where ρ is its
//! distance from that centre and r the set radius. The set circle therefore stays at r, and the
//! fitted ellipses are magnified by the same rule so that they overlay their paths.
//! M is chosen from the 1-2-5 sequence so that the largest radial deviation of either path
//! is drawn as at most 30 % of r.

use std::f64::consts::TAU;

use plotters::prelude::*;

use super::svg::{self, Entry, Mark};
use super::{short, Conditions, ReportError};
use crate::axes::Eij;
use crate::rtest::fit::{self, Ellipse, JointFit};
use crate::rtest::normalise::{self, Normalised};
use crate::rtest::{CircleSeries, EvalOptions, Location, RtestError};

/// Largest magnified radial deviation, as a fraction of the radius.
const TARGET_FRACTION: f64 = 0.3;
/// Points per path polyline at most (several steady revolutions overlay).
const MAX_PATH_POINTS: usize = 4000;
/// Points of the out-of-plane scatter at most.
const MAX_SCATTER_POINTS: usize = 1500;

/// One circle test prepared for plotting: its normalisation (steady revolutions, phase, set
/// points), the joint fit, the paths about the internal centre and the fitted ellipses.
#[derive(Debug, Clone)]
pub struct CircleView {
    /// Normalised test (eq. 5–6).
    pub norm: Normalised,
    /// Joint fit (section 2.2).
    pub joint: JointFit,
    /// Internal path (a, b) about the internal centre over the steady revolutions, mm.
    pub int_mm: [Vec<f64>; 2],
    /// External path (a, b) about the same centre, mm.
    pub ext_mm: [Vec<f64>; 2],
    /// Ellipse through the internal path (units of r, about the centre).
    pub ellipse_int: Option<Ellipse>,
    /// Ellipse through the external path.
    pub ellipse_ext: Option<Ellipse>,
    /// Magnification M of the radial deviations.
    pub magnification: f64,
}

impl CircleView {
    /// Normalises and fits `series` as [`crate::rtest::evaluate`] does.
    pub fn new(series: &CircleSeries, opts: &EvalOptions) -> Result<Self, ReportError> {
        let norm = normalise::normalise(series, opts)?;
        let joint = fit::joint(&norm).ok_or_else(|| RtestError::Singular {
            at: Location::source(series.source()),
            detail: "the joint EIJ fit has no unique solution".into(),
        })?;
        let (a, b) = norm.plane.axes();
        let c = norm.centre_mm;
        let window = |v: &[f64], c: f64| -> Vec<f64> {
            v[norm.first..norm.end].iter().map(|x| x - c).collect()
        };
        let int_mm = [
            window(series.int_mm(a), c[0]),
            window(series.int_mm(b), c[1]),
        ];
        let ext_mm = [
            window(series.ext_mm(a), c[0]),
            window(series.ext_mm(b), c[1]),
        ];
        let r = norm.radius_mm;
        let ellipse_int = fit::fit_ellipse(&int_mm[0], &int_mm[1], [0.0, 0.0], r);
        let ellipse_ext = fit::fit_ellipse(&ext_mm[0], &ext_mm[1], [0.0, 0.0], r);
        let max_dev = [&int_mm, &ext_mm]
            .iter()
            .flat_map(|p| p[0].iter().zip(&p[1]).map(|(x, y)| (x.hypot(*y) - r).abs()))
            .fold(0.0, f64::max);
        let magnification = magnification_for(max_dev, r);
        Ok(CircleView {
            norm,
            joint,
            int_mm,
            ext_mm,
            ellipse_int,
            ellipse_ext,
            magnification,
        })
    }

    /// Set acceleration r ω², m/s².
    pub fn accel_m_s2(&self) -> f64 {
        self.norm.accel_m_s2()
    }

    fn direction(&self) -> &'static str {
        if self.norm.omega_rad_s > 0.0 {
            "ccw"
        } else {
            "cw"
        }
    }

    /// The condition line shared by both circle figures.
    fn conditions_line(&self) -> String {
        format!(
            "plane {}  ·  {}  ·  radius r = {} mm  ·  set acceleration {} m/s²  ·  {} Hz  ·  {} steady revolutions",
            self.norm.plane,
            self.direction(),
            short(self.norm.radius_mm, 4),
            short(self.accel_m_s2(), 3),
            short(self.norm.freq_hz(), 3),
            self.norm.revolutions
        )
    }

    /// Magnified plot: set circle, internal and external paths, fitted ellipses.
    pub fn magnified_svg(&self, cond: &Conditions) -> Result<String, ReportError> {
        let r = self.norm.radius_mm;
        let m = self.magnification;
        let magnify = |x: f64, y: f64| -> (f64, f64) {
            let rho = x.hypot(y);
            if rho == 0.0 {
                return (0.0, 0.0);
            }
            let k = (r + m * (rho - r)) / rho;
            (x * k, y * k)
        };
        let path = |p: &[Vec<f64>; 2]| -> Vec<(f64, f64)> {
            svg::decimate(p[0].len(), MAX_PATH_POINTS)
                .map(|i| magnify(p[0][i], p[1][i]))
                .collect()
        };
        let ellipse = |e: &Option<Ellipse>| -> Option<Vec<(f64, f64)>> {
            let e = e.as_ref()?;
            let l = e.q.try_inverse()?.cholesky()?.l();
            Some(
                (0..=720)
                    .map(|i| {
                        let t = TAU * i as f64 / 720.0;
                        let (c, s) = (t.cos(), t.sin());
                        let u = e.centre[0] + l[(0, 0)] * c + l[(0, 1)] * s;
                        let v = e.centre[1] + l[(1, 0)] * c + l[(1, 1)] * s;
                        magnify(u * r, v * r)
                    })
                    .collect(),
            )
        };
        let set: Vec<(f64, f64)> = (0..=720)
            .map(|i| {
                let t = TAU * i as f64 / 720.0;
                (r * t.cos(), r * t.sin())
            })
            .collect();
        let int = path(&self.int_mm);
        let ext = path(&self.ext_mm);
        let e_int = ellipse(&self.ellipse_int);
        let e_ext = ellipse(&self.ellipse_ext);
        let extent = int
            .iter()
            .chain(&ext)
            .chain(e_int.iter().flatten())
            .chain(e_ext.iter().flatten())
            .map(|(x, y)| x.abs().max(y.abs()))
            .fold(r, f64::max)
            * 1.08;
        let (a, b) = self.norm.plane.axes();
        let p = self.norm.plane;
        let title = format!(
            "Circle test {} {}: paths with radial deviations magnified ×{}",
            p,
            self.direction(),
            short(m, 0)
        );
        let lines = vec![self.conditions_line(), cond.line("circle centre")];
        let ij = |i, j| Eij::new(i, j);
        let mut notes = vec![
            format!("magnification M = {}", short(m, 0)),
            "drawn radius = r + M·(ρ − r)".into(),
            format!(
                "{} µm radial deviation = {} mm on the axes",
                short(scale_bar_um(r, m), 3),
                short(scale_bar_um(r, m) * 1e-3 * m, 4)
            ),
            String::new(),
            "joint fit, µm·s²/m (± std err):".into(),
        ];
        for e in [ij(a, a), ij(b, b), ij(b, a), ij(a, b)] {
            notes.push(format!(
                "  {} = {:.4} ± {:.4}",
                e, self.joint.eij[&e].value, self.joint.eij[&e].std_err
            ));
        }
        notes.push(format!(
            "rms residual {} µm",
            short(self.joint.rms_residual_um, 3)
        ));
        if self.ellipse_ext.is_none() || self.ellipse_int.is_none() {
            notes.push("ellipse fit failed (not an ellipse)".into());
        }
        let legend = vec![
            Entry::new(
                format!("set circle, r = {} mm", short(r, 4)),
                svg::SET,
                Mark::Line,
            ),
            Entry::new("internal path (scales)", svg::INTERNAL, Mark::Line),
            Entry::new("external path (R-Test)", svg::EXTERNAL, Mark::Line),
            Entry::new("ellipse fit, internal", svg::ELLIPSE_INT, Mark::Line),
            Entry::new("ellipse fit, external", svg::ELLIPSE_EXT, Mark::Line),
        ];
        let dec = svg::decimals_for(2.0 * extent);
        let chart_px = 720u32;
        let side_px = 330u32;
        let header_px = 16 + 30 + 22 * lines.len() as u32 + 6;
        // Label areas: 70 px left, 50 px below, 10 px margins; the plot area is square.
        svg::render((chart_px + side_px, chart_px - 20 + header_px), |root| {
            let body = svg::header(root, &title, &lines)?;
            let (left, right) = body.split_horizontally(chart_px);
            let mut chart = ChartBuilder::on(&left)
                .margin(10)
                .x_label_area_size(50)
                .y_label_area_size(70)
                .build_cartesian_2d(-extent..extent, -extent..extent)?;
            svg::mesh(
                &mut chart,
                &format!("{a} − {a}c / mm (deviation ×{})", short(m, 0)),
                &format!("{b} − {b}c / mm (deviation ×{})", short(m, 0)),
                dec,
                dec,
            )?;
            // Wide ellipse bands first, the thin measured paths on top of them.
            chart.draw_series(LineSeries::new(set, svg::SET.stroke_width(1)))?;
            if let Some(e) = e_int {
                chart.draw_series(LineSeries::new(e, svg::ELLIPSE_INT.stroke_width(5)))?;
            }
            if let Some(e) = e_ext {
                chart.draw_series(LineSeries::new(e, svg::ELLIPSE_EXT.stroke_width(5)))?;
            }
            chart.draw_series(LineSeries::new(int, svg::INTERNAL.stroke_width(1)))?;
            chart.draw_series(LineSeries::new(ext, svg::EXTERNAL.stroke_width(1)))?;
            svg::side_panel(&right, &legend, &notes)
        })
    }

    /// The out-of-plane deviation d_k over the phase φ (°, of at most `max_points` samples)
    /// and the fitted plane d_k = E_ka ä_a + E_kb ä_b + c_k, ä = −r ω² (cos φ, sin φ), over
    /// 0…360°.
    pub fn out_of_plane(&self, max_points: usize) -> OutOfPlane {
        let (a, b) = self.norm.plane.axes();
        let k = self.norm.plane.normal();
        let [sa, sb] = &self.norm.set_mm;
        let dk = &self.norm.dev_um[2];
        let phase_deg = |i: usize| sb[i].atan2(sa[i]).to_degrees().rem_euclid(360.0);
        let points = svg::decimate(self.norm.samples(), max_points)
            .map(|i| (phase_deg(i), dk[i]))
            .collect();
        let (e_ka, e_kb) = (Eij::new(k, a), Eij::new(k, b));
        let (eka, ekb) = (self.joint.eij[&e_ka].value, self.joint.eij[&e_kb].value);
        let c_k_um = self.joint.offsets_um[&k];
        let acc = self.accel_m_s2();
        let plane = (0..=360)
            .map(|d| {
                let f = (d as f64).to_radians();
                (d as f64, -acc * (eka * f.cos() + ekb * f.sin()) + c_k_um)
            })
            .collect();
        OutOfPlane {
            e_ka,
            e_kb,
            c_k_um,
            points,
            plane,
        }
    }

    /// Out-of-plane view: d_k over the phase φ with the fitted plane
    /// d_k = E_ka ä_a + E_kb ä_b + c_k, ä = −r ω² (cos φ, sin φ).
    pub fn out_of_plane_svg(&self, cond: &Conditions) -> Result<String, ReportError> {
        let (a, b) = self.norm.plane.axes();
        let k = self.norm.plane.normal();
        let OutOfPlane {
            points,
            plane,
            c_k_um: ck,
            ..
        } = self.out_of_plane(MAX_SCATTER_POINTS);
        let (eka, ekb) = (
            self.joint.eij[&Eij::new(k, a)].value,
            self.joint.eij[&Eij::new(k, b)].value,
        );
        let (lo, hi) = svg::padded_range(points.iter().chain(&plane).map(|p| p.1), 0.08);
        let title = format!(
            "Circle test {} {}: out-of-plane deviation d{} over the phase",
            self.norm.plane,
            self.direction(),
            k
        );
        let lines = vec![self.conditions_line(), cond.line("circle centre")];
        let legend = vec![
            Entry::new(
                format!("measured d{k} = {k}_ext − {k}_int"),
                svg::EXTERNAL,
                Mark::Dot,
            ),
            Entry::new("fitted plane (joint fit)", svg::FIT, Mark::Line),
        ];
        let se = |e: Eij| format!("{:.4}", self.joint.eij[&e].std_err);
        let notes = vec![
            format!("φ = atan2({b}_int − {b}c, {a}_int − {a}c)"),
            format!("ä{a} = −rω²·cos φ,  ä{b} = −rω²·sin φ"),
            format!(
                "fit: d{k} = {}·ä{a} + {}·ä{b} + c{k}",
                Eij::new(k, a),
                Eij::new(k, b)
            ),
            String::new(),
            format!(
                "{} = {eka:.4} ± {} µm·s²/m",
                Eij::new(k, a),
                se(Eij::new(k, a))
            ),
            format!(
                "{} = {ekb:.4} ± {} µm·s²/m",
                Eij::new(k, b),
                se(Eij::new(k, b))
            ),
            format!("c{k} = {} µm", short(ck, 3)),
        ];
        let header_px = 16 + 30 + 22 * lines.len() as u32 + 6;
        let dec = svg::decimals_for(hi - lo);
        svg::render((1050, 460 + header_px), |root| {
            let body = svg::header(root, &title, &lines)?;
            let (left, right) = body.split_horizontally(720);
            let mut chart = ChartBuilder::on(&left)
                .margin(10)
                .x_label_area_size(50)
                .y_label_area_size(70)
                .build_cartesian_2d(0.0..360.0, lo..hi)?;
            svg::mesh(&mut chart, "phase φ / °", &format!("d{k} / µm"), 0, dec)?;
            chart.draw_series(
                points
                    .iter()
                    .map(|p| Circle::new(*p, 2, svg::EXTERNAL.filled())),
            )?;
            chart.draw_series(LineSeries::new(plane, svg::FIT.stroke_width(2)))?;
            svg::side_panel(&right, &legend, &notes)
        })
    }
}

/// The out-of-plane deviation of a test ([`CircleView::out_of_plane`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OutOfPlane {
    /// E_ka: deviation along the plane normal k per acceleration of the plane's first axis.
    pub e_ka: Eij,
    /// E_kb: the same for the second axis.
    pub e_kb: Eij,
    /// The constant c_k, µm.
    pub c_k_um: f64,
    /// (phase φ / °, d_k / µm) of the measured samples.
    pub points: Vec<(f64, f64)>,
    /// (φ / °, d_k / µm) of the fitted plane.
    pub plane: Vec<(f64, f64)>,
}

/// The 1-2-5 magnification that draws `max_dev_mm` as at most `TARGET_FRACTION` (0.3) of r
/// (1 when there is no deviation to magnify).
pub(crate) fn magnification_for(max_dev_mm: f64, radius_mm: f64) -> f64 {
    if !(max_dev_mm.is_finite() && max_dev_mm > 1e-9 * radius_mm) {
        return 1.0;
    }
    svg::nice_floor(TARGET_FRACTION * radius_mm / max_dev_mm).max(1.0)
}

/// A round deviation (µm) that is drawn as roughly a tenth of the radius.
fn scale_bar_um(radius_mm: f64, m: f64) -> f64 {
    svg::nice_floor(0.1 * radius_mm * 1e3 / m)
}
