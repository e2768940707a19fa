//! `eij report --measured PATH... [--identify-report FILE.json] [--move FILE.csv...] --out DIR`

use std::path::PathBuf;

use eij::report::{self, ReportRequest};

/// Arguments of `eij report`.
#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    /// R-Test CSV files or folders of them (folders: every *.csv, sorted; a folder's
    /// rtest.toml gives the set radius and the circle centre position).
    #[arg(long, value_name = "PATH", num_args = 1.., required = true)]
    measured: Vec<PathBuf>,
    /// Report JSON of `eij identify --report`: parameters, correlations, per-test table and
    /// figure.
    #[arg(long, value_name = "FILE.json")]
    identify_report: Option<PathBuf>,
    /// Simulated move CSVs (`eij simulate move`), one figure each.
    #[arg(long = "move", value_name = "FILE.csv", num_args = 1..)]
    moves: Vec<PathBuf>,
    /// EIJ maps (`eij map` compensation tables), one figure each.
    #[arg(long = "map", value_name = "FILE.csv", num_args = 1..)]
    maps: Vec<PathBuf>,
    /// Report folder: report.html and the SVG figures (created if missing; only the report's
    /// own files in it are replaced).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

/// Runs `eij report`.
pub fn run(args: ReportArgs) -> anyhow::Result<()> {
    // The page can be written (no FIFO, link or folder there) before anything is evaluated.
    if args.out.is_dir() {
        eij::io::check_outputs(&[&args.out.join(report::html::REPORT_FILE)], &[])?;
    }
    let written = report::generate(&ReportRequest {
        measured: args.measured,
        identify_report: args.identify_report,
        moves: args.moves,
        extra_figures: map_figures(&args.maps)?,
        out_dir: args.out.clone(),
    })?;
    eprintln!(
        "report: {} files written, open {}",
        written.len(),
        args.out.join(report::html::REPORT_FILE).display()
    );
    Ok(())
}

/// One figure per EIJ map table.
fn map_figures(maps: &[PathBuf]) -> anyhow::Result<Vec<report::html::Figure>> {
    let axes = eij::axes::Axis::ALL;
    maps.iter()
        .enumerate()
        .map(|(i, path)| {
            let (spec, points) = eij::map::read_csv(path)?;
            let svg = report::map_svg(&path.display().to_string(), &axes, &spec, &points)?;
            Ok(report::html::Figure {
                file_name: format!("map-{:02}.svg", i + 1),
                caption: format!(
                    "EIJ map {} ({} {}, {} m/s²)",
                    path.display(),
                    spec.plane,
                    spec.direction,
                    spec.accel_m_s2
                ),
                svg,
            })
        })
        .collect()
}
