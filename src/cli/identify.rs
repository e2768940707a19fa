//! `eij identify` and `eij verify`: fit reduction factors to measured EIJ; re-run known-good fits.

use super::machine_args::{write_output, write_outputs};
use anyhow::{bail, Context};
use eij::ident::config::{IdentConfig, KnownGood};
use eij::ident::measured::{self, MeasuredOptions};
use eij::ident::report::{self, Provenance};
use eij::ident::validation::{self, ParameterCovariance, Validation};
use eij::ident::{
    identify, IdentResult, Method, Parameter, Problem, Settings, SolverKind, StaticTerms,
};
use eij::machine::Machine;
use eij::measured::inputs::MeasuredInputs;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// The default output folder (created when missing), where the default outputs are named
/// after the machine: `out/<machine name>-identified.toml`, `out/<machine name>-identify-report.json`.
const DEFAULT_DIR: &str = "out";

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
    /// The identified machine file [default: out/<machine name>-identified.toml]. Not written
    /// when the fit ends on a bound or does not converge.
    #[arg(long, value_name = "FILE.toml")]
    out: Option<PathBuf>,
    /// The report JSON [default: out/<machine name>-identify-report.json]. When given, it is
    /// also written for a refused fit (with the diagnosis); the default one is not.
    #[arg(long, value_name = "FILE.json")]
    report: Option<PathBuf>,
    /// Hold-out validation: R-Test files, folders or EIJ tables not fitted, predicted by the
    /// identified model and compared with their measurement uncertainty.
    #[arg(long, value_name = "PATH", num_args = 1..)]
    validate: Vec<PathBuf>,
    /// Static (acceleration-independent) terms fitted with the EIJ: auto (shared per plane and
    /// circle centre where separable, reversal terms where the data need them), shared,
    /// per-direction, none.
    #[arg(long, value_enum)]
    static_terms: Option<StaticTermsArg>,
    /// Skip the ranking of candidate additional tests.
    #[arg(long)]
    no_design: bool,
    /// Identification settings (TOML: parameters, solver, method, max_iters, tol_cost,
    /// tol_step, tol_noise, min_factor, max_factor, rate_hz, revolutions, radius_mm, position_mm,
    /// table_std_err_um_s2_per_m, static_terms, design).
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
    /// Also print the full tables: every measured and simulated EIJ with their ratios, the
    /// correlation matrix, every static term, clock offset and candidate test.
    #[arg(long, visible_alias = "verbose", conflicts_with = "quiet")]
    tables: bool,
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

/// `--static-terms`: the library's [`StaticTerms`] as the command line spells it.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub(super) enum StaticTermsArg {
    /// Shared terms where separable; reversal terms where the data need them (default).
    Auto,
    /// Shared terms where separable, never reversal terms.
    Shared,
    /// Shared and reversal terms wherever separable.
    PerDirection,
    /// None: every test's EIJ as they are.
    None,
}

impl From<StaticTermsArg> for StaticTerms {
    fn from(s: StaticTermsArg) -> Self {
        match s {
            StaticTermsArg::Auto => StaticTerms::Auto,
            StaticTermsArg::Shared => StaticTerms::Shared,
            StaticTermsArg::PerDirection => StaticTerms::PerDirection,
            StaticTermsArg::None => StaticTerms::None,
        }
    }
}

/// Arguments of `eij verify`.
#[derive(Debug, clap::Args)]
pub struct VerifyArgs {
    /// Known-good identification files (default: tests/known-good/*.toml).
    files: Vec<PathBuf>,
}

pub(super) struct Prepared {
    pub(super) problem: Problem,
    pub(super) provenance: Provenance,
    /// What reading the measured tests found (conditions, clocks), for the report's warnings.
    pub(super) warnings: Vec<eij::rtest::Named>,
    /// How measured data were read (validation data are read alike).
    measured_options: MeasuredOptions,
    /// The clock offsets the evaluation estimated.
    clocks: Vec<eij::measured::suite::ClockReport>,
}

