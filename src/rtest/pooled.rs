//! Pooled evaluation of several circle tests of one plane (several accelerations, cw and ccw):
//! separates the acceleration correlated EIJ from static geometric deviations.

use std::collections::BTreeMap;

use nalgebra::DMatrix;

use super::error::{Location, RtestError};
use super::lstsq::{lstsq, Lstsq};
use super::normalise::{normalise, Normalised};
use super::{CircleSeries, EvalOptions, Warning};
use crate::axes::{Axis, Direction, Eij, EijEstimates, EijMap, Plane};

/// Accelerations closer than this ratio count as one.
const SAME_ACCEL_RATIO: f64 = 1.05;

/// The pooled result over several circle tests of one plane.
#[derive(Debug, Clone, PartialEq)]
pub struct PooledResult {
    /// The common plane.
    pub plane: Plane,
    /// The tests, in input order.
    pub sources: Vec<String>,
    /// Their set accelerations r ω², m/s².
    pub accel_m_s2: Vec<f64>,
    /// Their directions.
    pub directions: Vec<Direction>,
    /// The six EIJ of the plane with their standard errors, µm·s²/m.
    pub eij: EijEstimates,
    /// Static geometric terms G_ij with their standard errors, µm per mm of set position of
    /// axis j, keyed like EIJ (deviation i, in-plane axis j).
    pub geometric_um_per_mm: EijEstimates,
    /// Constant deviations per test and axis, µm.
    pub offsets_um: Vec<BTreeMap<Axis, f64>>,
    /// Residual RMS over all tests and the three components, µm.
    pub rms_residual_um: f64,
    /// (E_cw − E_ccw) / √(se_cw² + se_ccw²) per parameter, when each direction holds tests at
    /// two or more accelerations; empty otherwise.
    pub cw_ccw_difference_sigma: EijMap,
    /// Inconsistencies worth a look (cw/ccw beyond 3 combined standard errors, ...).
    pub warnings: Vec<Warning>,
}

/// Pooled fit over several circle tests of one plane, per axis i = a, b, k:
///
/// d_i = E_ia ä_a + E_ib ä_b + G_ia a_set + G_ib b_set + c_{i,test}
///
/// The G terms are static (geometric: radial and elliptic deviations that do not scale with
/// acceleration). On a steady circle ä = −ω² x_set, so in a single test G and E are collinear;
/// they separate only because the tests have different accelerations. Offsets are per test.
/// Every test is normalised as in [`super::evaluate`] with the same `opts`.
///
/// Errors when fewer than two tests are given, planes differ, or all accelerations agree
/// within 5 %.
pub fn evaluate_pooled(
    series: &[&CircleSeries],
    opts: &EvalOptions,
) -> Result<PooledResult, RtestError> {
    let all = || Location::source(&names(series));
    if series.len() < 2 {
        return Err(RtestError::Pooling {
            at: all(),
            detail: "a pooled evaluation needs at least two tests".into(),
        });
    }
    let norms = series
        .iter()
        .map(|s| normalise(s, opts))
        .collect::<Result<Vec<_>, _>>()?;
    let plane = norms[0].plane;
    for (s, n) in series.iter().zip(&norms) {
        if n.plane != plane {
            return Err(RtestError::Pooling {
                at: Location::source(s.source()),
                detail: format!(
                    "plane {} differs from plane {plane} of {}",
                    n.plane,
                    series[0].source()
                ),
            });
        }
    }
    let refs: Vec<&Normalised> = norms.iter().collect();
    if !separable(&refs) {
        return Err(RtestError::Pooling {
            at: all(),
            detail: format!(
                "all tests have the same acceleration ({:.3} m/s²): static geometry and EIJ \
                 are not separable; add tests at other accelerations",
                norms[0].accel_m_s2()
            ),
        });
    }
    let fit = fit_pool(&refs).ok_or_else(|| RtestError::Singular {
        at: all(),
        detail: "the pooled fit has no unique solution".into(),
    })?;
    let (eij, geometric) = unpack(plane, &fit);
    let (a, b) = plane.axes();
    let comps = [a, b, plane.normal()];
    let offsets_um = (0..norms.len())
        .map(|t| {
            comps
                .iter()
                .enumerate()
                .map(|(c, &ax)| (ax, fit.coef[(4 + t, c)]))
                .collect()
        })
        .collect();
    let n_total = refs.iter().map(|n| n.samples()).sum::<usize>();
    let rms_residual_um = (fit.rss.iter().sum::<f64>() / (3 * n_total) as f64).sqrt();

    let directions: Vec<Direction> = norms
        .iter()
        .map(|n| Direction::of_omega(n.omega_rad_s))
        .collect();
    let mut warnings = Vec::new();
    let mut cw_ccw = BTreeMap::new();
    let subset = |d: Direction| -> Vec<&Normalised> {
        refs.iter()
            .zip(&directions)
            .filter(|(_, &dir)| dir == d)
            .map(|(n, _)| *n)
            .collect()
    };
    let (cw, ccw) = (subset(Direction::Cw), subset(Direction::Ccw));
    if !cw.is_empty() && !ccw.is_empty() {
        let per_dir = |set: &[&Normalised]| -> Option<EijEstimates> {
            if set.len() < 2 || !separable(set) {
                return None;
            }
            Some(unpack(plane, &fit_pool(set)?).0)
        };
        match (per_dir(&cw), per_dir(&ccw)) {
            (Some(e_cw), Some(e_ccw)) => {
                for p in plane.parameters() {
                    let (c, cc) = (e_cw[&p], e_ccw[&p]);
                    let z = (c.value - cc.value) / c.std_err.hypot(cc.std_err);
                    if z.abs() > 3.0 {
                        warnings.push(Warning::CwCcwDiffer {
                            eij: p,
                            cw: c.value,
                            ccw: cc.value,
                            z,
                        });
                    }
                    cw_ccw.insert(p, z);
                }
            }
            _ => warnings.push(Warning::CwCcwNotChecked),
        }
    }
    Ok(PooledResult {
        plane,
        sources: series.iter().map(|s| s.source().to_string()).collect(),
        accel_m_s2: norms.iter().map(Normalised::accel_m_s2).collect(),
        directions,
        eij,
        geometric_um_per_mm: geometric,
        offsets_um,
        rms_residual_um,
        cw_ccw_difference_sigma: cw_ccw,
        warnings,
    })
}

