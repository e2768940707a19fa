//! The flexible demo end to end: `eij identify` of `machines/demo-vmc-flex.toml` (elastic
//! column) on the generated R-Test set `measurements/demo-vmc-flex/` (pos-a, pos-b) recovers
//! every factor of the generator's truth file within 3 standard errors and predicts the held-out
//! circle centre pos-c within its measurement uncertainty; the rigid demo machine cannot
//! reproduce the same data (χ² and hold-out both fail), so the data tell the two models apart.

use eij::ident::Parameter;
use eij::Machine;
use serde_json::Value;

mod common;

use common::{root, run, Scratch};

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
