//! The joint evaluation of a pure harmonic steady state in closed form.
//!
//! A simulated circle in steady state is a set of sinusoids: internal readings
//! a(θ) = Re(I_a e^{jθ}), b(θ) = Re(I_b e^{jθ}) (mm) and structural deviations
//! d_i(θ) = Re(D_i e^{jθ}) (µm) with θ = ωt. Sampled over whole revolutions and evaluated by
//! [`super::evaluate_joint`], every step of the evaluation is a sum of sinusoids over whole
//! periods, so it has a closed form in the phasors — this module computes it without sampling:
//!
//! * Centre: over whole revolutions a, b have mean zero and a² + b² holds only 0ω and 2ω, so
//!   the Kåsa fit's centre is the origin.
//! * Phase (eq. 5): with z = a + jb = P e^{jθ} + Q e^{−jθ}, P = (I_a + jI_b)/2,
//!   Q = (Ī_a + jĪ_b)/2 and q = Q/P (the internal path's ellipticity, |q| ≪ 1),
//!   e^{jφ} = z/|z| = e^{j arg P} e^{jθ} (1 + q e^{−2jθ})^{1/2} (1 + q̄ e^{2jθ})^{−1/2}: binomial
//!   series give its Fourier coefficients c₁, c₋₁ at e^{±jθ}, and ⟨e^{2jφ}⟩ = e^{2j arg P} q
//!   exactly.
//! * ω̂ (the least-squares slope of the unwrapped phase over the window's sample times):
//!   φ = θ + arg P + Σₘ (−1)^{m+1}/m · Im(qᵐ e^{−2jmθ}), and over N = R·S samples
//!   Σₖ (k − k̄) vᵏ = N/(v − 1) for vᴺ = 1, v ≠ 1: the ripple's share of the slope in closed
//!   form. It depends on where the window starts ([`Window::start_rad`]).
//! * Joint fit (section 2.2) on [ä_a, ä_b, 1] with ä = −r ω̂² (cos φ, sin φ): the offset column
//!   is orthogonal to the others (odd harmonics only), so
//!   [E_ia, E_ib] = (−r ω̂²)⁻¹ C⁻¹ [Re g_i, Im g_i] with the 2 × 2 moment matrix
//!   C = ⟨(cos φ, sin φ)(cos φ, sin φ)ᵀ⟩ from ⟨e^{2jφ}⟩ and g_i = ⟨e^{jφ} d_i⟩ = (D_i c₋₁ + D̄_i c₁)/2.
//!
//! The sums over S samples per revolution equal these means up to aliasing of harmonics of
//! order S, whose coefficients are of order |q|^{S/2}: nothing at double precision. The sampled
//! route ([`crate::sim::harmonic::steady_circle`] and [`super::evaluate_joint`]) stays, and
//! `tests/sim_harmonic.rs` checks that both agree to 1e-9.

use super::error::{Location, RtestError};
use crate::axes::{Eij, EijMap, Plane};
use faer::c64;
use std::collections::BTreeMap;
use std::f64::consts::TAU;

/// A pure harmonic steady state of one circle test, as phasors at ω (y = Re(Y e^{jωt})).
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyHarmonic {
    /// The circle plane (a, b, normal k).
    pub plane: Plane,
    /// Signed angular speed ω, rad/s (positive ccw).
    pub omega_rad_s: f64,
    /// Internal readings along a and b, mm.
    pub int_mm: [c64; 2],
    /// Structural deviation external − internal along a, b and k, µm.
    pub dev_um: [c64; 3],
}

/// Which samples the sampled evaluation would keep: `revolutions` whole revolutions of
/// `samples_per_revolution` samples, the first at set-point angle `start_rad` (θ = ωt).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// θ at the window's first sample, rad.
    pub start_rad: f64,
    /// Samples per revolution.
    pub samples_per_revolution: usize,
    /// Whole revolutions.
    pub revolutions: usize,
}

/// Ellipticity beyond which the internal path is no circle the evaluation can normalise
/// (half-axes in the ratio 3 : 1).
const MAX_ELLIPTICITY: f64 = 0.5;

/// Terms of the binomial series: |q|^{2a} below this relative to 1 ends them.
const SERIES_TOLERANCE: f64 = 1e-18;

/// binom(e, k) for k = 0, 1, … (e = ±1/2).
fn binomials(e: f64, count: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(count);
    let mut c = 1.0;
    for k in 0..count {
        out.push(c);
        c *= (e - k as f64) / (k as f64 + 1.0);
    }
    out
}

