//! Measured EIJ for identification, from R-Test CSV files (through the evaluation), folders of
//! them, or EIJ tables (docs/commands.md).

pub use super::settings::MeasuredOptions;
use super::{IdentError, TestCase};
use crate::axes::EijEstimates;
use crate::measured::conditions::DataFiles;
use crate::measured::inputs::{MeasuredInputs, TestInput};
use crate::measured::suite::{evaluate_tests, ClockReport, SuiteOptions};
use crate::measured::table;
use crate::predict::CircleTest;
use crate::rtest::{Named, Warning};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Reads every path into test cases: R-Test series (single files and two-system recordings
/// with their `rtest.toml` conditions) are evaluated as `eij evaluate` does
/// ([`crate::measured::suite::evaluate_tests`], so that the measured EIJ are evaluate's), the set
/// radius from `rtest.toml`, else `opts.radius_mm`; EIJ tables are grouped by plane, direction
/// and acceleration. Folders are read with their sub-folders.
pub fn load(paths: &[PathBuf], opts: &MeasuredOptions) -> Result<Vec<TestCase>, IdentError> {
    Ok(load_measured(&MeasuredInputs::expand(paths)?, opts)?.tests)
}

/// What [`load_measured`] read.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The test cases.
    pub tests: Vec<TestCase>,
    /// What the evaluation says about conditions and clocks, naming the test or clock; and,
    /// with [`MeasuredOptions::fit_time_offset`], which tests' clock offset is not separable.
    pub warnings: Vec<Named>,
    /// The clocks whose offsets the evaluation estimated (applied to single-file tests with
    /// [`MeasuredOptions::fit_time_offset`]; two-system recordings are always aligned).
    pub clocks: Vec<ClockReport>,
}

/// As [`load`] on inputs already expanded, with what the evaluation says about the tests'
/// conditions and clocks (a direction or feed at odds with the data, a clock offset not
/// separable from cross-talk, each naming its test or clock) and the clock offsets.
pub fn load_measured(
    inputs: &MeasuredInputs,
    opts: &MeasuredOptions,
) -> Result<Measured, IdentError> {
    let inputs = &inputs.tests;
    let (tables, series): (Vec<&TestInput>, Vec<&TestInput>) = inputs
        .iter()
        .partition(|t| matches!(&t.test.data, DataFiles::Single(f) if table::looks_like_table(f)));
    let series: Vec<TestInput> = series.into_iter().cloned().collect();
    let suite = evaluate_tests(
        &series,
        &SuiteOptions {
            fallback_radius_mm: Some(opts.radius_mm),
            fit_time_offset: opts.fit_time_offset,
            ..Default::default()
        },
    )?;
    let mut warnings = suite.warnings;
    if opts.fit_time_offset {
        let unseparated: Vec<String> = suite
            .tests
            .iter()
            .filter(|t| t.time_offset.is_none())
            .map(|t| t.input.name())
            .collect();
        if !unseparated.is_empty() {
            warnings.push(Named {
                name: None,
                warning: Warning::ClockOffsetNotSeparable { tests: unseparated },
            });
        }
    }
    let clocks = suite.clocks;
    warnings.extend(suite.tests.iter().flat_map(|t| {
        t.notes.iter().map(|n| Named {
            name: Some(t.input.name()),
            warning: n.clone(),
        })
    }));
    let mut evaluated = suite.tests.into_iter();
    let mut tests = Vec::new();
    for input in inputs {
        let position_m = input
            .test
            .position_mm
            .as_ref()
            .map(|p| p.iter().map(|v| v * 1e-3).collect::<Vec<f64>>());
        if tables.iter().any(|t| std::ptr::eq(*t, input)) {
            let radius_mm = input.test.radius_mm.unwrap_or(opts.radius_mm);
            tests.extend(table_tests(input, radius_mm, position_m, opts)?);
            continue;
        }
        let Some(e) = evaluated.next() else { break };
        let result = e.result;
        tests.push(TestCase {
            source: input.name(),
            circle: CircleTest {
                plane: result.plane,
                direction: result.direction,
                radius_mm: result.radius_mm,
                accel_m_s2: result.accel_m_s2,
                position_m,
            },
            measured: result.eij,
            clock: Some(
                input
                    .primary_file()
                    .parent()
                    .map(|d| d.display().to_string())
                    .unwrap_or_default(),
            ),
        });
    }
    if let Some((input, message)) = table_of_series(&tests).or_else(|| unplaced_table(&tests)) {
        return Err(IdentError::Test { input, message });
    }
    Ok(Measured {
        tests,
        warnings,
        clocks,
    })
}

