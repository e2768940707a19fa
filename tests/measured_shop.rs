//! A folder made the way a shop makes it (`measurements/demo-vmc-shop`, GENERATED from
//! `measurements/demo-vmc/pos-a` by `tests/common/shop.rs`): the control's TNCscope traces in
//! machine coordinates in one sub-folder, the R-Test logger's files with a metadata line, a
//! units row, `;`, decimal commas, ms and µm in another, one `rtest.toml` with one
//! `[[pairing]]`. It is what the generator writes and nothing else; it evaluates to pos-a's EIJ
//! (the same rows, re-aligned in time) and its clock offset to the one written in (−12.5 ms);
//! identify gives pos-a's factors within their standard errors; the report counts its 18
//! tests and shows the clock. The same folder with Sinumerik Operate traces (written to a
//! scratch folder) evaluates alike.

mod common;

use common::shop;
use common::{identified, root, run, Scratch};
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{evaluate_tests, Suite, SuiteOptions};
use std::path::Path;

const SHOP: &str = "measurements/demo-vmc-shop";
const POS_A: &str = "measurements/demo-vmc/pos-a";

fn evaluate(dir: &Path) -> Suite {
    let tests = expand_tests(&[root().join(dir)]).unwrap();
    evaluate_tests(&tests, &SuiteOptions::default()).unwrap()
}

/// Every file below `dir`, relative to it (`/` separated), sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy();
                out.push(rel.replace('\\', "/"));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn the_shop_folder_is_what_the_generator_writes() {
    let files = shop::files(&root().join(POS_A));
    let mut names: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
    names.push("README.md".into());
    names.sort();
    assert_eq!(listing(&root().join(SHOP)), names, "regenerate: README.md");
    for (name, bytes) in files {
        let on_disk = std::fs::read(root().join(SHOP).join(&name))
            .unwrap_or_else(|e| panic!("{name}: {e} (regenerate: README.md)"));
        assert!(on_disk == bytes, "{name} differs from the generator's");
    }
}

/// Every test of `s` against pos-a's test of the same circle: every EIJ within its
/// standard error (the same rows; only the clock alignment differs), the one clock offset
/// −12.5 ms within three standard errors plus the 0.4 µs of velocity-proportional structural
/// deviation of the demo machine that a clock fit absorbs (docs/identification.md), applied.
fn assert_like_pos_a(s: &Suite, a: &Suite) {
    assert_eq!(s.tests.len(), 18);
    assert_eq!(s.clocks.len(), 1);
    let c = &s.clocks[0];
    assert!(c.two_systems && c.separable && c.applied, "{c:?}");
    let truth = -shop::LOGGER_AHEAD_S * 1e3;
    let se = c.std_err_ms.unwrap();
    assert!(
        (c.offset_ms - truth).abs() < 3.0 * se,
        "{} ± {se} ms",
        c.offset_ms
    );
    for t in &s.tests {
        let r = &t.result;
        let twin = a
            .tests
            .iter()
            .find(|x| {
                x.result.plane == r.plane
                    && x.result.direction == r.direction
                    && (x.result.accel_m_s2 / r.accel_m_s2 - 1.0).abs() < 1e-3
            })
            .unwrap_or_else(|| panic!("{}: no pos-a twin", t.input.name()));
        for (p, v) in twin.result.eij.value_map() {
            let (got, se) = (r.eij[&p].value, twin.result.eij[&p].std_err);
            assert!(
                (got - v).abs() < se,
                "{} {p}: shop {got}, pos-a {v} ± {se}",
                t.input.name()
            );
        }
    }
}

#[test]
fn the_shop_folder_evaluates_to_the_contract_folders_eij() {
    assert_like_pos_a(&evaluate(Path::new(SHOP)), &evaluate(Path::new(POS_A)));
}

/// The same folder with Sinumerik Operate traces (XML, signals mapped in `rtest.toml`) in
/// place of the TNCscope exports: the same EIJ and clock.
#[test]
fn the_shop_folder_with_sinumerik_traces_evaluates_alike() {
    let d = Scratch::new("shop-sinumerik");
    for (name, bytes) in shop::sinumerik_files(&root().join(POS_A)) {
        d.write(&format!("shop/{name}"), bytes);
    }
    assert_like_pos_a(&evaluate(&d.path("shop")), &evaluate(Path::new(POS_A)));
}

/// identify on the shop folder and on pos-a: the same six factors within their standard
/// errors; the report page counts tests and shows the applied clock offset.
#[test]
fn the_shop_folder_identifies_and_reports_like_the_contract_folder() {
    let d = Scratch::new("shop");
    let identify = |tag: &str, dir: &str| -> serde_json::Value {
        let rep = d.s(&format!("{tag}.json"));
        let out = d.s(&format!("{tag}.toml"));
        let r = run(&[
            "identify",
            "--machine",
            "machines/demo-vmc.toml",
            "--measured",
            dir,
            "--no-design",
            "--quiet",
            "--out",
            &out,
            "--report",
            &rep,
        ]);
        assert!(r.ok, "{tag}: {}", r.stderr);
        serde_json::from_slice(&std::fs::read(&rep).unwrap()).unwrap()
    };
    let (s, a) = (identify("shop", SHOP), identify("pos-a", POS_A));
    let (ps, pa) = (identified(&s), identified(&a));
    assert_eq!(ps.len(), 6);
    for ((n, x, _), (m, y, se)) in ps.iter().zip(&pa) {
        assert_eq!(n, m);
        assert!((x - y).abs() < *se, "{n}: shop {x}, pos-a {y} ± {se}");
    }
    let out = d.s("report");
    let r = run(&["report", "--measured", SHOP, "--out", &out]);
    assert!(r.ok, "{}", r.stderr);
    let html = std::fs::read_to_string(d.path("report/report.html")).unwrap();
    assert!(html.contains("demo-vmc-shop (18 tests)"), "no test count");
    assert!(html.contains("id=\"clocks\""), "no clock table");
    assert!(html.contains("<td class=\"l\">two systems</td>"));
    assert!(html.contains("<td>yes</td>"));
}
