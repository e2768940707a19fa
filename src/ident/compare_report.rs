//! The report JSON of a model comparison (`eij compare --report`, docs/commands.md): the verdict,
//! per candidate its criteria, groups, hold-out and the full identification report.

use super::compare::{Comparison, Rank};
use super::groups::GroupFit;
use super::holdout::CentreHoldOut;
use super::report::{IdentReport, Provenance};
use crate::axes::Plane;
use serde::{Deserialize, Serialize};

/// What the criteria are, written into every report.
pub const CRITERION: &str = "BIC = chi2 + k ln m, AIC = chi2 + 2k; chi2 = sum of squared weighted residuals at the solution, m = weighted residuals, k = free parameters + static terms + clock offsets; the accepted candidate with the lowest BIC is preferred";

/// The comparison report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompareReport {
    /// Version of eij that wrote it.
    pub eij_version: String,
    /// UTC time stamp (RFC 3339).
    pub date: String,
    /// The measured inputs every candidate was fitted to.
    pub measured_inputs: Vec<String>,
    /// m: weighted residuals (the same for every candidate).
    pub residuals: usize,
    /// What BIC and AIC are ([`CRITERION`]).
    pub criterion: String,
    /// Label of the preferred candidate, null when none could be preferred.
    pub preferred: Option<String>,
    /// Whether the preferred candidate passes its χ² test (reproduces the data).
    pub reproduced: bool,
    /// The verdict's first sentence.
    pub verdict: String,
    /// The candidates in the order given.
    pub candidates: Vec<CandidateReport>,
}

/// One candidate of [`CompareReport`]; the numbers are null where the fit failed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateReport {
    /// Its label (the machine's name).
    pub label: String,
    /// The machine file.
    pub machine_file: String,
    /// `preferred`, `behind` (accepted, higher BIC), `refused` or `failed`.
    pub status: String,
    /// Why it is preferred or not, in words.
    pub reason: String,
    /// The error of a failed fit.
    pub error: Option<String>,
    /// χ² = Σr² at the solution.
    pub chi2: Option<f64>,
    /// Residual standard deviation s.
    pub residual_std: Option<f64>,
    /// Degrees of freedom of s.
    pub degrees_of_freedom: Option<usize>,
    /// The largest s that passes the χ² test.
    pub s_limit: Option<f64>,
    /// Whether the χ² test passed.
    pub chi2_passed: Option<bool>,
    /// Parameters fitted.
    pub free_parameters: Option<usize>,
    /// Static terms fitted.
    pub static_terms: Option<usize>,
    /// Clock offsets fitted.
    pub clock_offsets: Option<usize>,
    /// k = free parameters + static terms + clock offsets.
    pub k: Option<usize>,
    /// χ² + k ln m.
    pub bic: Option<f64>,
    /// χ² + 2k.
    pub aic: Option<f64>,
    /// BIC − BIC of the preferred candidate.
    pub delta_bic: Option<f64>,
    /// AIC − AIC of the preferred candidate.
    pub delta_aic: Option<f64>,
    /// The group and EIJ it reproduces worst.
    pub worst_group: Option<GroupReport>,
    /// Per plane and circle centre.
    pub groups: Vec<GroupReport>,
    /// Leave one circle centre out.
    pub holdout: Option<HoldOutReport>,
    /// The identification (keys as `eij identify --report`).
    pub identify_report: Option<IdentReport>,
}

/// One plane and circle centre of a candidate's fit (z with the static terms removed).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupReport {
    /// Plane.
    pub plane: Plane,
    /// Circle centre, mm.
    pub position_mm: Vec<f64>,
    /// Tests.
    pub tests: usize,
    /// Values.
    pub values: usize,
    /// RMS z over its values.
    pub rms_z: f64,
    /// The EIJ with the largest RMS z.
    pub worst_eij: String,
    /// Its RMS z.
    pub worst_eij_rms_z: f64,
}

impl From<&GroupFit> for GroupReport {
    fn from(g: &GroupFit) -> Self {
        let worst = g.worst_eij();
        GroupReport {
            plane: g.plane,
            position_mm: g.position_mm.clone(),
            tests: g.tests,
            values: g.values,
            rms_z: g.rms_z,
            worst_eij: worst.map(|e| e.eij.name()).unwrap_or_default(),
            worst_eij_rms_z: worst.map_or(0.0, |e| e.rms_z),
        }
    }
}

/// Leave one circle centre out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HoldOutReport {
    /// Every centre predicted within its uncertainty.
    pub passed: bool,
    /// Centres predicted within their uncertainty.
    pub passed_folds: usize,
    /// χ²/dof pooled over the validated folds.
    pub chi2_per_dof: Option<f64>,
    /// One per circle centre.
    pub folds: Vec<FoldReport>,
}

