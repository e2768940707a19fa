//! `eij identify` from the command line: outputs on success, one clear line and no output on
//! failure.

mod common;

use common::{root, Scratch};
use std::process::{Command, Output};

/// identify on three ZX files with the Z guideway factors, writing into `s`.
fn identify_command(s: &Scratch) -> Command {
    let zx = |n: &str| root().join("measurements/demo-vmc").join(n);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_eij"));
    cmd.current_dir(root())
        .args([
            "identify",
            "--machine",
            "machines/demo-vmc.toml",
            "--measured",
        ])
        .arg(zx("pos-a/zx_ccw_5.csv"))
        .arg(zx("pos-a/zx_cw_8.csv"))
        .arg(zx("pos-b/zx_ccw_8.csv"))
        .args([
            "--param",
            "z.guideway_normal",
            "--param",
            "z.guideway_lateral",
            "--out",
        ])
        .arg(s.path("id.toml"))
        .arg("--report")
        .arg(s.path("id.json"));
    cmd
}

/// Runs [`identify_command`] with `--quiet` and `extra` arguments.
fn identify(s: &Scratch, extra: &[&str]) -> Output {
    identify_command(s)
        .arg("--quiet")
        .args(extra)
        .output()
        .unwrap()
}

fn assert_failed_cleanly(s: &Scratch, out: &Output, expected: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "succeeded: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains(expected), "'{expected}' not in {stderr}");
    assert!(!stderr.contains("panicked"));
    assert!(
        !s.path("id.toml").exists() && !s.path("id.json").exists(),
        "output written on failure"
    );
    let leftovers = std::fs::read_dir(&s.0).unwrap().count();
    assert_eq!(leftovers, 0, "temporary files left behind");
}

#[test]
fn identified_machine_and_report_are_written_and_reload() {
    let s = Scratch::new("ok");
    let out = identify(&s, &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The exported machine file is a valid machine with the identified factors.
    let m = eij::machine::Machine::from_file(&s.path("id.toml")).unwrap();
    let z = m.axis(eij::axes::Axis::Z).unwrap();
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(s.path("id.json")).unwrap()).unwrap();
    let p = &json["parameters"][0];
    assert_eq!(p["name"], "z.guideway_normal");
    assert_eq!(
        z.guideway.reduction_normal,
        p["identified"].as_f64().unwrap()
    );
    assert!(p["std_err"].as_f64().unwrap() > 0.0);
    for key in [
        "cost_initial",
        "cost_final",
        "correlation",
        "jacobian_singular_values",
    ] {
        assert!(!json[key].is_null(), "missing {key}");
    }
    let t = &json["tests"][0];
    for key in [
        "plane",
        "direction",
        "accel_m_s2",
        "measured",
        "simulated_initial",
        "simulated_final",
    ] {
        assert!(!t[key].is_null(), "missing tests[0].{key}");
    }
    let text = std::fs::read_to_string(s.path("id.toml")).unwrap();
    assert!(text.starts_with("# Identified by eij"));
    assert!(text.contains("[provenance]"));
}

#[test]
fn reports_are_identical_across_runs_and_thread_counts() {
    let a = Scratch::new("det-a");
    let b = Scratch::new("det-b");
    let run = |s: &Scratch, threads: &str| {
        let zx = root().join("measurements/demo-vmc/pos-a/zx_ccw_5.csv");
        let out = Command::new(env!("CARGO_BIN_EXE_eij"))
            .current_dir(root())
            .env("RAYON_NUM_THREADS", threads)
            .env("SOURCE_DATE_EPOCH", "1700000000")
            .args([
                "identify",
                "--quiet",
                "--param",
                "z.guideway_normal",
                "--measured",
            ])
            .arg(&zx)
            .arg("--out")
            .arg(s.path("id.toml"))
            .arg("--report")
            .arg(s.path("id.json"))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        (
            std::fs::read(s.path("id.toml")).unwrap(),
            std::fs::read(s.path("id.json")).unwrap(),
        )
    };
    let one = run(&a, "1");
    let two = run(&b, "2");
    assert_eq!(one, two);
}

/// A refused fit: non-zero exit, the diagnosis as the last line of standard error (after the
/// warnings), no machine file, and the report the user asked for with status `refused`.
fn assert_refused(s: &Scratch, out: &Output, expected: &str) -> serde_json::Value {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "succeeded: {stderr}");
    let last = stderr.lines().last().unwrap_or_default();
    assert!(
        last.contains(expected),
        "'{expected}' not in the last line of {stderr}"
    );
    assert!(last.contains("nothing exported"), "{last}");
    assert!(
        stderr
            .lines()
            .all(|l| l == last || l.starts_with("warning: ")),
        "{stderr}"
    );
    assert!(
        !s.path("id.toml").exists(),
        "machine exported on a refused fit"
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(s.path("id.json")).unwrap()).unwrap();
    assert_eq!(json["status"], "refused");
    assert!(json["refusal"].as_str().unwrap().contains(expected));
    json
}

