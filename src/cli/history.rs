//! `eij history RUN… [--json] [--all]`: several dated evaluations of one machine lined up, each
//! diagnosis term and each EIJ over time with its standard error, drift flagged
//! ([`eij::measured::history`]).

use std::fmt::Write as _;
use std::path::PathBuf;

use eij::measured::history::{history, History, QuantityHistory, DRIFT_Z};
use eij::text::unit_symbol;

/// Arguments of `eij history`.
#[derive(Debug, clap::Args)]
pub struct HistoryArgs {
    /// Runs, at least two: folders (or files) of R-Test tests whose rtest.toml gives their
    /// `date`, or the output of `eij evaluate … --diagnose --json`.
    #[arg(value_name = "RUN", num_args = 2.., required = true)]
    runs: Vec<PathBuf>,
    /// Print one JSON object (every quantity) instead of the tables.
    #[arg(long)]
    json: bool,
    /// Show every term, also those within 3 standard errors of 0 in every run.
    #[arg(long)]
    all: bool,
}

/// Runs `eij history`.
pub fn run(args: HistoryArgs) -> anyhow::Result<()> {
    let h = history(&args.runs)?;
    let drifted = h.drifted().count();
    if args.json {
        let mut doc = serde_json::to_value(&h)?;
        doc["drift_z"] = DRIFT_Z.into();
        doc["drifted"] = drifted.into();
        outln!("{doc}");
    } else {
        out!("{}", render(&h, args.all));
    }
    if drifted > 0 {
        errln!(
            "eij: drift: {drifted} quantit{} changed beyond {DRIFT_Z} combined standard errors \
             from the first run",
            if drifted == 1 { "y" } else { "ies" }
        );
    }
    Ok(())
}

/// The history as text: the runs, the drift, and per group a table of quantities over runs.
pub fn render(h: &History, all: bool) -> String {
    let mut out = String::new();
    let machine = h.machine.as_deref().unwrap_or("a machine not named");
    let _ = writeln!(out, "History of {machine}: {} runs", h.runs.len());
    for (i, r) in h.runs.iter().enumerate() {
        let _ = writeln!(
            out,
            "  run {}  {}  day {:>6.1}  {:>3} tests  {}",
            i + 1,
            r.date,
            r.days,
            r.tests,
            r.source
        );
    }
    let drifted: Vec<&QuantityHistory> = h.drifted().collect();
    let _ = writeln!(
        out,
        "\ndrift (change from the first run beyond {DRIFT_Z} combined standard errors): {}",
        if drifted.is_empty() {
            "none".to_string()
        } else {
            format!("{} quantities", drifted.len())
        }
    );
    for q in &drifted {
        let first = &q.points[0];
        for p in q.points.iter().filter(|p| p.drift) {
            let _ = writeln!(
                out,
                "  {:<28} {:<26} {:>9.4} ± {:.4} → {:>9.4} ± {:.4} {:<8} ({}): {:+.4} ± {:.4}, z = {:+.1}",
                q.group,
                q.label(),
                first.value,
                first.std_err,
                p.value,
                p.std_err,
                unit_symbol(&q.unit),
                p.date,
                p.change.unwrap_or(f64::NAN),
                p.change_std_err.unwrap_or(f64::NAN),
                p.z.unwrap_or(f64::NAN)
            );
        }
    }
    let mut group = None;
    let mut hidden = 0;
    for q in &h.quantities {
        if !(all || q.stands_out || q.drift) {
            hidden += 1;
            continue;
        }
        if group != Some(&q.group) {
            let _ = writeln!(out, "\n{} (value ± standard error per run)", q.group);
            let _ = write!(out, "  {:<26} {:<8}", "quantity", "unit");
            for r in &h.runs {
                let _ = write!(out, " {:>21}", r.date);
            }
            out.push('\n');
            group = Some(&q.group);
        }
        let _ = write!(out, "  {:<26} {:<8}", q.label(), unit_symbol(&q.unit));
        for i in 0..h.runs.len() {
            let cell = q
                .points
                .iter()
                .find(|p| p.run == i)
                .map_or("–".into(), |p| {
                    format!(
                        "{:.4} ± {:.4}{}",
                        p.value,
                        p.std_err,
                        if p.drift { " !" } else { "" }
                    )
                });
            let _ = write!(out, " {cell:>21}");
        }
        out.push('\n');
    }
    if hidden > 0 {
        let _ = writeln!(
            out,
            "\n({hidden} more terms within 3 standard errors of 0 in every run: --all shows them; \
             ! marks drift)"
        );
    }
    out
}
