//! Bad inputs through the binary (issue 8, catalogue in `docs/bad-inputs.md`): every one gives a
//! non-zero exit, exactly one line `eij: error: …` on standard error naming the file or option
//! (and line or key), no panic, and leaves the output folder exactly as it was (no output, no
//! temporary file). Cases already pinned elsewhere are cited in the catalogue, not repeated here.
//! This file: R-Test CSV, machine files, the command line and identification inputs; outputs
//! are in cli_bad_input_outputs.rs.

mod common;

use common::bad_input::{circle, identify, map, measured_with_conditions, refused};
use common::{root, Scratch, DEMO, HEADER, ZX_CSV};

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
