//! `measurements/diagnosis-demo/`: the files are exactly what their generator writes
//! (`tests/common/diagnosis_demo.rs`, labelled generated with the command and the truth), and
//! `eij evaluate measurements/diagnosis-demo --diagnose` prints a ranked breakdown per source
//! whose values match the true terms within 3 standard errors: servo mismatch, backlash,
//! squareness, scale mismatch and cyclic error in the axes, EIJ in the structure, their sum in
//! the TCP; exit code 3 because the TCP's backlash_x exceeds its tolerance of 2 µm.

mod common;

use common::diagnosis_checks::within;
use common::diagnosis_demo::{self as demo, BACKLASH_UM, EIJ};
use common::{eij, root};
use serde_json::Value;

const DIR: &str = "measurements/diagnosis-demo";

#[test]
fn files_are_what_the_generator_writes() {
    for (name, bytes) in demo::files() {
        let path = root().join(DIR).join(&name);
        let on_disk = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            on_disk == bytes,
            "{name} differs from the generator's output: run `{}`",
            demo::COMMAND
        );
    }
}

/// (value, std_err) of a term of a test's source.
fn term(test: &Value, source: &str, name: &str) -> (f64, f64) {
    let t = test["diagnosis"][source]["terms"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["name"] == name)
        .unwrap_or_else(|| panic!("{source} {name}"));
    (t["value"].as_f64().unwrap(), t["std_err"].as_f64().unwrap())
}

#[test]
fn evaluate_finds_the_true_terms() {
    let out = eij(&["evaluate", DIR, "--diagnose", "--json"]);
    assert_eq!(
        out.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    let tests = doc["tests"].as_array().unwrap();
    assert_eq!(tests.len(), 4);
    let servo_ms = demo::LAG_MS[0] - demo::LAG_MS[1];
    for t in tests {
        let f = t["file"].as_str().unwrap().to_string();
        let axes = [
            ("backlash_x", BACKLASH_UM[0]),
            ("backlash_y", BACKLASH_UM[1]),
            ("scale_mismatch", demo::SCALE_MISMATCH_UM),
            ("squareness", demo::SQUARENESS_UM_PER_M),
            ("servo_mismatch", servo_ms),
            ("cyclic_x", demo::CYCLIC_X.0),
        ];
        for (name, truth) in axes {
            within(
                &format!("{f} internal {name}"),
                term(t, "internal", name),
                truth,
                3.0,
            );
        }
        // The structure has no ballbar error of the axes, the TCP has both.
        for name in ["backlash_x", "backlash_y", "servo_mismatch"] {
            within(
                &format!("{f} structure {name}"),
                term(t, "structure", name),
                0.0,
                4.0,
            );
        }
        within(
            &format!("{f} tcp backlash_x"),
            term(t, "tcp", "backlash_x"),
            BACKLASH_UM[0],
            3.0,
        );
        within(
            &format!("{f} tcp servo"),
            term(t, "tcp", "servo_mismatch"),
            servo_ms,
            3.0,
        );
        // EIJ of the structure: d_I = E_IJ·a_J.
        let names = [["EXX", "EXY"], ["EYX", "EYY"], ["ZX", "ZY"]];
        for (row, pair) in names.iter().enumerate() {
            for (col, name) in pair.iter().enumerate() {
                let name = if row == 2 {
                    format!("E{name}")
                } else {
                    name.to_string()
                };
                let v = t["eij_um_s2_per_m"][&name].as_f64().unwrap();
                let se = t["std_err_um_s2_per_m"][&name].as_f64().unwrap();
                within(&format!("{f} {name}"), (v, se), EIJ[row][col], 3.0);
            }
        }
        // Out of tolerance: the TCP's backlash_x (limit 2 µm), nothing else.
        assert_eq!(t["verdict"], "fail", "{f}");
        let failed: Vec<&str> = t["tolerance_checks"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| c["verdict"] == "fail")
            .map(|c| c["name"].as_str().unwrap())
            .collect();
        assert_eq!(failed, ["backlash_x"], "{f}");
    }
}

/// The text: per test and source the terms ranked by their share of G (descending), the
/// printed values those of the JSON.
#[test]
fn text_prints_the_ranked_breakdown() {
    let out = eij(&["evaluate", DIR, "--diagnose"]);
    assert_eq!(out.status.code(), Some(3));
    let text = String::from_utf8_lossy(&out.stdout);
    let internal = text
        .split("    internal — the axes' own readings")
        .nth(1)
        .expect("internal section");
    let internal = &internal[..internal.find("    structure —").unwrap()];
    let mut ranked: Vec<(String, f64)> = Vec::new();
    for line in internal.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.len() > 6 && words[0].parse::<usize>().is_ok() && words[3] == "±" {
            let g = words
                .iter()
                .position(|w| *w == "G")
                .map(|i| words[i + 1].parse::<f64>().unwrap());
            if let Some(g) = g {
                ranked.push((words[1].to_string(), g));
            }
        }
    }
    let names: Vec<&str> = ranked.iter().map(|(n, _)| n.as_str()).collect();
    for n in [
        "servo_mismatch",
        "backlash_x",
        "scale_mismatch",
        "squareness",
        "backlash_y",
        "cyclic_x",
    ] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    assert!(
        ranked.windows(2).all(|w| w[0].1 >= w[1].1),
        "ranked by share of G: {ranked:?}"
    );
    assert!(text.contains("tolerance tcp backlash_x"), "{text}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("eij: verdict: fail: 4 of 4"));
}
