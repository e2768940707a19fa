//! A Levenberg–Marquardt step as an argmin [`Solver`] (argmin 0.11 has none), with box bounds on
//! the (log) parameters.
//!
//! Each iteration solves (JᵀJ + λ·diag(JᵀJ)) δ = −Jᵀr (Cholesky) for the parameters not held
//! by an active bound, clamps θ + δ into the bounds and accepts the step if the cost ½‖r‖²
//! decreases (then λ ← λ/3), else retries with λ ← 4λ.
//! It converges when no step decreases the cost any more, when the relative decrease falls
//! below `tol_cost`, when the step falls below `tol_step`, or — checked before a trial step
//! is simulated — when the undamped Gauss–Newton step left is shorter than `tol_noise`
//! standard errors: δᵀJᵀJδ = gᵀ(JᵀJ)⁻¹g ≤ tol_noise²·s² (residuals weighted by σ, s² their
//! variance per degree of freedom, at least 1), so that neither the cost nor the parameters
//! would move by anything the noise lets one see.

use argmin::core::{
    Error, IterState, Jacobian, Operator, Problem, Solver, State, TerminationReason,
    TerminationStatus, KV,
};
use nalgebra::{DMatrix, DVector};

/// The state type used by [`LevenbergMarquardt`].
pub(crate) type LmState = IterState<DVector<f64>, (), DMatrix<f64>, (), DVector<f64>, f64>;

/// Levenberg–Marquardt with bounds.
#[derive(Debug, Clone)]
pub(crate) struct LevenbergMarquardt {
    lambda: f64,
    lower: DVector<f64>,
    upper: DVector<f64>,
    tol_cost: f64,
    tol_step: f64,
    tol_noise: f64,
    converged: bool,
}

impl LevenbergMarquardt {
    /// A solver with bounds `lower ≤ θ ≤ upper`, relative cost tolerance and step tolerance;
    /// no noise tolerance (see [`LevenbergMarquardt::with_noise_tolerance`]).
    pub(crate) fn new(
        lower: DVector<f64>,
        upper: DVector<f64>,
        tol_cost: f64,
        tol_step: f64,
    ) -> Self {
        LevenbergMarquardt {
            lambda: 1e-3,
            lower,
            upper,
            tol_cost,
            tol_step,
            tol_noise: 0.0,
            converged: false,
        }
    }

    /// Also converged when the Gauss–Newton step left is below `standard_errors` standard
    /// errors (see the module docs).
    pub(crate) fn with_noise_tolerance(mut self, standard_errors: f64) -> Self {
        self.tol_noise = standard_errors;
        self
    }

    fn clamp(&self, theta: &DVector<f64>) -> DVector<f64> {
        DVector::from_fn(theta.len(), |i, _| {
            theta[i].clamp(self.lower[i], self.upper[i])
        })
    }
}

fn half_sq(r: &DVector<f64>) -> f64 {
    0.5 * r.norm_squared()
}

