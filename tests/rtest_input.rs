//! Library-level input validation: the in-memory constructor, the reader's error values and
//! the EIJ table reader/writer.

mod common;

use common::synth::Synth;
use common::Scratch;
use eij::axes::{Axis, Direction, Eij, Plane};
use eij::measured::table::{self, EijRow};
use eij::rtest::{evaluate, CircleSeries, EvalOptions, Line, RtestError};

fn cols(n: usize) -> (Vec<f64>, [Vec<f64>; 3], [Vec<f64>; 3]) {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
    let z = || vec![0.0; n];
    (t, [z(), z(), z()], [z(), z(), z()])
}

#[test]
fn in_memory_series_is_validated_like_a_file() {
    let (t, int, mut ext) = cols(5);
    ext[2][3] = f64::NAN;
    let err = CircleSeries::new("sim".into(), t, int, ext).unwrap_err();
    assert_eq!(
        err.to_string(),
        "sim: row 4: column z_ext_mm: 'NaN' is not a finite number"
    );

    let (mut t, int, ext) = cols(5);
    t[2] = t[1];
    let err = CircleSeries::new("sim".into(), t, int, ext).unwrap_err();
    match &err {
        RtestError::TimeNotIncreasing { at, .. } => assert_eq!(at.line, Some(Line::Row(3))),
        e => panic!("{e}"),
    }

    let (t, mut int, ext) = cols(5);
    int[1].pop();
    let err = CircleSeries::new("sim".into(), t, int, ext).unwrap_err();
    assert_eq!(
        err.to_string(),
        "sim: column y_int_mm has 4 values, t_s has 5"
    );

    let (t, int, ext) = cols(1);
    let err = CircleSeries::new("sim".into(), t, int, ext).unwrap_err();
    assert!(
        matches!(err, RtestError::TooFewRows { rows: 1, .. }),
        "{err}"
    );
}

