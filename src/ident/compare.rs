//! Which model do the data support? Candidate machine models (e.g. a rigid and an elastic
//! column) are identified on the same measured tests and ranked.
//!
//! Per candidate: the fit ([`super::identify`], candidates in parallel), its χ² test, and two
//! information criteria on the weighted residuals that charge for what was fitted:
//!
//! BIC = χ² + k·ln m,   AIC = χ² + 2k,
//!
//! χ² = Σr² at the solution (the cost), m the number of weighted residuals, k the terms fitted:
//! free parameters + static terms + clock offsets (the rank of the static terms' columns; all
//! of them are fitted to the same m values). With Gaussian residuals of known σ, −2 ln L = χ² +
//! const, so these are Schwarz's and Akaike's criteria; the constant is the same for every
//! candidate because every candidate is weighted by the same measured σ. The candidate with the
//! lowest BIC among the accepted fits is preferred; ΔBIC = BIC − BIC of the preferred reads as
//! evidence for the preferred (Kass & Raftery 1995): below 2 not worth more than a bare
//! mention, 2–6 positive, 6–10 strong, above 10 very strong. A refused fit (a factor on its
//! bound, not converged; [`super::IdentResult::refusal`]) or one that failed is never preferred
//! and the verdict says why. BIC is used for the choice: with m in the hundreds it charges
//! ln m ≈ 5 per term, where AIC's 2 prefers a richer model on a χ² gain that noise gives.
//!
//! Where the tests hold two or more circle centres, each candidate also predicts every centre
//! from the others ([`super::holdout`]). The verdict names, for a candidate that loses and fails
//! its χ² test, the plane, circle centre and EIJ it reproduces worst ([`super::groups`]) and
//! how the preferred candidate does there, with the parameters the preferred has and the loser
//! lacks (`column.stiffness 0.713 ± 0.010`).

use super::groups::{group_fits, GroupFit};
use super::holdout::{leave_one_centre_out, CentreHoldOut};
use super::verdict::{format_interval, Chi2};
use super::{identify, IdentError, IdentResult, Problem};
use rayon::prelude::*;

/// ΔBIC below which the data do not tell two candidates apart.
pub(crate) const INDISTINCT_DELTA_BIC: f64 = 2.0;

/// A group reproduced within this RMS z counts as reproduced in the verdict's words.
const REPRODUCED_RMS_Z: f64 = 2.0;

/// One candidate model: a label (the machine's name) and its identification problem.
#[derive(Debug)]
pub struct Candidate {
    /// How the comparison names it.
    pub label: String,
    /// The machine with its parameters on the measured tests.
    pub problem: Problem,
}

/// The criteria of one fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Score {
    /// χ² = Σr² at the solution.
    pub chi2: f64,
    /// m: weighted residuals.
    pub residuals: usize,
    /// Parameters fitted (the ones kept at their start value not counted).
    pub free_parameters: usize,
    /// Static (geometric) terms fitted with them.
    pub static_terms: usize,
    /// Clock offsets fitted with them.
    pub clock_offsets: usize,
    /// k = free parameters + static terms + clock offsets.
    pub k: usize,
    /// χ² + k·ln m.
    pub bic: f64,
    /// χ² + 2k.
    pub aic: f64,
    /// The χ² test of the fit.
    pub chi2_test: Chi2,
}

impl Score {
    /// The criteria of `result`.
    pub fn of(result: &IdentResult) -> Score {
        let free_parameters = result.parameters.iter().filter(|p| p.identifiable).count();
        let clock_offsets = result
            .statics
            .columns
            .iter()
            .filter(|c| c.clock.is_some())
            .count();
        let static_terms = result.statics.rank().saturating_sub(clock_offsets);
        let k = free_parameters + static_terms + clock_offsets;
        let m = result.residuals;
        let chi2 = result.cost_final;
        Score {
            chi2,
            residuals: m,
            free_parameters,
            static_terms,
            clock_offsets,
            k,
            bic: chi2 + k as f64 * (m as f64).ln(),
            aic: chi2 + 2.0 * k as f64,
            chi2_test: result.chi2(),
        }
    }
}

