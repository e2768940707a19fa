//! Identification: stiffness reduction factors (and the like) fitted so that the simulated
//! circle tests reproduce the measured EIJ.
//!
//! Parameters p are optimised as compliance factors θ = 1/p, within bounds
//! 1/p_max ≤ θ ≤ 1/p_min (positive by construction). Deviations at the TCP are sums of elastic
//! deflections, each proportional to a compliance, so EIJ are nearly linear in θ: Gauss–Newton
//! steps then travel straight along the weakly determined combinations (e.g. X against Y
//! guideway compliance, both tilted by the same accelerations) instead of crawling along the
//! curved valley that ln p makes of them. The residuals
//! are r = (E_sim(p) − E_meas)/σ over every (test, EIJ) pair, where E_sim comes from simulating
//! the very same circle test (plane, direction, radius, acceleration) on the model and
//! evaluating it with the very same evaluation ([`crate::predict`]). The finite-difference
//! Jacobian runs its columns and tests in parallel (rayon); results do not depend on the number
//! of threads. The uncertainty follows from cov(θ) ≈ s²·(JᵀJ)⁻¹, s² = rᵀr/(m − n)
//! ([`uncertainty`]).
//!
//! The parts: [`parameters`] (what is fitted), [`problem`] (residuals, Jacobian, argmin
//! traits), [`lm`] (the Levenberg–Marquardt solver), [`uncertainty`], [`settings`] (every
//! default), [`measured`] (reading measured EIJ), [`config`] and [`report`] (files), and
//! [`identify`], which runs them in order; [`stiffness`] gives the identified stiffness set as a
//! table.

mod builder;
pub mod config;
mod error;
pub mod lm;
pub mod measured;
pub mod parameters;
pub mod problem;
pub mod report;
pub mod settings;
pub mod stiffness;
pub mod uncertainty;

pub use crate::predict::{EijMap, SolverKind};
pub use builder::Identification;
pub use error::IdentError;
pub use parameters::{Parameter, ParameterKind};
pub use problem::{Problem, TestCase};
pub use settings::{MeasuredOptions, Method, Settings};
pub use uncertainty::Uncertainty;

use crate::machine::Machine;
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{Executor, State, TerminationReason, KV};
use nalgebra::{DMatrix, DVector};
use parameters::to_factor;
use problem::Reduced;
use std::sync::{Arc, Mutex};

/// Called after every iteration with (iteration, cost = Σr²).
pub type ProgressFn = dyn Fn(u64, f64) + Send + Sync;

struct Progress {
    costs: Arc<Mutex<Vec<f64>>>,
    callback: Option<Arc<ProgressFn>>,
    half: bool,
}

impl<I: State<Float = f64>> Observe<I> for Progress {
    fn observe_iter(&mut self, state: &I, _kv: &KV) -> Result<(), argmin::core::Error> {
        let cost = if self.half {
            2.0 * state.get_cost()
        } else {
            state.get_cost()
        };
        if let Ok(mut c) = self.costs.lock() {
            c.push(cost);
        }
        if let Some(cb) = &self.callback {
            cb(state.get_iter(), cost);
        }
        Ok(())
    }
}

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
    /// Whether it ended on a bound of the factors (the data want a value outside).
    pub at_bound: bool,
}

/// The result of an identification.
#[derive(Debug, Clone)]
pub struct IdentResult {
    /// Parameters in the order given.
    pub parameters: Vec<Identified>,
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
    /// Residual standard deviation s = √(Σr²/(m − n)).
    pub residual_std: f64,
    /// Number of residuals m.
    pub residuals: usize,
    /// Iterations.
    pub iterations: u64,
    /// Parameter sets simulated (start, Jacobians, line searches, confirmation).
    pub evaluations: u64,
    /// Simulated EIJ per test at the start.
    pub simulated_initial: Vec<EijMap>,
    /// Simulated EIJ per test at the solution.
    pub simulated_final: Vec<EijMap>,
    /// The same by the time-domain simulation (confirmation of a harmonic optimisation).
    pub simulated_final_time: Option<Vec<EijMap>>,
    /// Warnings (non-identifiable parameters, near-singular combinations).
    pub warnings: Vec<String>,
    /// The identified machine.
    pub machine: Machine,
}

