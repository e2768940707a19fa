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
//! in order; [`stiffness`] gives the identified stiffness set as a table, [`verdict`] how to
//! read the result (each parameter's standing, the χ² test), [`groups`] how well each plane and
//! circle centre is reproduced, [`holdout`] leaving one circle centre out, and [`compare`] which
//! of several candidate models the data support (BIC, AIC, a verdict in words;
//! [`compare_report`] its file).

mod acceptance;
mod builder;
pub mod compare;
pub mod compare_report;
pub mod config;
pub mod design;
pub mod diagnosis;
mod error;
pub mod groups;
pub mod holdout;
pub(crate) mod identifiability;
pub(crate) mod lm;
pub mod measured;
pub mod mismatch;
mod note;
pub(crate) mod parameters;
pub(crate) mod problem;
pub mod report;
mod rounds;
pub mod settings;
mod solve;
pub(crate) mod statics;
pub mod stiffness;
pub(crate) mod uncertainty;
pub mod validation;
pub mod verdict;
mod warning;

pub use crate::predict::{EijMap, SolverKind};
pub use builder::Identification;
pub use error::IdentError;
pub use identifiability::NotIdentifiable;
pub use note::Note;
pub use parameters::{Parameter, ParameterKind};
pub use problem::{Problem, TestCase};
pub use settings::{MeasuredOptions, Method, Settings};
pub use statics::{StaticTerms, Statics};
pub use uncertainty::Uncertainty;
pub use warning::Warning;

use crate::machine::Machine;
use nalgebra::{DMatrix, DVector};
use parameters::to_factor;
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
    /// Whether it ended on a bound of the factors (within [`settings::AT_BOUND_REL`] of it, relative).
    pub at_bound: bool,
}

impl Identified {
    /// How well the tests determine it ([`verdict::Standing`]: determined, loose, weak, …).
    pub fn standing(&self) -> verdict::Standing {
        verdict::Standing::of(self.value, self.std_err, self.identifiable, self.at_bound)
    }
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
    /// Covariance of θ = 1/p, s²·(JᵀJ)⁻¹ (order of `parameters`; rows and columns of the
    /// parameters kept at their start value 0): what a prediction with the identified
    /// machine inherits ([`validation`]).
    pub covariance_theta: DMatrix<f64>,
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
    /// Degrees of freedom m − n − q of s (n free parameters, q static terms).
    pub degrees_of_freedom: usize,
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
    /// Static terms or clock offsets that may be absorbing a model error (a failed χ² test with
    /// significant terms; [`mismatch`]).
    pub model_mismatch: Option<mismatch::ModelMismatch>,
    /// Warnings (non-identifiable parameters, bounds, χ², plausibility, model mismatch).
    pub warnings: Vec<Warning>,
    /// Notes (static terms not separable, reversal terms added).
    pub notes: Vec<Note>,
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

