//! `eij report`, `eij evaluate --plot` and `eij simulate … --plot` end to end: one
//! self-contained page (figures inline, links only within it), the verdict before the figures,
//! the comparison of several identifications, tests at two circle centres told apart, the
//! ISO 230-4 figures and EIJ equal to `eij evaluate`'s, and the refusals on bad input.

mod common;

use std::path::{Path, PathBuf};

use common::synth::Synth;
use common::{one_line_error, run, Scratch};
use eij::axes::Plane;
use eij::report::labels::fmt_eij;
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

/// Two circle centres, each with a cw/ccw pair of the same file names; the first also with an
/// unpaired test.
fn two_positions(dir: &Path) -> [PathBuf; 2] {
    let folder = |name: &str, position: &str, seed: u64, extra: bool| {
        let m = dir.join(name);
        std::fs::create_dir_all(&m).unwrap();
        for ccw in [true, false] {
            let mut t = Synth::new(Plane::Zx, ccw, 3.0);
            t.seed = seed + u64::from(ccw);
            let d = if ccw { "ccw" } else { "cw" };
            t.write_csv(&m.join(format!("zx_{d}_3.csv")));
        }
        if extra {
            Synth::new(Plane::Xy, false, 5.0).write_csv(&m.join("xy_cw_5.csv"));
        }
        std::fs::write(
            m.join("rtest.toml"),
            format!("radius_mm = 2.0\nposition_mm = [{position}]\n"),
        )
        .unwrap();
        m
    };
    [
        folder("pos-a", "150.0, -100.0, 0.0", 11, true),
        folder("pos-b", "-150.0, 100.0, 0.0", 23, false),
    ]
}

