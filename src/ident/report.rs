//! Outputs of an identification, one serde type per file, written and read by the same type:
//! the report JSON ([`IdentReport`], docs/commands.md keys) and the identified machine file with its
//! `[provenance]` table ([`machine_toml`], [`crate::machine::raw::RawProvenance`]).

use super::diagnosis::{
    fitted_clocks, static_groups, ClockOffsetReport, DesignReport, FittedClockReport,
    NotIdentifiableReport, StaticGroupReport, ValidationReport,
};
use super::verdict::{Chi2, Standing};
use super::{IdentResult, Method, Problem, Settings, SolverKind, StaticTerms};
use crate::axes::{Direction, Eij, EijMap, Plane};
use crate::machine::raw::{RawProvenance, RawProvenanceParameter};
use crate::machine::stiffness::StiffnessRow;
use serde::{Deserialize, Deserializer, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Provenance written into exports: what produced them and when.
#[derive(Debug, Clone, PartialEq)]
pub struct Provenance {
    /// The machine file identified.
    pub machine_file: String,
    /// The measured inputs.
    pub measured: Vec<String>,
    /// UTC time stamp (RFC 3339); from SOURCE_DATE_EPOCH when set, for reproducible outputs.
    pub date: String,
}

impl Provenance {
    /// Provenance of the machine file `machine_file` identified from `measured`, with the
    /// current (or SOURCE_DATE_EPOCH) time; an error where SOURCE_DATE_EPOCH is set but is not
    /// a time ([`utc_timestamp`]).
    pub fn now<P: AsRef<Path>>(
        machine_file: impl AsRef<Path>,
        measured: impl IntoIterator<Item = P>,
    ) -> Result<Self, SourceDateError> {
        Ok(Provenance {
            machine_file: machine_file.as_ref().display().to_string(),
            measured: measured
                .into_iter()
                .map(|p| p.as_ref().display().to_string())
                .collect(),
            date: utc_timestamp()?,
        })
    }
}

/// The latest SOURCE_DATE_EPOCH written: 9999-12-31T23:59:59Z (RFC 3339 has four-digit years).
pub(crate) const MAX_SOURCE_DATE_EPOCH: u64 = 253_402_300_799;

/// SOURCE_DATE_EPOCH is set but is not a time stamp eij can write.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("SOURCE_DATE_EPOCH={value:?}: {why}; it must be whole seconds since 1970-01-01 UTC, 0…{MAX_SOURCE_DATE_EPOCH} (unset it to use the current time)")]
pub struct SourceDateError {
    /// The variable's value.
    pub value: String,
    /// What is wrong with it.
    pub why: &'static str,
}

/// The current UTC time (RFC 3339, seconds), or, for reproducible outputs, SOURCE_DATE_EPOCH
/// where it is set (and not empty), following the reproducible-builds convention: a
/// malformed value is an error, never silently replaced by the current time.
pub fn utc_timestamp() -> Result<String, SourceDateError> {
    let time = match std::env::var_os("SOURCE_DATE_EPOCH") {
        Some(v) if !v.is_empty() => {
            let value = v.to_string_lossy().into_owned();
            let bad = |why| SourceDateError {
                value: value.clone(),
                why,
            };
            let digits = value.trim();
            if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
                return Err(bad("not a whole number of seconds"));
            }
            let s: u64 = digits
                .parse()
                .ok()
                .filter(|s| *s <= MAX_SOURCE_DATE_EPOCH)
                .ok_or_else(|| bad("after the year 9999 (milliseconds given for seconds?)"))?;
            std::time::UNIX_EPOCH + std::time::Duration::from_secs(s)
        }
        _ => std::time::SystemTime::now(),
    };
    Ok(humantime::format_rfc3339_seconds(time).to_string())
}

/// `null` read as NaN (serde_json writes NaN as `null`: a value a simulation lacks).
fn nan_values<'de, D: Deserializer<'de>>(d: D) -> Result<EijMap, D::Error> {
    let m = BTreeMap::<Eij, Option<f64>>::deserialize(d)?;
    Ok(m.into_iter()
        .map(|(k, v)| (k, v.unwrap_or(f64::NAN)))
        .collect())
}

