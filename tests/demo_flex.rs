//! The flexible demo end to end: `eij identify` of `machines/demo-vmc-flex.toml` (elastic
//! column) on the generated R-Test set `measurements/demo-vmc-flex/` (pos-a, pos-b) recovers
//! every factor of the generator's truth file within 3 standard errors and predicts the held-out
//! circle centre pos-c within its measurement uncertainty; the rigid demo machine cannot
//! reproduce the same data (χ² and hold-out both fail), so the data tell the two models apart.
//! And the same column as exported FE files (`machines/demo-vmc-flex-fe.toml`, written by
//! `cargo run --release --example demo_column_fe`) gives the beam's EIJ.

use eij::axes::{Direction, Plane};
use eij::ident::Parameter;
use eij::predict::{simulated_eij, CircleTest, SimSettings};
use eij::Machine;
use serde_json::Value;

mod common;

use common::{machine as load, root, run, Scratch};

const TRUTH: &str = "measurements/demo-vmc-flex/generator/demo-vmc-flex-true.toml";

/// `eij identify` of `machine` on pos-a and pos-b, validated on pos-c, without the ranking of
/// candidate tests: (exit status 0, the report JSON).
fn identify(machine: &str, s: &Scratch) -> (bool, Value) {
    let (out, report) = (s.s("id.toml"), s.s("id.json"));
    let r = run(&[
        "identify",
        "--machine",
        machine,
        "--measured",
        "measurements/demo-vmc-flex/pos-a",
        "measurements/demo-vmc-flex/pos-b",
        "--validate",
        "measurements/demo-vmc-flex/pos-c",
        "--no-design",
        "--quiet",
        "--out",
        &out,
        "--report",
        &report,
    ]);
    let json = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    (r.ok, json)
}

#[test]
fn the_flexible_demo_recovers_its_truth_and_predicts_the_third_circle_centre() {
    let s = Scratch::new("demo-flex");
    let (ok, json) = identify("machines/demo-vmc-flex.toml", &s);
    assert!(ok, "{json}");
    let truth = Machine::from_file(&root().join(TRUTH)).unwrap();
    let parameters = json["parameters"].as_array().unwrap();
    let names: Vec<&str> = parameters
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert!(names.contains(&"column.stiffness"), "{names:?}");
    assert_eq!(names.len(), 7, "{names:?}");
    for p in parameters {
        let name = p["name"].as_str().unwrap();
        let want = Parameter::parse(name, &truth).unwrap().get(&truth);
        let (value, std_err) = (
            p["identified"].as_f64().unwrap(),
            p["std_err"].as_f64().unwrap(),
        );
        assert!(
            (value - want).abs() <= 3.0 * std_err,
            "{name} = {value} ± {std_err}, truth {want}"
        );
        assert!(std_err < 0.1 * value, "{name}: {std_err} of {value}");
    }
    assert_eq!(json["warnings"].as_array().unwrap().len(), 0, "{json}");
    let v = &json["validation"];
    assert_eq!(v["values"].as_u64(), Some(108));
    assert_eq!(v["passed"].as_bool(), Some(true), "{v}");
}

#[test]
fn the_rigid_demo_machine_cannot_reproduce_the_flexible_demo_data() {
    let s = Scratch::new("demo-flex-rigid");
    let (_, json) = identify("machines/demo-vmc.toml", &s);
    let warnings: Vec<&str> = json["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect();
    assert!(
        warnings.iter().any(|w| w.starts_with("χ² test failed")),
        "{warnings:?}"
    );
    assert!(json["residual_std"].as_f64().unwrap() > 3.0, "{json}");
    assert_eq!(
        json["validation"]["passed"].as_bool(),
        Some(false),
        "{}",
        json["validation"]
    );
}

#[test]
fn the_column_from_exported_fe_files_gives_the_eij_of_the_beam() {
    // The files hold the beam's matrices to 17 digits (an exact round trip), in another node
    // numbering and equation order: the two reductions differ by rounding alone (~1e-13), so
    // 1e-9 of the largest EIJ is a wide margin that a wrong DOF map (a rotation read as a
    // translation, a node swapped) exceeds by orders of magnitude.
    let beam = load("demo-vmc-flex.toml");
    let fe = load("demo-vmc-flex-fe.toml");
    let column = |m: &Machine| {
        m.bodies()
            .iter()
            .find(|b| b.name == "column")
            .cloned()
            .unwrap()
    };
    let (a, b) = (column(&beam), column(&fe));
    assert!(a.elastic().is_some() && b.elastic().is_some());
    assert!((a.mass_kg - b.mass_kg).abs() < 1e-9 * a.mass_kg);
    assert!((a.cog_m - b.cog_m).norm() < 1e-12);
    assert!((a.inertia_kg_m2 - b.inertia_kg_m2).abs().max() < 1e-9 * a.inertia_kg_m2.max());
    let circles: Vec<CircleTest> = [[0.15, -0.1, 0.0], [-0.15, 0.1, 0.25], [0.0, 0.05, 0.12]]
        .iter()
        .flat_map(|p| {
            Plane::ALL.map(|plane| CircleTest::new(plane, Direction::Ccw, 2.0, 8.0).at(p.to_vec()))
        })
        .collect();
    let eij = simulated_eij(&[beam, fe], &circles, &SimSettings::default()).unwrap();
    let scale = eij[0]
        .iter()
        .flat_map(|m| m.values())
        .fold(0.0f64, |s, v| s.max(v.abs()));
    for ((from_beam, from_files), circle) in eij[0].iter().zip(&eij[1]).zip(&circles) {
        for (k, v) in from_beam {
            assert!(
                (from_files[k] - v).abs() <= 1e-9 * scale,
                "{} {k}: {} from the files, {v} from the beam",
                circle.label(),
                from_files[k]
            );
        }
    }
}
