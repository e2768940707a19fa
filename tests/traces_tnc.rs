//! Heidenhain TNCscope exports as the internal recording of a two-system test: files written here
//! by hand from the published format. The positions eij reads are the numbers the file holds
//! (converted from `%DIMENSION=`), the `s ist` channels picked by `%AXISTYPE=` among velocities,
//! currents and nominal positions; channels of different cycle times come out on the slowest
//! one's instants; a trace with one axis, without an axis of the stated plane, or cut off
//! mid-row is refused in one line naming file (and line); and a trace with the demo's internal
//! readings evaluates to the EIJ of the contract CSV pair it was made from.

mod common;

use std::collections::BTreeMap;

use common::traces::{curve, demo_test, held, sco_header, sco_header_lines, sco_row, Curve};
use common::{one_line_error, run, Scratch};
use eij::axes::Eij;
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{evaluate_tests, SuiteOptions};
use eij::measured::traces::InternalRecording;

/// A 2 mm xy circle at 5 Hz about the centre, mm, at time `t` s.
fn circle(t: f64) -> [f64; 3] {
    let w = 2.0 * std::f64::consts::PI * 5.0;
    [
        2.0 * (w * t).cos(),
        2.0 * (w * t).sin(),
        0.000_7 * (3.0 * w * t).sin(),
    ]
}

/// Writes `trace` as `folder/cnc.sco`, the internal file of a `[[test]]` (with `entry` added)
/// whose external file is an empty R-Test CSV.
fn write(d: &Scratch, folder: &str, trace: &str, entry: &str) {
    d.write(&format!("{folder}/cnc.sco"), trace);
    d.write(
        &format!("{folder}/probe.csv"),
        "t_s,x_ext_mm,y_ext_mm,z_ext_mm\n",
    );
    d.write(
        &format!("{folder}/rtest.toml"),
        format!(
            "radius_mm = 2.0\n[[test]]\ninternal = \"cnc.sco\"\nexternal = \"probe.csv\"\n{entry}"
        ),
    );
}

/// Writes `trace` (see [`write`]) and returns what eij reads from it.
fn read(d: &Scratch, folder: &str, trace: &str, entry: &str) -> InternalRecording {
    write(d, folder, trace, entry);
    let tests = expand_tests(&[d.path(folder)]).unwrap();
    tests[0].read_internal().unwrap().unwrap()
}

/// The error reading `trace` (one line, as the command line prints it).
fn refused(d: &Scratch, folder: &str, trace: &str, entry: &str) -> String {
    write(d, folder, trace, entry);
    let out = common::eij(&["evaluate", &d.s(folder)]);
    one_line_error(&out, &[&d.s(&format!("{folder}/cnc.sco"))])
}

/// Six channels in shuffled columns: velocity, nominal position and current beside the actual
/// positions of X (mm), Y (µm) and Z (inch). What eij reads is exactly the file's numbers times
/// the unit, time the first column in µs.
#[test]
fn the_s_ist_channels_are_read_as_the_file_holds_them() {
    let d = Scratch::new("tnc-read");
    let curves = [
        curve("v ist", "X", "mm/min", 1),
        curve("s ist", "Y", "µm", 5),
        curve("s soll", "X", "mm", 2),
        curve("s ist", "X", "mm", 6),
        curve("I ist", "Z", "A", 3),
        curve("s ist", "Z", "inch", 4),
    ];
    let mut text = sco_header(1000, &curves);
    let n = 40;
    let mut expected = (Vec::new(), [Vec::new(), Vec::new(), Vec::new()]);
    for i in 0..n {
        let t_us = 3000.0 + 1000.0 * i as f64;
        let p = circle(t_us * 1e-6);
        let (y_um, z_in) = (p[1] * 1e3, p[2] / 25.4);
        // columns 1..6: v ist X, s soll X, I ist Z, s ist Z, s ist Y, s ist X
        text.push_str(&sco_row(
            t_us,
            &[
                Some(1234.5),
                Some(p[0] + 0.01),
                Some(3.2),
                Some(z_in),
                Some(y_um),
                Some(p[0]),
            ],
        ));
        expected.0.push(held(t_us) * 1e-6);
        expected.1[0].push(held(p[0]));
        expected.1[1].push(held(y_um) * 1e-3);
        expected.1[2].push(held(z_in) * 25.4);
    }
    let r = read(&d, "six", &text, "");
    assert_eq!(r.t_s, expected.0);
    assert_eq!(r.mm, expected.1);
    assert_eq!(r.absent, [false; 3]);
    let first = sco_header_lines(curves.len()) + 1;
    assert_eq!(r.lines, (first..first + n as u64).collect::<Vec<_>>());
    // Spot check against the numbers as written in the file.
    assert!(text.contains("3.000000000e+003;"));
    assert_eq!(r.t_s[0], 3.0e-3);
}

