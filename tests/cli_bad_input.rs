//! Bad inputs through the binary (issue 8, catalogue in `docs/bad-inputs.md`): every one gives a
//! non-zero exit, exactly one line `eij: error: …` on standard error naming the file or option
//! (and line or key), no panic, and leaves the output folder exactly as it was (no output, no
//! temporary file). Cases already pinned elsewhere are cited in the catalogue, not repeated here.

mod common;

use common::{eij, one_line_error, root, Scratch, DEMO, HEADER, ZX_CSV};
use std::path::Path;

/// Runs `eij args…` and checks the contract for a refused input: non-zero exit, one stderr line
/// starting `eij: error: ` holding every needle, no panic, nothing on stdout, the scratch folder
/// unchanged. Returns the error line.
fn refused(s: &Scratch, args: &[&str], needles: &[&str]) -> String {
    let before = s.snapshot();
    let out = eij(args);
    assert!(out.stdout.is_empty(), "{args:?}: stdout not empty");
    let line = one_line_error(&out, needles);
    assert!(
        s.snapshot() == before,
        "{args:?}: the scratch folder changed (output or temporary file written)"
    );
    line
}

fn circle<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec![
        "simulate",
        "circle",
        "--machine",
        DEMO,
        "--plane",
        "zx",
        "--radius-mm",
        "2",
        "--accel-m-s2",
        "5",
        "--direction",
        "ccw",
        "--out",
        out,
    ];
    v.extend_from_slice(extra);
    v
}

fn map<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec!["map", "--machine", DEMO, "--out", out];
    v.extend_from_slice(extra);
    v
}

// ---- R-Test CSV -------------------------------------------------------------------------

#[test]
fn csv_one_row() {
    let s = Scratch::new("one-row");
    let f = s.write("one.csv", format!("{HEADER}\n0,2,0,0,2,0,0\n"));
    refused(
        &s,
        &["evaluate", &f],
        &[&format!("{f}: 1 data row(s), at least 2 needed")],
    );
}

#[test]
fn csv_not_utf8() {
    let s = Scratch::new("utf8");
    let f = s.write("bin.csv", b"\xff\xfe\x00garbage\n");
    refused(
        &s,
        &["evaluate", &f],
        &[&format!("{f}:1: not valid UTF-8 text")],
    );
}

/// Found by fuzzing (`fuzz/`): a quoted cell spanning lines was echoed into the message, which
/// then spanned lines too. Cell text is now escaped and cut.
#[test]
fn csv_quoted_cell_with_line_ends_stays_on_one_line() {
    let s = Scratch::new("quoted");
    let f = s.write(
        "quoted.csv",
        format!("{HEADER}\n0,2,0,0,2,0,\"2.0\n0.001,2,0,0,2,0,2\n0.002,2,0,0,2,0,2\"\n"),
    );
    refused(
        &s,
        &["evaluate", &f],
        &[&format!(
            "{f}:2: column z_ext_mm: '2.0\\n0.001,2,0,0,2,0,2\\n0.002,2,0,0,2,0,2' is not a number"
        )],
    );
    let t = s.write(
        "table.csv",
        "plane,direction,accel_m_s2,parameter,value_um_s2_per_m,\"no\nte\"\nzx,ccw,4.5,EXZ,1,a\n",
    );
    let line = refused(
        &s,
        &[
            "identify",
            "--machine",
            DEMO,
            "--measured",
            &t,
            "--out",
            &s.s("o.toml"),
        ],
        &[&format!("{t}:1: unknown column 'no\\nte'")],
    );
    assert!(line.len() < 300, "{line}");
}

#[test]
fn csv_without_circular_motion() {
    let s = Scratch::new("no-motion");
    let f = s.write(
        "still.csv",
        format!("{HEADER}\n0,2,0,0,2,0,0\n0.001,2,0,0,2,0,0\n0.002,2,0,0,2,0,0\n"),
    );
    refused(
        &s,
        &["evaluate", &f],
        &[&format!("{f}: no circular motion in the internal readings")],
    );
}

#[test]
fn csv_plane_the_data_does_not_move_in() {
    let s = Scratch::new("wrong-plane");
    refused(
        &s,
        &["evaluate", ZX_CSV, "--plane", "xy"],
        &[&format!(
            "{ZX_CSV}: no circular motion in the internal readings (y_int_mm moves"
        )],
    );
}

