//! `eij identify` and `eij verify`: fit reduction factors to measured EIJ; re-run known-good fits.

use super::machine_args::write_output;
use anyhow::{bail, Context};
use eij::ident::config::{IdentConfig, KnownGood};
use eij::ident::measured::{self, MeasuredOptions};
use eij::ident::report::{self, Provenance};
use eij::ident::{identify, IdentResult, Method, Parameter, Problem, Settings, SolverKind};
use eij::machine::Machine;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// The main job's output folder (created when missing) and default outputs.
const DEFAULT_DIR: &str = "out";
const DEFAULT_OUT: &str = "out/demo-vmc-identified.toml";
const DEFAULT_REPORT: &str = "out/demo-vmc-identify-report.json";

/// Arguments of `eij identify`.
#[derive(Debug, clap::Args)]
pub struct IdentifyArgs {
    /// Machine description to calibrate.
    #[arg(
        long,
        value_name = "FILE.toml",
        default_value = "machines/demo-vmc.toml"
    )]
    machine: PathBuf,
    /// R-Test CSV files, folders of them, or EIJ tables.
    #[arg(long, value_name = "PATH", num_args = 1.., default_value = "measurements/demo-vmc")]
    measured: Vec<PathBuf>,
    /// The identified machine file.
    #[arg(
        long,
        value_name = "FILE.toml",
        default_value = "out/demo-vmc-identified.toml"
    )]
    out: PathBuf,
    /// The report JSON.
    #[arg(
        long,
        value_name = "FILE.json",
        default_value = "out/demo-vmc-identify-report.json"
    )]
    report: PathBuf,
    /// Identification settings (TOML: parameters, solver, method, max_iters, tol_cost,
    /// tol_step, min_factor, max_factor, rate_hz, revolutions, radius_mm, position_mm,
    /// table_std_err_um_s2_per_m).
    #[arg(long, value_name = "FILE.toml")]
    config: Option<PathBuf>,
    /// Parameters to identify, e.g. `z.guideway_normal` (repeatable; default: normal and
    /// lateral guideway factor of every axis). Kinds: guideway, guideway_normal,
    /// guideway_lateral, screw.
    #[arg(long = "param", value_name = "NAME")]
    params: Vec<String>,
    /// Optimiser.
    #[arg(long, value_enum)]
    method: Option<MethodArg>,
    /// How the tests are simulated during the optimisation (the result is confirmed in the time
    /// domain either way).
    #[arg(long, value_enum)]
    solver: Option<SolverArg>,
    /// Iteration limit.
    #[arg(long)]
    max_iters: Option<u64>,
    /// Set radius of the circle tests, mm (default 2, or the folder's rtest.toml).
    #[arg(long)]
    radius_mm: Option<f64>,
    /// Axis positions of the circle centre, mm, comma separated (default: the folder's
    /// rtest.toml, else the machine's reference position).
    #[arg(
        long,
        value_name = "X,Y,Z",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    position_mm: Option<Vec<f64>>,
    /// Also write the identified stiffness set as a table (CSV: catalogue value, factor,
    /// identified value and its standard error in N/µm per axis, element and direction).
    #[arg(long, value_name = "F.csv")]
    stiffness_out: Option<PathBuf>,
    /// Also draw the identification figure (measured vs simulated EIJ before and after per
    /// test, cost over iterations) as SVG.
    #[arg(long, value_name = "FILE.svg")]
    plot: Option<PathBuf>,
    /// No progress bar and no tables, only errors.
    #[arg(long)]
    quiet: bool,
}

/// `--method`: the library's [`Method`] as the command line spells it.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum MethodArg {
    /// Levenberg–Marquardt on the weighted residuals (default).
    Lm,
    /// Nelder–Mead on the weighted sum of squares (robust fallback, slower).
    NelderMead,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Lm => Method::Lm,
            MethodArg::NelderMead => Method::NelderMead,
        }
    }
}

/// `--solver`: the library's [`SolverKind`] as the command line spells it.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum SolverArg {
    /// Harmonic steady state (one complex solve per test; default).
    Harmonic,
    /// Time-domain simulation with ramps, exactly like `eij simulate circle`.
    Time,
}

impl From<SolverArg> for SolverKind {
    fn from(s: SolverArg) -> Self {
        match s {
            SolverArg::Harmonic => SolverKind::Harmonic,
            SolverArg::Time => SolverKind::Time,
        }
    }
}

/// Arguments of `eij verify`.
#[derive(Debug, clap::Args)]
pub struct VerifyArgs {
    /// Known-good identification files (default: tests/known-good/*.toml).
    files: Vec<PathBuf>,
}

struct Prepared {
    problem: Problem,
    provenance: Provenance,
    /// What reading the measured tests found (conditions, clocks), for the report's warnings.
    warnings: Vec<String>,
}

