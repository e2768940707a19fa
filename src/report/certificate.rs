//! The certificate: one section of the report that prints on one A4 page (the page's print
//! style sheet starts it on a page of its own and ends that page after it): the machine, the
//! dates, instrument and conditions of the measurement, the tolerances, and per test its
//! circular deviation and its verdict, the overall verdict first. The colours are the
//! verdict's ([`super::diagnosis_html`]).

use std::collections::BTreeSet;
use std::fmt::Write as _;

use super::diagnosis_html::{badge, failed_checks};
use super::labels::{feed_mm_min, test_name};
use super::page::{escape, Page};
use super::short;
use crate::measured::suite::diagnose::SuiteDiagnosis;
use crate::measured::suite::Suite;
use crate::rtest::diagnosis::tolerance::{Limits, Tolerances};
use crate::rtest::diagnosis::Source;

/// The anchor of the certificate.
pub(crate) const ID: &str = "certificate";
/// The last line of the certificate (the print check looks for it on the certificate's page).
pub(crate) const END: &str = "End of certificate.";

/// Above this many tests the printed certificate may run onto a second A4 page: a test is one
/// table line of about 2.2 mm; measured with `tests/print-check.sh` (docs/diagnosis.md), 106
/// tests without tolerances still fit on one page, 110 do not; lines that wrap (long lists of
/// failed checks) and many tolerance lines leave room for fewer.
const ONE_PAGE_TESTS: usize = 95;

/// What the certificate states besides the tests.
pub(crate) struct CertificateInput<'a> {
    /// The evaluated tests.
    pub suite: &'a Suite,
    /// Their diagnosis and verdicts (`None` where it could not be made).
    pub diagnosis: Option<&'a SuiteDiagnosis>,
    /// Machines named by identify reports, used where `rtest.toml` names none.
    pub machines_elsewhere: Vec<String>,
    /// When the report was written, and by which eij.
    pub written: String,
    /// The test conditions (planes, directions, radius, accelerations, feeds, centres).
    pub conditions: String,
    /// The data folders.
    pub folders: String,
}

/// Distinct values of the tests' sessions, in the order met.
fn distinct(values: impl Iterator<Item = Option<String>>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for v in values.flatten() {
        if !out.contains(&v) {
            out.push(v);
        }
    }
    out
}

/// The rows of one source's limits: (source, quantity, limit with unit).
fn limit_rows(source: Source, l: &Limits) -> Vec<[String; 3]> {
    let mut rows = Vec::new();
    if let Some(g) = l.circular_deviation_um {
        rows.push([
            source.name().to_string(),
            "circular deviation G".into(),
            format!("{} µm", short(g, 4)),
        ]);
    }
    for (term, limit) in &l.terms {
        rows.push([
            source.name().to_string(),
            format!("|{term}|"),
            short(*limit, 4),
        ]);
    }
    rows
}

/// The tolerances as a table, per set of folders that share them.
fn tolerances_html(suite: &Suite) -> String {
    let mut sets: Vec<(&Tolerances, BTreeSet<String>)> = Vec::new();
    for t in &suite.tests {
        let folder = t.input.conditions_file.as_ref().map_or("–".into(), |f| {
            f.parent()
                .map_or(String::new(), |p| p.display().to_string())
        });
        match sets.iter_mut().find(|(tol, _)| **tol == t.input.tolerances) {
            Some((_, folders)) => {
                folders.insert(folder);
            }
            None => sets.push((&t.input.tolerances, BTreeSet::from([folder]))),
        }
    }
    let mut h = String::new();
    for (tol, folders) in &sets {
        let from = if sets.len() > 1 {
            format!(
                " of {}",
                escape(&folders.iter().cloned().collect::<Vec<_>>().join(", "))
            )
        } else {
            String::new()
        };
        if tol.is_empty() {
            let _ = writeln!(
                h,
                "<p>Tolerances{from}: none given (<code>[tolerances]</code> in rtest.toml): \
                 the tests are measured, not judged.</p>"
            );
            continue;
        }
        let _ = writeln!(
            h,
            "<p>Tolerances{from} (limits on |value|; units of the term, µm unless stated in \
             its name):</p>\n<table class=\"cert\"><tr><th class=\"l\">source</th>\
             <th class=\"l\">quantity</th><th>limit</th></tr>"
        );
        for (source, limits) in &tol.sources {
            for [s, q, l] in limit_rows(*source, limits) {
                let _ = writeln!(
                    h,
                    "<tr><td class=\"l\">{s}</td><td class=\"l\">{}</td><td>{l}</td></tr>",
                    escape(&q)
                );
            }
        }
        h.push_str("</table>\n");
    }
    h
}