#[test]
fn csv_written_by_evaluate_over_its_own_input_or_to_nowhere() {
    let s = Scratch::new("csv-out");
    let input = s.write("in.csv", std::fs::read(root().join(ZX_CSV)).unwrap());
    refused(
        &s,
        &["evaluate", &input, "--csv-out", &input],
        &[&format!("{input}: refusing to overwrite an input file")],
    );
    refused(
        &s,
        &["evaluate", &input, "--csv-out", "/nonexistent-dir/x.csv"],
        &["/nonexistent-dir/x.csv: cannot write: folder /nonexistent-dir does not exist"],
    );
    let dir = s.s("");
    let dir = dir.trim_end_matches('/');
    refused(
        &s,
        &["evaluate", &input, "--csv-out", dir],
        &[&format!("{dir}: is a folder, not a file")],
    );
    refused(
        &s,
        &[
            "evaluate",
            &input,
            "--csv-out",
            &s.s("t.csv"),
            "--plot",
            &s.s("t.csv"),
        ],
        &[&format!(
            "{}: given for two outputs of the same run",
            s.s("t.csv")
        )],
    );
}

// ---- Machine file -----------------------------------------------------------------------

#[test]
fn machine_file_is_a_folder() {
    let s = Scratch::new("machine-folder");
    refused(
        &s,
        &["modal", "--machine", "machines"],
        &["machines: file: is a folder, not a file"],
    );
}

#[test]
fn machine_file_names_a_missing_catalogue() {
    let s = Scratch::new("catalogue");
    let text = std::fs::read_to_string(root().join(DEMO)).unwrap();
    let m = s.write("m.toml", format!("catalogue = [\"nope.toml\"]\n{text}"));
    refused(
        &s,
        &["export", "--machine", &m, "--out", &s.s("o.json")],
        &[&format!("{m}: catalogue[0]: "), "nope.toml"],
    );
}

#[test]
fn machine_file_empty() {
    let s = Scratch::new("machine-empty");
    let m = s.write("m.toml", "");
    refused(
        &s,
        &["export", "--machine", &m, "--out", &s.s("o.json")],
        &[&format!("{m}: "), "missing field"],
    );
}

// ---- Command line -----------------------------------------------------------------------

#[test]
fn unknown_plane() {
    let s = Scratch::new("plane");
    let out = s.s("c.csv");
    let mut args = circle(&out, &[]);
    args[5] = "qq";
    refused(
        &s,
        &args,
        &["invalid value 'qq' for '--plane <PLANE>': unknown plane 'qq' (expected xy, yz or zx)"],
    );
    refused(
        &s,
        &map(
            &out,
            &["--plane", "ab", "--accel-m-s2", "5", "--grid", "x=0:1:2"],
        ),
        &["invalid value 'ab' for '--plane <PLANE>'"],
    );
    refused(
        &s,
        &["evaluate", ZX_CSV, "--plane", "xz"],
        &["invalid value 'xz' for '--plane <PLANE>'"],
    );
}

#[test]
fn zero_or_negative_acceleration() {
    let s = Scratch::new("accel");
    let out = s.s("c.csv");
    for a in ["0", "-5", "nan", "inf"] {
        let mut args = circle(&out, &[]);
        args[9] = a;
        refused(&s, &args, &["--accel-m-s2: ", "must be a positive number"]);
        refused(
            &s,
            &map(
                &out,
                &["--plane", "zx", "--accel-m-s2", a, "--grid", "x=0:1:2"],
            ),
            &["--accel-m-s2: ", "must be a positive number"],
        );
    }
    refused(
        &s,
        &[
            "simulate",
            "move",
            "--machine",
            DEMO,
            "--axis",
            "z",
            "--distance-mm",
            "20",
            "--feed-mm-min",
            "30000",
            "--accel-m-s2",
            "-10",
            "--jerk-m-s3",
            "250",
            "--out",
            &out,
        ],
        &["--accel-m-s2: -10 must be a positive number"],
    );
}

