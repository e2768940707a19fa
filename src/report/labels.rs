//! How the report writes names and numbers in its tables and labels, shared by its sections:
//! test files as `folder/name`, data folders with their file counts, EIJ values, circle centres,
//! a test's path speed.

use std::collections::BTreeSet;
use std::path::Path;

use super::short;
use crate::measured::suite::EvaluatedTest;
use crate::rtest::CircleResult;

/// The name of a test with its circle centre: `pos-a/xy_ccw_2.csv @ 150,-100,0 mm`.
pub(crate) fn test_name(t: &EvaluatedTest) -> String {
    let name = folder_and_name(t.input.primary_file());
    match &t.input.test.position_mm {
        Some(p) => format!("{name} @ {} mm", position_label(p)),
        None => name,
    }
}

/// Distinct values, formatted, in ascending order.
pub fn distinct(values: impl Iterator<Item = f64>, decimals: usize) -> String {
    let mut v: Vec<f64> = values.filter(|v| v.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    let mut out: Vec<String> = Vec::new();
    for x in v {
        let s = short(x, decimals);
        if !out.contains(&s) {
            out.push(s);
        }
    }
    out.join(", ")
}

/// The conditions of a set of tests in one line: count, planes, directions, set radius,
/// accelerations, feeds and circle centres.
pub(crate) fn conditions_line(t: &[EvaluatedTest]) -> String {
    let planes: BTreeSet<String> = t.iter().map(|t| t.result.plane.to_string()).collect();
    let dirs: BTreeSet<String> = t.iter().map(|t| t.result.direction.to_string()).collect();
    let centres: BTreeSet<String> = t
        .iter()
        .map(|t| {
            t.input
                .test
                .position_mm
                .as_deref()
                .map_or("not stated".into(), |p| {
                    format!("[{}] mm", position_label(p))
                })
        })
        .collect();
    format!(
        "{} circle tests; planes {}; directions {}; set radius {} mm; set acceleration {} m/s²; \
         feed {} mm/min; circle centres (axis positions) {}",
        t.len(),
        planes.into_iter().collect::<Vec<_>>().join(", "),
        dirs.into_iter().collect::<Vec<_>>().join(", "),
        distinct(t.iter().map(|t| t.result.radius_mm), 4),
        distinct(t.iter().map(|t| t.result.accel_m_s2), 1),
        distinct(t.iter().map(|t| feed_mm_min(&t.result)), 0),
        centres.into_iter().collect::<Vec<_>>().join(", ")
    )
}

/// `folder/name` of a path: the name alone is ambiguous when several folders (test positions)
/// hold files of the same name.
pub(crate) fn folder_and_name(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    match path.parent().and_then(|p| p.file_name()) {
        Some(dir) => format!("{}/{name}", dir.to_string_lossy()),
        None => name,
    }
}

/// The folders of `files` with the number of files in each, in order of appearance:
/// `measurements/demo-vmc/pos-a (18 files)`.
pub(crate) fn folders_of<'a>(files: impl Iterator<Item = &'a Path>) -> Vec<String> {
    count_by_folder(files, "file")
}

/// The folders of the tests, each with its number of tests (a two-system test counts once), in
/// order of appearance: `measurements/demo-vmc/pos-a (18 tests)`. A test's folder is that of
/// its `rtest.toml`, else of its file.
pub(crate) fn folders_of_tests(tests: &[EvaluatedTest]) -> Vec<String> {
    count_by_folder(
        tests.iter().map(|t| {
            t.input
                .conditions_file
                .as_deref()
                .unwrap_or(t.input.primary_file())
        }),
        "test",
    )
}

/// The folders of `files`, each with the number of `noun`s (one per file) in it.
fn count_by_folder<'a>(files: impl Iterator<Item = &'a Path>, noun: &str) -> Vec<String> {
    let mut folders: Vec<(String, usize)> = Vec::new();
    for f in files {
        let dir = f
            .parent()
            .map(|d| d.display().to_string())
            .filter(|d| !d.is_empty())
            .unwrap_or_else(|| ".".into());
        match folders.iter_mut().find(|(d, _)| *d == dir) {
            Some((_, n)) => *n += 1,
            None => folders.push((dir, 1)),
        }
    }
    folders
        .into_iter()
        .map(|(d, n)| format!("{d} ({n} {noun}{})", if n == 1 { "" } else { "s" }))
        .collect()
}

/// An EIJ value as written in the tables (4 decimals).
pub fn fmt_eij(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4}")
    } else {
        "–".into()
    }
}

/// Axis positions as written in labels: `150,-100,0`.
pub(crate) fn position_label(p: &[f64]) -> String {
    p.iter().map(|v| short(*v, 1)).collect::<Vec<_>>().join(",")
}

/// The path speed of a circle test, mm/min: 2π·r·f·60, as the page shows it ([`shown_feed`]).
pub fn feed_mm_min(r: &CircleResult) -> f64 {
    shown_feed(std::f64::consts::TAU * r.radius_mm * r.freq_hz * 60.0)
}

/// A feed as the page shows it, to 10 mm/min: the programmed feed the circle ran at, not the
/// last digit of ω — one rule for the header, the tables and the certificate (3795.4 → 3790).
pub fn shown_feed(mm_min: f64) -> f64 {
    (mm_min / 10.0).round() * 10.0
}
