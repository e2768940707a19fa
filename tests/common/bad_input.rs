//! What the bad-input tests share (tests/cli_bad_input*.rs): the contract of a refused
//! command, and the commands they refuse.

use super::{eij, one_line_error, root, Scratch, DEMO, ZX_CSV};

/// Runs `eij args…` and checks the contract for a refused input: non-zero exit, one stderr line
/// starting `eij: error: ` holding every needle, no panic, nothing on stdout, the scratch folder
/// unchanged. Returns the error line.
pub fn refused(s: &Scratch, args: &[&str], needles: &[&str]) -> String {
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

/// `eij simulate circle` of the demo in zx, with `extra` arguments.
pub fn circle<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
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

/// `eij map` of the demo, with `extra` arguments.
pub fn map<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec!["map", "--machine", DEMO, "--out", out];
    v.extend_from_slice(extra);
    v
}

/// A folder with one demo R-Test file and the given `rtest.toml`.
pub fn measured_with_conditions(s: &Scratch, conditions: &str) -> (String, String) {
    let dir = s.path("m");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(root().join(ZX_CSV), dir.join("zx_ccw_5.csv")).unwrap();
    let c = s.write("m/rtest.toml", conditions);
    (dir.display().to_string(), c)
}

/// `eij identify` of one parameter of the demo from `measured`.
pub fn identify<'a>(
    s: &'a Scratch,
    measured: &'a str,
    out: &'a str,
    report: &'a str,
) -> Vec<&'a str> {
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