#[test]
fn radius_beyond_the_probe_range() {
    let s = Scratch::new("radius");
    let out = s.s("c.csv");
    let mut args = circle(&out, &[]);
    args[7] = "4";
    refused(
        &s,
        &args,
        &["--radius-mm: 4 mm exceeds the R-Test probe range of ±3 mm"],
    );
    args[7] = "-2";
    refused(&s, &args, &["--radius-mm: -2 must be a positive number"]);
    refused(
        &s,
        &map(
            &out,
            &[
                "--plane",
                "zx",
                "--accel-m-s2",
                "5",
                "--radius-mm",
                "5",
                "--grid",
                "x=0:1:2",
            ],
        ),
        &["--radius-mm: 5 must lie in (0, 3] mm (R-Test range)"],
    );
    refused(
        &s,
        &["evaluate", ZX_CSV, "--radius-mm", "4"],
        &["--radius-mm: 4 mm exceeds the R-Test probe range of ±3 mm"],
    );
    refused(
        &s,
        &["evaluate", ZX_CSV, "--radius-mm", "-1"],
        &["--radius-mm -1: expected a positive number of mm"],
    );
}

#[test]
fn bad_position_mm() {
    let s = Scratch::new("position");
    refused(
        &s,
        &["modal", "--machine", DEMO, "--position-mm", "1,2"],
        &["--position-mm: 2 values given, machine machines/demo-vmc.toml has 3 axes (x, y, z)"],
    );
    refused(
        &s,
        &["modal", "--machine", DEMO, "--position-mm", "a,0,0"],
        &["invalid value 'a' for '--position-mm <X,Y,Z>': invalid float literal"],
    );
    refused(
        &s,
        &["modal", "--machine", DEMO, "--position-mm", "0,0,999"],
        &["--position-mm: z = 999 mm is outside the stroke [-100, 300] mm of machines/demo-vmc.toml"],
    );
    refused(
        &s,
        &["modal", "--machine", DEMO, "--position-mm", "nan,0,0"],
        &["--position-mm: x = NaN mm is outside the stroke"],
    );
    let out = s.s("c.csv");
    refused(
        &s,
        &circle(&out, &["--position-mm", "400,0,0"]),
        &["--position-mm: x = 400 mm is outside the stroke [-300, 300] mm"],
    );
    refused(
        &s,
        &[
            "export",
            "--machine",
            DEMO,
            "--position-mm",
            "0,-999,0",
            "--out",
            &s.s("o.json"),
        ],
        &["--position-mm: y = -999 mm is outside the stroke"],
    );
}

#[test]
fn bad_grid() {
    let s = Scratch::new("grid");
    let out = s.s("m.csv");
    let cases: [(&[&str], &str); 8] = [
        (
            &["--grid", "x"],
            "--grid x: expected <axis>=<min>:<max>:<count>",
        ),
        (
            &["--grid", "x=0:1"],
            "--grid x=0:1: expected <min>:<max>:<count>",
        ),
        (&["--grid", "q=0:1:2"], "--grid q=0:1:2: unknown axis 'q'"),
        (
            &["--grid", "x=a:1:2"],
            "--grid x=a:1:2: min is not a number",
        ),
        (
            &["--grid", "x=0:1:1.5"],
            "--grid x=0:1:1.5: count is not a whole number",
        ),
        (
            &["--grid", "x=1:0:3"],
            "--grid x=1:0:3: need finite min < max and count ≥ 1",
        ),
        (
            &["--grid", "x=0:999:2"],
            "--grid x: outside the stroke [-300, 300] mm",
        ),
        (
            &["--grid", "x=0:1:2", "--grid", "x=0:1:2"],
            "--grid x: axis given twice",
        ),
    ];
    for (grid, needle) in cases {
        let mut extra = vec!["--plane", "zx", "--accel-m-s2", "5"];
        extra.extend_from_slice(grid);
        refused(&s, &map(&out, &extra), &[needle]);
    }
    refused(
        &s,
        &map(
            &out,
            &[
                "--plane",
                "zx",
                "--accel-m-s2",
                "5",
                "--grid",
                "x=0:1:200000",
            ],
        ),
        &["--grid x=0:1:200000: count 200000 exceeds 100000 points"],
    );
    refused(
        &s,
        &map(
            &out,
            &[
                "--plane",
                "zx",
                "--accel-m-s2",
                "5",
                "--grid",
                "x=0:1:1000",
                "--grid",
                "y=0:1:1000",
            ],
        ),
        &["--grid x, y: 1000000 grid points, at most 100000"],
    );
}

