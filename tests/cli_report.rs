//! `eij report`, `eij evaluate --plot` and `eij simulate … --plot` end to end: the folder's
//! files, the offline links, the numbers in the tables, and the refusals on bad input.

mod common;

use std::path::{Path, PathBuf};

use common::synth::Synth;
use common::{one_line_error, run, Scratch};
use eij::axes::Plane;
use eij::report::html::fmt_eij;
use eij::rtest::{evaluate, CircleSeries, EvalOptions};

/// Non-zero exit and one `eij: error:` line naming every needle.
fn assert_error(args: &[&str], needles: &[&str]) {
    one_line_error(&common::eij(args), needles);
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A folder of two synthetic tests, an rtest.toml and a non-CSV file that must be skipped.
fn measured_folder(dir: &Path) -> PathBuf {
    let m = dir.join("measured");
    std::fs::create_dir_all(&m).unwrap();
    Synth::new(Plane::Zx, true, 3.0).write_csv(&m.join("zx_ccw_3.csv"));
    Synth::new(Plane::Xy, false, 5.0).write_csv(&m.join("xy_cw_5.csv"));
    std::fs::write(m.join("notes.txt"), "not a test").unwrap();
    std::fs::write(
        m.join("rtest.toml"),
        "radius_mm = 2.0\nposition_mm = [150.0, -100.0, 0.0]\n",
    )
    .unwrap();
    m
}

fn ident_json(dir: &Path) -> PathBuf {
    let p = dir.join("id.json");
    let v = serde_json::json!({
        "machine": "machines/demo-vmc.toml",
        "parameters": [
            {"name": "z.guideway_normal", "initial": 1.0, "identified": 0.43127, "std_err": 0.0213, "identifiable": true},
            {"name": "y.guideway_lateral", "initial": 1.0, "identified": 2.75, "std_err": 0.5, "identifiable": true}
        ],
        "correlation": [[1.0, -0.4217], [-0.4217, 1.0]],
        "cost_initial": 400.0, "cost_final": 2.5, "cost_history": [400.0, 3.0, 2.5],
        "tests": [{"source": "measured/zx_ccw_3.csv", "plane": "zx", "direction": "ccw", "accel_m_s2": 3.0,
                   "measured": {"EZZ": -1.2345, "EXX": -2.7}, "measured_std_err": {"EZZ": 0.0512, "EXX": 0.04},
                   "simulated_initial": {"EZZ": -0.5111, "EXX": -1.1},
                   "simulated_final": {"EZZ": -1.2222, "EXX": -2.69}}]
    });
    std::fs::write(&p, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    p
}

fn move_csv(dir: &Path) -> PathBuf {
    let p = dir.join("move.csv");
    let r = run(&[
        "simulate",
        "move",
        "--machine",
        "machines/demo-vmc.toml",
        "--axis",
        "z",
        "--distance-mm",
        "10",
        "--feed-mm-min",
        "15000",
        "--accel-m-s2",
        "8",
        "--jerk-m-s3",
        "250",
        "--rate-hz",
        "2000",
        "--out",
        s(&p),
    ]);
    assert!(r.ok, "{}", r.stderr);
    p
}

/// Every `src="…"` / `href="…"` value of the page.
fn references(html: &str) -> Vec<String> {
    let mut refs = Vec::new();
    for attr in ["src=\"", "href=\"", "src='", "href='"] {
        for (i, _) in html.match_indices(attr) {
            let rest = &html[i + attr.len()..];
            let end = rest.find(['"', '\'']).unwrap();
            refs.push(rest[..end].to_string());
        }
    }
    refs
}

#[test]
fn report_folder_is_offline_complete_and_holds_the_numbers() {
    let scratch = Scratch::new("report-cli");
    let dir = scratch.0.clone();
    let measured = measured_folder(&dir);
    let id = ident_json(&dir);
    let mv = move_csv(&dir);
    let out = dir.join("report");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("mine.txt"), "keep me").unwrap();
    let r = run(&[
        "report",
        "--measured",
        s(&measured),
        "--identify-report",
        s(&id),
        "--move",
        s(&mv),
        "--out",
        s(&out),
    ]);
    assert!(r.ok, "{}", r.stderr);

    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "circle-01-xy_cw_5.svg",
            "circle-02-zx_ccw_3.svg",
            "identification.svg",
            "mine.txt",
            "move-01-move.svg",
            "out-of-plane-01-xy_cw_5.svg",
            "out-of-plane-02-zx_ccw_3.svg",
            "report.html",
        ]
    );
    assert_eq!(
        std::fs::read_to_string(out.join("mine.txt")).unwrap(),
        "keep me"
    );
    for n in names.iter().filter(|n| n.ends_with(".svg")) {
        let text = std::fs::read_to_string(out.join(n)).unwrap();
        roxmltree::Document::parse(&text).unwrap_or_else(|e| panic!("{n}: {e}"));
    }

    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    for bad in [
        "http:", "https:", "//", "<script", "<link", "@import", "url(",
    ] {
        assert!(!html.contains(bad), "report.html contains '{bad}'");
    }
    let refs = references(&html);
    assert_eq!(
        refs.iter().filter(|r| r.ends_with(".svg")).count(),
        6,
        "{refs:?}"
    );
    for r in &refs {
        assert!(!r.contains('/') && !r.contains('\\'), "{r}");
        assert!(out.join(r).is_file(), "{r} is not a file of the report");
    }
    assert_eq!(
        html.matches("<table>").count(),
        html.matches("</table>").count()
    );
    assert_eq!(html.matches("<tr>").count(), html.matches("</tr>").count());

    // EIJ ± standard error of each test as `eij evaluate` computes them (set radius from
    // the folder's rtest.toml).
    let opts = EvalOptions {
        plane: None,
        radius_mm: Some(2.0),
    };
    for f in ["zx_ccw_3.csv", "xy_cw_5.csv"] {
        let res = evaluate(&CircleSeries::read_csv(measured.join(f)).unwrap(), &opts).unwrap();
        // The file column shows folder/name (names repeat across test positions).
        let folder = measured.file_name().unwrap().to_string_lossy();
        let row_start = html
            .find(&format!("<td class=\"l\">{folder}/{f}</td>"))
            .expect(f);
        let row = &html[row_start..row_start + html[row_start..].find("</tr>").unwrap()];
        for p in res.plane.parameters() {
            for v in [res.eij[&p], res.std_err[&p]] {
                assert!(
                    row.contains(&format!("<td>{}</td>", fmt_eij(v))),
                    "{f} {p}: {row}"
                );
            }
        }
    }
    assert!(html.contains("circle centre at axis positions [150.0, -100.0, 0.0] mm"));
    // Identification: parameters, correlation, per-test before/after.
    for needle in [
        "<td class=\"l\">z.guideway_normal</td><td>1</td><td>0.4313</td><td>0.0213</td>",
        "<td>-0.422</td>",
        "<td>EZZ</td><td>-1.2345</td><td>0.0512</td><td>-0.5111</td><td>-1.2222</td><td>0.0123</td>",
        "zx ccw 3",
    ] {
        assert!(html.contains(needle), "report.html lacks {needle}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_input_is_refused_with_one_line_and_nothing_written() {
    let scratch = Scratch::new("report-bad");
    let dir = scratch.0.clone();
    let measured = measured_folder(&dir);
    let out = dir.join("out");

    let missing = dir.join("nope.csv");
    assert_error(
        &["report", "--measured", s(&missing), "--out", s(&out)],
        &[s(&missing), "not found"],
    );
    assert!(!out.exists());

    let id = ident_json(&dir);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&id).unwrap()).unwrap();
    v["tests"][0].as_object_mut().unwrap().remove("measured");
    std::fs::write(&id, v.to_string()).unwrap();
    assert_error(
        &[
            "report",
            "--measured",
            s(&measured),
            "--identify-report",
            s(&id),
            "--out",
            s(&out),
        ],
        &[s(&id), "tests[0].measured", "missing"],
    );
    assert!(!out.exists());

    let file = dir.join("a-file");
    std::fs::write(&file, "precious").unwrap();
    assert_error(
        &["report", "--measured", s(&measured), "--out", s(&file)],
        &[s(&file), "not a folder"],
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "precious");

    // A bad measured file among good ones: nothing written at all.
    std::fs::write(measured.join("zz_broken.csv"), "t_s,x_int_mm\n0,1\n").unwrap();
    assert_error(
        &["report", "--measured", s(&measured), "--out", s(&out)],
        &["zz_broken.csv"],
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn evaluate_plot_writes_one_figure_and_refuses_several_files() {
    let scratch = Scratch::new("report-eval-plot");
    let dir = scratch.0.clone();
    let measured = measured_folder(&dir);
    let csv = measured.join("zx_ccw_3.csv");
    let plot = dir.join("zx.svg");
    let r = run(&[
        "evaluate",
        s(&csv),
        "--radius-mm",
        "2",
        "--json",
        "--plot",
        s(&plot),
    ]);
    assert!(r.ok, "{}", r.stderr);
    let text = std::fs::read_to_string(&plot).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let texts: String = doc
        .descendants()
        .filter_map(|n| n.text())
        .collect::<Vec<_>>()
        .join("\n");
    for needle in [
        "Circle test zx ccw",
        "radius r = 2 mm",
        "set acceleration 3 m/s²",
        s(&csv),
        "[150.0, -100.0, 0.0] mm",
        "z − zc / mm",
    ] {
        assert!(texts.contains(needle), "plot lacks '{needle}'");
    }

    let two = dir.join("two.svg");
    let other = measured.join("xy_cw_5.csv");
    assert_error(
        &["evaluate", s(&csv), s(&other), "--plot", s(&two)],
        &["--plot", "2 files"],
    );
    assert!(!two.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn simulate_plot_draws_the_circle_and_the_move() {
    let scratch = Scratch::new("report-sim-plot");
    let dir = scratch.0.clone();
    let (csv, svg) = (dir.join("c.csv"), dir.join("c.svg"));
    let r = run(&[
        "simulate",
        "circle",
        "--machine",
        "machines/demo-vmc.toml",
        "--plane",
        "yz",
        "--radius-mm",
        "2",
        "--accel-m-s2",
        "4",
        "--direction",
        "cw",
        "--rate-hz",
        "4000",
        "--out",
        s(&csv),
        "--plot",
        s(&svg),
    ]);
    assert!(r.ok, "{}", r.stderr);
    let text = std::fs::read_to_string(&svg).unwrap();
    roxmltree::Document::parse(&text).unwrap();
    for needle in [
        "Circle test yz cw",
        "set acceleration 4 m/s²",
        "machine: demo",
        "y − yc / mm",
    ] {
        assert!(text.contains(needle), "circle plot lacks '{needle}'");
    }
    assert!(
        CircleSeries::read_csv(&csv).is_ok(),
        "the CSV is still written"
    );

    let (mcsv, msvg) = (dir.join("m.csv"), dir.join("m.svg"));
    let r = run(&[
        "simulate",
        "move",
        "--machine",
        "machines/demo-vmc.toml",
        "--axis",
        "x",
        "--distance-mm",
        "-5",
        "--feed-mm-min",
        "10000",
        "--accel-m-s2",
        "5",
        "--jerk-m-s3",
        "200",
        "--rate-hz",
        "2000",
        "--out",
        s(&mcsv),
        "--plot",
        s(&msvg),
    ]);
    assert!(r.ok, "{}", r.stderr);
    let text = std::fs::read_to_string(&msvg).unwrap();
    roxmltree::Document::parse(&text).unwrap();
    for needle in [
        "Positioning move of axis X",
        "distance -5 mm",
        "machine: demo",
        "time t / s",
        "dz = z_ext − z_int",
    ] {
        assert!(text.contains(needle), "move plot lacks '{needle}'");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