/// X and Y at 500 µs, Z at 1000 µs (its cells empty between its samples, or held): the time
/// base is Z's instants and every value is the file's.
#[test]
fn channels_of_different_cycle_times_meet_on_the_slowest() {
    let d = Scratch::new("tnc-cycles");
    let mut curves = vec![
        curve("s ist", "X", "mm", 1),
        curve("s ist", "Y", "mm", 2),
        curve("s ist", "Z", "mm", 3),
    ];
    curves.iter_mut().for_each(|c| c.cycle_us = 500);
    curves[2].cycle_us = 1000;
    for held_z in [false, true] {
        let mut text = sco_header(500, &curves);
        let mut expected: (Vec<f64>, [Vec<f64>; 3]) = Default::default();
        let mut z_last = 0.0;
        for i in 0..60 {
            let t_us = 500.0 * i as f64;
            let p = circle(t_us * 1e-6);
            let z = if i % 2 == 0 {
                z_last = p[2];
                Some(p[2])
            } else if held_z {
                Some(z_last)
            } else {
                None
            };
            text.push_str(&sco_row(t_us, &[Some(p[0]), Some(p[1]), z]));
            if i % 2 == 0 {
                expected.0.push(held(t_us) * 1e-6);
                (0..3).for_each(|k| expected.1[k].push(held(p[k])));
            }
        }
        let r = read(&d, &format!("cycles-{held_z}"), &text, "");
        assert_eq!(r.t_s, expected.0, "held {held_z}");
        assert_eq!(r.mm, expected.1, "held {held_z}");
        let first = sco_header_lines(3) + 1;
        assert_eq!(r.lines[1], first + 2);
    }
}

/// Empty cells (no sample) and missing-sample markers in one channel of equal cycle times:
/// those instants are dropped for all axes, never filled in.
#[test]
fn missing_samples_drop_their_instants() {
    let d = Scratch::new("tnc-missing");
    let curves = [curve("s ist", "X", "mm", 1), curve("s ist", "Y", "mm", 2)];
    let mut text = sco_header(1000, &curves);
    let mut kept = Vec::new();
    for i in 0..30 {
        let t_us = 1000.0 * i as f64;
        let p = circle(t_us * 1e-6);
        let x = match i {
            7 => None,
            11 => Some(9.223_372_036_854_776e18),
            _ => Some(p[0]),
        };
        text.push_str(&sco_row(t_us, &[x, Some(p[1])]));
        if i != 7 && i != 11 {
            kept.push(held(t_us) * 1e-6);
        }
    }
    let r = read(&d, "missing", &text, "");
    assert_eq!(r.t_s, kept);
    assert_eq!(r.absent, [false, false, true]);
    assert!(r.mm[2].iter().all(|z| *z == 0.0));
}

/// An X and Y trace of `rows` rows.
fn xy_rows(rows: usize) -> String {
    simple_rows(
        &[curve("s ist", "X", "mm", 1), curve("s ist", "Y", "mm", 2)],
        rows,
    )
}

fn simple_rows(curves: &[Curve], rows: usize) -> String {
    let mut text = sco_header(1000, curves);
    for i in 0..rows {
        let t_us = 1000.0 * i as f64;
        let p = circle(t_us * 1e-6);
        let values: Vec<Option<f64>> = (0..curves.len()).map(|k| Some(p[k % 3])).collect();
        text.push_str(&sco_row(t_us, &values));
    }
    text
}

/// One axis only; two axes but not those of the stated plane; a row cut off; a unit that is
/// no length; two `s ist` channels of one axis: one line each, naming the file (and line).
#[test]
fn malformed_traces_are_refused_in_one_line() {
    let d = Scratch::new("tnc-bad");
    let one = simple_rows(
        &[
            curve("s ist", "X", "mm", 1),
            curve("v ist", "Y", "mm/min", 2),
        ],
        20,
    );
    let line = refused(&d, "one", &one, "");
    assert!(
        line.contains("two axes") && line.contains("X only"),
        "{line}"
    );
    assert!(line.contains("'v ist/Y'"), "{line}");

    let xy = xy_rows(20);
    let line = refused(&d, "plane", &xy, "plane = \"zx\"\n");
    assert!(
        line.contains("plane zx needs the actual position of Z"),
        "{line}"
    );

    let mut cut = xy_rows(20);
    cut.push_str("2.000000000e+004; 1.6180");
    let at = format!("cnc.sco:{}:", sco_header_lines(2) + 21);
    let line = refused(&d, "cut", &cut, "");
    assert!(line.contains(&at) && line.contains("cut off"), "{line}");

    let mut short = xy_rows(5);
    short.push_str("6.000000000e+003; 1.0;\n");
    let line = refused(&d, "short", &short, "");
    assert!(
        line.contains(&format!("cnc.sco:{}:", sco_header_lines(2) + 6)),
        "{line}"
    );

    let velocity = simple_rows(
        &[
            curve("s ist", "X", "mm/min", 1),
            curve("s ist", "Y", "mm", 2),
        ],
        20,
    );
    let line = refused(&d, "unit", &velocity, "");
    assert!(
        line.contains("cnc.sco:11:") && line.contains("no unit of length"),
        "{line}"
    );

    let twice = simple_rows(
        &[
            curve("s ist", "X", "mm", 1),
            curve("s ist", "Y", "mm", 2),
            curve("s ist", "X", "mm", 3),
        ],
        20,
    );
    let line = refused(&d, "twice", &twice, "");
    assert!(
        line.contains("second s ist channel of X") && line.contains("[columns]"),
        "{line}"
    );

    let mut bad = sco_header(
        1000,
        &[curve("s ist", "X", "mm", 1), curve("s ist", "Y", "mm", 2)],
    );
    bad.push_str("0.0; 1.0; abc;\n");
    let line = refused(&d, "nan", &bad, "");
    assert!(
        line.contains("'abc' is not a number")
            && line.contains(&format!("cnc.sco:{}:", sco_header_lines(2) + 1)),
        "{line}"
    );

    // Given as a single R-Test file, a trace is named for what it is.
    d.write("lone/cnc.sco", &one);
    let out = common::eij(&["evaluate", &d.s("lone/cnc.sco")]);
    one_line_error(&out, &["controller trace", "internal"]);
}