/// Best parameters, iterations and whether the solver converged (rather than ran out of
/// iterations), from a finished argmin state.
fn outcome<S: State<Param = DVector<f64>>>(
    st: &S,
) -> Result<(DVector<f64>, u64, bool), IdentError> {
    let converged = matches!(
        st.get_termination_reason(),
        Some(TerminationReason::SolverConverged)
    );
    let p = st
        .get_best_param()
        .cloned()
        .ok_or_else(|| IdentError::Optimiser("no result".into()))?;
    Ok((p, st.get_iter(), converged))
}

/// An error from argmin's executor: ours (e.g. a failed simulation inside the cost) unwrapped,
/// the optimiser's own kept as its message.
fn optimiser_error(e: argmin::core::Error) -> IdentError {
    match e.downcast::<IdentError>() {
        Ok(ours) => ours,
        Err(e) => IdentError::Optimiser(format!("{e:#}")),
    }
}

/// The parameters the tests see: those whose Jacobian column at the start is not (nearly)
/// zero; a warning for each of the others.
fn free_parameters(
    problem: &Problem,
    j0: &DMatrix<f64>,
    theta0: &DVector<f64>,
) -> (Vec<usize>, Vec<String>) {
    let n = theta0.len();
    let norms: Vec<f64> = (0..n).map(|i| j0.column(i).norm()).collect();
    let max_norm = norms.iter().cloned().fold(0.0, f64::max);
    let free: Vec<usize> = (0..n)
        .filter(|&i| norms[i] > settings::UNIDENTIFIABLE_COLUMN * max_norm && norms[i] > 1e-12)
        .collect();
    let warnings = (0..n)
        .filter(|i| !free.contains(i))
        .map(|i| {
            format!(
                "{} is not identifiable from the tests given (no influence on any measured EIJ); kept at {}",
                problem.parameters()[i].name,
                to_factor(theta0[i])
            )
        })
        .collect();
    (free, warnings)
}

/// Runs the chosen optimiser from `start` over the free parameters: (θ, iterations, converged).
fn optimise(
    reduced: Reduced<'_>,
    start: DVector<f64>,
    cost0: f64,
    costs: Arc<Mutex<Vec<f64>>>,
    progress: Option<Arc<ProgressFn>>,
) -> Result<(DVector<f64>, u64, bool), IdentError> {
    let s = reduced.problem.settings();
    let (lo, hi) = s.theta_bounds();
    let nf = start.len();
    match s.method {
        Method::Lm => {
            let solver = lm::LevenbergMarquardt::new(
                DVector::from_element(nf, lo),
                DVector::from_element(nf, hi),
                s.tol_cost,
                s.tol_step,
            );
            let observer = Progress {
                costs,
                callback: progress,
                half: true,
            };
            let res = Executor::new(reduced, solver)
                .configure(|st| st.param(start).max_iters(s.max_iters()))
                .add_observer(observer, ObserverMode::Always)
                .run()
                .map_err(optimiser_error)?;
            outcome(res.state())
        }
        Method::NelderMead => {
            let mut simplex = vec![start.clone()];
            for i in 0..nf {
                let mut v = start.clone();
                v[i] *= settings::NELDER_MEAD_SIMPLEX_SCALE;
                simplex.push(v);
            }
            let solver = argmin::solver::neldermead::NelderMead::new(simplex)
                .with_sd_tolerance((settings::NELDER_MEAD_REL_SPREAD * cost0).max(1e-12))
                .map_err(|e| IdentError::Optimiser(e.to_string()))?;
            let observer = Progress {
                costs,
                callback: progress,
                half: false,
            };
            let res = Executor::new(reduced, solver)
                .configure(|st| st.max_iters(s.max_iters()))
                .add_observer(observer, ObserverMode::Always)
                .run()
                .map_err(optimiser_error)?;
            let (p, iterations, converged) = outcome(res.state())?;
            Ok((p.map(|t| t.clamp(lo, hi)), iterations, converged))
        }
    }
}

