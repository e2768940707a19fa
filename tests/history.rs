//! `eij history` and `eij report --history`: three dated runs of one machine (synthetic cw/ccw
//! pairs at 2 and 5 m/s², generated with known terms) lined up by date; the x axis' backlash
//! grows from 1 µm to 3 µm in the last run and is flagged there as drift (and only there),
//! the constant scale mismatch and the EIJ are not; each run's values lie within 3 standard
//! errors of the truth; an evaluate JSON gives the same history as its folder; runs without a
//! date, of two machines or without the diagnosis are refused in one line.

mod common;

use common::circle_terms::{Errors, TermCircle};
use common::synth::csv_text;
use common::{eij, one_line_error, Scratch};
use eij::axes::Plane;
use serde_json::Value;

/// The structure's EIJ of every run (µm·s²/m, `Errors::eij` rows a, b, normal).
const EIJ: [[f64; 2]; 3] = [[0.5, 0.3], [0.1, -0.4], [0.6, -0.2]];

/// A run: folder `name` dated `date`, xy cw/ccw pairs at 2 and 5 m/s² whose x axis has
/// `backlash_um` of lost motion and whose axes have 2 µm of scale mismatch.
fn run(dir: &Scratch, name: &str, date: &str, backlash_um: f64, seed: u64) -> String {
    for (k, accel) in [2.0, 5.0].into_iter().enumerate() {
        for ccw in [true, false] {
            let mut c = TermCircle::new(Plane::Xy, ccw, accel);
            c.internal.backlash_um = [backlash_um, 0.0];
            c.internal.scale_mismatch_um = 2.0;
            c.structure = Errors {
                eij: EIJ,
                ..Default::default()
            };
            c.seed = seed + 2 * k as u64 + u64::from(ccw);
            let (t, int, ext) = c.columns();
            let d = if ccw { "ccw" } else { "cw" };
            dir.write(
                &format!("{name}/xy_{d}_{accel}.csv"),
                csv_text(&t, &int, &ext),
            );
        }
    }
    dir.write(
        &format!("{name}/rtest.toml"),
        format!(
            "radius_mm = 2.0\nposition_mm = [0, 0, 0]\nmachine = \"VMC 4711\"\ndate = {date}\n"
        ),
    );
    dir.s(name)
}

fn json(args: &[&str]) -> Value {
    let out = eij(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn quantity<'a>(h: &'a Value, source: &str, name: &str) -> &'a Value {
    h["quantities"]
        .as_array()
        .unwrap()
        .iter()
        .find(|q| q["source"] == source && q["name"] == name)
        .unwrap_or_else(|| panic!("{source} {name}"))
}

/// (value, std_err, z, drift) per run.
fn points(q: &Value) -> Vec<(f64, f64, Option<f64>, bool)> {
    q["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["value"].as_f64().unwrap(),
                p["std_err"].as_f64().unwrap(),
                p["z"].as_f64(),
                p["drift"].as_bool().unwrap(),
            )
        })
        .collect()
}