/// Where a candidate stands in the comparison.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rank {
    /// The lowest BIC among the accepted fits.
    Preferred,
    /// Accepted, with a higher BIC by `delta_bic`.
    Behind {
        /// BIC − BIC of the preferred (≥ 0).
        delta_bic: f64,
    },
    /// The fit was refused (on a bound, not converged): not eligible.
    Refused,
    /// No fit (an error before or during it): not eligible.
    Failed,
}

/// One candidate after the comparison.
#[derive(Debug)]
pub struct CandidateOutcome {
    /// Its label.
    pub label: String,
    /// Its problem (machine, parameters, tests).
    pub problem: Problem,
    /// The fit, or why there is none.
    pub fit: Result<IdentResult, IdentError>,
    /// The criteria (of a fit, refused or not).
    pub score: Option<Score>,
    /// Per plane and circle centre.
    pub groups: Vec<GroupFit>,
    /// Leave one circle centre out (accepted fits on two or more centres).
    pub holdout: Option<CentreHoldOut>,
    /// Its rank.
    pub rank: Rank,
    /// One sentence: why it is preferred, or why not.
    pub reason: String,
}

/// The comparison.
#[derive(Debug)]
pub struct Comparison {
    /// The candidates in the order given.
    pub candidates: Vec<CandidateOutcome>,
    /// Index of the preferred one, `None` when no fit was accepted.
    pub preferred: Option<usize>,
    /// The verdict in one sentence (the reasons of the others follow it in
    /// [`CandidateOutcome::reason`]).
    pub verdict: String,
}

impl Comparison {
    /// The preferred candidate, where there is one.
    pub fn winner(&self) -> Option<&CandidateOutcome> {
        self.preferred.map(|i| &self.candidates[i])
    }

    /// Whether a candidate is preferred and reproduces the data (its χ² test passes).
    pub fn reproduced(&self) -> bool {
        self.winner()
            .and_then(|w| w.score)
            .is_some_and(|s| s.chi2_test.passed)
    }
}

/// Compares `candidates` on their tests (see the module docs); `holdout`: also leave one circle
/// centre out. An error when fewer than two candidates are given or when they were not given
/// the same measured values (their criteria would not be comparable).
pub fn compare(candidates: Vec<Candidate>, holdout: bool) -> Result<Comparison, IdentError> {
    if candidates.len() < 2 {
        return Err(IdentError::NoData(format!(
            "a comparison needs at least two candidate models ({} given)",
            candidates.len()
        )));
    }
    let values = |c: &Candidate| -> Vec<(u64, u64)> {
        c.problem
            .rows()
            .iter()
            .map(|r| {
                let m = c.problem.tests()[r.test].measured[&r.eij];
                (m.value.to_bits(), r.sigma.to_bits())
            })
            .collect()
    };
    let first = values(&candidates[0]);
    if let Some(c) = candidates.iter().skip(1).find(|c| values(c) != first) {
        return Err(IdentError::NoData(format!(
            "{} and {} were given different measured values: their fits cannot be compared",
            candidates[0].label, c.label
        )));
    }
    let mut outcomes: Vec<CandidateOutcome> = candidates
        .into_par_iter()
        .map(|c| {
            let fit = identify(&c.problem, None);
            let (score, groups, holdout) = match &fit {
                Ok(r) => {
                    let h = if holdout && r.refusal.is_none() {
                        leave_one_centre_out(&c.problem)
                    } else {
                        None
                    };
                    (Some(Score::of(r)), group_fits(&c.problem, r), h)
                }
                Err(_) => (None, Vec::new(), None),
            };
            CandidateOutcome {
                label: c.label,
                problem: c.problem,
                fit,
                score,
                groups,
                holdout,
                rank: Rank::Failed,
                reason: String::new(),
            }
        })
        .collect();
    let preferred = outcomes
        .iter()
        .enumerate()
        .filter(|(_, o)| o.fit.as_ref().is_ok_and(|r| r.refusal.is_none()))
        .filter_map(|(i, o)| o.score.map(|s| (i, s.bic)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i);
    for (i, o) in outcomes.iter_mut().enumerate() {
        o.rank = match (&o.fit, preferred) {
            (Err(_), _) => Rank::Failed,
            (Ok(r), _) if r.refusal.is_some() => Rank::Refused,
            (Ok(_), Some(p)) if p == i => Rank::Preferred,
            (Ok(_), _) => Rank::Behind { delta_bic: 0.0 },
        };
    }
    if let Some(p) = preferred {
        let best = outcomes[p].score.map_or(0.0, |s| s.bic);
        for o in &mut outcomes {
            if let (Rank::Behind { delta_bic }, Some(s)) = (&mut o.rank, o.score) {
                *delta_bic = s.bic - best;
            }
        }
    }
    let reasons: Vec<String> = (0..outcomes.len())
        .map(|i| reason(&outcomes, i, preferred))
        .collect();
    for (o, r) in outcomes.iter_mut().zip(reasons) {
        o.reason = r;
    }
    let verdict = headline(&outcomes, preferred);
    Ok(Comparison {
        candidates: outcomes,
        preferred,
        verdict,
    })
}

/// The strength of the evidence a ΔBIC gives (Kass & Raftery 1995).
pub fn evidence(delta_bic: f64) -> &'static str {
    if delta_bic < INDISTINCT_DELTA_BIC {
        "not worth more than a bare mention"
    } else if delta_bic < 6.0 {
        "positive"
    } else if delta_bic < 10.0 {
        "strong"
    } else {
        "very strong"
    }
}