    /// The χ² test of the fit: whether the residual standard deviation s is compatible with 1
    /// over the fit's degrees of freedom ([`verdict::Chi2`]).
    pub fn chi2(&self) -> verdict::Chi2 {
        verdict::Chi2::new(self.residual_std, self.degrees_of_freedom)
    }
}

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
    let names: Vec<String> = problem
        .parameters()
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let (j0, r0) = problem.jacobian_at(&theta0)?;
    let mut analysis = identifiability::analyse(&j0, &theta0);
    acceptance::check_start(problem, &analysis, &theta0, &names, r0.len())?;
    let mut notes: Vec<Note> = problem
        .statics()
        .groups
        .iter()
        .filter_map(|g| g.note.clone())
        .collect();
    // Cost history: the start, then after every iteration.
    let costs = Arc::new(Mutex::new(vec![r0.norm_squared()]));
    let fitted = rounds::fit_in_rounds(
        problem,
        &mut analysis,
        &theta0,
        &names,
        &mut notes,
        costs.clone(),
        progress,
    )?;
    let problem: &Problem = &fitted.problem;
    let theta = &fitted.theta;
    let free = &analysis.free;
    let refusal = acceptance::refusal(
        s,
        fitted.converged,
        fitted.iterations,
        theta,
        free,
        &fitted.edges,
        &names,
    );
    let mut warnings: Vec<Warning> = analysis
        .not_identifiable
        .iter()
        .map(|ni| Warning::NotIdentifiable {
            parameter: ni.clone(),
            names: names.clone(),
            kept_at: to_factor(theta0[ni.index]),
        })
        .collect();
    let fit = FitUncertainty::at(problem, &fitted.e_jac, &fitted.e, theta, free)?;
    warnings.extend(fit.uncertainty.warnings.iter().cloned());
    let parameters: Vec<Identified> = names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let fi = free.iter().position(|&f| f == i);
            Identified {
                name: name.clone(),
                initial: to_factor(theta0[i]),
                value: to_factor(theta[i]),
                std_err: fi.map(|k| fit.uncertainty.std_err[k]),
                identifiable: fi.is_some(),
                at_bound: fi.is_some() && acceptance::on_bound(to_factor(theta[i]), s),
            }
        })
        .collect();
    warnings.extend(acceptance::plausibility(&parameters, s));
    let model_mismatch = mismatch::ModelMismatch::check(
        fit.uncertainty.chi2_failed,
        fit.uncertainty.residual_std,
        problem.statics(),
        &fit.static_estimates,
    );
    warnings.extend(model_mismatch.clone().map(Warning::ModelMismatch));
    let mut sims = problem.simulate_many(&[theta0.clone(), theta.clone()])?;
    let simulated_final = sims.pop().unwrap_or_default();
    let simulated_initial = sims.pop().unwrap_or_default();
    let simulated_final_time = if s.simulation.solver == SolverKind::Harmonic && refusal.is_none() {
        let (time, warning) = solve::confirm_in_time_domain(problem, theta, &simulated_final)?;
        warnings.extend(warning);
        Some(time)
    } else {
        None
    };
    let design = if s.design {
        let s_res = fit.uncertainty.residual_std;
        Some(design::rank(problem, theta, &fitted.e_jac, s_res)?)
    } else {
        None
    };
    let rejected_steps = problem.unsimulable();
    if rejected_steps > 0 {
        notes.push(Note::RejectedSteps {
            count: rejected_steps,
        });
    }
    let cost_history = costs.lock().map(|c| c.clone()).unwrap_or_default();
    Ok(IdentResult {
        parameters,
        not_identifiable: analysis.not_identifiable,
        correlation: fit.correlation,
        covariance_theta: fit.covariance_theta,
        singular_values: fit.uncertainty.singular_values,
        cost_initial: r0.norm_squared(),
        cost_final: fit.cost,
        cost_history,
        residual_std: fit.uncertainty.residual_std,
        residuals: r0.len(),
        degrees_of_freedom: problem.dof(free.len()),
        iterations: fitted.iterations,
        evaluations: problem.evaluations() - evaluations_before,
        rejected_steps,
        simulated_initial,
        simulated_final,
        simulated_final_time,
        statics: problem.statics().clone(),
        static_estimates: fit.static_estimates,
        design,
        model_mismatch,
        warnings,
        notes,
        refusal,
        machine: problem.machine_at(theta)?,
    })
}

/// The uncertainty of a fit at θ over the free parameters, with the static terms eliminated.
struct FitUncertainty {
    /// Σr² of the projected residuals.
    cost: f64,
    /// Standard errors, correlations, singular values and their warnings (free parameters).
    uncertainty: Uncertainty,
    /// Correlation matrix over all parameters (held ones 0).
    correlation: DMatrix<f64>,
    /// Covariance of θ over all parameters (held ones 0).
    covariance_theta: DMatrix<f64>,
    /// The static terms' estimates.
    static_estimates: Vec<StaticEstimate>,
}

impl FitUncertainty {
    fn at(
        problem: &Problem,
        e_jac: &DMatrix<f64>,
        e: &DVector<f64>,
        theta: &DVector<f64>,
        free: &[usize],
    ) -> Result<Self, IdentError> {
        let m = e.len();
        let names: Vec<&str> = free
            .iter()
            .map(|&i| problem.parameters()[i].name.as_str())
            .collect();
        let j_all = problem.statics().project_matrix(e_jac);
        let cost = problem.statics().project(e).norm_squared();
        let j = DMatrix::from_fn(m, free.len(), |row, c| j_all[(row, free[c])]);
        let free_theta: Vec<f64> = free.iter().map(|&i| theta[i]).collect();
        let u = Uncertainty::at(&j, cost, &free_theta, &names, problem.dof(free.len()))?;
        let e_free = DMatrix::from_fn(m, free.len(), |row, c| e_jac[(row, free[c])]);
        let static_estimates = problem
            .statics()
            .estimates(e, &e_free, &u.covariance, u.residual_std.powi(2))
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
        let n = theta.len();
        let mut correlation = DMatrix::zeros(n, n);
        let mut covariance_theta = DMatrix::zeros(n, n);
        for (a, &i) in free.iter().enumerate() {
            for (b, &k) in free.iter().enumerate() {
                correlation[(i, k)] = u.correlation[(a, b)];
                covariance_theta[(i, k)] = u.covariance[(a, b)];
            }
        }
        Ok(FitUncertainty {
            cost,
            uncertainty: u,
            correlation,
            covariance_theta,
            static_estimates,
        })
    }
}
