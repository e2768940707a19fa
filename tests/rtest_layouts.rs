//! Real measurement files (docs/measurement-files.md): every accepted layout gives the EIJ of
//! the contract file of the same test; two-system recordings made from one simulation give the
//! single-file EIJ and the clock offset that was applied; elliptic internal paths (servo
//! mismatch), timestamp jitter and gaps are evaluated; ISO 230-4 figures against hand
//! calculations.
//!
//! Test data come from eij's own closed-loop simulation of the demo machine (library calls),
//! with seeded R-Test noise added here; every other layout is derived from them inside the test.
//! The truth of a derived layout is the evaluation of the contract file it was derived from, or
//! the transformation applied (a clock offset, a lag).

mod common;

use std::collections::BTreeMap;

use common::synth::{csv_text, Rng};
use common::{demo, Scratch};
use eij::axes::{Axis, Direction, Eij, Plane};
use eij::control::ClosedLoop;
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{evaluate_tests, EvaluatedTest, OffsetSource, Suite, SuiteOptions};
use eij::rtest::iso230::{bidirectional_deviation, path_figures};
use eij::rtest::Warning;
use eij::sim::setpoint::Circle;
use eij::sim::{output, simulate};

/// cw and ccw at 2 and 8 m/s²: tests that separate a clock offset from cross-talk.
const BOTH_DIRECTIONS_TWO_ACCELERATIONS: [(Direction, f64); 4] = [
    (Direction::Cw, 2.0),
    (Direction::Ccw, 2.0),
    (Direction::Cw, 8.0),
    (Direction::Ccw, 8.0),
];

/// Columns t, internal x/y/z, external x/y/z (s, mm).
#[derive(Clone)]
struct Cols {
    t: Vec<f64>,
    int: [Vec<f64>; 3],
    ext: [Vec<f64>; 3],
}

impl Cols {
    /// Every `step`-th sample from `first`.
    fn every(&self, first: usize, step: usize) -> Cols {
        let pick = |v: &Vec<f64>| v.iter().skip(first).step_by(step).copied().collect();
        Cols {
            t: pick(&self.t),
            int: [pick(&self.int[0]), pick(&self.int[1]), pick(&self.int[2])],
            ext: [pick(&self.ext[0]), pick(&self.ext[1]), pick(&self.ext[2])],
        }
    }

    fn csv(&self) -> String {
        csv_text(&self.t, &self.int, &self.ext)
    }
}

/// The demo machine's zx circle (r = 2 mm) at `rate_hz`, with Gaussian R-Test noise σ on the
/// external columns.
fn simulated(direction: Direction, accel: f64, rate_hz: f64, noise_um: f64, seed: u64) -> Cols {
    let machine = demo();
    let cl = ClosedLoop::new(&machine, &machine.reference_pose()).unwrap();
    let circle = Circle::new(Plane::Zx, 0.002, accel, direction);
    let run = simulate(&cl, &circle, rate_hz).unwrap();
    let s = output::to_series(&cl, &run, "sim".into()).unwrap();
    let mut rng = Rng::new(seed);
    let ext = Axis::ALL.map(|a| {
        s.ext_mm(a)
            .iter()
            .map(|v| v + noise_um * 1e-3 * rng.gauss())
            .collect()
    });
    Cols {
        t: s.t_s().to_vec(),
        int: Axis::ALL.map(|a| s.int_mm(a).to_vec()),
        ext,
    }
}

fn evaluate_folder(dir: &std::path::Path, opts: &SuiteOptions) -> Suite {
    let tests = expand_tests(&[dir.to_path_buf()]).unwrap();
    evaluate_tests(&tests, opts).unwrap()
}

fn eij_of(suite: &Suite, i: usize) -> BTreeMap<Eij, f64> {
    suite.tests[i].result.eij.value_map()
}

/// Largest |difference| between two parameter sets.
fn max_diff(a: &BTreeMap<Eij, f64>, b: &BTreeMap<Eij, f64>) -> f64 {
    a.iter().map(|(p, v)| (v - b[p]).abs()).fold(0.0, f64::max)
}