/// The final model once more in the time domain (when optimised harmonically), with a warning
/// when harmonic and time-domain EIJ disagree.
fn confirm_in_time_domain(
    problem: &Problem,
    theta: &DVector<f64>,
    harmonic: &[EijMap],
) -> Result<(Vec<EijMap>, Option<String>), IdentError> {
    let time = problem
        .simulate_many_with(std::slice::from_ref(theta), SolverKind::Time)?
        .remove(0);
    let mut worst = (0.0, String::new());
    for (i, (h, t)) in harmonic.iter().zip(&time).enumerate() {
        for (e, v) in h {
            let d = (v - t[e]).abs();
            let allowed =
                (settings::CONFIRM_REL * t[e].abs()).max(settings::CONFIRM_ABS_UM_S2_PER_M);
            if d / allowed > worst.0 {
                worst = (
                    d / allowed,
                    format!(
                        "{} {e}: harmonic {v:.4}, time domain {:.4}",
                        problem.tests()[i].label(),
                        t[e]
                    ),
                );
            }
        }
    }
    let warning = (worst.0 > 1.0).then(|| {
        format!(
            "harmonic and time-domain EIJ disagree beyond 1 % / 0.01 µm·s²/m: {}",
            worst.1
        )
    });
    Ok((time, warning))
}

/// Runs the identification: parameters the tests do not see are set aside, the others fitted
/// (Levenberg–Marquardt or Nelder–Mead within the bounds), the result refused when the optimiser
/// did not converge or a parameter ended on a bound, its uncertainty computed, and a harmonic
/// optimisation confirmed in the time domain.
pub fn identify(
    problem: &Problem,
    progress: Option<Arc<ProgressFn>>,
) -> Result<IdentResult, IdentError> {
    let s = problem.settings();
    let evaluations_before = problem.evaluations();
    let theta0 = problem.initial_theta();
    let (j0, r0) = problem.jacobian_at(&theta0)?;
    let m = r0.len();
    let (free, mut warnings) = free_parameters(problem, &j0, &theta0);
    if free.is_empty() {
        return Err(IdentError::NoData(
            "none of the parameters influences the measured EIJ: no overlap between parameters and tests".into(),
        ));
    }
    if m <= free.len() {
        return Err(IdentError::NoData(format!(
            "{m} measured values cannot determine {} parameters",
            free.len()
        )));
    }
    let start = DVector::from_iterator(free.len(), free.iter().map(|&i| theta0[i]));
    let reduced = Reduced {
        problem,
        free: free.clone(),
        base: theta0.clone(),
    };
    // Cost history: the start, then after every iteration.
    let costs = Arc::new(Mutex::new(vec![r0.norm_squared()]));
    let (theta_free, iterations, converged) =
        optimise(reduced, start, r0.norm_squared(), costs.clone(), progress)?;
    let mut theta = theta0.clone();
    for (k, &i) in free.iter().enumerate() {
        theta[i] = theta_free[k];
    }
    if !converged {
        return Err(IdentError::NotConverged { iterations });
    }
    let (lo, hi) = s.theta_bounds();
    let at_bound = |i: usize| (theta[i] - lo).abs() < 1e-9 || (theta[i] - hi).abs() < 1e-9;
    for &i in &free {
        if at_bound(i) {
            return Err(IdentError::AtBound {
                name: problem.parameters()[i].name.clone(),
                value: to_factor(theta[i]),
                min: s.min_factor,
                max: s.max_factor,
            });
        }
    }

    let (j_full, r) = problem.jacobian_at(&theta)?;
    let j = DMatrix::from_fn(m, free.len(), |row, c| j_full[(row, free[c])]);
    let cost_final = r.norm_squared();
    let names: Vec<&str> = free
        .iter()
        .map(|&i| problem.parameters()[i].name.as_str())
        .collect();
    let free_theta: Vec<f64> = free.iter().map(|&i| theta[i]).collect();
    let u = Uncertainty::at(&j, cost_final, &free_theta, &names)?;
    warnings.extend(u.warnings.iter().cloned());
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
    let mut sims = problem.simulate_many(&[theta0.clone(), theta.clone()])?;
    let simulated_final = sims.pop().unwrap_or_default();
    let simulated_initial = sims.pop().unwrap_or_default();
    let simulated_final_time = if s.simulation.solver == SolverKind::Harmonic {
        let (time, warning) = confirm_in_time_domain(problem, &theta, &simulated_final)?;
        warnings.extend(warning);
        Some(time)
    } else {
        None
    };
    let cost_history = costs.lock().map(|c| c.clone()).unwrap_or_default();
    Ok(IdentResult {
        parameters,
        correlation,
        singular_values: u.singular_values,
        cost_initial: r0.norm_squared(),
        cost_final,
        cost_history,
        residual_std: u.residual_std,
        residuals: m,
        iterations,
        evaluations: problem.evaluations() - evaluations_before,
        simulated_initial,
        simulated_final,
        simulated_final_time,
        warnings,
        machine: problem.machine_at(&theta),
    })
}
