//! Hold-out validation: does the identified model predict tests it was not fitted to?
//!
//! The held-out tests are simulated on the identified machine and compared with their measured
//! EIJ. The prediction carries two uncertainties: the measurement's own σ, and the identified
//! parameters' covariance Σ_θ (cov(θ), θ = 1/p, [`super::uncertainty`]) propagated through the
//! sensitivity of the held-out EIJ to the parameters, J = ∂((E_sim − E_meas)/σ)/∂θ (central
//! differences at the identified θ, as in the identification). In units of σ the prediction
//! errors e = (E_sim − E_meas)/σ then have the covariance
//!
//! C = I + J·Σ_θ·Jᵀ,
//!
//! full, not diagonal: one parameter error shifts many held-out values alike. The held-out
//! tests' static terms A·g (geometry of their own set-up, clock offsets; [`super::statics`]) are
//! not model predictions: they are fitted on the held-out data themselves by generalised least
//! squares with that covariance, and take their degrees of freedom (rank A):
//!
//! χ² = min_g (e + A·g)ᵀ C⁻¹ (e + A·g),  dof = m − rank(A).
//!
//! With a model that predicts within these uncertainties χ²/dof scatters about 1 by √(2/dof);
//! beyond [`CHI2_SIGMAS`] of that the validation fails. Per value the report shows
//! z = (E_sim − E_meas − static terms)/√(σ² + (J Σ_θ Jᵀ)ᵢᵢ σ²), i.e. the residual over its own
//! prediction standard deviation; χ²/dof without the parameters' covariance (C = I, the
//! measurement uncertainty alone) is reported beside it.

use super::settings::CHI2_SIGMAS;
use super::{IdentError, IdentResult, Parameter, Problem, Settings, TestCase};
use crate::machine::Machine;
use nalgebra::{DMatrix, DVector};

/// One held-out test.
#[derive(Debug, Clone, PartialEq)]
pub struct ValidatedTest {
    /// Where it came from.
    pub source: String,
    /// Its label (plane, direction, acceleration, centre).
    pub label: String,
    /// RMS of z over its EIJ.
    pub rms_z: f64,
    /// Largest |z|.
    pub max_abs_z: f64,
    /// RMS prediction error E_sim − E_meas (static terms removed), µm·s²/m.
    pub rms_error_um_s2_per_m: f64,
    /// RMS measurement uncertainty σ, µm·s²/m.
    pub rms_sigma_um_s2_per_m: f64,
    /// RMS standard deviation of the prediction from the parameters' covariance,
    /// √(J Σ_θ Jᵀ)ᵢᵢ·σᵢ, µm·s²/m.
    pub rms_prediction_sigma_um_s2_per_m: f64,
}

/// The validation.
#[derive(Debug, Clone, PartialEq)]
pub struct Validation {
    /// Per held-out test.
    pub tests: Vec<ValidatedTest>,
    /// Values compared.
    pub values: usize,
    /// Degrees of freedom (values − rank of the static terms).
    pub dof: usize,
    /// χ²/dof with the measurement uncertainty and the parameters' covariance.
    pub chi2_per_dof: f64,
    /// χ²/dof with the measurement uncertainty alone (as if the parameters were exact).
    pub chi2_per_dof_measurement_only: f64,
    /// Whether the model predicts the held-out tests within their uncertainty
    /// (`chi2_per_dof` ≤ 1 + [`CHI2_SIGMAS`]·√(2/dof)).
    pub passed: bool,
}

/// The identified parameters and the covariance of their θ = 1/p, which a prediction with the
/// identified machine inherits.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterCovariance {
    /// The parameters.
    pub parameters: Vec<Parameter>,
    /// cov(θ), in the order of `parameters` (0 rows and columns for parameters kept fixed).
    pub theta: DMatrix<f64>,
}

impl ParameterCovariance {
    /// The covariance of an identification's parameters (`parameters` as given to its problem).
    pub fn of(parameters: &[Parameter], result: &IdentResult) -> ParameterCovariance {
        ParameterCovariance {
            parameters: parameters.to_vec(),
            theta: result.covariance_theta.clone(),
        }
    }
}

/// The held-out χ² of prediction errors `e` (m, in units of σ) with sensitivity `j` (m × n,
/// per θ), parameter covariance `cov_theta` (n × n) and static terms `a` (m × q, weighted like
/// `e`, fitted away): see the module docs.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldOut {
    /// χ² = min_g (e + A g)ᵀ C⁻¹ (e + A g), C = I + J Σ Jᵀ.
    pub chi2: f64,
    /// m − rank(A).
    pub dof: usize,
    /// e + A ĝ: the prediction errors without the static terms fitted (units of σ).
    pub residual: DVector<f64>,
    /// diag(J Σ Jᵀ): the prediction's variance from the parameters (units of σ²).
    pub parameter_variance: DVector<f64>,
}

impl HeldOut {
    /// z per value: the residual over its standard deviation √(1 + (J Σ Jᵀ)ᵢᵢ).
    pub fn z(&self) -> DVector<f64> {
        self.residual
            .zip_map(&self.parameter_variance, |r, v| r / (1.0 + v).sqrt())
    }

