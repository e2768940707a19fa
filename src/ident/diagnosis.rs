//! The diagnostic parts of the identify report JSON ([`super::report::IdentReport`]): the
//! verdict, the parameters the tests cannot determine, the static terms, the ranking of
//! candidate tests and the hold-out validation. One serde type each, written and read alike.

use super::design::Design;
use super::validation::Validation;
use super::{IdentResult, NotIdentifiable};
use crate::axes::{Direction, Plane};
use crate::rtest::pooled::geometric_name;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A parameter kept at its start value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NotIdentifiableReport {
    /// Name.
    pub name: String,
    /// The parameters it cannot be separated from.
    #[serde(default)]
    pub tied_to: Vec<String>,
    /// Its predicted correlation with each of them.
    #[serde(default)]
    pub correlation: Vec<f64>,
    /// Weight of each in the null-space direction, relative to its own (relative units).
    #[serde(default)]
    pub null_direction: Vec<f64>,
    /// No test sees it at all.
    #[serde(default)]
    pub no_influence: bool,
    /// The sentence of the warning.
    pub reason: String,
}

impl NotIdentifiableReport {
    /// The report of `n` (parameter names `names`, kept at `kept_at`).
    pub fn new(n: &NotIdentifiable, names: &[String], kept_at: f64) -> Self {
        NotIdentifiableReport {
            name: names[n.index].clone(),
            tied_to: n.tied_to.iter().map(|(k, _)| names[*k].clone()).collect(),
            correlation: n.correlation.clone(),
            null_direction: n.tied_to.iter().map(|(_, w)| *w).collect(),
            no_influence: n.no_influence,
            reason: n.describe(names, kept_at),
        }
    }
}

/// The static terms of one plane at one circle-centre position, µm per mm of set position,
/// keyed `GXZ` (deviation X per mm of set position of Z).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticGroupReport {
    /// Plane.
    pub plane: Plane,
    /// Circle centre, mm.
    pub position_mm: Vec<f64>,
    /// Tests in the group.
    pub tests: usize,
    /// Whether shared terms were fitted.
    pub shared: bool,
    /// Whether reversal terms were fitted.
    pub reversal: bool,
    /// Why terms were not fitted, where they were not.
    #[serde(default)]
    pub note: Option<String>,
    /// Shared terms.
    #[serde(default)]
    pub geometric_um_per_mm: BTreeMap<String, f64>,
    /// Their standard errors.
    #[serde(default)]
    pub geometric_std_err_um_per_mm: BTreeMap<String, f64>,
    /// Reversal terms (sign of ccw; cw has the opposite).
    #[serde(default)]
    pub reversal_um_per_mm: BTreeMap<String, f64>,
    /// Their standard errors.
    #[serde(default)]
    pub reversal_std_err_um_per_mm: BTreeMap<String, f64>,
}

/// The static terms of `result` per group.
pub(crate) fn static_groups(result: &IdentResult) -> Vec<StaticGroupReport> {
    result
        .statics
        .groups
        .iter()
        .enumerate()
        .map(|(g, group)| {
            let mut r = StaticGroupReport {
                plane: group.plane,
                position_mm: group.position_m.iter().map(|v| v * 1e3).collect(),
                tests: group.tests.len(),
                shared: group.shared,
                reversal: group.reversal,
                note: group.note.as_ref().map(ToString::to_string),
                geometric_um_per_mm: BTreeMap::new(),
                geometric_std_err_um_per_mm: BTreeMap::new(),
                reversal_um_per_mm: BTreeMap::new(),
                reversal_std_err_um_per_mm: BTreeMap::new(),
            };
            for e in result
                .static_estimates
                .iter()
                .filter(|e| e.group == g && e.clock.is_none())
            {
                let (v, s) = if e.reversal {
                    (&mut r.reversal_um_per_mm, &mut r.reversal_std_err_um_per_mm)
                } else {
                    (
                        &mut r.geometric_um_per_mm,
                        &mut r.geometric_std_err_um_per_mm,
                    )
                };
                v.insert(geometric_name(e.eij), e.value_um_per_mm);
                s.insert(geometric_name(e.eij), e.std_err_um_per_mm);
            }
            r
        })
        .collect()
}

/// One ranked candidate test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateReport {
    /// Plane.
    pub plane: Plane,
    /// Direction.
    pub direction: Direction,
    /// Circle centre, mm.
    pub position_mm: Vec<f64>,
    /// Set acceleration, m/s².
    pub accel_m_s2: f64,
    /// Set radius, mm.
    pub radius_mm: f64,
    /// The largest relative standard error σ_p/p left with it added.
    pub worst_rel_std_err: f64,
    /// The parameter that has it.
    pub worst_parameter: String,
    /// Relative standard error of every parameter with it added.
    pub rel_std_err: BTreeMap<String, f64>,
}

/// The ranking of candidate additional tests.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignReport {
    /// Relative standard errors σ_p/p with the tests given.
    pub rel_std_err_now: BTreeMap<String, f64>,
    /// The largest of them.
    pub worst_rel_std_err_now: f64,
    /// Candidates evaluated.
    pub evaluated: usize,
    /// The best candidates, best first.
    pub candidates: Vec<CandidateReport>,
    /// Remarks.
    #[serde(default)]
    pub notes: Vec<String>,
}