/// Every accepted layout of the same test gives the contract file's EIJ (to 1e-9 µm·s²/m: the
/// numbers are the same, only written differently).
#[test]
fn every_layout_gives_the_contract_files_eij() {
    let d = Scratch::new("layouts");
    let c = simulated(Direction::Ccw, 5.0, 1000.0, 1.0, 11);
    let n = c.t.len();
    let row = |i: usize| -> [f64; 7] {
        [
            c.t[i],
            c.int[0][i],
            c.int[1][i],
            c.int[2][i],
            c.ext[0][i],
            c.ext[1][i],
            c.ext[2][i],
        ]
    };
    let radius = "radius_mm = 2.0\n";
    d.write("contract/rtest.toml", radius);
    d.write("contract/zx.csv", c.csv());

    // `;` with decimal commas, comment lines, a metadata block, upper-case quoted header, CRLF.
    let mut s =
        String::from("# exported by the R-Test software\r\nMachine;demo-vmc\r\nOperator;KS\r\n");
    s.push_str(
        "\"T_S\";\"X_INT_MM\";\"Y_INT_MM\";\"Z_INT_MM\";\"X_EXT_MM\";\"Y_EXT_MM\";\"Z_EXT_MM\"\r\n",
    );
    for i in 0..n {
        let cells: Vec<String> = row(i)
            .iter()
            .map(|v| format!("{v}").replace('.', ","))
            .collect();
        s.push_str(&cells.join(";"));
        s.push_str("\r\n");
        if i == n / 2 {
            s.push_str("# a comment between rows\r\n");
        }
    }
    d.write("semicolon/rtest.toml", radius);
    d.write("semicolon/zx.csv", s);

    // Tab separated, columns in another order, with extra columns.
    let mut s = String::from(
        "z_ext_mm\tnote\tt_s\tx_int_mm\ty_int_mm\tz_int_mm\tx_ext_mm\ty_ext_mm\tspeed\n",
    );
    for i in 0..n {
        let r = row(i);
        s.push_str(&format!(
            "{}\tok\t{}\t{}\t{}\t{}\t{}\t{}\t0\n",
            r[6], r[0], r[1], r[2], r[3], r[4], r[5]
        ));
    }
    d.write("tab/rtest.toml", radius);
    d.write("tab/zx.csv", s);

    // The CNC's names and units, mapped in rtest.toml: time in ms, internal in µm.
    let mut s = String::from("Time,X_ACT,Y_ACT,Z_ACT,RX,RY,RZ\n");
    for i in 0..n {
        let r = row(i);
        s.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            r[0] * 1e3,
            r[1] * 1e3,
            r[2] * 1e3,
            r[3] * 1e3,
            r[4],
            r[5],
            r[6]
        ));
    }
    d.write(
        "units/rtest.toml",
        "radius_mm = 2.0\n[columns]\nt_s = { name = \"Time\", unit = \"ms\" }\n\
         x_int_mm = { name = \"X_ACT\", unit = \"um\" }\ny_int_mm = { name = \"Y_ACT\", unit = \"µm\" }\n\
         z_int_mm = { name = \"z_act\", unit = \"um\" }\nx_ext_mm = \"RX\"\ny_ext_mm = \"RY\"\nz_ext_mm = { name = \"RZ\" }\n",
    );
    d.write("units/zx.csv", s);

    let reference = evaluate_folder(&d.path("contract"), &SuiteOptions::default());
    let e0 = eij_of(&reference, 0);
    assert!(e0[&Eij::new(Axis::Z, Axis::Z)].abs() > 0.1, "{e0:?}");
    for layout in ["semicolon", "tab", "units"] {
        let suite = evaluate_folder(&d.path(layout), &SuiteOptions::default());
        let t = &suite.tests[0];
        assert_eq!(
            t.result.samples_used, reference.tests[0].result.samples_used,
            "{layout}"
        );
        let diff = max_diff(&eij_of(&suite, 0), &e0);
        assert!(diff < 1e-9, "{layout}: EIJ differ by {diff:e}");
    }
}