fn names(series: &[&CircleSeries]) -> String {
    series
        .iter()
        .map(|s| s.source())
        .collect::<Vec<_>>()
        .join(", ")
}

fn separable(set: &[&Normalised]) -> bool {
    let (lo, hi) = set
        .iter()
        .map(|n| n.accel_m_s2())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
            (lo.min(a), hi.max(a))
        });
    hi > SAME_ACCEL_RATIO * lo
}

/// Design [ä_a, ä_b, a_set, b_set, one offset column per test] against [d_a, d_b, d_k].
fn fit_pool(set: &[&Normalised]) -> Option<Lstsq> {
    let n_total: usize = set.iter().map(|n| n.samples()).sum();
    let p = 4 + set.len();
    let mut x = DMatrix::zeros(n_total, p);
    let mut y = DMatrix::zeros(n_total, 3);
    let mut row = 0;
    for (t, n) in set.iter().enumerate() {
        for i in 0..n.samples() {
            x[(row, 0)] = n.acc_m_s2[0][i];
            x[(row, 1)] = n.acc_m_s2[1][i];
            x[(row, 2)] = n.set_mm[0][i];
            x[(row, 3)] = n.set_mm[1][i];
            x[(row, 4 + t)] = 1.0;
            for c in 0..3 {
                y[(row, c)] = n.dev_um[c][i];
            }
            row += 1;
        }
    }
    lstsq(x, y)
}

/// The EIJ and the geometric terms of a pooled fit, with their standard errors.
fn unpack(plane: Plane, fit: &Lstsq) -> (EijEstimates, EijEstimates) {
    let (mut eij, mut geometric) = (EijEstimates::new(), EijEstimates::new());
    let (a, b) = plane.axes();
    for (col, dev) in [a, b, plane.normal()].into_iter().enumerate() {
        for (j, ax) in [a, b].into_iter().enumerate() {
            let key = Eij::new(dev, ax);
            eij.insert(key, fit.coef[(j, col)], fit.std_err(j, col));
            geometric.insert(key, fit.coef[(2 + j, col)], fit.std_err(2 + j, col));
        }
    }
    (eij, geometric)
}

/// Name of a geometric term, e.g. `GXZ`: deviation in X per mm of set position of Z.
pub fn geometric_name(key: Eij) -> String {
    format!("G{}{}", key.deviation.letter(), key.accelerated.letter())
}

impl PooledResult {
    /// JSON object: `plane`, `files`, `accel_m_s2`, `directions`, `eij_um_s2_per_m`,
    /// `std_err_um_s2_per_m`, `geometric_um_per_mm`, `geometric_std_err_um_per_mm`,
    /// `rms_residual_um`, `cw_ccw_difference_sigma`, `warnings`.
    pub fn to_json(&self) -> serde_json::Value {
        let g = |m: &EijMap| -> serde_json::Value {
            serde_json::Value::Object(
                m.iter()
                    .map(|(k, v)| (geometric_name(*k), serde_json::json!(v)))
                    .collect(),
            )
        };
        serde_json::json!({
            "plane": self.plane.name(),
            "files": self.sources,
            "accel_m_s2": self.accel_m_s2,
            "directions": self.directions.iter().map(|d| d.name()).collect::<Vec<_>>(),
            "eij_um_s2_per_m": super::eij_json(&self.eij.value_map()),
            "std_err_um_s2_per_m": super::eij_json(&self.eij.std_err_map()),
            "geometric_um_per_mm": g(&self.geometric_um_per_mm.value_map()),
            "geometric_std_err_um_per_mm": g(&self.geometric_um_per_mm.std_err_map()),
            "rms_residual_um": self.rms_residual_um,
            "cw_ccw_difference_sigma": super::eij_json(&self.cw_ccw_difference_sigma),
            "warnings": self.warnings,
        })
    }
}
