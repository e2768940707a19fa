//! Model mismatch said, not hidden: when the fit fails its χ² test and static terms or clock
//! offsets come out significant, the fitted geometry or clock may be absorbing a model error.
//!
//! Why: the static terms G (µm per mm of set position, [`super::statics`]) go with 1/a in a
//! test's EIJ, a clock offset δ with sgn(ω)/√a. An effect the model lacks — a soft foot, a
//! bending column, a joint — changes the EIJ differently at each circle centre and plane; the
//! part of it that the factors cannot take up lands, as far as its shape allows, in those
//! nuisance terms. Real geometry of a few µm on the circle gives terms of a few standard
//! errors; with a passed χ² test they are what they say. With a failed χ² test, terms beyond
//! [`MISMATCH_SIGMAS`] standard errors say that the model, not only the geometry, is off
//! (measured: a demo whose true feet are ten times softer than the model's gives s = 7.9 and
//! static terms of 5.7 standard errors where the truth has none).

use super::settings::MISMATCH_SIGMAS;
use super::{StaticEstimate, Statics};
use crate::rtest::pooled::geometric_name;
use serde::{Deserialize, Serialize};

/// One significant static term or clock offset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SignificantTerm {
    /// `GXY` (shared), `GXY reversal`, or `clock`.
    pub name: String,
    /// Where: the group (`xy @ 150,-100,0 mm`) or the clock (folder).
    #[serde(rename = "where")]
    pub place: String,
    /// Value (µm/mm; ms for a clock: external readings late).
    pub value: f64,
    /// Its standard error.
    pub std_err: f64,
    /// `um_per_mm` or `ms`.
    pub unit: String,
}

impl SignificantTerm {
    /// |value|/σ.
    pub fn sigmas(&self) -> f64 {
        (self.value / self.std_err).abs()
    }
}

/// The fitted nuisance terms beyond [`MISMATCH_SIGMAS`] of a fit that failed its χ² test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelMismatch {
    /// The threshold, standard errors.
    pub threshold_sigmas: f64,
    /// Residual standard deviation s of the fit.
    pub residual_std: f64,
    /// Significant static terms, largest |value|/σ first.
    pub static_terms: Vec<SignificantTerm>,
    /// Significant clock offsets, largest first.
    pub clock_offsets: Vec<SignificantTerm>,
}

impl ModelMismatch {
    /// The mismatch of a fit with residual standard deviation `s` whose χ² test `failed`, from
    /// its static terms and their estimates; `None` when the χ² test passed or no term is
    /// significant.
    pub fn check(
        failed: bool,
        s: f64,
        statics: &Statics,
        estimates: &[StaticEstimate],
    ) -> Option<ModelMismatch> {
        if !failed {
            return None;
        }
        let significant = |e: &&StaticEstimate| {
            e.std_err_um_per_mm > 0.0
                && e.value_um_per_mm.abs() > MISMATCH_SIGMAS * e.std_err_um_per_mm
        };
        let term = |e: &StaticEstimate| match e.clock {
            Some(k) => SignificantTerm {
                name: "clock".into(),
                place: statics.clocks[k].clone(),
                value: e.value_um_per_mm,
                std_err: e.std_err_um_per_mm,
                unit: "ms".into(),
            },
            None => SignificantTerm {
                name: format!(
                    "{}{}",
                    geometric_name(e.eij),
                    if e.reversal { " reversal" } else { "" }
                ),
                place: statics.groups[e.group].label(),
                value: e.value_um_per_mm,
                std_err: e.std_err_um_per_mm,
                unit: "um_per_mm".into(),
            },
        };
        let sorted = |clock: bool| {
            let mut v: Vec<SignificantTerm> = estimates
                .iter()
                .filter(|e| e.clock.is_some() == clock)
                .filter(significant)
                .map(term)
                .collect();
            v.sort_by(|a, b| b.sigmas().total_cmp(&a.sigmas()));
            v
        };
        let m = ModelMismatch {
            threshold_sigmas: MISMATCH_SIGMAS,
            residual_std: s,
            static_terms: sorted(false),
            clock_offsets: sorted(true),
        };
        (!m.static_terms.is_empty() || !m.clock_offsets.is_empty()).then_some(m)
    }

    /// The warning: what is significant, the largest of each kind, and what it may mean.
    pub fn warning(&self) -> String {
        let describe = |v: &[SignificantTerm], what: &str| {
            v.first().map(|t| {
                let unit = if t.unit == "ms" { "ms" } else { "µm/mm" };
                format!(
                    "{} {what} beyond {:.0}σ (largest {} {:+.4} ± {:.4} {unit}, {:.1}σ, at {})",
                    v.len(),
                    self.threshold_sigmas,
                    t.name,
                    t.value,
                    t.std_err,
                    t.sigmas(),
                    t.place
                )
            })
        };
        let parts: Vec<String> = [
            describe(&self.static_terms, "static term(s)"),
            describe(&self.clock_offsets, "clock offset(s)"),
        ]
        .into_iter()
        .flatten()
        .collect();
        format!(
            "model mismatch suspected: the χ² test failed (s = {:.2}) and {}: the fitted geometry or clock may be absorbing a model error (an effect the model lacks — a soft joint or foot, a bending body — that the factors cannot take up), not real geometry or lag; the identified factors may then be biased beyond their standard errors. Check the model, or compare candidate models on these data",
            self.residual_std,
            parts.join(" and ")
        )
    }
}