/// The overall verdict line.
fn overall(d: Option<&SuiteDiagnosis>, n: usize) -> String {
    let Some(d) = d else {
        return format!(
            "<p class=\"cert-verdict\">{} the tests could not be diagnosed (see the verdict \
             above)</p>\n",
            badge(None)
        );
    };
    let judged = d.verdicts.iter().flatten().count();
    let failed = d.failed().len();
    let text = match d.verdict() {
        None => format!("none of the {n} tests has tolerances"),
        Some("pass") => format!("all {judged} judged tests within tolerance (of {n})"),
        Some(_) => format!("{failed} of {judged} judged tests out of tolerance (of {n})"),
    };
    format!(
        "<p class=\"cert-verdict\">{} {text}</p>\n",
        badge(d.verdict())
    )
}

/// Appends the certificate to `page`.
pub(crate) fn certificate(page: &mut Page, c: &CertificateInput) {
    let tests = &c.suite.tests;
    page.push("<div class=\"certificate\">\n");
    page.heading(2, ID, "Certificate of the circle tests");
    let mut h = overall(c.diagnosis, tests.len());
    let sessions = || tests.iter().map(|t| &t.input.session);
    let mut machines = distinct(sessions().map(|s| s.machine.clone()));
    if machines.is_empty() {
        machines = c.machines_elsewhere.clone();
    }
    let join = |v: Vec<String>, none: &str| {
        if v.is_empty() {
            none.to_string()
        } else {
            v.join("; ")
        }
    };
    let temps = distinct(sessions().map(|s| s.temperature_c.map(|t| format!("{t:.1} °C"))));
    let rows = [
        (
            "machine",
            join(machines, "not stated (give machine = \"…\" in rtest.toml)"),
        ),
        (
            "measured on",
            join(
                distinct(sessions().map(|s| s.date.clone())),
                "not stated (give date = YYYY-MM-DD in rtest.toml)",
            ),
        ),
        (
            "instrument",
            join(
                distinct(sessions().map(|s| s.instrument.clone())),
                "not stated",
            ),
        ),
        ("ambient temperature", join(temps, "not stated")),
        ("conditions", c.conditions.clone()),
        ("data", c.folders.clone()),
        ("report written", c.written.clone()),
    ];
    h.push_str("<table class=\"head cert-head\">\n");
    for (k, v) in rows {
        let _ = writeln!(h, "<tr><th>{k}</th><td>{}</td></tr>", escape(&v));
    }
    h.push_str("</table>\n");
    h.push_str(&tolerances_html(c.suite));
    h.push_str(
        "<table class=\"cert\">\n<tr><th>#</th><th class=\"l\">test</th><th>plane</th>\
         <th>dir</th><th>a / (m/s²)</th><th>feed / (mm/min)</th><th>G TCP / µm</th>\
         <th>G axes / µm</th><th>verdict</th><th class=\"l\">out of tolerance</th></tr>\n",
    );
    for (i, t) in tests.iter().enumerate() {
        let verdict = c.diagnosis.and_then(|d| d.verdicts[i].as_ref());
        let v = verdict.map(|v| v.verdict);
        let failed = verdict.map_or(Vec::new(), failed_checks);
        let iso = t.result.iso230;
        let g = |ext: bool| {
            iso.map_or("–".into(), |f| {
                let p = if ext { f.external } else { f.internal };
                format!("{:.2}", p.circular_deviation_um)
            })
        };
        let r = &t.result;
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td>\
             <td>{}</td><td>{:.0}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"w\">{}</td></tr>",
            i + 1,
            escape(&test_name(t)),
            r.plane,
            r.direction,
            short(r.accel_m_s2, 2),
            feed_mm_min(r),
            g(true),
            g(false),
            badge(v),
            escape(&failed.join("; "))
        );
    }
    h.push_str("</table>\n");
    if tests.len() > ONE_PAGE_TESTS {
        let _ = writeln!(
            h,
            "<p class=\"note\"><b>{} tests: printed on A4, this certificate may run onto a second \
             page (one page holds about 100 tests); keep its pages together.</b></p>",
            tests.len()
        );
    }
    let _ = writeln!(
        h,
        "<p class=\"note\">G: ISO 230-4 circular deviation over the steady revolutions, of the \
         TCP (R-Test) and of the axes' own readings. A test passes when every limit it can be \
         checked against holds (value compared with the limit; the standard errors are in the \
         breakdown beside each circle plot). eij {}.</p>\n\
         <p class=\"sign\">Checked by: ____________________ &nbsp; Date: ____________ &nbsp; \
         Signature: ____________________</p>\n<p class=\"note\">{END}</p>",
        env!("CARGO_PKG_VERSION")
    );
    page.push(&h);
    page.push("</div>\n");
}
