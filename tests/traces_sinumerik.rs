//! Siemens Sinumerik Operate traces as the internal recording of a two-system test: XML written
//! here by hand from the published format (`traceData/dataFrame`, `dataSignal` name and
//! description, `rec` with `time` in s and `f1`, `f2`, …). `[columns]` says which signal is which
//! axis; values above 9.2·10¹⁸ are no sample; signals of different cycle times meet on the
//! slowest one's instants (the faster interpolated, checked against the analytic circle); a
//! trace with one mapped axis, without `[columns]`, or cut off is refused in one line; and a
//! trace of the demo's internal readings evaluates to the EIJ of the contract CSV pair.

mod common;

use std::collections::BTreeMap;

use common::traces::{demo_test, sinumerik, sinumerik_header_lines, Signal};
use common::{one_line_error, Scratch};
use eij::axes::Eij;
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{evaluate_tests, SuiteOptions};
use eij::measured::traces::InternalRecording;

const SIGNALS: [Signal; 4] = [
    Signal {
        name: "/Nck/MachineAxis/actFeedRate[u1,1]",
        description: "Actual velocity X1",
    },
    Signal {
        name: "/Nck/MachineAxis/measPos1[u1,2]",
        description: "Position actual value Y1 (64 bit)",
    },
    Signal {
        name: "/Nck/MachineAxis/measPos1[u1,1]",
        description: "Position actual value X1 (64 bit)",
    },
    Signal {
        name: "/Nck/MachineAxis/measPos1[u1,3]",
        description: "Position actual value Z1 (64 bit)",
    },
];

/// X by description, Y by NC path (in µm), Z by description.
const COLUMNS: &str = "[columns]\nx_int_mm = { name = \"Position actual value X1\", unit = \"mm\" }\ny_int_mm = { name = \"/Nck/MachineAxis/measPos1[u1,2]\", unit = \"um\" }\nz_int_mm = \"Position actual value Z1\"\n";

/// A 2 mm xy circle at 5 Hz, mm.
fn circle(t: f64) -> [f64; 3] {
    let w = 2.0 * std::f64::consts::PI * 5.0;
    [
        2.0 * (w * t).cos(),
        2.0 * (w * t).sin(),
        0.000_7 * (3.0 * w * t).sin(),
    ]
}

fn write(d: &Scratch, folder: &str, xml: &str, toml: &str) {
    d.write(&format!("{folder}/trace.xml"), xml);
    d.write(
        &format!("{folder}/probe.csv"),
        "t_s,x_ext_mm,y_ext_mm,z_ext_mm\n",
    );
    d.write(
        &format!("{folder}/rtest.toml"),
        format!("radius_mm = 2.0\n{toml}\n[[test]]\ninternal = \"trace.xml\"\nexternal = \"probe.csv\"\n"),
    );
}

fn read(d: &Scratch, folder: &str, xml: &str, toml: &str) -> InternalRecording {
    write(d, folder, xml, toml);
    let tests = expand_tests(&[d.path(folder)]).unwrap();
    tests[0].read_internal().unwrap().unwrap()
}

fn refused(d: &Scratch, folder: &str, xml: &str, toml: &str) -> String {
    write(d, folder, xml, toml);
    let out = common::eij(&["evaluate", &d.s(folder)]);
    one_line_error(&out, &[&d.s(&format!("{folder}/trace.xml"))])
}

/// Every rec holds all four signals, one holds the missing-sample marker in X: what eij reads
/// is the file's numbers (Y converted from µm) at every other instant.
#[test]
fn the_mapped_signals_are_read_as_the_file_holds_them() {
    let d = Scratch::new("sinumerik-read");
    let mut recs = Vec::new();
    let mut expected: (Vec<f64>, [Vec<f64>; 3], Vec<u64>) = Default::default();
    let first = sinumerik_header_lines(4) + 1;
    for i in 0..50 {
        let t = 0.25 + 0.000_5 * i as f64;
        let p = circle(t);
        let x = if i == 17 {
            "9.2233720368547758e+18".to_string()
        } else {
            format!("{}", p[0])
        };
        recs.push((
            t,
            vec![
                (1, "1500.25".to_string()),
                (2, format!("{}", p[1] * 1e3)),
                (3, x),
                (4, format!("{}", p[2])),
            ],
        ));
        if i != 17 {
            expected.0.push(t);
            expected.1[0].push(p[0]);
            expected.1[1].push(p[1] * 1e3 * 1e-3);
            expected.1[2].push(p[2]);
            expected.2.push(first + i as u64);
        }
    }
    let r = read(&d, "all", &sinumerik(&SIGNALS, &recs), COLUMNS);
    assert_eq!(r.t_s, expected.0);
    assert_eq!(r.mm, expected.1);
    assert_eq!(r.lines, expected.2);
}

