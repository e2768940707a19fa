//! Bad machine files through the binary: one clear line naming file and key, non-zero exit,
//! no panic, no output file.

mod common;

use common::{demo_text, Scratch};
use std::process::Command;

/// Runs `eij <args…> --machine <file with text>`; returns (success, stderr).
fn run_with_machine(tag: &str, text: &str, args: &[&str]) -> (bool, String, bool) {
    let dir = Scratch::new(&format!("machine-{tag}"));
    let file = dir.0.join("machine.toml");
    std::fs::write(&file, text).unwrap();
    let out_file = dir.0.join("out.json");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_eij"));
    cmd.args(args).arg("--machine").arg(&file);
    if args[0] != "modal" {
        cmd.arg("--out").arg(&out_file);
    }
    let out = cmd.output().unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stderr).unwrap(),
        out_file.exists(),
    )
}

fn assert_one_line_error(tag: &str, text: &str, expected: &[&str]) {
    for args in [&["modal"][..], &["export"][..]] {
        let (ok, stderr, wrote) = run_with_machine(tag, text, args);
        assert!(!ok, "{tag}: {args:?} succeeded");
        assert!(!wrote, "{tag}: output written despite the error");
        assert_eq!(
            stderr.lines().count(),
            1,
            "{tag}: stderr not one line:\n{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{tag}: {stderr}");
        assert!(
            stderr.contains("machine.toml"),
            "{tag}: file not named: {stderr}"
        );
        for e in expected {
            assert!(stderr.contains(e), "{tag}: '{e}' not in: {stderr}");
        }
    }
}

#[test]
fn demo_machine_is_accepted() {
    let (ok, stderr, wrote) = run_with_machine("ok", &demo_text(), &["export"]);
    assert!(ok && wrote, "{stderr}");
}

#[test]
fn a_nest_away_from_the_tool_is_refused() {
    // The R-Test nest is set up under the tool: a workpiece point elsewhere contradicts it.
    let t = demo_text().replace(
        "body = \"table\"\npoint_m = [0.0, 0.0, 0.05]",
        "body = \"table\"\npoint_m = [0.1, 0.0, 0.05]",
    );
    assert_ne!(t, demo_text());
    assert_one_line_error(
        "nest_away",
        &t,
        &[
            "workpiece.point_m",
            "not the TCP at the reference position",
            "under the tool",
        ],
    );
    // Without the point the file means the same machine.
    let t = demo_text().replace(
        "body = \"table\"\npoint_m = [0.0, 0.0, 0.05]\n",
        "body = \"table\"\n",
    );
    assert_ne!(t, demo_text());
    let (ok, stderr, wrote) = run_with_machine("nest_implied", &t, &["export"]);
    assert!(ok && wrote, "{stderr}");
}

#[test]
fn zero_and_negative_mass() {
    let t = demo_text().replace("mass_kg = 450.0", "mass_kg = 0.0");
    assert_one_line_error("zero-mass", &t, &["body[table].mass_kg", "must be > 0"]);
    let t = demo_text().replace("mass_kg = 650.0", "mass_kg = -650.0");
    assert_one_line_error("neg-mass", &t, &["body[saddle].mass_kg", "must be > 0"]);
}

#[test]
fn inertia_not_positive_definite_or_not_physical() {
    let t = demo_text().replace(
        "inertia_kg_m2 = [[12.0, 0.0, 0.0], [0.0, 35.0, 0.0], [0.0, 0.0, 45.0]]",
        "inertia_kg_m2 = [[12.0, 0.0, 0.0], [0.0, -35.0, 0.0], [0.0, 0.0, 45.0]]",
    );
    assert_one_line_error(
        "inertia-pd",
        &t,
        &["body[table].inertia_kg_m2", "not positive definite"],
    );
    let t = demo_text().replace(
        "inertia_kg_m2 = [[12.0, 0.0, 0.0], [0.0, 35.0, 0.0], [0.0, 0.0, 45.0]]",
        "inertia_kg_m2 = [[1.0, 0.0, 0.0], [0.0, 35.0, 0.0], [0.0, 0.0, 45.0]]",
    );
    assert_one_line_error(
        "inertia-triangle",
        &t,
        &["body[table].inertia_kg_m2", "triangle inequality"],
    );
    let t = demo_text().replace(
        "inertia_kg_m2 = [[12.0, 0.0, 0.0], [0.0, 35.0, 0.0], [0.0, 0.0, 45.0]]",
        "inertia_kg_m2 = [[12.0, 3.0, 0.0], [0.0, 35.0, 0.0], [0.0, 0.0, 45.0]]",
    );
    assert_one_line_error(
        "inertia-sym",
        &t,
        &["body[table].inertia_kg_m2", "symmetric"],
    );
}

