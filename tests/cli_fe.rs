//! `eij fe --machine F --body NAME [--json]` against numbers written here: a slender variant of
//! the elastic column of `machines/reference/column-mill-beam.toml` has its first free-free
//! bending and torsion frequencies from the Euler–Bernoulli and the uniform-shaft formulas, its
//! mass and centre of gravity those of a uniform bar; the reduced body's frequencies are upper
//! bounds of the full model's (Rayleigh–Ritz); errors are one line.

mod common;

use common::{one_line_error, root, run, Scratch};
use serde_json::Value;
use std::f64::consts::PI;

const BEAM: &str = "machines/reference/column-mill-beam.toml";

/// The slender column: the reference column's beam with second moments I_y = I_z = 4e-6 m⁴,
/// torsion constant J = 2e-6 m⁴ and 24 elements (A = 0.08 m², L = 1.55 m, E = 1.2e11 Pa,
/// G = 4.6e10 Pa, ρ = 7200 kg/m³ as in the file).
const I: f64 = 4e-6;
const J: f64 = 2e-6;
const A: f64 = 0.08;
const L: f64 = 1.55;
const E: f64 = 1.2e11;
const G: f64 = 4.6e10;
const RHO: f64 = 7200.0;

fn slender(scratch: &Scratch) -> String {
    let text = std::fs::read_to_string(root().join(BEAM)).unwrap();
    let mut out = text.clone();
    for (from, to) in [
        ("elements = 8", "elements = 24"),
        ("iy_m4 = 2.167e-3", "iy_m4 = 4e-6"),
        ("iz_m4 = 2.167e-3", "iz_m4 = 4e-6"),
        ("torsion_m4 = 3.2e-3", "torsion_m4 = 2e-6"),
    ] {
        assert!(out.contains(from), "{from}");
        out = out.replacen(from, to, 1);
    }
    scratch.write("slender.toml", out)
}

fn json(args: &[&str]) -> Value {
    let r = run(args);
    assert!(r.ok, "{}", r.stderr);
    serde_json::from_str(&r.stdout).unwrap_or_else(|e| panic!("{e}: {}", r.stdout))
}

