//! Circle-test time series (docs/commands.md columns), validated on construction. Files are read
//! into it by [`crate::measured`] (`CircleSeries::read_csv` and its variants), the simulator
//! hands its runs over through [`CircleSeries::new`].

use super::error::{Line, Location, RtestError};
use crate::axes::Axis;

/// Column names of the internal readings, x, y, z.
pub(crate) const INT_COLUMNS: [&str; 3] = ["x_int_mm", "y_int_mm", "z_int_mm"];
/// Column names of the external (R-Test) readings, x, y, z.
pub(crate) const EXT_COLUMNS: [&str; 3] = ["x_ext_mm", "y_ext_mm", "z_ext_mm"];
/// Column name of the time.
pub(crate) const TIME_COLUMN: &str = "t_s";
/// The contract columns of an R-Test series: time, internal x, y, z, external x, y, z.
pub(crate) const CONTRACT_COLUMNS: [&str; 7] = [
    "t_s", "x_int_mm", "y_int_mm", "z_int_mm", "x_ext_mm", "y_ext_mm", "z_ext_mm",
];

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
    pub(crate) fn column_label(&self, contract: &str) -> String {
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
    pub(crate) fn is_from_file(&self) -> bool {
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
