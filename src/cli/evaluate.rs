//! `eij evaluate FILE.csv... [--plane xy|yz|zx] [--radius-mm R] [--json] [--csv-out FILE]
//! [--pooled]`

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use eij::axes::Plane;
use eij::rtest::{self, table, CircleResult, CircleSeries, EvalOptions, PooledResult};

/// Arguments of `eij evaluate`.
#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// R-Test / circle-test CSV files.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Circle plane (default: the two axes with the largest internal amplitude).
    #[arg(long)]
    pub plane: Option<Plane>,
    /// Set radius, mm (default: the mean internal radius; when given, the data must agree
    /// within 10 %).
    #[arg(long, allow_hyphen_values = true)]
    pub radius_mm: Option<f64>,
    /// Print one JSON object (CONTRACT.md) instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also write the EIJ table (CSV) of all tests to this file.
    #[arg(long, value_name = "FILE")]
    pub csv_out: Option<PathBuf>,
    /// Also fit all files together: EIJ separated from static geometric terms (needs tests
    /// at different accelerations of one plane).
    #[arg(long)]
    pub pooled: bool,
    /// Also write the magnified circle plot (SVG) of the test; takes exactly one file (for
    /// several, use `eij report`).
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
}

/// Runs `eij evaluate`.
pub fn run(args: EvaluateArgs) -> anyhow::Result<()> {
    if let Some(r) = args.radius_mm {
        if !(r.is_finite() && r > 0.0) {
            anyhow::bail!("--radius-mm {r}: expected a positive number of mm");
        }
        if r > 3.0 {
            anyhow::bail!("--radius-mm: {r} mm exceeds the R-Test probe range of ±3 mm");
        }
    }
    if args.plot.is_some() && args.files.len() != 1 {
        anyhow::bail!(
            "--plot: {} files given, a plot shows one test (use `eij report` for several)",
            args.files.len()
        );
    }
    let inputs: Vec<&Path> = args.files.iter().map(PathBuf::as_path).collect();
    let outputs: Vec<&Path> = args
        .csv_out
        .iter()
        .chain(&args.plot)
        .map(PathBuf::as_path)
        .collect();
    eij::io::check_outputs(&outputs, &inputs)?;
    let opts = EvalOptions {
        plane: args.plane,
        radius_mm: args.radius_mm,
    };
    let series = args
        .files
        .iter()
        .map(CircleSeries::read_csv)
        .collect::<Result<Vec<_>, _>>()?;
    let results = series
        .iter()
        .map(|s| rtest::evaluate(s, &opts))
        .collect::<Result<Vec<_>, _>>()
        .map_err(super::advice::evaluate)?;
    let pooled = if args.pooled {
        let refs: Vec<&CircleSeries> = series.iter().collect();
        Some(rtest::evaluate_pooled(&refs, &opts).map_err(super::advice::evaluate)?)
    } else {
        None
    };
    let plot_svg = match &args.plot {
        Some(_) => {
            let cond = eij::report::Conditions::of_file(&args.files[0])?;
            Some(eij::report::CircleView::new(&series[0], &opts)?.magnified_svg(&cond)?)
        }
        None => None,
    };
    if let Some(out) = &args.csv_out {
        let rows: Vec<_> = results.iter().flat_map(table::rows_from_result).collect();
        table::write(out, &rows, &inputs)?;
    }
    if let (Some(plot), Some(svg)) = (&args.plot, plot_svg) {
        eij::io::write_atomic(plot, svg.as_bytes(), &inputs)?;
    }
    if args.json {
        let mut doc = serde_json::Map::new();
        doc.insert(
            "tests".into(),
            results.iter().map(CircleResult::to_json).collect(),
        );
        if let Some(p) = &pooled {
            doc.insert("pooled".into(), p.to_json());
        }
        println!("{}", serde_json::Value::Object(doc));
    } else {
        let mut text = String::new();
        for r in &results {
            render_result(&mut text, r);
        }
        if let Some(p) = &pooled {
            render_pooled(&mut text, p);
        }
        print!("{text}");
    }
    Ok(())
}

fn render_result(out: &mut String, r: &CircleResult) {
    let _ = writeln!(out, "{}", r.source);
    let _ = writeln!(
        out,
        "  plane {}  {}  radius {:.4} mm  accel {:.3} m/s²  freq {:.3} Hz  {} revolutions  {} samples",
        r.plane, r.direction, r.radius_mm, r.accel_m_s2, r.freq_hz, r.revolutions, r.samples_used
    );
    let _ = writeln!(
        out,
        "  {:<9} {:>12} {:>10}  {:>12} {:>12}   (µm·s²/m)",
        "parameter", "joint fit", "std err", "plane fit", "ellipse fit"
    );
    for p in r.plane.parameters() {
        let route = |m: &std::collections::BTreeMap<eij::axes::Eij, f64>| {
            m.get(&p).map_or(String::new(), |v| format!("{v:.4}"))
        };
        let _ = writeln!(
            out,
            "  {:<9} {:>12.4} {:>10.4}  {:>12} {:>12}",
            p.name(),
            r.eij[&p],
            r.std_err[&p],
            route(&r.plane_fit.eij),
            r.ellipse_fit
                .as_ref()
                .map_or(String::new(), |e| route(&e.eij))
        );
    }
    let _ = writeln!(out, "  rms residual {:.4} µm", r.rms_residual_um);
    for w in &r.warnings {
        let _ = writeln!(out, "  warning: {w}");
    }
}

fn render_pooled(out: &mut String, p: &PooledResult) {
    let _ = writeln!(
        out,
        "pooled over {} tests, plane {}, accelerations {} m/s²",
        p.sources.len(),
        p.plane,
        p.accel_m_s2
            .iter()
            .map(|a| format!("{a:.3}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        out,
        "  {:<9} {:>12} {:>10}  {:<9} {:>12} {:>10}",
        "parameter", "µm·s²/m", "std err", "geometric", "µm/mm", "std err"
    );
    for k in p.plane.parameters() {
        let _ = writeln!(
            out,
            "  {:<9} {:>12.4} {:>10.4}  {:<9} {:>12.5} {:>10.5}",
            k.name(),
            p.eij[&k],
            p.std_err[&k],
            rtest::pooled::geometric_name(k),
            p.geometric_um_per_mm[&k],
            p.geometric_std_err[&k]
        );
    }
    let _ = writeln!(out, "  rms residual {:.4} µm", p.rms_residual_um);
    for w in &p.warnings {
        let _ = writeln!(out, "  warning: {w}");
    }
}