    /// The χ² of `e` given `j`, `cov_theta` and `a` (see the type's docs); `None` when C is not
    /// positive definite or the decomposition of the static terms fails.
    pub fn new(
        e: &DVector<f64>,
        j: &DMatrix<f64>,
        cov_theta: &DMatrix<f64>,
        a: &DMatrix<f64>,
    ) -> Option<HeldOut> {
        let m = e.len();
        let jsj = j * cov_theta * j.transpose();
        let chol = (DMatrix::identity(m, m) + &jsj).cholesky()?;
        // Whitened: ẽ = L⁻¹e, Ã = L⁻¹A; χ² = ‖ẽ + Ã ĝ‖², ĝ the least-squares fit.
        let l = chol.l();
        let e_w = l.solve_lower_triangular(&DMatrix::from_column_slice(m, 1, e.as_slice()))?;
        let (g, rank) = if a.ncols() == 0 {
            (DVector::zeros(0), 0)
        } else {
            let svd = l
                .solve_lower_triangular(a)?
                .try_svd(true, true, f64::EPSILON, 10_000)?;
            let eps = 1e-10 * svd.singular_values.max();
            let g = svd.solve(&(-e_w), eps).ok()?;
            (g.column(0).into_owned(), svd.rank(eps))
        };
        let residual = e + a * &g;
        let chi2 = chol.solve(&residual).dot(&residual);
        Some(HeldOut {
            chi2,
            dof: m.saturating_sub(rank).max(1),
            residual,
            parameter_variance: jsj.diagonal(),
        })
    }
}

/// Validates `machine` (identified) on `tests`, with the settings of the identification and
/// the covariance of its parameters (`None`: the machine taken as exact).
pub fn validate(
    machine: &Machine,
    covariance: Option<&ParameterCovariance>,
    tests: Vec<TestCase>,
    settings: &Settings,
) -> Result<Validation, IdentError> {
    let names: Vec<String> = tests.iter().map(|t| t.source.clone()).collect();
    // The parameters the prediction inherits an uncertainty from (positive variance); without
    // any, one parameter serves: the machine is simulated as it is.
    let (params, cov_theta) = match covariance {
        Some(c) => {
            let free: Vec<usize> = (0..c.parameters.len())
                .filter(|&i| c.theta[(i, i)] > 0.0)
                .collect();
            let cov = DMatrix::from_fn(free.len(), free.len(), |a, b| c.theta[(free[a], free[b])]);
            (free.iter().map(|&i| c.parameters[i].clone()).collect(), cov)
        }
        None => (Vec::new(), DMatrix::zeros(0, 0)),
    };
    let with_uncertainty = !params.is_empty();
    let params = if with_uncertainty {
        params
    } else {
        Parameter::default_set(machine)
            .into_iter()
            .take(1)
            .collect::<Vec<_>>()
    };
    if params.is_empty() {
        return Err(IdentError::NoData("the machine has no axis".into()));
    }
    let mut settings = settings.clone();
    for p in &params {
        settings.min_factor = settings.min_factor.min(p.get(machine));
        settings.max_factor = settings.max_factor.max(p.get(machine));
    }
    let problem = Problem::new(machine.clone(), params, tests, settings)?;
    let theta = problem.initial_theta();
    let (j, e) = if with_uncertainty {
        problem.error_jacobian_at(&theta)?
    } else {
        let sims = problem.simulate_many(std::slice::from_ref(&theta))?;
        let e = problem.errors_of(&sims[0]);
        (DMatrix::zeros(e.len(), 0), e)
    };
    let held = HeldOut::new(&e, &j, &cov_theta, problem.statics().matrix()).ok_or_else(|| {
        IdentError::Optimiser(
            "the held-out prediction covariance is not positive definite, or the held-out static terms cannot be decomposed".into(),
        )
    })?;
    let measurement_only = problem.statics().project(&e).norm_squared();
    let rows = problem.rows();
    let values = rows.len();
    let dof = held.dof;
    let chi2_per_dof = held.chi2 / dof as f64;
    let passed = chi2_per_dof <= 1.0 + CHI2_SIGMAS * (2.0 / dof as f64).sqrt();
    let z = held.z();
    let tests = problem
        .tests()
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let k: Vec<usize> = (0..values).filter(|&r| rows[r].test == i).collect();
            let count = k.len().max(1) as f64;
            let rms = |f: &dyn Fn(usize) -> f64| {
                (k.iter().map(|&r| f(r).powi(2)).sum::<f64>() / count).sqrt()
            };
            ValidatedTest {
                source: names[i].clone(),
                label: t.label(),
                rms_z: rms(&|r| z[r]),
                max_abs_z: k.iter().map(|&r| z[r].abs()).fold(0.0, f64::max),
                rms_error_um_s2_per_m: rms(&|r| held.residual[r] * rows[r].sigma),
                rms_sigma_um_s2_per_m: rms(&|r| rows[r].sigma),
                rms_prediction_sigma_um_s2_per_m: rms(&|r| {
                    held.parameter_variance[r].max(0.0).sqrt() * rows[r].sigma
                }),
            }
        })
        .collect();
    Ok(Validation {
        tests,
        values,
        dof,
        chi2_per_dof,
        chi2_per_dof_measurement_only: measurement_only / dof as f64,
        passed,
    })
}
