//! Test conditions of R-Test files that the series themselves do not carry: the set radius and
//! the circle-centre position, stated once per folder in `rtest.toml`.

use super::RtestError;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The file of a folder that states the conditions of the R-Test files in it.
pub const CONDITIONS_FILE: &str = "rtest.toml";

/// Conditions of the circle tests of one folder (`rtest.toml`); absent keys are unknown.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TestConditions {
    /// Set radius of the circles, mm (0 < r ≤ 3, the R-Test range).
    pub radius_mm: Option<f64>,
    /// Axis positions of the circle centre, mm, in the machine's axis order.
    pub position_mm: Option<Vec<f64>>,
}

impl TestConditions {
    /// The conditions of `file`: the `rtest.toml` in its folder, or none.
    pub fn of_file(file: &Path) -> Result<TestConditions, RtestError> {
        let dir = match file.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let path = dir.join(CONDITIONS_FILE);
        if !path.is_file() {
            return Ok(TestConditions::default());
        }
        let name = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| RtestError::Io {
            path: name.clone(),
            message: e.to_string(),
        })?;
        TestConditions::from_toml_str(&text, &name)
    }

    /// Parses and validates the text of an `rtest.toml`; `name` stands for the file in error
    /// messages, which name the key or the line and column.
    pub fn from_toml_str(text: &str, name: &str) -> Result<TestConditions, RtestError> {
        let bad = |key: &str, message: String| RtestError::Conditions {
            file: name.to_string(),
            key: key.to_string(),
            message,
        };
        let c: TestConditions = toml::from_str(text).map_err(|e| {
            let m = crate::machine::MachineError::toml(name, text, &e);
            bad(&m.key, m.message)
        })?;
        if let Some(r) = c.radius_mm {
            if !(r.is_finite() && r > 0.0 && r <= 3.0) {
                return Err(bad("radius_mm", format!("{r} must lie in (0, 3] mm")));
            }
        }
        if c.position_mm
            .as_ref()
            .is_some_and(|p| p.iter().any(|v| !v.is_finite()))
        {
            return Err(bad("position_mm", "values must be finite".into()));
        }
        if c.position_mm.as_ref().is_some_and(Vec::is_empty) {
            return Err(bad(
                "position_mm",
                "empty; give one position per machine axis".into(),
            ));
        }
        Ok(c)
    }
}

/// The `*.csv` files of a folder and, recursively, of its sub-folders, sorted by path.
fn folder_files(dir: &Path) -> Result<Vec<PathBuf>, RtestError> {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| RtestError::Io {
            path: dir.display().to_string(),
            message: format!("cannot read folder: {e}"),
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    let mut files = Vec::new();
    for e in entries {
        if e.is_dir() {
            files.extend(folder_files(&e)?);
        } else if e.extension().is_some_and(|x| x.eq_ignore_ascii_case("csv")) {
            files.push(e);
        }
    }
    Ok(files)
}

/// Expands the measured inputs of a command: files stay, folders give their `*.csv` files and
/// those of their sub-folders, sorted by path (other files are skipped). A missing path or a
/// folder without CSV files is an error.
pub fn expand_inputs(paths: &[PathBuf]) -> Result<Vec<PathBuf>, RtestError> {
    let mut files = Vec::new();
    for p in paths {
        if p.is_dir() {
            let inside = folder_files(p)?;
            if inside.is_empty() {
                return Err(RtestError::Io {
                    path: p.display().to_string(),
                    message: "folder holds no .csv files".into(),
                });
            }
            files.extend(inside);
        } else if p.is_file() {
            files.push(p.clone());
        } else {
            return Err(RtestError::Io {
                path: p.display().to_string(),
                message: "file not found".into(),
            });
        }
    }
    Ok(files)
}
