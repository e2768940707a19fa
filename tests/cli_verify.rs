//! Regression on known-good fits: `eij verify` re-runs every stored identification in
//! tests/known-good and must report no drift.

use std::process::Command;

#[test]
fn known_good_identifications_do_not_drift() {
    let out = Command::new(env!("CARGO_BIN_EXE_eij"))
        .arg("verify")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("ok")).count(),
        6,
        "{stdout}"
    );
}

#[test]
fn a_drifted_value_fails_verify_with_one_line() {
    let dir = std::env::temp_dir().join(format!("eij-known-good-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let root = env!("CARGO_MANIFEST_DIR");
    let file = dir.join("drift.toml");
    std::fs::write(
        &file,
        format!(
            "description = \"z only, expected value off on purpose\"\nmachine = \"{root}/machines/demo-vmc.toml\"\nmeasured = [\"{root}/measurements/demo-vmc/pos-a/zx_ccw_5.csv\", \"{root}/measurements/demo-vmc/pos-a/zx_ccw_8.csv\", \"{root}/measurements/demo-vmc/pos-b/zx_cw_5.csv\"]\n[settings]\nparameters = [\"z.guideway_normal\"]\n[expected.\"z.guideway_normal\"]\nvalue = 0.5\nrel_tol = 0.01\n"
        ),
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_eij"))
        .arg("verify")
        .arg(&file)
        .output()
        .unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(!out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stdout.starts_with("FAIL"), "{stdout}");
    // The fit's warnings (standard error, always), then one line with the verdict.
    let last = stderr.lines().last().unwrap_or_default();
    assert!(last.contains("1 known-good value(s) drifted"), "{stderr}");
    assert!(
        stderr
            .lines()
            .all(|l| l == last || l.starts_with("warning: ")),
        "{stderr}"
    );
}
