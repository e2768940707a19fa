//! Experiment design: which additional circle test would shrink the worst standard error most.
//!
//! Candidates form a grid over the workspace: every plane the machine has, both directions,
//! circle centres at 10 %, 50 % and 90 % of every stroke, and the lowest and the highest
//! acceleration measured (set radius: the median measured). For each candidate the Jacobian
//! rows of its six EIJ come from the same prediction stage as the fit's (harmonic steady state,
//! forward differences at the identified θ over all parameters, the ones kept at their start
//! value included), weighted by the σ such a test would have: σ·a is about constant for one
//! R-Test (the probe noise over the acceleration), so σ = median(σ·a of the measured values)/a.
//!
//! The information of the tests given plus the candidate, with the static terms eliminated as
//! the identification would eliminate them (a candidate at a new circle-centre position is a
//! group of one acceleration: its static geometry counts as part of its EIJ),
//! F = (P·J)ᵀ(P·J), gives cov(θ) = s²·F⁻¹ (s the fit's residual standard deviation) and the
//! relative standard errors σ_θi/θ_i = σ_pi/p_i. Candidates are ranked by the largest of these
//! (directions F does not see count with the eigenvalue floor 10⁻¹² of the largest, so a
//! candidate that makes a parameter identifiable ranks above one that does not).

use super::problem::Problem;
use super::statics::{Row, Statics};
use super::{IdentError, SolverKind};
use crate::axes::{Direction, Eij, Plane};
use crate::machine::Machine;
use crate::predict::{CircleTest, Prediction};
use nalgebra::{DMatrix, DVector};

/// How many ranked candidates are kept.
pub const KEEP: usize = 10;

/// Fractions of every stroke at which candidate circle centres lie.
pub(crate) const STROKE_FRACTIONS: [f64; 3] = [0.1, 0.5, 0.9];

/// One candidate test and what it would give.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Its conditions (circle centre always given).
    pub circle: CircleTest,
    /// The largest relative standard error σ_p/p over all parameters with it added.
    pub worst_rel_std_err: f64,
    /// The parameter that has it.
    pub worst_parameter: String,
    /// Relative standard error of every parameter with it added.
    pub rel_std_err: Vec<f64>,
}

/// The ranking.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// Parameter names.
    pub parameters: Vec<String>,
    /// Relative standard errors with the tests given (all parameters, the ones kept at their
    /// start value included).
    pub rel_std_err_now: Vec<f64>,
    /// The best [`KEEP`] candidates, best first.
    pub candidates: Vec<Candidate>,
    /// Candidates evaluated.
    pub evaluated: usize,
    /// Remarks (candidates left out, how new positions count).
    pub notes: Vec<super::Note>,
}

impl Design {
    /// The largest relative standard error now and its parameter.
    pub fn worst_now(&self) -> (f64, &str) {
        worst(&self.rel_std_err_now, &self.parameters)
    }
}

fn worst<'a>(rel: &[f64], names: &'a [String]) -> (f64, &'a str) {
    rel.iter()
        .zip(names)
        .max_by(|a, b| a.0.total_cmp(b.0))
        .map(|(r, n)| (*r, n.as_str()))
        .unwrap_or((0.0, ""))
}