impl From<&Design> for DesignReport {
    fn from(d: &Design) -> Self {
        let by_name = |v: &[f64]| -> BTreeMap<String, f64> {
            d.parameters
                .iter()
                .cloned()
                .zip(v.iter().copied())
                .collect()
        };
        DesignReport {
            rel_std_err_now: by_name(&d.rel_std_err_now),
            worst_rel_std_err_now: d.worst_now().0,
            evaluated: d.evaluated,
            candidates: d
                .candidates
                .iter()
                .map(|c| CandidateReport {
                    plane: c.circle.plane,
                    direction: c.circle.direction,
                    position_mm: c
                        .circle
                        .position_m
                        .as_deref()
                        .unwrap_or_default()
                        .iter()
                        .map(|v| v * 1e3)
                        .collect(),
                    accel_m_s2: c.circle.accel_m_s2,
                    radius_mm: c.circle.radius_mm,
                    worst_rel_std_err: c.worst_rel_std_err,
                    worst_parameter: c.worst_parameter.clone(),
                    rel_std_err: by_name(&c.rel_std_err),
                })
                .collect(),
            notes: d.notes.iter().map(ToString::to_string).collect(),
        }
    }
}

/// One held-out test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ValidatedTestReport {
    /// Source.
    pub source: String,
    /// Conditions.
    pub label: String,
    /// RMS of z = (E_sim − E_meas)/√(σ² + σ_pred²), σ_pred from the parameters' covariance.
    pub rms_z: f64,
    /// Largest |z|.
    pub max_abs_z: f64,
    /// RMS prediction error, µm·s²/m.
    pub rms_error_um_s2_per_m: f64,
    /// RMS measurement uncertainty, µm·s²/m.
    pub rms_sigma_um_s2_per_m: f64,
    /// RMS standard deviation of the prediction from the identified parameters' covariance,
    /// µm·s²/m (absent in reports written before it was computed).
    #[serde(default)]
    pub rms_prediction_sigma_um_s2_per_m: Option<f64>,
}

/// The hold-out validation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ValidationReport {
    /// Values compared.
    pub values: usize,
    /// Degrees of freedom.
    pub dof: usize,
    /// χ²/dof with the measurement uncertainty and the parameters' covariance
    /// ([`super::validation`]).
    pub chi2_per_dof: f64,
    /// χ²/dof with the measurement uncertainty alone (absent in older reports).
    #[serde(default)]
    pub chi2_per_dof_measurement_only: Option<f64>,
    /// Whether predicted within the measurement uncertainty.
    pub passed: bool,
    /// Per test.
    pub tests: Vec<ValidatedTestReport>,
}

impl From<&Validation> for ValidationReport {
    fn from(v: &Validation) -> Self {
        ValidationReport {
            values: v.values,
            dof: v.dof,
            chi2_per_dof: v.chi2_per_dof,
            chi2_per_dof_measurement_only: Some(v.chi2_per_dof_measurement_only),
            passed: v.passed,
            tests: v
                .tests
                .iter()
                .map(|t| ValidatedTestReport {
                    source: t.source.clone(),
                    label: t.label.clone(),
                    rms_z: t.rms_z,
                    max_abs_z: t.max_abs_z,
                    rms_error_um_s2_per_m: t.rms_error_um_s2_per_m,
                    rms_sigma_um_s2_per_m: t.rms_sigma_um_s2_per_m,
                    rms_prediction_sigma_um_s2_per_m: Some(t.rms_prediction_sigma_um_s2_per_m),
                })
                .collect(),
        }
    }
}

/// A clock offset fitted with the EIJ (see [`super::statics::Statics::with_clocks`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedClockReport {
    /// The clock (the folder of its files).
    pub clock: String,
    /// How late the external (R-Test) readings are against the internal ones, ms.
    pub external_late_ms: f64,
    /// Its standard error, ms.
    pub std_err_ms: f64,
}

/// The clock offsets fitted with the EIJ.
pub fn fitted_clocks(result: &IdentResult) -> Vec<FittedClockReport> {
    result
        .static_estimates
        .iter()
        .filter_map(|e| {
            e.clock.map(|k| FittedClockReport {
                clock: result.statics.clocks[k].clone(),
                external_late_ms: e.value_um_per_mm,
                std_err_ms: e.std_err_um_per_mm,
            })
        })
        .collect()
}

/// A clock whose offset the evaluation estimated (docs/commands.md `time_offset_ms`: internal
/// clock minus external clock; a probe logger lagging the scales by δ gives −δ).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClockOffsetReport {
    /// The clock: a folder, or a folder and its `[[test]]` `clock`.
    pub clock: String,
    /// Its tests.
    pub tests: Vec<String>,
    /// Two-system recordings (always aligned) rather than single files.
    pub two_systems: bool,
    /// The offset, ms.
    pub time_offset_ms: f64,
    /// Its standard error, ms.
    #[serde(default)]
    pub std_err_ms: Option<f64>,
    /// Whether the tests separate it from antisymmetric cross-talk.
    pub separable: bool,
    /// Whether the tests were corrected by it.
    pub applied: bool,
    /// Remarks.
    #[serde(default)]
    pub notes: Vec<String>,
}

impl From<&crate::measured::suite::ClockReport> for ClockOffsetReport {
    fn from(c: &crate::measured::suite::ClockReport) -> Self {
        ClockOffsetReport {
            clock: c.clock.clone(),
            tests: c.tests.clone(),
            two_systems: c.two_systems,
            time_offset_ms: c.offset_ms,
            std_err_ms: c.std_err_ms,
            separable: c.separable,
            applied: c.applied,
            notes: c.notes.iter().map(ToString::to_string).collect(),
        }
    }
}
