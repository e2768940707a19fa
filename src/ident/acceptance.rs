//! The acceptance of a fit: whether the identification may start at all, whether its result may be
//! exported (converged, off the bounds, away from the limit of what the model can simulate),
//! and the plausibility of the identified factors.

use super::identifiability::Analysis;
use super::parameters::to_factor;
use super::settings::{Settings, AT_BOUND_REL};
use super::verdict::Implausible;
use super::{IdentError, Identified, Problem, Warning};
use nalgebra::DVector;

/// Refuses to start a fit the tests cannot carry: no parameter they determine, or fewer
/// measured values (`m`) than parameters and static terms.
pub(super) fn check_start(
    problem: &Problem,
    analysis: &Analysis,
    theta0: &DVector<f64>,
    names: &[String],
    m: usize,
) -> Result<(), IdentError> {
    if analysis.free.is_empty() {
        let no_influence = analysis.not_identifiable.iter().all(|n| n.no_influence);
        let why: Vec<String> = analysis
            .not_identifiable
            .iter()
            .map(|ni| ni.describe(names, to_factor(theta0[ni.index])))
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
    Ok(())
}

/// Whether factor `p` lies on a bound of `settings`' factors, judged relative to the bound
/// (0.010006 against 0.01 is on it).
pub(super) fn on_bound(p: f64, settings: &Settings) -> bool {
    let (lo, hi) = (settings.min_factor, settings.max_factor);
    (p - lo).abs() <= AT_BOUND_REL * lo || (p - hi).abs() <= AT_BOUND_REL * hi
}

/// Why a fit must not be exported, if it must not: it did not converge, a free parameter ended
/// on a bound, or a free parameter sits where a neighbouring value cannot be simulated
/// (`edges`, e.g. the closed loop's stability limit).
pub(super) fn refusal(
    settings: &Settings,
    converged: bool,
    iterations: u64,
    theta: &DVector<f64>,
    free: &[usize],
    edges: &[usize],
    names: &[String],
) -> Option<IdentError> {
    let (lo, hi) = (settings.min_factor, settings.max_factor);
    if !converged {
        return Some(IdentError::NotConverged { iterations });
    }
    if let Some(&i) = free
        .iter()
        .find(|&&i| on_bound(to_factor(theta[i]), settings))
    {
        let p = to_factor(theta[i]);
        return Some(IdentError::AtBound {
            name: names[i].clone(),
            value: p,
            bound: if (p - lo).abs() < (p - hi).abs() {
                lo
            } else {
                hi
            },
            min: lo,
            max: hi,
        });
    }
    let at: Vec<String> = edges
        .iter()
        .filter(|i| free.contains(i))
        .map(|&i| format!("{} = {:.4}", names[i], to_factor(theta[i])))
        .collect();
    (!at.is_empty()).then(|| IdentError::AtSimulationLimit {
        names: at.join(", "),
        detail: format!(
            "a change of {} relative makes a simulation fail, e.g. an unstable closed loop",
            settings.fd_step
        ),
    })
}

/// Warnings on identified factors: on a bound, or implausible ([`Implausible`]: a reduction
/// factor stiffer than the catalogue or more than ten times softer, an elastic body's stiffness
/// factor far from its FE model, each beyond its uncertainty).
pub(super) fn plausibility(parameters: &[Identified], settings: &Settings) -> Vec<Warning> {
    let (lo, hi) = (settings.min_factor, settings.max_factor);
    parameters
        .iter()
        .filter(|q| q.identifiable)
        .filter_map(|q| {
            if q.at_bound {
                Some(Warning::AtBound {
                    name: q.name.clone(),
                    value: q.value,
                    min: lo,
                    max: hi,
                })
            } else {
                Implausible::of(&q.name, q.value, q.std_err).map(|why| Warning::Implausible {
                    name: q.name.clone(),
                    value: q.value,
                    std_err: q.std_err,
                    why,
                })
            }
        })
        .collect()
}