#[test]
fn in_memory_and_file_series_evaluate_alike() {
    let scratch = Scratch::new("input-alike");
    let d = scratch.0.clone();
    let syn = Synth::new(Plane::Yz, false, 3.0);
    let p = d.join("yz.csv");
    syn.write_csv(&p);
    let from_file = CircleSeries::read_csv(&p).unwrap();
    let in_memory = syn.series();
    let (rf, rm) = (
        evaluate(&from_file, &EvalOptions::default()).unwrap(),
        evaluate(&in_memory, &EvalOptions::default()).unwrap(),
    );
    assert_eq!(rf.samples_used, rm.samples_used);
    for p in Plane::Yz.parameters() {
        // The CSV holds the shortest round-trip representation: identical numbers.
        assert_eq!(rf.eij[&p].value, rm.eij[&p].value, "{p}");
    }
    assert_eq!(from_file.at_row(0).line, Some(Line::File(2)));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn plane_override_and_motion_checks() {
    let s = Synth::new(Plane::Xy, true, 5.0).series();
    let opts = EvalOptions {
        plane: Some(Plane::Yz),
        ..Default::default()
    };
    let err = evaluate(&s, &opts).unwrap_err();
    assert!(matches!(err, RtestError::NoMotion { .. }), "{err}");
    assert!(err.to_string().contains("z_int_mm"), "{err}");

    let (t, int, ext) = cols(100);
    let err = CircleSeries::new("still".into(), t, int, ext)
        .and_then(|s| evaluate(&s, &EvalOptions::default()))
        .unwrap_err();
    assert!(matches!(err, RtestError::NoMotion { .. }), "{err}");

    // A helix-like motion in all three axes: no plane to infer.
    let (t, mut int, mut ext) = cols(2000);
    for i in 0..2000 {
        let ph = i as f64 * 0.05;
        int[0][i] = 2.0 * ph.cos();
        int[1][i] = 2.0 * ph.sin();
        int[2][i] = 1.5 * (ph * 0.5).sin();
        for a in 0..3 {
            ext[a][i] = int[a][i];
        }
    }
    let err = CircleSeries::new("helix".into(), t, int, ext)
        .and_then(|s| evaluate(&s, &EvalOptions::default()))
        .unwrap_err();
    assert!(matches!(err, RtestError::AmbiguousPlane { .. }), "{err}");
}

#[test]
fn eij_table_round_trips_and_is_strict() {
    let scratch = Scratch::new("input-table");
    let d = scratch.0.clone();
    let rows = vec![
        EijRow {
            plane: Plane::Zx,
            direction: Direction::Ccw,
            accel_m_s2: 5.0,
            parameter: Eij::new(Axis::X, Axis::Z),
            value: -1.55,
            std_err: None,
            radius_mm: None,
            position_mm: None,
        },
        EijRow {
            plane: Plane::Xy,
            direction: Direction::Cw,
            accel_m_s2: 2.5,
            parameter: Eij::new(Axis::Z, Axis::Y),
            value: 0.1 + 0.2,
            std_err: Some(0.0123),
            radius_mm: None,
            position_mm: None,
        },
    ];
    let p = d.join("t.csv");
    table::write(&p, &rows, &[]).unwrap();
    assert_eq!(table::read(&p).unwrap(), rows);
    assert!(std::fs::read_to_string(&p).unwrap().starts_with(
        "plane,direction,accel_m_s2,parameter,value_um_s2_per_m,std_err_um_s2_per_m\n"
    ));

    let head = "plane,direction,accel_m_s2,parameter,value_um_s2_per_m";
    let cases = [
        (
            format!("{head}\nzx,ccw,4.5,EXZ,-1.55\nzx,ccw,4.5,EXY,1\n"),
            ":3: column parameter: EXY is not a parameter of plane zx",
        ),
        (
            format!("{head}\nzq,ccw,4.5,EXZ,-1.55\n"),
            ":2: column plane: unknown plane 'zq'",
        ),
        (
            format!("{head}\nzx,up,4.5,EXZ,-1.55\n"),
            ":2: column direction: unknown direction 'up'",
        ),
        (
            format!("{head}\nzx,ccw,-4.5,EXZ,-1.55\n"),
            ":2: column accel_m_s2: acceleration -4.5 must be positive",
        ),
        (
            format!("{head}\nzx,ccw,4.5,EXZ,x\n"),
            ":2: column value_um_s2_per_m: 'x' is not a number",
        ),
        (
            format!("{head},std_err_um_s2_per_m\nzx,ccw,4.5,EXZ,1,-2\n"),
            ":2: column std_err_um_s2_per_m: standard error -2 must be positive",
        ),
        (
            format!("{head},std_err_um_s2_per_m\nzx,ccw,4.5,EXZ,1,0\n"),
            ":2: column std_err_um_s2_per_m: standard error 0 must be positive (a zero would give the value infinite weight",
        ),
        (
            format!("{head}\nzx,ccw,4.5,EXZ,-1.55\nzx,cw,4.5,EXZ,-1.5\nzx,ccw,4.5,EXZ,-1.6\n"),
            ":4: column parameter: EXZ of zx ccw at 4.5 m/s² given twice (first on line 2)",
        ),
        (
            format!("{head},note\nzx,ccw,4.5,EXZ,1,a\n"),
            ":1: unknown column 'note'",
        ),
        (
            "plane,direction,parameter,value_um_s2_per_m\n".to_string(),
            ":1: missing column(s) accel_m_s2",
        ),
        (format!("{head}\n"), ": 0 data row(s), at least 1 needed"),
    ];
    for (text, needle) in cases {
        std::fs::write(&p, text).unwrap();
        let err = table::read(&p).unwrap_err().to_string();
        assert_eq!(err.lines().count(), 1);
        assert!(err.contains(&format!("{}{needle}", p.display())), "{err}");
    }
    std::fs::write(
        &p,
        format!("{head},std_err_um_s2_per_m\nzx,ccw,4.5,EXZ,-1.55,\n"),
    )
    .unwrap();
    assert_eq!(table::read(&p).unwrap()[0].std_err, None);
    // A spreadsheet's `;` table with decimal commas and a comment reads as the `,` one.
    std::fs::write(
        &p,
        "# typed from the paper\nplane;direction;accel_m_s2;parameter;value_um_s2_per_m;std_err_um_s2_per_m\nzx;ccw;4,5;EXZ;-1,55;0,05\n",
    )
    .unwrap();
    let row = &table::read(&p).unwrap()[0];
    assert_eq!(
        (row.accel_m_s2, row.value, row.std_err),
        (4.5, -1.55, Some(0.05))
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// The shipped table of the paper's values reads back with the documented single row.
#[test]
fn paper_table_is_a_valid_eij_table() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("measurements/paper/eij_table.csv");
    let rows = table::read(&path).unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0].parameter, Eij::new(Axis::X, Axis::Z));
    assert_eq!(rows[0].value, -1.55);
}

