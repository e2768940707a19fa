//! The circle diagnosis on the report page (`eij report --measured …`): per test the verdict
//! before its breakdown, beside its circle plot; the breakdown's numbers equal
//! `eij evaluate --diagnose --json`'s; one colour per verdict; and the certificate — machine,
//! date, instrument, temperature, tolerances, pass/fail per test — set up to print on one A4
//! page (its fit on the page is checked with headless Chromium by tests/print-check.sh).

mod common;

use common::circle_terms::TermCircle;
use common::synth::csv_text;
use common::{eij, one_line_error, Scratch};
use eij::axes::Plane;
use serde_json::Value;

/// Folder `name` with a cw/ccw pair of xy circles whose x axis has `backlash_um` of lost
/// motion, and an `rtest.toml` with the session keys and `extra`.
fn folder(dir: &Scratch, name: &str, backlash_um: f64, seed: u64, extra: &str) -> String {
    for (ccw, file) in [(true, "ccw.csv"), (false, "cw.csv")] {
        let mut c = TermCircle::new(Plane::Xy, ccw, 3.0);
        c.internal.backlash_um = [backlash_um, 0.0];
        c.seed = seed + u64::from(ccw);
        let (t, int, ext) = c.columns();
        dir.write(&format!("{name}/{file}"), csv_text(&t, &int, &ext));
    }
    dir.write(
        &format!("{name}/rtest.toml"),
        format!(
            "radius_mm = 2.0\nposition_mm = [0, 0, 0]\nmachine = \"VMC 4711\"\n\
             date = 2026-03-14\ninstrument = \"R-Test 0815\"\ntemperature_c = 20.5\n{extra}"
        ),
    );
    dir.s(name)
}

/// The text from the first `start` to the first `end` after it.
fn between<'a>(text: &'a str, start: &str, end: &str) -> &'a str {
    let i = text
        .find(start)
        .unwrap_or_else(|| panic!("{start} missing"));
    let j = text[i..]
        .find(end)
        .unwrap_or_else(|| panic!("{end} missing"))
        + i;
    &text[i..j]
}