/// As [`nan_values`], for an optional map.
fn nan_values_opt<'de, D: Deserializer<'de>>(d: D) -> Result<Option<EijMap>, D::Error> {
    let m = Option::<BTreeMap<Eij, Option<f64>>>::deserialize(d)?;
    Ok(m.map(|m| {
        m.into_iter()
            .map(|(k, v)| (k, v.unwrap_or(f64::NAN)))
            .collect()
    }))
}

/// As [`nan_values`], for a matrix.
fn nan_matrix<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vec<f64>>, D::Error> {
    let m = Vec::<Vec<Option<f64>>>::deserialize(d)?;
    Ok(m.into_iter()
        .map(|row| row.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect())
        .collect())
}

/// The report JSON of `eij identify` (docs/commands.md): parameters with standard errors and
/// correlations, costs, warnings, settings, and per test the measured and simulated EIJ before
/// and after. Keys that older reports may lack are optional for reading; `eij identify` writes
/// every one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IdentReport {
    /// Version of eij that wrote it.
    #[serde(default)]
    pub eij_version: String,
    /// UTC time stamp (RFC 3339).
    #[serde(default)]
    pub date: String,
    /// The machine file identified.
    #[serde(default)]
    pub machine: Option<String>,
    /// The measured inputs.
    #[serde(default)]
    pub measured_inputs: Vec<String>,
    /// Identified parameters, in the order given.
    pub parameters: Vec<ParameterReport>,
    /// Correlation matrix of the parameters (rows and columns in parameter order; 0 for a
    /// parameter that is not identifiable).
    #[serde(deserialize_with = "nan_matrix")]
    pub correlation: Vec<Vec<f64>>,
    /// Singular values of the weighted Jacobian ∂r/∂θ at the solution, descending.
    #[serde(default)]
    pub jacobian_singular_values: Vec<f64>,
    /// Σr² at the start.
    pub cost_initial: f64,
    /// Σr² at the solution.
    pub cost_final: f64,
    /// Σr² at the start and after every iteration (`[cost_initial, cost_final]` when absent).
    #[serde(default)]
    pub cost_history: Vec<f64>,
    /// What the cost is.
    #[serde(default)]
    pub cost_definition: String,
    /// Parameter sets simulated.
    #[serde(default)]
    pub evaluations: Option<u64>,
    /// Residual standard deviation s = √(Σr²/(m − n)).
    #[serde(default)]
    pub residual_std: Option<f64>,
    /// Number of residuals m.
    #[serde(default)]
    pub residuals: Option<usize>,
    /// Degrees of freedom of s: m − n − q (n free parameters, q static terms).
    #[serde(default)]
    pub degrees_of_freedom: Option<usize>,
    /// Iterations of the optimiser.
    #[serde(default)]
    pub iterations: Option<u64>,
    /// `accepted` (exported) or `refused` (ended on a bound or did not converge: nothing
    /// exported).
    #[serde(default)]
    pub status: Option<String>,
    /// Why refused.
    #[serde(default)]
    pub refusal: Option<String>,
    /// Warnings (also printed on standard error).
    #[serde(default)]
    pub warnings: Vec<String>,
    /// Notes (static terms not separable, reversal terms added, rejected trial steps).
    #[serde(default)]
    pub notes: Vec<String>,
    /// Trial steps that could not be simulated and were rejected.
    #[serde(default)]
    pub rejected_steps: Option<u64>,
    /// Parameters the tests cannot determine (kept at their start value), and why.
    #[serde(default)]
    pub not_identifiable: Vec<NotIdentifiableReport>,
    /// Static (acceleration-independent) terms fitted with the EIJ, per plane and circle
    /// centre.
    #[serde(default)]
    pub static_terms: Vec<StaticGroupReport>,
    /// Candidate additional tests ranked by the worst relative standard error they leave.
    #[serde(default)]
    pub experiment_design: Option<DesignReport>,
    /// Hold-out validation (`--validate`).
    #[serde(default)]
    pub validation: Option<ValidationReport>,
    /// Static terms and clock offsets that may be absorbing a model error (a failed χ² test
    /// with significant terms; [`super::mismatch`]); null when none.
    #[serde(default)]
    pub model_mismatch: Option<super::mismatch::ModelMismatch>,
    /// Clock offsets between scales and R-Test estimated by the evaluation (applied with the
    /// setting `fit_time_offset`).
    #[serde(default)]
    pub clocks: Vec<ClockOffsetReport>,
    /// Clock offsets fitted jointly with the EIJ (per folder with both directions).
    #[serde(default)]
    pub clock_offsets: Vec<FittedClockReport>,
    /// The settings of the run.
    #[serde(default)]
    pub settings: Option<SettingsReport>,
    /// The tests fitted.
    pub tests: Vec<TestReport>,
    /// The identified stiffness set, one row per axis, element and direction
    /// ([`crate::machine::stiffness`]; absent from reports of older versions).
    #[serde(default)]
    pub stiffness: Option<Vec<StiffnessRow>>,
    /// The elastic bodies: modes kept, frequencies, identified stiffness factor.
    #[serde(default)]
    pub elastic_bodies: Vec<super::stiffness::ElasticBodyReport>,
}

