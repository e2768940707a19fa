//! `eij report --measured PATH... [--identify-report FILE.json]... [--move FILE.csv...]
//! [--map FILE.csv...] [--history RUN...] --out DIR`

use std::path::PathBuf;

use eij::report::{self, ReportRequest};

/// Arguments of `eij report`: at least one of `--measured`, `--identify-report`, `--move`,
/// `--map`.
#[derive(Debug, clap::Args)]
#[command(group(
    clap::ArgGroup::new("inputs")
        .required(true)
        .multiple(true)
        .args(["measured", "identify_report", "compare_report", "moves", "maps", "history"])
))]
pub struct ReportArgs {
    /// R-Test CSV files or folders of them (folders: every *.csv, sorted; a folder's
    /// rtest.toml gives the set radius and the circle centre position).
    #[arg(long, value_name = "PATH", num_args = 1..)]
    measured: Vec<PathBuf>,
    /// Report JSON of `eij identify --report`: verdict, parameters, correlations, per-test
    /// table and figure. Repeatable: several reports (before/after a repair, two machines, two
    /// dates) are compared side by side, in the order given.
    #[arg(long, value_name = "FILE.json")]
    identify_report: Vec<PathBuf>,
    /// Report JSON of `eij compare --report`: the model comparison first (verdict, candidates
    /// with s, χ² test, BIC, AIC, hold-out), each candidate's identification with the others.
    #[arg(long, value_name = "FILE.json")]
    compare_report: Option<PathBuf>,
    /// Simulated move CSVs (`eij simulate move`), one figure each.
    #[arg(long = "move", value_name = "FILE.csv", num_args = 1..)]
    moves: Vec<PathBuf>,
    /// EIJ maps (`eij map` compensation tables), one figure each.
    #[arg(long = "map", value_name = "FILE.csv", num_args = 1..)]
    maps: Vec<PathBuf>,
    /// Dated runs of one machine, lined up in a history section (each EIJ and diagnosis term
    /// over time, drift flagged): folders whose rtest.toml gives a `date`, or the output of
    /// `eij evaluate … --diagnose --json`; at least two.
    #[arg(long, value_name = "RUN", num_args = 2..)]
    history: Vec<PathBuf>,
    /// Report folder: report.html, one self-contained page with every figure inline (created
    /// if missing; only report.html in it is replaced).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

/// Runs `eij report`.
pub fn run(args: ReportArgs) -> anyhow::Result<()> {
    // The page can be written (no FIFO, link or folder there) before anything is evaluated.
    if args.out.is_dir() {
        eij::io::check_outputs(&[&args.out.join(report::html::REPORT_FILE)], &[])?;
    }
    let spinner = super::console::Progress::spinner("report: reading, evaluating and drawing");
    let page = report::generate(&ReportRequest {
        measured: args.measured,
        identify_reports: args.identify_report,
        compare_report: args.compare_report,
        moves: args.moves,
        extra_figures: map_figures(&args.maps)?,
        history: args.history,
        out_dir: args.out,
    })?;
    drop(spinner);
    super::console::status(format_args!(
        "wrote {} (one page, figures inline)",
        page.display()
    ));
    Ok(())
}

/// One figure per EIJ map table, titled by the machine it maps.
fn map_figures(maps: &[PathBuf]) -> anyhow::Result<Vec<report::html::Figure>> {
    let axes = eij::axes::Axis::ALL;
    maps.iter()
        .enumerate()
        .map(|(i, path)| {
            let table = eij::map::read_csv(path)?;
            let machine = table.machine.clone().unwrap_or_else(|| {
                format!(
                    "an unnamed machine ({} has no machine column)",
                    path.display()
                )
            });
            let spec = &table.spec;
            let svg = report::map_svg(&machine, &axes, spec, &table.points)?;
            Ok(report::html::Figure {
                id: format!("map-{}", i + 1),
                caption: format!(
                    "EIJ map of {machine} ({}): {} {} circles at {} m/s²",
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