impl<O> Solver<O, LmState> for LevenbergMarquardt
where
    O: Operator<Param = DVector<f64>, Output = DVector<f64>>
        + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
{
    fn name(&self) -> &str {
        "Levenberg-Marquardt"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let theta = state.take_param().ok_or_else(|| {
            anyhow::anyhow!("Levenberg-Marquardt needs an initial parameter vector")
        })?;
        let theta = self.clamp(&theta);
        let r = problem.apply(&theta)?;
        let cost = half_sq(&r);
        Ok((state.param(theta).residuals(r).cost(cost), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let theta = state
            .get_param()
            .ok_or_else(|| anyhow::anyhow!("Levenberg-Marquardt: no parameter"))?
            .clone();
        let r = state
            .get_residuals()
            .ok_or_else(|| anyhow::anyhow!("Levenberg-Marquardt: no residuals"))?
            .clone();
        let cost = half_sq(&r);
        let j = problem.jacobian(&theta)?;
        let a = j.transpose() * &j;
        let g = j.transpose() * &r;
        let floor = 1e-12 * a.diagonal().max().max(1e-300);
        // Active bounds: a parameter on its bound whose descent direction −g points outwards
        // stays there; the step is solved for the others (projected LM).
        let free: Vec<usize> = (0..theta.len())
            .filter(|&i| {
                !((theta[i] <= self.lower[i] && g[i] > 0.0)
                    || (theta[i] >= self.upper[i] && g[i] < 0.0))
            })
            .collect();
        if free.is_empty() {
            self.converged = true;
            return Ok((state.param(theta).residuals(r).cost(cost).jacobian(j), None));
        }
        let nf = free.len();
        let a_free = DMatrix::from_fn(nf, nf, |p, q| a[(free[p], free[q])]);
        let g_free = DVector::from_fn(nf, |p, _| g[free[p]]);
        if self.tol_noise > 0.0 {
            let dof = r.len().saturating_sub(nf).max(1) as f64;
            let s2 = (2.0 * cost / dof).max(1.0);
            let gauss_newton = a_free
                .clone()
                .cholesky()
                .map(|c| g_free.dot(&c.solve(&g_free)));
            if gauss_newton.is_some_and(|d| d <= self.tol_noise * self.tol_noise * s2) {
                self.converged = true;
                return Ok((state.param(theta).residuals(r).cost(cost).jacobian(j), None));
            }
        }
        for _ in 0..16 {
            let mut damped = a_free.clone();
            for i in 0..nf {
                damped[(i, i)] += self.lambda * a_free[(i, i)].max(floor);
            }
            let Some(chol) = damped.cholesky() else {
                self.lambda *= 10.0;
                continue;
            };
            let step_free = -chol.solve(&g_free);
            let mut delta = DVector::zeros(theta.len());
            for (p, &i) in free.iter().enumerate() {
                delta[i] = step_free[p];
            }
            let trial = self.clamp(&(&theta + &delta));
            let step = (&trial - &theta).amax();
            if step == 0.0 {
                break;
            }
            let r_new = problem.apply(&trial)?;
            let c_new = half_sq(&r_new);
            if c_new < cost {
                self.lambda = (self.lambda / 3.0).max(1e-12);
                // Converged: a negligible relative decrease, a negligible step, or a fit at the
                // level of rounding (rms residual below 1e-7 σ).
                let rounding = 0.5e-14 * r_new.len() as f64;
                if cost - c_new <= self.tol_cost * cost
                    || step <= self.tol_step
                    || c_new <= rounding
                {
                    self.converged = true;
                }
                let kv = argmin::kv!("lambda" => self.lambda; "step" => step;);
                return Ok((
                    state.param(trial).residuals(r_new).cost(c_new).jacobian(j),
                    Some(kv),
                ));
            }
            self.lambda *= 4.0;
        }
        // No step lowers the cost: a (local) minimum within the bounds.
        self.converged = true;
        Ok((state.param(theta).residuals(r).cost(cost).jacobian(j), None))
    }

    fn terminate(&mut self, _state: &LmState) -> TerminationStatus {
        if self.converged {
            TerminationStatus::Terminated(TerminationReason::SolverConverged)
        } else {
            TerminationStatus::NotTerminated
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use argmin::core::Executor;

    /// Exponential decay y = a·exp(−b·t) fitted to exact data: the solution is (a, b) = (2, 0.7).
    struct Decay {
        t: Vec<f64>,
        y: Vec<f64>,
    }

    impl Operator for Decay {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
            Ok(DVector::from_fn(self.t.len(), |i, _| {
                p[0] * (-p[1] * self.t[i]).exp() - self.y[i]
            }))
        }
    }

    impl Jacobian for Decay {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok(DMatrix::from_fn(self.t.len(), 2, |i, c| {
                let e = (-p[1] * self.t[i]).exp();
                if c == 0 {
                    e
                } else {
                    -p[0] * self.t[i] * e
                }
            }))
        }
    }

    #[test]
    fn fits_an_exponential_exactly_and_respects_bounds() {
        let t: Vec<f64> = (0..20).map(|i| i as f64 * 0.25).collect();
        let y = t.iter().map(|t| 2.0 * (-0.7 * t).exp()).collect();
        let problem = Decay { t, y };
        let lm = LevenbergMarquardt::new(
            DVector::from_vec(vec![0.0, 0.0]),
            DVector::from_vec(vec![10.0, 10.0]),
            1e-15,
            1e-12,
        );
        let res = Executor::new(problem, lm)
            .configure(|s| s.param(DVector::from_vec(vec![1.0, 2.0])).max_iters(100))
            .run()
            .unwrap();
        let p = res.state().get_best_param().unwrap();
        // The solver stops once the rms residual is below 1e-7 (rounding level for residuals
        // in units of σ); here that leaves the parameters within ~1e-7.
        assert!(res.state().get_cost() <= 0.5e-14 * 20.0);
        assert!(
            (p[0] - 2.0).abs() < 1e-6 && (p[1] - 0.7).abs() < 1e-6,
            "{p}"
        );

        // With b bounded to ≤ 0.5 the solution sits on the bound.
        let t: Vec<f64> = (0..20).map(|i| i as f64 * 0.25).collect();
        let y = t.iter().map(|t| 2.0 * (-0.7 * t).exp()).collect();
        let lm = LevenbergMarquardt::new(
            DVector::from_vec(vec![0.0, 0.0]),
            DVector::from_vec(vec![10.0, 0.5]),
            1e-15,
            1e-12,
        );
        let res = Executor::new(Decay { t, y }, lm)
            .configure(|s| s.param(DVector::from_vec(vec![1.0, 0.1])).max_iters(100))
            .run()
            .unwrap();
        assert_eq!(res.state().get_best_param().unwrap()[1], 0.5);
    }
}