/// The verdict's first sentence.
fn headline(o: &[CandidateOutcome], preferred: Option<usize>) -> String {
    let Some(p) = preferred else {
        return "no candidate can be preferred: every fit was refused or failed (reasons below)"
            .into();
    };
    let w = &o[p];
    let Some(s) = w.score else {
        return format!("{} is preferred", w.label);
    };
    let close: Vec<&str> = o
        .iter()
        .filter(
            |c| matches!(c.rank, Rank::Behind { delta_bic } if delta_bic < INDISTINCT_DELTA_BIC),
        )
        .map(|c| c.label.as_str())
        .collect();
    let mut h = if close.is_empty() {
        format!("{} is preferred (lowest BIC)", w.label)
    } else {
        format!(
            "the data do not tell {} and {} apart (ΔBIC < {INDISTINCT_DELTA_BIC}); {} has the lowest BIC",
            w.label,
            close.join(", "),
            w.label
        )
    };
    if !s.chi2_test.passed {
        h.push_str(&format!(
            ", but it does not reproduce the data either (χ² test failed: s = {:.2} > {:.2}): no candidate explains the measurements within their uncertainty, and its factors carry that model error",
            s.chi2_test.s, s.chi2_test.s_limit
        ));
    }
    h
}

/// Parameters `w` fitted that `l` has not, with value ± standard error and 3σ interval.
fn extra_parameters(w: &IdentResult, l: Option<&IdentResult>) -> Vec<String> {
    w.parameters
        .iter()
        .filter(|p| l.is_none_or(|l| l.parameters.iter().all(|q| q.name != p.name)))
        .filter_map(|p| {
            let se = p.std_err?;
            let interval =
                super::verdict::factor_interval(p.value, se, super::settings::INTERVAL_SIGMAS)
                    .map(|i| format!(", 3σ {}", format_interval(i)))
                    .unwrap_or_default();
            Some(format!("{} {:.3} ± {:.3}{interval}", p.name, p.value, se))
        })
        .collect()
}

/// `; hold-out (leave one circle centre out): 2/3 centres predicted (χ²/dof 1.42)`.
fn holdout_words(h: &Option<CentreHoldOut>) -> String {
    let Some(h) = h else {
        return String::new();
    };
    let chi2 = h
        .chi2_per_dof()
        .map(|c| format!(", pooled χ²/dof {c:.2}"))
        .unwrap_or_default();
    format!(
        "; leaving one circle centre out, {}/{} centres predicted within their uncertainty{chi2}",
        h.passed_folds(),
        h.folds.len()
    )
}

