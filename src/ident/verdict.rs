//! How to read an identification: how well the tests determine each parameter, and whether
//! the fit passes its χ² test. One rule for the console (`eij identify`) and the HTML report
//! (`eij report`), so that neither calls a factor of 9.998 ± 86 "identified".
//!
//! A parameter's standing follows from its relative standard error σ_p/p:
//!
//! | standing | rule |
//! | --- | --- |
//! | not identifiable | the tests cannot determine it (no influence, or tied to others): kept at its start value, no standard error |
//! | on a bound | ended within [`super::settings::AT_BOUND_REL`] of a bound of the factors: the data want a value outside |
//! | not determined | σ_p/p > [`NOT_IDENTIFIABLE_REL_STD_ERR`] (100 %): the standard error exceeds the value itself |
//! | weak | σ_p/p > [`WEAK_REL_STD_ERR`] (50 %) |
//! | loose | σ_p/p > [`DETERMINED_REL_STD_ERR`] (10 %) |
//! | determined | σ_p/p ≤ 10 % |
//!
//! The χ² test: with honest measurement uncertainties σ, s² = Σr²/dof scatters about 1 with a
//! standard deviation √(2/dof); the fit fails when s² > 1 + [`CHI2_SIGMAS`]·√(2/dof) (the
//! model cannot reproduce the measured EIJ within their uncertainty, and the standard errors,
//! scaled by s, do not cover that model error).

use super::settings::{
    BODY_PLAUSIBLE_MAX, BODY_PLAUSIBLE_MIN, CHI2_SIGMAS, DETERMINED_REL_STD_ERR, INTERVAL_SIGMAS,
    NOT_IDENTIFIABLE_REL_STD_ERR, PLAUSIBLE_MAX, PLAUSIBLE_MIN, WEAK_REL_STD_ERR,
};

/// How well the tests determine one parameter (see the module docs for the rules).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Standing {
    /// Kept at its start value: the tests cannot determine it.
    NotIdentifiable,
    /// Ended on a bound of the factors.
    OnBound,
    /// Standard error above the value.
    NotDetermined {
        /// σ_p/p.
        rel: f64,
    },
    /// Standard error above half the value.
    Weak {
        /// σ_p/p.
        rel: f64,
    },
    /// Standard error above a tenth of the value.
    Loose {
        /// σ_p/p.
        rel: f64,
    },
    /// Standard error at most a tenth of the value.
    Determined {
        /// σ_p/p.
        rel: f64,
    },
}

impl Standing {
    /// The standing of a parameter identified as `value` ± `std_err` (`None`: not
    /// identifiable), `identifiable` and `at_bound` as the identification says.
    pub fn of(value: f64, std_err: Option<f64>, identifiable: bool, at_bound: bool) -> Standing {
        let Some(se) = std_err.filter(|_| identifiable) else {
            return Standing::NotIdentifiable;
        };
        if at_bound {
            return Standing::OnBound;
        }
        let rel = if value != 0.0 {
            (se / value).abs()
        } else {
            f64::INFINITY
        };
        // NaN (a standard error that could not be computed) counts as not determined.
        if rel.is_nan() || rel > NOT_IDENTIFIABLE_REL_STD_ERR {
            Standing::NotDetermined { rel }
        } else if rel > WEAK_REL_STD_ERR {
            Standing::Weak { rel }
        } else if rel > DETERMINED_REL_STD_ERR {
            Standing::Loose { rel }
        } else {
            Standing::Determined { rel }
        }
    }

    /// The word for tables: `determined`, `loose`, `weak`, `NOT determined`, `NOT identifiable`,
    /// `ON A BOUND`; the last three in capitals because the value must not be used.
    pub fn label(self) -> &'static str {
        match self {
            Standing::NotIdentifiable => "NOT identifiable",
            Standing::OnBound => "ON A BOUND",
            Standing::NotDetermined { .. } => "NOT determined",
            Standing::Weak { .. } => "weak",
            Standing::Loose { .. } => "loose",
            Standing::Determined { .. } => "determined",
        }
    }

    /// The relative standard error σ_p/p, where there is one.
    pub fn rel_std_err(self) -> Option<f64> {
        match self {
            Standing::NotDetermined { rel }
            | Standing::Weak { rel }
            | Standing::Loose { rel }
            | Standing::Determined { rel } => Some(rel),
            Standing::NotIdentifiable | Standing::OnBound => None,
        }
    }

    /// Whether the value may be used as identified (determined or loose).
    pub fn usable(self) -> bool {
        matches!(self, Standing::Determined { .. } | Standing::Loose { .. })
    }

    /// One line that explains the words of [`Standing::label`].
    pub fn legend() -> String {
        format!(
            "standing from the relative standard error σ/value: determined ≤ {:.0} %, loose ≤ {:.0} %, weak ≤ {:.0} %, NOT determined above; NOT identifiable = the tests cannot determine it (kept at its start value); ON A BOUND = the data want a value outside the bounds",
            100.0 * DETERMINED_REL_STD_ERR,
            100.0 * WEAK_REL_STD_ERR,
            100.0 * NOT_IDENTIFIABLE_REL_STD_ERR
        )
    }
}

