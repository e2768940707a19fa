//! EIJ table (docs/commands.md): `plane,direction,accel_m_s2,parameter,value_um_s2_per_m` and
//! optionally `std_err_um_s2_per_m`, one row per parameter value. For values taken from a
//! report, typed by hand, or written by `eij evaluate --csv-out`.

use std::fmt::Write as _;
use std::path::Path;

use super::error::MeasuredError;
use super::layout::{csv_error, parse_decimal};
use super::series::{column_indices, read_bounded, require_columns};
use crate::axes::{Direction, Eij, Plane};
use crate::io::delimited::{header_line, header_separator, quote_cell, LineCounter};
use crate::rtest::{CircleResult, Location, RtestError};
use crate::text::num;

/// Whether a file looks like an EIJ table (its header has a `parameter` column) rather than a
/// time series.
pub(crate) fn looks_like_table(path: &Path) -> bool {
    // The header is found within the first lines; a pipe or a device is never sniffed (what
    // is read from it would be lost to the reader).
    let head = |path: &Path| -> std::io::Result<Vec<u8>> {
        use std::io::Read;
        let mut b = Vec::new();
        std::fs::File::open(path)?
            .take(1 << 20)
            .read_to_end(&mut b)?;
        Ok(b)
    };
    if !path.is_file() {
        return false;
    }
    head(path)
        .map(|b| {
            let sep = header_separator(&b);
            header_line(&b).is_some_and(|line| {
                String::from_utf8_lossy(line)
                    .split(sep as char)
                    .any(|c| c.trim().trim_matches('"') == "parameter")
            })
        })
        .unwrap_or(false)
}

/// Largest |EIJ| or standard error a table may give, µm·s²/m.
pub(crate) const MAX_EIJ: f64 = 1e6;

/// Required columns, in the order written.
pub(crate) const COLUMNS: [&str; 5] = [
    "plane",
    "direction",
    "accel_m_s2",
    "parameter",
    "value_um_s2_per_m",
];
/// The optional standard-error column.
pub(crate) const STD_ERR_COLUMN: &str = "std_err_um_s2_per_m";

/// One parameter value of one test condition.
#[derive(Debug, Clone, PartialEq)]
pub struct EijRow {
    /// Circle plane.
    pub plane: Plane,
    /// Sense of rotation.
    pub direction: Direction,
    /// Set acceleration r ω², m/s².
    pub accel_m_s2: f64,
    /// The parameter; always one of the plane's six.
    pub parameter: Eij,
    /// Value, µm·s²/m.
    pub value: f64,
    /// Standard error, µm·s²/m, where known.
    pub std_err: Option<f64>,
}

/// The six rows of one evaluated circle test.
pub fn rows_from_result(result: &CircleResult) -> Vec<EijRow> {
    result
        .plane
        .parameters()
        .iter()
        .map(|p| EijRow {
            plane: result.plane,
            direction: result.direction,
            accel_m_s2: result.accel_m_s2,
            parameter: *p,
            value: result.eij[p].value,
            std_err: result.eij.std_err(p),
        })
        .collect()
}

/// Reads an EIJ table strictly: header with the five required columns (any order), the
/// optional standard-error column, nothing else; every row a known plane and direction, a
/// positive finite acceleration, a parameter of that plane, a finite value and, where given,
/// a finite positive standard error (an empty cell means unknown); no parameter of a test
/// (plane, direction, acceleration) twice. At least one row. Separator `,`, `;` or tab (decimal
/// comma where `,` is not the separator) and `#` comment lines are recognised.
pub fn read(path: impl AsRef<Path>) -> Result<Vec<EijRow>, MeasuredError> {
    let path = path.as_ref();
    let bytes = read_bounded(path, crate::io::read::MAX_TEXT_BYTES)?;
    from_bytes(&path.display().to_string(), &bytes)
}