/// The demo's xy and zx tests (ccw, 5 m/s²): the internal readings written as a TNCscope export
/// (mm, and once in µm) with the R-Test columns as their own CSV evaluate to the EIJ of the
/// same two files as contract CSVs (the numbers are the same, only written differently).
#[test]
fn a_trace_gives_the_eij_of_the_contract_pair() {
    let d = Scratch::new("tnc-demo");
    let toml = |folder: &str, internal: &str| {
        d.write(
            &format!("{folder}/rtest.toml"),
            format!(
                "radius_mm = 2.0\n[[test]]\ninternal = \"{internal}\"\nexternal = \"probe.csv\"\n"
            ),
        );
    };
    for name in ["pos-a/xy_ccw_5.csv", "pos-a/zx_ccw_5.csv"] {
        let demo = demo_test(name);
        let stem = name.replace(['/', '.'], "_");
        let curves = [
            curve("v ist", "X", "mm/min", 4),
            curve("s ist", "X", "mm", 1),
            curve("s ist", "Y", "µm", 2),
            curve("s ist", "Z", "mm", 3),
        ];
        let mut sco = sco_header(1000, &curves);
        let mut csv = String::from("t_s,x_int_mm,y_int_mm,z_int_mm\n");
        for i in 0..demo.t_s.len() {
            let t_us = (demo.t_s[i] * 1e6).round();
            let y_um = demo.int[1][i] * 1e3;
            sco.push_str(&sco_row(
                t_us,
                &[
                    Some(demo.int[0][i]),
                    Some(y_um),
                    Some(demo.int[2][i]),
                    Some(100.0),
                ],
            ));
            // The contract file holds the very numbers the trace holds.
            csv.push_str(&format!(
                "{},{},{},{}\n",
                held(t_us) * 1e-6,
                held(demo.int[0][i]),
                held(y_um) * 1e-3,
                held(demo.int[2][i])
            ));
        }
        for (folder, file, text) in [("sco", "cnc.sco", &sco), ("csv", "cnc.csv", &csv)] {
            let folder = format!("{folder}-{stem}");
            d.write(&format!("{folder}/{file}"), text);
            d.write(&format!("{folder}/probe.csv"), demo.external_csv());
            toml(&folder, file);
        }
        let eij = |folder: &str| -> BTreeMap<Eij, f64> {
            let tests = expand_tests(&[d.path(&format!("{folder}-{stem}"))]).unwrap();
            let suite = evaluate_tests(&tests, &SuiteOptions::default()).unwrap();
            suite.tests[0].result.eij.value_map()
        };
        let (from_trace, from_csv) = (eij("sco"), eij("csv"));
        assert_eq!(from_trace.len(), 6);
        for (p, v) in &from_csv {
            assert!(
                (from_trace[p] - v).abs() < 1e-9,
                "{name} {p}: trace {} vs contract pair {v}",
                from_trace[p]
            );
        }
        // And the command line agrees.
        let r = run(&["evaluate", &d.s(&format!("sco-{stem}"))]);
        assert!(r.ok, "{}", r.stderr);
    }
}

/// A trace cut at every byte (and with any single byte replaced by a digit, `;` or a line end)
/// is read or refused with an error naming the file, never a panic.
#[test]
fn a_trace_cut_anywhere_never_panics() {
    let d = Scratch::new("tnc-cuts");
    let text = xy_rows(12);
    write(&d, "c", "", "");
    let tests = expand_tests(&[d.path("c")]).unwrap();
    let file = d.path("c/cnc.sco");
    let check = |bytes: &[u8]| {
        std::fs::write(&file, bytes).unwrap();
        if let Err(e) = tests[0].read_internal() {
            let m = e.to_string();
            assert!(m.contains("cnc.sco") && !m.contains('\n'), "{m}");
        }
    };
    let bytes = text.as_bytes();
    for cut in 0..=bytes.len() {
        check(&bytes[..cut]);
    }
    for i in (0..bytes.len()).step_by(3) {
        for b in [b'7', b';', b'\n', b'%'] {
            let mut v = bytes.to_vec();
            v[i] = b;
            check(&v);
        }
    }
}