/// Writes the two-system files of `c` (internal every 5th sample on the internal clock,
/// external every 2nd on the external clock, `offset_s` behind) and returns the `[[test]]`
/// entry.
fn write_two_systems(
    d: &Scratch,
    folder: &str,
    name: &str,
    c: &Cols,
    clock: f64,
    offset_s: f64,
) -> String {
    let mut int = String::from("t_s,x_int_mm,y_int_mm,z_int_mm\n");
    for i in (0..c.t.len()).step_by(5) {
        int.push_str(&format!(
            "{},{},{},{}\n",
            c.t[i] + clock,
            c.int[0][i],
            c.int[1][i],
            c.int[2][i]
        ));
    }
    let mut ext = String::from("t_s,x_ext_mm,y_ext_mm,z_ext_mm\n");
    for i in (1..c.t.len()).step_by(2) {
        ext.push_str(&format!(
            "{},{},{},{}\n",
            c.t[i] + clock - offset_s,
            c.ext[0][i],
            c.ext[1][i],
            c.ext[2][i]
        ));
    }
    d.write(&format!("{folder}/cnc_{name}.csv"), int);
    d.write(&format!("{folder}/probe_{name}.csv"), ext);
    format!("[[test]]\ninternal = \"cnc_{name}.csv\"\nexternal = \"probe_{name}.csv\"\n")
}

/// Two systems: the internal readings at 1 kHz on one clock, the R-Test at 2.5 kHz on another
/// (offset 37.3456 ms, each test starting at its own time on the clocks), made from one 5 kHz
/// simulation per test. cw and ccw at 2 and 8 m/s² separate the offset from cross-talk. Without
/// noise the EIJ equal those of the single 1 kHz file of the same simulation within 2 % (of each
/// in-talk, and of the largest EIJ for cross-talk) and the offset is recovered to 0.5 µs; with
/// R-Test noise (σ = 1.4 µm) the offset lies within three of its standard errors.
#[test]
fn two_system_recordings_give_the_single_file_eij_and_the_clock_offset() {
    let d = Scratch::new("two-systems");
    let offset_s = 0.0373456;
    let mut toml = String::from("radius_mm = 2.0\n");
    let mut noisy_toml = toml.clone();
    let mut clock = 1234.5;
    for (k, (dir, accel)) in BOTH_DIRECTIONS_TWO_ACCELERATIONS.into_iter().enumerate() {
        let c = simulated(dir, accel, 5000.0, 0.0, 0);
        let name = format!("{dir}_{accel}");
        d.write(&format!("single/{name}.csv"), c.every(0, 5).csv());
        toml.push_str(&write_two_systems(&d, "split", &name, &c, clock, offset_s));
        let mut noisy = c.clone();
        let mut rng = Rng::new(100 + k as u64);
        for a in 0..3 {
            noisy.ext[a]
                .iter_mut()
                .for_each(|v| *v += 1.4e-3 * rng.gauss());
        }
        noisy_toml.push_str(&write_two_systems(
            &d, "noisy", &name, &noisy, clock, offset_s,
        ));
        clock += 17.25;
    }
    d.write("split/rtest.toml", &toml);
    d.write("noisy/rtest.toml", &noisy_toml);
    d.write("single/rtest.toml", "radius_mm = 2.0\n");
    let split = evaluate_folder(&d.path("split"), &SuiteOptions::default());
    let single = evaluate_folder(&d.path("single"), &SuiteOptions::default());
    assert_eq!(split.clocks.len(), 1);
    let c = &split.clocks[0];
    assert!(c.separable && c.applied && c.two_systems, "{:?}", c);
    assert!(
        (c.offset_ms - offset_s * 1e3).abs() < 5e-4,
        "offset {} ± {:?} ms, applied {} ms",
        c.offset_ms,
        c.std_err_ms,
        offset_s * 1e3
    );
    for (t, s) in split.tests.iter().zip(&single.tests) {
        let o = t.time_offset.as_ref().unwrap();
        assert_eq!(o.source, OffsetSource::JointFit);
        // The test's own trajectory alignment is off by the antisymmetric cross-talk only.
        assert!((o.alignment_ms.unwrap() - offset_s * 1e3).abs() < 0.05);
        let name = t.input.name();
        let stem = s
            .input
            .primary_file()
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        assert!(
            name.contains(&format!("cnc_{stem}.csv")),
            "{name} vs {stem}"
        );
        let (e_split, e_single) = (t.result.eij.value_map(), s.result.eij.value_map());
        let largest = e_single.values().fold(0.0f64, |m, v| m.max(v.abs()));
        for (p, v) in &e_single {
            let tol = if p.deviation == p.accelerated {
                0.02 * v.abs()
            } else {
                0.02 * largest
            };
            assert!(
                (e_split[p] - v).abs() < tol,
                "{name} {p}: two systems {} vs single file {v}",
                e_split[p]
            );
        }
    }
    assert!(split.warnings.is_empty(), "{:?}", split.warnings);

    let noisy = evaluate_folder(&d.path("noisy"), &SuiteOptions::default());
    let c = &noisy.clocks[0];
    let se = c.std_err_ms.unwrap();
    assert!(se > 0.0 && se < 2e-3, "std err {se} ms");
    assert!(
        (c.offset_ms - offset_s * 1e3).abs() < 3.0 * se,
        "offset {} ± {se} ms, applied {} ms",
        c.offset_ms,
        offset_s * 1e3
    );
}

