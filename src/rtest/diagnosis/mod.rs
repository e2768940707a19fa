//! Circle diagnosis by source: each circle test's deviation broken down into the named errors a
//! ballbar user knows (centre offset, scale mismatch, squareness, servo mismatch, backlash,
//! reversal spikes, lateral play, straightness, cyclic error, out-of-plane terms), for three
//! sources:
//!
//! * `internal`: the axes' own readings (what the control and the drives did);
//! * `structure`: external − internal (what the structure did between scale and TCP,
//!   paper section 2.2);
//! * `tcp`: the external reading, the TCP as a ballbar would see it.
//!
//! A ballbar sees only the last; the split says whether an error comes from the axes or from
//! the structure. Every term is a column of one linear least-squares fit per source
//! ([`decompose`]), with its value, unit, standard error, axis or phase, and its contribution
//! to the ISO 230-4 circular deviation G. The formulas are in docs/diagnosis.md.
//!
//! Nominal angle: θ(t) = θ₀ + ωt, a straight line fitted to the unwrapped phase of the internal
//! readings over the steady revolutions (eq. 5). A path point p deviates by e = p − r·u(θ),
//! u = (cos θ, sin θ); the structure by d = external − internal. Their projections on u(θ)
//! and t(θ) = (−sin θ, cos θ) are the radial and tangential deviations: linear in the
//! readings, so that tcp = internal + structure holds term by term.
//!
//! What one test cannot tell, several can ([`separate`]): the 45° ellipse of one test is
//! squareness plus servo mismatch (a cw/ccw pair separates them), and a term that grows with
//! the acceleration over tests at several accelerations is EIJ (structure) or a dynamic
//! control error, not geometry.
//!
//! ```
//! use eij::rtest::diagnosis::{diagnose_series, DiagnosisOptions, Source};
//! use eij::rtest::{CircleSeries, EvalOptions};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
//! let series = CircleSeries::read_csv(root.join("measurements/demo-vmc/pos-a/xy_ccw_8.csv"))?;
//! let opts = EvalOptions { radius_mm: Some(2.0), ..Default::default() };
//! let d = diagnose_series(&series, &opts, &DiagnosisOptions::default())?;
//! let structure = d.source(Source::Structure);
//! for t in structure.terms.iter().take(3) {
//!     println!("{} = {:.3} ± {:.3} {} ({:.2} µm of G)", t.name, t.value, t.std_err, t.unit, t.contribution_um);
//! }
//! # Ok(())
//! # }
//! ```

use serde::Serialize;

use super::error::{Location, RtestError};
use super::lstsq::lstsq;
use super::normalise::{normalise, unwrapped_phase, Normalised};
use super::{CircleSeries, EvalOptions};
use crate::axes::{Axis, Direction, Plane};

pub(crate) mod basis;
pub(crate) mod decompose;
mod fit;
mod note;
pub(crate) mod separate;
pub(crate) mod terms;
pub mod tolerance;

pub use note::Note;
pub use separate::{separate, GroupSeparation};

/// Options of the diagnosis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiagnosisOptions {
    /// Pitch of the cyclic error (ball screw lead, scale period), mm; `None` fits no cyclic
    /// terms. Cyclic error is told apart from the other terms only when the pitch is well
    /// below the circle's diameter.
    pub cyclic_pitch_mm: Option<f64>,
    /// Harmonics of the pitch fitted as cyclic error (1 = the pitch itself).
    pub cyclic_harmonics: usize,
    /// Decay time of a reversal spike, ms (default 10 ms, about 1/Kv of a stiff axis).
    pub spike_decay_ms: f64,
}

impl Default for DiagnosisOptions {
    fn default() -> Self {
        DiagnosisOptions {
            cyclic_pitch_mm: None,
            cyclic_harmonics: 2,
            spike_decay_ms: 10.0,
        }
    }
}

/// Where a deviation was seen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Source {
    /// The axes' own readings.
    Internal,
    /// External − internal.
    Structure,
    /// The external reading (TCP).
    Tcp,
}

impl serde::Serialize for Source {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl Source {
    /// The three sources in report order.
    pub const ALL: [Source; 3] = [Source::Internal, Source::Structure, Source::Tcp];

    /// JSON name: `internal`, `structure`, `tcp`.
    pub fn name(self) -> &'static str {
        match self {
            Source::Internal => "internal",
            Source::Structure => "structure",
            Source::Tcp => "tcp",
        }
    }
}

/// Which figure a term's contribution refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Figure {
    /// The ISO 230-4 circular deviation G of the term alone.
    CircularDeviation,
    /// The peak-to-valley of the term's out-of-plane deviation.
    OutOfPlane,
}

/// The value of a term at one reversal point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrossingValue {
    /// The reversal point: the axis and its extreme, e.g. `x+`.
    pub side: String,
    /// Its nominal angle θ, degrees.
    pub at_deg: f64,
    /// Value, in the term's unit.
    pub value: f64,
    /// Standard error.
    pub std_err: f64,
}