/// Why an identified factor is implausible. A reduction factor on catalogue data
/// (`<axis>.guideway…`, `<axis>.screw`) is plausible in [[`PLAUSIBLE_MIN`], [`PLAUSIBLE_MAX`]];
/// an elastic body's stiffness factor (`<body>.stiffness`) in [[`BODY_PLAUSIBLE_MIN`],
/// [`BODY_PLAUSIBLE_MAX`]] around its FE model. A factor is implausible only when its whole
/// [`INTERVAL_SIGMAS`] (3σ) interval ([`factor_interval`], taken in 1/p) lies outside that range:
/// far from it beyond its uncertainty. A factor of 1.0003 ± 0.0010 (interval [0.9973, 1.0033])
/// may well be 1 and is no alarm; 1.0300 ± 0.0010 ([1.0211, 1.0392]) is stiffer than the
/// catalogue beyond doubt.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Implausible {
    /// A reduction factor above [`PLAUSIBLE_MAX`]: stiffer than the catalogue.
    StifferThanCatalogue,
    /// A reduction factor below [`PLAUSIBLE_MIN`]: more than ten times softer.
    FarSofterThanCatalogue,
    /// A body stiffness factor below [`BODY_PLAUSIBLE_MIN`]: far softer than its FE model.
    SofterThanFeModel,
    /// A body stiffness factor above [`BODY_PLAUSIBLE_MAX`]: far stiffer than its FE model.
    StifferThanFeModel,
}

impl Implausible {
    /// Whether the factor `value` ± `std_err` of parameter `name` is implausible, and why: its
    /// [`INTERVAL_SIGMAS`] interval lies wholly above or below the plausible range (without
    /// a standard error, the value alone is judged). The kind of factor follows from the name
    /// (`<body>.stiffness` is an elastic body's).
    pub fn of(name: &str, value: f64, std_err: Option<f64>) -> Option<Implausible> {
        let (low, high) = factor_interval(value, std_err.unwrap_or(0.0), INTERVAL_SIGMAS)
            .unwrap_or((value, Some(value)));
        let above = |limit: f64| low > limit;
        let below = |limit: f64| high.is_some_and(|h| h < limit);
        if name.ends_with(".stiffness") {
            if below(BODY_PLAUSIBLE_MIN) {
                Some(Implausible::SofterThanFeModel)
            } else if above(BODY_PLAUSIBLE_MAX) {
                Some(Implausible::StifferThanFeModel)
            } else {
                None
            }
        } else if above(PLAUSIBLE_MAX) {
            Some(Implausible::StifferThanCatalogue)
        } else if below(PLAUSIBLE_MIN) {
            Some(Implausible::FarSofterThanCatalogue)
        } else {
            None
        }
    }