#[test]
fn plane_the_machine_lacks() {
    let s = Scratch::new("plane-axes");
    refused(
        &s,
        &[
            "map",
            "--machine",
            "machines/reference/single-axis.toml",
            "--plane",
            "zx",
            "--accel-m-s2",
            "5",
            "--grid",
            "x=0:1:2",
            "--out",
            &s.s("m.csv"),
        ],
        &["--plane zx: the machine single-axis has no axis z"],
    );
}

#[test]
fn missing_or_unknown_arguments() {
    let s = Scratch::new("args");
    let out = s.s("c.csv");
    let mut args = circle(&out, &[]);
    args.truncate(12);
    refused(
        &s,
        &args,
        &["the following required arguments were not provided: --out <FILE.csv>"],
    );
    refused(
        &s,
        &["modal", "--machine", DEMO, "--bogus"],
        &["unexpected argument '--bogus' found"],
    );
    refused(
        &s,
        &["frobnicate"],
        &["unrecognized subcommand 'frobnicate'"],
    );
}

#[test]
fn sample_rate_too_low_or_too_high() {
    let s = Scratch::new("rate");
    let out = s.s("c.csv");
    refused(
        &s,
        &circle(&out, &["--rate-hz", "10"]),
        &["--rate-hz 10: 1.3 samples per revolution of the 7.958 Hz circle, at least 36 needed"],
    );
    refused(
        &s,
        &circle(&out, &["--rate-hz", "1e9"]),
        &["--rate-hz 1000000000: ", "at most 1e6 are written"],
    );
    refused(
        &s,
        &circle(&out, &["--rate-hz", "0"]),
        &["--rate-hz: 0 must be a positive number"],
    );
    refused(
        &s,
        &circle(&out, &["--noise-um", "-1"]),
        &["--noise-um: -1 must be ≥ 0"],
    );
    refused(
        &s,
        &circle(&out, &["--decimals", "20"]),
        &["--decimals: 20 is more than the 15 an f64 holds"],
    );
}

#[test]
fn move_beyond_the_stroke() {
    let s = Scratch::new("move");
    refused(
        &s,
        &[
            "simulate",
            "move",
            "--machine",
            DEMO,
            "--axis",
            "x",
            "--distance-mm",
            "1000",
            "--feed-mm-min",
            "30000",
            "--accel-m-s2",
            "10",
            "--jerk-m-s3",
            "250",
            "--out",
            &s.s("m.csv"),
        ],
        &["--distance-mm: the move ends at 1000.0 mm, outside the x stroke [-300.0, 300.0] mm"],
    );
}

// ---- Identification inputs --------------------------------------------------------------

/// A folder with one demo R-Test file and the given `rtest.toml`.
fn measured_with_conditions(s: &Scratch, conditions: &str) -> (String, String) {
    let dir = s.path("m");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(root().join(ZX_CSV), dir.join("zx_ccw_5.csv")).unwrap();
    let c = s.write("m/rtest.toml", conditions);
    (dir.display().to_string(), c)
}

fn identify<'a>(s: &'a Scratch, measured: &'a str, out: &'a str, report: &'a str) -> Vec<&'a str> {
    let _ = s;
    vec![
        "identify",
        "--machine",
        DEMO,
        "--measured",
        measured,
        "--param",
        "z.guideway_normal",
        "--quiet",
        "--out",
        out,
        "--report",
        report,
    ]
}

#[test]
fn rtest_toml_bad_key_or_value() {
    let cases = [
        (
            "radius_mm = 2.0\npositon_mm = [1.0, 2.0, 3.0]\n",
            "rtest.toml: line 2, column 1: unknown field `positon_mm`, expected one of `radius_mm`, `position_mm`, `columns`",
        ),
        (
            "radius_mm = \"two\"\n",
            "rtest.toml: line 1, column 13: invalid type: string \"two\", expected f64",
        ),
        ("radius_mm = 7.0\n", "rtest.toml: radius_mm: 7 must lie in (0, 3] mm"),
        (
            "position_mm = []\n",
            "rtest.toml: position_mm: empty; give one position per machine axis",
        ),
        (
            "position_mm = [0.0, nan, 0.0]\n",
            "rtest.toml: position_mm: values must be finite",
        ),
        (
            "radius_mm = two\n",
            "rtest.toml: line 1, column 13: invalid boolean",
        ),
    ];
    for (i, (text, needle)) in cases.iter().enumerate() {
        let s = Scratch::new(&format!("conditions-{i}"));
        let (m, c) = measured_with_conditions(&s, text);
        let (out, report) = (s.s("id.toml"), s.s("id.json"));
        let line = refused(&s, &identify(&s, &m, &out, &report), &[needle]);
        assert!(line.contains(&c), "{line}");
    }
}