/// Two folders (3 µm backlash on x against a 2 µm limit: fails; none: passes), the report
/// and the evaluate JSON of the same tests.
fn setup(tag: &str) -> (Scratch, String, Value) {
    let dir = Scratch::new(tag);
    let limits = "[tolerances]\nbacklash_um = 2\ncircular_deviation_um = 20\n";
    let bad = folder(&dir, "worn", 3.0, 5, limits);
    let good = folder(&dir, "new", 0.0, 9, limits);
    let out = dir.s("report");
    let r = eij(&["report", "--measured", &bad, &good, "--out", &out]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let html = std::fs::read_to_string(dir.path("report/report.html")).unwrap();
    let e = eij(&["evaluate", &bad, &good, "--diagnose", "--json"]);
    assert_eq!(e.status.code(), Some(3), "one folder fails its tolerances");
    let json: Value = serde_json::from_slice(&e.stdout).unwrap();
    (dir, html, json)
}

/// Beside each circle plot, each test's verdict comes before its breakdown, with the class of
/// its verdict, equal to evaluate's; the backlash and G cells hold evaluate's numbers.
#[test]
fn breakdown_beside_each_plot_verdict_first() {
    let (_dir, html, json) = setup("report-diag");
    let tests = json["tests"].as_array().unwrap();
    assert_eq!(tests.len(), 4);
    let rows: Vec<&str> = html.split("<div class=\"row\">").skip(1).collect();
    assert_eq!(rows.len(), 2, "one circle plot per folder");
    let mut seen = 0;
    for t in tests {
        let file = t["file"].as_str().unwrap();
        let (folder, name) = file.rsplit_once('/').unwrap();
        let folder = folder.rsplit('/').next().unwrap();
        let dir = if name.starts_with("ccw") { "ccw" } else { "cw" };
        let label = format!("{dir}: {folder}/{name}");
        let row = rows
            .iter()
            .find(|r| r.contains(&format!("<b>{label}</b>")))
            .unwrap_or_else(|| panic!("no breakdown for {label}"));
        assert!(row.find("<svg").unwrap() < row.find(&label).unwrap());
        let k = row.find(&format!("<b>{label}</b>")).unwrap();
        let start = row[..k].rfind("<div class=\"diag\">").unwrap();
        let block = &row[start..k + row[k..].find("</table>").unwrap()];
        let verdict = t["verdict"].as_str().unwrap();
        let badge = format!(
            "<span class=\"badge v-{verdict}\">{}</span>",
            verdict.to_uppercase()
        );
        let (b, table) = (block.find(&badge), block.find("<table"));
        assert!(
            b.is_some() && b < table,
            "{label}: {badge} before the table"
        );
        for source in ["internal", "structure", "tcp"] {
            let g = t["diagnosis"][source]["circular_deviation_um"]
                .as_f64()
                .unwrap();
            assert!(
                block.contains(&format!("<b>{g:.3}</b>")),
                "{label} {source} G"
            );
        }
        let bx = t["diagnosis"]["tcp"]["terms"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["name"] == "backlash_x")
            .unwrap();
        let (v, se) = (
            bx["value"].as_f64().unwrap(),
            bx["std_err"].as_f64().unwrap(),
        );
        let row_bx = between(block, "<th class=\"l\">backlash_x</th>", "</tr>");
        // Two significant digits of the standard error.
        let d = (1.0 - se.log10().floor()) as usize;
        let cell = format!(
            "<td class=\"v-{}\">{v:.d$} ± {se:.d$}",
            bx["verdict"].as_str().unwrap()
        );
        assert!(row_bx.contains(&cell), "{label}: {cell} in {row_bx}");
        if folder == "worn" {
            assert_eq!(verdict, "fail");
            assert!((v - 3.0).abs() < 3.0 * se, "backlash {v} ± {se}");
            assert!(row_bx.contains("x+ ") && row_bx.contains("x- "), "{row_bx}");
        } else {
            assert_eq!(verdict, "pass");
        }
        seen += 1;
    }
    assert_eq!(seen, 4);
}

/// One verdict, one colour: the style sheet gives PASS one green and FAIL one red, badge and
/// cell alike, and no badge says PASS in red or FAIL in green.
#[test]
fn one_verdict_one_colour() {
    let (_dir, html, _) = setup("report-colour");
    let style = between(&html, "<style>", "</style>");
    let colour_of = |rule: &str, prop: &str| -> String {
        let r = between(style, rule, "}");
        let p = &r[r.find(prop).unwrap() + prop.len()..];
        p.split(';').next().unwrap().to_string()
    };
    let pass = colour_of(".badge.v-pass{", "background:");
    let fail = colour_of(".badge.v-fail{", "background:");
    assert_ne!(pass, fail);
    assert_eq!(colour_of("td.v-pass{", "color:"), pass);
    assert_eq!(colour_of("td.v-fail{", "color:"), fail);
    assert_eq!(colour_of("p.v-fail,li.v-fail{", "color:"), fail);
    assert!(!html.contains("v-pass\">FAIL") && !html.contains("v-fail\">PASS"));
    let badges = |v: &str| html.matches(&format!("badge v-{v}\">")).count();
    // Per test: beside its plot and in the certificate; overall: verdict and certificate.
    assert_eq!(badges("pass"), 2 * 2);
    assert_eq!(badges("fail"), 2 * 2 + 2);
}

/// The certificate: after the verdict, before the circle plots; the session, the tolerances,
/// every test with its G and verdict; its own page in print (A4).
#[test]
fn certificate_states_machine_date_tolerances_and_verdicts() {
    let (_dir, html, json) = setup("report-cert");
    let cert = between(&html, "<div class=\"certificate\">", "End of certificate.");
    assert!(html.find("id=\"verdict\"") < html.find("class=\"certificate\""));
    assert!(html.find("class=\"certificate\"") < html.find("id=\"circles\""));
    for needle in [
        "<tr><th>machine</th><td>VMC 4711</td></tr>",
        "<tr><th>measured on</th><td>2026-03-14</td></tr>",
        "<tr><th>instrument</th><td>R-Test 0815</td></tr>",
        "<tr><th>ambient temperature</th><td>20.5 °C</td></tr>",
        "<td class=\"l\">|backlash|</td><td>2</td>",
        "<td class=\"l\">circular deviation G</td><td>20 µm</td>",
        "<span class=\"badge v-fail\">FAIL</span> 2 of 4 judged tests out of tolerance",
    ] {
        assert!(cert.contains(needle), "certificate lacks {needle}");
    }
    for t in json["tests"].as_array().unwrap() {
        let file = t["file"].as_str().unwrap();
        let name: Vec<&str> = file.rsplit('/').take(2).collect();
        let label = format!("{}/{} @ 0,0,0 mm", name[1], name[0]);
        let row = between(cert, &label, "</tr>");
        let g = t["iso230_4"]["external"]["circular_deviation_um"]
            .as_f64()
            .unwrap();
        assert!(row.contains(&format!("<td>{g:.2}</td>")), "{label}: G {g}");
        let v = t["verdict"].as_str().unwrap();
        assert!(row.contains(&format!("badge v-{v}")), "{label}: {v}");
        if v == "fail" {
            assert!(row.contains("tcp backlash_x"), "{row}");
        }
    }
    let style = between(&html, "<style>", "</style>");
    assert!(style.contains("@page{size:A4"));
    let print = &style[style.find("@media print{").unwrap()..];
    assert!(print.contains(".certificate{break-before:page;break-after:page"));
    assert!(print.contains("nav.toc{display:none}"));
}

/// The session keys travel into `evaluate --json`; a date that is none is refused in one line
/// naming the key.
#[test]
fn session_keys_in_json_and_bad_dates_refused() {
    let (_dir, _, json) = setup("report-session");
    for t in json["tests"].as_array().unwrap() {
        assert_eq!(t["machine"], "VMC 4711");
        assert_eq!(t["date"], "2026-03-14");
    }
    let dir = Scratch::new("report-bad-date");
    for (date, needle) in [
        ("date = \"14.03.2026\"", "14.03.2026"),
        ("date = 20260314", "integer"),
        ("date = \"2026-02-30\"", "2026-02-30"),
    ] {
        let f = folder(&dir, "m", 0.0, 1, "");
        let text = std::fs::read_to_string(dir.path("m/rtest.toml")).unwrap();
        dir.write("m/rtest.toml", text.replace("date = 2026-03-14", date));
        let out = eij(&["evaluate", &f]);
        one_line_error(&out, &["rtest.toml", "date", needle]);
    }
    let f = folder(&dir, "t", 0.0, 1, "");
    let text = std::fs::read_to_string(dir.path("t/rtest.toml")).unwrap();
    dir.write("t/rtest.toml", text.replace("20.5", "250"));
    one_line_error(&eij(&["evaluate", &f]), &["temperature_c", "250"]);
}
