//! Errors of the R-Test evaluation: every message is one line naming the source (file or
//! in-memory series), the line or row where one applies, and what is wrong. Reading files has
//! its own errors ([`crate::measured::MeasuredError`]), which carry these where a file's
//! series fails the evaluation.

use std::fmt;

/// Where in a source a problem was found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// File path, or the name given to an in-memory series.
    pub source: String,
    /// Line in the file (1-based, the header is line 1) or row of an in-memory series.
    pub line: Option<Line>,
}

/// A position inside a source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Line {
    /// Line of a text file, 1-based.
    File(u64),
    /// Row of an in-memory series, 1-based.
    Row(usize),
}

impl Location {
    /// The source as a whole.
    pub fn source(source: &str) -> Self {
        Location {
            source: source.to_string(),
            line: None,
        }
    }

    /// A line of a file.
    pub(crate) fn file_line(source: &str, line: u64) -> Self {
        Location {
            source: source.to_string(),
            line: Some(Line::File(line)),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            None => write!(f, "{}", self.source),
            Some(Line::File(l)) => write!(f, "{}:{}", self.source, l),
            Some(Line::Row(r)) => write!(f, "{}: row {}", self.source, r),
        }
    }
}

/// Everything that can go wrong evaluating a circle test (in-memory or read from a file).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RtestError {
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
    /// An option outside its domain (the set radius).
    #[error("{at}: column {column}: {message}")]
    BadValue {
        /// The series.
        at: Location,
        /// The option.
        column: String,
        /// What is wrong.
        message: String,
    },
    /// Fewer data rows than needed.
    #[error("{at}: {rows} data row(s), at least {needed} needed")]
    TooFewRows {
        /// The source.
        at: Location,
        /// Rows found.
        rows: usize,
        /// Rows needed.
        needed: usize,
    },
    /// Time does not increase strictly.
    #[error("{at}: t_s = {t_s} does not increase (previous row {previous_t_s})")]
    TimeNotIncreasing {
        /// Where.
        at: Location,
        /// This row's time.
        t_s: f64,
        /// The previous row's time.
        previous_t_s: f64,
    },
    /// Columns of an in-memory series differ in length.
    #[error("{at}: column {column} has {len} values, t_s has {expected}")]
    LengthMismatch {
        /// The series.
        at: Location,
        /// The column.
        column: String,
        /// Its length.
        len: usize,
        /// The length of `t_s`.
        expected: usize,
    },
    /// Values that are plausible only as micrometres in a millimetre column.
    #[error("{at}: column {column}: {detail}; values look like µm, expected mm")]
    LooksLikeMicrometres {
        /// Where.
        at: Location,
        /// The column.
        column: String,
        /// The observation behind the guess.
        detail: String,
    },
    /// Values that cannot be what the column's name says: wrong units of time, a dead probe.
    #[error("{at}: column {column}: {detail}")]
    Implausible {
        /// The source.
        at: Location,
        /// The column (the file's name, with the contract name where they differ).
        column: String,
        /// What was found, and the likely cause.
        detail: String,
    },
    /// External minus internal beyond the R-Test measuring range.
    #[error(
        "{at}: column {axis}_ext_mm: deviation {deviation_mm:.4} mm from {axis}_int_mm is beyond \
         the R-Test range ±{range_mm} mm{}",
        if *looks_like_um { " (values look like µm, expected mm)" } else { "" }
    )]
    ProbeRange {
        /// Where.
        at: Location,
        /// The axis whose external column is out of range.
        axis: crate::axes::Axis,
        /// ext − int, mm.
        deviation_mm: f64,
        /// The range, mm.
        range_mm: f64,
        /// The external value read as µm would be in range.
        looks_like_um: bool,
    },
    /// No circular motion in the internal readings.
    #[error("{at}: no circular motion in the internal readings ({detail})")]
    NoMotion {
        /// The source.
        at: Location,
        /// Amplitudes seen.
        detail: String,
    },
    /// The plane cannot be told from the data.
    #[error("{at}: circle plane is ambiguous ({detail})")]
    AmbiguousPlane {
        /// The source.
        at: Location,
        /// Amplitudes seen.
        detail: String,
    },
    /// The measured radius is far from the set radius.
    #[error(
        "{at}: mean internal radius {measured_mm:.4} mm differs from the set radius \
         {set_mm} mm by more than 10 %"
    )]
    RadiusMismatch {
        /// The source.
        at: Location,
        /// Mean internal radius, mm.
        measured_mm: f64,
        /// Set radius, mm.
        set_mm: f64,
    },
    /// Not enough steady motion to evaluate.
    #[error("{at}: {detail}")]
    TooShort {
        /// The source.
        at: Location,
        /// What is missing.
        detail: String,
    },
    /// A least-squares problem without a unique solution.
    #[error("{at}: {detail}")]
    Singular {
        /// The source.
        at: Location,
        /// Which fit and why.
        detail: String,
    },
    /// Inputs of a pooled evaluation that do not go together.
    #[error("{at}: {detail}")]
    Pooling {
        /// The source that does not fit, or the whole set.
        at: Location,
        /// What is wrong.
        detail: String,
    },
}
