//! Errors of reading what was measured (circle-test series, `rtest.toml`, EIJ tables): every
//! message is one line naming the file, the line or key where one applies, and what is wrong.
//! A series that is read but fails the evaluation carries the evaluation's error
//! ([`RtestError`]) unchanged.

use crate::rtest::{Location, RtestError};

/// Everything that can go wrong reading circle tests, their conditions and EIJ tables, and
/// evaluating what was read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasuredError {
    /// The file could not be opened or read.
    #[error("{path}: cannot read: {message}")]
    Io {
        /// The path given.
        path: String,
        /// What the operating system said (or "file not found").
        message: String,
    },
    /// The path names a folder.
    #[error("{path}: is a folder, not a file")]
    NotAFile {
        /// The path given.
        path: String,
    },
    /// No header line at all.
    #[error("{at}: empty file (expected a header line with {expected})")]
    Empty {
        /// The file.
        at: Location,
        /// The required columns.
        expected: String,
    },
    /// The file is not well-formed CSV (e.g. a row with the wrong number of fields).
    #[error("{at}: {message}")]
    Csv {
        /// Where.
        at: Location,
        /// What the CSV reader found.
        message: String,
    },
    /// A controller trace (TNCscope, Sinumerik) that does not hold what its format promises or
    /// what a circle test needs (channels, units, rows, well-formed XML).
    #[error("{at}: {message}")]
    Trace {
        /// Where.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// Required columns are missing from the header.
    #[error(
        "{at}: missing column(s) {}{}",
        columns.join(", "),
        header.as_ref().map_or(String::new(), |h| format!(" (header read: {h})"))
    )]
    MissingColumns {
        /// The header line.
        at: Location,
        /// The missing names.
        columns: Vec<String>,
        /// The header as read, with the separator recognised, where that helps.
        header: Option<String>,
    },
    /// A required column appears twice.
    #[error("{at}: duplicate column '{column}'")]
    DuplicateColumn {
        /// The header line.
        at: Location,
        /// The repeated name.
        column: String,
    },
    /// A column that this reader does not know (EIJ tables only, to catch typos).
    #[error("{at}: unknown column '{column}' (expected {expected})")]
    UnknownColumn {
        /// The header line.
        at: Location,
        /// The unknown name.
        column: String,
        /// The known names.
        expected: String,
    },
    /// A cell that is not a number.
    #[error("{at}: column {column}: '{value}' is not a number")]
    NotANumber {
        /// Where.
        at: Location,
        /// The column.
        column: String,
        /// The cell text.
        value: String,
    },
    /// A cell that is NaN or infinite.
    #[error("{at}: column {column}: '{value}' is not a finite number")]
    NotFinite {
        /// Where.
        at: Location,
        /// The column.
        column: String,
        /// The cell text.
        value: String,
    },
    /// An invalid `rtest.toml` (test conditions of a folder).
    #[error("{file}: {key}: {message}")]
    Conditions {
        /// The conditions file.
        file: String,
        /// The key.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// The two recordings of a two-system test are not of one circle (plane, direction or
    /// frequency differ): files paired wrongly.
    #[error("{test}: not one test: {message}")]
    NotOnePair {
        /// The test (`internal + external`).
        test: String,
        /// What differs, and how the files were paired.
        message: String,
    },
    /// A cell with a value outside its domain (EIJ tables: plane, direction, parameter, ...).
    #[error("{at}: column {column}: {message}")]
    BadValue {
        /// Where.
        at: Location,
        /// The column.
        column: String,
        /// What is wrong.
        message: String,
    },
    /// Writing an output file failed.
    #[error(transparent)]
    Write(#[from] WriteFailure),
    /// A series read from a file fails the evaluation's own checks, or its evaluation failed.
    #[error(transparent)]
    Evaluation(#[from] RtestError),
}

/// A failed output write (wraps [`crate::io::WriteError`], kept as text so that
/// [`MeasuredError`] stays `Clone + PartialEq`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct WriteFailure(pub String);

impl From<crate::io::WriteError> for MeasuredError {
    fn from(e: crate::io::WriteError) -> Self {
        MeasuredError::Write(WriteFailure(e.to_string()))
    }
}