/// One parameter of [`IdentReport`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParameterReport {
    /// Name, e.g. `z.guideway_normal`.
    pub name: String,
    /// Start value.
    pub initial: f64,
    /// Identified value (the start value when not identifiable).
    pub identified: f64,
    /// Standard error, `null` when not identifiable.
    pub std_err: Option<f64>,
    /// Whether the tests determine it.
    #[serde(default)]
    pub identifiable: Option<bool>,
    /// Whether it ended on a bound of the factors.
    #[serde(default)]
    pub at_bound: Option<bool>,
    /// `[low, high]`: the identified value ± [`super::settings::INTERVAL_SIGMAS`] standard
    /// errors, taken in θ = 1/p and mapped to p (asymmetric; `high` null: unbounded above;
    /// [`super::verdict::factor_interval`]); null when not identifiable.
    #[serde(default)]
    pub interval_3sigma: Option<(f64, Option<f64>)>,
}

impl ParameterReport {
    /// The 3σ interval: as written, else (older reports) from the value and standard error.
    pub fn interval(&self) -> Option<(f64, Option<f64>)> {
        self.interval_3sigma.or_else(|| {
            self.std_err.and_then(|se| {
                super::verdict::factor_interval(
                    self.identified,
                    se,
                    super::settings::INTERVAL_SIGMAS,
                )
            })
        })
    }

    /// How well the tests determine it ([`Standing`]); without a standard error it is not
    /// identifiable whatever its `identifiable` key says (see also
    /// [`IdentReport::standing`]).
    pub fn standing(&self) -> Standing {
        Standing::of(
            self.identified,
            self.std_err,
            self.identifiable.unwrap_or(true),
            self.at_bound.unwrap_or(false),
        )
    }
}

/// The settings of the run in [`IdentReport`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SettingsReport {
    /// Optimiser.
    pub method: Method,
    /// How the tests were simulated during the optimisation.
    pub solver: SolverKind,
    /// Output rate of time-domain simulations, Hz.
    pub rate_hz: f64,
    /// Steady revolutions per simulated test.
    pub revolutions: u32,
    /// Lower bound of the factors.
    pub min_factor: f64,
    /// Upper bound of the factors.
    pub max_factor: f64,
    /// Iteration limit.
    pub max_iters: u64,
    /// Relative cost decrease that counts as converged.
    pub tol_cost: f64,
    /// Step in θ = 1/p that counts as converged.
    pub tol_step: f64,
    /// Gauss–Newton step left, in standard errors, that counts as converged.
    #[serde(default)]
    pub tol_noise: Option<f64>,
    /// Central-difference step, relative to θ.
    pub fd_step: f64,
    /// Smallest σ used to weight a measured value, µm·s²/m.
    pub sigma_floor_um_s2_per_m: f64,
    /// Static terms fitted with the EIJ.
    #[serde(default)]
    pub static_terms: Option<StaticTerms>,
}

impl From<&Settings> for SettingsReport {
    fn from(s: &Settings) -> Self {
        SettingsReport {
            method: s.method,
            solver: s.simulation.solver,
            rate_hz: s.simulation.rate_hz,
            revolutions: s.simulation.revolutions,
            min_factor: s.min_factor,
            max_factor: s.max_factor,
            max_iters: s.max_iters(),
            tol_cost: s.tol_cost,
            tol_step: s.tol_step,
            tol_noise: Some(s.tol_noise),
            fd_step: s.fd_step,
            sigma_floor_um_s2_per_m: s.sigma_floor,
            static_terms: Some(s.static_terms),
        }
    }
}