/// One named term of a source's decomposition.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Term {
    /// docs/commands.md name (`scale_mismatch`, `backlash_x`, …).
    pub name: String,
    /// Value in `unit`.
    pub value: f64,
    /// `um`, `um_per_m` or `ms`.
    pub unit: &'static str,
    /// Standard error of the value.
    pub std_err: f64,
    /// The machine axis the term belongs to, if one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis: Option<Axis>,
    /// Phase of a harmonic term (cyclic error: of the pitch; tilt: azimuth of the steepest
    /// rise; saddle: of 2θ), degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase_deg: Option<f64>,
    /// The term alone: ISO 230-4 G of its in-plane deviation, or the peak-to-valley of its
    /// out-of-plane deviation, µm (see `figure`).
    pub contribution_um: f64,
    /// What `contribution_um` measures.
    pub figure: Figure,
    /// Per reversal point (backlash, reversal spikes).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub crossings: Vec<CrossingValue>,
    /// What the value may also be, and what tests at other accelerations or directions said.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<Note>,
    /// The tolerance on |value|, where `[tolerances]` gives one ([`tolerance::judge`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit: Option<f64>,
    /// `pass` or `fail` against `limit`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<&'static str>,
}

/// A term stands out of its noise beyond this many standard errors…
pub const STANDS_OUT_SE: f64 = 3.0;
/// …and changes G (or the out-of-plane range) by at least this, µm.
pub const STANDS_OUT_UM: f64 = 0.01;

impl Term {
    /// Whether the term is worth showing: it has a limit, or it stands out of its noise
    /// (|value| > [`STANDS_OUT_SE`] standard errors) and changes its figure by at least
    /// [`STANDS_OUT_UM`].
    pub fn stands_out(&self) -> bool {
        self.limit.is_some()
            || (self.value.abs() > STANDS_OUT_SE * self.std_err
                && self.contribution_um >= STANDS_OUT_UM)
    }
}

/// The decomposition of one source of one test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceDiagnosis {
    /// The source.
    #[serde(skip)]
    pub source: Source,
    /// The terms, in-plane ones ranked by their contribution to G, then the out-of-plane ones
    /// by theirs.
    pub terms: Vec<Term>,
    /// RMS of the radial residual after all terms, µm.
    pub residual_um: f64,
    /// RMS of the tangential residual, µm.
    pub residual_tangential_um: f64,
    /// RMS of the out-of-plane residual, µm.
    pub residual_normal_um: f64,
    /// ISO 230-4 G of the residual alone, µm.
    pub residual_contribution_um: f64,
    /// ISO 230-4 G of the source's path (nominal circle plus the source's deviation), µm; of
    /// `internal` and `tcp` the G eij reports for the internal and external path.
    pub circular_deviation_um: f64,
    /// G of the nominal circle plus the sum of all terms, µm.
    pub circular_deviation_terms_um: f64,
    /// Terms left out (a design without a unique solution) and the like.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<Note>,
    /// The deviations behind the figures, for plots.
    #[serde(skip)]
    pub curves: Curves,
}

impl SourceDiagnosis {
    /// The term called `name`.
    pub fn term(&self, name: &str) -> Option<&Term> {
        self.terms.iter().find(|t| t.name == name)
    }

    /// Mutable access to the term called `name`.
    pub(crate) fn term_mut(&mut self, name: &str) -> Option<&mut Term> {
        self.terms.iter_mut().find(|t| t.name == name)
    }
}

/// The measured and modelled deviations of one source over the steady revolutions.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Curves {
    /// Nominal angle θ, rad.
    pub theta: Vec<f64>,
    /// Radial deviation, µm.
    pub radial_um: Vec<f64>,
    /// Radial deviation of the sum of the terms, µm.
    pub radial_model_um: Vec<f64>,
}

/// The diagnosis of one circle test.
#[derive(Debug, Clone, PartialEq)]
pub struct CircleDiagnosis {
    /// File or series name.
    pub name: String,
    /// Circle plane.
    pub plane: Plane,
    /// Sense of rotation.
    pub direction: Direction,
    /// Set radius, mm.
    pub radius_mm: f64,
    /// Signed angular speed ω of the nominal angle, rad/s.
    pub omega_rad_s: f64,
    /// Set acceleration r ω², m/s².
    pub accel_m_s2: f64,
    /// Path feed r |ω|, mm/min.
    pub feed_mm_min: f64,
    /// Circle centre in machine coordinates, mm, when known: tests are separated by
    /// [`separate`] only with tests at the same centre.
    pub position_mm: Option<[f64; 3]>,
    /// The three sources, in [`Source::ALL`] order.
    pub sources: Vec<SourceDiagnosis>,
}

impl CircleDiagnosis {
    /// The decomposition of `source`.
    pub fn source(&self, source: Source) -> &SourceDiagnosis {
        &self.sources[source as usize]
    }

