//! EIJ table (docs/commands.md): `plane,direction,accel_m_s2,parameter,value_um_s2_per_m` and
//! optionally `std_err_um_s2_per_m`, `radius_mm` and the circle centre `position_x_mm`,
//! `position_y_mm`, `position_z_mm`, one row per parameter value. For values taken from a
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
/// The optional columns of the test's conditions: its set radius and circle centre, written
/// by `eij evaluate --csv-out` so that identify places every test where it was run.
pub(crate) const CONDITION_COLUMNS: [&str; 4] = [
    "radius_mm",
    "position_x_mm",
    "position_y_mm",
    "position_z_mm",
];

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
    /// Set radius of the test, mm, where the table gives it (`radius_mm`).
    pub radius_mm: Option<f64>,
    /// Circle centre of the test, x, y, z, mm, where the table gives it (`position_x_mm`, …).
    pub position_mm: Option<[f64; 3]>,
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
            radius_mm: None,
            position_mm: None,
        })
        .collect()
}

/// The six rows of one evaluated test with its set radius and circle centre (where its
/// conditions give one; missing trailing axes 0).
pub fn rows_of_test(t: &super::suite::EvaluatedTest) -> Vec<EijRow> {
    let position_mm = t.input.test.position_mm.as_ref().map(|p| {
        let mut xyz = [0.0; 3];
        for (dst, src) in xyz.iter_mut().zip(p) {
            *dst = *src;
        }
        xyz
    });
    rows_from_result(&t.result)
        .into_iter()
        .map(|r| EijRow {
            radius_mm: Some(t.result.radius_mm),
            position_mm,
            ..r
        })
        .collect()
}

/// Reads an EIJ table strictly: header with the five required columns (any order), the
/// optional standard-error column, the optional set radius `radius_mm` and circle centre
/// (`position_x_mm`, `position_y_mm`, `position_z_mm`, all three or none), nothing else; every row a known plane and direction, a
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
    let expected = || {
        format!(
            "{},{},{}",
            COLUMNS.join(","),
            STD_ERR_COLUMN,
            CONDITION_COLUMNS.join(",")
        )
    };
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
        CONDITION_COLUMNS[0],
        CONDITION_COLUMNS[1],
        CONDITION_COLUMNS[2],
        CONDITION_COLUMNS[3],
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
    // The circle centre is three columns or none.
    let position = &index[7..10];
    if position.iter().any(|i| *i != usize::MAX) {
        require_columns(position, &CONDITION_COLUMNS[1..], &header_at)?;
    }
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
        let (radius_mm, position_mm) = conditions(&record, &index, &name, line, &number)?;
        let key = (
            plane,
            direction,
            accel_m_s2.to_bits(),
            parameter,
            radius_mm.map(f64::to_bits),
            position_mm.map(|p| p.map(f64::to_bits)),
        );
        if let Some(first) = seen.insert(key, line) {
            return Err(bad(
                3,
                format!(
                    "{parameter} of {plane} {direction} at {} m/s²{} given twice \
                     (first on line {first})",
                    num(accel_m_s2),
                    position_mm.map_or(String::new(), |p| format!(
                        " at {} mm",
                        crate::text::nums(&p)
                    ))
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
            radius_mm,
            position_mm,
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

/// The set radius and circle centre of one row (empty cells: not given), checked: a radius in
/// (0, 3] mm, a centre of three finite values within ±1e5 mm or none.
fn conditions(
    record: &csv::StringRecord,
    index: &[usize; 10],
    name: &str,
    line: u64,
    number: &dyn Fn(&str, u64, &str) -> Result<f64, MeasuredError>,
) -> Result<(Option<f64>, Option<[f64; 3]>), MeasuredError> {
    let cell = |k: usize| match index[k] {
        usize::MAX => None,
        i => Some(record.get(i).unwrap_or("")).filter(|t| !t.is_empty()),
    };
    let bad = |column: &str, message: String| MeasuredError::BadValue {
        at: Location::file_line(name, line),
        column: column.to_string(),
        message,
    };
    let radius_mm = match cell(6) {
        None => None,
        Some(t) => {
            let r = number(t, line, CONDITION_COLUMNS[0])?;
            if !(r > 0.0 && r <= 3.0) {
                return Err(bad(
                    CONDITION_COLUMNS[0],
                    format!("{} must lie in (0, 3] mm", num(r)),
                ));
            }
            Some(r)
        }
    };
    let cells = [cell(7), cell(8), cell(9)];
    let position_mm = match cells {
        [None, None, None] => None,
        [Some(x), Some(y), Some(z)] => {
            let mut p = [0.0; 3];
            for (k, (v, t)) in p.iter_mut().zip([x, y, z]).enumerate() {
                *v = number(t, line, CONDITION_COLUMNS[k + 1])?;
                if v.abs() > 1e5 {
                    return Err(bad(
                        CONDITION_COLUMNS[k + 1],
                        format!("{} mm is beyond ±1e5 mm", num(*v)),
                    ));
                }
            }
            Some(p)
        }
        _ => {
            let k = cells.iter().position(Option::is_none).unwrap_or(0);
            return Err(bad(
                CONDITION_COLUMNS[k + 1],
                "empty while other position cells of the row are given (a circle centre \
                 needs x, y and z, or none)"
                    .into(),
            ));
        }
    };
    Ok((radius_mm, position_mm))
}

/// The table as CSV text; the standard-error column is written when any row has one, the
/// radius and the circle-centre columns when any row has them (empty cells for the others).
/// Numbers use the shortest representation that reads back exactly.
pub fn to_csv(rows: &[EijRow]) -> String {
    let with_se = rows.iter().any(|r| r.std_err.is_some());
    let with_radius = rows.iter().any(|r| r.radius_mm.is_some());
    let with_position = rows.iter().any(|r| r.position_mm.is_some());
    let mut out = COLUMNS.join(",");
    if with_se {
        out.push(',');
        out.push_str(STD_ERR_COLUMN);
    }
    if with_radius {
        out.push(',');
        out.push_str(CONDITION_COLUMNS[0]);
    }
    if with_position {
        out.push(',');
        out.push_str(&CONDITION_COLUMNS[1..].join(","));
    }
    out.push('\n');
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v}"));
    for r in rows {
        let _ = write!(
            out,
            "{},{},{},{},{}",
            r.plane, r.direction, r.accel_m_s2, r.parameter, r.value
        );
        if with_se {
            let _ = write!(out, ",{}", opt(r.std_err));
        }
        if with_radius {
            let _ = write!(out, ",{}", opt(r.radius_mm));
        }
        if with_position {
            let p = r.position_mm;
            for k in 0..3 {
                let _ = write!(out, ",{}", opt(p.map(|p| p[k])));
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