/// One direction at two accelerations cannot separate a clock offset from cross-talk: the
/// offset stays the trajectory alignment, and the output says that the antisymmetric
/// cross-talk is not measured. Clocks that restart per file are not one offset either.
#[test]
fn an_offset_the_tests_cannot_separate_is_said_so() {
    let d = Scratch::new("clock-not-separable");
    let mut toml = String::from("radius_mm = 2.0\n");
    let mut restart = String::from("radius_mm = 2.0\n");
    for (k, (dir, accel)) in [
        (Direction::Cw, 2.0),
        (Direction::Cw, 8.0),
        (Direction::Ccw, 8.0),
    ]
    .into_iter()
    .enumerate()
    {
        let c = simulated(dir, accel, 2000.0, 0.0, 7);
        let mut int = String::from("t_s,x_int_mm,y_int_mm,z_int_mm\n");
        let mut ext = String::from("t_s,x_ext_mm,y_ext_mm,z_ext_mm\n");
        // Clock offsets 12 ms, 12 ms, then 512 ms (the third test's logger restarted).
        let offset = if k == 2 { 0.512 } else { 0.012 };
        for i in 0..c.t.len() {
            int.push_str(&format!(
                "{},{},{},{}\n",
                c.t[i], c.int[0][i], c.int[1][i], c.int[2][i]
            ));
            ext.push_str(&format!(
                "{},{},{},{}\n",
                c.t[i] - offset,
                c.ext[0][i],
                c.ext[1][i],
                c.ext[2][i]
            ));
        }
        d.write(&format!("m/i{k}.csv"), &int);
        d.write(&format!("m/e{k}.csv"), &ext);
        let entry = format!("[[test]]\ninternal = \"i{k}.csv\"\nexternal = \"e{k}.csv\"\n");
        restart.push_str(&entry);
        if k < 2 {
            toml.push_str(&entry);
        }
    }
    d.write("m/rtest.toml", &toml);
    let tests = expand_tests(&[d.path("m/i0.csv"), d.path("m/i1.csv")]).unwrap();
    let suite = evaluate_tests(&tests, &SuiteOptions::default()).unwrap();
    let c = &suite.clocks[0];
    assert!(!c.separable, "{c:?}");
    assert!((c.offset_ms - 12.0).abs() < 0.05, "{}", c.offset_ms);
    assert!(suite.warnings.iter().any(
        |w| matches!(&w.warning, Warning::ClockOffsetFromTrajectories { reason, .. }
            if reason.contains("cannot be told from antisymmetric cross-talk"))
    ));
    for t in &suite.tests {
        assert_eq!(
            t.time_offset.as_ref().unwrap().source,
            OffsetSource::Trajectory
        );
        assert!(
            t.result.warnings.iter().any(
                |w| matches!(w, Warning::TestOffsetFromTrajectories { ab, ba, .. }
                    if ab.name() == "EZX" && ba.name() == "EXZ")
            ),
            "{:?}",
            t.result.warnings
        );
    }

    d.write("m/rtest.toml", &restart);
    let suite = evaluate_folder(&d.path("m"), &SuiteOptions::default());
    assert!(
        suite
            .warnings
            .iter()
            .any(|w| matches!(w.warning, Warning::AlignmentsDiffer { .. })),
        "{:?}",
        suite.warnings
    );
    let offsets: Vec<f64> = suite
        .tests
        .iter()
        .map(|t| t.time_offset.as_ref().unwrap().offset_ms)
        .collect();
    assert!(
        (offsets[2] - 512.0).abs() < 0.05 && (offsets[0] - 12.0).abs() < 0.05,
        "{offsets:?}"
    );
}

