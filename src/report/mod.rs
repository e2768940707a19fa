//! Figures and reports from eij's own data: SVG plots (plotters, SVG backend only) and one
//! self-contained HTML page.
//!
//! ```text
//! CircleSeries ─► CircleView ─► magnified_svg      (paper Fig. 5, 8: paths, set circle, ellipses)
//!                            └► out_of_plane_svg  (paper Fig. 4, 7: d_k over φ, fitted plane)
//! move CSV / sim::Run ─► MoveData ─► move_svg      (paper Fig. 9: position, acceleration, cross-talk)
//! identify report JSON ─► identification_svg        (measured vs simulated EIJ, cost history)
//! map::eij_map points ─► map_svg                   (EIJ over the workspace)
//! cw/ccw pairs (measured::suite) ─► circle_group ─► polar_svg (ISO 230-4 circle plot, µm rings)
//!                                             └► polar::out_of_plane_svg (cw and ccw over φ)
//! identify reports ─► verdict (standing, χ², warnings), compare (side by side)
//! eij compare report ─► model_compare (verdict, candidates' criteria; their identifications join the rest)
//! measured::suite::diagnose ─► diagnosis_html (per test and source, beside the circle plot)
//!                           └► certificate (one A4 page: machine, date, tolerances, pass/fail)
//! measured::history (dated runs) ─► history_html (terms and EIJ over time, trend plots, drift)
//! all of it ─► html::generate ─► DIR/report.html (figures inline, page::Page)
//! ```
//!
//! Every figure states its conditions (source, machine where known, plane, radius, direction,
//! acceleration, frequency, magnification, position where known) and units on its axes.
//! Series colours are the public constants of [`svg`] and [`polar`], so that tests and
//! scripts can find a series in the SVG by its stroke or fill colour.
//!
//! EIJ maps over the workspace ([`map_svg`], from `eij map`) enter a report as further
//! [`html::Figure`]s through [`html::ReportRequest::extra_figures`].

use crate::measured::conditions::TestConditions;
use std::path::Path;

pub(crate) mod certificate;
pub(crate) mod circle;
pub(crate) mod circle_group;
pub(crate) mod clocks_html;
pub(crate) mod compare;
pub(crate) mod diagnosis_html;
pub(crate) mod history_html;
pub mod html;
pub(crate) mod ident_html;
pub(crate) mod ident_plot;
pub mod labels;
pub(crate) mod map_plot;
pub(crate) mod model_compare;
pub(crate) mod move_plot;
pub(crate) mod page;
pub(crate) mod polar;
pub mod stiffness;
pub mod svg;
pub mod verdict;

pub use circle::CircleView;
pub use html::{generate, ReportRequest};
pub use ident_plot::identification_svg;
pub use map_plot::map_svg;
pub use move_plot::{move_svg, MoveData};
pub use stiffness::stiffness_html;

/// Reads an input file of the report (the R-Test reader's, telling a missing file and a folder
/// apart from other failures).
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>, ReportError> {
    Ok(crate::measured::series::read_file(path)?)
}

/// Errors of the figures and the report; every message is one line naming the file or key.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// Reading or evaluating a circle test failed.
    #[error(transparent)]
    Rtest(#[from] crate::rtest::RtestError),
    /// Reading a measured file failed (the message names file and line or key).
    #[error(transparent)]
    Measured(#[from] crate::measured::MeasuredError),
    /// A file holds something unusable (missing column, bad number, ...).
    #[error("{source_name}: {message}")]
    BadInput {
        /// The file (with line where one applies) or in-memory name.
        source_name: String,
        /// What is wrong.
        message: String,
    },
    /// Drawing failed (plotters).
    #[error("drawing {figure}: {message}")]
    Plot {
        /// Which figure.
        figure: String,
        /// The drawing error.
        message: String,
    },
    /// The output folder cannot be used.
    #[error("{path}: {message}")]
    Output {
        /// The folder.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// Writing an output file failed.
    #[error(transparent)]
    Write(#[from] crate::io::WriteError),
    /// SOURCE_DATE_EPOCH is set but is not a time.
    #[error(transparent)]
    SourceDate(#[from] crate::ident::report::SourceDateError),
}

/// What is known about where and on what a test ran, for titles and captions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Conditions {
    /// File path or in-memory name of the data.
    pub source: String,
    /// Machine name or file, where known.
    pub machine: Option<String>,
    /// Axis positions of the circle centre or move start, mm, in the machine's axis order.
    pub position_mm: Option<Vec<f64>>,
}

impl Conditions {
    /// Conditions of a measured file: its path and the position from its folder's
    /// `rtest.toml`, if any.
    pub fn of_file(file: &Path) -> Result<Self, ReportError> {
        Ok(Conditions {
            source: file.display().to_string(),
            machine: None,
            position_mm: TestConditions::of_file(file)?.position_mm,
        })
    }

    /// One caption line: source, machine and position where known.
    pub fn line(&self, position_of: &str) -> String {
        let mut parts = vec![format!("source: {}", self.source)];
        if let Some(m) = &self.machine {
            parts.push(format!("machine: {m}"));
        }
        if let Some(p) = &self.position_mm {
            let p: Vec<String> = p.iter().map(|v| format!("{v:.1}")).collect();
            parts.push(format!(
                "{position_of} at axis positions [{}] mm",
                p.join(", ")
            ));
        }
        parts.join("  ·  ")
    }
}

/// A number in a short form for titles: up to `max_decimals`, trailing zeros dropped.
pub(crate) fn short(v: f64, max_decimals: usize) -> String {
    let s = format!("{v:.max_decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}
