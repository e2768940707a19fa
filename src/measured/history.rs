//! The history of one machine: several dated evaluations ("runs") lined up, each term of the
//! circle diagnosis and each EIJ over time with its standard error, and every change from the
//! first run beyond [`DRIFT_Z`] combined standard errors flagged as drift (docs/diagnosis.md).
//!
//! A run is a folder (or files) of R-Test tests whose `rtest.toml` gives their `date`, evaluated
//! and diagnosed here, or the output of `eij evaluate … --diagnose --json` (with the `date` of its
//! tests). Both are read through the same JSON, so that a run archived as JSON and the same
//! folder evaluated again line up identically.
//!
//! Per run and per plane and circle centre (a *group*):
//! * each term of each source: its part at no acceleration `geometric` ± `geometric_std_err`
//!   from [`crate::rtest::diagnosis::separate`] (the weighted mean over the group's tests where it
//!   does not grow with the acceleration), and the servo mismatch where both directions exist;
//! * each EIJ: the weighted mean over the group's tests, v̄ = Σ wᵢvᵢ / Σ wᵢ with wᵢ = 1/σᵢ²,
//!   σ(v̄) = 1/√Σ wᵢ, scaled by the Birge ratio √(χ²/(n − 1)) where the tests scatter more.
//!
//! Drift: Δ = v_k − v_first, σ_Δ = √(σ_k² + σ_first²), z = Δ/σ_Δ; drift where |z| > 3.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::conditions::epoch_s;
use super::json::TestJson;
use super::MeasuredError;

/// A change beyond this many combined standard errors is drift.
pub const DRIFT_Z: f64 = 3.0;

/// One run: where it came from and when.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunInfo {
    /// The folder or file given.
    pub source: String,
    /// Date of the measurement (ISO 8601, from `rtest.toml`).
    pub date: String,
    /// Days since the first run.
    pub days: f64,
    /// Circle tests in the run.
    pub tests: usize,
}

/// One value of a quantity in one run, and its change from the first run that has it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HistoryPoint {
    /// Index of the run in [`History::runs`].
    pub run: usize,
    /// Its date.
    pub date: String,
    /// Value.
    pub value: f64,
    /// Standard error.
    pub std_err: f64,
    /// Δ from the first run's value (`null` for the first).
    pub change: Option<f64>,
    /// √(σ² + σ_first²).
    pub change_std_err: Option<f64>,
    /// Δ / σ_Δ.
    pub z: Option<f64>,
    /// |z| > [`DRIFT_Z`].
    pub drift: bool,
}

/// One quantity over the runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QuantityHistory {
    /// Plane and circle centre: `xy @ 150,-100,0 mm`.
    pub group: String,
    /// `internal`, `structure`, `tcp` for a term; `eij` for an EIJ.
    pub source: String,
    /// Term name (`backlash_x`, `servo_mismatch`, …) or EIJ (`EXY`).
    pub name: String,
    /// Unit: `um`, `um_per_m`, `ms`, `um_s2_per_m`.
    pub unit: String,
    /// Per run that has it, in date order.
    pub points: Vec<HistoryPoint>,
    /// Some run drifted from the first.
    pub drift: bool,
    /// Some run's value lies beyond 3 standard errors of 0 (every EIJ counts).
    pub stands_out: bool,
}

impl QuantityHistory {
    /// `EXY` for an EIJ, `internal backlash_x` for a term.
    pub fn label(&self) -> String {
        if self.source == "eij" {
            self.name.clone()
        } else {
            format!("{} {}", self.source, self.name)
        }
    }
}

/// The history of one machine.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct History {
    /// The machine, where the runs name it.
    pub machine: Option<String>,
    /// The runs in date order.
    pub runs: Vec<RunInfo>,
    /// Every quantity, by group, EIJ first, then the terms by source and name.
    pub quantities: Vec<QuantityHistory>,
}

impl History {
    /// The quantities that drifted.
    pub fn drifted(&self) -> impl Iterator<Item = &QuantityHistory> {
        self.quantities.iter().filter(|q| q.drift)
    }
}

#[derive(Debug, Deserialize)]
struct Doc {
    tests: Vec<TestJson>,
    diagnosis_groups: Option<Vec<GroupJson>>,
}

#[derive(Debug, Deserialize)]
struct GroupJson {
    plane: String,
    position_mm: Option<Vec<f64>>,
    sources: BTreeMap<String, Vec<TermJson>>,
}