#[test]
fn unknown_catalogue_entry_and_body() {
    let t = demo_text().replace(
        "carriage = \"HIWIN HGH25CA ZA\"",
        "carriage = \"HIWIN HGH99CA ZA\"",
    );
    assert_one_line_error(
        "catalogue",
        &t,
        &[
            "axis[x].guideway.carriage",
            "unknown catalogue entry 'HIWIN HGH99CA ZA'",
        ],
    );
    let t = demo_text().replace("carrier = \"saddle\"", "carrier = \"sadle\"");
    assert_one_line_error("body", &t, &["axis[x].carrier", "unknown body 'sadle'"]);
}

#[test]
fn carriages_that_cannot_support_a_body() {
    // All four X carriages on one line: the table can roll about it.
    let t = demo_text().replace(
        "carriages_m = [[-0.2, 0.2, -0.16], [0.2, 0.2, -0.16]]",
        "carriages_m = [[-0.1, -0.2, -0.16], [0.1, -0.2, -0.16]]",
    );
    assert_one_line_error("singular", &t, &["cannot support the structure", "table."]);
}

#[test]
fn negative_stiffness_and_reduction_factor() {
    let t = demo_text().replace(
        "[axis.guideway]\ncarriage = \"HIWIN HGH25CA ZA\"",
        "[axis.guideway]\ncarriage = \"HIWIN HGH25CA ZA\"\nreduction_normal = -0.5",
    );
    assert_one_line_error(
        "reduction",
        &t,
        &["axis[x].guideway.reduction_normal", "-0.5 must be > 0"],
    );
    let t = demo_text().replace(
        "nut_stiffness_n_per_um = 900.0",
        "nut_stiffness_n_per_um = -900.0",
    );
    assert_one_line_error(
        "nut",
        &t,
        &["axis[x].drive.nut_stiffness_n_per_um", "must be > 0"],
    );
    let t = demo_text().replace(
        "stiffness_n_per_m = [1.3e8, 1.3e8, 2.5e8]",
        "stiffness_n_per_m = [1.0e8, -1.0e8, 2.5e8]",
    );
    assert_one_line_error(
        "joint",
        &t,
        &["joint[foot-front-left].stiffness_n_per_m", "must be ≥ 0"],
    );
}

#[test]
fn unknown_key_and_broken_toml_are_located() {
    let t = demo_text().replace(
        "lead_m = 0.02\nscrew_diameter_m = 0.028",
        "lead_m = 0.02\nscrew_diamter_m = 0.028",
    );
    assert_one_line_error(
        "unknown-key",
        &t,
        &["line ", "unknown field `screw_diamter_m`"],
    );
    let t = demo_text().replace("mass_kg = 450.0", "mass_kg = 450.0.0");
    assert_one_line_error("syntax", &t, &["line 42, column 16", "invalid float"]);
}

#[test]
fn unstable_gains_name_the_axis() {
    let t = demo_text().replacen("kp_nm_s_per_rad = 5.0", "kp_nm_s_per_rad = 5000.0", 1);
    let (ok, stderr, wrote) = run_with_machine("unstable", &t, &["export"]);
    assert!(!ok && !wrote);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("closed loop unstable at axis y") && stderr.contains("lower kv_per_s"),
        "{stderr}"
    );
}

#[test]
fn missing_machine_file() {
    let out = Command::new(env!("CARGO_BIN_EXE_eij"))
        .args(["modal", "--machine", "no/such/machine.toml"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(stderr.lines().count(), 1);
    assert!(
        stderr.contains("no/such/machine.toml: file: cannot read"),
        "{stderr}"
    );
}
