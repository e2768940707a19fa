//! Internal readings in absolute machine coordinates (docs/measurement-files.md, "Controller
//! traces"): `internal_coordinates = "absolute"` subtracts the circle centre `position_mm`, so a
//! test whose internal columns are shifted by the centre evaluates to the same EIJ as the
//! relative file (an invariance, to rounding); without the key such a recording is refused with
//! one message that names the key — not a clock offset, not an R-Test range error.
//!
//! Data: the synthetic circle generator of `tests/common/synth.rs` (known EIJ, seeded noise);
//! the absolute files are its internal columns plus the centre, written here.

mod common;

use std::collections::BTreeMap;

use common::synth::{csv_text, Synth};
use common::{one_line_error, Scratch};
use eij::axes::{Eij, Plane};
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{evaluate_tests, Suite, SuiteOptions};

const CENTRE: [f64; 3] = [150.0, -100.0, 0.0];
const POSITION: &str = "position_mm = [150.0, -100.0, 0.0]\n";

fn shifted(int: &[Vec<f64>; 3], by: [f64; 3]) -> [Vec<f64>; 3] {
    [0, 1, 2].map(|a| int[a].iter().map(|v| v + by[a]).collect())
}

fn evaluate(dir: &std::path::Path) -> Result<Suite, String> {
    let tests = expand_tests(&[dir.to_path_buf()]).map_err(|e| e.to_string())?;
    evaluate_tests(&tests, &SuiteOptions::default()).map_err(|e| e.to_string())
}

fn eij(s: &Suite, i: usize) -> BTreeMap<Eij, f64> {
    s.tests[i].result.eij.value_map()
}

fn max_diff(a: &BTreeMap<Eij, f64>, b: &BTreeMap<Eij, f64>) -> f64 {
    a.iter().map(|(p, v)| (v - b[p]).abs()).fold(0.0, f64::max)
}

/// The internal file of a two-system test (t, x/y/z internal).
fn internal_csv(t: &[f64], int: &[Vec<f64>; 3]) -> String {
    let mut s = String::from("t_s,x_int_mm,y_int_mm,z_int_mm\n");
    for i in 0..t.len() {
        s.push_str(&format!(
            "{},{},{},{}\n",
            t[i], int[0][i], int[1][i], int[2][i]
        ));
    }
    s
}

/// The external file of a two-system test (t, x/y/z external).
fn external_csv(t: &[f64], ext: &[Vec<f64>; 3]) -> String {
    let mut s = String::from("t_s,x_ext_mm,y_ext_mm,z_ext_mm\n");
    for i in 0..t.len() {
        s.push_str(&format!(
            "{},{},{},{}\n",
            t[i], ext[0][i], ext[1][i], ext[2][i]
        ));
    }
    s
}

/// A single file whose internal columns are machine positions (centre [150, −100, 0] mm):
/// with the key, the EIJ of the relative file to 1e-6 µm·s²/m (the subtraction is exact to
/// rounding, 150 mm · 2⁻⁵² ≈ 3·10⁻¹¹ µm), and those lie within four standard errors of the
/// generator's truth; the key on a `[[test]]` entry does the same.
#[test]
fn absolute_internal_readings_give_the_relative_files_eij() {
    let d = Scratch::new("absolute-single");
    let s = Synth::new(Plane::Zx, true, 5.0);
    let (t, int, ext) = s.columns();
    let abs = shifted(&int, CENTRE);
    d.write("rel/rtest.toml", format!("radius_mm = 2.0\n{POSITION}"));
    d.write("rel/zx.csv", csv_text(&t, &int, &ext));
    d.write(
        "abs/rtest.toml",
        format!("radius_mm = 2.0\n{POSITION}internal_coordinates = \"absolute\"\n"),
    );
    d.write("abs/zx.csv", csv_text(&t, &abs, &ext));
    d.write(
        "entry/rtest.toml",
        format!(
            "radius_mm = 2.0\n{POSITION}[[test]]\nfile = \"zx.csv\"\ninternal_coordinates = \"absolute\"\n"
        ),
    );
    d.write("entry/zx.csv", csv_text(&t, &abs, &ext));
    let rel = evaluate(&d.path("rel")).unwrap();
    let truth = s.truth();
    for (p, v) in eij(&rel, 0) {
        let se = rel.tests[0].result.eij[&p].std_err;
        assert!(
            (v - truth[&p]).abs() < 4.0 * se,
            "{p}: {v} ± {se} vs {}",
            truth[&p]
        );
    }
    for folder in ["abs", "entry"] {
        let a = evaluate(&d.path(folder)).unwrap();
        let diff = max_diff(&eij(&a, 0), &eij(&rel, 0));
        assert!(diff < 1e-6, "{folder}: EIJ differ by {diff:e}");
        assert!(
            (a.tests[0].result.measured_radius_mm - rel.tests[0].result.measured_radius_mm).abs()
                < 1e-9
        );
    }
}

