//! The fit in rounds: the free parameters fitted, reversal terms added where the data need them,
//! and identifiability re-checked at the solution (a parameter hidden at the start may be
//! determined once the others are fitted, or the reverse), fitting again with the new set, a
//! few rounds at most.

use super::identifiability::{self, Analysis};
use super::problem::Reduced;
use super::settings::CHI2_SIGMAS;
use super::{solve, IdentError, Note, Problem, ProgressFn, StaticTerms};
use nalgebra::{DMatrix, DVector};
use std::borrow::Cow;
use std::sync::{Arc, Mutex};

/// Rounds of fitting with a changed set of free parameters.
const MAX_ROUNDS: usize = 3;

/// Where the rounds ended.
pub(super) struct Rounds<'a> {
    /// The problem with the static terms it ended with (reversal terms may have been added).
    pub problem: Cow<'a, Problem>,
    /// θ of all parameters at the solution.
    pub theta: DVector<f64>,
    /// Iterations over all rounds.
    pub iterations: u64,
    /// Whether the last fit converged.
    pub converged: bool,
    /// Jacobian of the weighted errors at the solution, all parameters.
    pub e_jac: DMatrix<f64>,
    /// The weighted errors at the solution.
    pub e: DVector<f64>,
    /// Parameters whose finite-difference neighbours cannot be simulated.
    pub edges: Vec<usize>,
}

/// Fits the parameters `analysis.free` from θ₀ in rounds (see the module docs); `analysis`
/// ends as the identifiability at the solution, `notes` gets what changed on the way.
pub(super) fn fit_in_rounds<'a>(
    problem: &'a Problem,
    analysis: &mut Analysis,
    theta0: &DVector<f64>,
    names: &[String],
    notes: &mut Vec<Note>,
    costs: Arc<Mutex<Vec<f64>>>,
    progress: Option<Arc<ProgressFn>>,
) -> Result<Rounds<'a>, IdentError> {
    let mut current = Cow::Borrowed(problem);
    let mut theta = theta0.clone();
    let mut iterations = 0;
    let mut reversal_checked = problem.settings().static_terms != StaticTerms::Auto;
    let mut history = vec![analysis.free.clone()];
    loop {
        let free = analysis.free.clone();
        let (t, it, converged) = fit(&current, &free, &theta, costs.clone(), progress.clone())?;
        (theta, iterations) = (t, iterations + it);
        if converged && !reversal_checked {
            reversal_checked = true;
            let need = reversal_needed(&current, &theta, free.len())?;
            if !need.is_empty() {
                let with = current.with_statics(current.statics_with(&need));
                for &g in &need {
                    notes.push(Note::ReversalTermsFitted {
                        group: with.statics().groups[g].label(),
                    });
                }
                current = Cow::Owned(with);
                continue;
            }
        }
        let (e_jac, e, edges) = current.error_jacobian_edges(&theta)?;
        let settled = !converged
            || rounds_left(
                analysis,
                &mut history,
                &current,
                &e_jac,
                &mut theta,
                Start { theta0, names },
                notes,
            );
        if settled {
            return Ok(Rounds {
                problem: current,
                theta,
                iterations,
                converged,
                e_jac,
                e,
                edges,
            });
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

/// The start of the rounds: θ₀ of all parameters and their names.
struct Start<'s> {
    theta0: &'s DVector<f64>,
    names: &'s [String],
}

/// Re-checks identifiability at the solution θ (the operating point matters: a compliance
/// weakly seen from the catalogue values may be determined at the solution, or the reverse)
/// with the Jacobian of the weighted errors `e_jac`, over all parameters. Returns true when the
/// set of free parameters stays; else updates `analysis` (with a note), resets the newly held
/// parameters in `theta` to their start values `theta0` and returns false: fit again. A set
/// seen before (the rounds would oscillate) is replaced by the parameters free in both of the
/// last two sets, fitted once more; `history` holds the sets tried, at most [`MAX_ROUNDS`].
fn rounds_left(
    analysis: &mut Analysis,
    history: &mut Vec<Vec<usize>>,
    problem: &Problem,
    e_jac: &DMatrix<f64>,
    theta: &mut DVector<f64>,
    Start { theta0, names }: Start<'_>,
    notes: &mut Vec<Note>,
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
    let list = |v: Vec<usize>| -> Vec<String> { v.into_iter().map(|i| names[i].clone()).collect() };
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
    notes.push(Note::IdentifiabilityChanged {
        determined: list(released),
        not_determined: list(held),
    });
    *analysis = again;
    false
}