/// A probe logger whose external channels lag the scales by 0.2 ms in one file: the lag fitted
/// over cw and ccw at two accelerations is the applied one, it is reported without
/// `fit_time_offset` and corrected with it (cubic interpolation of the external columns),
/// giving the EIJ of the unlagged files within 2 % (noise-free, so that only the correction is
/// compared).
#[test]
fn a_lagging_logger_is_found_and_corrected() {
    let d = Scratch::new("lag");
    for (dir, accel) in BOTH_DIRECTIONS_TWO_ACCELERATIONS {
        let c = simulated(dir, accel, 5000.0, 0.0, 0);
        // 1 kHz rows; the external value of 0.2 ms (one 5 kHz sample) earlier.
        let mut lagged = c.every(5, 5);
        for a in 0..3 {
            lagged.ext[a] = c.ext[a].iter().skip(4).step_by(5).copied().collect();
            lagged.ext[a].truncate(lagged.t.len());
        }
        let n = lagged.ext[0].len();
        lagged.t.truncate(n);
        for a in 0..3 {
            lagged.int[a].truncate(n);
        }
        d.write(&format!("lag/{dir}_{accel}.csv"), lagged.csv());
        d.write(&format!("clean/{dir}_{accel}.csv"), c.every(5, 5).csv());
    }
    d.write("lag/rtest.toml", "radius_mm = 2.0\n");
    d.write("clean/rtest.toml", "radius_mm = 2.0\n");
    let clean = evaluate_folder(&d.path("clean"), &SuiteOptions::default());
    let found = evaluate_folder(&d.path("lag"), &SuiteOptions::default());
    let c = &found.clocks[0];
    assert!(!c.applied);
    let se = c.std_err_ms.unwrap();
    assert!(
        (c.offset_ms + 0.2).abs() < (3.0 * se).max(2e-3),
        "{} ± {se}",
        c.offset_ms
    );
    assert!(found.warnings.iter().any(|w| matches!(
        w.warning,
        Warning::ClockOffsetNotCorrected {
            external_late: true,
            ..
        }
    )));
    // Uncorrected, the lag passes as cross-talk: EXZ of cw and ccw at 2 m/s² far apart
    // (±10⁶·0.2 ms/ω = ±6.3 µm·s²/m).
    let exz = Eij::new(Axis::X, Axis::Z);
    let at = |name: &str| {
        let t = found
            .tests
            .iter()
            .find(|t| t.input.name().ends_with(name))
            .unwrap();
        t.result.eij[&exz].value
    };
    assert!((at("/cw_2.csv") - at("/ccw_2.csv")).abs() > 10.0);

    let corrected = evaluate_folder(
        &d.path("lag"),
        &SuiteOptions {
            fit_time_offset: true,
            ..Default::default()
        },
    );
    for (t, r) in corrected.tests.iter().zip(&clean.tests) {
        assert_corrected(t, r, OffsetSource::JointFit);
    }

    // A known lag stated per test in rtest.toml corrects alike.
    let mut toml = String::from("radius_mm = 2.0\n");
    for (dir, accel) in BOTH_DIRECTIONS_TWO_ACCELERATIONS {
        toml.push_str(&format!(
            "[[test]]\nfile = \"{dir}_{accel}.csv\"\ntime_offset_ms = -0.2\n"
        ));
    }
    d.write("lag/rtest.toml", toml);
    let given = evaluate_folder(&d.path("lag"), &SuiteOptions::default());
    for (t, r) in given.tests.iter().zip(&clean.tests) {
        assert_corrected(t, r, OffsetSource::Given);
    }
}

