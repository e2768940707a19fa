//! Circle-test time series (CONTRACT.md columns): strict CSV reader and in-memory constructor.

use std::path::Path;

use super::error::{quote_cell, Line, Location, RtestError};
use super::layout::{read_table, ColumnMap, CONTRACT_COLUMNS};
use crate::axes::Axis;

/// Column names of the internal readings, x, y, z.
pub const INT_COLUMNS: [&str; 3] = ["x_int_mm", "y_int_mm", "z_int_mm"];
/// Column names of the external (R-Test) readings, x, y, z.
pub const EXT_COLUMNS: [&str; 3] = ["x_ext_mm", "y_ext_mm", "z_ext_mm"];
/// Column name of the time.
pub const TIME_COLUMN: &str = "t_s";

/// One circle test: time, internal readings (the axes' own measuring systems) and external
/// readings (R-Test sphere centre relative to the nest), all relative to the circle centre.
///
/// Validated on construction: equal lengths, at least two rows, every value finite, time
/// strictly increasing. The evaluation never re-checks these.
#[derive(Debug, Clone, PartialEq)]
pub struct CircleSeries {
    source: String,
    t_s: Vec<f64>,
    int_mm: [Vec<f64>; 3],
    ext_mm: [Vec<f64>; 3],
    /// File line of every row, when read from a file.
    lines: Option<Vec<u64>>,
    /// The file's names of the contract columns (order of [`CONTRACT_COLUMNS`]), where any
    /// differs from the contract's.
    names: Option<Box<[String; 7]>>,
}

impl CircleSeries {
    /// Builds a series from memory (e.g. handed over by the simulator), validating it like the
    /// CSV reader does. `source` names the series in error messages; rows are counted from 1.
    pub fn new(
        source: String,
        t_s: Vec<f64>,
        int_mm: [Vec<f64>; 3],
        ext_mm: [Vec<f64>; 3],
    ) -> Result<Self, RtestError> {
        let n = t_s.len();
        let whole = Location::source(&source);
        for (cols, names) in [(&int_mm, INT_COLUMNS), (&ext_mm, EXT_COLUMNS)] {
            for (col, name) in cols.iter().zip(names) {
                if col.len() != n {
                    return Err(RtestError::LengthMismatch {
                        at: whole,
                        column: name.to_string(),
                        len: col.len(),
                        expected: n,
                    });
                }
            }
        }
        let series = CircleSeries {
            source,
            t_s,
            int_mm,
            ext_mm,
            lines: None,
            names: None,
        };
        for i in 0..n {
            let cells = std::iter::once((TIME_COLUMN, series.t_s[i]))
                .chain(
                    INT_COLUMNS
                        .iter()
                        .zip(&series.int_mm)
                        .map(|(c, v)| (*c, v[i])),
                )
                .chain(
                    EXT_COLUMNS
                        .iter()
                        .zip(&series.ext_mm)
                        .map(|(c, v)| (*c, v[i])),
                );
            for (column, v) in cells {
                if !v.is_finite() {
                    return Err(RtestError::NotFinite {
                        at: series.at_row(i),
                        column: column.to_string(),
                        value: v.to_string(),
                    });
                }
            }
        }
        series.check_rows_and_time()?;
        Ok(series)
    }

    /// Reads a circle-test CSV (CONTRACT.md): required columns `t_s`, `{x,y,z}_int_mm`,
    /// `{x,y,z}_ext_mm` in any order; other columns ignored. The dialect (separator, decimal
    /// comma, comment lines, a metadata block before the header) is recognised, see
    /// [`super::layout`].
    pub fn read_csv(path: impl AsRef<Path>) -> Result<Self, RtestError> {
        Self::read_csv_with(path, &ColumnMap::default())
    }

    /// As [`CircleSeries::read_csv`], the columns named and scaled as `map` says (a folder's
    /// `rtest.toml` `[columns]`).
    pub fn read_csv_with(path: impl AsRef<Path>, map: &ColumnMap) -> Result<Self, RtestError> {
        let path = path.as_ref();
        let bytes = read_file(path)?;
        Self::from_csv_bytes_with(&path.display().to_string(), &bytes, map)
    }

    /// As [`CircleSeries::read_csv`] on the bytes of a file already read (or generated);
    /// `name` stands for the file in error messages. A leading UTF-8 byte-order mark is dropped.
    pub fn from_csv_bytes(name: &str, bytes: &[u8]) -> Result<Self, RtestError> {
        Self::from_csv_bytes_with(name, bytes, &ColumnMap::default())
    }

    /// As [`CircleSeries::from_csv_bytes`] with a column map.
    pub fn from_csv_bytes_with(
        name: &str,
        bytes: &[u8],
        map: &ColumnMap,
    ) -> Result<Self, RtestError> {
        let table = read_table(name, bytes, &CONTRACT_COLUMNS, map)?;
        let mut cols = table.columns.into_iter();
        let mut next = || cols.next().unwrap_or_default();
        let t_s = next();
        let int_mm = [next(), next(), next()];
        let ext_mm = [next(), next(), next()];
        let series = CircleSeries {
            source: name.to_string(),
            t_s,
            int_mm,
            ext_mm,
            lines: Some(table.lines),
            names: mapped_names(&table.names),
        };
        series.check_rows_and_time()?;
        Ok(series)
    }