#[test]
fn eij_table_with_a_bad_row() {
    let s = Scratch::new("table");
    let t = s.write(
        "t.csv",
        "plane,direction,accel_m_s2,parameter,value_um_s2_per_m\nzx,ccw,4.5,EXZ,-1.55\nzx,ccw,4.5,EQZ,1\n",
    );
    let (out, report) = (s.s("id.toml"), s.s("id.json"));
    refused(
        &s,
        &identify(&s, &t, &out, &report),
        &[&format!("{t}:3: column parameter: unknown parameter 'EQZ'")],
    );
}

#[test]
fn too_few_values_for_the_parameters() {
    let s = Scratch::new("few");
    let t = s.write(
        "t.csv",
        "plane,direction,accel_m_s2,parameter,value_um_s2_per_m\nzx,ccw,4.5,EXZ,-1.55\n",
    );
    let (out, report) = (s.s("id.toml"), s.s("id.json"));
    refused(
        &s,
        &[
            "identify",
            "--machine",
            DEMO,
            "--measured",
            &t,
            "--quiet",
            "--out",
            &out,
            "--report",
            &report,
        ],
        &["1 measured values cannot determine 6 parameters"],
    );
}

// ---- Outputs ----------------------------------------------------------------------------

#[test]
fn output_in_a_missing_folder_is_refused_by_every_writer() {
    let s = Scratch::new("nowhere");
    let x = "/nonexistent-dir/x.out";
    let needle = "/nonexistent-dir/x.out: cannot write: folder /nonexistent-dir does not exist";
    refused(&s, &circle(x, &[]), &[needle]);
    refused(&s, &["export", "--machine", DEMO, "--out", x], &[needle]);
    refused(
        &s,
        &map(
            x,
            &["--plane", "zx", "--accel-m-s2", "5", "--grid", "x=0:1:2"],
        ),
        &[needle],
    );
    refused(&s, &["evaluate", ZX_CSV, "--csv-out", x], &[needle]);
    assert!(!Path::new("/nonexistent-dir").exists());
}

#[test]
fn output_that_is_a_folder_or_an_input_is_refused() {
    let s = Scratch::new("clobber");
    let m = s.write("m.toml", std::fs::read(root().join(DEMO)).unwrap());
    let dir = s.s("sub");
    std::fs::create_dir_all(&dir).unwrap();
    let folder = format!("{dir}: is a folder, not a file");
    let clobber = format!("{m}: refusing to overwrite an input file");
    let sim = |out: &str| common::circle_args(&m, out);
    let map_args = |out: &str| common::map_args(&m, out);
    let export = |out: &str| -> Vec<String> {
        ["export", "--machine", &m, "--out", out]
            .map(String::from)
            .to_vec()
    };
    for args in [sim(&dir), map_args(&dir), export(&dir)] {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&s, &args, &[&folder]);
    }
    for args in [sim(&m), map_args(&m), export(&m)] {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&s, &args, &[&clobber]);
    }
    let mut plot = sim(&s.s("c.csv"));
    plot.extend(["--plot".to_string(), m.clone()]);
    let plot: Vec<&str> = plot.iter().map(String::as_str).collect();
    refused(&s, &plot, &[&clobber]);
}