/// The six EIJ of the plane (µm·s²/m) that the joint evaluation gives for `steady` sampled
/// over `window` and normalised on the set radius `radius_mm` (see the module docs).
pub fn joint_eij(
    steady: &SteadyHarmonic,
    radius_mm: f64,
    window: &Window,
    source: &str,
) -> Result<EijMap, RtestError> {
    let whole = || Location::source(source);
    let [ia, ib] = steady.int_mm;
    if ia.norm() < 1e-3 || ib.norm() < 1e-3 {
        return Err(RtestError::NoMotion {
            at: whole(),
            detail: format!(
                "internal half-amplitudes {:.3e} and {:.3e} mm in plane {}",
                ia.norm(),
                ib.norm(),
                steady.plane
            ),
        });
    }
    let j = c64::new(0.0, 1.0);
    let p = (ia + j * ib) * 0.5;
    let q = (ia.conj() + j * ib.conj()) * 0.5 / p;
    let q2 = q.norm_sqr();
    if q2.sqrt() > MAX_ELLIPTICITY {
        return Err(RtestError::Singular {
            at: whole(),
            detail: format!(
                "the internal path is no circle (ellipticity {:.3})",
                q2.sqrt()
            ),
        });
    }
    let terms = ((SERIES_TOLERANCE.ln() / q2.max(1e-300).ln()).ceil() as usize).clamp(1, 64) + 1;
    let half = binomials(0.5, terms + 1);
    let minus_half = binomials(-0.5, terms);
    // Mean internal radius |P|·⟨|1 + q e^{−2jθ}|⟩ = |P|·Σ binom(1/2, a)² |q|^{2a}.
    let mut mean_radius = 0.0;
    let (mut c_plus, mut c_minus) = (0.0, 0.0);
    let mut power = 1.0;
    for a in 0..terms {
        mean_radius += half[a] * half[a] * power;
        c_plus += half[a] * minus_half[a] * power;
        c_minus += half[a + 1] * minus_half[a] * power;
        power *= q2;
    }
    let measured_mm = p.norm() * mean_radius;
    if (measured_mm - radius_mm).abs() > 0.1 * radius_mm {
        return Err(RtestError::RadiusMismatch {
            at: whole(),
            measured_mm,
            set_mm: radius_mm,
        });
    }
    let rot = p / p.norm();
    let (c1, cm1) = (rot * c_plus, rot * q * c_minus);
    let m2 = rot * rot * q;

    // ω̂: the slope of the phase over the window's sample times.
    let s = window.samples_per_revolution;
    let n = window.revolutions * s;
    let omega = steady.omega_rad_s;
    let h = TAU / (omega.abs() * s as f64);
    let step = omega * h;
    let mut ripple = 0.0;
    let mut qm = c64::new(1.0, 0.0);
    for m in 1..=2 * terms {
        qm *= q;
        if qm.norm() < SERIES_TOLERANCE {
            break;
        }
        let v = c64::cis(-2.0 * m as f64 * step);
        if (v - 1.0).norm() < 1e-12 {
            continue;
        }
        let sign = if m % 2 == 1 { 1.0 } else { -1.0 };
        let sum = qm * c64::cis(-2.0 * m as f64 * window.start_rad) * (n as f64) / (v - 1.0);
        ripple += sign / m as f64 * sum.im;
    }
    let nf = n as f64;
    let omega_hat = omega + 12.0 * ripple / (h * nf * (nf * nf - 1.0));

    let scale = -radius_mm * 1e-3 * omega_hat * omega_hat;
    let (cc, ss, cs) = (0.5 * (1.0 + m2.re), 0.5 * (1.0 - m2.re), 0.5 * m2.im);
    let det = cc * ss - cs * cs;
    if det.is_nan() || det <= 1e-12 {
        return Err(RtestError::Singular {
            at: whole(),
            detail: "the joint EIJ fit has no unique solution".into(),
        });
    }
    let (a, b) = steady.plane.axes();
    let mut eij = BTreeMap::new();
    for (dev, d) in [a, b, steady.plane.normal()].into_iter().zip(steady.dev_um) {
        let g = (d * cm1 + d.conj() * c1) * 0.5;
        let ea = (ss * g.re - cs * g.im) / det / scale;
        let eb = (cc * g.im - cs * g.re) / det / scale;
        eij.insert(Eij::new(dev, a), ea);
        eij.insert(Eij::new(dev, b), eb);
    }
    Ok(eij)
}