/// As [`read`] on the bytes of a file already read; `name` stands for the file in error
/// messages. A leading UTF-8 byte-order mark is dropped.
pub fn from_bytes(name: &str, bytes: &[u8]) -> Result<Vec<EijRow>, MeasuredError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let name = name.to_string();
    let separator = header_separator(bytes);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .delimiter(separator)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(bytes);
    // A decimal comma where `,` is not the separator.
    let number = |text: &str, line: u64, column: &str| {
        parse_decimal(text, separator != b',', &name, line, column)
    };
    let mut counter = LineCounter::new(bytes);
    let mut records = reader.records();
    let expected = || format!("{},{}", COLUMNS.join(","), STD_ERR_COLUMN);
    let header = match records.next() {
        None => {
            return Err(MeasuredError::Empty {
                at: Location::source(&name),
                expected: expected(),
            })
        }
        Some(r) => r.map_err(|e| csv_error(&name, &mut counter, e))?,
    };
    let header_at = Location::file_line(&name, counter.line_of_record(&header));
    let wanted = [
        COLUMNS[0],
        COLUMNS[1],
        COLUMNS[2],
        COLUMNS[3],
        COLUMNS[4],
        STD_ERR_COLUMN,
    ];
    // An unknown column is refused: a typo must not drop the standard errors silently.
    let index = column_indices(&header, &wanted, &header_at, |cell| {
        Err(MeasuredError::UnknownColumn {
            at: header_at.clone(),
            column: quote_cell(cell),
            expected: expected(),
        })
    })?;
    require_columns(&index[..COLUMNS.len()], &COLUMNS, &header_at)?;
    let mut rows = Vec::new();
    let mut seen = std::collections::HashMap::new();
    for record in records {
        let record = record.map_err(|e| csv_error(&name, &mut counter, e))?;
        let line = counter.line_of_record(&record);
        let at = || Location::file_line(&name, line);
        // Quoting changes only text that is no valid plane, direction or parameter anyway, and
        // keeps such text readable and on one line in the error.
        let raw = |k: usize| record.get(index[k]).unwrap_or("");
        let cell = |k: usize| quote_cell(raw(k));
        let bad = |k: usize, message: String| MeasuredError::BadValue {
            at: at(),
            column: COLUMNS[k].to_string(),
            message,
        };
        let plane: Plane = cell(0).parse().map_err(|m| bad(0, m))?;
        let direction: Direction = cell(1).parse().map_err(|m| bad(1, m))?;
        let accel_m_s2 = number(raw(2), line, COLUMNS[2])?;
        if accel_m_s2 <= 0.0 {
            return Err(bad(
                2,
                format!("acceleration {} must be positive", num(accel_m_s2)),
            ));
        }
        // The range of circle tests (the evaluation's plausibility check of a series).
        if !(0.01..=1000.0).contains(&accel_m_s2) {
            return Err(bad(
                2,
                format!(
                    "acceleration {} m/s² is implausible for a circle test (expected 0.01–1000)",
                    num(accel_m_s2)
                ),
            ));
        }
        let parameter: Eij = cell(3).parse().map_err(|m| bad(3, m))?;
        if !plane.parameters().contains(&parameter) {
            return Err(bad(
                3,
                format!("{parameter} is not a parameter of plane {plane}"),
            ));
        }
        let value = number(raw(4), line, COLUMNS[4])?;
        // 1e6 µm·s²/m is 1 m of deviation per m/s²: beyond it a value is a unit slip.
        if value.abs() > MAX_EIJ {
            return Err(bad(
                4,
                format!(
                    "{} µm·s²/m is implausible for an EIJ (at most ±{}; units?)",
                    num(value),
                    num(MAX_EIJ)
                ),
            ));
        }
        let std_err = match index[5] {
            usize::MAX => None,
            i => match record.get(i).unwrap_or("") {
                "" => None,
                text => {
                    let s = number(text, line, STD_ERR_COLUMN)?;
                    if s <= 0.0 || s > MAX_EIJ {
                        return Err(MeasuredError::BadValue {
                            at: at(),
                            column: STD_ERR_COLUMN.into(),
                            message: format!(
                                "standard error {} must be positive (a zero would give the \
                                 value infinite weight; leave the cell empty when unknown) and \
                                 at most {}",
                                num(s),
                                num(MAX_EIJ)
                            ),
                        });
                    }
                    Some(s)
                }
            },
        };
        let key = (plane, direction, accel_m_s2.to_bits(), parameter);
        if let Some(first) = seen.insert(key, line) {
            return Err(bad(
                3,
                format!(
                    "{parameter} of {plane} {direction} at {} m/s² given twice \
                     (first on line {first})",
                    num(accel_m_s2)
                ),
            ));
        }
        rows.push(EijRow {
            plane,
            direction,
            accel_m_s2,
            parameter,
            value,
            std_err,
        });
    }
    if rows.is_empty() {
        return Err(RtestError::TooFewRows {
            at: Location::source(&name),
            rows: 0,
            needed: 1,
        }
        .into());
    }
    Ok(rows)
}

/// The table as CSV text; the standard-error column is written when any row has one (empty
/// cells for the others). Numbers use the shortest representation that reads back exactly.
pub fn to_csv(rows: &[EijRow]) -> String {
    let with_se = rows.iter().any(|r| r.std_err.is_some());
    let mut out = COLUMNS.join(",");
    if with_se {
        out.push(',');
        out.push_str(STD_ERR_COLUMN);
    }
    out.push('\n');
    for r in rows {
        let _ = write!(
            out,
            "{},{},{},{},{}",
            r.plane, r.direction, r.accel_m_s2, r.parameter, r.value
        );
        if with_se {
            out.push(',');
            if let Some(s) = r.std_err {
                let _ = write!(out, "{s}");
            }
        }
        out.push('\n');
    }
    out
}

/// Writes the table atomically ([`crate::io::write_atomic`]); refuses to replace any of
/// `inputs`.
pub fn write(
    path: impl AsRef<Path>,
    rows: &[EijRow],
    inputs: &[&Path],
) -> Result<(), MeasuredError> {
    crate::io::write_atomic(path.as_ref(), to_csv(rows).as_bytes(), inputs)?;
    Ok(())
}
