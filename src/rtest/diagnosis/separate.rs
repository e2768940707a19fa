//! What several tests tell that one cannot: per plane and circle centre, every term's values
//! over the tests fitted as
//!
//! v_i = g + κ·a_i                      (every term)
//! q_i = α + 10³·ω_i·Δτ + κ·a_i          (the 45° ellipse, `squareness`, µm/m)
//!
//! by weighted least squares (weights 1/se_i²; the standard errors scaled by the Birge ratio
//! √(χ²/dof) where the tests scatter more than their own errors say). a_i = r ω_i² is the
//! test's set acceleration, ω_i its signed angular speed (rad/s), Δτ the servo mismatch (ms):
//! the lag of axis a minus that of axis b, which turns the 45° ellipse one way in ccw and the
//! other in cw (ω flips sign), while squareness α does not.
//!
//! κ is fitted only where the tests hold at least two accelerations (ratio ≥ 1.2) and more
//! tests than unknowns, and kept only where it is significant (|κ| > 3 se): a term that grows
//! with the acceleration is EIJ (structure) or a dynamic control error (internal), not
//! geometry. Δτ is fitted only where both directions are present.

use serde::Serialize;

use super::terms::MS;
use super::{CircleDiagnosis, Figure, Note, Source, Term};
use crate::axes::Plane;
use crate::rtest::lstsq::lstsq;

/// Accelerations closer than this ratio count as one.
const DISTINCT_ACCEL_RATIO: f64 = 1.2;
/// A slope counts as significant beyond this many standard errors.
const SIGNIFICANT: f64 = 3.0;

/// One term over the tests of a group.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TermSeparation {
    /// Term name.
    pub name: String,
    /// Unit of the value.
    pub unit: &'static str,
    /// The part that does not change with acceleration or direction (g, α).
    pub geometric: f64,
    /// Its standard error.
    pub geometric_std_err: f64,
    /// κ, unit per m/s², where fitted and significant.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub per_m_s2: Option<f64>,
    /// Its standard error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub per_m_s2_std_err: Option<f64>,
    /// Servo mismatch Δτ, ms (squareness, both directions present).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub servo_mismatch_ms: Option<f64>,
    /// Its standard error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub servo_mismatch_std_err_ms: Option<f64>,
    /// √(χ²/dof) of the fit over the tests (1 where the tests agree within their errors;
    /// `null` without degrees of freedom).
    pub birge_ratio: Option<f64>,
}

/// The separation of one group (one plane at one circle centre).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupSeparation {
    /// Plane.
    pub plane: Plane,
    /// Circle centre, mm, where known.
    pub position_mm: Option<[f64; 3]>,
    /// The tests (names).
    pub tests: Vec<String>,
    /// Their set accelerations, m/s².
    pub accelerations_m_s2: Vec<f64>,
    /// Per source (`internal`, `structure`, `tcp`), every term.
    pub sources: std::collections::BTreeMap<&'static str, Vec<TermSeparation>>,
    /// What the group could not separate.
    pub notes: Vec<Note>,
}

/// Groups `tests` by plane and circle centre, separates each group and writes the result into
/// the tests' terms (squareness split from servo mismatch, notes on acceleration-dependent
/// terms). Groups of one test are left as they are and not returned.
pub fn separate(tests: &mut [CircleDiagnosis]) -> Vec<GroupSeparation> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in 0..tests.len() {
        let same = |j: &usize| {
            tests[*j].plane == tests[i].plane
                && match (tests[*j].position_mm, tests[i].position_mm) {
                    (None, None) => true,
                    (Some(p), Some(q)) => p.iter().zip(&q).all(|(x, y)| (x - y).abs() < 1e-6),
                    _ => false,
                }
        };
        match groups.iter_mut().find(|g| same(&g[0])) {
            Some(g) => g.push(i),
            None => groups.push(vec![i]),
        }
    }
    groups
        .into_iter()
        .filter(|g| g.len() > 1)
        .map(|g| separate_group(tests, &g))
        .collect()
}

