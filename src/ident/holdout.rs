//! Leave one circle centre out: where the tests hold two or more circle centres, the model is
//! identified on the tests of all centres but one and predicts the tests of that one
//! ([`super::validation`]: the measurement's σ and the fold's parameter covariance, its own
//! static terms fitted on it), for every centre in turn. A model that only fits, and cannot
//! predict, fails here even where its χ² passes.

use super::validation::{validate, ParameterCovariance, Validation};
use super::{identify, IdentError, Problem};
use rayon::prelude::*;

/// One fold: the tests of one circle centre, predicted by the model identified on the others.
#[derive(Debug, Clone)]
pub struct Fold {
    /// The held-out circle centre, mm (machine axis order).
    pub position_mm: Vec<f64>,
    /// Its tests.
    pub tests: usize,
    /// The prediction's validation, or why there is none (the fold's fit was refused or
    /// failed).
    pub outcome: Result<Validation, String>,
}

impl Fold {
    /// Whether the held-out centre was predicted within its uncertainty.
    pub fn passed(&self) -> bool {
        self.outcome.as_ref().is_ok_and(|v| v.passed)
    }
}

/// Every fold of a problem's tests.
#[derive(Debug, Clone)]
pub struct CentreHoldOut {
    /// One per circle centre, in the order the tests first name them.
    pub folds: Vec<Fold>,
}

impl CentreHoldOut {
    /// Folds predicted within their uncertainty.
    pub fn passed_folds(&self) -> usize {
        self.folds.iter().filter(|f| f.passed()).count()
    }

    /// Every fold predicted within its uncertainty.
    pub fn passed(&self) -> bool {
        self.passed_folds() == self.folds.len()
    }

    /// χ²/dof pooled over the folds that were validated (Σχ² / Σdof), `None` when none was.
    pub fn chi2_per_dof(&self) -> Option<f64> {
        let (chi2, dof) = self
            .folds
            .iter()
            .filter_map(|f| f.outcome.as_ref().ok())
            .fold((0.0, 0usize), |(c, d), v| {
                (c + v.chi2_per_dof * v.dof as f64, d + v.dof)
            });
        (dof > 0).then(|| chi2 / dof as f64)
    }
}

/// The circle centres of `problem`'s tests (mm), in the order first named, with the indices of
/// their tests.
pub fn centres(problem: &Problem) -> Vec<(Vec<f64>, Vec<usize>)> {
    let mut out: Vec<(Vec<f64>, Vec<usize>)> = Vec::new();
    for i in 0..problem.tests().len() {
        let p: Vec<f64> = problem.position_m(i).iter().map(|v| v * 1e3).collect();
        match out.iter_mut().find(|(q, _)| *q == p) {
            Some((_, tests)) => tests.push(i),
            None => out.push((p, vec![i])),
        }
    }
    out
}

/// Leave one circle centre out (see the module docs); `None` when the tests hold fewer than two
/// centres. The folds are fitted in parallel without the ranking of candidate tests.
pub(crate) fn leave_one_centre_out(problem: &Problem) -> Option<CentreHoldOut> {
    let centres = centres(problem);
    if centres.len() < 2 {
        return None;
    }
    let mut settings = problem.settings().clone();
    settings.design = false;
    let folds = centres
        .par_iter()
        .map(|(position_mm, held)| {
            let pick = |keep: bool| {
                problem
                    .tests()
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| held.contains(i) != keep)
                    .map(|(_, t)| t.clone())
                    .collect::<Vec<_>>()
            };
            let outcome = fold(problem, pick(true), pick(false), &settings)
                .map_err(|e| e.to_string())
                .and_then(|r| r);
            Fold {
                position_mm: position_mm.clone(),
                tests: held.len(),
                outcome,
            }
        })
        .collect();
    Some(CentreHoldOut { folds })
}

/// Identifies on `train` and validates on `held`: the validation, or why the fit gives none
/// (refused), inside; errors of the fit or the prediction outside.
fn fold(
    problem: &Problem,
    train: Vec<super::TestCase>,
    held: Vec<super::TestCase>,
    settings: &super::Settings,
) -> Result<Result<Validation, String>, IdentError> {
    let p = Problem::new(
        problem.machine().clone(),
        problem.parameters().to_vec(),
        train,
        settings.clone(),
    )?;
    let result = identify(&p, None)?;
    if let Some(refusal) = &result.refusal {
        return Ok(Err(format!(
            "the fit without this centre was refused: {refusal}"
        )));
    }
    let covariance = ParameterCovariance::of(p.parameters(), &result);
    Ok(Ok(validate(
        &result.machine,
        Some(&covariance),
        held,
        settings,
    )?))
}