/// Runs given out of order come back by date; the backlash's drift is found in the last run
/// only, with the change within 3 combined standard errors of the true 2 µm.
#[test]
fn drift_of_known_size_found_where_it_is() {
    let dir = Scratch::new("history-drift");
    let march = run(&dir, "march", "2026-03-14", 3.0, 30);
    let jan = run(&dir, "jan", "2026-01-10", 1.0, 10);
    let feb = run(&dir, "feb", "2026-02-10", 1.0, 20);
    let h = json(&["history", &march, &jan, &feb, "--json"]);
    assert_eq!(h["machine"], "VMC 4711");
    let dates: Vec<&str> = h["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["date"].as_str().unwrap())
        .collect();
    assert_eq!(dates, ["2026-01-10", "2026-02-10", "2026-03-14"]);
    assert_eq!(h["runs"][2]["days"].as_f64().unwrap(), 63.0);

    let truth = [1.0, 1.0, 3.0];
    for source in ["internal", "tcp"] {
        let p = points(quantity(&h, source, "backlash_x"));
        assert_eq!(p.len(), 3);
        for (k, &(v, se, _, _)) in p.iter().enumerate() {
            assert!(
                (v - truth[k]).abs() < 3.0 * se,
                "{source} run {k}: {v} ± {se}"
            );
        }
        assert!(!p[1].3, "{source}: no drift in February: z = {:?}", p[1].2);
        assert!(p[2].3, "{source}: drift in March: z = {:?}", p[2].2);
        let change = p[2].0 - p[0].0;
        let se = p[2].1.hypot(p[0].1);
        assert!((change - 2.0).abs() < 3.0 * se, "{change} ± {se}");
        assert!((p[2].2.unwrap() - change / se).abs() < 1e-9);
        assert!(quantity(&h, source, "backlash_x")["drift"]
            .as_bool()
            .unwrap());
    }
    let scale = quantity(&h, "internal", "scale_mismatch");
    assert!(!scale["drift"].as_bool().unwrap(), "{scale}");
    for (v, se, _, _) in points(scale) {
        assert!((v - 2.0).abs() < 3.0 * se, "scale mismatch {v} ± {se}");
    }
    assert!(!quantity(&h, "internal", "backlash_y")["drift"]
        .as_bool()
        .unwrap());
    for e in ["EXX", "EYY", "EXY", "EYX", "EZX", "EZY"] {
        let q = quantity(&h, "eij", e);
        assert_eq!(q["unit"], "um_s2_per_m");
        assert!(!q["drift"].as_bool().unwrap(), "{e}: {q}");
    }
    assert_eq!(h["drifted"].as_u64().unwrap(), 2, "only the backlash: {h}");

    // The text says the same, and the drift goes to standard error too.
    let out = eij(&["history", &jan, &feb, &march]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("History of VMC 4711: 3 runs"), "{text}");
    assert!(text.contains(
        "drift (change from the first run beyond 3 combined standard errors): 2 quantities"
    ));
    let line = text
        .lines()
        .find(|l| l.contains("internal backlash_x") && l.contains("(2026-03-14)"))
        .expect("drift line");
    assert!(line.contains("z = +"), "{line}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("eij: drift: 2 quantities"));
}

/// An archived `eij evaluate --diagnose --json` is the same run as its folder.
#[test]
fn evaluate_json_is_the_same_run_as_its_folder() {
    let dir = Scratch::new("history-json");
    let jan = run(&dir, "jan", "2026-01-10", 1.0, 10);
    let march = run(&dir, "march", "2026-03-14", 3.0, 30);
    let out = eij(&["evaluate", &jan, "--diagnose", "--json"]);
    assert!(out.status.success());
    let archived = dir.write("jan.json", &out.stdout);
    let a = json(&["history", &jan, &march, "--json"]);
    let b = json(&["history", &archived, &march, "--json"]);
    assert_eq!(a["quantities"], b["quantities"]);
    assert_eq!(a["runs"][1], b["runs"][1]);
    // Without --diagnose the JSON has no terms.
    let plain = eij(&["evaluate", &jan, "--json"]);
    let plain = dir.write("plain.json", &plain.stdout);
    one_line_error(
        &eij(&["history", &plain, &march]),
        &["plain.json", "diagnosis_groups", "--diagnose"],
    );
}

/// Runs without a date, with two dates or of two machines are refused, naming the key.
#[test]
fn undated_mixed_or_foreign_runs_refused() {
    let dir = Scratch::new("history-bad");
    let jan = run(&dir, "jan", "2026-01-10", 1.0, 10);
    let nodate = run(&dir, "nodate", "2026-02-10", 1.0, 20);
    let text = std::fs::read_to_string(dir.path("nodate/rtest.toml")).unwrap();
    dir.write("nodate/rtest.toml", text.replace("date = 2026-02-10\n", ""));
    one_line_error(
        &eij(&["history", &jan, &nodate]),
        &["nodate", "date", "missing"],
    );
    let other = run(&dir, "other", "2026-02-10", 1.0, 20);
    let text = std::fs::read_to_string(dir.path("other/rtest.toml")).unwrap();
    dir.write("other/rtest.toml", text.replace("VMC 4711", "HMC 12"));
    one_line_error(
        &eij(&["history", &jan, &other]),
        &["other", "machine", "HMC 12", "VMC 4711"],
    );
    // One run of two dates: a folder holding two dated sub-folders.
    let both = dir.path("both");
    std::fs::create_dir_all(&both).unwrap();
    std::fs::rename(dir.path("jan"), both.join("jan")).unwrap();
    run(&dir, "both/feb", "2026-02-10", 1.0, 20);
    let mar = run(&dir, "mar", "2026-03-10", 1.0, 40);
    one_line_error(
        &eij(&["history", both.to_str().unwrap(), &mar]),
        &["both", "date", "2 dates"],
    );
}

/// The report's history section: the runs, the drift in the verdict's red, one trend plot per
/// quantity shown.
#[test]
fn report_has_a_history_section_with_trend_plots() {
    let dir = Scratch::new("history-report");
    let jan = run(&dir, "jan", "2026-01-10", 1.0, 10);
    let feb = run(&dir, "feb", "2026-02-10", 1.0, 20);
    let march = run(&dir, "march", "2026-03-14", 3.0, 30);
    let out = dir.s("report");
    let r = eij(&["report", "--history", &jan, &feb, &march, "--out", &out]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let html = std::fs::read_to_string(dir.path("report/report.html")).unwrap();
    let sec = &html[html.find("<h2 id=\"history\">").expect("history section")..];
    assert!(sec.contains("<p class=\"v-fail\"><b>Drift in 2 quantities:</b></p>"));
    assert!(sec.contains("xy @ 0,0,0 mm internal backlash_x: +"));
    let h = json(&["history", &jan, &feb, &march, "--json"]);
    let shown = h["quantities"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|q| q["stands_out"] == true || q["drift"] == true)
        .count();
    assert!(shown >= 8, "6 EIJ and the backlash at least: {shown}");
    assert_eq!(sec.matches("<td class=\"trend\"><svg").count(), shown);
    // The drifting point is drawn in the drift colour, the others in the steady one.
    let row = &sec[sec
        .find("<th class=\"l\">internal backlash_x</th>")
        .unwrap()..];
    let row = &row[..row.find("</tr>").unwrap()];
    assert_eq!(row.matches("<td class=\"v-fail\">").count(), 1, "{row}");
    assert!(row.contains("fill=\"#BB2222\""), "drift point red");
}
