//! Bad outputs through the binary (issue 8, catalogue in `docs/bad-inputs.md`): an output that
//! cannot be written (a missing folder, a folder, an input) is refused with one line `eij:
//! error: …` before anything is written; an existing output is replaced atomically. Inputs are
//! in cli_bad_input.rs.

mod common;

use common::bad_input::{circle, identify, map, measured_with_conditions, refused};
use common::{eij, root, Scratch, DEMO, ZX_CSV};
use std::path::Path;

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