/// One test of [`IdentReport`]: its conditions and the measured and simulated EIJ, µm·s²/m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TestReport {
    /// Source file or table rows.
    #[serde(default)]
    pub source: Option<String>,
    /// Plane.
    pub plane: Plane,
    /// Direction.
    pub direction: Direction,
    /// Set radius, mm.
    #[serde(default)]
    pub radius_mm: Option<f64>,
    /// Set acceleration, m/s².
    pub accel_m_s2: f64,
    /// Circle frequency √(a/r)/2π, Hz.
    #[serde(default)]
    pub freq_hz: Option<f64>,
    /// Axis positions of the circle centre the test was simulated at, mm (machine axis order).
    #[serde(default)]
    pub position_mm: Option<Vec<f64>>,
    /// Measured EIJ.
    #[serde(deserialize_with = "nan_values")]
    pub measured: EijMap,
    /// Their standard errors (σ of the weighting before the floor).
    #[serde(default, deserialize_with = "nan_values")]
    pub measured_std_err: EijMap,
    /// Simulated with the starting factors.
    #[serde(deserialize_with = "nan_values")]
    pub simulated_initial: EijMap,
    /// Simulated with the identified factors.
    #[serde(deserialize_with = "nan_values")]
    pub simulated_final: EijMap,
    /// The same in the time domain (confirmation of a harmonic optimisation).
    #[serde(default, deserialize_with = "nan_values_opt")]
    pub simulated_final_time_domain: Option<EijMap>,
    /// simulated_initial / measured (measured values ≠ 0).
    #[serde(default, deserialize_with = "nan_values")]
    pub ratio_initial: EijMap,
    /// simulated_final / measured (measured values ≠ 0).
    #[serde(default, deserialize_with = "nan_values")]
    pub ratio_final: EijMap,
}

