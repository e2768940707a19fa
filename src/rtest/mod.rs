//! R-Test circle-test evaluation (paper section 2.3): normalise, fit EIJ. The series come from
//! files ([`crate::measured`]) or from the simulator ([`crate::sim`]).
//!
//! ```text
//! CSV / simulator ─► CircleSeries ─► normalise (eq. 5–6) ─► joint fit (primary)
//!                                                       ├─► plane fit   (paper, cross-talk)
//!                                                       └─► ellipse fit (paper, in-talk)
//! several series of one plane ─► pooled (separates static geometry from EIJ)
//! ```
//!
//! ```no_run
//! use eij::rtest::{evaluate, evaluate_pooled, CircleSeries, EvalOptions};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let opts = EvalOptions { radius_mm: Some(2.0), ..Default::default() };
//! let slow = CircleSeries::read_csv("measurements/zx_ccw_2.csv")?;
//! let fast = CircleSeries::read_csv("measurements/zx_ccw_10.csv")?;
//! let result = evaluate(&fast, &opts)?;
//! println!("{} {} {:?}", result.plane, result.direction, result.eij);
//! let pooled = evaluate_pooled(&[&slow, &fast], &opts)?;
//! println!("{:?} {:?}", pooled.eij, pooled.geometric_um_per_mm);
//! # Ok(())
//! # }
//! ```
//!
//! What counts as steady: the local angular speed (half a revolution of phase over the time it
//! takes) within 0.5 % of the plateau speed; of the longest such run only whole revolutions are
//! kept, centred. The half-revolution window makes elliptic internal paths (axes with a few per
//! cent different gain or lag), timestamp jitter and gaps harmless. With slow ramps this band
//! includes the last ~5 % of each ramp's duration, where the acceleration is up to 1 % below
//! the plateau's.

use std::collections::BTreeMap;

use serde_json::{json, Value};

use crate::axes::{Axis, Direction, Eij, EijEstimates, EijMap, Plane};

pub mod checks;
pub(crate) mod clock;
pub(crate) mod clock_fit;
pub mod diagnosis;
pub(crate) mod error;
pub(crate) mod fit;
pub mod harmonic;
pub mod iso230;
pub(crate) mod lstsq;
pub mod moves;
pub mod normalise;
pub mod pooled;
pub(crate) mod series;
pub(crate) mod warning;

pub use error::{Line, Location, RtestError};
pub use pooled::{evaluate_pooled, PooledResult};
pub use series::CircleSeries;
pub use warning::{Named, Warning};

/// Options of [`evaluate`]; `None` means "infer from the data".
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EvalOptions {
    /// The circle plane; inferred as the two axes with the largest internal amplitude.
    pub plane: Option<Plane>,
    /// The set radius, mm; the mean internal radius is used when absent. When given, the mean
    /// internal radius must lie within 10 % of it. Give it when known: the set accelerations
    /// scale with r, and the mean internal radius differs from the set radius by the axes'
    /// radius errors (e.g. +0.5 µm on 2 mm biases every EIJ by 2.5·10⁻⁴ relative).
    pub radius_mm: Option<f64>,
}

/// The evaluation of one circle test.
#[derive(Debug, Clone, PartialEq)]
pub struct CircleResult {
    /// File path or in-memory name.
    pub source: String,
    /// Circle plane.
    pub plane: Plane,
    /// Sense of rotation (sign of ω from the unwrapped phase).
    pub direction: Direction,
    /// Radius used for the set points, mm.
    pub radius_mm: f64,
    /// Mean internal radius over the steady revolutions, mm.
    pub measured_radius_mm: f64,
    /// Set acceleration magnitude r ω², m/s².
    pub accel_m_s2: f64,
    /// |ω| / 2π, Hz.
    pub freq_hz: f64,
    /// The six EIJ of the plane from the joint fit with their standard errors, µm·s²/m
    /// (primary result).
    pub eij: EijEstimates,
    /// Constant deviations per axis, µm.
    pub offsets_um: BTreeMap<Axis, f64>,
    /// Residual RMS of the joint fit over its three components, µm.
    pub rms_residual_um: f64,
    /// Steady whole revolutions used.
    pub revolutions: usize,
    /// Samples used.
    pub samples_used: usize,
    /// Cross-talk E_ka, E_kb by the paper's plane fit ([`fit::plane_route`]), µm·s²/m.
    pub plane_fit: EijEstimates,
    /// In-talk by the paper's ellipse fit; `None` (with a warning) when a path is no ellipse.
    pub ellipse_fit: Option<fit::EllipseRoute>,
    /// ISO 230-4 circular and radial deviations of the internal and the external path over the
    /// steady revolutions (`None` where no circle can be fitted to a path).
    pub iso230: Option<iso230::CircleFigures>,
    /// The steady whole revolutions as sample indices of the series.
    pub steady: std::ops::Range<usize>,
    /// Disagreements between the routes beyond noise (see [`evaluate`]); a suite of measured
    /// tests adds what their conditions say ([`crate::measured::suite`]).
    pub warnings: Vec<Warning>,
}

