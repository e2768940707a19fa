//! `eij evaluate PATH... [--plane xy|yz|zx] [--radius-mm R] [--json] [--csv-out FILE]
//! [--pooled] [--fit-time-offset] [--diagnose [--cyclic-pitch-mm P] [--spike-decay-ms T]]`

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use eij::axes::Plane;
use eij::measured::conditions::DiagnosisSettings;
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{self, EvaluatedTest, Suite, SuiteOptions};
use eij::measured::table;
use eij::rtest::{self, CircleSeries, EvalOptions, PooledResult};

/// Arguments of `eij evaluate`.
#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// R-Test / circle-test CSV files, or folders of them (with their `rtest.toml`).
    #[arg(required = true, value_name = "PATH")]
    pub files: Vec<PathBuf>,
    /// Circle plane (default: the two axes with the largest internal amplitude).
    #[arg(long)]
    pub plane: Option<Plane>,
    /// Set radius, mm (default: the folder's `rtest.toml`, else the mean internal radius with
    /// a warning; the data must agree within 10 %).
    #[arg(long, allow_hyphen_values = true)]
    pub radius_mm: Option<f64>,
    /// Print one JSON object (docs/commands.md) instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also write the EIJ table (CSV) of all tests to this file.
    #[arg(long, value_name = "FILE")]
    pub csv_out: Option<PathBuf>,
    /// Also fit all files together: EIJ separated from static geometric terms (needs tests
    /// at different accelerations of one plane).
    #[arg(long)]
    pub pooled: bool,
    /// Also write the magnified circle plot (SVG) of the test; takes exactly one test (for
    /// several, use `eij report`).
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Correct single-file tests by the clock offset (external readings lagging the internal
    /// ones) fitted jointly over the tests of their folder; two-system recordings are always
    /// aligned.
    #[arg(long)]
    pub fit_time_offset: bool,
    /// Also break every circle down into named errors (backlash, servo mismatch, squareness,
    /// …) per source — the axes, the structure (external − internal) and the TCP — ranked by
    /// their share of G and judged against the folder's `[tolerances]` (docs/diagnosis.md);
    /// a test out of tolerance makes the exit code 3.
    #[arg(long)]
    pub diagnose: bool,
    /// Pitch of the cyclic error fitted by --diagnose (screw lead, scale period), mm
    /// (default: `rtest.toml` `[diagnosis]`, else no cyclic terms).
    #[arg(long, value_name = "MM", requires = "diagnose")]
    pub cyclic_pitch_mm: Option<f64>,
    /// Decay time of the reversal spikes fitted by --diagnose, ms (default: `rtest.toml`
    /// `[diagnosis]`, else 10).
    #[arg(long, value_name = "MS", requires = "diagnose")]
    pub spike_decay_ms: Option<f64>,
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
    let settings = DiagnosisSettings {
        cyclic_pitch_mm: args.cyclic_pitch_mm,
        cyclic_harmonics: None,
        spike_decay_ms: args.spike_decay_ms,
    };
    if let Err((key, message)) = settings.check() {
        anyhow::bail!("--{}: {message}", key.replace('_', "-"));
    }
    if args.plot.is_some() && args.files.len() != 1 {
        anyhow::bail!(
            "--plot: {} files given, a plot shows one test (use `eij report` for several)",
            args.files.len()
        );
    }
    let tests = expand_tests(&args.files)?;
    let files: Vec<PathBuf> = tests.iter().flat_map(|t| t.files()).collect();
    let inputs: Vec<&Path> = args
        .files
        .iter()
        .chain(&files)
        .map(PathBuf::as_path)
        .collect();
    let outputs: Vec<&Path> = args
        .csv_out
        .iter()
        .chain(&args.plot)
        .map(PathBuf::as_path)
        .collect();
    eij::io::check_outputs(&outputs, &inputs)?;
    if args.plot.is_some() && tests.len() != 1 {
        anyhow::bail!(
            "--plot: {} tests in {}, a plot shows one test (use `eij report` for several)",
            tests.len(),
            args.files[0].display()
        );
    }
    let opts = SuiteOptions {
        plane: args.plane,
        radius_mm: args.radius_mm,
        fallback_radius_mm: None,
        fit_time_offset: args.fit_time_offset,
    };
    let spinner =
        super::console::Progress::spinner(&format!("evaluate: {} circle test(s)", tests.len()));
    let suite = suite::evaluate_tests(&tests, &opts).map_err(super::advice::evaluate)?;
    let diagnosis = if args.diagnose {
        Some(suite::diagnose::diagnose(&suite, settings).map_err(super::advice::evaluate)?)
    } else {
        None
    };
    drop(spinner);
    let pooled = if args.pooled {
        pooled_groups(&suite, args.plane)?
    } else {
        Vec::new()
    };
    let plot_svg = match (&args.plot, suite.tests.first()) {
        (Some(_), Some(t)) => {
            let cond = eij::report::Conditions {
                source: t.input.name(),
                machine: None,
                position_mm: t.input.test.position_mm.clone(),
            };
            let opts = EvalOptions {
                plane: Some(t.result.plane),
                radius_mm: Some(t.result.radius_mm),
            };
            Some(eij::report::CircleView::new(&t.series, &opts)?.magnified_svg(&cond)?)
        }
        _ => None,
    };
    let csv = args.csv_out.as_ref().map(|_| {
        let rows: Vec<_> = suite.tests.iter().flat_map(table::rows_of_test).collect();
        table::to_csv(&rows)
    });
    let mut files: Vec<(&Path, &[u8])> = Vec::new();
    if let (Some(out), Some(csv)) = (&args.csv_out, &csv) {
        files.push((out, csv.as_bytes()));
    }
    if let (Some(plot), Some(svg)) = (&args.plot, &plot_svg) {
        files.push((plot, svg.as_bytes()));
    }
    if !files.is_empty() {
        eij::io::write_set(&files, &inputs)?;
    }
    for w in suite
        .tests
        .iter()
        .flat_map(|t| t.result.warnings.iter().map(move |w| (t, w)))
    {
        errln!(
            "eij: warning: {}: {}",
            w.0.input.name(),
            super::advice::evaluate_warning(w.1)
        );
    }
    for w in &suite.warnings {
        errln!("eij: warning: {w}");
    }
    if let Some(d) = &diagnosis {
        for (t, v) in suite.tests.iter().zip(&d.verdicts) {
            for u in v.iter().flat_map(|v| &v.unchecked) {
                errln!(
                    "eij: warning: {}: tolerance {u}: not measured in this test",
                    t.input.name()
                );
            }
        }
    }
    if args.json {
        let mut doc = suite.to_json_map();
        if args.pooled {
            let groups: Vec<serde_json::Value> = pooled
                .iter()
                .map(|(centre, p)| {
                    let mut v = p.to_json();
                    if let (Some(o), Some(c)) = (v.as_object_mut(), centre) {
                        o.insert("position_mm".into(), serde_json::json!(c));
                    }
                    v
                })
                .collect();
            doc.insert("pooled".into(), groups.into());
        }
        if let Some(d) = &diagnosis {
            d.add_to_json(&mut doc);
        }
        outln!("{}", serde_json::Value::Object(doc));
    } else {
        let mut text = String::new();
        for (i, t) in suite.tests.iter().enumerate() {
            render_result(&mut text, t);
            if let Some(d) = &diagnosis {
                super::evaluate_diagnosis::render_test(&mut text, d, i);
            }
        }
        render_suite(&mut text, &suite);
        if let Some(d) = &diagnosis {
            super::evaluate_diagnosis::render_groups(&mut text, d);
        }
        for (centre, p) in &pooled {
            render_pooled(&mut text, p, centre.as_deref());
        }
        out!("{text}");
    }
    if !files.is_empty() {
        let written: Vec<&Path> = files.iter().map(|(p, _)| *p).collect();
        super::console::wrote(&written);
    }
    match diagnosis
        .as_ref()
        .and_then(super::evaluate_diagnosis::OutOfTolerance::of)
    {
        Some(fail) => Err(fail.into()),
        None => Ok(()),
    }
}