#[derive(Debug, Deserialize)]
struct TermJson {
    name: String,
    unit: String,
    geometric: f64,
    geometric_std_err: f64,
    servo_mismatch_ms: Option<f64>,
    servo_mismatch_std_err_ms: Option<f64>,
}

/// A quantity's key: group, source rank, source, name.
type Key = (String, usize, String, String);

/// One run read: its info, machine and values.
struct Run {
    info: RunInfo,
    epoch_s: f64,
    machine: Option<String>,
    values: BTreeMap<Key, (String, f64, f64)>,
}

fn group_name(plane: &str, position: Option<&[f64]>) -> String {
    match position {
        Some(p) => {
            let p: Vec<String> = p.iter().map(|v| crate::text::num(*v)).collect();
            format!("{plane} @ {} mm", p.join(","))
        }
        None => format!("{plane} @ circle centre not stated"),
    }
}

fn source_rank(source: &str) -> usize {
    ["eij", "internal", "structure", "tcp"]
        .iter()
        .position(|s| *s == source)
        .unwrap_or(4)
}

/// The weighted mean of `(value, std_err)` pairs with its standard error, scaled by the
/// Birge ratio where they scatter beyond their errors.
pub fn weighted_mean(values: &[(f64, f64)]) -> Option<(f64, f64)> {
    let ok: Vec<(f64, f64)> = values
        .iter()
        .copied()
        .filter(|(v, s)| v.is_finite() && s.is_finite() && *s > 0.0)
        .collect();
    if ok.is_empty() {
        return None;
    }
    let sw: f64 = ok.iter().map(|(_, s)| 1.0 / (s * s)).sum();
    let mean = ok.iter().map(|(v, s)| v / (s * s)).sum::<f64>() / sw;
    let mut se = 1.0 / sw.sqrt();
    if ok.len() > 1 {
        let chi2: f64 = ok.iter().map(|(v, s)| ((v - mean) / s).powi(2)).sum();
        se *= (chi2 / (ok.len() - 1) as f64).sqrt().max(1.0);
    }
    Some((mean, se))
}

/// Reads one run: an `eij evaluate --diagnose --json` file (`.json`), else R-Test files or
/// folders evaluated and diagnosed now.
fn read_run(path: &Path) -> Result<Run, MeasuredError> {
    let name = path.display().to_string();
    let bad = |key: &str, message: String| MeasuredError::Conditions {
        file: name.clone(),
        key: key.to_string(),
        message,
    };
    let is_json = path.is_file()
        && path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let doc: Value = if is_json {
        let bytes = super::series::read_bounded(path, crate::io::read::MAX_TEXT_BYTES)?;
        serde_json::from_slice(&bytes).map_err(|e| bad("json", format!("not valid JSON: {e}")))?
    } else {
        let inputs = super::inputs::MeasuredInputs::expand(&[path.to_path_buf()])?;
        let suite = super::suite::evaluate_tests(&inputs.tests, &Default::default())?;
        let d = super::suite::diagnose::diagnose(&suite, Default::default())?;
        let mut doc = suite.to_json_map();
        d.add_to_json(&mut doc);
        Value::Object(doc)
    };
    let doc: Doc = serde_json::from_value(doc).map_err(|e| {
        bad(
            "tests",
            format!("not the JSON of eij evaluate --diagnose --json: {e}"),
        )
    })?;
    let groups = doc.diagnosis_groups.ok_or_else(|| {
        bad(
            "diagnosis_groups",
            "missing: write the run with eij evaluate … --diagnose --json".into(),
        )
    })?;
    if doc.tests.is_empty() {
        return Err(bad("tests", "no circle test in this run".into()));
    }
    let distinct = |f: fn(&TestJson) -> Option<&String>| {
        let mut v: Vec<String> = doc.tests.iter().filter_map(f).cloned().collect();
        v.sort();
        v.dedup();
        v
    };
    let dates = distinct(|t| t.date.as_ref());
    let date = match dates.as_slice() {
        [d] if doc.tests.iter().all(|t| t.date.is_some()) => d.clone(),
        [] | [_] => {
            return Err(bad(
                "date",
                "missing: give date = YYYY-MM-DD in the rtest.toml of every test of the run".into(),
            ))
        }
        many => {
            return Err(bad(
                "date",
                format!(
                    "the run's tests have {} dates ({}): one run is one date",
                    many.len(),
                    many.join(", ")
                ),
            ))
        }
    };
    let machines = distinct(|t| t.machine.as_ref());
    if machines.len() > 1 {
        return Err(bad(
            "machine",
            format!(
                "the run's tests name {}: one run is one machine",
                machines.join(", ")
            ),
        ));
    }
    let epoch = epoch_s(&date).map_err(|m| bad("date", m))?;
    let mut values = BTreeMap::new();
    let mut eij: BTreeMap<Key, Vec<(f64, f64)>> = BTreeMap::new();
    for t in &doc.tests {
        let group = group_name(&t.circle.plane, t.position_mm.as_deref());
        for (e, v) in &t.circle.eij_um_s2_per_m {
            let se = t
                .circle
                .std_err_um_s2_per_m
                .get(e)
                .copied()
                .unwrap_or(f64::NAN);
            let key = (group.clone(), 0, "eij".to_string(), e.clone());
            eij.entry(key).or_default().push((*v, se));
        }
    }
    for (key, vs) in eij {
        if let Some((m, se)) = weighted_mean(&vs) {
            values.insert(key, ("um_s2_per_m".to_string(), m, se));
        }
    }
    for g in &groups {
        let group = group_name(&g.plane, g.position_mm.as_deref());
        for (source, terms) in &g.sources {
            let rank = source_rank(source);
            for t in terms {
                let key = |n: &str| (group.clone(), rank, source.clone(), n.to_string());
                values.insert(
                    key(&t.name),
                    (t.unit.clone(), t.geometric, t.geometric_std_err),
                );
                if let (Some(v), Some(se)) = (t.servo_mismatch_ms, t.servo_mismatch_std_err_ms) {
                    values.insert(key("servo_mismatch"), ("ms".into(), v, se));
                }
            }
        }
    }
    Ok(Run {
        info: RunInfo {
            source: name.clone(),
            date,
            days: 0.0,
            tests: doc.tests.len(),
        },
        epoch_s: epoch,
        machine: machines.into_iter().next(),
        values,
    })
}

