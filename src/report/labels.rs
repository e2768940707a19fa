//! How the report writes names and numbers in its tables and labels, shared by its sections:
//! test files as `folder/name`, data folders with their file counts, EIJ values, circle centres,
//! a test's path speed.

use std::path::Path;

use super::short;
use crate::rtest::CircleResult;

/// `folder/name` of a path: the name alone is ambiguous when several folders (test positions)
/// hold files of the same name.
pub fn folder_and_name(path: &Path) -> String {
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
pub fn folders_of<'a>(files: impl Iterator<Item = &'a Path>) -> Vec<String> {
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
        .map(|(d, n)| format!("{d} ({n} file{})", if n == 1 { "" } else { "s" }))
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
pub fn position_label(p: &[f64]) -> String {
    p.iter().map(|v| short(*v, 1)).collect::<Vec<_>>().join(",")
}

/// The path speed of a circle test, mm/min: 2π·r·f·60.
pub fn feed_mm_min(r: &CircleResult) -> f64 {
    std::f64::consts::TAU * r.radius_mm * r.freq_hz * 60.0
}