fn list(v: &Value, key: &str) -> Vec<f64> {
    v[key]
        .as_array()
        .unwrap_or_else(|| panic!("{key} missing"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn the_slender_column_has_the_textbook_free_free_frequencies() {
    let scratch = Scratch::new("cli-fe-slender");
    let machine = slender(&scratch);
    let s = json(&["fe", "--machine", &machine, "--body", "column", "--json"]);
    assert_eq!(s["body"], "column");
    assert_eq!(s["dofs"], 6 * 25);
    let m = RHO * A * L;
    assert!((s["mass_kg"].as_f64().unwrap() - m).abs() < 1e-9 * m, "{s}");
    let cog = list(&s, "cog_m");
    let want = [0.0, 0.55, -0.45 + L / 2.0];
    for (c, w) in cog.iter().zip(want) {
        assert!((c - w).abs() < 1e-9, "{cog:?}");
    }
    let reduced = list(&s, "free_frequencies_hz");
    let full = list(&s, "full_free_frequencies_hz");
    assert_eq!(reduced.len(), full.len());
    assert!(reduced.len() > 12, "{reduced:?}");
    // Craig–Bampton is a Rayleigh–Ritz projection: its frequencies bound the full model's from
    // above, mode by mode.
    for (r, f) in reduced.iter().zip(&full) {
        assert!(*r >= f * (1.0 - 1e-9), "{r} < {f}");
    }
    // Euler–Bernoulli free-free beam: f₁ = (β₁L)² / (2π L²) · √(EI / ρA), β₁L = 4.730041; twice
    // (I_y = I_z). Shear and rotary inertia lower it by ~0.2 % at r/L = 0.0046.
    let bending = 4.730_040_745_f64.powi(2) / (2.0 * PI * L * L) * (E * I / (RHO * A)).sqrt();
    for f in [&reduced[..2], &full[..2]].concat() {
        assert!(
            ((f - bending) / bending).abs() < 5e-3,
            "{f} Hz vs {bending} Hz"
        );
    }
    // A free-free shaft in torsion: f₁ = 1/(2L) · √(GJ / ρI_p), I_p = I_y + I_z.
    let torsion = 1.0 / (2.0 * L) * (G * J / (RHO * 2.0 * I)).sqrt();
    for freqs in [&reduced, &full] {
        assert!(
            freqs.iter().any(|f| ((f - torsion) / torsion).abs() < 5e-3),
            "no mode near {torsion} Hz in {freqs:?}"
        );
    }
    // Every point the machine attaches to the column, with nodes and weights summing to one.
    let atts = s["attachments"].as_array().unwrap();
    let points: Vec<&str> = atts.iter().map(|a| a["point"].as_str().unwrap()).collect();
    for p in [
        "y.carriage[0]",
        "y.nut",
        "z.carriage[3]",
        "z.bearing",
        "z.scale",
    ] {
        assert!(points.contains(&p), "{p} not in {points:?}");
    }
    for a in atts {
        let w: f64 = a["weights"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .sum();
        assert!((w - 1.0).abs() < 1e-12, "{a}");
        assert!(s["reduction_s"].as_f64().unwrap() >= 0.0);
    }
    assert_eq!(s["warnings"].as_array().map(Vec::len), Some(0));
}

#[test]
fn a_stiffness_factor_scales_both_frequency_lists_by_its_root() {
    let scratch = Scratch::new("cli-fe-factor");
    let text = std::fs::read_to_string(root().join(BEAM)).unwrap();
    let soft = scratch.write(
        "soft.toml",
        text.replacen("modes = 12", "modes = 12\nstiffness_factor = 0.25", 1),
    );
    let base = json(&["fe", "--machine", BEAM, "--body", "column", "--json"]);
    let half = json(&["fe", "--machine", &soft, "--body", "column", "--json"]);
    assert_eq!(half["stiffness_factor"], 0.25);
    for key in ["free_frequencies_hz", "full_free_frequencies_hz"] {
        for (a, b) in list(&base, key).iter().zip(list(&half, key)) {
            assert!((0.5 * a - b).abs() <= 1e-9 * a, "{key}: {a} vs {b}");
        }
    }
}

#[test]
fn the_text_says_how_well_the_reduction_resolves_the_body() {
    let r = run(&["fe", "--machine", BEAM, "--body", "column"]);
    assert!(r.ok, "{}", r.stderr);
    for needle in [
        "Elastic body column of column-mill-beam",
        "mass 892.800 kg",
        "Resolution: all 48 elastic modes",
        "within 0.1 %",
        "z.carriage[0]",
    ] {
        assert!(r.stdout.contains(needle), "{needle} not in:\n{}", r.stdout);
    }
}

#[test]
fn the_words_count_the_modes_the_numbers_show_within_a_tenth_of_a_percent() {
    let scratch = Scratch::new("cli-fe-words");
    let machine = slender(&scratch);
    let s = json(&["fe", "--machine", &machine, "--body", "column", "--json"]);
    let within = list(&s, "free_frequencies_hz")
        .iter()
        .zip(list(&s, "full_free_frequencies_hz"))
        .take_while(|(r, f)| ((*r - f) / f).abs() <= 1e-3)
        .count();
    let r = run(&["fe", "--machine", &machine, "--body", "column"]);
    assert!(r.ok, "{}", r.stderr);
    let said = format!("Resolution: within 0.1 % of the full model: the lowest {within} modes");
    assert!(r.stdout.contains(&said), "{said} not in:\n{}", r.stdout);
    assert!(r.stdout.contains("keep more modes"), "{}", r.stdout);
}

#[test]
fn a_body_that_is_not_elastic_is_one_line() {
    let machine = BEAM;
    for (body, needles) in [
        ("head", &["--body head", "rigid", "elastic: column"][..]),
        ("floor", &["--body floor", "fixed"][..]),
        (
            "spindle",
            &["--body spindle", "no body", "elastic: column"][..],
        ),
    ] {
        let out = common::eij(&["fe", "--machine", machine, "--body", body]);
        one_line_error(&out, needles);
        assert!(out.stdout.is_empty());
    }
    let rigid = common::eij(&[
        "fe",
        "--machine",
        "machines/reference/column-mill.toml",
        "--body",
        "column",
    ]);
    one_line_error(&rigid, &["--body column", "rigid", "elastic: none"]);
    let missing = common::eij(&["fe", "--machine", machine]);
    one_line_error(&missing, &["--body"]);
}