/// Spreadsheet habits are tolerated where harmless: a byte-order mark, CRLF line ends, blank
/// lines, spaces around cells; line numbers still count every physical line.
#[test]
fn byte_order_mark_crlf_and_blank_lines() {
    let scratch = Scratch::new("input-bom");
    let d = scratch.0.clone();
    let p = d.join("bom.csv");
    let text = "\u{feff}t_s, x_int_mm,y_int_mm,z_int_mm,x_ext_mm,y_ext_mm,z_ext_mm\r\n\
                0,2,0,0,2,0,0\r\n\r\n\n0.001,2,0,0,2,0,0\r\n0.0005,2,0,0,2,0,0\r\n";
    std::fs::write(&p, text).unwrap();
    let err = CircleSeries::read_csv(&p).unwrap_err().to_string();
    assert_eq!(
        err,
        format!(
            "{}:6: t_s = 0.0005 does not increase (previous row 0.001)",
            p.display()
        )
    );
    std::fs::write(&p, text.replace("0.0005,2,0,0,2,0,0", "0.0005,2")).unwrap();
    let err = CircleSeries::read_csv(&p).unwrap_err().to_string();
    assert_eq!(
        err,
        format!("{}:6: 2 field(s), the header has 7", p.display())
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// No input panics: random and degenerate in-memory series (jumps, points at the centre,
/// reversals, tiny and huge values) evaluate to a result or an error.
#[test]
fn random_series_never_panic() {
    let mut rng = common::synth::Rng::new(42);
    let (mut evaluated, mut succeeded) = (0, 0);
    for case in 0..400 {
        let n = 2 + (rng.gauss().abs() * 1500.0) as usize;
        let step = [0.05, 0.2, 0.01][case % 3];
        let scale = [1e-9, 1e-3, 1.0, 2.0, 40.0, 1e6][case % 6];
        let mut t = Vec::with_capacity(n);
        let mut acc = 0.0;
        for _ in 0..n {
            acc += 1e-3
                * if case % 5 == 0 {
                    1.0 + rng.gauss().abs()
                } else {
                    1.0
                };
            t.push(acc);
        }
        let mut col = |circle: bool, sin: bool| -> Vec<f64> {
            (0..n)
                .map(|i| {
                    let ph = i as f64 * step * if case % 4 == 0 { -1.0 } else { 1.0 };
                    let base = if !circle {
                        0.0
                    } else if sin {
                        2.0 * ph.sin()
                    } else {
                        2.0 * ph.cos()
                    };
                    let jump = if case % 7 == 0 && i == n / 2 {
                        5.0
                    } else {
                        0.0
                    };
                    base + jump + scale * 1e-5 * rng.gauss()
                })
                .collect()
        };
        let circle = case % 3 != 0;
        let int = [col(circle, false), col(circle, true), col(false, false)];
        let ext = [
            int[0].iter().map(|v| v + 1e-3 * rng.gauss()).collect(),
            int[1].clone(),
            int[2].iter().map(|v| v + scale * 1e-4).collect(),
        ];
        if let Ok(s) = CircleSeries::new(format!("case {case}"), t, int, ext) {
            evaluated += 1;
            for opts in [
                EvalOptions::default(),
                EvalOptions {
                    plane: Some(Plane::Zx),
                    radius_mm: Some(2.0),
                },
            ] {
                match evaluate(&s, &opts) {
                    Ok(_) => succeeded += 1,
                    Err(e) => {
                        assert!(e.to_string().starts_with(&format!("case {case}")), "{e}")
                    }
                }
            }
            let _ = eij::rtest::evaluate_pooled(&[&s, &s], &EvalOptions::default());
        }
    }
    // The cases reach the fits, not only the input checks.
    assert!(
        evaluated > 300 && succeeded >= 20,
        "{evaluated} {succeeded}"
    );
}
