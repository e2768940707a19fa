//! The entries of `rtest.toml` that name a test's data ([`TestEntry`]: `[[test]]`, and the
//! pairs a `[[pairing]]` makes, [`Pairing`]) and the keys they share with the folder, checked
//! as written (docs/measurement-files.md). Read by [`super::conditions`].

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::error::MeasuredError;
use crate::axes::{Direction, Plane};

/// What a test's data are: one file with both measurements, or one file per measuring system
/// (each read into one system's [`crate::rtest::clock::Recording`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DataFiles {
    /// One file with `t_s`, the internal and the external columns.
    Single(PathBuf),
    /// Two systems with their own clocks: the internal file (`t_s` and `_int_mm`, e.g. a CNC
    /// trace) and the external one (`t_s` and `_ext_mm`, e.g. the R-Test logger).
    Split {
        /// The internal (axis readings) file.
        internal: PathBuf,
        /// The external (R-Test) file.
        external: PathBuf,
    },
}

/// How a test's internal readings are given (`internal_coordinates` in `rtest.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Coordinates {
    /// Relative to the circle centre (the contract's columns; the default).
    #[default]
    Relative,
    /// Absolute machine coordinates of the axes (a controller trace): the circle centre
    /// `position_mm` is subtracted.
    Absolute,
}

impl Coordinates {
    /// The name as written in `rtest.toml`: `relative`, `absolute`.
    pub fn name(self) -> &'static str {
        match self {
            Coordinates::Relative => "relative",
            Coordinates::Absolute => "absolute",
        }
    }
}

impl std::str::FromStr for Coordinates {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "relative" => Ok(Coordinates::Relative),
            "absolute" => Ok(Coordinates::Absolute),
            other => Err(format!(
                "'{}': expected \"absolute\" (machine coordinates, the circle centre \
                 position_mm subtracted) or \"relative\" (to the circle centre)",
                crate::io::delimited::quote_cell(other)
            )),
        }
    }
}

/// One test's data and the conditions stated for it: a `[[test]]` entry (overriding the
/// folder's conditions), or, held by a [`crate::measured::inputs::TestInput`], the conditions
/// it is evaluated at (the entry's, the folder's where the entry is silent).
#[derive(Debug, Clone, PartialEq)]
pub struct TestEntry {
    /// 1-based number of its `[[test]]` entry in `rtest.toml`; none for a file of the folder
    /// that no entry names and for a pair of a `[[pairing]]`.
    pub number: Option<usize>,
    /// Its data, paths relative to the folder resolved.
    pub data: DataFiles,
    /// Circle plane, where stated.
    pub plane: Option<Plane>,
    /// Sense of rotation, where stated (checked against the data).
    pub direction: Option<Direction>,
    /// Set radius, mm.
    pub radius_mm: Option<f64>,
    /// Circle-centre position, mm.
    pub position_mm: Option<Vec<f64>>,
    /// Programmed feed, mm/min (checked against the data).
    pub feed_mm_min: Option<f64>,
    /// Free text carried into the outputs.
    pub note: Option<String>,
    /// The clock group: tests of one group share one constant clock offset (default: one
    /// group per folder; single-file and two-system tests are grouped apart).
    pub clock: Option<String>,
    /// A known clock offset (internal clock minus external clock), ms: used as given, not
    /// estimated (for a single file: the lag of its external columns, negative when they lag).
    pub time_offset_ms: Option<f64>,
    /// How the internal readings are given (`internal_coordinates`), where stated.
    pub internal_coordinates: Option<Coordinates>,
}

impl TestEntry {
    /// A test of `data` with nothing stated about it.
    pub fn of(data: DataFiles) -> TestEntry {
        TestEntry {
            number: None,
            data,
            plane: None,
            direction: None,
            radius_mm: None,
            position_mm: None,
            feed_mm_min: None,
            note: None,
            clock: None,
            time_offset_ms: None,
            internal_coordinates: None,
        }
    }
}

