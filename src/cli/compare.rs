//! `eij compare`: which of several candidate machine models the measured EIJ support
//! ([`eij::ident::compare`]).

use super::identify::{prepare, StaticTermsArg};
use super::machine_args::write_output;
use anyhow::{bail, Context};
use eij::ident::compare::{compare, Candidate, Comparison, Rank};
use eij::ident::compare_report::CompareReport;
use eij::ident::config::IdentConfig;
use eij::ident::report;
use eij::machine::Machine;
use eij::measured::inputs::MeasuredInputs;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Exit code of a comparison in which no candidate reproduces the data (1 is an error, 2 a
/// usage error).
pub const EXIT_CODE: u8 = 3;

/// Raised after the outputs are written when no candidate is preferred, or the preferred one
/// fails its χ² test: `main` exits with [`EXIT_CODE`].
#[derive(Debug, thiserror::Error)]
#[error("verdict: no candidate reproduces the measured EIJ within their uncertainty: {0}")]
pub struct NotReproduced(pub String);

/// Arguments of `eij compare`.
#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// Candidate machine files (at least two): each is identified on the same measured tests
    /// with its default parameters (normal and lateral guideway factor of every axis, the
    /// stiffness factor of every elastic body) or the config's `parameters`.
    #[arg(long = "machine", value_name = "FILE.toml", required = true)]
    machines: Vec<PathBuf>,
    /// R-Test CSV files, folders of them, or EIJ tables (as `eij identify --measured`).
    #[arg(long, value_name = "PATH", num_args = 1.., required = true)]
    measured: Vec<PathBuf>,
    /// Identification settings for every candidate (TOML, as `eij identify --config`).
    #[arg(long, value_name = "FILE.toml")]
    config: Option<PathBuf>,
    /// Static terms fitted with the EIJ (as `eij identify --static-terms`).
    #[arg(long, value_enum)]
    static_terms: Option<StaticTermsArg>,
    /// Skip the hold-out validation that leaves out one circle centre at a time.
    #[arg(long)]
    no_holdout: bool,
    /// The comparison report JSON (verdict, per candidate its criteria, groups, hold-out and
    /// the full identification report).
    #[arg(long, value_name = "FILE.json")]
    report: Option<PathBuf>,
    /// The comparison report JSON on standard output instead of the text.
    #[arg(long)]
    json: bool,
}