/// The identification problem of a machine (read from `machine_path`) and measured inputs
/// (expanded once by the caller, who also checks the outputs against their files).
pub(super) fn prepare(
    machine: Machine,
    machine_path: &Path,
    measured_inputs: &MeasuredInputs,
    config: &IdentConfig,
    cli_params: &[String],
    design: bool,
) -> anyhow::Result<Prepared> {
    let mut settings = Settings {
        design,
        ..Default::default()
    };
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
    let measured::Measured {
        tests,
        warnings,
        clocks,
    } = measured::load_measured(measured_inputs, &mopts)?;
    let problem =
        Problem::new(machine, params, tests, settings).map_err(super::advice::identify)?;
    let provenance = Provenance::now(machine_path, measured_inputs.data_files())?;
    Ok(Prepared {
        problem,
        provenance,
        warnings,
        clocks,
        measured_options: mopts,
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

/// Runs the identification with a progress bar; warnings go to standard error, always.
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
    result.warnings.splice(
        0..0,
        prep.warnings
            .iter()
            .cloned()
            .map(eij::ident::Warning::Measured),
    );
    for w in &result.warnings {
        errln!("warning: {}", super::advice::identify_warning(w));
    }
    Ok((result, start.elapsed().as_secs_f64()))
}

/// A file name made of the machine name (characters other than letters, digits, `-`, `_`
/// and `.` replaced by `_`).
fn file_stem(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Runs `eij identify`.
pub fn run(args: IdentifyArgs) -> anyhow::Result<()> {
    // The date the outputs carry is checked before any work.
    report::utc_timestamp()?;
    let mut config = match &args.config {
        Some(c) => IdentConfig::from_file(c)?,
        None => IdentConfig::default(),
    };
    // The values given as options are checked as such, before they override the file's.
    IdentConfig {
        max_iters: args.max_iters.map(|m| m as f64),
        radius_mm: args.radius_mm,
        position_mm: args.position_mm.clone(),
        ..IdentConfig::default()
    }
    .apply(&mut Settings::default(), &mut MeasuredOptions::default())?;
    if let Some(m) = args.method {
        config.method = Some(m.into());
    }
    if let Some(m) = args.solver {
        config.solver = Some(m.into());
    }
    if let Some(m) = args.max_iters {
        config.max_iters = Some(m as f64);
    }
    if let Some(r) = args.radius_mm {
        config.radius_mm = Some(r);
    }
    if let Some(p) = &args.position_mm {
        config.position_mm = Some(p.clone());
    }
    if let Some(t) = args.static_terms {
        config.static_terms = Some(t.into());
    }
    if args.no_design {
        config.design = Some(false);
    }
    // Inputs of the run (never overwritten): measured and validation files, the rtest.toml of
    // their folders, the machine and the config. Outputs are checked before any work.
    let measured_inputs = MeasuredInputs::expand(&args.measured)?;
    let validation_inputs = MeasuredInputs::expand(&args.validate)?;
    let measured_files = measured_inputs.data_files();
    let validation_files = validation_inputs.data_files();
    if let Some(f) = validation_files.iter().find(|f| measured_files.contains(f)) {
        bail!(
            "{}: given both as measured and as validation data (hold-out tests must not be fitted)",
            f.display()
        );
    }
    let mut inputs: Vec<PathBuf> = measured_files;
    inputs.extend(validation_files);
    inputs.extend(measured_inputs.conditions_files());
    inputs.extend(validation_inputs.conditions_files());
    inputs.push(args.machine.clone());
    if let Some(c) = &args.config {
        inputs.push(c.clone());
    }
    let input_refs: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
    let machine = Machine::from_file(&args.machine)?;
    let stem = file_stem(machine.name());
    let default_out = Path::new(DEFAULT_DIR).join(format!("{stem}-identified.toml"));
    let default_report = Path::new(DEFAULT_DIR).join(format!("{stem}-identify-report.json"));
    let out = args.out.clone().unwrap_or(default_out);
    let report_path = args.report.clone().unwrap_or(default_report);
    // Only the default output folder is created; any other must exist.
    if args.out.is_none() || args.report.is_none() {
        std::fs::create_dir_all(DEFAULT_DIR)
            .with_context(|| format!("{DEFAULT_DIR}: cannot create the folder"))?;
    }
    let outputs: Vec<&Path> = [
        Some(out.as_path()),
        Some(report_path.as_path()),
        args.stiffness_out.as_deref(),
        args.plot.as_deref(),
    ]
    .into_iter()
    .flatten()
    .collect();
    eij::io::check_outputs(&outputs, &input_refs)?;

    let prep = prepare(
        machine,
        &args.machine,
        &measured_inputs,
        &config,
        &args.params,
        true,
    )?;
    let validation_tests = if args.validate.is_empty() {
        None
    } else {
        Some(measured::load_measured(&validation_inputs, &prep.measured_options)?.tests)
    };
    let (result, seconds) = run_identification(&prep, super::console::quiet())?;
    let validation = match validation_tests {
        Some(tests) => Some(check_validation(&prep, &result, tests)?),
        None => None,
    };
    let mut ident_report = report::IdentReport::new(&prep.problem, &result, &prep.provenance);
    ident_report.warnings = result
        .warnings
        .iter()
        .map(super::advice::identify_warning)
        .collect();
    ident_report.validation = validation.as_ref().map(Into::into);
    ident_report.clocks = prep.clocks.iter().map(Into::into).collect();
    if !super::console::quiet() {
        let tables = args.tables;
        super::identify_print::print_result(&prep.problem, &result, &ident_report, seconds, tables);
        super::identify_print::print_clocks(&prep.clocks, tables);
        if let Some(v) = &validation {
            super::identify_print::print_validation(v, tables);
        }
        if !tables {
            outln!(
                "\nfull tables (every EIJ measured and simulated, correlations, static terms, candidate tests, clocks): --tables;\n\
                 all of it is in the report JSON, and `eij report --identify-report` shows it as a page"
            );
        }
    }
    if let Some(refusal) = &result.refusal {
        // The diagnosis is written where the user asked for a report; nothing is exported.
        let written = if args.report.is_some() {
            write_output(&report_path, &ident_report.to_json(), &input_refs)?;
            format!(" (diagnosis in {})", report_path.display())
        } else {
            String::new()
        };
        return Err(anyhow::anyhow!(
            "{}{written}",
            super::advice::identify(refusal.clone())
        ));
    }
    let toml_text = report::machine_toml(&prep.problem, &result, &prep.provenance)
        .context("cannot write the identified machine")?;
    let svg = match &args.plot {
        Some(_) => Some(eij::report::identification_svg(&ident_report)?),
        None => None,
    };
    let report_json = ident_report.to_json();
    let table = args
        .stiffness_out
        .as_ref()
        .map(|_| eij::ident::stiffness::identified_table(&prep.problem, &result).to_csv());
    let mut files: Vec<(&Path, &[u8])> = vec![
        (&out, toml_text.as_bytes()),
        (&report_path, report_json.as_slice()),
    ];
    if let (Some(path), Some(table)) = (&args.stiffness_out, &table) {
        files.push((path, table.as_slice()));
    }
    if let (Some(path), Some(svg)) = (&args.plot, &svg) {
        files.push((path, svg.as_bytes()));
    }
    write_outputs(&files, &input_refs)
}

/// Validates the identified machine on the held-out tests; a failed validation is a warning.
fn check_validation(
    prep: &Prepared,
    result: &IdentResult,
    tests: Vec<eij::ident::TestCase>,
) -> anyhow::Result<Validation> {
    let covariance = ParameterCovariance::of(prep.problem.parameters(), result);
    let v = validation::validate(
        &result.machine,
        Some(&covariance),
        tests,
        prep.problem.settings(),
    )
    .map_err(super::advice::identify)?;
    if !v.passed {
        errln!(
            "warning: hold-out validation failed: the identified model does not predict the {} held-out value(s) within their uncertainty, measurement and identified parameters (χ²/dof = {:.2} over {} degrees of freedom)",
            v.values, v.chi2_per_dof, v.dof
        );
    }
    Ok(v)
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
            outln!("{line}");
        }
        super::console::flush();
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
    // The ranking of candidate tests does not change the factors: not needed here.
    let machine = Machine::from_file(&k.machine)?;
    let measured_inputs = MeasuredInputs::expand(&k.measured)?;
    let prep = prepare(
        machine,
        &k.machine,
        &measured_inputs,
        &k.settings,
        &[],
        false,
    )?;
    let (result, _) = run_identification(&prep, true)?;
    let mut lines = Vec::new();
    if let Some(refusal) = &result.refusal {
        lines.push(format!("FAIL {}: {refusal}", file.display()));
    }
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