/// Lines up the runs at `paths` (at least two) by date.
pub fn history(paths: &[impl AsRef<Path>]) -> Result<History, MeasuredError> {
    let mut runs = paths
        .iter()
        .map(|p| read_run(p.as_ref()))
        .collect::<Result<Vec<_>, _>>()?;
    let named: Vec<&Run> = runs.iter().filter(|r| r.machine.is_some()).collect();
    if let Some(other) = named.iter().find(|r| r.machine != named[0].machine) {
        return Err(MeasuredError::Conditions {
            file: other.info.source.clone(),
            key: "machine".into(),
            message: format!(
                "{} is not {} of {}: a history is one machine's",
                other.machine.as_deref().unwrap_or_default(),
                named[0].machine.as_deref().unwrap_or_default(),
                named[0].info.source
            ),
        });
    }
    let machine = named.first().and_then(|r| r.machine.clone());
    // By date; runs of one date in the order given.
    runs.sort_by(|a, b| a.epoch_s.total_cmp(&b.epoch_s));
    let t0 = runs.first().map_or(0.0, |r| r.epoch_s);
    for r in &mut runs {
        r.info.days = (r.epoch_s - t0) / 86_400.0;
    }
    let mut keys: Vec<&Key> = runs.iter().flat_map(|r| r.values.keys()).collect();
    keys.sort();
    keys.dedup();
    let mut quantities = Vec::new();
    for key in keys {
        let mut points: Vec<HistoryPoint> = Vec::new();
        let mut unit = String::new();
        for (i, r) in runs.iter().enumerate() {
            let Some((u, v, se)) = r.values.get(key) else {
                continue;
            };
            unit.clone_from(u);
            let first = points.first().map(|p| (p.value, p.std_err));
            let (change, change_se) = match first {
                Some((v0, se0)) => (Some(v - v0), Some(se.hypot(se0))),
                None => (None, None),
            };
            let z = change.zip(change_se).map(|(d, s)| d / s);
            points.push(HistoryPoint {
                run: i,
                date: r.info.date.clone(),
                value: *v,
                std_err: *se,
                change,
                change_std_err: change_se,
                z,
                drift: z.is_some_and(|z| z.abs() > DRIFT_Z),
            });
        }
        let (group, _, source, name) = key.clone();
        let stands_out = source == "eij" || points.iter().any(|p| p.value.abs() > 3.0 * p.std_err);
        quantities.push(QuantityHistory {
            drift: points.iter().any(|p| p.drift),
            group,
            source,
            name,
            unit,
            points,
            stands_out,
        });
    }
    Ok(History {
        machine,
        runs: runs.into_iter().map(|r| r.info).collect(),
        quantities,
    })
}