/// Runs `eij compare`.
pub fn run(args: CompareArgs) -> anyhow::Result<()> {
    report::utc_timestamp()?;
    if args.machines.len() < 2 {
        bail!(
            "--machine: a comparison needs at least two candidate machine files ({} given: {})",
            args.machines.len(),
            args.machines
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    for (i, m) in args.machines.iter().enumerate() {
        if args.machines[..i].contains(m) {
            bail!("{}: given twice as --machine", m.display());
        }
    }
    let mut config = match &args.config {
        Some(c) => IdentConfig::from_file(c)?,
        None => IdentConfig::default(),
    };
    if let Some(t) = args.static_terms {
        config.static_terms = Some(t.into());
    }
    config.design = Some(false);
    let measured_inputs = MeasuredInputs::expand(&args.measured)?;
    let mut inputs: Vec<PathBuf> = measured_inputs.data_files();
    inputs.extend(measured_inputs.conditions_files());
    inputs.extend(args.machines.iter().cloned());
    inputs.extend(args.config.iter().cloned());
    let input_refs: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
    if let Some(r) = &args.report {
        eij::io::check_outputs(&[r.as_path()], &input_refs)?;
    }
    let mut candidates = Vec::new();
    let mut provenance = Vec::new();
    let mut warnings = Vec::new();
    for path in &args.machines {
        let machine = Machine::from_file(path)?;
        let prep = prepare(machine, path, &measured_inputs, &config, &[], false)
            .with_context(|| format!("{}: as a candidate", path.display()))?;
        // The evaluation's warnings are the same for every candidate: said once.
        if warnings.is_empty() {
            warnings = prep
                .warnings
                .iter()
                .cloned()
                .map(|w| super::advice::identify_warning(&eij::ident::Warning::Measured(w)))
                .collect();
        }
        candidates.push(Candidate {
            label: prep.problem.machine().name().to_string(),
            problem: prep.problem,
        });
        provenance.push(prep.provenance);
    }
    // Two files of one machine name are told apart by their files.
    let names: Vec<String> = candidates.iter().map(|c| c.label.clone()).collect();
    for (c, path) in candidates.iter_mut().zip(&args.machines) {
        if names.iter().filter(|n| **n == c.label).count() > 1 {
            c.label = path.display().to_string();
        }
    }
    let spinner = super::console::Progress::spinner("compare: identifying every candidate");
    let start = Instant::now();
    let comparison = compare(candidates, !args.no_holdout).map_err(super::advice::identify);
    drop(spinner);
    let comparison = comparison?;
    let seconds = start.elapsed().as_secs_f64();
    for w in &warnings {
        errln!("warning: {w}");
    }
    for c in &comparison.candidates {
        if let Ok(r) = &c.fit {
            for w in &r.warnings {
                errln!("warning: {}: {w}", c.label);
            }
        }
    }
    let report = CompareReport::new(&comparison, &provenance);
    let json = report.to_json();
    if args.json {
        out!("{}", String::from_utf8_lossy(&json));
    } else if !super::console::quiet() {
        print_comparison(&comparison, &args.measured, seconds);
    }
    if let Some(path) = &args.report {
        write_output(path, &json, &input_refs)?;
    }
    if !comparison.reproduced() {
        return Err(NotReproduced(comparison.verdict.clone()).into());
    }
    Ok(())
}

/// The comparison on standard output: the verdict first, then one line per candidate and the
/// parameters side by side.
fn print_comparison(c: &Comparison, measured: &[PathBuf], seconds: f64) {
    let first = &c.candidates[0].problem;
    let folders: Vec<String> = measured.iter().map(|p| p.display().to_string()).collect();
    outln!(
        "Compared {} candidate models on {} tests ({} values) of {}, {:.1} s",
        c.candidates.len(),
        first.tests().len(),
        first.rows().len(),
        folders.join(", "),
        seconds
    );
    outln!("\nverdict: {}", c.verdict);
    let order: Vec<usize> = c
        .preferred
        .into_iter()
        .chain((0..c.candidates.len()).filter(|&i| Some(i) != c.preferred))
        .collect();
    for &i in &order {
        outln!("  - {}", c.candidates[i].reason);
    }
    let width = c
        .candidates
        .iter()
        .map(|o| o.label.chars().count())
        .max()
        .unwrap_or(9)
        .max(9);
    outln!(
        "\n  {:<width$}  status      s        χ² test   k     BIC         ΔBIC       AIC         ΔAIC       hold-out (one centre left out)",
        "candidate"
    );
    let best = c.winner().and_then(|w| w.score);
    for &i in &order {
        let o = &c.candidates[i];
        let status = match o.rank {
            Rank::Preferred => "preferred",
            Rank::Behind { .. } => "behind",
            Rank::Refused => "REFUSED",
            Rank::Failed => "FAILED",
        };
        let hold = o.holdout.as_ref().map_or("-".to_string(), |h| {
            format!(
                "{}/{} centres{}",
                h.passed_folds(),
                h.folds.len(),
                h.chi2_per_dof()
                    .map(|x| format!(" (χ²/dof {x:.2})"))
                    .unwrap_or_default()
            )
        });
        match o.score {
            Some(s) => {
                let delta =
                    |a: f64, b: Option<f64>| b.map_or("-".into(), |b| format!("{:+.1}", a - b));
                outln!(
                    "  {:<width$}  {:<10}  {:>7.3}  {:<8}  {:>4}  {:>10.1}  {:>9}  {:>10.1}  {:>9}  {}",
                    o.label,
                    status,
                    s.chi2_test.s,
                    if s.chi2_test.passed { "passed" } else { "FAILED" },
                    s.k,
                    s.bic,
                    delta(s.bic, best.map(|b| b.bic)),
                    s.aic,
                    delta(s.aic, best.map(|b| b.aic)),
                    hold
                );
            }
            None => outln!("  {:<width$}  {status}", o.label),
        }
    }
    outln!(
        "  (m = {} weighted residuals; k = free parameters + static terms + clock offsets; BIC = χ² + k·ln m, AIC = χ² + 2k;\n   ΔBIC against the preferred: < 2 not worth a mention, 2–6 positive, 6–10 strong, > 10 very strong evidence)",
        first.rows().len()
    );
    print_parameters(c, &order, width);
    outln!(
        "\nall of it is in the report JSON (--report F.json); `eij identify --machine <preferred>` exports the identified machine"
    );
}

/// Every candidate's parameters side by side: value ± standard error and standing.
fn print_parameters(c: &Comparison, order: &[usize], width: usize) {
    let mut names: Vec<String> = Vec::new();
    for &i in order {
        if let Ok(r) = &c.candidates[i].fit {
            for p in &r.parameters {
                if !names.contains(&p.name) {
                    names.push(p.name.clone());
                }
            }
        }
    }
    let col = width.max(28);
    let mut header = format!("\n  {:<22}", "parameter");
    for &i in order {
        header.push_str(&format!("  {:<col$}", c.candidates[i].label));
    }
    outln!("{}", header.trim_end());
    for name in &names {
        let mut line = format!("  {name:<22}");
        for &i in order {
            let cell = match &c.candidates[i].fit {
                Ok(r) => r
                    .parameters
                    .iter()
                    .find(|p| &p.name == name)
                    .map_or("-".into(), |p| match p.std_err {
                        Some(se) => format!("{:.4} ± {:.4} {}", p.value, se, p.standing().label()),
                        None => format!("{:.4} {}", p.value, p.standing().label()),
                    }),
                Err(_) => "-".into(),
            };
            line.push_str(&format!("  {cell:<col$}"));
        }
        outln!("{}", line.trim_end());
    }
}
