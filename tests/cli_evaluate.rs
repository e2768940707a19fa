//! `eij evaluate` end to end: the binary on good and bad files.

mod common;

use std::path::{Path, PathBuf};

use common::synth::{csv_text, Synth};
use common::{eij, one_line_error, run, Scratch};
use eij::axes::Plane;
use eij::measured::table;

/// Non-zero exit, exactly one line on stderr naming `file` and every one of `needles`, no panic.
fn assert_error(args: &[&str], file: &Path, needles: &[&str]) {
    let out = eij(args);
    assert!(
        out.stdout.is_empty(),
        "stdout: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    let line = one_line_error(&out, needles);
    assert!(line.contains(&file.display().to_string()), "{line}");
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const HEADER: &str = "t_s,x_int_mm,y_int_mm,z_int_mm,x_ext_mm,y_ext_mm,z_ext_mm";

#[test]
fn malformed_files_name_file_line_and_column() {
    let scratch = Scratch::new("cli-malformed");
    let d = scratch.0.clone();
    let rows = "0,2,0,0,2.001,0,0\n0.001,1.9,0.6,0,1.9,0.6,0\n0.002,1.8,0.9,0,1.8,0.9,0\n";
    let cases: Vec<(&str, String, Vec<String>)> = vec![
        (
            "missing.csv",
            format!(
                "t_s,x_int_mm,y_int_mm,z_int_mm,x_ext_mm,y_ext_mm\n{}",
                "0,1,2,3,4,5\n"
            ),
            vec![":1: missing column(s) z_ext_mm".into()],
        ),
        (
            "duplicate.csv",
            format!("{HEADER},x_int_mm\n{rows}"),
            vec![":1: duplicate column 'x_int_mm'".into()],
        ),
        (
            "nan.csv",
            format!("{HEADER}\n0,2,0,0,2,0,0\n0.001,2,0,0,2,NaN,0\n"),
            vec![":3: column y_ext_mm: 'NaN' is not a finite number".into()],
        ),
        (
            "inf.csv",
            format!("{HEADER}\n0,2,0,0,2,0,0\n0.001,inf,0,0,2,0,0\n"),
            vec![":3: column x_int_mm: 'inf' is not a finite number".into()],
        ),
        (
            "text.csv",
            format!("{HEADER}\n0,2,0,0,2,0,0\n0.001,2,0,0,2,0,0\n0.002,2,0,0,2,0,abc\n"),
            vec![":4: column z_ext_mm: 'abc' is not a number".into()],
        ),
        (
            "short_row.csv",
            format!("{HEADER}\n0,2,0,0,2,0,0\n0.001,2,0\n"),
            vec![":3: 3 field(s), the header has 7".into()],
        ),
        ("empty.csv", String::new(), vec![": empty file".into()]),
        (
            "header_only.csv",
            format!("{HEADER}\n"),
            vec![": 0 data row(s), at least 2 needed".into()],
        ),
        (
            "backwards.csv",
            format!("{HEADER}\n0,2,0,0,2,0,0\n0.002,2,0,0,2,0,0\n0.001,2,0,0,2,0,0\n"),
            vec![":4: t_s = 0.001 does not increase".into()],
        ),
    ];
    for (name, text, needles) in cases {
        let p = write(&d, name, &text);
        let needles: Vec<String> = needles
            .iter()
            .map(|n| {
                if n.starts_with(':') {
                    format!("{}{n}", p.display())
                } else {
                    n.clone()
                }
            })
            .collect();
        let needles: Vec<&str> = needles.iter().map(String::as_str).collect();
        assert_error(&["evaluate", p.to_str().unwrap()], &p, &needles);
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn implausible_data_is_refused() {
    let scratch = Scratch::new("cli-implausible");
    let d = scratch.0.clone();
    // Less than one revolution in all.
    let mut s = Synth::new(Plane::Xy, true, 5.0);
    s.steady_revs = 0.3;
    s.ramp_revs = 0.2;
    let p = d.join("short.csv");
    s.write_csv(&p);
    assert_error(&["evaluate", p.to_str().unwrap()], &p, &["revolution"]);
    // Revolutions, but less than one of them steady.
    s.steady_revs = 0.6;
    s.ramp_revs = 1.0;
    s.write_csv(&p);
    assert_error(
        &["evaluate", p.to_str().unwrap()],
        &p,
        &["steady revolution(s), at least one whole steady revolution needed"],
    );
    // Too coarse sampling.
    let mut s = Synth::new(Plane::Xy, true, 10.0);
    s.sample_hz = 300.0;
    let p = d.join("coarse.csv");
    s.write_csv(&p);
    assert_error(
        &["evaluate", p.to_str().unwrap()],
        &p,
        &["samples per revolution"],
    );
    // Radius far from the set radius.
    let p = d.join("radius.csv");
    Synth::new(Plane::Zx, false, 5.0).write_csv(&p);
    assert_error(
        &["evaluate", p.to_str().unwrap(), "--radius-mm", "3"],
        &p,
        &["mean internal radius 2.0", "set radius 3 mm"],
    );
    // Beyond the ±3 mm R-Test range at one row (line = row + 2).
    let (t, int, mut ext) = Synth::new(Plane::Zx, false, 5.0).columns();
    ext[1][100] += 4.0;
    let p = write(&d, "range.csv", &csv_text(&t, &int, &ext));
    assert_error(
        &["evaluate", p.to_str().unwrap()],
        &p,
        &[
            &format!("{}:102: column y_ext_mm: deviation", p.display()),
            "beyond the R-Test range ±3 mm",
        ],
    );
    let r = run(&["evaluate", p.to_str().unwrap()]);
    assert!(
        !r.stderr.contains("µm"),
        "no µm hint for a single outlier: {}",
        r.stderr
    );
    // µm in the in-plane external columns.
    let (t, int, mut ext) = Synth::new(Plane::Xy, true, 5.0).columns();
    for v in ext.iter_mut().take(2) {
        v.iter_mut().for_each(|x| *x *= 1000.0);
    }
    let p = write(&d, "um_ext.csv", &csv_text(&t, &int, &ext));
    assert_error(
        &["evaluate", p.to_str().unwrap()],
        &p,
        &["column x_ext_mm", "values look like µm, expected mm"],
    );
    // µm everywhere: an implausibly large circle.
    let (t, mut int, mut ext) = Synth::new(Plane::Xy, true, 5.0).columns();
    for v in int.iter_mut().chain(ext.iter_mut()) {
        v.iter_mut().for_each(|x| *x *= 1000.0);
    }
    let p = write(&d, "um_all.csv", &csv_text(&t, &int, &ext));
    assert_error(
        &["evaluate", p.to_str().unwrap()],
        &p,
        &[
            "implausible for an R-Test circle",
            "values look like µm, expected mm",
        ],
    );
    // µm in the normal axis' external column: out of range, with the hint.
    let (t, int, mut ext) = Synth::new(Plane::Xy, true, 5.0).columns();
    ext[2].iter_mut().for_each(|x| *x = *x * 1000.0 + 4.0);
    let p = write(&d, "um_normal.csv", &csv_text(&t, &int, &ext));
    assert_error(
        &["evaluate", p.to_str().unwrap()],
        &p,
        &[":2: column z_ext_mm", "values look like µm, expected mm"],
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn folders_and_missing_files_are_named() {
    let scratch = Scratch::new("cli-paths");
    let d = scratch.0.clone();
    assert_error(
        &["evaluate", d.to_str().unwrap()],
        &d,
        &["folder holds no .csv files"],
    );
    let p = d.join("nope.csv");
    assert_error(&["evaluate", p.to_str().unwrap()], &p, &["file not found"]);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn json_output_follows_the_contract() {
    let scratch = Scratch::new("cli-json");
    let d = scratch.0.clone();
    let syn = Synth::new(Plane::Zx, true, 5.0);
    let p = d.join("zx_ccw_5.csv");
    syn.write_csv(&p);
    let out = d.join("eij.csv");
    let r = run(&[
        "evaluate",
        p.to_str().unwrap(),
        "--json",
        "--csv-out",
        out.to_str().unwrap(),
    ]);
    assert!(r.ok, "{}", r.stderr);
    // No set radius anywhere: said on standard error and in the JSON; then what was written.
    assert_eq!(r.stderr.lines().count(), 2, "{}", r.stderr);
    assert!(
        r.stderr
            .ends_with(&format!("eij: wrote {}\n", out.display())),
        "{}",
        r.stderr
    );
    assert!(r.stderr.contains("no set radius given"), "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let top: Vec<&String> = v.as_object().unwrap().keys().collect();
    assert_eq!(top, ["bidirectional", "clocks", "tests", "warnings"]);
    let tests = v["tests"].as_array().unwrap();
    assert_eq!(tests.len(), 1);
    let t = &tests[0];
    for key in [
        "file",
        "plane",
        "direction",
        "radius_mm",
        "accel_m_s2",
        "freq_hz",
        "eij_um_s2_per_m",
        "std_err_um_s2_per_m",
        "rms_residual_um",
    ] {
        assert!(t.get(key).is_some(), "missing key {key}");
    }
    assert_eq!(t["file"], p.to_str().unwrap());
    assert_eq!(t["plane"], "zx");
    assert_eq!(t["direction"], "ccw");
    assert!((t["radius_mm"].as_f64().unwrap() - 2.0).abs() < 1e-3);
    assert!((t["accel_m_s2"].as_f64().unwrap() - 5.0).abs() < 5e-3);
    let f = (5.0f64 / 0.002).sqrt() / (2.0 * std::f64::consts::PI);
    assert!((t["freq_hz"].as_f64().unwrap() - f).abs() < 1e-3 * f);
    let names = ["EZZ", "EXX", "EXZ", "EZX", "EYZ", "EYX"];
    for map in ["eij_um_s2_per_m", "std_err_um_s2_per_m"] {
        let mut keys: Vec<&str> = t[map]
            .as_object()
            .unwrap()
            .keys()
            .map(|k| k.as_str())
            .collect();
        keys.sort();
        let mut want = names.to_vec();
        want.sort();
        assert_eq!(keys, want, "{map}");
    }
    for (p, truth) in syn.truth() {
        let got = t["eij_um_s2_per_m"][p.name()].as_f64().unwrap();
        let se = t["std_err_um_s2_per_m"][p.name()].as_f64().unwrap();
        assert!(
            ((got - truth) / se).abs() < 3.0,
            "{p}: {got} ± {se} vs {truth}"
        );
    }
    assert_eq!(t["radius_source"], "internal-mean");
    let warnings = t["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0]
        .as_str()
        .unwrap()
        .contains("no set radius given"));

    // The EIJ table written alongside holds the same six values.
    let rows = table::read(&out).unwrap();
    assert_eq!(rows.len(), 6);
    for row in rows {
        assert_eq!(row.plane, Plane::Zx);
        let json = t["eij_um_s2_per_m"][row.parameter.name()].as_f64().unwrap();
        assert_eq!(row.value, json);
        assert!(row.std_err.is_some());
    }

    // The same run again prints the same bytes.
    let again = run(&["evaluate", p.to_str().unwrap(), "--json"]);
    assert_eq!(again.stdout, r.stdout);

    // Never overwrite an input.
    let before = std::fs::read(&p).unwrap();
    assert_error(
        &[
            "evaluate",
            p.to_str().unwrap(),
            "--csv-out",
            p.to_str().unwrap(),
        ],
        &p,
        &["refusing to overwrite an input file"],
    );
    assert_eq!(std::fs::read(&p).unwrap(), before);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn table_and_pooled_output() {
    let scratch = Scratch::new("cli-pooled");
    let d = scratch.0.clone();
    let mut files = Vec::new();
    for (accel, ccw) in [(2.0, true), (10.0, false)] {
        let p = d.join(format!("xy_{accel}.csv"));
        Synth::new(Plane::Xy, ccw, accel).write_csv(&p);
        files.push(p.to_str().unwrap().to_string());
    }
    let mut args = vec!["evaluate"];
    args.extend(files.iter().map(String::as_str));
    let r = run(&args);
    assert!(r.ok, "{}", r.stderr);
    for f in &files {
        assert!(r.stdout.contains(f.as_str()));
    }
    assert!(r.stdout.contains("EXY") && r.stdout.contains("rms residual"));
    args.extend(["--pooled", "--json"]);
    let r = run(&args);
    assert!(r.ok, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert_eq!(v["tests"].as_array().unwrap().len(), 2);
    let pooled = &v["pooled"][0];
    assert_eq!(pooled["plane"], "xy");
    assert_eq!(pooled["eij_um_s2_per_m"].as_object().unwrap().len(), 6);
    assert_eq!(pooled["geometric_um_per_mm"].as_object().unwrap().len(), 6);
    let _ = std::fs::remove_dir_all(&d);
}

/// A folder of the demo evaluates at its `rtest.toml` radius (`radius_source`), with the ISO
/// 230-4 figures of both paths and the cw/ccw pair's G(b); and the measured EIJ that `eij
/// identify` fits equal `eij evaluate`'s for the same files to 1e-6 µm·s²/m, its report naming
/// each test's position and frequency as evaluate does (issue 11: one normalisation, at the
/// set acceleration).
#[test]
fn folders_evaluate_at_the_set_radius_as_identify_does() {
    let s = Scratch::new("cli-folder-identify");
    let demo = common::root().join("measurements/demo-vmc/pos-a");
    std::fs::create_dir_all(s.path("m")).unwrap();
    for f in ["rtest.toml", "zx_cw_5.csv", "zx_ccw_5.csv", "zx_ccw_8.csv"] {
        std::fs::copy(demo.join(f), s.path(&format!("m/{f}"))).unwrap();
    }
    let r = run(&["evaluate", &s.s("m"), "--json"]);
    assert!(r.ok, "{}", r.stderr);
    assert!(r.stderr.is_empty(), "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let tests = v["tests"].as_array().unwrap();
    assert_eq!(tests.len(), 3);
    for t in tests {
        assert_eq!(t["radius_source"], "rtest.toml");
        assert_eq!(t["radius_mm"], 2.0);
        assert_eq!(t["position_mm"], serde_json::json!([150.0, -100.0, 0.0]));
        let g = &t["circular_deviation_um"];
        let (gi, ge) = (
            g["internal"].as_f64().unwrap(),
            g["external"].as_f64().unwrap(),
        );
        assert!(gi > 0.0 && ge > gi, "{g}");
        let iso = &t["iso230_4"]["external"];
        let span = iso["radial_deviation_max_um"].as_f64().unwrap()
            - iso["radial_deviation_min_um"].as_f64().unwrap();
        assert!((span - ge).abs() < 1e-9, "F max − F min = G");
    }
    let pairs = v["bidirectional"].as_array().unwrap();
    assert_eq!(pairs.len(), 1, "{pairs:?}");
    assert!(pairs[0]["files"][0]
        .as_str()
        .unwrap()
        .ends_with("zx_cw_5.csv"));

    let out = common::eij(&[
        "identify",
        "--quiet",
        "--machine",
        "machines/demo-vmc.toml",
        "--measured",
        &s.s("m"),
        "--param",
        "z.guideway_normal",
        "--out",
        &s.s("id.toml"),
        "--report",
        &s.s("id.json"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.path("id.json")).unwrap()).unwrap();
    let measured = report["tests"].as_array().unwrap();
    assert_eq!(measured.len(), 3);
    for (m, t) in measured.iter().zip(tests) {
        assert_eq!(m["accel_m_s2"], t["accel_m_s2"]);
        assert_eq!(m["position_mm"], t["position_mm"]);
        let (fi, fe) = (
            m["freq_hz"].as_f64().unwrap(),
            t["freq_hz"].as_f64().unwrap(),
        );
        assert!((fi - fe).abs() < 1e-9 * fe, "freq_hz {fi} vs {fe}");
        for (p, value) in t["eij_um_s2_per_m"].as_object().unwrap() {
            let id = m["measured"][p].as_f64().unwrap();
            assert!(
                (id - value.as_f64().unwrap()).abs() < 1e-6,
                "{p}: identify {id} vs evaluate {value}"
            );
        }
    }
}

/// What real files get wrong is refused with one line naming the file and the column: time in
/// ms under a seconds header (with the unit that would fit), a dead probe (external columns all
/// zero), a constant external column, a header eij cannot use (shown with its separator), and
/// rtest.toml mistakes in `[columns]` and `[[test]]`.
#[test]
fn wrong_units_dead_probes_and_bad_layouts_are_refused() {
    let s = Scratch::new("cli-units-probe");
    let (t, int, ext) = Synth::new(Plane::Zx, true, 5.0).columns();
    let t_ms: Vec<f64> = t.iter().map(|v| v * 1e3).collect();
    let p = s.write("ms.csv", csv_text(&t_ms, &int, &ext));
    let line = one_line_error(
        &eij(&["evaluate", &p, "--radius-mm", "2"]),
        &[
            &p,
            "column t_s",
            "implausible",
            "ms read as s",
            "5.000 m/s²",
        ],
    );
    assert!(!line.contains("µm"), "{line}");

    let zeros = [vec![0.0; t.len()], vec![0.0; t.len()], vec![0.0; t.len()]];
    let p = s.write("dead.csv", csv_text(&t, &int, &zeros));
    one_line_error(
        &eij(&["evaluate", &p]),
        &[
            &p,
            "column z_ext_mm",
            "does not follow the circle",
            "dead or unconnected",
        ],
    );
    let mut stuck = ext.clone();
    stuck[1] = vec![0.25; t.len()];
    let p = s.write("stuck.csv", csv_text(&t, &int, &stuck));
    one_line_error(
        &eij(&["evaluate", &p]),
        &[&p, "column y_ext_mm", "constant (0.25) over the whole file"],
    );

    let p = s.write(
        "header.csv",
        "# probe export\nTime;X;Y;Z;XR;YR;ZR\n0;0;0;2;0;0;2\n",
    );
    one_line_error(
        &eij(&["evaluate", &p]),
        &[
            &format!("{p}:2: missing column(s) t_s, x_int_mm"),
            "header read: 'Time;X;Y;Z;XR;YR;ZR' separated by ';'",
        ],
    );
    // The same file with its columns mapped is no longer refused for its header.
    s.write(
        "mapped/rtest.toml",
        "[columns]\nt_s = \"Time\"\nx_int_mm = \"X\"\ny_int_mm = \"Y\"\nz_int_mm = { name = \"Z\", unit = \"mm\" }\nx_ext_mm = \"XR\"\ny_ext_mm = \"YR\"\nz_ext_mm = \"ZR\"\n",
    );
    s.write("mapped/a.csv", std::fs::read(&p).unwrap());
    let line = one_line_error(&eij(&["evaluate", &s.s("mapped")]), &["a.csv"]);
    assert!(!line.contains("missing column"), "{line}");

    let cases = [
        (
            "[columns]\nt_sec = \"Time\"\n",
            "rtest.toml: columns.t_sec: not a contract column (expected one of t_s, x_int_mm",
        ),
        (
            "[columns]\nt_s = { name = \"Time\", unit = \"mm\" }\n",
            "rtest.toml: columns.t_s.unit: 'mm' is no unit of this column (expected s, ms or us)",
        ),
        (
            "[[test]]\nfile = \"nope.csv\"\n",
            "rtest.toml: [[test]] #1 file:",
        ),
        (
            "[[test]]\nfile = \"a.csv\"\ninternal = \"a.csv\"\n",
            "rtest.toml: [[test]] #1 file: give either file or internal and external, not both",
        ),
        (
            "[[test]]\ninternal = \"a.csv\"\n",
            "rtest.toml: [[test]] #1 external: missing: internal needs its external file",
        ),
        (
            "[[test]]\nfile = \"a.csv\"\ndirection = \"left\"\n",
            "rtest.toml: [[test]] #1 direction: unknown direction 'left'",
        ),
    ];
    for (toml, needle) in cases {
        s.write("bad/rtest.toml", toml);
        s.write("bad/a.csv", csv_text(&t, &int, &ext));
        one_line_error(&eij(&["evaluate", &s.s("bad")]), &[needle]);
    }
}

/// `[[test]]` conditions reach the output: a note, and warnings where the stated direction or
/// feed disagree with the data; no radius anywhere is said as `internal-mean`.
#[test]
fn test_entries_state_conditions_that_are_checked() {
    let s = Scratch::new("cli-test-entries");
    // The steady speed: r ω = 2 mm · 50 rad/s = 6000 mm/min.
    s.write(
        "m/rtest.toml",
        "radius_mm = 2.0\n[[test]]\nfile = \"zx.csv\"\ndirection = \"cw\"\nfeed_mm_min = 9000\nnote = \"warm\"\n",
    );
    Synth::new(Plane::Zx, true, 5.0).write_csv(&s.path("m/zx.csv"));
    let r = run(&["evaluate", &s.s("m"), "--json"]);
    assert!(r.ok, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let t = &v["tests"][0];
    assert_eq!(t["note"], "warm");
    let w = t["warnings"].to_string();
    assert!(w.contains("rtest.toml says cw, the data turn ccw"), "{w}");
    assert!(
        w.contains("programmed feed 9000 mm/min, the steady circle runs at 6000.0"),
        "{w}"
    );
    assert_eq!(r.stderr.lines().count(), 2, "{}", r.stderr);
}

#[test]
fn evaluate_json_is_read_back_by_the_type_that_writes_it() {
    // One serde type per file format: every test of a folder's JSON (conditions from its
    // rtest.toml, ISO 230-4 figures, plane and ellipse routes) parses into `TestJson` and
    // serialises back to the very same JSON; the numbers are those of the evaluation.
    let r = run(&["evaluate", "measurements/demo-vmc/pos-b", "--json"]);
    assert!(r.ok, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let tests = v["tests"].as_array().unwrap();
    assert_eq!(tests.len(), 18);
    for t in tests {
        let typed: eij::measured::json::TestJson = serde_json::from_value(t.clone()).unwrap();
        assert_eq!(&serde_json::to_value(&typed).unwrap(), t);
        assert_eq!(typed.radius_source, "rtest.toml");
        assert_eq!(
            typed.position_mm.as_deref(),
            Some(&[-150.0, 100.0, 0.0][..])
        );
        assert_eq!(typed.circle.eij_um_s2_per_m.len(), 6);
        assert!(typed.circle.iso230_4.is_some() && typed.circle.ellipse_fit.is_some());
        let e = typed
            .circle
            .eij_um_s2_per_m
            .values()
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(e > 0.5 && e < 5.0, "{}: largest EIJ {e}", typed.circle.file);
    }
}