/// The fast path for repeated use (e.g. inside identification): normalisation and the joint
/// fit only, without the paper's routes and their comparison (about a third less time).
pub fn evaluate_joint(
    series: &CircleSeries,
    opts: &EvalOptions,
) -> Result<(normalise::Normalised, fit::JointFit), RtestError> {
    let norm = normalise::normalise(series, opts)?;
    let joint = fit::joint(&norm).ok_or_else(|| RtestError::Singular {
        at: Location::source(series.source()),
        detail: "the joint EIJ fit has no unique solution".into(),
    })?;
    Ok((norm, joint))
}

/// Differences between evaluation routes below this are not reported: 1e-3 µm·s²/m is 5 nm at
/// 5 m/s², three orders below the R-Test's U(k=2) = 2.8 µm. Noise-free simulated series reach
/// it through the small transient left in their steady revolutions, not through noise.
pub const RESOLUTION_UM_S2_PER_M: f64 = 1e-3;

/// Evaluates one circle test: normalisation (eq. 5–6), joint fit (section 2.2), the paper's
/// plane and ellipse routes, and their comparison.
///
/// A route is flagged in `warnings` when it differs by more than three combined standard
/// errors, taking the joint fit's standard error `se` as the noise scale of both (combined:
/// √2·se), plus [`RESOLUTION_UM_S2_PER_M`] below which no R-Test resolves a difference. The
/// plane fit is compared with the joint fit. The
/// ellipse route is first order only (see [`fit::EllipseRoute`]), so it is compared with the
/// same route applied to the joint fit's noise-free model ([`fit::predict_ellipse_route`]):
/// the route's own truncation then cancels and what remains is noise or a model misfit.
pub fn evaluate(series: &CircleSeries, opts: &EvalOptions) -> Result<CircleResult, RtestError> {
    let (norm, joint) = evaluate_joint(series, opts)?;
    let plane_fit = fit::plane_route(&norm).ok_or_else(|| RtestError::Singular {
        at: Location::source(series.source()),
        detail: "the plane fit has no unique solution".into(),
    })?;
    let (a, b) = norm.plane.axes();
    let window = |v: &[f64]| -> Vec<f64> { v[norm.first..norm.end].to_vec() };
    let (ia, ib) = (window(series.int_mm(a)), window(series.int_mm(b)));
    let (ea, eb) = (window(series.ext_mm(a)), window(series.ext_mm(b)));
    let ellipse = fit::ellipse_route(&norm, [&ia, &ib], [&ea, &eb]).and_then(|mut route| {
        route.predicted_from_joint = fit::predict_ellipse_route(&norm, [&ia, &ib], &joint.eij)?;
        Some(route)
    });

    let tolerance =
        |p: &Eij| 3.0 * std::f64::consts::SQRT_2 * joint.eij[p].std_err + RESOLUTION_UM_S2_PER_M;
    let mut warnings = Vec::new();
    for (p, route) in &plane_fit {
        if (route.value - joint.eij[p].value).abs() > tolerance(p) {
            warnings.push(Warning::PlaneFitDiffers {
                eij: *p,
                plane_fit: route.value,
                joint: joint.eij[p],
            });
        }
    }
    match &ellipse {
        None => warnings.push(Warning::EllipseFitFailed),
        Some(route) => {
            for (p, v) in &route.eij {
                let expected = route.predicted_from_joint[p];
                if (v - expected).abs() > tolerance(p) {
                    warnings.push(Warning::EllipseFitDiffers {
                        eij: *p,
                        ellipse_fit: *v,
                        expected,
                        std_err: joint.eij[p].std_err,
                    });
                }
            }
        }
    }
    let iso = {
        let figures = |u: &[f64], v: &[f64]| iso230::path_figures(u, v, norm.radius_mm);
        match (figures(&ia, &ib), figures(&ea, &eb)) {
            (Some(internal), Some(external)) => Some(iso230::CircleFigures {
                nominal_radius_mm: norm.radius_mm,
                internal,
                external,
            }),
            _ => None,
        }
    };
    let direction = Direction::of_omega(norm.omega_rad_s);
    Ok(CircleResult {
        source: series.source().to_string(),
        plane: norm.plane,
        direction,
        radius_mm: norm.radius_mm,
        measured_radius_mm: norm.measured_radius_mm,
        accel_m_s2: norm.accel_m_s2(),
        freq_hz: norm.freq_hz(),
        eij: joint.eij,
        offsets_um: joint.offsets_um,
        rms_residual_um: joint.rms_residual_um,
        revolutions: norm.revolutions,
        samples_used: norm.samples(),
        plane_fit,
        ellipse_fit: ellipse,
        iso230: iso,
        steady: norm.first..norm.end,
        warnings,
    })
}

/// A parameter map as a JSON object keyed by the parameter names (`EZZ`, ...).
pub(crate) fn eij_json(map: &EijMap) -> Value {
    Value::Object(map.iter().map(|(k, v)| (k.name(), json!(v))).collect())
}
