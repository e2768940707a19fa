//! `eij evaluate … --diagnose`: the diagnosis by source in JSON (CONTRACT.md keys) and text,
//! `[tolerances]` of `rtest.toml` judged with the verdict in the JSON and the exit code, and
//! bad tolerances or settings refused in one line.

mod common;

use common::circle_terms::TermCircle;
use common::synth::csv_text;
use common::{eij, one_line_error, Scratch};
use eij::axes::Plane;
use serde_json::Value;

/// A folder with a cw/ccw pair of xy circles whose x axis has 3 µm of lost motion, and an
/// `rtest.toml` with `extra` appended.
fn folder(tag: &str, extra: &str) -> Scratch {
    let dir = Scratch::new(tag);
    for (ccw, name) in [(true, "ccw.csv"), (false, "cw.csv")] {
        let mut c = TermCircle::new(Plane::Xy, ccw, 3.0);
        c.internal.backlash_um = [3.0, 0.0];
        c.seed = 5 + u64::from(ccw);
        let (t, int, ext) = c.columns();
        dir.write(name, csv_text(&t, &int, &ext));
    }
    dir.write(
        "rtest.toml",
        format!("radius_mm = 2.0\nposition_mm = [0, 0, 0]\n{extra}"),
    );
    dir
}

fn json(out: &std::process::Output) -> Value {
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)))
}

fn term<'a>(test: &'a Value, source: &str, name: &str) -> &'a Value {
    test["diagnosis"][source]["terms"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["name"] == name)
        .unwrap_or_else(|| panic!("{source} {name}"))
}

#[test]
fn json_names_every_term_with_value_unit_and_std_err() {
    let dir = folder("diag-json", "");
    let out = eij(&["evaluate", &dir.s(""), "--diagnose", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = json(&out);
    assert!(doc.get("verdict").is_none(), "no tolerances, no verdict");
    for test in doc["tests"].as_array().unwrap() {
        for source in ["internal", "structure", "tcp"] {
            let d = &test["diagnosis"][source];
            assert!(d["residual_um"].as_f64().unwrap() > 0.0);
            for t in d["terms"].as_array().unwrap() {
                for key in ["name", "value", "unit", "std_err", "contribution_um"] {
                    assert!(t.get(key).is_some(), "{source}: {t} lacks {key}");
                }
            }
            for name in [
                "centre_offset_a",
                "centre_offset_b",
                "scale_mismatch",
                "squareness",
                "backlash_x",
                "reversal_spike_y",
                "lateral_play_x",
                "out_of_plane_tilt",
            ] {
                term(test, source, name);
            }
            assert_eq!(term(test, source, "servo_mismatch")["unit"], "ms");
        }
        let b = term(test, "internal", "backlash_x");
        let (v, se) = (b["value"].as_f64().unwrap(), b["std_err"].as_f64().unwrap());
        assert!((v - 3.0).abs() < 3.0 * se, "backlash_x {v} ± {se}");
        assert_eq!(b["crossings"][0]["side"], "x+");
        // The ISO 230-4 G of the TCP is the external path's.
        let g = test["diagnosis"]["tcp"]["circular_deviation_um"]
            .as_f64()
            .unwrap();
        assert!((g - test["circular_deviation_um"]["external"].as_f64().unwrap()).abs() < 1e-9);
    }
    assert_eq!(doc["diagnosis_groups"].as_array().unwrap().len(), 1);
}

#[test]
fn text_ranks_the_terms_per_source() {
    let dir = folder("diag-text", "");
    let out = eij(&["evaluate", &dir.s(""), "--diagnose"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let internal = text.find("internal — the axes' own readings").expect(&text);
    let first = text[internal..].lines().nth(1).unwrap();
    assert!(first.contains(" 1 backlash_x"), "{first}");
    assert!(text.contains("tcp — the TCP, as a ballbar sees it"));
}

#[test]
fn tolerances_give_the_verdict_and_the_exit_code() {
    let tight = folder(
        "diag-tight",
        "[tolerances]\ncircular_deviation_um = 20\nbacklash_um = 2\n",
    );
    let out = eij(&["evaluate", &tight.s(""), "--diagnose", "--json"]);
    assert_eq!(out.status.code(), Some(3));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("eij: verdict: fail: 2 of 2 judged test(s) out of tolerance"),
        "{stderr}"
    );
    let doc = json(&out);
    assert_eq!(doc["verdict"], "fail");
    for test in doc["tests"].as_array().unwrap() {
        assert_eq!(test["verdict"], "fail");
        let checks: Vec<(&str, &str)> = test["tolerance_checks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| (c["name"].as_str().unwrap(), c["verdict"].as_str().unwrap()))
            .collect();
        assert_eq!(
            checks,
            [
                ("circular_deviation", "pass"),
                ("backlash_x", "fail"),
                ("backlash_y", "pass")
            ]
        );
        assert_eq!(term(test, "tcp", "backlash_x")["verdict"], "fail");
    }
    let loose = folder(
        "diag-loose",
        "[tolerances]\nbacklash_um = 4\n[tolerances.internal]\nservo_mismatch_ms = 0.05\n",
    );
    let out = eij(&["evaluate", &loose.s(""), "--diagnose", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(json(&out)["verdict"], "pass");
}

#[test]
fn bad_tolerances_and_settings_are_one_line_errors() {
    let dir = folder("diag-bad", "[tolerances]\nbacklash_mm = 2\n");
    let out = eij(&["evaluate", &dir.s(""), "--diagnose"]);
    one_line_error(
        &out,
        &["rtest.toml", "tolerances.backlash_mm", "backlash is in um"],
    );
    let dir = folder("diag-bad-pitch", "[diagnosis]\ncyclic_pitch_mm = -1\n");
    let out = eij(&["evaluate", &dir.s(""), "--diagnose"]);
    one_line_error(
        &out,
        &["rtest.toml", "diagnosis.cyclic_pitch_mm", "must lie in"],
    );
    let ok = folder("diag-flags", "");
    let out = eij(&["evaluate", &ok.s(""), "--diagnose", "--spike-decay-ms", "0"]);
    one_line_error(&out, &["--spike-decay-ms", "must lie in"]);
    let out = eij(&["evaluate", &ok.s(""), "--cyclic-pitch-mm", "5"]);
    one_line_error(&out, &["--diagnose"]);
}