#[test]
fn non_convergence_exports_nothing() {
    let s = Scratch::new("iters");
    let out = identify(&s, &["--max-iters", "1"]);
    assert_refused(&s, &out, "did not converge in 1 iterations");
    // --quiet silences the tables, not the warnings: the fit after one iteration is far off.
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("warning: χ² test failed"), "{stderr}");
    assert!(
        stderr.contains("do not cover such a model error"),
        "{stderr}"
    );
}

#[test]
fn parameter_at_its_bound_exports_nothing() {
    let s = Scratch::new("bound");
    std::fs::write(s.path("cfg.toml"), "min_factor = 0.6\n").unwrap();
    let cfg = s.path("cfg.toml");
    let out = identify(&s, &["--config", cfg.to_str().unwrap(), "--no-design"]);
    std::fs::remove_file(&cfg).unwrap();
    let json = assert_refused(&s, &out, "z.guideway_normal ended at its bound 0.6");
    assert_eq!(json["parameters"][0]["at_bound"], true);
}

#[test]
fn a_factor_just_off_its_bound_counts_as_on_it() {
    // The bound sits 0.06 % below where the data want the factor: the optimiser stops at
    // 1.0006 × bound or on it; either way the fit is refused (relative, not absolute, check).
    let s = Scratch::new("bound-rel");
    let free = identify(&s, &["--no-design"]);
    assert!(free.status.success());
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(s.path("id.json")).unwrap()).unwrap();
    let p = json["parameters"][0]["identified"].as_f64().unwrap();
    std::fs::remove_file(s.path("id.toml")).unwrap();
    std::fs::remove_file(s.path("id.json")).unwrap();
    std::fs::write(s.path("cfg.toml"), format!("min_factor = {}\n", p / 1.0006)).unwrap();
    let cfg = s.path("cfg.toml");
    let out = identify(&s, &["--config", cfg.to_str().unwrap(), "--no-design"]);
    std::fs::remove_file(&cfg).unwrap();
    assert_refused(&s, &out, "z.guideway_normal ended at its bound");
}

#[test]
fn unknown_parameter_and_missing_measurement() {
    let s = Scratch::new("names");
    let out = identify(&s, &["--param", "q.guideway"]);
    assert_failed_cleanly(&s, &out, "parameter 'q.guideway': unknown axis 'q'");
    let out = Command::new(env!("CARGO_BIN_EXE_eij"))
        .current_dir(root())
        .args([
            "identify",
            "--measured",
            "measurements/nothing-here.csv",
            "--out",
        ])
        .arg(s.path("id.toml"))
        .arg("--report")
        .arg(s.path("id.json"))
        .output()
        .unwrap();
    assert_failed_cleanly(&s, &out, "measurements/nothing-here.csv: cannot read");
}

#[test]
fn measured_plane_the_model_cannot_simulate() {
    let s = Scratch::new("plane");
    let out = Command::new(env!("CARGO_BIN_EXE_eij"))
        .current_dir(root())
        .args([
            "identify",
            "--machine",
            "machines/reference/single-axis.toml",
            "--param",
            "x.guideway",
            "--measured",
            "measurements/demo-vmc/pos-a/xy_ccw_5.csv",
            "--out",
        ])
        .arg(s.path("id.toml"))
        .arg("--report")
        .arg(s.path("id.json"))
        .output()
        .unwrap();
    assert_failed_cleanly(
        &s,
        &out,
        "plane xy needs axis y, which the model single-axis does not have",
    );
}

#[test]
fn time_domain_and_harmonic_identifications_agree() {
    let h = Scratch::new("solver-h");
    let t = Scratch::new("solver-t");
    assert!(identify(&h, &["--solver", "harmonic"]).status.success());
    assert!(identify(&t, &["--solver", "time"]).status.success());
    let value = |s: &Scratch, i: usize| -> f64 {
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(s.path("id.json")).unwrap()).unwrap();
        json["parameters"][i]["identified"].as_f64().unwrap()
    };
    for i in 0..2 {
        let (a, b) = (value(&h, i), value(&t, i));
        assert!(
            (a / b - 1.0).abs() < 0.01,
            "parameter {i}: harmonic {a}, time {b}"
        );
    }
}

