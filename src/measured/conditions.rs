//! Test conditions of R-Test files that the series themselves do not carry, stated once per
//! folder in `rtest.toml` (docs/measurement-files.md): the set radius and circle-centre
//! position, how the files name their columns and in which unit (`[columns]`), and per-test
//! entries (`[[test]]`) with their own conditions, including tests recorded by two systems
//! (an `internal` and an `external` file with their own clocks), folders of such recordings
//! paired by file name or recording order (`[[pairing]]`), internal readings in absolute
//! machine coordinates (`internal_coordinates`); the tolerances the tests are judged against
//! (`[tolerances]`) and the settings of their diagnosis (`[diagnosis]`).

use super::entries::{
    check_position, check_radius, pairing_entry, test_entry, RawPairing, RawTest,
};
pub use super::entries::{Coordinates, DataFiles, Pairing, TestEntry};
use super::error::MeasuredError;
use super::layout::{ColumnEntry, ColumnMap};
use crate::rtest::diagnosis::tolerance::Tolerances;
use crate::rtest::diagnosis::DiagnosisOptions;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The file of a folder that states the conditions of the R-Test files in it.
pub(crate) const CONDITIONS_FILE: &str = "rtest.toml";

/// Most tests one command reads (files named, found in folders and in `[[test]]` tables).
pub(crate) const MAX_TESTS: usize = 10_000;

/// Conditions of the circle tests of one folder (`rtest.toml`); absent keys are unknown.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TestConditions {
    /// Set radius of the circles, mm (0 < r ≤ 3, the R-Test range).
    pub radius_mm: Option<f64>,
    /// Axis positions of the circle centre, mm, in the machine's axis order.
    pub position_mm: Option<Vec<f64>>,
    /// How the files name the contract columns and in which unit (`[columns]`).
    pub columns: ColumnMap,
    /// `[columns]` with `[internal_columns]` over it: the map of the internal files of tests
    /// recorded by two systems.
    pub internal_columns: ColumnMap,
    /// `[columns]` with `[external_columns]` over it: the map of their external files.
    pub external_columns: ColumnMap,
    /// How the internal readings are given (`internal_coordinates`; absent: relative to the
    /// circle centre).
    pub internal_coordinates: Option<Coordinates>,
    /// The `[[test]]` entries, in file order.
    pub tests: Vec<TestEntry>,
    /// The `[[pairing]]` entries, in file order.
    pub pairings: Vec<Pairing>,
    /// Limits on G and on the diagnosis' terms (`[tolerances]`, docs/diagnosis.md).
    pub tolerances: Tolerances,
    /// Settings of the diagnosis (`[diagnosis]`).
    pub diagnosis: DiagnosisSettings,
    /// Machine, date, instrument and temperature of the measurement (top-level keys).
    pub session: Session,
    /// The `rtest.toml` these conditions come from, if any.
    pub file: Option<PathBuf>,
}

/// `[diagnosis]` of `rtest.toml`: what the circle diagnosis needs to know about the machine;
/// absent keys take [`DiagnosisOptions`]' defaults.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiagnosisSettings {
    /// Pitch of the cyclic error (screw lead, scale period), mm.
    pub cyclic_pitch_mm: Option<f64>,
    /// Harmonics of the pitch fitted, 1 to 5.
    pub cyclic_harmonics: Option<usize>,
    /// Decay time of a reversal spike, ms.
    pub spike_decay_ms: Option<f64>,
}

impl DiagnosisSettings {
    /// These settings over `self`'s unset keys `under` (e.g. the command line's over a
    /// folder's).
    pub fn over(self, under: DiagnosisSettings) -> DiagnosisSettings {
        DiagnosisSettings {
            cyclic_pitch_mm: self.cyclic_pitch_mm.or(under.cyclic_pitch_mm),
            cyclic_harmonics: self.cyclic_harmonics.or(under.cyclic_harmonics),
            spike_decay_ms: self.spike_decay_ms.or(under.spike_decay_ms),
        }
    }

    /// The options of the diagnosis, defaults where unset.
    pub fn options(self) -> DiagnosisOptions {
        let d = DiagnosisOptions::default();
        DiagnosisOptions {
            cyclic_pitch_mm: self.cyclic_pitch_mm,
            cyclic_harmonics: self.cyclic_harmonics.unwrap_or(d.cyclic_harmonics),
            spike_decay_ms: self.spike_decay_ms.unwrap_or(d.spike_decay_ms),
        }
    }

