//! Issue 29, item 13: inputs that gave wrong results with exit 0 — a measured folder copied
//! beside itself, an EIJ table made from a series lying beside it, a `[[joint]]` block pasted
//! twice, `parameters = []`, too few `--decimals` for the sample rate — and a CSV with CR-only
//! line ends. Each is refused with one line (or, for CR, read as it should be).

mod common;

use common::{demo_text, eij, one_line_error, run, Scratch, DEMO};

const POS_A: &str = "measurements/demo-vmc/pos-a";

fn copy_folder(from: &str, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(common::root().join(from)).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
    }
}

#[test]
fn a_copied_folder_is_refused_not_counted_twice() {
    let s = Scratch::new("i29-copy");
    copy_folder(POS_A, &s.path("a"));
    copy_folder(POS_A, &s.path("b"));
    let dir = s.s("");
    let o = eij(&["evaluate", &dir]);
    one_line_error(
        &o,
        &[
            "the same content as",
            "a/xy_ccw_2.csv",
            "count its test twice",
        ],
    );
    let args = common::identify_args(&s.s("m.toml"), &s.s("r.json"));
    let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
    let measured = args.iter().position(|a| *a == "--measured").unwrap() + 1;
    args[measured] = &dir;
    one_line_error(&eij(&args), &["the same content as"]);
    // One copy alone is fine.
    let a = s.s("a");
    args[measured] = &a;
    let r = run(&args);
    assert!(r.ok, "{}", r.stderr);
}

#[test]
fn a_table_made_from_a_series_beside_it_is_refused() {
    let s = Scratch::new("i29-table");
    let dir = s.path("t");
    std::fs::create_dir_all(&dir).unwrap();
    for f in ["rtest.toml", "zx_ccw_5.csv", "xy_cw_2.csv"] {
        std::fs::copy(common::root().join(POS_A).join(f), dir.join(f)).unwrap();
    }
    let table = s.s("table.csv");
    let zx = dir.join("zx_ccw_5.csv");
    let r = run(&["evaluate", zx.to_str().unwrap(), "--csv-out", &table]);
    assert!(r.ok, "{}", r.stderr);
    let text = std::fs::read_to_string(&table).unwrap();
    let args = common::identify_args(&s.s("m.toml"), &s.s("r.json"));
    let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
    let measured = args.iter().position(|a| *a == "--measured").unwrap() + 1;
    let d = dir.display().to_string();
    args[measured] = &d;
    // The table as evaluate wrote it, and rounded to three decimals as from a report.
    let rounded = round_values(&text, 3);
    for t in [text.clone(), rounded] {
        std::fs::write(dir.join("zx_table.csv"), &t).unwrap();
        one_line_error(
            &eij(&args),
            &[
                "zx_table.csv",
                "the EIJ of the measured series",
                "zx_ccw_5.csv",
            ],
        );
    }
    // A table of other values (another measurement of the same conditions) counts.
    std::fs::write(dir.join("zx_table.csv"), shift_values(&text, 0.05)).unwrap();
    let r = run(&args);
    assert!(r.ok, "{}", r.stderr);
}

/// The table with `value_um_s2_per_m` rounded to `decimals`.
fn round_values(text: &str, decimals: usize) -> String {
    map_values(text, |v| format!("{v:.decimals$}"))
}

/// The table with `value_um_s2_per_m` shifted by `by`.
fn shift_values(text: &str, by: f64) -> String {
    map_values(text, |v| format!("{}", v + by))
}

fn map_values(text: &str, f: impl Fn(f64) -> String) -> String {
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let col = header
        .split(',')
        .position(|c| c == "value_um_s2_per_m")
        .unwrap();
    let mut out = format!("{header}\n");
    for l in lines {
        let mut cells: Vec<String> = l.split(',').map(String::from).collect();
        cells[col] = f(cells[col].parse().unwrap());
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

#[test]
fn a_joint_given_twice_is_refused() {
    let s = Scratch::new("i29-joint");
    let text = demo_text();
    let first = text.find("[[joint]]").unwrap();
    let second = first + 1 + text[first + 1..].find("[[joint]]").unwrap();
    let block = &text[first..second];
    let twice = format!("{}{block}{}", &text[..second], &text[second..]);
    let m = s.write("twice.toml", &twice);
    one_line_error(
        &eij(&["modal", "--machine", &m]),
        &[
            "twice.toml",
            "joint[foot-front-left].name",
            "duplicate joint name",
        ],
    );
    // The same joint under another name: still one spring counted twice.
    let renamed = block.replacen("foot-front-left", "foot-front-left-2", 1);
    let m = s.write(
        "renamed.toml",
        format!("{}{renamed}{}", &text[..second], &text[second..]),
    );
    one_line_error(
        &eij(&["modal", "--machine", &m]),
        &[
            "joint[foot-front-left-2].point_m",
            "already joins bed and floor",
        ],
    );
}

#[test]
fn an_empty_parameter_list_is_refused() {
    let s = Scratch::new("i29-params");
    let cfg = s.write("cfg.toml", "parameters = []\n");
    let args = common::identify_args(&s.s("m.toml"), &s.s("r.json"));
    let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
    // The config's list alone decides (no --param).
    let p = args.iter().position(|a| *a == "--param").unwrap();
    args.drain(p..p + 2);
    args.extend(["--config", &cfg]);
    one_line_error(
        &eij(&args),
        &["cfg.toml", "parameters = [] names no parameter"],
    );
    assert_eq!(std::fs::read_dir(&s.0).unwrap().count(), 1);
}

#[test]
fn decimals_must_resolve_the_sample_rate() {
    let s = Scratch::new("i29-decimals");
    let out = s.s("c.csv");
    let circle = common::circle_args(DEMO, &out);
    let with = |rate: &str, decimals: &str| {
        let mut v: Vec<&str> = circle.iter().map(String::as_str).collect();
        v.extend(["--rate-hz", rate, "--decimals", decimals, "--required-only"]);
        eij(&v)
    };
    one_line_error(
        &with("10000", "3"),
        &["--decimals 3", "10000 Hz", "at least 5 decimals"],
    );
    one_line_error(&with("10000", "4"), &["at least 5 decimals"]);
    assert!(!std::path::Path::new(&out).exists());
    // The least allowed is enough for eij's own evaluation.
    let o = with("10000", "5");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = run(&["evaluate", &out, "--radius-mm", "2", "--json"]);
    assert!(r.ok, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let exz = v["tests"][0]["eij_um_s2_per_m"]["EXZ"].as_f64().unwrap();
    assert!(exz.is_finite() && exz.abs() < 10.0, "{exz}");
}

#[test]
fn cr_only_line_ends_are_lines() {
    let s = Scratch::new("i29-cr");
    let lf = common::root().join(common::ZX_CSV);
    let text = std::fs::read_to_string(&lf).unwrap();
    assert!(!text.contains('\r'));
    let cr = s.write("zx_ccw_5.csv", text.replace('\n', "\r"));
    let json = |p: &str| {
        let r = run(&["evaluate", p, "--radius-mm", "2", "--json"]);
        assert!(r.ok, "{}", r.stderr);
        let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
        v["tests"][0]["eij_um_s2_per_m"].clone()
    };
    assert_eq!(json(&cr), json(lf.to_str().unwrap()));
}
