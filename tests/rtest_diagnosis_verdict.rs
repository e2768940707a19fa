//! `[tolerances]` of `rtest.toml` and the verdict of a diagnosed test
//! (`eij::rtest::diagnosis::tolerance`).

mod common;

use common::circle_terms::TermCircle;
use eij::axes::Plane;
use eij::rtest::diagnosis::tolerance::{judge, Tolerances};
use eij::rtest::diagnosis::{diagnose_series, DiagnosisOptions, Source};
use eij::rtest::EvalOptions;

fn parse(text: &str) -> Result<Tolerances, String> {
    let table: toml::Table = text.parse().unwrap();
    Tolerances::from_toml(&table).map_err(|e| e.to_string())
}

#[test]
fn keys_name_a_term_or_family_and_its_unit() {
    let t = parse(
        "circular_deviation_um = 10\nbacklash_um = 3\nbacklash_x_um = 2\nsquareness_um_per_m = 50\n\
         servo_mismatch_ms = 0.5\ncyclic_y_h2_um = 0.3\ncentre_offset_a_um = 20\n\
         [internal]\ncircular_deviation_um = 6\n[structure]\nscale_mismatch_um = 2",
    )
    .unwrap();
    let tcp = &t.sources[&Source::Tcp];
    assert_eq!(tcp.circular_deviation_um, Some(10.0));
    let terms: Vec<(&str, f64)> = tcp.terms.iter().map(|(k, v)| (k.as_str(), *v)).collect();
    assert_eq!(
        terms,
        [
            ("backlash", 3.0),
            ("backlash_x", 2.0),
            ("centre_offset_a", 20.0),
            ("cyclic_y_h2", 0.3),
            ("servo_mismatch", 0.5),
            ("squareness", 50.0)
        ]
    );
    assert_eq!(
        t.sources[&Source::Internal].circular_deviation_um,
        Some(6.0)
    );
    assert_eq!(t.sources[&Source::Structure].terms["scale_mismatch"], 2.0);
}

#[test]
fn bad_keys_are_named_with_what_is_wrong() {
    let cases = [
        (
            "backlash_mm = 3",
            "tolerances.backlash_mm: backlash is in um",
        ),
        ("squareness_um = 3", "squareness is in um_per_m"),
        ("backlash_q_um = 3", "backlash_q: no such term"),
        ("wobble_um = 3", "tolerances.wobble_um: unknown term"),
        ("backlash_um = -1", "expected a number > 0"),
        ("backlash_um = \"3\"", "expected a number, found string"),
        (
            "[spindle]\nbacklash_um = 3",
            "tolerances.spindle: unknown table",
        ),
        (
            "[internal]\nbacklash_mm = 3",
            "tolerances.internal.backlash_mm",
        ),
        ("backlash_um = 3\n[tcp]\nbacklash_um = 2", "given twice"),
        ("cyclic_x_h1_um = 1", "no such term"),
    ];
    for (text, needle) in cases {
        let e = parse(text).expect_err(text);
        assert!(e.contains(needle), "{text}: {e}");
    }
}

/// 3 µm of lost motion on x: a 2 µm limit fails backlash_x and passes backlash_y; a 4 µm one
/// passes both; servo mismatch (no test in the other direction) stays unchecked.
#[test]
fn terms_beyond_their_limit_fail_the_test() {
    let mut c = TermCircle::new(Plane::Xy, true, 3.0);
    c.internal.backlash_um = [3.0, 0.0];
    let eval = EvalOptions {
        radius_mm: Some(2.0),
        ..Default::default()
    };
    let mut d = diagnose_series(&c.series(), &eval, &DiagnosisOptions::default()).unwrap();
    let g = d.source(Source::Tcp).circular_deviation_um;
    let tight =
        parse("backlash_um = 2\nservo_mismatch_ms = 0.1\ncircular_deviation_um = 10").unwrap();
    let v = judge(&mut d, &tight);
    assert_eq!(v.verdict, "fail");
    let got: Vec<(&str, &str)> = v
        .checks
        .iter()
        .map(|c| (c.name.as_str(), c.verdict))
        .collect();
    assert_eq!(
        got,
        [
            ("circular_deviation", "pass"),
            ("backlash_x", "fail"),
            ("backlash_y", "pass")
        ]
    );
    assert_eq!(v.checks[0].value, g);
    assert_eq!(v.unchecked, ["tcp servo_mismatch"]);
    let term = d.source(Source::Tcp).term("backlash_x").unwrap();
    assert_eq!((term.limit, term.verdict), (Some(2.0), Some("fail")));
    // The internal path's terms are not limited by the TCP's tolerances.
    assert_eq!(
        d.source(Source::Internal).term("backlash_x").unwrap().limit,
        None
    );

    let loose = parse("backlash_um = 4\n[internal]\ncircular_deviation_um = 0.5").unwrap();
    let v = judge(&mut d, &loose);
    let got: Vec<(Source, &str, &str)> = v
        .checks
        .iter()
        .map(|c| (c.source, c.name.as_str(), c.verdict))
        .collect();
    assert_eq!(
        got,
        [
            (Source::Internal, "circular_deviation", "fail"),
            (Source::Tcp, "backlash_x", "pass"),
            (Source::Tcp, "backlash_y", "pass")
        ]
    );
    assert!(!v.passed());
}