    /// Checks the values; the error names the key (`cyclic_pitch_mm`, …).
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        let positive = |v: Option<f64>, key: &'static str, max: f64| match v {
            Some(x) if !(x.is_finite() && x > 0.0 && x <= max) => Err((
                key,
                format!(
                    "{} must lie in (0, {}]",
                    crate::text::num(x),
                    crate::text::num(max)
                ),
            )),
            _ => Ok(()),
        };
        positive(self.cyclic_pitch_mm, "cyclic_pitch_mm", 1e3)?;
        positive(self.spike_decay_ms, "spike_decay_ms", 1e3)?;
        match self.cyclic_harmonics {
            Some(h) if !(1..=5).contains(&h) => {
                Err(("cyclic_harmonics", format!("{h} must lie in 1 to 5")))
            }
            _ => Ok(()),
        }
    }
}

/// What `rtest.toml` says about the measurement session, for the certificate and the history:
/// `machine`, `date` (a TOML date or date-time, or a string `YYYY-MM-DD[THH:MM[:SS]][Z]`),
/// `instrument` and the ambient `temperature_c`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Session {
    /// Machine name or serial number.
    pub machine: Option<String>,
    /// Date (and time) of the measurement, as written (ISO 8601).
    pub date: Option<String>,
    /// The measuring instrument (R-Test, probe serial number, …).
    pub instrument: Option<String>,
    /// Ambient temperature, °C.
    pub temperature_c: Option<f64>,
}

impl Session {
    /// Seconds since 1970-01-01T00:00:00Z of [`Session::date`] (a date alone is midnight UTC,
    /// a time without offset UTC).
    pub fn epoch_s(&self) -> Option<f64> {
        self.date.as_deref().and_then(|d| epoch_s(d).ok())
    }
}

