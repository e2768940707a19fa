//! Running the optimisers (Levenberg–Marquardt or Nelder–Mead, through argmin's executor with a
//! progress observer) and confirming a harmonic optimisation in the time domain.

use super::problem::Reduced;
use super::{lm, settings, EijMap, IdentError, Method, Problem, ProgressFn, SolverKind, Warning};
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{Executor, State, TerminationReason, KV};
use nalgebra::DVector;
use std::sync::{Arc, Mutex};

/// Records the cost after every iteration and reports it to the caller's callback.
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

/// Runs the chosen optimiser from `start` over the free parameters: (θ, iterations, converged).
pub(super) fn optimise(
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
            )
            .with_noise_tolerance(s.tol_noise);
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
pub(super) fn confirm_in_time_domain(
    problem: &Problem,
    theta: &DVector<f64>,
    harmonic: &[EijMap],
) -> Result<(Vec<EijMap>, Option<Warning>), IdentError> {
    let time = problem
        .simulate_many_with(std::slice::from_ref(theta), SolverKind::Time)?
        .remove(0);
    let mut worst: (f64, Option<Warning>) = (0.0, None);
    for (i, (h, t)) in harmonic.iter().zip(&time).enumerate() {
        for (e, v) in h {
            let d = (v - t[e]).abs();
            let allowed =
                (settings::CONFIRM_REL * t[e].abs()).max(settings::CONFIRM_ABS_UM_S2_PER_M);
            if d / allowed > worst.0 {
                worst = (
                    d / allowed,
                    Some(Warning::TimeDomainDisagrees {
                        test: problem.tests()[i].label(),
                        eij: *e,
                        harmonic: *v,
                        time: t[e],
                    }),
                );
            }
        }
    }
    let warning = if worst.0 > 1.0 { worst.1 } else { None };
    Ok((time, warning))
}
