//! Hold-out validation: does the identified model predict tests it was not fitted to?
//!
//! The held-out tests are simulated on the identified machine and compared with their measured
//! EIJ in units of the measurement uncertainty, z = (E_sim − E_meas)/σ. Their static terms
//! (geometry of their own set-up, [`super::statics`]) are not model predictions: they are
//! fitted on the held-out data themselves, as in the identification, and take their degrees of
//! freedom. With a model that predicts within the measurement uncertainty, χ²/dof = Σz²/dof
//! scatters about 1 by √(2/dof); beyond [`CHI2_SIGMAS`] of that the validation fails.

use super::settings::CHI2_SIGMAS;
use super::{IdentError, Parameter, Problem, Settings, TestCase};
use crate::machine::Machine;

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
}

/// The validation.
#[derive(Debug, Clone, PartialEq)]
pub struct Validation {
    /// Per held-out test.
    pub tests: Vec<ValidatedTest>,
    /// Values compared.
    pub values: usize,
    /// Degrees of freedom (values − static terms).
    pub dof: usize,
    /// Σz²/dof.
    pub chi2_per_dof: f64,
    /// Whether the model predicts the held-out tests within their uncertainty.
    pub passed: bool,
}

/// Validates `machine` (identified) on `tests`, with the settings of the identification.
pub fn validate(
    machine: &Machine,
    tests: Vec<TestCase>,
    settings: &Settings,
) -> Result<Validation, IdentError> {
    let names: Vec<String> = tests.iter().map(|t| t.source.clone()).collect();
    // Any parameter serves: validation simulates the machine as it is.
    let param = Parameter::default_set(machine)
        .into_iter()
        .next()
        .ok_or_else(|| IdentError::NoData("the machine has no axis".into()))?;
    let mut settings = settings.clone();
    settings.min_factor = settings.min_factor.min(param.get(machine));
    settings.max_factor = settings.max_factor.max(param.get(machine));
    let problem = Problem::new(machine.clone(), vec![param], tests, settings)?;
    let sims = problem.simulate_many(std::slice::from_ref(&problem.initial_theta()))?;
    let z = problem.residuals_of(&sims[0]);
    let rows = problem.rows();
    let values = rows.len();
    let dof = values.saturating_sub(problem.statics().rank()).max(1);
    let chi2_per_dof = z.norm_squared() / dof as f64;
    let passed = chi2_per_dof <= 1.0 + CHI2_SIGMAS * (2.0 / dof as f64).sqrt();
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
                rms_error_um_s2_per_m: rms(&|r| z[r] * rows[r].sigma),
                rms_sigma_um_s2_per_m: rms(&|r| rows[r].sigma),
            }
        })
        .collect();
    Ok(Validation {
        tests,
        values,
        dof,
        chi2_per_dof,
        passed,
    })
}