    /// A short remark for tables, e.g. `stiffer than the catalogue`.
    pub fn remark(self) -> &'static str {
        match self {
            Implausible::StifferThanCatalogue => "stiffer than the catalogue",
            Implausible::FarSofterThanCatalogue => "more than ten times softer than the catalogue",
            Implausible::SofterThanFeModel => {
                "more than twice as soft as its FE model: the FE model or its joints are wrong"
            }
            Implausible::StifferThanFeModel => {
                "more than twice as stiff as its FE model: the FE model or its joints are wrong"
            }
        }
    }

    /// The warning for parameter `name` identified as `value` ± `std_err`.
    pub fn warning(self, name: &str, value: f64, std_err: Option<f64>) -> String {
        let at = match std_err.and_then(|s| {
            factor_interval(value, s, INTERVAL_SIGMAS).map(|i| (s, format_interval(i)))
        }) {
            Some((s, interval)) => format!("{name} = {value:.4} ± {s:.4} (3σ interval {interval})"),
            None => format!("{name} = {value:.4}"),
        };
        match self {
            Implausible::StifferThanCatalogue => format!(
                "{at} lies above {PLAUSIBLE_MAX} beyond its uncertainty: stiffer than its catalogue data, implausible for a reduction factor (a compliance missing elsewhere in the model, or a data problem)"
            ),
            Implausible::FarSofterThanCatalogue => format!(
                "{at} lies below {PLAUSIBLE_MIN} beyond its uncertainty: more than ten times softer than its catalogue data, implausible (a compliance missing elsewhere in the model, or a data problem)"
            ),
            Implausible::SofterThanFeModel => format!(
                "{at} lies below {BODY_PLAUSIBLE_MIN} beyond its uncertainty: the body is more than twice as soft as its FE model, far beyond what its material allows: the FE model (sections, mesh, material) or the joints that hold the body (bolted flanges, feet, attachments) are likely wrong, or a compliance is missing elsewhere in the model"
            ),
            Implausible::StifferThanFeModel => format!(
                "{at} lies above {BODY_PLAUSIBLE_MAX} beyond its uncertainty: the body is more than twice as stiff as its FE model, far beyond what its material allows: the FE model (sections, mesh, material) or the joints that hold the body are likely wrong, or the other compliances of the model are too large"
            ),
        }
    }
}

/// Whether the identified factor `value` ± `std_err` of parameter `name` is implausible
/// ([`Implausible::of`]).
pub fn implausible(name: &str, value: f64, std_err: Option<f64>) -> bool {
    Implausible::of(name, value, std_err).is_some()
}

/// The interval p ∈ [low, high] of a factor identified as `value` ± `std_err`, `k` standard
/// errors wide, taken where the fit is linear — in the compliance θ = 1/p, σ_θ = σ_p·θ²
/// (the delta method the standard error came from) — and mapped back:
/// low = 1/(θ + k·σ_θ), high = 1/(θ − k·σ_θ). Asymmetric: a loosely determined factor of
/// 0.5 ± 0.1 (σ_θ = 0.4) spans [0.31, 1.25] at 3σ, not 0.5 ± 0.3. `high` is `None` (unbounded)
/// when θ − k·σ_θ ≤ 0: the data cannot exclude an element that does not yield at all. `None`
/// for a value that is not positive or a standard error that is not finite.
pub fn factor_interval(value: f64, std_err: f64, k: f64) -> Option<(f64, Option<f64>)> {
    if !(value > 0.0 && std_err.is_finite() && std_err >= 0.0) {
        return None;
    }
    let theta = 1.0 / value;
    let sigma_theta = std_err * theta * theta;
    let low = 1.0 / (theta + k * sigma_theta);
    let upper = theta - k * sigma_theta;
    Some((low, (upper > 0.0).then(|| 1.0 / upper)))
}

/// `[0.316, 0.529]` or `[0.316, ∞)`.
pub fn format_interval(interval: (f64, Option<f64>)) -> String {
    match interval.1 {
        Some(high) => format!("[{:.4}, {:.4}]", interval.0, high),
        None => format!("[{:.4}, ∞)", interval.0),
    }
}

/// The χ² test of a fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chi2 {
    /// Residual standard deviation s = √(Σr²/dof).
    pub s: f64,
    /// Degrees of freedom m − n − q.
    pub dof: usize,
    /// The largest s that passes.
    pub s_limit: f64,
    /// s ≤ s_limit.
    pub passed: bool,
}

impl Chi2 {
    /// The test of residual standard deviation `s` over `dof` degrees of freedom.
    pub fn new(s: f64, dof: usize) -> Chi2 {
        let s_limit = (1.0 + CHI2_SIGMAS * (2.0 / dof.max(1) as f64).sqrt()).sqrt();
        Chi2 {
            s,
            dof,
            s_limit,
            passed: s <= s_limit,
        }
    }

    /// `passed: s = 0.949 ≤ 1.196 over 172 degrees of freedom: …` or `FAILED: …`.
    pub fn describe(&self) -> String {
        if self.passed {
            format!(
                "passed: s = {:.3} ≤ {:.3} over {} degrees of freedom: the model reproduces the measured EIJ within their uncertainty",
                self.s, self.s_limit, self.dof
            )
        } else {
            format!(
                "FAILED: s = {:.3} > {:.3} over {} degrees of freedom: the model cannot reproduce the measured EIJ within their uncertainty, and the standard errors do not cover that model error",
                self.s, self.s_limit, self.dof
            )
        }
    }
}