/// The regressors of one group: per test (set acceleration, 10³·ω).
struct Conditions {
    accel: Vec<f64>,
    omega_k: Vec<f64>,
    several_accels: bool,
    both_directions: bool,
}

fn separate_group(tests: &mut [CircleDiagnosis], idx: &[usize]) -> GroupSeparation {
    let cond = {
        let accel: Vec<f64> = idx.iter().map(|&i| tests[i].accel_m_s2).collect();
        let omega_k: Vec<f64> = idx.iter().map(|&i| 1e3 * tests[i].omega_rad_s).collect();
        let (lo, hi) = accel
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), &a| (l.min(a), h.max(a)));
        Conditions {
            several_accels: hi >= DISTINCT_ACCEL_RATIO * lo,
            both_directions: omega_k.iter().any(|&w| w > 0.0) && omega_k.iter().any(|&w| w < 0.0),
            accel,
            omega_k,
        }
    };
    let mut notes = Vec::new();
    if !cond.several_accels {
        notes.push(Note::OneAcceleration);
    }
    if !cond.both_directions {
        notes.push(Note::OneDirection);
    }
    let mut sources = std::collections::BTreeMap::new();
    for source in Source::ALL {
        let s = source as usize;
        let names: Vec<String> = tests[idx[0]].sources[s]
            .terms
            .iter()
            .map(|t| t.name.clone())
            .filter(|n| idx.iter().all(|&i| tests[i].sources[s].term(n).is_some()))
            .collect();
        let mut seps = Vec::new();
        for name in names {
            let values: Vec<(f64, f64)> = idx
                .iter()
                .map(|&i| {
                    let t = tests[i].sources[s].term(&name).expect("filtered above");
                    (t.value, t.std_err)
                })
                .collect();
            let Some(sep) = fit_term(&name, &values, &cond, tests[idx[0]].sources[s].term(&name))
            else {
                continue;
            };
            for (k, &i) in idx.iter().enumerate() {
                write_back(&mut tests[i], source, &sep, &cond, k);
            }
            seps.push(sep);
        }
        sources.insert(source.name(), seps);
    }
    GroupSeparation {
        plane: tests[idx[0]].plane,
        position_mm: tests[idx[0]].position_mm,
        tests: idx.iter().map(|&i| tests[i].name.clone()).collect(),
        accelerations_m_s2: cond.accel,
        sources,
        notes,
    }
}

/// Weighted least squares of one term over the group; the slope column is dropped again when
/// not significant.
fn fit_term(
    name: &str,
    values: &[(f64, f64)],
    cond: &Conditions,
    first: Option<&Term>,
) -> Option<TermSeparation> {
    let unit = first?.unit;
    let n = values.len();
    let servo = name == "squareness" && cond.both_directions;
    let solve = |with_accel: bool| {
        let mut cols: Vec<&[f64]> = Vec::new();
        if servo {
            cols.push(&cond.omega_k);
        }
        if with_accel {
            cols.push(&cond.accel);
        }
        let p = cols.len() + 1;
        if n < p {
            return None;
        }
        let w: Vec<f64> = values.iter().map(|(_, se)| 1.0 / se.max(1e-9)).collect();
        let x = nalgebra::DMatrix::from_fn(n, p, |i, j| {
            w[i] * if j == 0 { 1.0 } else { cols[j - 1][i] }
        });
        let y = nalgebra::DMatrix::from_fn(n, 1, |i, _| w[i] * values[i].0);
        if n == p {
            // Exactly determined: the covariance is (XᵀWX)⁻¹ itself.
            let xtx = x.transpose() * &x;
            let cov = xtx.clone().try_inverse()?;
            let coef = xtx.lu().solve(&(x.transpose() * y))?;
            return Some((
                coef.column(0).iter().copied().collect::<Vec<_>>(),
                cov,
                None,
            ));
        }
        let fit = lstsq(x, y)?;
        let chi2_dof = fit.residual_variance(0);
        let cov = &fit.cov_unscaled * chi2_dof.max(1.0);
        let coef = fit.coef.column(0).iter().copied().collect::<Vec<_>>();
        Some((coef, cov, Some(chi2_dof.sqrt())))
    };
    let try_accel = cond.several_accels && n > 2 + usize::from(servo);
    let (coef, cov, birge, with_accel) = match try_accel.then(|| solve(true)).flatten() {
        Some((c, v, b))
            if c[c.len() - 1].abs() > SIGNIFICANT * v[(c.len() - 1, c.len() - 1)].sqrt() =>
        {
            (c, v, b, true)
        }
        _ => {
            let (c, v, b) = solve(false)?;
            (c, v, b, false)
        }
    };
    let se = |i: usize| cov[(i, i)].max(0.0).sqrt();
    let last = coef.len() - 1;
    Some(TermSeparation {
        name: name.to_string(),
        unit,
        geometric: coef[0],
        geometric_std_err: se(0),
        per_m_s2: with_accel.then(|| coef[last]),
        per_m_s2_std_err: with_accel.then(|| se(last)),
        servo_mismatch_ms: servo.then(|| coef[1]),
        servo_mismatch_std_err_ms: servo.then(|| se(1)),
        birge_ratio: birge,
    })
}