/// A report JSON that cannot be read: the key path (`tests[1].simulated_final`) and what is
/// wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("key `{key}`: {message}")]
pub struct ReportKeyError {
    /// Path of the key.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl IdentReport {
    /// The report of `result` on `problem`.
    pub fn new(problem: &Problem, result: &IdentResult, prov: &Provenance) -> IdentReport {
        let tests = problem
            .tests()
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let measured: EijMap = t.measured.value_map();
                let only_measured = |sim: &EijMap| -> EijMap {
                    measured
                        .keys()
                        .map(|p| (*p, sim.get(p).copied().unwrap_or(f64::NAN)))
                        .collect()
                };
                let ratio = |sim: &EijMap| -> EijMap {
                    measured
                        .iter()
                        .filter(|(_, m)| m.abs() > 0.0)
                        .map(|(p, m)| (*p, sim.get(p).copied().unwrap_or(f64::NAN) / m))
                        .collect()
                };
                TestReport {
                    source: Some(t.source.clone()),
                    plane: t.circle.plane,
                    direction: t.circle.direction,
                    radius_mm: Some(t.circle.radius_mm),
                    accel_m_s2: t.circle.accel_m_s2,
                    freq_hz: Some(t.circle.freq_hz()),
                    position_mm: Some(problem.position_m(i).iter().map(|v| v * 1e3).collect()),
                    measured_std_err: t.measured.std_err_map(),
                    simulated_initial: only_measured(&result.simulated_initial[i]),
                    simulated_final: only_measured(&result.simulated_final[i]),
                    simulated_final_time_domain: result
                        .simulated_final_time
                        .as_ref()
                        .map(|t| only_measured(&t[i])),
                    ratio_initial: ratio(&result.simulated_initial[i]),
                    ratio_final: ratio(&result.simulated_final[i]),
                    measured,
                }
            })
            .collect();
        let n = result.parameters.len();
        IdentReport {
            eij_version: env!("CARGO_PKG_VERSION").into(),
            date: prov.date.clone(),
            machine: Some(prov.machine_file.clone()),
            measured_inputs: prov.measured.clone(),
            parameters: result
                .parameters
                .iter()
                .map(|p| ParameterReport {
                    name: p.name.clone(),
                    initial: p.initial,
                    identified: p.value,
                    std_err: p.std_err,
                    identifiable: Some(p.identifiable),
                    at_bound: Some(p.at_bound),
                    interval_3sigma: p.std_err.and_then(|se| {
                        super::verdict::factor_interval(
                            p.value,
                            se,
                            super::settings::INTERVAL_SIGMAS,
                        )
                    }),
                })
                .collect(),
            correlation: (0..n)
                .map(|i| (0..n).map(|k| result.correlation[(i, k)]).collect())
                .collect(),
            jacobian_singular_values: result.singular_values.clone(),
            cost_initial: result.cost_initial,
            cost_final: result.cost_final,
            cost_history: result.cost_history.clone(),
            cost_definition: "sum of squared weighted residuals ((E_sim - E_meas) / sigma)^2"
                .into(),
            evaluations: Some(result.evaluations),
            residual_std: Some(result.residual_std),
            residuals: Some(result.residuals),
            degrees_of_freedom: Some(result.degrees_of_freedom),
            iterations: Some(result.iterations),
            status: Some(
                if result.refusal.is_some() {
                    "refused"
                } else {
                    "accepted"
                }
                .into(),
            ),
            refusal: result.refusal.as_ref().map(|e| e.to_string()),
            warnings: result.warnings.iter().map(ToString::to_string).collect(),
            notes: result.notes.iter().map(ToString::to_string).collect(),
            rejected_steps: Some(result.rejected_steps),
            not_identifiable: result
                .not_identifiable
                .iter()
                .map(|n| {
                    let names: Vec<String> =
                        result.parameters.iter().map(|p| p.name.clone()).collect();
                    NotIdentifiableReport::new(n, &names, result.parameters[n.index].initial)
                })
                .collect(),
            static_terms: static_groups(result),
            experiment_design: result.design.as_ref().map(Into::into),
            validation: None,
            model_mismatch: result.model_mismatch.clone(),
            clocks: Vec::new(),
            clock_offsets: fitted_clocks(result),
            settings: Some(problem.settings().into()),
            tests,
            stiffness: Some(super::stiffness::identified_table(problem, result).rows),
            elastic_bodies: super::stiffness::elastic_bodies(problem, result),
        }
    }

    /// The JSON text (pretty, with a final line end).
    pub fn to_json(&self) -> Vec<u8> {
        let mut json = serde_json::to_vec_pretty(self).unwrap_or_default();
        json.push(b'\n');
        json
    }

    /// Reads a report, naming the first missing or malformed key; a missing `cost_history` is
    /// taken as `[cost_initial, cost_final]`.
    pub fn from_json(bytes: &[u8]) -> Result<IdentReport, ReportKeyError> {
        let de = &mut serde_json::Deserializer::from_slice(bytes);
        let mut r: IdentReport = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let (line, column) = (inner.line(), inner.column());
            let text = inner.to_string();
            let text = text
                .strip_suffix(&format!(" at line {line} column {column}"))
                .unwrap_or(&text);
            // A missing field is named as a key of its own: `tests[1].simulated_final`.
            let (key, message) = match text
                .strip_prefix("missing field `")
                .and_then(|f| f.strip_suffix('`'))
            {
                Some(field) if path == "." => (field.to_string(), "missing".to_string()),
                Some(field) => (format!("{path}.{field}"), "missing".to_string()),
                None => (path, text.to_string()),
            };
            ReportKeyError {
                key,
                message: format!("{message} (line {line}, column {column})"),
            }
        })?;
        r.check()?;
        Ok(r)
    }

    /// As [`IdentReport::from_json`] from a parsed JSON value.
    pub fn from_value(value: &serde_json::Value) -> Result<IdentReport, ReportKeyError> {
        IdentReport::from_json(value.to_string().as_bytes())
    }

    /// What the types cannot say: a square correlation matrix over the parameters, a test.
    fn check(&mut self) -> Result<(), ReportKeyError> {
        let bad = |key: String, message: String| ReportKeyError { key, message };
        let n = self.parameters.len();
        if self.correlation.len() != n {
            return Err(bad(
                "correlation".into(),
                format!("{} rows for {n} parameters", self.correlation.len()),
            ));
        }
        if let Some(i) = self.correlation.iter().position(|r| r.len() != n) {
            return Err(bad(
                format!("correlation[{i}]"),
                format!("expected a row of {n} numbers"),
            ));
        }
        if self.tests.is_empty() {
            return Err(bad("tests".into(), "no tests".into()));
        }
        if self.cost_history.is_empty() {
            self.cost_history = vec![self.cost_initial, self.cost_final];
        }
        Ok(())
    }

    /// The χ² test of the fit (`None` for reports without `residual_std` and
    /// `degrees_of_freedom`, written by older versions).
    pub fn chi2(&self) -> Option<Chi2> {
        Some(Chi2::new(self.residual_std?, self.degrees_of_freedom?))
    }

    /// How well the tests determine parameter `p` ([`ParameterReport::standing`]); a parameter
    /// the report lists under `not_identifiable` is not identifiable.
    pub fn standing(&self, p: &ParameterReport) -> Standing {
        if self.not_identifiable.iter().any(|n| n.name == p.name) {
            Standing::NotIdentifiable
        } else {
            p.standing()
        }
    }

    /// The EIJ measured in at least one test, in parameter order.
    pub(crate) fn eij_parameters(&self) -> Vec<Eij> {
        let mut all: Vec<Eij> = self
            .tests
            .iter()
            .flat_map(|t| t.measured.keys().copied())
            .collect();
        all.sort();
        all.dedup();
        all
    }
}