/// Why candidate `i` is preferred or not.
fn reason(o: &[CandidateOutcome], i: usize, preferred: Option<usize>) -> String {
    let c = &o[i];
    let fit = match &c.fit {
        Err(e) => return format!("{} could not be fitted: {e}", c.label),
        Ok(r) => r,
    };
    let s = match c.score {
        Some(s) => s,
        None => return format!("{} could not be scored", c.label),
    };
    let fit_words = format!(
        "s = {:.2}, χ² test {}",
        s.chi2_test.s,
        if s.chi2_test.passed {
            "passed"
        } else {
            "FAILED"
        }
    );
    if let Some(refusal) = &fit.refusal {
        let why = match refusal {
            IdentError::AtBound {
                name, bound, max, ..
            } if bound == max && name.ends_with(".stiffness") => format!(
                ": the data drive {name} towards a rigid body — they show none of the elasticity this model adds"
            ),
            IdentError::AtBound { bound, max, .. } if bound == max => {
                ": the data want an element stiffer than the model allows — they show none of that compliance".into()
            }
            IdentError::AtBound { .. } => {
                ": the data want an element softer than the model allows — a compliance missing elsewhere in the model".into()
            }
            _ => String::new(),
        };
        return format!(
            "{} is not preferred: its fit was refused ({refusal}){why} ({fit_words})",
            c.label
        );
    }
    let Some(p) = preferred else {
        return format!("{} ({fit_words})", c.label);
    };
    let w = &o[p];
    let w_fit = w.fit.as_ref().ok();
    if i == p {
        let extra: Vec<String> = o
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != p)
            .filter_map(|(_, l)| l.fit.as_ref().ok())
            .flat_map(|l| extra_parameters(fit, Some(l)))
            .fold(Vec::new(), |mut v, x| {
                if !v.contains(&x) {
                    v.push(x);
                }
                v
            });
        let with = if extra.is_empty() {
            String::new()
        } else {
            format!(", with {}", extra.join(", "))
        };
        return format!(
            "{} has the lowest BIC ({:.1}; {fit_words}){with}{}",
            c.label,
            s.bic,
            holdout_words(&c.holdout)
        );
    }
    let delta = match c.rank {
        Rank::Behind { delta_bic } => delta_bic,
        _ => 0.0,
    };
    let evidence_words = format!(
        "ΔBIC {delta:+.1}: {} evidence for {}",
        evidence(delta),
        w.label
    );
    let extra = w_fit
        .map(|wf| extra_parameters(wf, Some(fit)))
        .unwrap_or_default();
    let with = if extra.is_empty() {
        String::new()
    } else {
        format!(", with {}", extra.join(", "))
    };
    let hold = holdout_words(&c.holdout);
    if !s.chi2_test.passed {
        let worst = c
            .groups
            .iter()
            .filter_map(|g| g.worst_eij().map(|e| (g, e)))
            .max_by(|a, b| a.1.rms_z.total_cmp(&b.1.rms_z));
        if let Some((g, e)) = worst {
            let there = w
                .groups
                .iter()
                .find(|x| x.plane == g.plane && x.position_mm == g.position_mm)
                .and_then(|x| x.eijs.iter().find(|y| y.eij == e.eij));
            let can = match there {
                Some(t) if t.rms_z <= REPRODUCED_RMS_Z => {
                    format!("{} can (rms z {:.2} there){with}", w.label, t.rms_z)
                }
                Some(t) => format!(
                    "{} comes closer (rms z {:.2} there){with}",
                    w.label, t.rms_z
                ),
                None => format!("{} is preferred{with}", w.label),
            };
            return format!(
                "{} cannot reproduce {} of the {} circles at {} (rms z {:.2} over {} tests; {fit_words}); {can}; {evidence_words}{hold}",
                c.label, e.eij, g.plane, g.position_label, e.rms_z, e.values
            );
        }
    }
    let w_k = w.score.map_or(0, |x| x.k);
    let cost = if s.k > w_k {
        format!(
            "its {} more fitted term(s) are not supported by the data",
            s.k - w_k
        )
    } else {
        "it fits less closely".into()
    };
    format!(
        "{} also reproduces the data ({fit_words}), but {cost}; {evidence_words}{hold}",
        c.label
    )
}
