//! `eij fe --machine FILE.toml --body NAME [--json]`: an elastic body's FE model and its
//! reduction (docs/fe.md; docs/fe.md).

use super::console::Progress;
use eij::fe::FeSummary;
use eij::machine::raw::RawBody;
use eij::machine::Machine;
use serde_json::json;
use std::path::PathBuf;

/// Arguments of `eij fe`.
#[derive(Debug, clap::Args)]
pub struct FeArgs {
    /// Machine description (TOML) with the elastic body.
    #[arg(long, value_name = "FILE.toml")]
    machine: PathBuf,
    /// The elastic body (a `[[body]]` with `[body.fe]` or `[body.beam]`).
    #[arg(long, value_name = "NAME")]
    body: String,
    /// Print one JSON object (docs/fe.md keys) instead of text.
    #[arg(long)]
    json: bool,
}

/// Relative differences of the reduced body's free-free frequencies from the full model's that
/// the words name: 0.1 % (the bar below half the cutoff) and 1 %.
const CLOSE: f64 = 1e-3;
const FAIR: f64 = eij::fe::FIRST_MODE_OFF;

/// Runs `eij fe`.
pub fn run(args: FeArgs) -> anyhow::Result<()> {
    let spinner = Progress::spinner(&format!("fe: reducing {}", args.body));
    let machine = Machine::from_file(&args.machine)?;
    let raw = machine.to_raw();
    let elastic: Vec<&str> = raw
        .bodies
        .iter()
        .filter(|b| b.fe.is_some() || b.beam.is_some())
        .map(|b| b.name.as_str())
        .collect();
    let listed = if elastic.is_empty() {
        "elastic: none".to_string()
    } else {
        format!("elastic: {}", elastic.join(", "))
    };
    let Some(b) = raw.bodies.iter().position(|b| b.name == args.body) else {
        anyhow::bail!(
            "--body {}: {} has no body of that name ({listed})",
            args.body,
            args.machine.display()
        );
    };
    drop(spinner);
    let _spinner = Progress::spinner(&format!("fe: full model of {} for comparison", args.body));
    let Some(summary) = machine.fe_summary(b)? else {
        let kind = if machine.bodies()[b].is_fixed() {
            "fixed"
        } else {
            "rigid"
        };
        anyhow::bail!(
            "--body {}: body {} of {} is {kind} (no [body.fe] or [body.beam]); eij fe shows elastic bodies ({listed})",
            args.body,
            args.body,
            args.machine.display()
        );
    };
    let warnings = summary.warnings();
    for w in &warnings {
        errln!("eij: warning: {w}");
    }
    if args.json {
        let mut out = serde_json::to_value(&summary)?;
        if let Some(map) = out.as_object_mut() {
            map.insert("machine".into(), json!(machine.source()));
            map.insert("warnings".into(), json!(warnings));
        }
        outln!("{out}");
        return Ok(());
    }
    out!("{}", text(&machine, &raw.bodies[b], &summary));
    Ok(())
}

/// (reduced − full) / full per mode.
fn differences(s: &FeSummary) -> Vec<f64> {
    s.free_frequencies_hz
        .iter()
        .zip(&s.full_free_frequencies_hz)
        .map(|(r, f)| (r - f) / f)
        .collect()
}

/// `x` rounded to `decimals` for display, without a minus sign on a value that rounds to zero.
fn tidy(x: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (x * scale).round() / scale + 0.0
}

/// A relative difference in per cent for the table: round-off (below 1e-8) shown as 0.
fn percent(d: f64) -> f64 {
    if d.abs() < 1e-8 {
        0.0
    } else {
        100.0 * d
    }
}

/// How many of the lowest modes lie within `tol` of the full model's.
fn lowest_within(d: &[f64], tol: f64) -> usize {
    d.iter().take_while(|x| x.abs() <= tol).count()
}

