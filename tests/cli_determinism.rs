//! Results are deterministic: the same command gives byte-identical output across runs and for
//! any number of worker threads (`RAYON_NUM_THREADS=1` vs `2`). The full demo identification
//! across thread counts is pinned by `tests/cli_identify.rs`
//! (`reports_are_identical_across_runs_and_thread_counts`).

mod common;

use common::{root, Scratch};
use std::process::Command;

/// Runs `eij args…` with `threads` rayon workers; returns standard output and the bytes of each
/// of `outputs` (which are removed afterwards, so that every run writes them anew).
fn run(args: &[&str], threads: &str, outputs: &[&str]) -> (Vec<u8>, Vec<Vec<u8>>) {
    let out = Command::new(env!("CARGO_BIN_EXE_eij"))
        .current_dir(root())
        .env("RAYON_NUM_THREADS", threads)
        .env("SOURCE_DATE_EPOCH", "1700000000")
        .args(args)
        .output()
        .expect("run eij");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let files = outputs
        .iter()
        .map(|p| {
            let bytes = std::fs::read(p).unwrap();
            std::fs::remove_file(p).unwrap();
            bytes
        })
        .collect();
    (out.stdout, files)
}

/// Two runs with one thread and one with two give the same bytes.
fn assert_deterministic(args: &[&str], outputs: &[&str]) -> (Vec<u8>, Vec<Vec<u8>>) {
    let first = run(args, "1", outputs);
    assert_eq!(first, run(args, "1", outputs), "{args:?}: two runs differ");
    assert_eq!(
        first,
        run(args, "2", outputs),
        "{args:?}: 1 and 2 threads differ"
    );
    first
}

#[test]
fn evaluate_json_is_deterministic() {
    let (stdout, _) = assert_deterministic(
        &[
            "evaluate",
            "--json",
            "--pooled",
            "measurements/demo-vmc/pos-a/zx_ccw_2.csv",
            "measurements/demo-vmc/pos-a/zx_ccw_5.csv",
            "measurements/demo-vmc/pos-a/zx_ccw_8.csv",
        ],
        &[],
    );
    let json: serde_json::Value = serde_json::from_slice(&stdout).unwrap();
    assert_eq!(json["tests"].as_array().unwrap().len(), 3);
}

#[test]
fn noisy_simulation_is_deterministic_for_a_seed() {
    let s = Scratch::new("simulate");
    let out = s.s("c.csv");
    let args = |seed: &'static str| {
        vec![
            "simulate",
            "circle",
            "--machine",
            "machines/demo-vmc.toml",
            "--plane",
            "zx",
            "--radius-mm",
            "2",
            "--accel-m-s2",
            "5",
            "--direction",
            "ccw",
            "--rate-hz",
            "2000",
            "--noise-um",
            "1.4",
            "--seed",
            seed,
            "--out",
            &out,
        ]
    };
    let (_, seven) = assert_deterministic(&args("7"), &[&out]);
    let (_, eight) = run(&args("8"), "1", &[&out]);
    assert_ne!(seven, eight, "the seed does not change the noise");
}

#[test]
fn map_is_deterministic() {
    let s = Scratch::new("map");
    let out = s.s("m.csv");
    let (_, files) = assert_deterministic(
        &[
            "map",
            "--machine",
            "machines/demo-vmc.toml",
            "--plane",
            "zx",
            "--accel-m-s2",
            "5",
            "--grid",
            "x=-200:200:3",
            "--grid",
            "z=0:200:2",
            "--out",
            &out,
        ],
        &[&out],
    );
    assert_eq!(String::from_utf8_lossy(&files[0]).lines().count(), 1 + 6);
}

#[test]
fn small_identification_is_deterministic() {
    let s = Scratch::new("identify");
    let (out, report) = (s.s("id.toml"), s.s("id.json"));
    assert_deterministic(
        &[
            "identify",
            "--machine",
            "machines/demo-vmc.toml",
            "--measured",
            "measurements/demo-vmc/pos-a/zx_ccw_5.csv",
            "measurements/demo-vmc/pos-a/zx_ccw_8.csv",
            "--param",
            "z.guideway_normal",
            "--param",
            "x.guideway_normal",
            "--quiet",
            "--out",
            &out,
            "--report",
            &report,
        ],
        &[&out, &report],
    );
}

/// `simulate circle` streams its CSV block by block (2048 samples) unless a figure needs the
/// whole run: both give the same bytes, noise included, across block boundaries (10 kHz, five
/// blocks), and leave no temporary file behind.
#[test]
fn streamed_csv_equals_the_whole_run_csv() {
    let s = Scratch::new("stream");
    let (streamed, whole, plot) = (s.s("streamed.csv"), s.s("whole.csv"), s.s("c.svg"));
    let args = |out: &str| -> Vec<String> {
        [
            "simulate",
            "circle",
            "--machine",
            "machines/demo-vmc.toml",
            "--plane",
            "xy",
            "--radius-mm",
            "2",
            "--accel-m-s2",
            "5",
            "--direction",
            "cw",
            "--revolutions",
            "3",
            "--noise-um",
            "1.4",
            "--out",
            out,
        ]
        .iter()
        .map(|a| a.to_string())
        .collect()
    };
    let streamed_args = args(&streamed);
    let mut whole_args = args(&whole);
    whole_args.extend(["--plot".to_string(), plot.clone()]);
    for a in [&streamed_args, &whole_args] {
        let a: Vec<&str> = a.iter().map(|s| s.as_str()).collect();
        run(&a, "2", &[]);
    }
    let (a, b) = (
        std::fs::read(&streamed).unwrap(),
        std::fs::read(&whole).unwrap(),
    );
    assert!(a.iter().filter(|&&c| c == b'\n').count() > 4 * 2048);
    assert!(a == b, "streamed and whole-run CSV differ");
    let names: Vec<String> = std::fs::read_dir(&s.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 3, "{names:?}");
}