/// One held-out circle centre.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FoldReport {
    /// The centre, mm.
    pub position_mm: Vec<f64>,
    /// Its tests.
    pub tests: usize,
    /// Why it was not validated (the fit without it was refused or failed); null when it was.
    pub refusal: Option<String>,
    /// Values predicted.
    pub values: Option<usize>,
    /// Degrees of freedom.
    pub dof: Option<usize>,
    /// χ²/dof with the measurement's and the parameters' uncertainty.
    pub chi2_per_dof: Option<f64>,
    /// Predicted within its uncertainty.
    pub passed: bool,
}

impl From<&CentreHoldOut> for HoldOutReport {
    fn from(h: &CentreHoldOut) -> Self {
        HoldOutReport {
            passed: h.passed(),
            passed_folds: h.passed_folds(),
            chi2_per_dof: h.chi2_per_dof(),
            folds: h
                .folds
                .iter()
                .map(|f| {
                    let v = f.outcome.as_ref().ok();
                    FoldReport {
                        position_mm: f.position_mm.clone(),
                        tests: f.tests,
                        refusal: f.outcome.as_ref().err().cloned(),
                        values: v.map(|v| v.values),
                        dof: v.map(|v| v.dof),
                        chi2_per_dof: v.map(|v| v.chi2_per_dof),
                        passed: f.passed(),
                    }
                })
                .collect(),
        }
    }
}

impl CompareReport {
    /// The report of `c`, each candidate with its provenance (machine file, measured inputs,
    /// date) in the order of the candidates.
    pub fn new(c: &Comparison, provenance: &[Provenance]) -> CompareReport {
        let best = c.winner().and_then(|w| w.score);
        let candidates = c
            .candidates
            .iter()
            .zip(provenance)
            .map(|(o, prov)| {
                let s = o.score;
                let status = match o.rank {
                    Rank::Preferred => "preferred",
                    Rank::Behind { .. } => "behind",
                    Rank::Refused => "refused",
                    Rank::Failed => "failed",
                };
                let worst = o
                    .groups
                    .iter()
                    .max_by(|a, b| {
                        let z = |g: &GroupFit| g.worst_eij().map_or(0.0, |e| e.rms_z);
                        z(a).total_cmp(&z(b))
                    })
                    .map(GroupReport::from);
                CandidateReport {
                    label: o.label.clone(),
                    machine_file: prov.machine_file.clone(),
                    status: status.into(),
                    reason: o.reason.clone(),
                    error: o.fit.as_ref().err().map(|e| e.to_string()),
                    chi2: s.map(|s| s.chi2),
                    residual_std: s.map(|s| s.chi2_test.s),
                    degrees_of_freedom: s.map(|s| s.chi2_test.dof),
                    s_limit: s.map(|s| s.chi2_test.s_limit),
                    chi2_passed: s.map(|s| s.chi2_test.passed),
                    free_parameters: s.map(|s| s.free_parameters),
                    static_terms: s.map(|s| s.static_terms),
                    clock_offsets: s.map(|s| s.clock_offsets),
                    k: s.map(|s| s.k),
                    bic: s.map(|s| s.bic),
                    aic: s.map(|s| s.aic),
                    delta_bic: s.zip(best).map(|(s, b)| s.bic - b.bic),
                    delta_aic: s.zip(best).map(|(s, b)| s.aic - b.aic),
                    worst_group: worst,
                    groups: o.groups.iter().map(Into::into).collect(),
                    holdout: o.holdout.as_ref().map(Into::into),
                    identify_report: o
                        .fit
                        .as_ref()
                        .ok()
                        .map(|r| IdentReport::new(&o.problem, r, prov)),
                }
            })
            .collect();
        let first = provenance.first();
        CompareReport {
            eij_version: env!("CARGO_PKG_VERSION").into(),
            date: first.map(|p| p.date.clone()).unwrap_or_default(),
            measured_inputs: first.map(|p| p.measured.clone()).unwrap_or_default(),
            residuals: c.candidates[0].problem.rows().len(),
            criterion: CRITERION.into(),
            preferred: c.winner().map(|w| w.label.clone()),
            reproduced: c.reproduced(),
            verdict: c.verdict.clone(),
            candidates,
        }
    }

    /// The JSON text (pretty, with a final line end).
    pub fn to_json(&self) -> Vec<u8> {
        let mut json = serde_json::to_vec_pretty(self).unwrap_or_default();
        json.push(b'\n');
        json
    }

    /// Reads a report, naming the first key that is missing or malformed
    /// (`candidates[1].bic: invalid type …`); the identification reports inside are checked as
    /// [`IdentReport::from_json`] checks one.
    pub fn from_json(bytes: &[u8]) -> Result<CompareReport, String> {
        let de = &mut serde_json::Deserializer::from_slice(bytes);
        let r: CompareReport = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            format!("key `{path}`: {}", e.into_inner())
        })?;
        for (i, c) in r.candidates.iter().enumerate() {
            if let Some(id) = &c.identify_report {
                let value = serde_json::to_value(id).map_err(|e| e.to_string())?;
                IdentReport::from_value(&value)
                    .map_err(|e| format!("candidates[{i}].identify_report: {e}"))?;
            }
        }
        Ok(r)
    }
}