    /// Builds a series from columns already read from files (`lines`: the file line of every
    /// row, `names`: the files' names of the seven contract columns, where they differ).
    pub(crate) fn from_parts(
        source: String,
        t_s: Vec<f64>,
        int_mm: [Vec<f64>; 3],
        ext_mm: [Vec<f64>; 3],
        lines: Option<Vec<u64>>,
        names: Option<Box<[String; 7]>>,
    ) -> Result<Self, RtestError> {
        let series = CircleSeries {
            source,
            t_s,
            int_mm,
            ext_mm,
            lines,
            names,
        };
        series.check_rows_and_time()?;
        Ok(series)
    }

    /// The file's name of a contract column with the contract name, e.g. `Time (t_s)`, or
    /// the contract name where the file uses it.
    pub fn column_label(&self, contract: &str) -> String {
        let file_name = self.names.as_ref().and_then(|names| {
            CONTRACT_COLUMNS
                .iter()
                .position(|c| *c == contract)
                .map(|i| names[i].clone())
        });
        match file_name {
            Some(n) if !n.eq_ignore_ascii_case(contract) => format!("{n} ({contract})"),
            _ => contract.to_string(),
        }
    }

    fn check_rows_and_time(&self) -> Result<(), RtestError> {
        if self.t_s.len() < 2 {
            return Err(RtestError::TooFewRows {
                at: Location::source(&self.source),
                rows: self.t_s.len(),
                needed: 2,
            });
        }
        for i in 1..self.t_s.len() {
            if self.t_s[i] <= self.t_s[i - 1] {
                return Err(RtestError::TimeNotIncreasing {
                    at: self.at_row(i),
                    t_s: self.t_s[i],
                    previous_t_s: self.t_s[i - 1],
                });
            }
        }
        Ok(())
    }

    /// The file path or in-memory name.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Always false: a valid series has at least two rows.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Time, s.
    pub fn t_s(&self) -> &[f64] {
        &self.t_s
    }

    /// Internal reading of `axis`, mm.
    pub fn int_mm(&self, axis: Axis) -> &[f64] {
        &self.int_mm[axis.index()]
    }

    /// External (R-Test) reading of `axis`, mm.
    pub fn ext_mm(&self, axis: Axis) -> &[f64] {
        &self.ext_mm[axis.index()]
    }

    /// Whether the series was read from a file (else built in memory).
    pub fn is_from_file(&self) -> bool {
        self.lines.is_some()
    }

    /// Where sample `i` (0-based) came from: a file line or an in-memory row.
    pub fn at_row(&self, i: usize) -> Location {
        let line = match &self.lines {
            Some(lines) => Line::File(lines.get(i).copied().unwrap_or(0)),
            None => Line::Row(i + 1),
        };
        Location {
            source: self.source.clone(),
            line: Some(line),
        }
    }
}

/// The index of each `wanted` column in `header` (`usize::MAX` when absent); a wanted column
/// given twice is an error, any other column goes to `other` (to be ignored or refused).
pub(crate) fn column_indices<const N: usize>(
    header: &csv::StringRecord,
    wanted: &[&str; N],
    at: &Location,
    mut other: impl FnMut(&str) -> Result<(), RtestError>,
) -> Result<[usize; N], RtestError> {
    let mut index = [usize::MAX; N];
    for (i, cell) in header.iter().enumerate() {
        match wanted.iter().position(|w| *w == cell) {
            Some(k) if index[k] != usize::MAX => {
                return Err(RtestError::DuplicateColumn {
                    at: at.clone(),
                    column: quote_cell(cell),
                })
            }
            Some(k) => index[k] = i,
            None => other(cell)?,
        }
    }
    Ok(index)
}

/// Fails naming every one of `names` whose `index` is absent.
pub(crate) fn require_columns(
    index: &[usize],
    names: &[&str],
    at: &Location,
) -> Result<(), RtestError> {
    let missing: Vec<String> = names
        .iter()
        .zip(index)
        .filter(|(_, i)| **i == usize::MAX)
        .map(|(n, _)| n.to_string())
        .collect();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(RtestError::MissingColumns {
            at: at.clone(),
            columns: missing,
            header: None,
        })
    }
}

/// The file's names where any differs from the contract's.
fn mapped_names(names: &[String]) -> Option<Box<[String; 7]>> {
    let differ = names
        .iter()
        .zip(CONTRACT_COLUMNS)
        .any(|(n, c)| !n.eq_ignore_ascii_case(c));
    let names: [String; 7] = names.to_vec().try_into().ok()?;
    differ.then(|| Box::new(names))
}

/// Reads a whole measured file (at most [`crate::io::read::MAX_SERIES_BYTES`]), telling "not
/// found" and "is a folder" apart from other failures.
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>, RtestError> {
    read_bounded(path, crate::io::read::MAX_SERIES_BYTES)
}

/// Reads a whole input file of at most `max_bytes` bytes ([`crate::io::read_input`]).
pub(crate) fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>, RtestError> {
    let name = path.display().to_string();
    crate::io::read_input(path, max_bytes).map_err(|e| match e {
        crate::io::ReadError::IsAFolder => RtestError::NotAFile { path: name },
        e => RtestError::Io {
            path: name,
            message: e.to_string(),
        },
    })
}
