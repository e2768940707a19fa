//! What was measured, read from files: R-Test circle-test series in their CSV dialects and
//! column maps ([`layout`], [`series`]), a folder's test conditions (`rtest.toml`, [`conditions`])
//! and the tests they make ([`inputs`]), two-system recordings ([`recording`]), EIJ tables
//! ([`table`]) and the evaluation JSON ([`json`]), positioning moves ([`moves`]), controller traces
//! as internal recordings (TNCscope, Sinumerik: [`traces`]), folders of two-system recordings
//! paired by pattern (`[[pairing]]`) and internal readings in absolute machine coordinates
//! (`internal_coordinates`); and the
//! evaluation of a command's measured tests as one suite ([`suite`]: clocks aligned, each test
//! evaluated by [`crate::rtest`] at its conditions, cw/ccw pairs).
//!
//! A new file format goes here: a reader into the types [`crate::rtest`] evaluates, with its
//! errors as [`MeasuredError`] (one line naming file, line or key, and what is wrong).
//!
//! ```no_run
//! use eij::measured::inputs::expand_tests;
//! use eij::measured::suite::{evaluate_tests, SuiteOptions};
//!
//! # fn main() -> Result<(), eij::measured::MeasuredError> {
//! let tests = expand_tests(&["measurements/demo-vmc/pos-a".into()])?;
//! let suite = evaluate_tests(&tests, &SuiteOptions::default())?;
//! for t in &suite.tests {
//!     println!("{} {:?}", t.result.source, t.result.eij);
//! }
//! # Ok(())
//! # }
//! ```

pub mod conditions;
pub(crate) mod coordinates;
pub(crate) mod entries;
pub(crate) mod error;
pub mod history;
pub mod inputs;
pub mod json;
pub(crate) mod layout;
pub mod moves;
pub(crate) mod pairing;
pub(crate) mod recording;
pub(crate) mod series;
pub mod suite;
pub mod table;
pub mod traces;

pub use error::MeasuredError;