/// Relative standard errors s·√(F⁻¹)_ii/θ_i from the information F (eigenvalues floored).
fn rel_std_err(f: &DMatrix<f64>, theta: &DVector<f64>, s: f64) -> Vec<f64> {
    let n = f.nrows();
    let eig = f.clone().symmetric_eigen();
    let largest = eig.eigenvalues.amax().max(f64::MIN_POSITIVE);
    let mut inv = DMatrix::zeros(n, n);
    for k in 0..n {
        let l = eig.eigenvalues[k].max(1e-12 * largest);
        let v = eig.eigenvectors.column(k);
        inv += v * v.transpose() / l;
    }
    (0..n)
        .map(|i| s * inv[(i, i)].max(0.0).sqrt() / theta[i].abs())
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The candidate grid for `problem`'s machine and measured accelerations.
fn grid(problem: &Problem) -> Vec<CircleTest> {
    let machine = problem.machine();
    let tests = problem.tests();
    let radius_mm = median(tests.iter().map(|t| t.circle.radius_mm).collect());
    let lo = tests
        .iter()
        .map(|t| t.circle.accel_m_s2)
        .fold(f64::INFINITY, f64::min);
    let hi = tests
        .iter()
        .map(|t| t.circle.accel_m_s2)
        .fold(0.0, f64::max);
    let accels: Vec<f64> = if hi > 1.05 * lo {
        vec![lo, hi]
    } else {
        vec![hi]
    };
    let mut poses: Vec<Vec<f64>> = vec![Vec::new()];
    for a in machine.axes() {
        let [s0, s1] = a.stroke_m;
        poses = poses
            .into_iter()
            .flat_map(|p| {
                STROKE_FRACTIONS.iter().map(move |f| {
                    let mut q = p.clone();
                    q.push(s0 + f * (s1 - s0));
                    q
                })
            })
            .collect();
    }
    poses.retain(|p| crate::machine::Pose::new(machine, p).is_ok());
    let mut out = Vec::new();
    for plane in Plane::ALL {
        let (a, b) = plane.axes();
        if machine.axis(a).is_none() || machine.axis(b).is_none() {
            continue;
        }
        for pose in &poses {
            for direction in Direction::ALL {
                for &accel in &accels {
                    out.push(CircleTest::new(plane, direction, radius_mm, accel).at(pose.clone()));
                }
            }
        }
    }
    out
}

/// Ranks the candidate tests at the identified θ, given the Jacobian of the weighted errors
/// of the tests measured (`e_jac`, m × n, before the static terms are eliminated) and the fit's
/// residual standard deviation `s`.
pub fn rank(
    problem: &Problem,
    theta: &DVector<f64>,
    e_jac: &DMatrix<f64>,
    s: f64,
) -> Result<Design, IdentError> {
    let names: Vec<String> = problem
        .parameters()
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let n = theta.len();
    let statics = problem.statics();
    let pj = statics.project_matrix(e_jac);
    let f_now = pj.transpose() * &pj;
    let rel_std_err_now = rel_std_err(&f_now, theta, s);
    let mut notes = Vec::new();
    let candidates = grid(problem);
    let mut sim = problem.settings().simulation.clone();
    sim.solver = SolverKind::Harmonic;
    sim.position_m = None;
    let h: Vec<f64> = theta
        .iter()
        .map(|t| problem.settings().fd_step * t.abs())
        .collect();
    let mut thetas = vec![theta.clone()];
    for i in 0..n {
        let mut t = theta.clone();
        t[i] += h[i];
        thetas.push(t);
    }
    let machines: Vec<Machine> = thetas
        .iter()
        .map(|t| problem.machine_at(t))
        .collect::<Result<_, _>>()?;
    let sims = Prediction::new(problem.machine(), candidates.clone(), sim)
        .and_then(|p| p.simulate_with(&machines, SolverKind::Harmonic));
    let sims = match sims {
        Ok(s) => s,
        Err(e) => {
            notes.push(super::Note::CandidatesNotSimulated(e));
            return Ok(Design {
                parameters: names,
                rel_std_err_now,
                candidates: Vec::new(),
                evaluated: 0,
                notes,
            });
        }
    };
    // σ·a of the measured values: the R-Test's noise over the acceleration.
    let rows = problem.rows();
    let sigma_a = median(
        rows.iter()
            .map(|r| r.sigma * problem.tests()[r.test].circle.accel_m_s2)
            .collect(),
    );
    let mut existing: Vec<(Plane, Vec<f64>, f64, Direction)> = problem
        .tests()
        .iter()
        .enumerate()
        .map(|(i, t)| {
            (
                t.circle.plane,
                problem.position_m(i).to_vec(),
                t.circle.accel_m_s2,
                t.circle.direction,
            )
        })
        .collect();
    let reversal: Vec<usize> = (0..statics.groups.len())
        .filter(|&g| statics.groups[g].reversal)
        .collect();
    let mode = problem.settings().static_terms;
    let m = rows.len();
    let mut ranked: Vec<Candidate> = Vec::new();
    for (c, circle) in candidates.iter().enumerate() {
        let eijs: Vec<Eij> = circle.plane.parameters().to_vec();
        let sigma = (sigma_a / circle.accel_m_s2).max(problem.settings().sigma_floor);
        let mut all_rows = rows.to_vec();
        for &eij in &eijs {
            all_rows.push(Row {
                test: existing.len(),
                eij,
                sigma,
                r_over_a: circle.radius_mm / circle.accel_m_s2,
                direction: circle.direction,
            });
        }
        existing.push((
            circle.plane,
            circle.position_m.clone().unwrap_or_default(),
            circle.accel_m_s2,
            circle.direction,
        ));
        let mut aug = Statics::assemble(&existing, &all_rows, mode, &reversal);
        if mode != super::StaticTerms::None {
            let mut clocks = problem.clock_of();
            clocks.push("candidate".into());
            let mut planes: Vec<Plane> = problem.tests().iter().map(|t| t.circle.plane).collect();
            planes.push(circle.plane);
            aug = aug.add_clocks(&clocks, &all_rows, &planes);
        }
        existing.pop();
        let jc = DMatrix::from_fn(eijs.len(), n, |r, i| {
            let e = eijs[r];
            let (base, plus) = (sims[0][c][&e], sims[1 + i][c][&e]);
            (plus - base) / h[i] / sigma
        });
        // A candidate that brings no static term (most: a new circle centre, one acceleration)
        // leaves A as it is with zero rows added, so the projection is P for the tests given
        // and the identity for its rows: its information adds to F without a new SVD.
        let a = aug.matrix();
        let unchanged = a.ncols() == statics.matrix().ncols()
            && a.rows(0, m) == *statics.matrix()
            && a.rows(m, eijs.len()).iter().all(|v| *v == 0.0);
        let f = if unchanged {
            &f_now + jc.transpose() * &jc
        } else {
            let j = DMatrix::from_fn(m + eijs.len(), n, |r, i| {
                if r < m {
                    e_jac[(r, i)]
                } else {
                    jc[(r - m, i)]
                }
            });
            let pj = aug.decomposed().project_matrix(&j);
            pj.transpose() * &pj
        };
        let rel = rel_std_err(&f, theta, s);
        let (w, name) = worst(&rel, &names);
        ranked.push(Candidate {
            circle: circle.clone(),
            worst_rel_std_err: w,
            worst_parameter: name.to_string(),
            rel_std_err: rel,
        });
    }
    ranked.sort_by(|a, b| a.worst_rel_std_err.total_cmp(&b.worst_rel_std_err));
    let evaluated = ranked.len();
    ranked.truncate(KEEP);
    notes.push(super::Note::NewPositionCountsOnce);
    Ok(Design {
        parameters: names,
        rel_std_err_now,
        candidates: ranked,
        evaluated,
        notes,
    })
}
