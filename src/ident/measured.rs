//! Measured EIJ for identification, from R-Test CSV files (through the evaluation), folders of
//! them, or EIJ tables (CONTRACT.md).

pub use super::settings::MeasuredOptions;
use super::{IdentError, TestCase};
use crate::predict::CircleTest;
use crate::rtest::conditions::TestConditions;
use crate::rtest::{self, table, CircleSeries, EvalOptions};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Whether a CSV file is an EIJ table (has a `parameter` column) rather than a time series.
fn is_table(path: &Path) -> bool {
    std::fs::read(path)
        .ok()
        .and_then(|b| {
            let first = b.split(|&c| c == b'\n').next()?.to_vec();
            Some(
                String::from_utf8_lossy(&first)
                    .split(',')
                    .any(|c| c.trim() == "parameter"),
            )
        })
        .unwrap_or(false)
}

/// Expands folders (their `*.csv`, sub-folders included, sorted) and keeps files.
pub fn expand(paths: &[PathBuf]) -> Result<Vec<PathBuf>, IdentError> {
    Ok(crate::rtest::conditions::expand_inputs(paths)?)
}

/// Reads every path into test cases (R-Test series are evaluated; tables grouped by plane,
/// direction and acceleration). Folders are read with their sub-folders; the optional
/// `rtest.toml` beside the files states their set radius and circle-centre position.
pub fn load(paths: &[PathBuf], opts: &MeasuredOptions) -> Result<Vec<TestCase>, IdentError> {
    // The rtest.toml of a file's own folder states the conditions of that file.
    let mut tests = Vec::new();
    for f in expand(paths)? {
        let conditions = TestConditions::of_file(&f)?;
        tests.extend(load_files(std::slice::from_ref(&f), opts, &conditions)?);
    }
    Ok(tests)
}

fn load_files(
    files: &[PathBuf],
    opts: &MeasuredOptions,
    cond: &TestConditions,
) -> Result<Vec<TestCase>, IdentError> {
    let radius_mm = cond.radius_mm.unwrap_or(opts.radius_mm);
    let position_m = cond
        .position_mm
        .as_ref()
        .map(|p| p.iter().map(|v| v * 1e-3).collect::<Vec<f64>>());
    let mut tests = Vec::new();
    for f in files {
        let name = f.display().to_string();
        let err = IdentError::Rtest;
        if is_table(f) {
            let rows = table::read(f).map_err(err)?;
            let mut groups: BTreeMap<(String, String, u64), TestCase> = BTreeMap::new();
            for row in rows {
                let key = (
                    row.plane.to_string(),
                    row.direction.to_string(),
                    row.accel_m_s2.to_bits(),
                );
                let case = groups.entry(key).or_insert_with(|| TestCase {
                    source: format!(
                        "{name} ({} {} {} m/s²)",
                        row.plane, row.direction, row.accel_m_s2
                    ),
                    circle: CircleTest {
                        plane: row.plane,
                        direction: row.direction,
                        radius_mm,
                        accel_m_s2: row.accel_m_s2,
                        position_m: position_m.clone(),
                    },
                    measured: BTreeMap::new(),
                });
                case.measured.insert(
                    row.parameter,
                    (row.value, row.std_err.unwrap_or(opts.table_std_err)),
                );
            }
            tests.extend(groups.into_values());
        } else {
            let series = CircleSeries::read_csv(f).map_err(err)?;
            let eval = EvalOptions {
                plane: None,
                radius_mm: Some(radius_mm),
            };
            let result = rtest::evaluate(&series, &eval).map_err(err)?;
            tests.push(TestCase {
                source: name.clone(),
                circle: CircleTest {
                    plane: result.plane,
                    direction: result.direction,
                    radius_mm: result.radius_mm,
                    accel_m_s2: result.accel_m_s2,
                    position_m: position_m.clone(),
                },
                measured: result
                    .eij
                    .iter()
                    .map(|(p, v)| (*p, (*v, result.std_err[p])))
                    .collect(),
            });
        }
    }
    Ok(tests)
}