/// The same absolute file without the key: one message naming `internal_coordinates` and the
/// centre it found; without `position_mm` it still names the key; with the key and a wrong
/// centre, or no centre, it says what is wrong; an unknown value is refused naming the key.
#[test]
fn absolute_readings_without_the_key_are_refused_naming_it() {
    let d = Scratch::new("absolute-refused");
    let s = Synth::new(Plane::Xy, false, 2.0);
    let (t, int, ext) = s.columns();
    let abs = csv_text(&t, &shifted(&int, CENTRE), &ext);
    let cases: [(&str, String, &[&str]); 5] = [
        (
            "nokey",
            format!("radius_mm = 2.0\n{POSITION}"),
            &[
                "nokey/zx.csv: internal_coordinates:",
                "at the circle centre position_mm = [150, -100, 0] mm",
                "write internal_coordinates = \"absolute\"",
            ],
        ),
        (
            "noposition",
            "radius_mm = 2.0\n".to_string(),
            &["not about the circle centre at 0", "internal_coordinates = \"absolute\""],
        ),
        (
            "wrongcentre",
            "radius_mm = 2.0\nposition_mm = [0.0, 0.0, -200.0]\ninternal_coordinates = \"absolute\"\n"
                .to_string(),
            &["\"absolute\": the internal readings lie about [150", "away from the circle centre"],
        ),
        (
            "keynocentre",
            "radius_mm = 2.0\ninternal_coordinates = \"absolute\"\n".to_string(),
            &["rtest.toml: internal_coordinates: \"absolute\" needs the circle centre position_mm"],
        ),
        (
            "badvalue",
            format!("radius_mm = 2.0\n{POSITION}internal_coordinates = \"machine\"\n"),
            &["rtest.toml: internal_coordinates: 'machine': expected \"absolute\""],
        ),
    ];
    for (folder, toml, needles) in cases {
        d.write(&format!("{folder}/rtest.toml"), &toml);
        d.write(&format!("{folder}/zx.csv"), &abs);
        let e = evaluate(&d.path(folder)).unwrap_err();
        for n in needles {
            assert!(e.contains(n), "{folder}: '{n}' not in: {e}");
        }
        for not in ["clock", "R-Test range ±", "deviation"] {
            assert!(!e.contains(not), "{folder}: '{not}' in: {e}");
        }
        let out = common::eij(&["evaluate", &d.s(folder)]);
        one_line_error(&out, &["internal_coordinates"]);
    }
}

/// A two-system test (the internal file a controller's trace in machine coordinates, the
/// external one the R-Test's, each on its own clock 12.5 ms apart): without the key one line
/// naming it (before any clock alignment); with it, the EIJ and the clock offset of the same
/// test written with relative internal readings, exactly.
#[test]
fn an_absolute_trace_of_a_two_system_test() {
    let d = Scratch::new("absolute-split");
    let s = Synth::new(Plane::Zx, false, 5.0);
    let (t, int, ext) = s.columns();
    let t_ext: Vec<f64> = t.iter().map(|v| v + 0.0125).collect();
    let entry = "[[test]]\ninternal = \"cnc.csv\"\nexternal = \"probe.csv\"\n";
    for (folder, internal, key) in [
        ("rel", int.clone(), ""),
        (
            "abs",
            shifted(&int, CENTRE),
            "internal_coordinates = \"absolute\"\n",
        ),
        ("nokey", shifted(&int, CENTRE), ""),
    ] {
        d.write(
            &format!("{folder}/rtest.toml"),
            format!("radius_mm = 2.0\n{POSITION}{key}{entry}"),
        );
        d.write(&format!("{folder}/cnc.csv"), internal_csv(&t, &internal));
        d.write(&format!("{folder}/probe.csv"), external_csv(&t_ext, &ext));
    }
    let rel = evaluate(&d.path("rel")).unwrap();
    let abs = evaluate(&d.path("abs")).unwrap();
    let diff = max_diff(&eij(&abs, 0), &eij(&rel, 0));
    assert!(diff < 1e-6, "EIJ differ by {diff:e}");
    let (o_rel, o_abs) = (
        rel.tests[0].time_offset.as_ref().unwrap().offset_ms,
        abs.tests[0].time_offset.as_ref().unwrap().offset_ms,
    );
    // The files' clocks differ by −12.5 ms (internal minus external); the trajectory alignment
    // finds it up to the antisymmetric cross-talk (well under 0.1 ms here).
    assert!((o_rel + 12.5).abs() < 0.1, "offset {o_rel} ms");
    assert!((o_abs - o_rel).abs() < 1e-9, "{o_abs} vs {o_rel}");
    let e = evaluate(&d.path("nokey")).unwrap_err();
    assert!(e.contains("cnc.csv: internal_coordinates:"), "{e}");
    assert!(!e.contains("clock") && !e.contains("beyond"), "{e}");
    one_line_error(
        &common::eij(&["evaluate", &d.s("nokey")]),
        &["internal_coordinates = \"absolute\""],
    );
}