/// The summary for reading, with the resolution in words.
fn text(machine: &Machine, raw: &RawBody, s: &FeSummary) -> String {
    let mut t = String::new();
    let origin = match (&raw.fe, &raw.beam) {
        (Some(fe), _) => format!("[body.fe], stiffness {}", fe.stiffness_matrix),
        (_, Some(beam)) => format!("[body.beam], Timoshenko beam of {} elements", beam.elements),
        _ => String::new(),
    };
    t += &format!("Elastic body {} of {} ({origin})\n", s.body, machine.name());
    t += &format!("  FE model: {} DOFs\n", s.dofs);
    let c = s.cog_m;
    t += &format!(
        "  mass {:.3} kg, centre of gravity [{:.4}, {:.4}, {:.4}] m\n  inertia about the centre of gravity, kg·m²:\n",
        s.mass_kg,
        tidy(c[0], 4),
        tidy(c[1], 4),
        tidy(c[2], 4)
    );
    for row in &s.inertia_kg_m2 {
        let [a, b, c] = row.map(|x| tidy(x, 4));
        t += &format!("    [{a:>12.4} {b:>12.4} {c:>12.4}]\n");
    }
    let stations = s.interface_dofs / 6;
    let interface = if s.interface_coordinates == s.interface_dofs {
        format!("{} interface DOFs ({stations} stations)", s.interface_dofs)
    } else {
        format!(
            "{} interface DOFs ({stations} stations) reduced to {} interface coordinates",
            s.interface_dofs, s.interface_coordinates
        )
    };
    let asked = match (&raw.fe, &raw.beam) {
        (Some(fe), _) => fe.modes,
        (_, Some(beam)) => beam.modes,
        _ => None,
    };
    let modes = match asked {
        Some(a) if a > s.modes => format!(
            "{} fixed-interface modes ({a} asked: the body held at its attachments has no more)",
            s.modes
        ),
        _ => format!("{} fixed-interface modes", s.modes),
    };
    t += &format!(
        "Reduction (Craig–Bampton) in {:.3} s: {interface} + {modes}\n  \
         → 6 rigid-body + {} elastic coordinates; stiffness factor {}\n",
        s.reduction_s,
        s.free_frequencies_hz.len(),
        s.stiffness_factor
    );
    t += "Free-free elastic modes of the body alone (rigid-body modes left out):\n";
    t += &format!(
        "  {:>4}  {:>12}  {:>12}  {:>10}\n",
        "mode", "reduced/Hz", "full/Hz", "difference"
    );
    let d = differences(s);
    for (i, (r, f)) in s
        .free_frequencies_hz
        .iter()
        .zip(&s.full_free_frequencies_hz)
        .enumerate()
    {
        t += &format!(
            "  {:>4}  {r:>12.2}  {f:>12.2}  {:>+9.3} %\n",
            i + 1,
            percent(d[i])
        );
    }
    t += &format!("{}\n", resolution(s, &d, cutoff_hz(raw)));
    t += "Attachments at the reference position (FE node: weight):\n";
    let width = s
        .attachments
        .iter()
        .map(|a| a.point.chars().count())
        .max()
        .unwrap_or(0);
    for a in &s.attachments {
        let nodes: Vec<String> = a
            .nodes
            .iter()
            .zip(&a.weights)
            .map(|(n, w)| format!("{n}: {w:.3}"))
            .collect();
        t += &format!("  {:<width$}  {}\n", a.point, nodes.join(", "));
    }
    t
}

fn cutoff_hz(raw: &RawBody) -> Option<f64> {
    match (&raw.fe, &raw.beam) {
        (Some(fe), _) => fe.cutoff_hz,
        (_, Some(beam)) => beam.cutoff_hz,
        _ => None,
    }
}

/// "the first mode (817.0 Hz)" or "the lowest 9 modes (up to 2806.4 Hz)".
fn lowest(count: usize, top_hz: f64) -> String {
    if count == 1 {
        format!("the first mode ({top_hz:.1} Hz)")
    } else {
        format!("the lowest {count} modes (up to {top_hz:.1} Hz)")
    }
}

/// How well the reduction resolves the body, in words: how far up the lowest modes agree with
/// the full model, and (with `cutoff_hz`) the modes below half the cutoff.
fn resolution(s: &FeSummary, d: &[f64], cutoff_hz: Option<f64>) -> String {
    let n = d.len();
    if n == 0 {
        return "Resolution: the body has no elastic modes in the reduction.".into();
    }
    let worst = d
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map_or((0, 0.0), |(i, x)| (i, *x));
    let hz = |k: usize| s.full_free_frequencies_hz[k - 1];
    let mut w = String::from("Resolution: ");
    let close = lowest_within(d, CLOSE);
    let fair = lowest_within(d, FAIR);
    if close == n {
        w += &format!(
            "all {n} elastic modes of the reduced body (up to {:.1} Hz) agree with the full model within 0.1 % \
             (largest difference {:+.4} %, mode {}).",
            hz(n),
            percent(worst.1),
            worst.0 + 1
        );
    } else {
        w += &match (close, fair) {
            (0, 0) => "not even the first mode is within 1 % of the full model".to_string(),
            (0, f) => format!("within 1 % of the full model: {}", lowest(f, hz(f))),
            (c, f) if f > c => format!(
                "within 0.1 % of the full model: {}; within 1 %: {}",
                lowest(c, hz(c)),
                lowest(f, hz(f))
            ),
            (c, _) => format!("within 0.1 % of the full model: {}", lowest(c, hz(c))),
        };
        w += &format!(
            "; the largest difference is {:+.2} % (mode {}, {:.1} Hz). Above these the reduced body is \
             stiffer than the full model: keep more modes (`modes`, `cutoff_hz`) if the machine's \
             dynamics reach there.",
            100.0 * worst.1,
            worst.0 + 1,
            hz(worst.0 + 1)
        );
    }
    if let Some(cutoff) = cutoff_hz {
        let half = 0.5 * cutoff;
        let below: Vec<f64> = d
            .iter()
            .zip(&s.full_free_frequencies_hz)
            .filter(|(_, f)| **f < half)
            .map(|(x, _)| x.abs())
            .collect();
        let max = below.iter().copied().fold(0.0, f64::max);
        w += &format!(
            "\n  Below half the cutoff ({half:.1} Hz): {} modes, largest difference {:.4} % ({}).",
            below.len(),
            100.0 * max,
            if max <= CLOSE {
                "within 0.1 %, as cutoff_hz promises"
            } else {
                "MORE than the 0.1 % cutoff_hz aims at"
            }
        );
    }
    w
}
