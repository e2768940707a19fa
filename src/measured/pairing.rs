//! `[[pairing]]` in `rtest.toml`: the internal and the external files of many two-system tests
//! given by two file-name patterns (`internal = "cnc/*.sco"`, `external = "rtest/*.csv"`),
//! instead of one `[[test]]` entry per test.
//!
//! Pairs are matched
//! - by equal file stems (`cnc/zx_cw_5.sco` with `rtest/zx_cw_5.csv`) where every file's stem
//!   has its partner on the other side;
//! - else, where no stem is shared, in recording order: each side's files ordered by the start
//!   times in their data where these put the recordings one after another on that side's
//!   clock (each one starting after the one before ended: a clock that runs through the
//!   session, such as a time of day), else by their names (loggers that number or date-stamp
//!   their files; recordings whose time starts anew in each file). File modification times are
//!   not used: copying a folder changes them.
//!
//! Refused, each with one line naming `rtest.toml`, the entry and the file: a pattern that
//! matches no file, a file matched by both patterns, unequal counts, stems shared by some files
//! and not by others, and two files with the stem of one partner. Whether a pair is one test is
//! checked again on the data ([`crate::measured::suite`]: the plane, direction and circle
//! frequency of the two recordings must agree).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::conditions::{DataFiles, Pairing, TestConditions, TestEntry};
use super::error::MeasuredError;
use super::layout::ColumnMap;
use super::recording::{read_external, read_internal};
use crate::io::delimited::quote_cell;

/// How the two files of a test of a `[[pairing]]` were paired.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PairedOn {
    /// Equal file stems (`cnc/zx_cw_5.sco` and `rtest/zx_cw_5.csv`).
    Stems,
    /// Recording order from the start times in the data (each side's recordings one after
    /// another on its clock).
    StartTimes,
    /// Recording order from the order of the file names (recordings without a common clock).
    Names,
}

impl PairedOn {
    /// In words, for messages.
    pub fn describe(self) -> &'static str {
        match self {
            PairedOn::Stems => "by equal file stems",
            PairedOn::StartTimes => "in recording order (start times in the data)",
            PairedOn::Names => "in recording order (order of the file names)",
        }
    }
}

/// Where a test of a `[[pairing]]` comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PairedBy {
    /// The 1-based number of the `[[pairing]]` entry.
    pub pairing: usize,
    /// How its files were paired.
    pub on: PairedOn,
}

/// The pairs of every `[[pairing]]` of `cond` (the conditions of folder `dir`), as entries
/// with the pairing's stated conditions.
pub(crate) fn expand(
    dir: &Path,
    cond: &TestConditions,
) -> Result<Vec<(TestEntry, PairedBy)>, MeasuredError> {
    let mut out = Vec::new();
    for p in &cond.pairings {
        let bad = |key: &str, message: String| MeasuredError::Conditions {
            file: cond
                .file
                .as_ref()
                .map_or(dir.display().to_string(), |f| f.display().to_string()),
            key: format!("[[pairing]] #{} {key}", p.number),
            message,
        };
        let internal = matches(dir, &p.internal, &bad, "internal")?;
        let external = matches(dir, &p.external, &bad, "external")?;
        if let Some(f) = internal.iter().find(|f| external.contains(f)) {
            return Err(bad(
                "external",
                format!(
                    "{}: matched by both patterns (a file is either internal or external)",
                    f.display()
                ),
            ));
        }
        let (pairs, on) = pair(p, &internal, &external, cond, &bad)?;
        for (i, e) in pairs {
            let mut entry = p.stated.clone();
            entry.data = DataFiles::Split {
                internal: i,
                external: e,
            };
            out.push((
                entry,
                PairedBy {
                    pairing: p.number,
                    on,
                },
            ));
        }
    }
    Ok(out)
}

