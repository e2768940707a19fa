//! Identification: stiffness reduction factors (and the like) fitted so that the simulated
//! circle tests reproduce the measured EIJ.
//!
//! Parameters p are optimised as compliance factors θ = 1/p, within bounds
//! 1/p_max ≤ θ ≤ 1/p_min (positive by construction). Deviations at the TCP are sums of elastic
//! deflections, each proportional to a compliance, so EIJ are nearly linear in θ: Gauss–Newton
//! steps then travel straight along the weakly determined combinations (e.g. X against Y
//! guideway compliance, both tilted by the same accelerations) instead of crawling along the
//! curved valley that ln p makes of them. The residuals
//! are r = P·(E_sim(p) − E_meas)/σ over every (test, EIJ) pair, where E_sim comes from
//! simulating the very same circle test (plane, direction, radius, acceleration) on the model
//! and evaluating it with the very same evaluation ([`crate::predict`]), and P eliminates the
//! static (acceleration-independent) terms of the measurement, fitted jointly ([`statics`]).
//! The finite-difference Jacobian runs its columns and tests in parallel (rayon); results do
//! not depend on the number of threads. The uncertainty follows from cov(θ) ≈ s²·(JᵀJ)⁻¹,
//! s² = rᵀr/(m − n − q) ([`uncertainty`]).
//!
//! The order of [`identify`]: identifiability first ([`identifiability`]: parameters the tests
//! cannot determine, or cannot separate from others, are named and kept at their start
//! value), then the fit of the others, reversal terms where the data need them, the bound and
//! convergence verdict (relative to the factor: 0.010006 against the bound 0.01 is on it), the
//! uncertainty, plausibility, the time-domain confirmation, and the ranking of candidate
//! additional tests ([`design`]). A fit that ends on a bound or does not converge is returned
//! with [`IdentResult::refusal`] set: it must not be exported ([`IdentResult::accepted`]).
//!
//! The parts: [`parameters`] (what is fitted), [`problem`] (residuals, Jacobian, argmin
//! traits), [`statics`], [`identifiability`], [`lm`] (the Levenberg–Marquardt solver),
//! [`uncertainty`], [`design`], [`validation`], [`settings`] (every default), [`measured`]
//! (reading measured EIJ), [`config`] and [`report`] (files), and [`identify`], which runs them
//! in order; [`stiffness`] gives the identified stiffness set as a table.

mod builder;
pub mod config;
pub mod design;
pub mod diagnosis;
mod error;
pub mod identifiability;
pub mod lm;
pub mod measured;
pub mod parameters;
pub mod problem;
pub mod report;
pub mod settings;
mod solve;
pub mod statics;
pub mod stiffness;
pub mod uncertainty;
pub mod validation;

pub use crate::predict::{EijMap, SolverKind};
pub use builder::Identification;
pub use error::IdentError;
pub use identifiability::NotIdentifiable;
pub use parameters::{Parameter, ParameterKind};
pub use problem::{Problem, TestCase};
pub use settings::{MeasuredOptions, Method, Settings};
pub use statics::{StaticTerms, Statics};
pub use uncertainty::Uncertainty;

use crate::machine::Machine;
use nalgebra::{DMatrix, DVector};
use parameters::to_factor;
use problem::Reduced;
use settings::{AT_BOUND_REL, CHI2_SIGMAS, PLAUSIBLE_MAX, PLAUSIBLE_MIN};
use std::borrow::Cow;
use std::sync::{Arc, Mutex};

/// Called after every iteration with (iteration, cost = Σr²).
pub type ProgressFn = dyn Fn(u64, f64) + Send + Sync;

/// One identified parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Identified {
    /// Name.
    pub name: String,
    /// Start value.
    pub initial: f64,
    /// Identified value (the start value when not identifiable).
    pub value: f64,
    /// Standard error (delta method: p·σ_θ), `None` when not identifiable.
    pub std_err: Option<f64>,
    /// Whether the tests determine it.
    pub identifiable: bool,
    /// Whether it ended on a bound of the factors (within [`AT_BOUND_REL`] of it, relative).
    pub at_bound: bool,
}