/// One `[[pairing]]` entry: the internal and the external files of many two-system tests,
/// given as file-name patterns relative to the folder (`cnc/*.sco`, `rtest/*.csv`), paired by
/// equal file stems, else in recording order ([`crate::measured::inputs`]); plane, direction
/// and acceleration come from the data.
#[derive(Debug, Clone, PartialEq)]
pub struct Pairing {
    /// 1-based number of the entry in `rtest.toml`.
    pub number: usize,
    /// Pattern of the internal files (`*`, `?`, `[...]` as in a shell).
    pub internal: String,
    /// Pattern of the external files.
    pub external: String,
    /// Conditions of all its tests over the folder's (`radius_mm`, `position_mm`,
    /// `internal_coordinates`, `clock`, `time_offset_ms`, `note`); its data is unused.
    pub stated: TestEntry,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTest {
    file: Option<PathBuf>,
    internal: Option<PathBuf>,
    external: Option<PathBuf>,
    plane: Option<String>,
    direction: Option<String>,
    radius_mm: Option<f64>,
    position_mm: Option<Vec<f64>>,
    feed_mm_min: Option<f64>,
    note: Option<String>,
    clock: Option<String>,
    time_offset_ms: Option<f64>,
    internal_coordinates: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPairing {
    internal: Option<String>,
    external: Option<String>,
    radius_mm: Option<f64>,
    position_mm: Option<Vec<f64>>,
    note: Option<String>,
    clock: Option<String>,
    time_offset_ms: Option<f64>,
    internal_coordinates: Option<String>,
}

pub(super) fn check_radius(
    r: Option<f64>,
    key: &str,
    bad: &dyn Fn(&str, String) -> MeasuredError,
) -> Result<(), MeasuredError> {
    match r {
        Some(r) if !(r.is_finite() && r > 0.0 && r <= 3.0) => Err(bad(
            key,
            format!("{} must lie in (0, 3] mm", crate::text::num(r)),
        )),
        _ => Ok(()),
    }
}

pub(super) fn check_position(
    p: Option<&[f64]>,
    key: &str,
    bad: &dyn Fn(&str, String) -> MeasuredError,
) -> Result<(), MeasuredError> {
    match p {
        Some(p) if p.iter().any(|v| !v.is_finite()) => {
            Err(bad(key, "values must be finite".into()))
        }
        Some([]) => Err(bad(key, "empty; give one position per machine axis".into())),
        Some(p) if p.len() > 3 || p.iter().any(|v| v.abs() > 1e5) => Err(bad(
            key,
            format!(
                "{} mm: give one position per machine axis (at most 3, within ±1e5 mm)",
                crate::text::nums(p)
            ),
        )),
        _ => Ok(()),
    }
}

pub(super) fn test_entry(
    number: usize,
    t: RawTest,
    bad: &dyn Fn(&str, String) -> MeasuredError,
) -> Result<TestEntry, MeasuredError> {
    let key = |k: &str| format!("[[test]] #{number} {k}");
    let data = match (t.file, t.internal, t.external) {
        (Some(f), None, None) => DataFiles::Single(f),
        (None, Some(internal), Some(external)) => {
            if internal == external {
                return Err(bad(
                    &key("external"),
                    "names the same file as internal".into(),
                ));
            }
            DataFiles::Split { internal, external }
        }
        (None, Some(_), None) => {
            return Err(bad(
                &key("external"),
                "missing: internal needs its external file".into(),
            ))
        }
        (None, None, Some(_)) => {
            return Err(bad(
                &key("internal"),
                "missing: external needs its internal file".into(),
            ))
        }
        (None, None, None) => {
            return Err(bad(
                &key("file"),
                "missing: give file, or internal and external".into(),
            ))
        }
        (Some(_), _, _) => {
            return Err(bad(
                &key("file"),
                "give either file or internal and external, not both".into(),
            ))
        }
    };
    let plane = t
        .plane
        .map(|p| p.parse::<Plane>())
        .transpose()
        .map_err(|m| bad(&key("plane"), m))?;
    let direction = t
        .direction
        .map(|d| d.parse::<Direction>())
        .transpose()
        .map_err(|m| bad(&key("direction"), m))?;
    if let Some(f) = t.feed_mm_min {
        if !(f.is_finite() && f > 0.0) {
            return Err(bad(
                &key("feed_mm_min"),
                format!("{} must be a positive feed", crate::text::num(f)),
            ));
        }
    }
    let mut entry = stated(
        &key,
        Stated {
            radius_mm: t.radius_mm,
            position_mm: t.position_mm,
            note: t.note,
            clock: t.clock,
            time_offset_ms: t.time_offset_ms,
            internal_coordinates: t.internal_coordinates,
        },
        bad,
    )?;
    entry.number = Some(number);
    entry.data = data;
    entry.plane = plane;
    entry.direction = direction;
    entry.feed_mm_min = t.feed_mm_min;
    Ok(entry)
}

/// The keys a `[[test]]` and a `[[pairing]]` entry share, as written.
struct Stated {
    radius_mm: Option<f64>,
    position_mm: Option<Vec<f64>>,
    note: Option<String>,
    clock: Option<String>,
    time_offset_ms: Option<f64>,
    internal_coordinates: Option<String>,
}

/// Checks the shared keys of an entry (`key` names them in errors) into a [`TestEntry`]
/// without data.
fn stated(
    key: &dyn Fn(&str) -> String,
    t: Stated,
    bad: &dyn Fn(&str, String) -> MeasuredError,
) -> Result<TestEntry, MeasuredError> {
    check_radius(t.radius_mm, &key("radius_mm"), bad)?;
    check_position(t.position_mm.as_deref(), &key("position_mm"), bad)?;
    if let Some(o) = t.time_offset_ms {
        if !(o.is_finite() && o.abs() <= 3.6e6) {
            return Err(bad(
                &key("time_offset_ms"),
                format!("{} must be finite, within an hour", crate::text::num(o)),
            ));
        }
    }
    let internal_coordinates = t
        .internal_coordinates
        .map(|c| c.parse::<Coordinates>())
        .transpose()
        .map_err(|m| bad(&key("internal_coordinates"), m))?;
    Ok(TestEntry {
        radius_mm: t.radius_mm,
        position_mm: t.position_mm,
        note: t.note,
        clock: t.clock,
        time_offset_ms: t.time_offset_ms,
        internal_coordinates,
        ..TestEntry::of(DataFiles::Single(PathBuf::new()))
    })
}

/// A `[[pairing]]` entry checked: both patterns given, valid, not the same.
pub(super) fn pairing_entry(
    number: usize,
    p: RawPairing,
    bad: &dyn Fn(&str, String) -> MeasuredError,
) -> Result<Pairing, MeasuredError> {
    let key = |k: &str| format!("[[pairing]] #{number} {k}");
    let pattern = |v: Option<String>, k: &str| -> Result<String, MeasuredError> {
        let Some(v) = v.map(|v| v.trim().to_string()) else {
            return Err(bad(
                &key(k),
                format!(
                    "missing: a pairing needs internal and external patterns, e.g. {k} = \"{}\"",
                    if k == "internal" {
                        "cnc/*.sco"
                    } else {
                        "rtest/*.csv"
                    }
                ),
            ));
        };
        if v.is_empty() {
            return Err(bad(&key(k), "empty pattern".into()));
        }
        if Path::new(&v).is_absolute()
            || Path::new(&v)
                .components()
                .any(|c| c == std::path::Component::ParentDir)
        {
            return Err(bad(
                &key(k),
                format!(
                    "'{}': a pattern names files inside the folder (no absolute path, no ..)",
                    crate::io::delimited::quote_cell(&v)
                ),
            ));
        }
        glob::Pattern::new(&v).map_err(|e| {
            bad(
                &key(k),
                format!(
                    "'{}' is no file pattern: {e}",
                    crate::io::delimited::quote_cell(&v)
                ),
            )
        })?;
        Ok(v)
    };
    let internal = pattern(p.internal, "internal")?;
    let external = pattern(p.external, "external")?;
    if internal == external {
        return Err(bad(&key("external"), "the same pattern as internal".into()));
    }
    let stated = stated(
        &key,
        Stated {
            radius_mm: p.radius_mm,
            position_mm: p.position_mm,
            note: p.note,
            clock: p.clock,
            time_offset_ms: p.time_offset_ms,
            internal_coordinates: p.internal_coordinates,
        },
        bad,
    )?;
    Ok(Pairing {
        number,
        internal,
        external,
        stated,
    })
}