/// X every 1 ms, Y every 1.5 ms (recs holding only its own `f`), no Z: the time base is Y's
/// instants, Y as written, X interpolated (four-point Lagrange) to within 1 nm of the circle.
#[test]
fn signals_of_different_cycle_times_meet_on_the_slowest() {
    let d = Scratch::new("sinumerik-cycles");
    let mut recs: Vec<(f64, Vec<(usize, String)>)> = Vec::new();
    for i in 0..300 {
        let t = 1e-3 * i as f64;
        recs.push((t, vec![(3, format!("{}", circle(t)[0]))]));
    }
    let mut y_times = Vec::new();
    for i in 0..190 {
        let t = 4e-4 + 1.5e-3 * i as f64;
        y_times.push(t);
        recs.push((t, vec![(2, format!("{}", circle(t)[1] * 1e3))]));
    }
    recs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let columns = "[columns]\nx_int_mm = \"Position actual value X1\"\ny_int_mm = { name = \"Position actual value Y1\", unit = \"um\" }\n";
    let r = read(&d, "cycles", &sinumerik(&SIGNALS, &recs), columns);
    // X reaches from 0 to 0.299 s: its interpolation needs a sample on either side and one more.
    let inside: Vec<f64> = y_times
        .iter()
        .copied()
        .filter(|t| *t >= 1e-3 && *t <= 0.298)
        .collect();
    assert_eq!(r.t_s, inside);
    assert_eq!(r.absent, [false, false, true]);
    for (i, t) in r.t_s.iter().enumerate() {
        let p = circle(*t);
        assert_eq!(r.mm[1][i], p[1] * 1e3 * 1e-3);
        assert!(
            (r.mm[0][i] - p[0]).abs() < 1e-6,
            "x at {t}: {} vs {}",
            r.mm[0][i],
            p[0]
        );
        assert_eq!(r.mm[2][i], 0.0);
    }
}

fn recs(n: usize) -> Vec<(f64, Vec<(usize, String)>)> {
    (0..n)
        .map(|i| {
            let t = 1e-3 * i as f64;
            let p = circle(t);
            (t, (0..3).map(|k| (k + 2, format!("{}", p[k]))).collect())
        })
        .collect()
}

/// No `[columns]`; one axis mapped; the plane's axis missing; cut off mid-record; a value that is
/// no number; two signals matching one entry; XML that is no trace: one line each.
#[test]
fn malformed_traces_are_refused_in_one_line() {
    let d = Scratch::new("sinumerik-bad");
    let xml = sinumerik(&SIGNALS, &recs(40));
    let line = refused(&d, "unmapped", &xml, "");
    assert!(
        line.contains("[columns]") && line.contains("'Position actual value X1 (64 bit)'"),
        "{line}"
    );

    let line = refused(
        &d,
        "one",
        &xml,
        "[columns]\nx_int_mm = \"Position actual value X1\"\n",
    );
    assert!(
        line.contains("two axes") && line.contains("X only"),
        "{line}"
    );

    let xy = "[columns]\nx_int_mm = \"Position actual value X1\"\ny_int_mm = \"Position actual value Y1\"\n";
    write(&d, "plane", &xml, xy);
    let toml = format!("radius_mm = 2.0\n{xy}\n[[test]]\ninternal = \"trace.xml\"\nexternal = \"probe.csv\"\nplane = \"yz\"\n");
    d.write("plane/rtest.toml", toml);
    let out = common::eij(&["evaluate", &d.s("plane")]);
    one_line_error(
        &out,
        &["trace.xml", "plane yz needs the actual position of Z"],
    );

    let cut_at = xml.match_indices("<rec ").nth(20).unwrap().0 + 30;
    let line = refused(&d, "cut", &xml[..cut_at], COLUMNS);
    let last = xml[..cut_at].trim_end().lines().count();
    assert!(
        line.contains(&format!("trace.xml:{last}:")) && line.contains("cut off"),
        "{line}"
    );

    let bad = xml.replacen("f3=\"", "f3=\"x", 1);
    let line = refused(&d, "nan", &bad, COLUMNS);
    let at = format!("trace.xml:{}:", sinumerik_header_lines(4) + 1);
    assert!(
        line.contains(&at) && line.contains("is not a number"),
        "{line}"
    );

    let same = [
        Signal {
            name: "/Nck/MachineAxis/measPos1[u1,1]",
            description: "Position actual value X1",
        },
        Signal {
            name: "/Nck/MachineAxis/measPos2[u1,1]",
            description: "Position actual value X1",
        },
        Signal {
            name: "/Nck/MachineAxis/measPos1[u1,2]",
            description: "Position actual value Y1",
        },
    ];
    let line = refused(&d, "twice", &sinumerik(&same, &recs(40)), COLUMNS);
    assert!(
        line.contains("two signals match [columns] x_int_mm"),
        "{line}"
    );

    let line = refused(
        &d,
        "other",
        "<?xml version=\"1.0\"?>\n<config><a/></config>\n",
        COLUMNS,
    );
    assert!(line.contains("not a Sinumerik"), "{line}");
}