fn prepare(
    machine_path: &Path,
    measured_paths: &[PathBuf],
    config: &IdentConfig,
    cli_params: &[String],
) -> anyhow::Result<Prepared> {
    let machine = Machine::from_file(machine_path)?;
    let mut settings = Settings::default();
    let mut mopts = MeasuredOptions::default();
    config.apply(&mut settings, &mut mopts)?;
    let names: Vec<String> = if !cli_params.is_empty() {
        cli_params.to_vec()
    } else {
        config.parameters.clone().unwrap_or_default()
    };
    let params = if names.is_empty() {
        Parameter::default_set(&machine)
    } else {
        names
            .iter()
            .map(|n| Parameter::parse(n, &machine))
            .collect::<Result<Vec<_>, _>>()?
    };
    let (tests, warnings) = measured::load_with_warnings(measured_paths, &mopts)?;
    let problem =
        Problem::new(machine, params, tests, settings).map_err(super::advice::identify)?;
    let provenance = Provenance::now(
        machine_path.display().to_string(),
        measured::expand(measured_paths)?
            .iter()
            .map(|p| p.display().to_string())
            .collect(),
    );
    Ok(Prepared {
        problem,
        provenance,
        warnings,
    })
}

fn progress_bar(quiet: bool, max_iters: u64) -> Option<ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(max_iters);
    bar.set_style(
        ProgressStyle::with_template("{spinner} iteration {pos}/{len} {msg} [{elapsed}]")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    Some(bar)
}

fn run_identification(prep: &Prepared, quiet: bool) -> anyhow::Result<(IdentResult, f64)> {
    let max_iters = prep.problem.tests().len() as u64;
    let bar = progress_bar(quiet, max_iters.max(1));
    if let Some(b) = &bar {
        b.set_length(50);
    }
    let callback: Option<Arc<eij::ident::ProgressFn>> = bar.clone().map(|b| {
        Arc::new(move |iter: u64, cost: f64| {
            b.set_position(iter);
            b.set_message(format!("cost {cost:.6e}"));
        }) as Arc<eij::ident::ProgressFn>
    });
    let start = Instant::now();
    let result = identify(&prep.problem, callback);
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let mut result = result.map_err(super::advice::identify)?;
    result.warnings.splice(0..0, prep.warnings.iter().cloned());
    Ok((result, start.elapsed().as_secs_f64()))
}

fn print_result(prep: &Prepared, result: &IdentResult, seconds: f64) {
    let p = &prep.problem;
    println!(
        "Identified {} from {} tests ({} values), {} iterations, {:.1} s",
        p.machine().name,
        p.tests().len(),
        result.residuals,
        result.iterations,
        seconds
    );
    println!(
        "cost Σr² {:.4e} -> {:.4e}   residual std s = {:.3}",
        result.cost_initial, result.cost_final, result.residual_std
    );
    println!("\n  parameter              initial   identified    std err");
    for q in &result.parameters {
        match q.std_err {
            Some(s) => println!(
                "  {:<22} {:>7.4}   {:>10.4}   {:>8.4}",
                q.name, q.initial, q.value, s
            ),
            None => println!(
                "  {:<22} {:>7.4}   {:>10}   not identifiable",
                q.name, q.initial, "-"
            ),
        }
    }
    let n = result.parameters.len();
    if n > 1 {
        println!("\n  correlation");
        for i in 0..n {
            let row: Vec<String> = (0..n)
                .map(|k| format!("{:>6.2}", result.correlation[(i, k)]))
                .collect();
            println!("  {:<22} {}", result.parameters[i].name, row.join(" "));
        }
    }
    println!(
        "\n  {:<36} EIJ   measured ± σ       catalogue (ratio)   identified (ratio)   (µm·s²/m)",
        "test"
    );
    for (i, t) in p.tests().iter().enumerate() {
        for (e, (m, s)) in &t.measured {
            let a = result.simulated_initial[i]
                .get(e)
                .copied()
                .unwrap_or(f64::NAN);
            let b = result.simulated_final[i]
                .get(e)
                .copied()
                .unwrap_or(f64::NAN);
            let ratio = |x: f64| {
                if m.abs() > 3.0 * s {
                    format!("{:>5.2}", x / m)
                } else {
                    "    -".to_string()
                }
            };
            println!(
                "  {:<36} {} {:>8.3} ± {:<6.3}  {:>8.3} ({})     {:>8.3} ({})",
                t.label(),
                e,
                m,
                s,
                a,
                ratio(a),
                b,
                ratio(b)
            );
        }
    }
    let (mut before, mut after) = (Vec::new(), Vec::new());
    for (i, t) in p.tests().iter().enumerate() {
        for (e, (m, s)) in &t.measured {
            if m.abs() > 3.0 * s {
                before.push(result.simulated_initial[i][e] / m);
                after.push(result.simulated_final[i][e] / m);
            }
        }
    }
    if !before.is_empty() {
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        println!(
            "\nsimulated/measured over the {} values beyond 3σ: median {:.2} with the catalogue model, {:.2} identified",
            before.len(),
            median(&mut before),
            median(&mut after)
        );
    }
    for w in &result.warnings {
        println!("warning: {w}");
    }
}