/// One fitted static term (see [`statics`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StaticEstimate {
    /// Index of its group in [`Statics::groups`].
    pub group: usize,
    /// The EIJ it shifts; its name as a geometric term is `G` + the two letters.
    pub eij: crate::axes::Eij,
    /// A reversal term (sign flips with the direction).
    pub reversal: bool,
    /// A clock offset instead (index into [`Statics::clocks`]): external readings late by
    /// `value_um_per_mm` ms (± `std_err_um_per_mm`).
    pub clock: Option<usize>,
    /// Value, µm per mm of set position.
    pub value_um_per_mm: f64,
    /// Standard error, µm/mm.
    pub std_err_um_per_mm: f64,
}

/// The result of an identification.
#[derive(Debug, Clone)]
pub struct IdentResult {
    /// Parameters in the order given.
    pub parameters: Vec<Identified>,
    /// Parameters kept at their start value, and why.
    pub not_identifiable: Vec<NotIdentifiable>,
    /// Correlation matrix of the identifiable parameters (order of `parameters`, others 0).
    pub correlation: DMatrix<f64>,
    /// Singular values of the weighted Jacobian ∂r/∂θ (θ = 1/p) at the solution, descending.
    pub singular_values: Vec<f64>,
    /// Σr² at the start.
    pub cost_initial: f64,
    /// Σr² at the solution.
    pub cost_final: f64,
    /// Σr² at the start and after every iteration.
    pub cost_history: Vec<f64>,
    /// Residual standard deviation s = √(Σr²/(m − n − q)).
    pub residual_std: f64,
    /// Number of residuals m.
    pub residuals: usize,
    /// Iterations.
    pub iterations: u64,
    /// Parameter sets simulated (start, Jacobians, line searches, confirmation).
    pub evaluations: u64,
    /// Trial points that could not be simulated (unstable closed loop) and were rejected.
    pub rejected_steps: u64,
    /// Simulated EIJ per test at the start.
    pub simulated_initial: Vec<EijMap>,
    /// Simulated EIJ per test at the solution.
    pub simulated_final: Vec<EijMap>,
    /// The same by the time-domain simulation (confirmation of a harmonic optimisation).
    pub simulated_final_time: Option<Vec<EijMap>>,
    /// The static terms of the fit (groups and columns).
    pub statics: Statics,
    /// Their estimates, in the order of [`Statics::columns`].
    pub static_estimates: Vec<StaticEstimate>,
    /// Candidate additional tests ranked by how much they would shrink the worst standard
    /// error (when [`Settings::design`]).
    pub design: Option<design::Design>,
    /// Warnings (non-identifiable parameters, bounds, χ², plausibility).
    pub warnings: Vec<String>,
    /// Notes (static terms not separable, reversal terms added).
    pub notes: Vec<String>,
    /// Why the fit must not be exported: it did not converge or ended on a bound.
    pub refusal: Option<IdentError>,
    /// The identified machine.
    pub machine: Machine,
}

impl IdentResult {
    /// The result if it may be exported; else the reason ([`IdentError::NotConverged`],
    /// [`IdentError::AtBound`]).
    pub fn accepted(&self) -> Result<&IdentResult, IdentError> {
        match &self.refusal {
            Some(e) => Err(e.clone()),
            None => Ok(self),
        }
    }
}

/// Fits the free parameters from `start` (θ of all parameters): (θ, iterations, converged).
fn fit(
    problem: &Problem,
    free: &[usize],
    start: &DVector<f64>,
    costs: Arc<Mutex<Vec<f64>>>,
    progress: Option<Arc<ProgressFn>>,
) -> Result<(DVector<f64>, u64, bool), IdentError> {
    let x0 = DVector::from_iterator(free.len(), free.iter().map(|&i| start[i]));
    let cost0 = costs
        .lock()
        .ok()
        .and_then(|c| c.last().copied())
        .unwrap_or(1.0);
    let reduced = Reduced {
        problem,
        free: free.to_vec(),
        base: start.clone(),
    };
    let (x, iterations, converged) = solve::optimise(reduced, x0, cost0, costs, progress)?;
    let mut theta = start.clone();
    for (k, &i) in free.iter().enumerate() {
        theta[i] = x[k];
    }
    Ok((theta, iterations, converged))
}