/// The convention: an existing output file is replaced atomically (the new content in full, no
/// temporary file left), by every command that writes a file.
#[test]
fn existing_outputs_are_replaced_atomically() {
    let s = Scratch::new("replace");
    let old = b"old content\n";
    let check = |name: &str, args: &[&str], starts: &str| {
        let p = s.write(name, old);
        let out = eij(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(
            text.starts_with(starts),
            "{name}: {}",
            &text[..40.min(text.len())]
        );
        let leftovers: Vec<_> = std::fs::read_dir(&s.0)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
    };
    let c = s.s("c.csv");
    check("c.csv", &circle(&c, &["--rate-hz", "2000"]), "t_s,");
    let e = s.s("e.json");
    check("e.json", &["export", "--machine", DEMO, "--out", &e], "{");
    let m = s.s("m.csv");
    check(
        "m.csv",
        &map(
            &m,
            &["--plane", "zx", "--accel-m-s2", "5", "--grid", "x=0:1:2"],
        ),
        "x_mm,y_mm,z_mm,",
    );
    let t = s.s("t.csv");
    check(
        "t.csv",
        &["evaluate", ZX_CSV, "--csv-out", &t],
        "plane,direction,",
    );
    let (id_toml, id_json) = (s.s("id.toml"), s.s("id.json"));
    std::fs::write(&id_json, old).unwrap();
    let mut identify = common::identify_args(&id_toml, &id_json);
    identify.push("--quiet".into());
    let identify: Vec<&str> = identify.iter().map(String::as_str).collect();
    check("id.toml", &identify, "");
    assert!(std::fs::read_to_string(&id_json).unwrap().starts_with('{'));
}

/// `eij report --out` names a folder: an existing one is reused and its report files replaced.
#[test]
fn report_folder_is_reused_and_its_files_replaced() {
    let s = Scratch::new("report-folder");
    let out = s.s("r");
    let run = || {
        let o = eij(&["report", "--measured", ZX_CSV, "--out", &out]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run();
    let html = s.path("r/report.html");
    std::fs::write(&html, "old").unwrap();
    run();
    assert!(std::fs::read_to_string(&html).unwrap().contains("<html"));
    let tmp = std::fs::read_dir(s.path("r"))
        .unwrap()
        .filter_map(|e| e.ok())
        .any(|e| e.file_name().to_string_lossy().ends_with(".tmp"));
    assert!(!tmp, "temporary file left in the report folder");
}

// ---- Outputs of `eij identify` ------------------------------------------------------------
// `src/cli/identify.rs` creates missing output folders, writes `--report` before it finds that
// `--out` cannot be written, and does not count the folder's `rtest.toml` among its inputs.
// These tests state the contract; they are ignored until identify checks its outputs first
// (`eij::io::check_outputs`) — see docs/bad-inputs.md.

fn quick_identify(s: &Scratch, out: &str, report: &str) -> Vec<String> {
    let (m, _) =
        measured_with_conditions(s, "radius_mm = 2.0\nposition_mm = [150.0, -100.0, 0.0]\n");
    identify(s, &m, out, report)
        .into_iter()
        .map(String::from)
        .collect()
}

#[test]
fn identify_output_in_a_missing_folder() {
    let s = Scratch::new("id-nowhere");
    let x = s.s("no-such-dir/x.toml");
    let args = quick_identify(&s, &x, &s.s("id.json"));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(
        &s,
        &args,
        &[&format!(
            "{x}: cannot write: folder {} does not exist",
            s.s("no-such-dir")
        )],
    );
}

#[test]
fn identify_output_that_is_a_folder_leaves_no_report() {
    let s = Scratch::new("id-folder");
    let dir = s.s("sub");
    std::fs::create_dir_all(&dir).unwrap();
    let args = quick_identify(&s, &dir, &s.s("id.json"));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(&s, &args, &[&format!("{dir}: is a folder, not a file")]);
}

#[test]
fn identify_out_and_report_the_same_file() {
    let s = Scratch::new("id-same");
    let args = quick_identify(&s, &s.s("id.toml"), &s.s("id.toml"));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(&s, &args, &["given for two outputs of the same run"]);
}

#[test]
fn identify_report_over_the_conditions_file() {
    let s = Scratch::new("id-conditions");
    let c = s.s("m/rtest.toml");
    let args = quick_identify(&s, &s.s("id.toml"), &c);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(
        &s,
        &args,
        &[&format!("{c}: refusing to overwrite an input file")],
    );
}

#[test]
fn identify_output_over_an_input_is_refused() {
    let s = Scratch::new("id-clobber");
    let (m, _) = measured_with_conditions(&s, "radius_mm = 2.0\n");
    let csv = format!("{m}/zx_ccw_5.csv");
    let before = std::fs::read(&csv).unwrap();
    let out = eij(&identify(&s, &m, &csv, &s.s("id.json")));
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains(&format!("{csv}: refusing to overwrite an input file")),
        "{stderr}"
    );
    assert_eq!(std::fs::read(&csv).unwrap(), before);
}