/// A test corrected for a lag gives the EIJ of the unlagged test within 2 % of the largest.
fn assert_corrected(t: &EvaluatedTest, clean: &EvaluatedTest, source: OffsetSource) {
    let largest = clean
        .result
        .eij
        .iter()
        .fold(0.0f64, |m, (_, e)| m.max(e.value.abs()));
    let diff = max_diff(&t.result.eij.value_map(), &clean.result.eij.value_map());
    assert!(
        diff < 0.02 * largest,
        "{}: {diff} of {largest}",
        t.input.name()
    );
    assert_eq!(t.time_offset.as_ref().unwrap().source, source);
}

/// Servo mismatch: the X path 3 % smaller than the Z path (the X readings scaled by 0.97 about
/// the centre, the deviation kept), timestamp jitter of ±0.4 ms at 1 kHz, and three gaps of
/// 20 ms are evaluated, within 6 % (ellipse) and 2 % (jitter, gaps) of the round, regular file.
#[test]
fn ellipses_jitter_and_gaps_are_evaluated() {
    let d = Scratch::new("ellipse-jitter");
    let c = simulated(Direction::Ccw, 5.0, 1000.0, 0.5, 21);
    d.write("m/round.csv", c.csv());
    let mut ellipse = c.clone();
    for i in 0..c.t.len() {
        let dev = c.ext[0][i] - c.int[0][i];
        ellipse.int[0][i] = 0.97 * c.int[0][i];
        ellipse.ext[0][i] = ellipse.int[0][i] + dev;
    }
    d.write("m/ellipse.csv", ellipse.csv());
    let mut jitter = c.clone();
    let mut rng = Rng::new(5);
    for t in jitter.t.iter_mut() {
        *t += 0.8e-3 * ((rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
    }
    d.write("m/jitter.csv", jitter.csv());
    let mid = c.t.len() / 2;
    let keep: Vec<usize> = (0..c.t.len())
        .filter(|&i| {
            !(mid - 200..mid - 180).contains(&i)
                && !(mid..mid + 20).contains(&i)
                && !(mid + 150..mid + 170).contains(&i)
        })
        .collect();
    let gaps = Cols {
        t: keep.iter().map(|&i| c.t[i]).collect(),
        int: std::array::from_fn(|a| keep.iter().map(|&i| c.int[a][i]).collect()),
        ext: std::array::from_fn(|a| keep.iter().map(|&i| c.ext[a][i]).collect()),
    };
    d.write("m/gaps.csv", gaps.csv());
    d.write("m/rtest.toml", "radius_mm = 2.0\n");
    let suite = evaluate_folder(&d.path("m"), &SuiteOptions::default());
    let by = |stem: &str| {
        suite
            .tests
            .iter()
            .find(|t| t.input.name().ends_with(&format!("{stem}.csv")))
            .unwrap()
    };
    let round = by("round");
    let largest = round
        .result
        .eij
        .iter()
        .fold(0.0f64, |m, (_, e)| m.max(e.value.abs()));
    for (stem, tol) in [("ellipse", 0.06), ("jitter", 0.02), ("gaps", 0.02)] {
        let t = by(stem);
        assert!(
            t.result.revolutions >= 4,
            "{stem}: {} revolutions",
            t.result.revolutions
        );
        for (p, v) in &round.result.eij.value_map() {
            let bound = if p.deviation == p.accelerated {
                tol * v.abs()
            } else {
                tol * largest
            };
            assert!(
                (t.result.eij[p].value - v).abs() < bound,
                "{stem} {p}: {} vs round {v}",
                t.result.eij[p].value
            );
        }
    }
    // The ISO 230-4 circular deviation sees the 3 % ellipse: 60 µm on a 2 mm circle.
    let g = by("ellipse")
        .result
        .iso230
        .unwrap()
        .internal
        .circular_deviation_um;
    assert!((g - 60.0).abs() < 3.0, "G = {g} µm");
}

/// ISO 230-4 figures against hand calculations: an ellipse with half-axes r(1 ± ε) about an
/// offset centre has G = 2εr, F max = +εr, F min = −εr against the nominal r; two round paths of
/// radii r ± a about one centre have G(b) = 2a, each G = 0.
#[test]
fn iso_230_4_figures_match_hand_calculations() {
    let (r, eps, c) = (2.0, 0.004, [0.013, -0.021]);
    let n = 3600;
    let phi: Vec<f64> = (0..n)
        .map(|k| k as f64 * std::f64::consts::TAU / n as f64)
        .collect();
    let a: Vec<f64> = phi
        .iter()
        .map(|p| c[0] + r * (1.0 + eps) * p.cos())
        .collect();
    let b: Vec<f64> = phi
        .iter()
        .map(|p| c[1] + r * (1.0 - eps) * p.sin())
        .collect();
    let f = path_figures(&a, &b, r).unwrap();
    assert!(
        (f.circular_deviation_um - 2.0 * eps * r * 1e3).abs() < 1e-6,
        "{f:?}"
    );
    assert!((f.radial_deviation_max_um - eps * r * 1e3).abs() < 1e-6);
    assert!((f.radial_deviation_min_um + eps * r * 1e3).abs() < 1e-6);
    assert!((f.centre_mm[0] - c[0]).abs() < 1e-12 && (f.centre_mm[1] - c[1]).abs() < 1e-12);

    let off = 0.0015;
    let circle = |rad: f64| -> (Vec<f64>, Vec<f64>) {
        (
            phi.iter().map(|p| c[0] + rad * p.cos()).collect(),
            phi.iter().map(|p| c[1] + rad * p.sin()).collect(),
        )
    };
    let (cw, ccw) = (circle(r + off), circle(r - off));
    let g = bidirectional_deviation([(&cw.0, &cw.1), (&ccw.0, &ccw.1)]).unwrap();
    assert!((g - 2.0 * off * 1e3).abs() < 1e-6, "G(b) = {g}");
    assert!(path_figures(&cw.0, &cw.1, r).unwrap().circular_deviation_um < 1e-6);
}

/// An R-Test logger that ran through a whole session: the external file holds a minute of rest
/// before and after the circle (2.5 kHz, its own clock), the CNC trace only the test. The
/// alignment searches the whole session and finds the offset of the one test (the trajectory
/// alone: one test does not separate it from cross-talk, which the output says).
#[test]
fn a_session_long_probe_record_is_aligned() {
    let d = Scratch::new("session");
    let c = simulated(Direction::Ccw, 5.0, 5000.0, 0.0, 0);
    let offset_s = 61.2345;
    let mut int = String::from("t_s,x_int_mm,y_int_mm,z_int_mm\n");
    for i in (0..c.t.len()).step_by(5) {
        int.push_str(&format!(
            "{},{},{},{}\n",
            c.t[i], c.int[0][i], c.int[1][i], c.int[2][i]
        ));
    }
    let mut ext = String::from("t_s,x_ext_mm,y_ext_mm,z_ext_mm\n");
    let last = c.t.len() - 1;
    let row = |t: f64, i: usize| format!("{t},{},{},{}\n", c.ext[0][i], c.ext[1][i], c.ext[2][i]);
    // 60 s at rest at the start point, the test, 60 s at rest at its end point.
    let (t0, dt) = (c.t[0] - offset_s, 4e-4);
    let rest = (60.0 / dt) as usize;
    for k in (1..=rest).rev() {
        ext.push_str(&row(t0 - k as f64 * dt, 0));
    }
    for i in (0..c.t.len()).step_by(2) {
        ext.push_str(&row(c.t[i] - offset_s, i));
    }
    let t1 = c.t[last - last % 2] - offset_s;
    for k in 1..=rest {
        ext.push_str(&row(t1 + k as f64 * dt, last - last % 2));
    }
    d.write("m/cnc.csv", int);
    d.write("m/probe.csv", ext);
    d.write(
        "m/rtest.toml",
        "radius_mm = 2.0\n[[test]]\ninternal = \"cnc.csv\"\nexternal = \"probe.csv\"\n",
    );
    let suite = evaluate_folder(&d.path("m"), &SuiteOptions::default());
    let o = suite.tests[0].time_offset.as_ref().unwrap();
    assert_eq!(o.source, OffsetSource::Trajectory);
    assert!(
        (o.offset_ms - offset_s * 1e3).abs() < 0.05,
        "{} ms",
        o.offset_ms
    );
}