/// An identify report: `factor` ± `std_err` for x.guideway_normal, the tests at both centres.
fn ident_json(dir: &Path, name: &str, factor: f64, std_err: f64, warnings: &[&str]) -> PathBuf {
    let p = dir.join(name);
    let test = |pos: [f64; 3], ezz: f64| {
        serde_json::json!({"source": "pos/zx_ccw_3.csv", "plane": "zx", "direction": "ccw",
            "accel_m_s2": 3.0, "position_mm": pos,
            "measured": {"EZZ": ezz, "EXX": -2.7}, "measured_std_err": {"EZZ": 0.0512, "EXX": 0.04},
            "simulated_initial": {"EZZ": -0.5111, "EXX": -1.1},
            "simulated_final": {"EZZ": -1.2222, "EXX": -2.69}})
    };
    let v = serde_json::json!({
        "machine": "machines/demo-vmc.toml",
        "date": "2026-11-20T10:00:00Z",
        "parameters": [
            {"name": "z.guideway_normal", "initial": 1.0, "identified": 0.43127, "std_err": 0.0213, "identifiable": true, "at_bound": false},
            {"name": "x.guideway_normal", "initial": 1.0, "identified": factor, "std_err": std_err, "identifiable": true, "at_bound": false}
        ],
        "correlation": [[1.0, -0.4217], [-0.4217, 1.0]],
        "cost_initial": 400.0, "cost_final": 2.5, "cost_history": [400.0, 3.0, 2.5],
        "residual_std": 0.8123, "degrees_of_freedom": 2, "residuals": 4,
        "status": "accepted", "warnings": warnings,
        "tests": [test([150.0, -100.0, 0.0], -1.2345), test([-150.0, 100.0, 0.0], -1.1)]
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

/// The inline SVGs of the page, each parsed as XML (the namespace added back).
fn inline_svgs(html: &str) -> Vec<String> {
    html.match_indices("<svg ")
        .map(|(i, _)| {
            let end = i + html[i..].find("</svg>").unwrap() + 6;
            let svg =
                html[i..end].replacen("<svg ", "<svg xmlns=\"http://www.w3.org/2000/svg\" ", 1);
            roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{e}: {}", &svg[..200]));
            html[i..end].to_string()
        })
        .collect()
}

/// The HTML-escaped form of a text.
fn escaped(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[test]
fn report_is_one_self_contained_page_with_the_verdict_first() {
    let scratch = Scratch::new("report-cli");
    let dir = scratch.0.clone();
    let [pos_a, pos_b] = two_positions(&dir);
    let warn_b = "x.guideway_normal = 9.998 ± 86.000 is only weakly determined by these tests";
    let id_a = ident_json(&dir, "before.json", 0.45, 0.02, &[]);
    let id_b = ident_json(
        &dir,
        "after.json",
        9.998,
        86.0,
        &[warn_b, "χ² test failed: <s> & co"],
    );
    let mv = move_csv(&dir);
    let out = dir.join("report");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("mine.txt"), "keep me").unwrap();
    let r = run(&[
        "report",
        "--measured",
        s(&pos_a),
        s(&pos_b),
        "--identify-report",
        s(&id_a),
        "--identify-report",
        s(&id_b),
        "--move",
        s(&mv),
        "--out",
        s(&out),
    ]);
    assert!(r.ok, "{}", r.stderr);

    // One page, nothing else written; the user's file left alone.
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["mine.txt", "report.html"]);
    assert_eq!(
        std::fs::read_to_string(out.join("mine.txt")).unwrap(),
        "keep me"
    );
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();

    // Self-contained: no network, no scripts, no other file; links only to anchors of the page.
    for bad in [
        "http:", "https:", "file:", "<script", "<link", "<img", "<iframe", "<object", "<embed",
        "@import", "url(", "src=",
    ] {
        assert!(!html.contains(bad), "report.html contains '{bad}'");
    }
    let mut ids: Vec<&str> = html
        .match_indices(" id=\"")
        .map(|(i, _)| {
            let rest = &html[i + 5..];
            &rest[..rest.find('"').unwrap()]
        })
        .collect();
    let n = ids.len();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), n, "anchors must be unique");
    for r in references(&html) {
        let id = r
            .strip_prefix('#')
            .unwrap_or_else(|| panic!("link {r} leaves the page"));
        assert!(
            html.contains(&format!("id=\"{id}\"")),
            "anchor {id} missing"
        );
    }
    // Every figure inline: three circle groups (polar + out-of-plane), the move, one
    // identification figure per report.
    let svgs = inline_svgs(&html);
    assert_eq!(html.matches("<figure").count(), svgs.len());
    assert_eq!(svgs.len(), 3 * 2 + 1 + 2, "figures");
    assert_eq!(
        html.matches("<table").count(),
        html.matches("</table>").count()
    );
    assert_eq!(html.matches("<tr>").count(), html.matches("</tr>").count());
    for needle in [
        "<nav class=\"toc\">",
        "machines/demo-vmc.toml",
        "pos-a (3 tests)",
        "pos-b (2 tests)",
    ] {
        assert!(html.contains(needle), "header lacks {needle}");
    }

    // The verdict before any figure: s, the χ² test, every warning, the standing.
    let first_svg = html.find("<svg").unwrap();
    let verdict = &html[..first_svg];
    let limit = (1.0f64 + 4.0 * (2.0f64 / 2.0).sqrt()).sqrt();
    for needle in [
        format!("residual std s = 0.812; χ² test passed: s = 0.812 ≤ {limit:.3} over 2 degrees of freedom"),
        escaped(warn_b),
        escaped("χ² test failed: <s> & co"),
    ] {
        assert!(verdict.contains(&needle), "verdict lacks {needle}");
    }
    // 9.998 ± 86 is 860 %: not determined, never "identifiable: yes".
    let row_b = verdict
        .match_indices("<td class=\"l\">x.guideway_normal</td>")
        .map(|(i, _)| &verdict[i..i + verdict[i..].find("</tr>").unwrap()])
        .find(|r| r.contains("9.9980"))
        .expect("B's row");
    assert!(
        row_b.contains(&format!("{:.1} %", 100.0 * 86.0 / 9.998))
            && row_b.contains("NOT determined"),
        "{row_b}"
    );
    assert!(verdict.contains("DOUBTFUL: x.guideway_normal NOT determined"));
    assert!(!html.contains(">yes<"));

    // Comparison: A and B side by side with the change and its z.
    let cmp = &html[html.find("id=\"comparison\"").expect("comparison")..];
    for needle in [
        "<th>A identified ± std err</th>",
        "<th>B identified ± std err</th>",
        "<th>B − A</th>",
    ] {
        assert!(cmp.contains(needle), "comparison lacks {needle}");
    }
    let z = (9.998 - 0.45) / 0.02f64.hypot(86.0);
    assert!(
        cmp.contains(&format!("{:+.4} (z = {z:+.1})", 9.998 - 0.45)),
        "Δ of x.guideway_normal"
    );
    assert!(cmp.contains("0.8123") || cmp.contains("0.812"));

    // Tests at the two centres are told apart in every label.
    for pos in ["150,-100,0", "-150,100,0"] {
        assert!(
            html.contains(&format!("zx ccw 3 @ {pos}")),
            "ident label at {pos}"
        );
    }
    let titles: Vec<&str> = svgs
        .iter()
        .filter_map(|s| s.split("aria-label=\"").nth(1)?.split(':').next())
        .filter(|t| t.starts_with("Circle plot"))
        .collect();
    assert_eq!(titles.len(), 3, "{titles:?}");
    let mut unique = titles.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), 3, "{titles:?}");
    for t in [
        "circle centre [150, -100, 0] mm",
        "circle centre [-150, 100, 0] mm",
    ] {
        assert!(titles.iter().any(|x| x.contains(t)), "{t}");
    }

    // ISO 230-4: G per path and G(b) per pair exactly as `eij evaluate --json` gives them.
    let ev = run(&["evaluate", "--json", s(&pos_a), s(&pos_b)]);
    assert!(ev.ok, "{}", ev.stderr);
    let json: serde_json::Value = serde_json::from_str(&ev.stdout).unwrap();
    let g = |file: &str, path: &str| -> f64 {
        json["tests"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["file"].as_str().unwrap().ends_with(file))
            .unwrap()["circular_deviation_um"][path]
            .as_f64()
            .unwrap()
    };
    let tables: Vec<&str> = html.split("<table class=\"iso\">").skip(1).collect();
    assert_eq!(tables.len(), 3);
    for folder in ["pos-a", "pos-b"] {
        let (cw, ccw) = (
            format!("{folder}/zx_cw_3.csv"),
            format!("{folder}/zx_ccw_3.csv"),
        );
        let t = tables
            .iter()
            .find(|t| t[..t.find("</p>").unwrap()].contains(&format!("cw: {cw}, ccw: {ccw}")))
            .unwrap_or_else(|| panic!("no ISO table of {folder}"));
        let row = |name: &str| {
            let i = t.find(name).unwrap();
            t[i..i + t[i..].find("</tr>").unwrap()].to_string()
        };
        let cells = format!(
            "<td>{:.2}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td>",
            g(&cw, "external"),
            g(&ccw, "external"),
            g(&cw, "internal"),
            g(&ccw, "internal")
        );
        assert!(
            row("circular deviation G").contains(&cells),
            "{folder}: {cells}"
        );
        let pair = json["bidirectional"]
            .as_array()
            .unwrap()
            .iter()
            .find(|b| b["files"][0].as_str().unwrap().ends_with(&cw))
            .unwrap();
        let gb = &pair["bidirectional_circular_deviation_um"];
        let cells = format!(
            "<td colspan=\"2\">{:.2}</td><td colspan=\"2\">{:.2}</td>",
            gb["external"].as_f64().unwrap(),
            gb["internal"].as_f64().unwrap()
        );
        assert!(
            row("bi-directional G(b)").contains(&cells),
            "{folder}: {cells}"
        );
    }

    // EIJ ± standard error of each test as `eij evaluate` computes them (set radius from
    // the folder's rtest.toml); the file column shows folder/name.
    let opts = EvalOptions {
        plane: None,
        radius_mm: Some(2.0),
    };
    for (folder, f) in [
        (&pos_a, "zx_ccw_3.csv"),
        (&pos_b, "zx_cw_3.csv"),
        (&pos_a, "xy_cw_5.csv"),
    ] {
        let res = evaluate(&CircleSeries::read_csv(folder.join(f)).unwrap(), &opts).unwrap();
        let name = folder.file_name().unwrap().to_string_lossy();
        let row_start = html
            .find(&format!("<td class=\"l\">{name}/{f}</td>"))
            .expect(f);
        let row = &html[row_start..row_start + html[row_start..].find("</tr>").unwrap()];
        for p in res.plane.parameters() {
            let cell = format!(
                "<td>{} ± {}</td>",
                fmt_eij(res.eij[&p].value),
                fmt_eij(res.eij[&p].std_err)
            );
            assert!(row.contains(&cell), "{f} {p}: {row}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn one_identify_report_has_no_comparison_and_an_old_one_says_what_it_lacks() {
    let scratch = Scratch::new("report-one");
    let dir = scratch.0.clone();
    let measured = measured_folder(&dir);
    let id = ident_json(&dir, "id.json", 0.45, 0.02, &[]);
    // A report of an older eij: no degrees of freedom, no status.
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&id).unwrap()).unwrap();
    for key in ["degrees_of_freedom", "status", "residual_std"] {
        v.as_object_mut().unwrap().remove(key);
    }
    std::fs::write(&id, v.to_string()).unwrap();
    let out = dir.join("report");
    let r = run(&[
        "report",
        "--measured",
        s(&measured),
        "--identify-report",
        s(&id),
        "--out",
        s(&out),
    ]);
    assert!(r.ok, "{}", r.stderr);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(!html.contains("id=\"comparison\""));
    assert!(html.contains("residual std s not recorded (older report)"));
    assert!(html.contains("usable with care: χ² test not recorded (older report)"));
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

    let id = ident_json(&dir, "id.json", 0.45, 0.02, &[]);
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