    /// docs/commands.md `"diagnosis"` object: `{"internal": {...}, "structure": {...}, "tcp": {...}}`.
    pub fn to_json(&self) -> serde_json::Value {
        let map = self
            .sources
            .iter()
            .map(|s| {
                let v = serde_json::to_value(s).unwrap_or(serde_json::Value::Null);
                (s.source.name().to_string(), v)
            })
            .collect();
        serde_json::Value::Object(map)
    }
}

/// Normalises `series` (as [`super::evaluate`] does) and diagnoses it.
pub fn diagnose_series(
    series: &CircleSeries,
    eval: &EvalOptions,
    opts: &DiagnosisOptions,
) -> Result<CircleDiagnosis, RtestError> {
    let norm = normalise(series, eval)?;
    diagnose(series, &norm, opts)
}

/// Diagnoses the steady revolutions of a normalised test, each source on its own.
pub fn diagnose(
    series: &CircleSeries,
    norm: &Normalised,
    opts: &DiagnosisOptions,
) -> Result<CircleDiagnosis, RtestError> {
    let singular = |detail: String| RtestError::Singular {
        at: Location::source(series.source()),
        detail,
    };
    if let Some(p) = opts.cyclic_pitch_mm {
        if !(p.is_finite() && p > 0.0) {
            return Err(singular(format!(
                "cyclic error pitch {p} mm: expected a positive number"
            )));
        }
    }
    let (a, b) = norm.plane.axes();
    let k = norm.plane.normal();
    let w = norm.first..norm.end;
    let t = &series.t_s()[w.clone()];
    let int = [a, b, k].map(|ax| &series.int_mm(ax)[w.clone()]);
    let ext = [a, b, k].map(|ax| &series.ext_mm(ax)[w.clone()]);
    let (theta, theta_mid_rad, omega) = nominal_angle(t, int[0], int[1])
        .ok_or_else(|| singular("cannot fit the nominal angle over time".into()))?;
    let r = norm.radius_mm;
    let circle = basis::Circle {
        radius_mm: r,
        omega_rad_s: omega,
        spike_decay_s: opts.spike_decay_ms * 1e-3,
        cyclic_pitch_mm: opts.cyclic_pitch_mm,
        theta_mid_rad,
    };
    // The deviation of a path from the nominal point r·u(θ) (`nominal`: true) or from the
    // internal path (external − internal), projected on u(θ) and t(θ): linear in the path.
    let deviation = |p: [&[f64]; 3], from: Option<[&[f64]; 3]>| -> fit::Deviation {
        let n = theta.len();
        let mut dev = fit::Deviation::with_capacity(n);
        for i in 0..n {
            let (s, c) = theta[i].sin_cos();
            let base = match from {
                Some(q) => [q[0][i], q[1][i], q[2][i]],
                None => [r * c, r * s, 0.0],
            };
            let d = [0, 1, 2].map(|j| (p[j][i] - base[j]) * 1e3);
            dev.radial_um.push(c * d[0] + s * d[1]);
            dev.tangential_um.push(-s * d[0] + c * d[1]);
            dev.normal_um.push(d[2]);
        }
        dev
    };
    let data = [
        deviation(int, None),
        deviation(ext, Some(int)),
        deviation(ext, None),
    ];
    let mut sources = Vec::with_capacity(3);
    for (source, dev) in Source::ALL.into_iter().zip(&data) {
        let d =
            fit::fit_source(source, norm.plane, &circle, &theta, dev, opts).ok_or_else(|| {
                singular(format!(
                    "the {} diagnosis has no unique solution",
                    source.name()
                ))
            })?;
        sources.push(d);
    }
    Ok(CircleDiagnosis {
        name: series.source().to_string(),
        plane: norm.plane,
        direction: Direction::of_omega(omega),
        radius_mm: r,
        omega_rad_s: omega,
        accel_m_s2: r * 1e-3 * omega * omega,
        feed_mm_min: r * omega.abs() * 60.0,
        position_mm: None,
        sources,
    })
}

/// θ(t) = θ_mid + ω (t − t̄): a straight line through the unwrapped phase of the internal
/// path about the circle centre; returns θ at every sample, θ_mid and ω.
fn nominal_angle(t: &[f64], a: &[f64], b: &[f64]) -> Option<(Vec<f64>, f64, f64)> {
    let phase = unwrapped_phase(a, b, [0.0, 0.0]);
    let n = t.len();
    let t_mean = t.iter().sum::<f64>() / n as f64;
    let x = nalgebra::DMatrix::from_fn(n, 2, |i, j| if j == 0 { 1.0 } else { t[i] - t_mean });
    let y = nalgebra::DMatrix::from_column_slice(n, 1, &phase);
    let fit = lstsq(x, y)?;
    let (theta0, omega) = (fit.coef[(0, 0)], fit.coef[(1, 0)]);
    let theta = t.iter().map(|ti| theta0 + omega * (ti - t_mean)).collect();
    Some((theta, theta0, omega))
}