fn render_result(out: &mut String, t: &EvaluatedTest) {
    let r = &t.result;
    let _ = writeln!(out, "{}", t.input.name());
    let _ = writeln!(
        out,
        "  plane {}  {}  radius {:.4} mm ({})  accel {:.3} m/s²  freq {:.3} Hz  {} revolutions  {} samples",
        r.plane,
        r.direction,
        r.radius_mm,
        t.radius_source.name(),
        r.accel_m_s2,
        r.freq_hz,
        r.revolutions,
        r.samples_used
    );
    if let Some(o) = &t.time_offset {
        let se = o.std_err_ms.map_or(String::new(), |s| format!(" ± {s:.4}"));
        let _ = writeln!(
            out,
            "  clock offset {:.4}{se} ms (internal − external, {})",
            o.offset_ms,
            o.source.name()
        );
    }
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
            r.eij[&p].value,
            r.eij[&p].std_err,
            route(&r.plane_fit.value_map()),
            r.ellipse_fit
                .as_ref()
                .map_or(String::new(), |e| route(&e.eij))
        );
    }
    let _ = writeln!(out, "  rms residual {:.4} µm", r.rms_residual_um);
    if let Some(iso) = &r.iso230 {
        for (name, p) in [("internal", &iso.internal), ("external", &iso.external)] {
            let _ = writeln!(
                out,
                "  ISO 230-4 {name:<8} G {:>8.3} µm   F max {:>+8.3} µm   F min {:>+8.3} µm",
                p.circular_deviation_um, p.radial_deviation_max_um, p.radial_deviation_min_um
            );
        }
    }
    for w in &r.warnings {
        let _ = writeln!(out, "  warning: {w}");
    }
}

