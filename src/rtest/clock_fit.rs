//! The clock-offset term of a pooled evaluation: one residual time offset δ between the
//! internal and the external time base, fitted jointly over several circle tests.
//!
//! Physics: δ is the offset to add to the internal-minus-external clock offset, so external
//! samples late by τ against the internal ones (the sample stamped t is the position at t − τ)
//! have δ = −τ, read x(t − τ) ≈ x − τ·v, and the deviation gains δ·v
//! (`tests/rtest_clock_sign.rs` measures the sign on series lagged by whole samples). On a
//! steady circle v_a = (ρ/r)·ä_b/ω and v_b = −(ρ/r)·ä_a/ω (ρ the path's radius, r the set
//! radius of the set accelerations), so in one test δ is indistinguishable from antisymmetric
//! in-plane cross-talk: the joint fit returns E_ab + (ρ/r)·δ/ω and E_ba − (ρ/r)·δ/ω (δ in s, E
//! in µm·s²/m: a factor 10⁶). The shift flips sign between cw and ccw and scales with
//! 1/ω ∝ 1/√a, while EIJ do not change; static geometry G (µm per mm of set position)
//! enters as −10³·G/ω², even in ω. Across tests of one plane at one position the per-test
//! cross-talk is therefore
//!
//! Ê_ij(ω) = E_ij − 10³·G_ij/ω² + 10⁶·δ·s_ij·(ρ/r)/ω,   s_ab = +1, s_ba = −1, else 0,
//!
//! and δ, shared by every test of the clock (all planes and positions), follows by weighted
//! least squares on the per-test estimates with their covariances. G is fitted for a group
//! only where its tests have two or more accelerations (otherwise it is part of E, as in a
//! single test). δ is separable where a group has more distinct signed ω than its E and G
//! need: both directions at one acceleration, or three or more distinct signed ω. One direction
//! at two accelerations is not enough: an antisymmetric static term (an R-Test frame rotated
//! against the axes) would pass as δ.

use std::collections::BTreeMap;

use nalgebra::{DMatrix, Matrix2};

use super::fit::joint_lstsq;
use super::lstsq::lstsq;
use super::normalise::Normalised;
use crate::axes::{Eij, EijMap, Plane};

/// Signed angular speeds closer than this ratio count as one.
const SAME_OMEGA_RATIO: f64 = 1.05;
/// Smallest residual standard deviation used as a weight, µm (noise-free data).
const MIN_SIGMA_UM: f64 = 1e-3;

/// One test of the fit: its normalisation and the key of its group (tests that share EIJ:
/// one plane at one position).
#[derive(Debug, Clone, Copy)]
pub(crate) struct OffsetTest<'a> {
    /// The normalised test (merged at the base offset).
    pub norm: &'a Normalised,
    /// Tests with equal keys share EIJ and static geometry (same plane, same position).
    pub group: &'a str,
}

/// The fitted clock offset.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct OffsetFit {
    /// Whether the tests separate δ from cross-talk (see the module docs); when false, δ is 0
    /// and `reason` says why.
    pub separable: bool,
    /// Why not separable, or which tests separate it.
    pub reason: String,
    /// δ, s: add it to the base offset.
    pub offset_s: f64,
    /// Its standard error, s (scaled by √(χ²/dof) where that exceeds 1).
    pub std_err_s: f64,
    /// χ² per degree of freedom of the fit on the per-test estimates (≫ 1: the tests disagree
    /// beyond their noise, e.g. EIJ that depend on the direction).
    pub chi2_per_dof: f64,
    /// Pooled EIJ per group (corrected for δ), µm·s²/m.
    pub eij: BTreeMap<String, EijMap>,
}

struct PerTest {
    plane: Plane,
    omega: f64,
    /// Mean internal radius over the set radius: the path's speed is ρω, its set acceleration
    /// rω², so the offset's shift of the per-test cross-talk carries ρ/r.
    speed_ratio: f64,
    group: usize,
    /// Ê per component (a, b, k) and accelerated axis (a, b).
    e: [[f64; 2]; 3],
    /// Cholesky factor L of each component's covariance (LLᵀ = s²·C).
    chol: [Matrix2<f64>; 3],
}

fn distinct(values: &[f64]) -> usize {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let mut count = 0;
    let mut last: Option<f64> = None;
    for x in v {
        let same =
            last.is_some_and(|l| l.signum() == x.signum() && x.abs() <= SAME_OMEGA_RATIO * l.abs());
        if !same {
            count += 1;
            last = Some(x);
        }
    }
    count
}

/// Per-test joint fit [ä_a, ä_b, 1] with the covariance of the two EIJ columns.
fn per_test(norm: &Normalised, group: usize) -> Option<PerTest> {
    let fit = joint_lstsq(norm)?;
    let c = fit.cov_unscaled.view((0, 0), (2, 2)).into_owned();
    let c = Matrix2::new(c[(0, 0)], c[(0, 1)], c[(1, 0)], c[(1, 1)]);
    let mut e = [[0.0; 2]; 3];
    let mut chol = [Matrix2::zeros(); 3];
    for comp in 0..3 {
        e[comp] = [fit.coef[(0, comp)], fit.coef[(1, comp)]];
        let s2 = fit.residual_variance(comp).max(MIN_SIGMA_UM * MIN_SIGMA_UM);
        chol[comp] = (c * s2).cholesky()?.l();
    }
    Some(PerTest {
        plane: norm.plane,
        omega: norm.omega_rad_s,
        speed_ratio: norm.measured_radius_mm / norm.radius_mm,
        group,
        e,
        chol,
    })
}