/// Seconds since 1970-01-01T00:00:00Z of an ISO 8601 date or date-time (RFC 3339, the offset
/// optional: UTC).
pub(crate) fn epoch_s(date: &str) -> Result<f64, String> {
    let full = if date.len() == 10 {
        format!("{date}T00:00:00Z")
    } else if date.ends_with('Z') {
        date.to_string()
    } else {
        format!("{date}Z")
    };
    let t = humantime::parse_rfc3339_weak(&full)
        .or_else(|_| humantime::parse_rfc3339(&full))
        .map_err(|e| {
            format!("{date}: not a date (expected YYYY-MM-DD or YYYY-MM-DDTHH:MM:SS, UTC): {e}")
        })?;
    t.duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .map_err(|_| format!("{date}: before 1970"))
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConditions {
    radius_mm: Option<f64>,
    position_mm: Option<Vec<f64>>,
    columns: Option<BTreeMap<String, ColumnEntry>>,
    internal_columns: Option<BTreeMap<String, ColumnEntry>>,
    external_columns: Option<BTreeMap<String, ColumnEntry>>,
    internal_coordinates: Option<String>,
    #[serde(default)]
    test: Vec<RawTest>,
    #[serde(default)]
    pairing: Vec<RawPairing>,
    tolerances: Option<toml::Table>,
    diagnosis: Option<DiagnosisSettings>,
    machine: Option<String>,
    date: Option<toml::Value>,
    instrument: Option<String>,
    temperature_c: Option<f64>,
}

impl TestConditions {
    /// The conditions of `file`: the `rtest.toml` in its folder, or none.
    pub fn of_file(file: &Path) -> Result<TestConditions, MeasuredError> {
        Self::of_folder(&folder_of(file))
    }

    /// The conditions of the files in `dir`: its `rtest.toml`, or none.
    pub fn of_folder(dir: &Path) -> Result<TestConditions, MeasuredError> {
        let path = dir.join(CONDITIONS_FILE);
        if std::fs::symlink_metadata(&path).is_err() {
            return Ok(TestConditions::default());
        }
        let name = path.display().to_string();
        // A folder, a device or a broken link of that name is a mistake, never "no conditions".
        if !path.is_file() {
            let what = match std::fs::metadata(&path) {
                Err(_) => "a broken symbolic link",
                Ok(m) if m.is_dir() => "a folder",
                Ok(_) => "not a regular file",
            };
            return Err(MeasuredError::Io {
                path: name,
                message: format!("is {what}; the conditions file must be a TOML file"),
            });
        }
        let bytes = super::series::read_bounded(&path, crate::io::read::MAX_TEXT_BYTES)?;
        let text = String::from_utf8(bytes).map_err(|_| MeasuredError::Io {
            path: name.clone(),
            message: "not valid UTF-8 text".into(),
        })?;
        let mut c = TestConditions::from_toml_str(&text, &name)?;
        for t in &mut c.tests {
            t.data = match &t.data {
                DataFiles::Single(f) => DataFiles::Single(dir.join(f)),
                DataFiles::Split { internal, external } => DataFiles::Split {
                    internal: dir.join(internal),
                    external: dir.join(external),
                },
            };
        }
        c.file = Some(path);
        Ok(c)
    }

    /// Parses and validates the text of an `rtest.toml`; `name` stands for the file in error
    /// messages, which name the key or the line and column. Paths of `[[test]]` entries stay
    /// as written (relative to the folder).
    pub fn from_toml_str(text: &str, name: &str) -> Result<TestConditions, MeasuredError> {
        let bad = |key: &str, message: String| MeasuredError::Conditions {
            file: name.to_string(),
            key: key.to_string(),
            message,
        };
        let raw: RawConditions = toml::from_str(text).map_err(|e| {
            let m = crate::machine::MachineError::toml(name, text, &e);
            bad(&m.key, m.message)
        })?;
        check_radius(raw.radius_mm, "radius_mm", &bad)?;
        let session = session(&raw, &bad)?;
        check_position(raw.position_mm.as_deref(), "position_mm", &bad)?;
        let map = |t: &Option<BTreeMap<String, ColumnEntry>>, table: &str| match t {
            Some(entries) => ColumnMap::from_entries(entries, name, table),
            None => Ok(ColumnMap::default()),
        };
        let columns = map(&raw.columns, "columns")?;
        let internal_columns =
            columns.overridden_by(&map(&raw.internal_columns, "internal_columns")?);
        let external_columns =
            columns.overridden_by(&map(&raw.external_columns, "external_columns")?);
        for (table, n) in [
            ("[[test]]", raw.test.len()),
            ("[[pairing]]", raw.pairing.len()),
        ] {
            if n > MAX_TESTS {
                return Err(bad(table, format!("{n} entries, at most {MAX_TESTS}")));
            }
        }
        let internal_coordinates = raw
            .internal_coordinates
            .as_deref()
            .map(str::parse::<Coordinates>)
            .transpose()
            .map_err(|m| bad("internal_coordinates", m))?;
        let mut tests = Vec::new();
        for (i, t) in raw.test.into_iter().enumerate() {
            tests.push(test_entry(i + 1, t, &bad)?);
        }
        let mut pairings = Vec::new();
        for (i, p) in raw.pairing.into_iter().enumerate() {
            pairings.push(pairing_entry(i + 1, p, &bad)?);
        }
        let tolerances = match &raw.tolerances {
            Some(t) => Tolerances::from_toml(t).map_err(|e| bad(&e.key, e.message))?,
            None => Tolerances::default(),
        };
        let diagnosis = raw.diagnosis.unwrap_or_default();
        diagnosis
            .check()
            .map_err(|(key, m)| bad(&format!("diagnosis.{key}"), m))?;
        Ok(TestConditions {
            radius_mm: raw.radius_mm,
            position_mm: raw.position_mm,
            columns,
            internal_columns,
            external_columns,
            internal_coordinates,
            tests,
            pairings,
            tolerances,
            diagnosis,
            session,
            file: None,
        })
    }
}

fn session(
    raw: &RawConditions,
    bad: &dyn Fn(&str, String) -> MeasuredError,
) -> Result<Session, MeasuredError> {
    let date = match &raw.date {
        None => None,
        Some(toml::Value::Datetime(d)) => Some(d.to_string()),
        Some(toml::Value::String(s)) => Some(s.trim().to_string()),
        Some(other) => {
            return Err(bad(
                "date",
                format!(
                    "expected a date such as 2026-03-14, found {}",
                    other.type_str()
                ),
            ))
        }
    };
    if let Some(d) = &date {
        epoch_s(d).map_err(|m| bad("date", m))?;
    }
    if let Some(t) = raw.temperature_c {
        if !(t.is_finite() && (-50.0..=100.0).contains(&t)) {
            return Err(bad(
                "temperature_c",
                format!("{} °C must lie in −50 to 100", crate::text::num(t)),
            ));
        }
    }
    let text = |v: &Option<String>| {
        v.as_ref()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
    };
    Ok(Session {
        machine: text(&raw.machine),
        date,
        instrument: text(&raw.instrument),
        temperature_c: raw.temperature_c,
    })
}

/// The folder of a file (`.` for a bare file name).
pub(crate) fn folder_of(file: &Path) -> PathBuf {
    match file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}