fn render_suite(out: &mut String, suite: &Suite) {
    for b in &suite.bidirectional {
        let _ = writeln!(
            out,
            "ISO 230-4 bi-directional circular deviation G(b) of {} and {}: internal {:.3} µm, external {:.3} µm",
            suite.tests[b.tests[0]].input.name(),
            suite.tests[b.tests[1]].input.name(),
            b.internal_um,
            b.external_um
        );
    }
    for c in &suite.clocks {
        let se = c.std_err_ms.map_or(String::new(), |s| format!(" ± {s:.4}"));
        let _ = writeln!(
            out,
            "clock {}: offset {:.4}{se} ms over {} test(s){}{}",
            c.clock,
            c.offset_ms,
            c.tests.len(),
            if c.separable {
                ""
            } else {
                ", not separable from cross-talk"
            },
            if c.applied { "" } else { ", not applied" }
        );
        for n in &c.notes {
            let _ = writeln!(out, "  warning: {n}");
        }
    }
}

/// Accelerations as `2.000, 5.000` (m/s²).
pub(super) fn accelerations(a: &[f64]) -> String {
    a.iter()
        .map(|a| format!("{a:.3}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// `--pooled`: one pooled fit per plane and circle centre (tests at one centre and plane share
/// their EIJ and static geometry). A group that cannot be pooled (one test, one acceleration)
/// is an error when it is the only one, else a warning naming it.
fn pooled_groups(
    suite: &Suite,
    plane: Option<Plane>,
) -> anyhow::Result<Vec<(Option<Vec<f64>>, PooledResult)>> {
    type Group<'a> = (Plane, Option<Vec<f64>>, Vec<&'a EvaluatedTest>);
    let mut groups: Vec<Group> = Vec::new();
    for t in &suite.tests {
        let key = (t.result.plane, t.input.test.position_mm.clone());
        match groups.iter_mut().find(|g| g.0 == key.0 && g.1 == key.1) {
            Some(g) => g.2.push(t),
            None => groups.push((key.0, key.1, vec![t])),
        }
    }
    let several = groups.len() > 1;
    let mut out = Vec::new();
    for (p, centre, tests) in groups {
        let refs: Vec<&CircleSeries> = tests.iter().map(|t| &t.series).collect();
        let radius_mm = tests
            .first()
            .filter(|t| t.radius_source != suite::RadiusSource::InternalMean)
            .map(|t| t.result.radius_mm);
        let opts = EvalOptions {
            plane: plane.or(Some(p)),
            radius_mm,
        };
        match rtest::evaluate_pooled(&refs, &opts) {
            Ok(r) => out.push((centre, r)),
            Err(e) if several => errln!(
                "eij: warning: pooled plane {p}{}: {e}",
                centre
                    .as_deref()
                    .map_or(String::new(), |c| format!(" at {} mm", eij::text::nums(c)))
            ),
            Err(e) => return Err(super::advice::evaluate(e.into())),
        }
    }
    if out.is_empty() {
        anyhow::bail!("--pooled: no plane holds tests that can be pooled (see the warnings)");
    }
    Ok(out)
}

fn render_pooled(out: &mut String, p: &PooledResult, centre: Option<&[f64]>) {
    let _ = writeln!(
        out,
        "pooled over {} tests, plane {}{}, accelerations {} m/s²",
        p.sources.len(),
        p.plane,
        centre.map_or(String::new(), |c| format!(
            ", circle centre {} mm",
            eij::text::nums(c)
        )),
        accelerations(&p.accel_m_s2)
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
            p.eij[&k].value,
            p.eij[&k].std_err,
            rtest::pooled::geometric_name(k),
            p.geometric_um_per_mm[&k].value,
            p.geometric_um_per_mm[&k].std_err
        );
    }
    let _ = writeln!(out, "  rms residual {:.4} µm", p.rms_residual_um);
    for w in &p.warnings {
        let _ = writeln!(out, "  warning: {w}");
    }
}
