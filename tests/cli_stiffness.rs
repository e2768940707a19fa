//! `eij stiffness` and `eij identify --stiffness-out` against a hand calculation written here:
//! catalogue N/µm from machines/catalogue/carriages.toml × factor, the screw shaft E·A/l₁ from
//! the machine file's own numbers, standard errors propagated from the factors'; and the table of
//! an identified machine file equal to the one `identify` wrote.

mod common;

use common::{one_line_error, root, run, Scratch, DEMO};
use std::collections::BTreeMap;

/// A table as rows of column → cell, and its header.
fn read_table(path: &std::path::Path) -> (Vec<String>, Vec<BTreeMap<String, String>>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|rec| {
            header
                .iter()
                .cloned()
                .zip(rec.unwrap().iter().map(String::from))
                .collect()
        })
        .collect();
    (header, rows)
}

fn num(row: &BTreeMap<String, String>, col: &str) -> f64 {
    row[col]
        .parse()
        .unwrap_or_else(|_| panic!("{col} = '{}' is not a number", row[col]))
}

fn toml_file(path: &str) -> toml::Value {
    toml::from_str(&std::fs::read_to_string(root().join(path)).unwrap()).unwrap()
}

/// The stiffness set of one axis of a machine file by hand, N/µm per element, with the factors
/// the file gives: (element, direction) → (count, file value, factor).
fn by_hand(machine: &toml::Value, axis: &str) -> BTreeMap<(String, String), (usize, f64, f64)> {
    let catalogue = toml_file("machines/catalogue/carriages.toml");
    let a = machine["axis"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"].as_str() == Some(axis))
        .unwrap();
    let f = |v: &toml::Value| v.as_float().or(v.as_integer().map(|i| i as f64)).unwrap();
    let factor = |t: &toml::Value, key: &str| t.get(key).map_or(1.0, f);
    let g = &a["guideway"];
    let id = g["carriage"].as_str().unwrap();
    let entry = catalogue["carriage"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"].as_str() == Some(id))
        .unwrap();
    // Linearised about the preload: normal = mean of radial and reverse-radial.
    let normal = 0.5 * (f(&entry["radial_n_per_um"]) + f(&entry["reverse_radial_n_per_um"]));
    let lateral = f(&entry["lateral_n_per_um"]);
    let carriages: usize = g["rail"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["carriages_m"].as_array().unwrap().len())
        .sum();
    let d = &a["drive"];
    let k = ["x", "y", "z"].iter().position(|c| *c == axis).unwrap();
    let l1 = (f(&d["nut_m"][k]) - f(&d["bearing_m"][k])).abs();
    let diameter = f(&d["screw_diameter_m"]);
    let modulus = d.get("screw_modulus_pa").map_or(2.1e11, f);
    let shaft = modulus * std::f64::consts::PI * diameter * diameter / 4.0 / l1 / 1e6;
    let r = factor(d, "reduction");
    let key = |e: &str, dir: &str| (e.to_string(), dir.to_string());
    BTreeMap::from([
        (
            key("guideway", "normal"),
            (carriages, normal, factor(g, "reduction_normal")),
        ),
        (
            key("guideway", "lateral"),
            (carriages, lateral, factor(g, "reduction_lateral")),
        ),
        (key("screw", "axial"), (1, shaft, r)),
        (key("nut", "axial"), (1, f(&d["nut_stiffness_n_per_um"]), r)),
        (
            key("bearing", "axial"),
            (1, f(&d["bearing_stiffness_n_per_um"]), r),
        ),
    ])
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

/// Checks every row of a table against the hand calculation on `machine` (a machine file's
/// parsed text).
fn check_against_hand(machine: &toml::Value, rows: &[BTreeMap<String, String>]) {
    assert_eq!(rows.len(), 15, "five rows per axis");
    for axis in ["x", "y", "z"] {
        let hand = by_hand(machine, axis);
        for ((element, direction), (count, file, factor)) in &hand {
            let row = rows
                .iter()
                .find(|r| {
                    r["axis"] == axis && &r["element"] == element && &r["direction"] == direction
                })
                .unwrap_or_else(|| panic!("no row {axis} {element} {direction}"));
            let what = format!("{axis} {element} {direction}");
            assert_eq!(row["count"], count.to_string(), "{what}");
            assert!(
                close(num(row, "file_n_per_um"), *file),
                "{what}: {row:?} vs {file}"
            );
            assert_eq!(num(row, "factor"), *factor, "{what}");
            assert!(
                close(num(row, "value_n_per_um"), file * factor),
                "{what}: {row:?} vs {}",
                file * factor
            );
        }
    }
}

#[test]
fn catalogue_model_table_is_the_hand_calculation() {
    let s = Scratch::new("stiff-cat");
    // The X drive scaled by hand, so the screw chain's factor is seen on its three rows.
    let text = common::demo_text().replacen(
        "support = \"fixed-free\"",
        "support = \"fixed-free\"\nreduction = 0.8",
        1,
    );
    let machine_path = s.write("m.toml", &text);
    let r = run(&[
        "stiffness",
        "--machine",
        &machine_path,
        "--out",
        &s.s("t.csv"),
    ]);
    assert!(r.ok, "{}", r.stderr);
    assert!(
        r.stdout.is_empty() && r.stderr == format!("eij: wrote {}\n", s.s("t.csv")),
        "{}{}",
        r.stdout,
        r.stderr
    );
    let (header, rows) = read_table(&s.path("t.csv"));
    assert_eq!(
        header,
        [
            "axis",
            "element",
            "direction",
            "count",
            "file_n_per_um",
            "factor",
            "value_n_per_um"
        ]
    );
    let machine: toml::Value = toml::from_str(&text).unwrap();
    check_against_hand(&machine, &rows);
    // Demo X: 2.1e11 Pa × π·(28 mm)²/4 / 550 mm = 235.1 N/µm, × 0.8.
    let x_screw = rows
        .iter()
        .find(|r| r["axis"] == "x" && r["element"] == "screw")
        .unwrap();
    assert!((num(x_screw, "value_n_per_um") - 0.8 * 235.105).abs() < 0.01);
    // Without --out: a readable table naming where the screw values hold.
    let r = run(&["stiffness", "--machine", DEMO]);
    assert!(r.ok, "{}", r.stderr);
    assert!(
        r.stdout
            .contains("x: nut 550 mm from the fixed bearing at x = 0.0 mm, 152.1 … 517.2 N/µm"),
        "{}",
        r.stdout
    );
}

#[test]
fn identified_table_is_catalogue_times_factor_and_the_exported_file_gives_it_again() {
    let s = Scratch::new("stiff-id");
    let r = run(&[
        "identify",
        "--quiet",
        "--out",
        &s.s("id.toml"),
        "--report",
        &s.s("id.json"),
        "--stiffness-out",
        &s.s("id.csv"),
    ]);
    assert!(r.ok, "{}", r.stderr);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(s.path("id.json")).unwrap()).unwrap();
    let (header, rows) = read_table(&s.path("id.csv"));
    assert_eq!(header.len(), 9);
    assert_eq!(&header[7..], ["std_err_n_per_um", "parameter"]);

    // Hand calculation on the catalogue model with the identified factors put in.
    let mut machine = toml_file(DEMO);
    for p in report["parameters"].as_array().unwrap() {
        let name = p["name"].as_str().unwrap();
        let (axis, kind) = name.split_once('.').unwrap();
        let key = match kind {
            "guideway_normal" => "reduction_normal",
            "guideway_lateral" => "reduction_lateral",
            other => panic!("unexpected default parameter {other}"),
        };
        let a = machine["axis"]
            .as_array_mut()
            .unwrap()
            .iter_mut()
            .find(|a| a["name"].as_str() == Some(axis))
            .unwrap();
        a["guideway"]
            .as_table_mut()
            .unwrap()
            .insert(key.into(), p["identified"].as_f64().unwrap().into());
        // Standard error of the value = catalogue value × standard error of the factor.
        let row = rows.iter().find(|r| r["parameter"] == name).unwrap();
        let std_err = p["std_err"].as_f64().unwrap();
        assert!(std_err > 0.0);
        assert!(close(
            num(row, "std_err_n_per_um"),
            num(row, "file_n_per_um") * std_err
        ));
    }
    check_against_hand(&machine, &rows);
    for r in &rows {
        let drive = r["element"] != "guideway";
        assert_eq!(r["std_err_n_per_um"].is_empty(), drive, "{r:?}");
        assert_eq!(r["parameter"].is_empty(), drive, "{r:?}");
    }
    // The demo's Z guideway: HIWIN HGH30CA ZA, 618 N/µm, × the identified factor (≈ 0.40).
    let z = rows
        .iter()
        .find(|r| r["axis"] == "z" && r["direction"] == "normal")
        .unwrap();
    assert_eq!(num(z, "file_n_per_um"), 618.0);
    assert!((num(z, "value_n_per_um") / 618.0 - 0.40).abs() < 0.02);

    // The report JSON holds the same rows (keys as the columns, null for an empty cell).
    let json_rows = report["stiffness"].as_array().unwrap();
    assert_eq!(json_rows.len(), rows.len());
    for (j, r) in json_rows.iter().zip(&rows) {
        for col in &header {
            let cell = match &j[col.as_str()] {
                serde_json::Value::Null => String::new(),
                serde_json::Value::String(t) => t.clone(),
                v => v.to_string(),
            };
            let same = match (cell.parse::<f64>(), r[col].parse::<f64>()) {
                (Ok(a), Ok(b)) => a == b,
                _ => cell == r[col],
            };
            assert!(same, "{col}: JSON {cell} vs CSV {}", r[col]);
        }
        assert_eq!(j.get("screw").is_some(), r["element"] == "screw");
    }
    let x_screw = &json_rows[2]["screw"];
    assert_eq!(x_screw["nut_bearing_mm"].as_f64(), Some(550.0));

    // ... and the HTML report shows them as a table.
    let r = run(&[
        "report",
        "--measured",
        "measurements/demo-vmc/pos-a/zx_ccw_5.csv",
        "--identify-report",
        &s.s("id.json"),
        "--out",
        &s.s("report"),
    ]);
    assert!(r.ok, "{}", r.stderr);
    let html = std::fs::read_to_string(s.path("report/report.html")).unwrap();
    let table = &html[html
        .find("Identified stiffness")
        .expect("no stiffness table")..];
    let table = &table[..table.find("</table>").unwrap()];
    assert_eq!(table.matches("<tr>").count(), 16, "header and 15 rows");
    let z_row = format!(
        "<td>{:.1}</td><td>{:.4}</td><td>{:.1}</td><td>{:.1}</td><td class=\"l\">z.guideway_normal</td>",
        num(z, "file_n_per_um"),
        num(z, "factor"),
        num(z, "value_n_per_um"),
        num(z, "std_err_n_per_um")
    );
    assert!(table.contains(&z_row), "{z_row} not in {table}");

    // eij stiffness of the identified machine file: the very same table, byte for byte.
    let r = run(&[
        "stiffness",
        "--machine",
        &s.s("id.toml"),
        "--out",
        &s.s("again.csv"),
    ]);
    assert!(r.ok, "{}", r.stderr);
    assert_eq!(
        std::fs::read_to_string(s.path("again.csv")).unwrap(),
        std::fs::read_to_string(s.path("id.csv")).unwrap()
    );

    // A factor edited after the identification loses its recorded standard error, said on
    // standard error; the rest of the table stands.
    let edited = std::fs::read_to_string(s.path("id.toml"))
        .unwrap()
        .replacen("reduction_normal = ", "reduction_normal = 0.5 #", 1);
    let path = s.write("edited.toml", edited);
    let r = run(&["stiffness", "--machine", &path, "--out", &s.s("edited.csv")]);
    assert!(r.ok, "{}", r.stderr);
    assert!(
        r.stderr
            .contains("x.guideway_normal = 0.5 differs from the identified"),
        "{}",
        r.stderr
    );
    let (_, rows) = read_table(&s.path("edited.csv"));
    let x = rows
        .iter()
        .find(|r| r["axis"] == "x" && r["direction"] == "normal")
        .unwrap();
    assert_eq!(
        (x["factor"].as_str(), x["std_err_n_per_um"].as_str()),
        ("0.5", "")
    );
    assert!(
        rows.iter()
            .filter(|r| !r["std_err_n_per_um"].is_empty())
            .count()
            == 5
    );
}

#[test]
fn a_refused_identification_writes_no_table() {
    let s = Scratch::new("stiff-refused");
    let zx = "measurements/demo-vmc/pos-a/zx_ccw_5.csv";
    std::fs::write(s.path("cfg.toml"), "min_factor = 0.6\n").unwrap();
    for extra in [vec!["--max-iters", "1"], vec!["--config", &s.s("cfg.toml")]] {
        let mut args = vec![
            "identify",
            "--quiet",
            "--param",
            "z.guideway_normal",
            "--measured",
            zx,
            "--out",
        ];
        let (out, rep, tab) = (s.s("id.toml"), s.s("id.json"), s.s("id.csv"));
        args.extend([out.as_str(), "--report", &rep, "--stiffness-out", &tab]);
        args.extend(extra);
        // The fit's warnings (standard error, always), then one line with the diagnosis.
        let run = common::eij(&args);
        assert!(!run.status.success());
        let stderr = String::from_utf8_lossy(&run.stderr);
        let line = stderr.lines().last().unwrap_or_default();
        assert!(line.starts_with("eij: error: "), "{stderr}");
        assert!(
            stderr
                .lines()
                .all(|l| l == line || l.starts_with("warning: ")),
            "{stderr}"
        );
        assert!(
            line.contains("did not converge") || line.contains("ended at its bound"),
            "{line}"
        );
        assert!(!s.path("id.csv").exists(), "table written by a refused fit");
        assert!(!s.path("id.toml").exists());
    }
}

#[test]
fn bad_machine_and_outputs_are_refused_in_one_line() {
    let s = Scratch::new("stiff-bad");
    one_line_error(
        &common::eij(&[
            "stiffness",
            "--machine",
            "machines/nothing.toml",
            "--out",
            &s.s("t.csv"),
        ]),
        &["machines/nothing.toml"],
    );
    one_line_error(
        &common::eij(&[
            "stiffness",
            "--machine",
            DEMO,
            "--out",
            &s.s("no-such/t.csv"),
        ]),
        &["no-such", "does not exist"],
    );
    let copy = s.write("m.toml", common::demo_text());
    one_line_error(
        &common::eij(&["stiffness", "--machine", &copy, "--out", &copy]),
        &["refusing to overwrite an input file"],
    );
    let broken = s.write(
        "broken.toml",
        common::demo_text().replace("carriage = \"HIWIN HGH25CA ZA\"", "carriage = \"HGX\""),
    );
    one_line_error(
        &common::eij(&["stiffness", "--machine", &broken, "--out", &s.s("t.csv")]),
        &[
            "broken.toml",
            "axis[x].guideway.carriage",
            "unknown catalogue entry 'HGX'",
        ],
    );
    assert!(!s.path("t.csv").exists());
    assert_eq!(std::fs::read_to_string(&copy).unwrap(), common::demo_text());
}
