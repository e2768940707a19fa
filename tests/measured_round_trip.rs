//! Round trips (docs/eij-table.md): `eij evaluate --csv-out` writes every test's set radius and
//! circle centre, and `eij identify --measured TABLE` fitted on that table gives the factors of
//! the folders it was written from, each within its standard error; a table without centres
//! beside folders at two centres is refused; `evaluate --pooled` pools per plane and centre.
//!
//! Data: the generated demo set `measurements/demo-vmc` (36 tests at two centres, truth in its
//! README); the centres the table must carry are the folders' `rtest.toml` values.

mod common;

use common::{identified as factors, one_line_error, run, Scratch};
use eij::axes::Plane;
use eij::measured::table;

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

fn identify(s: &Scratch, tag: &str, measured: &[&str]) -> serde_json::Value {
    let (out, rep) = (s.s(&format!("{tag}.toml")), s.s(&format!("{tag}.json")));
    let mut args = vec![
        "identify",
        "--machine",
        "machines/demo-vmc.toml",
        "--measured",
    ];
    args.extend(measured);
    args.extend(["--no-design", "--quiet", "--out", &out, "--report", &rep]);
    let r = run(&args);
    assert!(r.ok, "{tag}: {}", r.stderr);
    json(&s.path(&format!("{tag}.json")))
}

/// The table of the 36 demo tests carries their centres (108 rows at each `rtest.toml`
/// position) and radius 2 mm; identify on it gives the folders' six factors, each within its
/// standard error.
#[test]
fn evaluate_csv_out_fed_to_identify_gives_the_folders_factors() {
    let s = Scratch::new("round-trip");
    let csv = s.s("eij.csv");
    let r = run(&["evaluate", "measurements/demo-vmc", "--csv-out", &csv]);
    assert!(r.ok, "{}", r.stderr);
    let rows = table::read(&csv).unwrap();
    assert_eq!(rows.len(), 36 * 6);
    for centre in [[150.0, -100.0, 0.0], [-150.0, 100.0, 0.0]] {
        let n = rows
            .iter()
            .filter(|r| r.position_mm == Some(centre))
            .count();
        assert_eq!(n, 18 * 6, "{centre:?}");
    }
    assert!(rows.iter().all(|r| r.radius_mm == Some(2.0)));

    let folders = identify(&s, "folders", &["measurements/demo-vmc"]);
    let tables = identify(&s, "table", &[&csv]);
    let (f, t) = (factors(&folders), factors(&tables));
    assert_eq!(f.len(), 6);
    for ((name, a, se), (name_t, b, se_t)) in f.iter().zip(&t) {
        assert_eq!(name, name_t);
        assert!(
            (a - b).abs() < *se,
            "{name}: folders {a} ± {se}, table {b} ± {se_t}"
        );
        // The table's standard errors are the evaluation's: the same information.
        assert!(se_t / se > 0.5 && se_t / se < 2.0, "{name}: {se} vs {se_t}");
    }
    assert_eq!(tables["tests"].as_array().unwrap().len(), 36);
}

/// The same table without its centres, given with the two folders (centres [150, −100, 0] and
/// [−150, 100, 0] mm), is refused with one line naming both; alone it is still read (one
/// centre: nothing to tell apart).
#[test]
fn a_table_without_centres_beside_several_centres_is_refused() {
    let s = Scratch::new("round-trip-old");
    let csv = s.s("pos-b.csv");
    let r = run(&["evaluate", "measurements/demo-vmc/pos-b", "--csv-out", &csv]);
    assert!(r.ok, "{}", r.stderr);
    let mut rows = table::read(&csv).unwrap();
    for r in &mut rows {
        r.position_mm = None;
    }
    let old = s.path("old.csv");
    table::write(&old, &rows, &[]).unwrap();
    let old = old.display().to_string();
    let (out, rep) = (s.s("id.toml"), s.s("id.json"));
    let args = |measured: &[&str]| {
        let mut a = vec![
            "identify",
            "--machine",
            "machines/demo-vmc.toml",
            "--measured",
        ];
        a.extend(measured.iter().copied());
        a.extend(["--no-design", "--quiet", "--out", &out, "--report", &rep]);
        a.iter().map(|s| s.to_string()).collect::<Vec<String>>()
    };
    let a = args(&[
        "measurements/demo-vmc/pos-a",
        "measurements/demo-vmc/pos-b",
        &old,
    ]);
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    one_line_error(
        &common::eij(&a),
        &[
            "old.csv",
            "the table gives no circle centre",
            "2 centres ([150, -100, 0], [-150, 100, 0] mm)",
        ],
    );
    assert!(!s.path("id.json").exists());
}

/// `--pooled` on a folder of three planes: one pooled fit per plane at the folder's centre,
/// each the pooled fit of that plane's files alone (to 1e-9 µm·s²/m).
#[test]
fn pooled_pools_per_plane() {
    let r = run(&[
        "evaluate",
        "measurements/demo-vmc/pos-a",
        "--pooled",
        "--json",
    ]);
    assert!(r.ok, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let pooled = v["pooled"].as_array().unwrap();
    let planes: Vec<&str> = pooled
        .iter()
        .map(|p| p["plane"].as_str().unwrap())
        .collect();
    assert_eq!(planes, ["xy", "yz", "zx"]);
    for p in pooled {
        assert_eq!(p["position_mm"], serde_json::json!([150.0, -100.0, 0.0]));
        let plane: Plane = p["plane"].as_str().unwrap().parse().unwrap();
        let files: Vec<String> = ["cw", "ccw"]
            .iter()
            .flat_map(|d| {
                [2, 5, 8].map(|a| format!("measurements/demo-vmc/pos-a/{plane}_{d}_{a}.csv"))
            })
            .collect();
        let mut args = vec!["evaluate", "--pooled", "--json"];
        args.extend(files.iter().map(String::as_str));
        let alone = run(&args);
        assert!(alone.ok, "{}", alone.stderr);
        let w: serde_json::Value = serde_json::from_str(&alone.stdout).unwrap();
        let q = &w["pooled"][0];
        for (k, val) in p["eij_um_s2_per_m"].as_object().unwrap() {
            let other = q["eij_um_s2_per_m"][k].as_f64().unwrap();
            assert!((val.as_f64().unwrap() - other).abs() < 1e-9, "{plane} {k}");
        }
    }
}