/// The regular files of `dir` that `pattern` matches, in name order.
fn matches(
    dir: &Path,
    pattern: &str,
    bad: &dyn Fn(&str, String) -> MeasuredError,
    key: &str,
) -> Result<Vec<PathBuf>, MeasuredError> {
    let Some(folder) = dir.to_str() else {
        return Err(bad(
            key,
            format!("{}: the folder's name is not UTF-8 text", dir.display()),
        ));
    };
    let full = format!("{}/{pattern}", glob::Pattern::escape(folder));
    let options = glob::MatchOptions {
        case_sensitive: true,
        require_literal_separator: true,
        require_literal_leading_dot: true,
    };
    let paths = glob::glob_with(&full, options).map_err(|e| {
        bad(
            key,
            format!("'{}' is no file pattern: {e}", quote_cell(pattern)),
        )
    })?;
    let mut files = Vec::new();
    for p in paths {
        let p = p.map_err(|e| bad(key, format!("{}: cannot read: {}", e.path().display(), e)))?;
        if p.is_file() {
            files.push(p);
        }
        if files.len() > super::conditions::MAX_TESTS {
            return Err(bad(
                key,
                format!("more than {} files", super::conditions::MAX_TESTS),
            ));
        }
    }
    if files.is_empty() {
        return Err(bad(
            key,
            format!(
                "'{}' matches no file in {}",
                quote_cell(pattern),
                dir.display()
            ),
        ));
    }
    files.sort();
    Ok(files)
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Whether the file starts as a controller trace (TNCscope, Sinumerik XML) does.
fn is_trace(f: &Path) -> bool {
    use std::io::Read;
    let mut head = Vec::new();
    std::fs::File::open(f)
        .and_then(|h| h.take(4096).read_to_end(&mut head))
        .is_ok()
        && super::traces::format_of(&super::series::utf8_of(head))
            != super::traces::Format::Delimited
}

/// The internal and external files of one pairing matched (see the module docs).
fn pair(
    p: &Pairing,
    internal: &[PathBuf],
    external: &[PathBuf],
    cond: &TestConditions,
    bad: &dyn Fn(&str, String) -> MeasuredError,
) -> Result<(Vec<(PathBuf, PathBuf)>, PairedOn), MeasuredError> {
    let by_stem = |files: &[PathBuf]| {
        let mut m: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
        for f in files {
            m.entry(stem(f)).or_default().push(f.clone());
        }
        m
    };
    if let Some(t) = external.iter().find(|f| is_trace(f)) {
        return Err(bad(
            "external",
            format!(
                "'{}' matches {}, a controller trace (the axes' own readings): traces belong to the internal pattern, the R-Test files to the external one (the patterns swapped?)",
                quote_cell(&p.external),
                t.display()
            ),
        ));
    }
    let (int_stems, ext_stems) = (by_stem(internal), by_stem(external));
    let shared = int_stems.keys().any(|s| ext_stems.contains_key(s));
    if shared {
        for (side, mine, other) in [
            ("internal", &int_stems, &ext_stems),
            ("external", &ext_stems, &int_stems),
        ] {
            for (s, files) in mine {
                match (files.as_slice(), other.get(s)) {
                    ([a, b, ..], Some(partner)) => {
                        return Err(bad(
                            side,
                            format!(
                                "{} and {} both claim {} as their partner (equal stems '{}'); \
                                 leave one out of the pattern",
                                a.display(),
                                b.display(),
                                partner[0].display(),
                                quote_cell(s)
                            ),
                        ))
                    }
                    ([a, ..], None) => {
                        return Err(bad(
                            side,
                            format!(
                                "{}: no {} file of the same stem, while {} file(s) pair by \
                                 stem ({} internal, {} external files): name every pair \
                                 alike, or none (then they pair in recording order)",
                                a.display(),
                                if side == "internal" {
                                    "external"
                                } else {
                                    "internal"
                                },
                                mine.keys().filter(|k| other.contains_key(*k)).count(),
                                internal.len(),
                                external.len()
                            ),
                        ))
                    }
                    _ => {}
                }
            }
        }
        let pairs = int_stems
            .iter()
            .map(|(s, f)| (f[0].clone(), ext_stems[s][0].clone()))
            .collect();
        return Ok((pairs, PairedOn::Stems));
    }
    if internal.len() != external.len() {
        return Err(bad(
            "external",
            format!(
                "{} internal files match '{}' but {} external files '{}': every test needs \
                 both (no file stem is shared, so they would pair in recording order)",
                internal.len(),
                quote_cell(&p.internal),
                external.len(),
                quote_cell(&p.external)
            ),
        ));
    }
    let (int_order, int_on) = recording_order(internal, &cond.internal_columns, true)?;
    let (ext_order, ext_on) = recording_order(external, &cond.external_columns, false)?;
    let on = if int_on == PairedOn::StartTimes && ext_on == PairedOn::StartTimes {
        PairedOn::StartTimes
    } else {
        PairedOn::Names
    };
    Ok((int_order.into_iter().zip(ext_order).collect(), on))
}

/// One side's files in recording order: by the start times in their data where these put the
/// recordings one after another, else in name order (as given).
fn recording_order(
    files: &[PathBuf],
    map: &ColumnMap,
    internal: bool,
) -> Result<(Vec<PathBuf>, PairedOn), MeasuredError> {
    let mut spans = Vec::with_capacity(files.len());
    for f in files {
        let r = if internal {
            read_internal(f, map, None)?
        } else {
            read_external(f, map)?
        };
        let (first, last) = (r.t_s[0], r.t_s[r.t_s.len() - 1]);
        spans.push((first, last, f.clone()));
    }
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    let one_after_another = spans.windows(2).all(|w| w[1].0 > w[0].1);
    if files.len() > 1 && one_after_another {
        Ok((
            spans.into_iter().map(|s| s.2).collect(),
            PairedOn::StartTimes,
        ))
    } else {
        Ok((files.to_vec(), PairedOn::Names))
    }
}