#[test]
fn nelder_mead_fallback_agrees_with_levenberg_marquardt() {
    let lm = Scratch::new("lm");
    let nm = Scratch::new("nm");
    assert!(identify(&lm, &[]).status.success());
    let out = identify(&nm, &["--method", "nelder-mead", "--max-iters", "500"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let value = |s: &Scratch, i: usize| -> f64 {
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(s.path("id.json")).unwrap()).unwrap();
        json["parameters"][i]["identified"].as_f64().unwrap()
    };
    for i in 0..2 {
        let (a, b) = (value(&lm, i), value(&nm, i));
        assert!(
            (a / b - 1.0).abs() < 0.01,
            "parameter {i}: LM {a}, Nelder-Mead {b}"
        );
    }
}

#[test]
fn default_outputs_are_named_after_the_machine() {
    let s = Scratch::new("mymill");
    let text = common::demo_text().replace("name = \"demo-vmc\"", "name = \"mymill\"");
    let machine = s.write("mymill.toml", text);
    let out = Command::new(env!("CARGO_BIN_EXE_eij"))
        .current_dir(&s.0)
        .args([
            "identify",
            "--quiet",
            "--no-design",
            "--param",
            "z.guideway_normal",
        ])
        .args(["--machine", &machine, "--measured"])
        .arg(root().join("measurements/demo-vmc/pos-a/zx_ccw_5.csv"))
        .arg(root().join("measurements/demo-vmc/pos-a/zx_cw_8.csv"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(s.path("out/mymill-identified.toml").is_file());
    assert!(s.path("out/mymill-identify-report.json").is_file());
    assert!(!s.path("out/demo-vmc-identified.toml").exists());
}

#[test]
fn a_file_without_its_set_radius_says_which_radius_was_assumed() {
    // A lone file (no rtest.toml beside it): identify takes its config radius (2 mm by default)
    // as the set radius and says so, with the data's own mean internal radius beside it.
    let s = Scratch::new("radius-fallback");
    let file = s.path("zx_ccw_5.csv");
    std::fs::copy(
        root().join("measurements/demo-vmc/pos-a/zx_ccw_5.csv"),
        &file,
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_eij"))
        .current_dir(root())
        .args([
            "identify",
            "--quiet",
            "--no-design",
            "--param",
            "z.guideway_normal",
        ])
        .args(["--position-mm", "150,-100,0", "--measured"])
        .arg(&file)
        .arg("--out")
        .arg(s.path("id.toml"))
        // Not the default report: that would replace out/demo-vmc-identify-report.json.
        .arg("--report")
        .arg(s.path("id.json"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("no set radius in the test's conditions")
            && stderr.contains("radius 2.0000 mm")
            && stderr.contains("mean internal radius is 1.9"),
        "{stderr}"
    );
}

/// The default output is a short verdict whose χ² line follows from the report's numbers;
/// `--tables` adds one line per measured EIJ under a header that explains its columns.
#[test]
fn default_output_is_a_short_verdict_and_tables_come_on_request() {
    let s = Scratch::new("print");
    let run = |extra: &[&str]| {
        let out = identify_command(&s)
            .arg("--no-design")
            .args(extra)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let short = run(&[]);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(s.path("id.json")).unwrap()).unwrap();
    assert!(short.lines().count() <= 30, "{short}");
    // χ²: s² against 1 + 4·√(2/dof), dof = values − free parameters − static terms − clocks.
    let statics: usize = json["static_terms"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| {
            g["geometric_um_per_mm"].as_object().unwrap().len()
                + g["reversal_um_per_mm"].as_object().unwrap().len()
        })
        .sum();
    let clocks = json["clock_offsets"].as_array().unwrap().len();
    let dof = json["residuals"].as_u64().unwrap() as usize - 2 - statics - clocks;
    assert_eq!(json["degrees_of_freedom"].as_u64().unwrap() as usize, dof);
    let s_fit = json["residual_std"].as_f64().unwrap();
    let limit = (1.0 + 4.0 * (2.0 / dof as f64).sqrt()).sqrt();
    let verdict = if s_fit <= limit { "passed" } else { "FAILED" };
    let expected = format!("χ² test {verdict}: s = {s_fit:.3}");
    assert!(short.contains(&expected), "'{expected}' not in {short}");
    assert!(short.contains(&format!("over {dof} degrees of freedom")));
    for p in json["parameters"].as_array().unwrap() {
        let (v, se) = (
            p["identified"].as_f64().unwrap(),
            p["std_err"].as_f64().unwrap(),
        );
        let line = short
            .lines()
            .find(|l| l.trim_start().starts_with(p["name"].as_str().unwrap()))
            .unwrap();
        assert!(line.contains(&format!("{:.1} %", 100.0 * se / v)), "{line}");
        let rel = se / v;
        let word = match rel {
            r if r <= 0.1 => "determined",
            r if r <= 0.5 => "loose",
            r if r <= 1.0 => "weak",
            _ => "NOT determined",
        };
        assert!(line.ends_with(word), "{line}");
    }
    assert!(
        !short.contains(" EZZ "),
        "the per-EIJ table is not in the short output"
    );

    let long = run(&["--tables"]);
    assert!(long.contains("'-' where the measured value is zero within 3σ"));
    let rows = long
        .lines()
        .filter(|l| l.contains(" m/s² @ ") && l.contains(" ± "))
        .count();
    assert_eq!(rows as u64, json["residuals"].as_u64().unwrap(), "{long}");
}