/// An EIJ table's test that repeats a measured series' evaluation (the table made from
/// that series, e.g. by `evaluate --csv-out`, lying beside it): same plane, direction,
/// acceleration and circle centre, and every EIJ the same within rounding to three decimals.
/// Both would count, the test twice, and the standard errors come out too small. (A repeated
/// measurement of the same conditions has its own noise: its EIJ differ by far more.) Returns
/// the table's test and what is wrong, for the error that refuses it.
fn table_of_series(tests: &[TestCase]) -> Option<(String, String)> {
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-3 + 1e-6 * a.abs().max(b.abs());
    let (tables, series): (Vec<&TestCase>, Vec<&TestCase>) =
        tests.iter().partition(|t| t.clock.is_none());
    for t in tables {
        let repeated = series.iter().find(|s| {
            s.circle.plane == t.circle.plane
                && s.circle.direction == t.circle.direction
                && same(s.circle.accel_m_s2, t.circle.accel_m_s2)
                && s.circle.position_m == t.circle.position_m
                && !t.measured.is_empty()
                && t.measured
                    .iter()
                    .all(|(p, v)| s.measured.value(p).is_some_and(|w| same(v.value, w)))
        });
        if let Some(s) = repeated {
            return Some((
                t.source.clone(),
                format!(
                    "the EIJ of the measured series {} again (same plane, direction, acceleration, circle centre and values): a table made from a series counts its test twice; give the series or the table",
                    s.source
                ),
            ));
        }
    }
    None
}

/// The tests of an EIJ table, one per plane, direction, acceleration, radius and circle
/// centre; a row's own radius and centre (`radius_mm`, `position_*_mm`) over the folder's.
fn table_tests(
    input: &TestInput,
    radius_mm: f64,
    position_m: Option<Vec<f64>>,
    opts: &MeasuredOptions,
) -> Result<Vec<TestCase>, IdentError> {
    let name = input.name();
    let rows = table::read(input.primary_file())?;
    type Key = (String, String, u64, Option<u64>, Option<[u64; 3]>);
    let mut groups: BTreeMap<Key, TestCase> = BTreeMap::new();
    for row in rows {
        let key = (
            row.plane.to_string(),
            row.direction.to_string(),
            row.accel_m_s2.to_bits(),
            row.radius_mm.map(f64::to_bits),
            row.position_mm.map(|p| p.map(f64::to_bits)),
        );
        let case = groups.entry(key).or_insert_with(|| TestCase {
            source: format!(
                "{name} ({} {} {} m/s²{})",
                row.plane,
                row.direction,
                row.accel_m_s2,
                row.position_mm.map_or(String::new(), |p| format!(
                    " at {} mm",
                    crate::text::nums(&p)
                ))
            ),
            circle: CircleTest {
                plane: row.plane,
                direction: row.direction,
                radius_mm: row.radius_mm.unwrap_or(radius_mm),
                accel_m_s2: row.accel_m_s2,
                position_m: row
                    .position_mm
                    .map(|p| p.iter().map(|v| v * 1e-3).collect())
                    .or_else(|| position_m.clone()),
            },
            measured: EijEstimates::new(),
            clock: None,
        });
        let std_err = row.std_err.unwrap_or(opts.table_std_err);
        case.measured.insert(row.parameter, row.value, std_err);
    }
    Ok(groups.into_values().collect())
}

/// A table test without a circle centre among tests at several centres: identify cannot tell
/// where it was run (it would take the machine's reference position, and its EIJ would be
/// fitted there). Returns the table's test and what is wrong, for the error that refuses it.
fn unplaced_table(tests: &[TestCase]) -> Option<(String, String)> {
    let mut centres: Vec<&Vec<f64>> = Vec::new();
    for t in tests {
        if let Some(p) = &t.circle.position_m {
            if !centres.contains(&p) {
                centres.push(p);
            }
        }
    }
    if centres.len() < 2 {
        return None;
    }
    let t = tests
        .iter()
        .find(|t| t.clock.is_none() && t.circle.position_m.is_none())?;
    let list: Vec<String> = centres
        .iter()
        .map(|p| {
            let mm: Vec<f64> = p.iter().map(|v| v * 1e3).collect();
            crate::text::nums(&mm)
        })
        .collect();
    Some((
        t.source.clone(),
        format!(
            "the table gives no circle centre (columns position_x_mm, position_y_mm, \
             position_z_mm, or position_mm in its folder's rtest.toml) while the other \
             measured tests lie at {} centres ({} mm): its tests cannot be placed; write the table \
             with eij evaluate --csv-out (which adds the centres) or state position_mm",
            centres.len(),
            list.join(", ")
        ),
    ))
}