/// Fits the residual clock offset δ shared by `tests` (see the module docs). `None` when a
/// per-test or the joint least-squares problem has no unique solution.
pub(crate) fn fit_offset(tests: &[OffsetTest]) -> Option<OffsetFit> {
    let mut keys: Vec<&str> = tests.iter().map(|t| t.group).collect();
    keys.sort();
    keys.dedup();
    let per: Vec<PerTest> = tests
        .iter()
        .map(|t| per_test(t.norm, keys.binary_search(&t.group).unwrap_or(0)))
        .collect::<Option<_>>()?;
    // Per group: fit G? and does it separate δ?
    let mut with_g = vec![false; keys.len()];
    let mut separating = Vec::new();
    for (g, key) in keys.iter().enumerate() {
        let omegas: Vec<f64> = per
            .iter()
            .filter(|p| p.group == g)
            .map(|p| p.omega)
            .collect();
        let abs: Vec<f64> = omegas.iter().map(|w| w.abs()).collect();
        with_g[g] = distinct(&abs) >= 2;
        let needed = if with_g[g] { 3 } else { 2 };
        if distinct(&omegas) >= needed {
            separating.push(key.to_string());
        }
    }
    let not_separable = |reason: String| OffsetFit {
        separable: false,
        reason,
        offset_s: 0.0,
        std_err_s: f64::NAN,
        chi2_per_dof: f64::NAN,
        eij: BTreeMap::new(),
    };
    if separating.is_empty() {
        return Some(not_separable(
            "no plane holds both directions at one acceleration or three distinct signed \
             circle speeds, so a clock offset cannot be told from antisymmetric cross-talk"
                .into(),
        ));
    }
    // Columns: per group 6 E (+ 6 G), then δ (ms).
    let mut first_col = Vec::with_capacity(keys.len());
    let mut p = 0;
    for &g in &with_g {
        first_col.push(p);
        p += if g { 12 } else { 6 };
    }
    let delta_col = p;
    p += 1;
    let rows = per.len() * 6;
    let mut x = DMatrix::zeros(rows, p);
    let mut y = DMatrix::zeros(rows, 1);
    for (t, pt) in per.iter().enumerate() {
        for comp in 0..3 {
            // Unwhitened rows j = a, b of component `comp`.
            let mut raw = DMatrix::zeros(2, p);
            for j in 0..2 {
                let k = first_col[pt.group] + 2 * comp + j;
                raw[(j, k)] = 1.0;
                if with_g[pt.group] {
                    raw[(j, k + 6)] = -1e3 / (pt.omega * pt.omega);
                }
                let s = match (comp, j) {
                    (0, 1) => 1.0,
                    (1, 0) => -1.0,
                    _ => 0.0,
                };
                raw[(j, delta_col)] = 1e3 * s * pt.speed_ratio / pt.omega;
            }
            let l = pt.chol[comp];
            let l_inv = l.try_inverse()?;
            let obs = l_inv * nalgebra::Vector2::new(pt.e[comp][0], pt.e[comp][1]);
            for j in 0..2 {
                let row = 6 * t + 2 * comp + j;
                y[(row, 0)] = obs[j];
                for col in 0..p {
                    x[(row, col)] = l_inv[(j, 0)] * raw[(0, col)] + l_inv[(j, 1)] * raw[(1, col)];
                }
            }
        }
    }
    let fit = lstsq(x, y)?;
    let dof = rows - p;
    let chi2_per_dof = if dof > 0 {
        fit.rss[0] / dof as f64
    } else {
        f64::NAN
    };
    let scale = if chi2_per_dof.is_finite() {
        chi2_per_dof.max(1.0).sqrt()
    } else {
        1.0
    };
    let mut eij = BTreeMap::new();
    for (g, key) in keys.iter().enumerate() {
        let plane = per.iter().find(|pt| pt.group == g).map(|pt| pt.plane)?;
        let (a, b) = plane.axes();
        let mut m = BTreeMap::new();
        for (comp, dev) in [a, b, plane.normal()].into_iter().enumerate() {
            for (j, acc) in [a, b].into_iter().enumerate() {
                m.insert(
                    Eij::new(dev, acc),
                    fit.coef[(first_col[g] + 2 * comp + j, 0)],
                );
            }
        }
        eij.insert(key.to_string(), m);
    }
    Some(OffsetFit {
        separable: true,
        reason: format!("separated by {}", separating.join(", ")),
        offset_s: fit.coef[(delta_col, 0)] * 1e-3,
        std_err_s: scale * fit.cov_unscaled[(delta_col, delta_col)].sqrt() * 1e-3,
        chi2_per_dof,
        eij,
    })
}
