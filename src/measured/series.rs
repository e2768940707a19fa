//! Circle-test series read from CSV files (docs/commands.md columns; dialects and column maps of
//! [`super::layout`]), and the column and file helpers the other readers of measured files share.

use std::path::Path;

use super::error::MeasuredError;
use super::layout::{read_table, ColumnMap};
use crate::io::delimited::quote_cell;
use crate::rtest::series::CONTRACT_COLUMNS;
use crate::rtest::{CircleSeries, Location};

impl CircleSeries {
    /// Reads a circle-test CSV (docs/commands.md): required columns `t_s`, `{x,y,z}_int_mm`,
    /// `{x,y,z}_ext_mm` in any order; other columns ignored. The dialect (separator, decimal
    /// comma, comment lines, a metadata block before the header) is recognised, see
    /// [`super::layout`].
    pub fn read_csv(path: impl AsRef<Path>) -> Result<Self, MeasuredError> {
        Self::read_csv_with(path, &ColumnMap::default())
    }

    /// As [`CircleSeries::read_csv`], the columns named and scaled as `map` says (a folder's
    /// `rtest.toml` `[columns]`).
    pub fn read_csv_with(path: impl AsRef<Path>, map: &ColumnMap) -> Result<Self, MeasuredError> {
        let path = path.as_ref();
        let bytes = read_recording(path)?;
        Self::from_csv_bytes_with(&path.display().to_string(), &bytes, map)
    }

    /// As [`CircleSeries::read_csv`] on the bytes of a file already read (or generated);
    /// `name` stands for the file in error messages. A leading UTF-8 byte-order mark is dropped.
    pub fn from_csv_bytes(name: &str, bytes: &[u8]) -> Result<Self, MeasuredError> {
        Self::from_csv_bytes_with(name, bytes, &ColumnMap::default())
    }

    /// As [`CircleSeries::from_csv_bytes`] with a column map.
    pub fn from_csv_bytes_with(
        name: &str,
        bytes: &[u8],
        map: &ColumnMap,
    ) -> Result<Self, MeasuredError> {
        Self::from_csv_placed(name, bytes, map, |_| Ok(()))
    }

    /// As [`CircleSeries::from_csv_bytes_with`], the internal columns (x, y, z, mm) handed to
    /// `place` before the series is built (absolute coordinates made relative, or refused).
    pub(crate) fn from_csv_placed(
        name: &str,
        bytes: &[u8],
        map: &ColumnMap,
        place: impl FnOnce(&mut [Vec<f64>; 3]) -> Result<(), MeasuredError>,
    ) -> Result<Self, MeasuredError> {
        if super::traces::format_of(bytes) != super::traces::Format::Delimited {
            return Err(MeasuredError::Trace {
                at: Location::source(name),
                message: "a controller trace holds only the axes' own readings: pair it with the R-Test file in rtest.toml ([[test]] internal = this file, external = the R-Test file)".into(),
            });
        }
        let table = read_table(name, bytes, &CONTRACT_COLUMNS, map)?;
        let mut cols = table.columns.into_iter();
        let mut next = || cols.next().unwrap_or_default();
        let t_s = next();
        let mut int_mm = [next(), next(), next()];
        let ext_mm = [next(), next(), next()];
        place(&mut int_mm)?;
        let names = mapped_names(&table.names);
        let series = CircleSeries::from_parts(
            name.to_string(),
            t_s,
            int_mm,
            ext_mm,
            Some(table.lines),
            names,
        )?;
        Ok(series)
    }
}

/// The index of each `wanted` column in `header` (`usize::MAX` when absent); a wanted column
/// given twice is an error, any other column goes to `other` (to be ignored or refused).
pub(crate) fn column_indices<const N: usize>(
    header: &csv::StringRecord,
    wanted: &[&str; N],
    at: &Location,
    mut other: impl FnMut(&str) -> Result<(), MeasuredError>,
) -> Result<[usize; N], MeasuredError> {
    let mut index = [usize::MAX; N];
    for (i, cell) in header.iter().enumerate() {
        match wanted.iter().position(|w| *w == cell) {
            Some(k) if index[k] != usize::MAX => {
                return Err(MeasuredError::DuplicateColumn {
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
) -> Result<(), MeasuredError> {
    let missing: Vec<String> = names
        .iter()
        .zip(index)
        .filter(|(_, i)| **i == usize::MAX)
        .map(|(n, _)| n.to_string())
        .collect();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(MeasuredError::MissingColumns {
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
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>, MeasuredError> {
    read_bounded(path, crate::io::read::MAX_SERIES_BYTES)
}

/// As [`read_file`], for a recording (R-Test CSV, controller trace): text that is not UTF-8
/// given as UTF-8 ([`utf8_of`]).
pub(crate) fn read_recording(path: &Path) -> Result<Vec<u8>, MeasuredError> {
    read_file(path).map(utf8_of)
}

/// `bytes` as UTF-8: UTF-16 with a byte-order mark (`FF FE` or `FE FF`, as spreadsheets write
/// "Unicode text") decoded; else bytes that are no UTF-8 but hold no NUL read as Latin-1 (ISO
/// 8859-1, as controls and loggers on Windows write `µm`: byte B5); anything else (binary
/// data, broken UTF-16) as it is, for the reader to refuse as not UTF-8.
pub(crate) fn utf8_of(bytes: Vec<u8>) -> Vec<u8> {
    let little = match bytes.get(..2) {
        Some([0xFF, 0xFE]) => Some(true),
        Some([0xFE, 0xFF]) => Some(false),
        _ => None,
    };
    if let Some(little) = little {
        let body = &bytes[2..];
        if body.len() % 2 != 0 {
            return bytes;
        }
        let units = body.chunks_exact(2).map(|b| {
            if little {
                u16::from_le_bytes([b[0], b[1]])
            } else {
                u16::from_be_bytes([b[0], b[1]])
            }
        });
        return match char::decode_utf16(units).collect::<Result<String, _>>() {
            Ok(s) if !s.contains('\0') => s.into_bytes(),
            _ => bytes,
        };
    }
    if std::str::from_utf8(&bytes).is_ok() || bytes.contains(&0) {
        return bytes;
    }
    bytes
        .iter()
        .map(|&b| b as char)
        .collect::<String>()
        .into_bytes()
}

/// Reads a whole input file of at most `max_bytes` bytes ([`crate::io::read_input`]).
pub(crate) fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>, MeasuredError> {
    let name = path.display().to_string();
    crate::io::read_input(path, max_bytes).map_err(|e| match e {
        crate::io::ReadError::IsAFolder => MeasuredError::NotAFile { path: name },
        e => MeasuredError::Io {
            path: name,
            message: e.to_string(),
        },
    })
}
