//! `eij compare`: the command line of the model comparison (issue 28 item 3) — its report JSON
//! keys, the criteria recomputed from the numbers it writes, the winner against the
//! generator's truth, exit codes and bad input.

use serde_json::Value;

mod common;

use common::{eij, one_line_error, root, run, Scratch};

const FLEX_A: &str = "measurements/demo-vmc-flex/pos-a";
const FLEX_B: &str = "measurements/demo-vmc-flex/pos-b";

fn read_json(path: &str) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn compare_prefers_the_elastic_column_on_its_data_and_writes_every_key() {
    let s = Scratch::new("cli-compare");
    let report = s.s("compare.json");
    let r = run(&[
        "compare",
        "--machine",
        "machines/demo-vmc.toml",
        "--machine",
        "machines/demo-vmc-flex.toml",
        "--measured",
        FLEX_A,
        FLEX_B,
        "--report",
        &report,
    ]);
    assert!(r.ok, "{}", r.stderr);
    let json = read_json(&report);
    // The generator's truth has an elastic column.
    let truth = eij::Machine::from_file(
        &root().join("measurements/demo-vmc-flex/generator/demo-vmc-flex-true.toml"),
    )
    .unwrap();
    assert!(truth.bodies().iter().any(|b| b.elastic().is_some()));
    assert_eq!(json["preferred"], "demo-vmc-flex", "{}", json["verdict"]);
    assert_eq!(json["reproduced"], true);
    for key in [
        "eij_version",
        "date",
        "measured_inputs",
        "residuals",
        "criterion",
        "verdict",
    ] {
        assert!(!json[key].is_null(), "{key}");
    }
    let m = json["residuals"].as_u64().unwrap();
    assert_eq!(m, 216, "36 tests × 6 EIJ");
    let candidates = json["candidates"].as_array().unwrap();
    assert_eq!(candidates.len(), 2);
    for c in candidates {
        for key in [
            "label",
            "machine_file",
            "status",
            "reason",
            "chi2",
            "residual_std",
            "degrees_of_freedom",
            "s_limit",
            "chi2_passed",
            "free_parameters",
            "static_terms",
            "clock_offsets",
            "k",
            "bic",
            "aic",
            "delta_bic",
            "delta_aic",
            "worst_group",
            "groups",
            "holdout",
            "identify_report",
        ] {
            assert!(!c[key].is_null(), "{}: {key}", c["label"]);
        }
        // The criteria from the numbers written beside them.
        let chi2 = c["chi2"].as_f64().unwrap();
        let k = c["k"].as_u64().unwrap();
        let parts: u64 = ["free_parameters", "static_terms", "clock_offsets"]
            .iter()
            .map(|key| c[key].as_u64().unwrap())
            .sum();
        assert_eq!(k, parts);
        assert_eq!(m - c["degrees_of_freedom"].as_u64().unwrap(), k);
        let bic = chi2 + k as f64 * (m as f64).ln();
        assert!((c["bic"].as_f64().unwrap() - bic).abs() < 1e-9 * bic);
        let aic = chi2 + 2.0 * k as f64;
        assert!((c["aic"].as_f64().unwrap() - aic).abs() < 1e-9 * aic);
        let s = (chi2 / c["degrees_of_freedom"].as_f64().unwrap()).sqrt();
        assert!((c["residual_std"].as_f64().unwrap() - s).abs() < 1e-9 * s);
        // The identification report inside is identify's own.
        assert_eq!(c["identify_report"]["cost_final"].as_f64(), Some(chi2));
    }
    let (rigid, flex) = (&candidates[0], &candidates[1]);
    assert_eq!(flex["status"], "preferred");
    assert_eq!(flex["delta_bic"].as_f64(), Some(0.0));
    assert_eq!(rigid["status"], "behind");
    let delta = rigid["bic"].as_f64().unwrap() - flex["bic"].as_f64().unwrap();
    assert!((rigid["delta_bic"].as_f64().unwrap() - delta).abs() < 1e-9 * delta);
    assert!(delta > 10.0);
    assert_eq!(rigid["chi2_passed"], false);
    assert_eq!(flex["chi2_passed"], true);
    // The rigid column's worst group is the one at Z = 250 mm, and its reason names it.
    let worst = &rigid["worst_group"];
    assert_eq!(worst["position_mm"][2].as_f64(), Some(250.0), "{worst}");
    let why = rigid["reason"].as_str().unwrap();
    let eij_name = worst["worst_eij"].as_str().unwrap();
    assert!(why.contains("cannot reproduce"), "{why}");
    assert!(why.contains(eij_name), "{why}");
    assert!(why.contains("column.stiffness"), "{why}");
    // Hold-out: both centres predicted by the elastic column, not by the rigid one.
    assert_eq!(flex["holdout"]["passed"], true, "{}", flex["holdout"]);
    assert_eq!(flex["holdout"]["folds"].as_array().unwrap().len(), 2);
    assert_eq!(rigid["holdout"]["passed"], false);

    // Standard output: the verdict first, both candidates in the table, the preferred first.
    let lines: Vec<&str> = r.stdout.lines().collect();
    assert!(lines[0].starts_with("Compared 2 candidate models on 36 tests (216 values)"));
    assert_eq!(
        lines[2],
        format!("verdict: {}", json["verdict"].as_str().unwrap())
    );
    let flex_row = lines
        .iter()
        .position(|l| l.starts_with("  demo-vmc-flex  "));
    let rigid_row = lines.iter().position(|l| l.starts_with("  demo-vmc  "));
    assert!(flex_row.unwrap() < rigid_row.unwrap(), "{}", r.stdout);
    // The rigid candidate's warnings are named by it.
    assert!(
        r.stderr.contains("warning: demo-vmc: χ² test failed"),
        "{}",
        r.stderr
    );

    // The elastic column in the identification: its frequencies scale with √factor from the FE
    // reduction's own free-free eigenvalues at factor 1 (independent of the body's modal solve).
    let bodies = flex["identify_report"]["elastic_bodies"]
        .as_array()
        .unwrap();
    assert_eq!(bodies.len(), 1);
    let column = &bodies[0];
    let factor = column["factor"].as_f64().unwrap();
    let p = flex["identify_report"]["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "column.stiffness")
        .unwrap()
        .clone();
    assert_eq!(column["parameter"], "column.stiffness");
    assert_eq!(Some(factor), p["identified"].as_f64());
    assert_eq!(column["std_err"], p["std_err"]);
    assert_eq!(column["interval_3sigma"], p["interval_3sigma"]);
    let machine = common::machine("demo-vmc-flex.toml");
    let reduced = machine
        .bodies()
        .iter()
        .find_map(|b| b.elastic())
        .and_then(|e| {
            e.model()
                .as_any()
                .downcast_ref::<eij::machine::elastic::FeBody>()
        })
        .map(|f| f.reduction().reduced.frequencies_hz(1.0))
        .unwrap();
    let freqs: Vec<f64> = column["frequencies_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_f64().unwrap())
        .collect();
    assert_eq!(freqs.len(), column["modes"].as_u64().unwrap() as usize);
    for (f, f1) in freqs.iter().zip(&reduced) {
        assert!(
            (f - factor.sqrt() * f1).abs() < 1e-9 * f1,
            "{f} against √{factor} × {f1}"
        );
    }

    // The report page: the comparison first (verdict, then the candidates' table), and the
    // elastic column in the identification's details.
    let page_dir = s.s("page");
    let page = run(&["report", "--compare-report", &report, "--out", &page_dir]);
    assert!(page.ok, "{}", page.stderr);
    let html = std::fs::read_to_string(s.path("page/report.html")).unwrap();
    let at = |needle: &str| {
        html.find(needle)
            .unwrap_or_else(|| panic!("{needle} not on the page"))
    };
    let verdict = at(&format!(
        "Verdict: <span class=\"ok\">{}",
        json["verdict"].as_str().unwrap()
    ));
    let table = at("<th class=\"l\">candidate</th>");
    assert!(at("Which model do the data support") < verdict && verdict < table);
    assert!(table < at("<h3>Elastic bodies</h3>"));
    let bic = format!("<td>{:.1}</td>", rigid["bic"].as_f64().unwrap());
    assert!(html.contains(&bic), "{bic}");
    assert!(html.contains(&format!("<td>{factor:.4}</td>")));
    // Both candidates' identifications are on the page, compared side by side.
    assert!(html.contains("Comparison of the identifications"));
}

#[test]
fn compare_exits_3_when_no_candidate_reproduces_the_data() {
    // Two rigid columns (one renamed) on data of an elastic one: both fail their χ² test.
    let s = Scratch::new("cli-compare-none");
    let renamed = common::demo_text().replace("name = \"demo-vmc\"", "name = \"demo-vmc-copy\"");
    let other = s.write("copy.toml", renamed);
    let report = s.s("none.json");
    let out = eij(&[
        "compare",
        "--machine",
        "machines/demo-vmc.toml",
        "--machine",
        &other,
        "--measured",
        FLEX_A,
        FLEX_B,
        "--no-holdout",
        "--quiet",
        "--report",
        &report,
    ]);
    assert_eq!(out.status.code(), Some(3));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let last = stderr.lines().last().unwrap();
    assert!(
        last.starts_with("eij: verdict: no candidate reproduces"),
        "{last}"
    );
    assert!(out.stdout.is_empty());
    // The report is written all the same, and says so.
    let json = read_json(&report);
    assert_eq!(json["reproduced"], false);
    for c in json["candidates"].as_array().unwrap() {
        assert_eq!(c["chi2_passed"], false);
        assert!(c["holdout"].is_null());
    }
}

#[test]
fn compare_refuses_bad_input_with_one_line() {
    let s = Scratch::new("cli-compare-bad");
    let report = s.s("r.json");
    let one = eij(&[
        "compare",
        "--machine",
        "machines/demo-vmc.toml",
        "--measured",
        "measurements/demo-vmc/pos-a",
        "--report",
        &report,
    ]);
    one_line_error(&one, &["--machine", "at least two", "1 given"]);
    let missing = eij(&[
        "compare",
        "--machine",
        "machines/demo-vmc.toml",
        "--machine",
        "machines/no-such-machine.toml",
        "--measured",
        "measurements/demo-vmc/pos-a",
        "--report",
        &report,
    ]);
    one_line_error(&missing, &["machines/no-such-machine.toml"]);
    let twice = eij(&[
        "compare",
        "--machine",
        "machines/demo-vmc.toml",
        "--machine",
        "machines/demo-vmc.toml",
        "--measured",
        "measurements/demo-vmc/pos-a",
    ]);
    one_line_error(&twice, &["machines/demo-vmc.toml", "given twice"]);
    let broken = s.write("broken.toml", "name = \"broken\"\n[[axis]\n");
    let bad = eij(&[
        "compare",
        "--machine",
        "machines/demo-vmc.toml",
        "--machine",
        &broken,
        "--measured",
        "measurements/demo-vmc/pos-a",
        "--report",
        &report,
    ]);
    one_line_error(&bad, &["broken.toml"]);
    // A parameter one candidate lacks is named with that candidate's file.
    let config = s.write("c.toml", "parameters = [\"column.stiffness\"]\n");
    let lacking = eij(&[
        "compare",
        "--machine",
        "machines/demo-vmc.toml",
        "--machine",
        "machines/demo-vmc-flex.toml",
        "--measured",
        "measurements/demo-vmc/pos-a",
        "--config",
        &config,
        "--report",
        &report,
    ]);
    one_line_error(&lacking, &["machines/demo-vmc.toml", "column.stiffness"]);
    assert!(!std::path::Path::new(&report).exists(), "nothing written");
}

#[test]
fn compare_json_on_standard_output_prefers_the_rigid_column_on_rigid_data() {
    let out = eij(&[
        "compare",
        "--machine",
        "machines/demo-vmc-flex.toml",
        "--machine",
        "machines/demo-vmc.toml",
        "--measured",
        "measurements/demo-vmc/pos-a",
        "measurements/demo-vmc/pos-b",
        "--no-holdout",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: Value = serde_json::from_slice(&out.stdout).unwrap();
    // The demo data were generated by the rigid machine (its truth file has no elastic body).
    assert_eq!(json["preferred"], "demo-vmc", "{}", json["verdict"]);
    let flex = &json["candidates"][0];
    assert_ne!(flex["status"], "preferred");
    assert!(!flex["reason"].as_str().unwrap().is_empty());
}