/// Writes the group's result into test `k` of the group.
fn write_back(
    test: &mut CircleDiagnosis,
    source: Source,
    sep: &TermSeparation,
    cond: &Conditions,
    k: usize,
) {
    let r_m = test.radius_mm * 1e-3;
    let accel = cond.accel[k];
    let sd = &mut test.sources[source as usize];
    let Some(term) = sd.term_mut(&sep.name) else {
        return;
    };
    let slope_note = || {
        sep.per_m_s2.map(|per_m_s2| Note::GrowsWithAcceleration {
            per_m_s2,
            per_m_s2_std_err: sep.per_m_s2_std_err.unwrap_or(f64::NAN),
            unit: sep.unit,
            accelerations_m_s2: cond.accel.clone(),
            source,
            geometric: sep.geometric,
            geometric_std_err: sep.geometric_std_err,
        })
    };
    if let (Some(dtau), Some(dtau_se)) = (sep.servo_mismatch_ms, sep.servo_mismatch_std_err_ms) {
        let apparent = term.value;
        let servo_part = cond.omega_k[k] * dtau;
        let accel_part = sep.per_m_s2.map_or(0.0, |kappa| kappa * accel);
        term.value = sep.geometric + accel_part;
        term.std_err = sep.geometric_std_err;
        term.contribution_um = term.value.abs() * r_m;
        term.notes = vec![Note::DirectionIndependent {
            apparent,
            servo_part,
        }];
        term.notes.extend(slope_note());
        let servo = Term {
            name: "servo_mismatch".into(),
            value: dtau,
            unit: MS,
            std_err: dtau_se,
            axis: None,
            phase_deg: None,
            contribution_um: servo_part.abs() * r_m,
            figure: Figure::CircularDeviation,
            crossings: Vec::new(),
            notes: vec![Note::ServoLag {
                first: test.plane.axes().0,
                second: test.plane.axes().1,
                feed_mm_min: test.feed_mm_min,
            }],
            limit: None,
            verdict: None,
        };
        let sd = &mut test.sources[source as usize];
        sd.terms.push(servo);
        rerank(&mut sd.terms);
        return;
    }
    term.notes.extend(slope_note());
    if !cond.several_accels && source == Source::Structure && eij_shaped(&sep.name) {
        term.notes.push(Note::CouldBeEij);
    }
}

/// Terms an acceleration-proportional deviation d = E·ä produces on a circle: the first
/// harmonics in the plane and the tilt out of it.
fn eij_shaped(name: &str) -> bool {
    matches!(
        name,
        "radius_deviation" | "rotation" | "scale_mismatch" | "squareness" | "out_of_plane_tilt"
    )
}

/// In-plane terms by their contribution to G, then out-of-plane ones by theirs.
fn rerank(terms: &mut [Term]) {
    terms.sort_by(|x, y| {
        let plane = |t: &Term| t.figure == Figure::OutOfPlane;
        plane(x)
            .cmp(&plane(y))
            .then(y.contribution_um.total_cmp(&x.contribution_um))
    });
}