/// The identified machine as TOML text (see [`IdentResult::machine_toml`]); `problem` is the
/// problem `result` was identified from.
pub fn machine_toml(
    problem: &Problem,
    result: &IdentResult,
    prov: &Provenance,
) -> Result<String, toml::ser::Error> {
    debug_assert_eq!(problem.tests().len(), result.simulated_final.len());
    result.machine_toml(prov)
}

/// Why an identified machine file was not written.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The fit must not be exported ([`IdentResult::accepted`]): it did not converge or ended on
    /// a bound.
    #[error("the identification is not exported: {0}")]
    Refused(#[source] Box<super::IdentError>),
    /// The machine could not be written as TOML.
    #[error("cannot write the identified machine: {0}")]
    Toml(#[from] toml::ser::Error),
    /// The file could not be written (the message names it).
    #[error(transparent)]
    Write(#[from] crate::io::WriteError),
}

impl IdentResult {
    /// The identified machine as TOML text: the machine file with the identified factors, a
    /// comment header and a `[provenance]` table saying from what and how it was identified
    /// (what `eij identify --out` writes).
    pub fn machine_toml(&self, prov: &Provenance) -> Result<String, toml::ser::Error> {
        let mut raw = self.machine.to_raw();
        raw.provenance = Some(RawProvenance {
            cost_final: self.cost_final,
            cost_initial: self.cost_initial,
            date: prov.date.clone(),
            from_machine: prov.machine_file.clone(),
            identified_by: format!("eij {}", env!("CARGO_PKG_VERSION")),
            measured: prov.measured.clone(),
            parameters: self
                .parameters
                .iter()
                .map(|q| {
                    let entry = RawProvenanceParameter {
                        identifiable: q.identifiable,
                        identified: q.value,
                        initial: q.initial,
                        std_err: q.std_err,
                    };
                    (q.name.clone(), entry)
                })
                .collect(),
            tests: self.simulated_final.len(),
        });
        raw.name = format!("{}-identified", self.machine.name());
        let body = toml::to_string_pretty(&raw)?;
        let mut header = format!(
            "# Identified by eij {} on {} from {} and {} measured input(s).\n",
            env!("CARGO_PKG_VERSION"),
            prov.date,
            prov.machine_file,
            prov.measured.len()
        );
        header.push_str("# Stiffness = catalogue value × reduction factor; identified factors:\n");
        for q in &self.parameters {
            match q.std_err {
                Some(s) => header.push_str(&format!(
                    "#   {} = {:.4} ± {:.4} (start {})\n",
                    q.name, q.value, s, q.initial
                )),
                None => header.push_str(&format!(
                    "#   {} = {} (not identifiable, unchanged)\n",
                    q.name, q.value
                )),
            }
        }
        header.push('\n');
        Ok(header + &body)
    }

    /// Writes the identified machine file ([`IdentResult::machine_toml`]) to `path`, atomically
    /// and never over one of the measured inputs named in `prov` ([`crate::io::write_atomic`]);
    /// a fit that must not be exported ([`IdentResult::refusal`]) is refused.
    pub fn write_machine_file(
        &self,
        path: impl AsRef<Path>,
        prov: &Provenance,
    ) -> Result<(), ExportError> {
        if let Some(refusal) = &self.refusal {
            return Err(ExportError::Refused(Box::new(refusal.clone())));
        }
        let text = self.machine_toml(prov)?;
        let inputs: Vec<&Path> = std::iter::once(&prov.machine_file)
            .chain(&prov.measured)
            .map(Path::new)
            .collect();
        crate::io::write_atomic(path.as_ref(), text.as_bytes(), &inputs)?;
        Ok(())
    }
}