/// The demo's xy test (ccw, 5 m/s²): the internal readings as a Sinumerik trace (X in mm, Y in
/// µm) with the R-Test columns as their own CSV evaluate to the EIJ of the contract CSV pair.
#[test]
fn a_trace_gives_the_eij_of_the_contract_pair() {
    let d = Scratch::new("sinumerik-demo");
    let demo = demo_test("pos-a/xy_ccw_5.csv");
    let mut recs = Vec::new();
    let mut csv = String::from("t_s,x_int_mm,y_int_mm,z_int_mm\n");
    for i in 0..demo.t_s.len() {
        let y_um = demo.int[1][i] * 1e3;
        recs.push((
            demo.t_s[i],
            vec![
                (1, "0.0".to_string()),
                (2, format!("{y_um}")),
                (3, format!("{}", demo.int[0][i])),
                (4, format!("{}", demo.int[2][i])),
            ],
        ));
        csv.push_str(&format!(
            "{},{},{},{}\n",
            demo.t_s[i],
            demo.int[0][i],
            y_um * 1e-3,
            demo.int[2][i]
        ));
    }
    let entry = |internal: &str| {
        format!("radius_mm = 2.0\n{COLUMNS}\n[[test]]\ninternal = \"{internal}\"\nexternal = \"probe.csv\"\n")
    };
    d.write("xml/trace.xml", sinumerik(&SIGNALS, &recs));
    d.write("xml/probe.csv", demo.external_csv());
    d.write("xml/rtest.toml", entry("trace.xml"));
    d.write("csv/cnc.csv", csv);
    d.write("csv/probe.csv", demo.external_csv());
    d.write(
        "csv/rtest.toml",
        "radius_mm = 2.0\n[[test]]\ninternal = \"cnc.csv\"\nexternal = \"probe.csv\"\n",
    );
    let eij = |folder: &str| -> BTreeMap<Eij, f64> {
        let tests = expand_tests(&[d.path(folder)]).unwrap();
        let suite = evaluate_tests(&tests, &SuiteOptions::default()).unwrap();
        suite.tests[0].result.eij.value_map()
    };
    let (from_trace, from_csv) = (eij("xml"), eij("csv"));
    assert_eq!(from_trace.len(), 6);
    for (p, v) in &from_csv {
        assert!(
            (from_trace[p] - v).abs() < 1e-9,
            "{p}: trace {} vs contract pair {v}",
            from_trace[p]
        );
    }
}

/// A trace cut at every byte (and with any single byte replaced by a quote, `<` or a digit) is
/// read or refused with an error naming the file, never a panic.
#[test]
fn a_trace_cut_anywhere_never_panics() {
    let d = Scratch::new("sinumerik-cuts");
    let xml = sinumerik(&SIGNALS, &recs(8));
    write(&d, "c", "", COLUMNS);
    let tests = expand_tests(&[d.path("c")]).unwrap();
    let file = d.path("c/trace.xml");
    let check = |bytes: &[u8]| {
        std::fs::write(&file, bytes).unwrap();
        if let Err(e) = tests[0].read_internal() {
            let m = e.to_string();
            assert!(m.contains("trace.xml") && !m.contains('\n'), "{m}");
        }
    };
    let bytes = xml.as_bytes();
    for cut in 0..=bytes.len() {
        check(&bytes[..cut]);
    }
    for i in (0..bytes.len()).step_by(3) {
        for b in [b'"', b'<', b'9'] {
            let mut v = bytes.to_vec();
            v[i] = b;
            check(&v);
        }
    }
}