/// Runs `eij identify`.
pub fn run(args: IdentifyArgs) -> anyhow::Result<()> {
    let mut config = match &args.config {
        Some(c) => IdentConfig::from_file(c)?,
        None => IdentConfig::default(),
    };
    if let Some(m) = args.method {
        config.method = Some(m.into());
    }
    if let Some(m) = args.solver {
        config.solver = Some(m.into());
    }
    if let Some(m) = args.max_iters {
        config.max_iters = Some(m);
    }
    if let Some(r) = args.radius_mm {
        config.radius_mm = Some(r);
    }
    if let Some(p) = &args.position_mm {
        config.position_mm = Some(p.clone());
    }
    // Inputs of the run (never overwritten): measured files, the rtest.toml of their folders,
    // the machine and the config. Outputs are checked before any work.
    let mut inputs: Vec<PathBuf> = measured::expand(&args.measured)?;
    let conditions: Vec<PathBuf> = inputs
        .iter()
        .filter_map(|f| {
            f.parent()
                .map(|d| d.join(eij::rtest::conditions::CONDITIONS_FILE))
        })
        .filter(|c| c.is_file())
        .collect();
    inputs.extend(conditions);
    inputs.push(args.machine.clone());
    if let Some(c) = &args.config {
        inputs.push(c.clone());
    }
    let input_refs: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
    // Only the main job's default output folder is created; any other must exist.
    if args.out == Path::new(DEFAULT_OUT) || args.report == Path::new(DEFAULT_REPORT) {
        std::fs::create_dir_all(DEFAULT_DIR)
            .with_context(|| format!("{DEFAULT_DIR}: cannot create the folder"))?;
    }
    let outputs: Vec<&Path> = [
        Some(args.out.as_path()),
        Some(args.report.as_path()),
        args.stiffness_out.as_deref(),
        args.plot.as_deref(),
    ]
    .into_iter()
    .flatten()
    .collect();
    eij::io::check_outputs(&outputs, &input_refs)?;

    let prep = prepare(&args.machine, &args.measured, &config, &args.params)?;
    let (result, seconds) = run_identification(&prep, args.quiet)?;
    let toml_text = report::machine_toml(&prep.problem, &result, &prep.provenance)
        .context("cannot write the identified machine")?;
    let ident_report = report::IdentReport::new(&prep.problem, &result, &prep.provenance);
    let svg = match &args.plot {
        Some(_) => Some(eij::report::identification_svg(&ident_report)?),
        None => None,
    };
    let json = ident_report.to_json();
    write_output(&args.out, toml_text.as_bytes(), &input_refs)?;
    write_output(&args.report, &json, &input_refs)?;
    if let Some(path) = &args.stiffness_out {
        let table = eij::ident::stiffness::identified_table(&prep.problem, &result);
        write_output(path, &table.to_csv(), &input_refs)?;
    }
    if let (Some(path), Some(svg)) = (&args.plot, &svg) {
        write_output(path, svg.as_bytes(), &input_refs)?;
    }
    if !args.quiet {
        print_result(&prep, &result, seconds);
        let table = args
            .stiffness_out
            .as_ref()
            .map(|p| format!(" (stiffness table {})", p.display()))
            .unwrap_or_default();
        println!(
            "\nwrote {} and {}{table}",
            args.out.display(),
            args.report.display()
        );
    }
    Ok(())
}

/// Runs `eij verify`.
pub fn verify(args: VerifyArgs) -> anyhow::Result<()> {
    let files = if args.files.is_empty() {
        let dir = Path::new("tests/known-good");
        let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
            .with_context(|| format!("{}: cannot read", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        v.sort();
        v
    } else {
        args.files
    };
    if files.is_empty() {
        bail!("no known-good files given or found in tests/known-good");
    }
    let mut failures = Vec::new();
    for f in &files {
        let outcome = verify_one(f)?;
        for line in &outcome {
            println!("{line}");
        }
        failures.extend(outcome.into_iter().filter(|l| l.starts_with("FAIL")));
    }
    if !failures.is_empty() {
        bail!(
            "{} known-good value(s) drifted: {}",
            failures.len(),
            failures.join("; ")
        );
    }
    Ok(())
}

/// Re-runs one known-good identification; one line per expected value (`ok …` or `FAIL …`).
pub fn verify_one(file: &Path) -> anyhow::Result<Vec<String>> {
    let k = KnownGood::from_file(file)?;
    let prep = prepare(&k.machine, &k.measured, &k.settings, &[])?;
    let (result, _) = run_identification(&prep, true)?;
    let mut lines = Vec::new();
    for (name, exp) in &k.expected {
        let Some(got) = result.parameters.iter().find(|p| &p.name == name) else {
            lines.push(format!(
                "FAIL {}: {name} is not among the identified parameters",
                file.display()
            ));
            continue;
        };
        let rel = (got.value - exp.value).abs() / exp.value.abs();
        let verdict = if rel <= exp.rel_tol { "ok  " } else { "FAIL" };
        lines.push(format!(
            "{verdict} {}: {name} = {:.5} (expected {:.5} ± {:.1} %)",
            file.display(),
            got.value,
            exp.value,
            100.0 * exp.rel_tol
        ));
    }
    Ok(lines)
}