/// The groups whose reversal terms lower χ² by more than [`CHI2_SIGMAS`] standard deviations
/// of a χ²_k (k terms) — scaled by s² where s > 1 — at θ.
fn reversal_needed(
    problem: &Problem,
    theta: &DVector<f64>,
    free: usize,
) -> Result<Vec<usize>, IdentError> {
    let statics = problem.statics();
    let candidates: Vec<usize> = (0..statics.groups.len())
        .filter(|&g| {
            let gr = &statics.groups[g];
            gr.shared && gr.reversal_possible && !gr.reversal
        })
        .collect();
    if candidates.is_empty() {
        return Ok(Vec::new());
    }
    let r = problem.residuals_at(theta)?;
    let s2 = (r.norm_squared() / problem.dof(free).max(1) as f64).max(1.0);
    Ok(candidates
        .into_iter()
        .filter(|&g| {
            let (gain, k) = statics.reversal_gain(g, problem.rows(), &r);
            let k = k as f64;
            k > 0.0 && gain / s2 > k + CHI2_SIGMAS * (2.0 * k).sqrt()
        })
        .collect())
}

/// Re-checks identifiability at the solution θ (the operating point matters: a compliance
/// weakly seen from the catalogue values may be determined at the solution, or the reverse)
/// with the Jacobian of the weighted errors `e_jac`, over all parameters. Returns true when the
/// set of free parameters stays; else updates `analysis` (with a note), resets the newly held
/// parameters in `theta` to their start values `theta0` and returns false: fit again. A set
/// seen before (the rounds would oscillate) is replaced by the parameters free in both of the
/// last two sets, fitted once more; `history` holds the sets tried, at most [`MAX_ROUNDS`].
fn rounds_left(
    analysis: &mut identifiability::Analysis,
    history: &mut Vec<Vec<usize>>,
    problem: &Problem,
    e_jac: &DMatrix<f64>,
    theta: &mut DVector<f64>,
    theta0: &DVector<f64>,
    names: &[String],
    notes: &mut Vec<String>,
) -> bool {
    if history.len() > MAX_ROUNDS || history.last() != Some(&analysis.free) {
        return true;
    }
    let mut again = identifiability::analyse(&problem.statics().project_matrix(e_jac), theta);
    if again.free == analysis.free {
        return true;
    }
    if history.contains(&again.free) || history.len() == MAX_ROUNDS {
        // Oscillating: keep what both agree on.
        let both: Vec<usize> = again
            .free
            .iter()
            .copied()
            .filter(|i| analysis.free.contains(i))
            .collect();
        let held: Vec<usize> = again
            .free
            .iter()
            .chain(&analysis.free)
            .copied()
            .filter(|i| !both.contains(i))
            .collect();
        for &i in &held {
            if !again.not_identifiable.iter().any(|n| n.index == i) {
                let kept = analysis.not_identifiable.iter().find(|n| n.index == i);
                again.not_identifiable.extend(kept.cloned());
            }
        }
        again.free = both;
        history.push(Vec::new());
    } else {
        history.push(again.free.clone());
    }
    if again.free.is_empty() {
        return true;
    }
    let list = |v: Vec<usize>| -> String {
        v.into_iter()
            .map(|i| names[i].clone())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let released: Vec<usize> = again
        .free
        .iter()
        .copied()
        .filter(|i| !analysis.free.contains(i))
        .collect();
    let held: Vec<usize> = analysis
        .free
        .iter()
        .copied()
        .filter(|i| !again.free.contains(i))
        .collect();
    for &i in &held {
        theta[i] = theta0[i];
    }
    notes.push(format!(
        "identifiability at the solution differs from that at the start values{}{}: fitted again",
        if released.is_empty() {
            String::new()
        } else {
            format!("; determined now: {}", list(released))
        },
        if held.is_empty() {
            String::new()
        } else {
            format!(
                "; not determined now (back to the start value): {}",
                list(held)
            )
        },
    ));
    *analysis = again;
    false
}

/// Rounds of fitting with a changed set of free parameters.
const MAX_ROUNDS: usize = 3;

/// Runs the identification (see the module docs for the order of its steps). Errors are
/// what prevents a fit at all (no data, no parameter the tests see, a start that cannot be
/// simulated); a fit that ends on a bound or does not converge is returned with
/// [`IdentResult::refusal`] set, its diagnosis complete.
pub fn identify(
    problem: &Problem,
    progress: Option<Arc<ProgressFn>>,
) -> Result<IdentResult, IdentError> {
    let s = problem.settings();
    let evaluations_before = problem.evaluations();
    let theta0 = problem.initial_theta();
    let (j0, r0) = problem.jacobian_at(&theta0)?;
    let m = r0.len();
    let names: Vec<String> = problem
        .parameters()
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let mut analysis = identifiability::analyse(&j0, &theta0);
    if analysis.free.is_empty() {
        let no_influence = analysis.not_identifiable.iter().all(|n| n.no_influence);
        let why: Vec<String> = analysis
            .not_identifiable
            .iter()
            .map(|ni| ni.describe(&names, to_factor(theta0[ni.index])))
            .collect();
        return Err(IdentError::NoData(if no_influence {
            "none of the parameters influences the measured EIJ: no overlap between parameters and tests".into()
        } else {
            format!(
                "the tests determine none of the parameters: {}",
                why.join("; ")
            )
        }));
    }
    // Enough values for every parameter the tests see (ties are the analysis's business)?
    let seen = analysis.free.len()
        + analysis
            .not_identifiable
            .iter()
            .filter(|n| !n.no_influence)
            .count();
    if problem.dof(seen) == 0 || problem.dof(analysis.free.len()) == 0 {
        let q = problem.statics().rank();
        return Err(IdentError::NoData(format!(
            "{m} measured values cannot determine {seen} parameters{}",
            if q > 0 {
                format!(" and {q} static terms")
            } else {
                String::new()
            }
        )));
    }
    let mut notes: Vec<String> = problem
        .statics()
        .groups
        .iter()
        .filter_map(|g| g.note.clone())
        .collect();
    // Cost history: the start, then after every iteration.
    let costs = Arc::new(Mutex::new(vec![r0.norm_squared()]));
    let mut current = Cow::Borrowed(problem);
    let mut theta = theta0.clone();
    let mut iterations = 0;
    let mut reversal_checked = s.static_terms != StaticTerms::Auto;
    let mut history = vec![analysis.free.clone()];
    // Fit; add reversal terms where the data need them; re-check identifiability at the
    // solution (a parameter hidden at the start may be determined once the others are fitted,
    // or the reverse) and fit again with the new set, a few rounds at most.
    let (converged, e_jac, e, edges) = loop {
        let free = analysis.free.clone();
        let (t, it, converged) = fit(&current, &free, &theta, costs.clone(), progress.clone())?;
        (theta, iterations) = (t, iterations + it);
        if converged && !reversal_checked {
            reversal_checked = true;
            let need = reversal_needed(&current, &theta, free.len())?;
            if !need.is_empty() {
                let with = current.with_statics(current.statics_with(&need));
                for &g in &need {
                    notes.push(format!(
                        "reversal terms (static, sign flipping with the direction) fitted at {}: the data need them",
                        with.statics().groups[g].label()
                    ));
                }
                current = Cow::Owned(with);
                continue;
            }
        }
        let (e_jac, e, edges) = current.error_jacobian_edges(&theta)?;
        let settled = !converged
            || rounds_left(
                &mut analysis,
                &mut history,
                &current,
                &e_jac,
                &mut theta,
                &theta0,
                &names,
                &mut notes,
            );
        if settled {
            break (converged, e_jac, e, edges);
        }
    };
    let free = analysis.free.clone();
    let mut warnings: Vec<String> = analysis
        .not_identifiable
        .iter()
        .map(|ni| ni.describe(&names, to_factor(theta0[ni.index])))
        .collect();
    let problem: &Problem = &current;
    let (lo, hi) = (s.min_factor, s.max_factor);
    let at_bound = |i: usize| {
        let p = to_factor(theta[i]);
        (p - lo).abs() <= AT_BOUND_REL * lo || (p - hi).abs() <= AT_BOUND_REL * hi
    };
    let refusal = if !converged {
        Some(IdentError::NotConverged { iterations })
    } else {
        free.iter().find(|&&i| at_bound(i)).map(|&i| {
            let p = to_factor(theta[i]);
            IdentError::AtBound {
                name: names[i].clone(),
                value: p,
                bound: if (p - lo).abs() < (p - hi).abs() {
                    lo
                } else {
                    hi
                },
                min: lo,
                max: hi,
            }
        })
    };
    let edges: Vec<usize> = edges.into_iter().filter(|i| free.contains(i)).collect();
    let refusal = refusal.or_else(|| {
        (!edges.is_empty()).then(|| {
            let at: Vec<String> = edges
                .iter()
                .map(|&i| format!("{} = {:.4}", names[i], to_factor(theta[i])))
                .collect();
            let step = problem.settings().fd_step;
            IdentError::AtSimulationLimit {
                names: at.join(", "),
                detail: format!("a change of {step} relative makes a simulation fail, e.g. an unstable closed loop"),
            }
        })
    });
    let j_all = problem.statics().project_matrix(&e_jac);
    let r = problem.statics().project(&e);
    let j = DMatrix::from_fn(m, free.len(), |row, c| j_all[(row, free[c])]);
    let cost_final = r.norm_squared();
    let free_names: Vec<&str> = free.iter().map(|&i| names[i].as_str()).collect();
    let free_theta: Vec<f64> = free.iter().map(|&i| theta[i]).collect();
    let dof = problem.dof(free.len());
    let u = Uncertainty::at(&j, cost_final, &free_theta, &free_names, dof)?;
    warnings.extend(u.warnings.iter().cloned());
    let e_free = DMatrix::from_fn(m, free.len(), |row, c| e_jac[(row, free[c])]);
    let static_estimates = problem
        .statics()
        .estimates(&e, &e_free, &u.covariance, u.residual_std.powi(2))
        .into_iter()
        .zip(&problem.statics().columns)
        .map(|((v, se), c)| StaticEstimate {
            group: c.group,
            eij: c.eij,
            reversal: c.reversal,
            clock: c.clock,
            value_um_per_mm: v,
            std_err_um_per_mm: se,
        })
        .collect();
    let n = theta0.len();
    let mut correlation = DMatrix::zeros(n, n);
    for (a, &i) in free.iter().enumerate() {
        for (b, &k) in free.iter().enumerate() {
            correlation[(i, k)] = u.correlation[(a, b)];
        }
    }
    let parameters: Vec<Identified> = problem
        .parameters()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let fi = free.iter().position(|&f| f == i);
            Identified {
                name: p.name.clone(),
                initial: to_factor(theta0[i]),
                value: to_factor(theta[i]),
                std_err: fi.map(|k| u.std_err[k]),
                identifiable: fi.is_some(),
                at_bound: fi.is_some() && at_bound(i),
            }
        })
        .collect();
    for q in parameters.iter().filter(|q| q.identifiable) {
        if q.at_bound {
            warnings.push(format!(
                "{} = {} ended on a bound of the factors [{lo}, {hi}]: the data want a value outside",
                q.name, q.value
            ));
        } else if q.value > PLAUSIBLE_MAX {
            warnings.push(format!(
                "{} = {:.4} > {PLAUSIBLE_MAX}: stiffer than its catalogue data, implausible for a reduction factor (a compliance missing elsewhere in the model, or a data problem)",
                q.name, q.value
            ));
        } else if q.value < PLAUSIBLE_MIN {
            warnings.push(format!(
                "{} = {:.4} < {PLAUSIBLE_MIN}: more than ten times softer than its catalogue data, implausible (a compliance missing elsewhere in the model, or a data problem)",
                q.name, q.value
            ));
        }
    }
    let mut sims = problem.simulate_many(&[theta0.clone(), theta.clone()])?;
    let simulated_final = sims.pop().unwrap_or_default();
    let simulated_initial = sims.pop().unwrap_or_default();
    let simulated_final_time = if s.simulation.solver == SolverKind::Harmonic && refusal.is_none() {
        let (time, warning) = solve::confirm_in_time_domain(problem, &theta, &simulated_final)?;
        warnings.extend(warning);
        Some(time)
    } else {
        None
    };
    let design = if s.design {
        Some(design::rank(problem, &theta, &e_jac, u.residual_std)?)
    } else {
        None
    };
    let rejected_steps = problem.unsimulable();
    if rejected_steps > 0 {
        notes.push(format!(
            "{rejected_steps} trial step(s) could not be simulated (e.g. an unstable closed loop) and were rejected"
        ));
    }
    let cost_history = costs.lock().map(|c| c.clone()).unwrap_or_default();
    Ok(IdentResult {
        parameters,
        not_identifiable: analysis.not_identifiable,
        correlation,
        singular_values: u.singular_values,
        cost_initial: r0.norm_squared(),
        cost_final,
        cost_history,
        residual_std: u.residual_std,
        residuals: m,
        iterations,
        evaluations: problem.evaluations() - evaluations_before,
        rejected_steps,
        simulated_initial,
        simulated_final,
        simulated_final_time,
        statics: problem.statics().clone(),
        static_estimates,
        design,
        warnings,
        notes,
        refusal,
        machine: problem.machine_at(&theta)?,
    })
}
