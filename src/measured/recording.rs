//! The files of a test recorded by two systems (`[[test]]` with `internal` and `external`):
//! each read into one system's [`Recording`] on its own clock, to be brought onto one time
//! base by [`crate::rtest::clock`].

use std::path::Path;

use super::error::MeasuredError;
use super::layout::{read_table, ColumnMap};
use super::series::read_recording;
use super::traces::{format_of, Format};
use crate::axes::Plane;
use crate::rtest::clock::Recording;
use crate::rtest::series::{EXT_COLUMNS, INT_COLUMNS, TIME_COLUMN};
use crate::rtest::Location;

/// Reads the internal file of a two-system test: a controller trace (TNCscope, Sinumerik,
/// [`super::traces`], recognised by content), else delimited text with `t_s` and
/// `{x,y,z}_int_mm`. `plane`, where the test states it, names the two axes a trace must hold.
pub(crate) fn read_internal(
    path: &Path,
    map: &ColumnMap,
    plane: Option<Plane>,
) -> Result<Recording, MeasuredError> {
    let name = path.display().to_string();
    let bytes = read_recording(path)?;
    match format_of(&bytes) {
        Format::Tnc => super::traces::tnc::read(&name, &bytes, map, plane),
        Format::Sinumerik => super::traces::sinumerik::read(&name, &bytes, map, plane),
        Format::Delimited => read_delimited(name, &bytes, map, &INT_COLUMNS),
    }
}

/// Reads the external file of a two-system test: `t_s` and `{x,y,z}_ext_mm`.
pub(crate) fn read_external(path: &Path, map: &ColumnMap) -> Result<Recording, MeasuredError> {
    let name = path.display().to_string();
    let bytes = read_recording(path)?;
    if format_of(&bytes) != Format::Delimited {
        return Err(MeasuredError::Trace {
            at: Location::source(&name),
            message: "a controller trace holds the axes' own readings: give it as `internal`, the R-Test file as `external`".into(),
        });
    }
    read_delimited(name, &bytes, map, &EXT_COLUMNS)
}

fn read_delimited(
    name: String,
    bytes: &[u8],
    map: &ColumnMap,
    columns: &[&str; 3],
) -> Result<Recording, MeasuredError> {
    let wanted = [TIME_COLUMN, columns[0], columns[1], columns[2]];
    let table = read_table(&name, bytes, &wanted, map)?;
    let mut cols = table.columns.into_iter();
    let mut next = || cols.next().unwrap_or_default();
    let (t_s, mm) = (next(), [next(), next(), next()]);
    Ok(Recording::with_lines(name, t_s, mm, table.lines)?)
}
