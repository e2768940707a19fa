//! `[[pairing]]` (docs/measurement-files.md): the internal and external files of many
//! two-system tests given by two patterns are the tests that one `[[test]]` entry per pair
//! gives — the same EIJ, clock offset, plane and direction (from the data) — whether they pair
//! by equal stems, by the start times in the data or by the order of their names; the files in
//! the pattern's sub-folders are not tests of their own; wrong pairs and ambiguous patterns are
//! refused with one line naming `rtest.toml`, the entry and the file.
//!
//! Data: the synthetic circle generator of `tests/common/synth.rs` (known EIJ, seeded noise),
//! internal readings written in machine coordinates (centre [150, −100, 0] mm), the external
//! clock 4 ms behind the internal one.

mod common;

use common::synth::Synth;
use common::{one_line_error, Scratch};
use eij::axes::{Direction, Plane};
use eij::measured::inputs::{expand_tests, PairedOn};
use eij::measured::suite::{evaluate_tests, Suite, SuiteOptions};

const HEAD: &str =
    "radius_mm = 2.0\nposition_mm = [150.0, -100.0, 0.0]\ninternal_coordinates = \"absolute\"\n";
const PAIRING: &str = "[[pairing]]\ninternal = \"cnc/*.csv\"\nexternal = \"rtest/*.csv\"\n";

/// The tests: zx cw/ccw at 2 and 8 m/s² (they separate the clock offset) and one xy.
fn tests() -> Vec<(String, Synth)> {
    let mut v = Vec::new();
    for (k, (plane, ccw, a)) in [
        (Plane::Zx, false, 2.0),
        (Plane::Zx, true, 2.0),
        (Plane::Zx, false, 8.0),
        (Plane::Zx, true, 8.0),
        (Plane::Xy, true, 5.0),
    ]
    .into_iter()
    .enumerate()
    {
        let mut s = Synth::new(plane, ccw, a);
        s.seed = 1000 + k as u64;
        let dir = if ccw { "ccw" } else { "cw" };
        v.push((format!("{plane}_{dir}_{a}"), s));
    }
    v
}

/// Internal (absolute, clock `start`) and external (clock `start` − 4 ms) files of one test.
fn files(s: &Synth, start: f64) -> (String, String) {
    let (t, int, ext) = s.columns();
    let centre = [150.0, -100.0, 0.0];
    let mut i = String::from("t_s,x_int_mm,y_int_mm,z_int_mm\n");
    let mut e = String::from("# R-Test logger export\nt_s,x_ext_mm,y_ext_mm,z_ext_mm\n");
    for k in 0..t.len() {
        i.push_str(&format!(
            "{},{},{},{}\n",
            t[k] + start,
            int[0][k] + centre[0],
            int[1][k] + centre[1],
            int[2][k] + centre[2]
        ));
        e.push_str(&format!(
            "{},{},{},{}\n",
            t[k] + start - 0.004,
            ext[0][k],
            ext[1][k],
            ext[2][k]
        ));
    }
    (i, e)
}

fn evaluate(dir: &std::path::Path) -> Result<Suite, String> {
    let tests = expand_tests(&[dir.to_path_buf()]).map_err(|e| e.to_string())?;
    evaluate_tests(&tests, &SuiteOptions::default()).map_err(|e| e.to_string())
}

/// The same tests, by test number in `tests()`, as `[[test]]` entries and as a pairing named
/// by stems, by start times and by names: equal EIJ and clock offsets (to 1e-6 µm·s²/m and
/// ms: the clocks of "times" run to 800 s and round differently), the plane and
/// direction of the generator, the test count of the pairs (the sub-folders' files are not
/// single-file tests).
#[test]
fn a_pairing_gives_the_tests_of_one_entry_per_pair() {
    let d = Scratch::new("pairing");
    let all = tests();
    let mut entries = String::from(HEAD);
    // Names whose order differs from the recording order; recordings 200 s apart on clocks
    // that run through the session ("times") or start anew in each file (the others).
    let scrambled = [3, 0, 4, 1, 2];
    for (k, (name, s)) in all.iter().enumerate() {
        let (i, e) = files(s, 0.0);
        d.write(&format!("entries/cnc/{name}.csv"), &i);
        d.write(&format!("entries/rtest/{name}.csv"), &e);
        entries.push_str(&format!(
            "[[test]]\ninternal = \"cnc/{name}.csv\"\nexternal = \"rtest/{name}.csv\"\n"
        ));
        d.write(&format!("stems/cnc/{name}.csv"), &i);
        d.write(&format!("stems/rtest/{name}.csv"), &e);
        d.write(&format!("names/cnc/trace_{k:02}.csv"), &i);
        d.write(&format!("names/rtest/R{:04}.csv", k + 1), &e);
        let (i, e) = files(s, 200.0 * k as f64);
        d.write(&format!("times/cnc/trace_{}.csv", scrambled[k]), &i);
        d.write(&format!("times/rtest/RT_{}.csv", 4 - scrambled[k]), &e);
    }
    d.write("entries/rtest.toml", &entries);
    for f in ["stems", "names", "times"] {
        d.write(&format!("{f}/rtest.toml"), format!("{HEAD}{PAIRING}"));
    }
    let reference = evaluate(&d.path("entries")).unwrap();
    assert_eq!(reference.tests.len(), all.len());
    for (f, on) in [
        ("stems", PairedOn::Stems),
        ("names", PairedOn::Names),
        ("times", PairedOn::StartTimes),
    ] {
        let suite = evaluate(&d.path(f)).unwrap();
        assert_eq!(suite.tests.len(), all.len(), "{f}");
        for t in &suite.tests {
            assert_eq!(t.input.paired.unwrap().on, on, "{f}");
            assert_eq!(t.input.paired.unwrap().pairing, 1);
            // Its test: the one of the same circle (every test's circle differs).
            let r = reference
                .tests
                .iter()
                .find(|r| {
                    r.result.plane == t.result.plane
                        && r.result.direction == t.result.direction
                        && (r.result.accel_m_s2 / t.result.accel_m_s2 - 1.0).abs() < 0.01
                })
                .unwrap_or_else(|| panic!("{f}: {} has no reference", t.input.name()));
            let (a, b) = (t.result.eij.value_map(), r.result.eij.value_map());
            for (p, v) in &b {
                assert!(
                    (a[p] - v).abs() < 1e-6,
                    "{f} {}: {p} {} vs {v}",
                    t.input.name(),
                    a[p]
                );
            }
            let (o, ro) = (
                t.time_offset.as_ref().unwrap(),
                r.time_offset.as_ref().unwrap(),
            );
            assert!((o.offset_ms - ro.offset_ms).abs() < 1e-6, "{f}");
        }
    }
    // The generator's planes and directions, from the data alone.
    for (name, s) in &all {
        let t = reference
            .tests
            .iter()
            .find(|t| t.input.primary_file().ends_with(format!("cnc/{name}.csv")))
            .unwrap();
        assert_eq!(t.result.plane, s.plane, "{name}");
        let dir = if s.ccw { Direction::Ccw } else { Direction::Cw };
        assert_eq!(t.result.direction, dir, "{name}");
        assert!(
            (t.result.accel_m_s2 / s.accel_m_s2 - 1.0).abs() < 0.01,
            "{name}"
        );
    }
    // One constant offset over the folder: external stamps 4 ms early, internal − external
    // clock = +4 ms, within three standard errors.
    let c = &reference.clocks[0];
    assert!(c.separable, "{c:?}");
    assert!(
        (c.offset_ms - 4.0).abs() < 3.0 * c.std_err_ms.unwrap(),
        "{c:?}"
    );
}

/// Wrong pairs and ambiguous patterns: one line each, naming the file and the entry.
#[test]
fn wrong_pairings_are_refused_with_one_line() {
    let d = Scratch::new("pairing-bad");
    let all = tests();
    let write = |folder: &str, cnc: &[(String, usize)], rtest: &[(String, usize)], toml: &str| {
        for (name, k) in cnc {
            d.write(&format!("{folder}/cnc/{name}"), files(&all[*k].1, 0.0).0);
        }
        for (name, k) in rtest {
            d.write(&format!("{folder}/rtest/{name}"), files(&all[*k].1, 0.0).1);
        }
        d.write(&format!("{folder}/rtest.toml"), format!("{HEAD}{toml}"));
    };
    let n = |s: &str, k: usize| (s.to_string(), k);
    // External files named in another order than the internal ones: not one test.
    write(
        "swapped",
        &[n("a1.csv", 0), n("a2.csv", 4)],
        &[n("b1.csv", 4), n("b2.csv", 0)],
        PAIRING,
    );
    // Three internal files, two external ones.
    write(
        "counts",
        &[n("a1.csv", 0), n("a2.csv", 1), n("a3.csv", 2)],
        &[n("b1.csv", 0), n("b2.csv", 1)],
        PAIRING,
    );
    // Stems shared by some pairs only.
    write(
        "partial",
        &[n("zx1.csv", 0), n("zx2.csv", 1)],
        &[n("zx1.csv", 0), n("other.csv", 1)],
        PAIRING,
    );
    // Two internal files with the stem of one external file.
    write(
        "claim",
        &[n("zx1.csv", 0), n("zx1.txt", 0)],
        &[n("zx1.csv", 0)],
        "[[pairing]]\ninternal = \"cnc/*\"\nexternal = \"rtest/*.csv\"\n",
    );
    write(
        "nomatch",
        &[n("zx1.csv", 0)],
        &[n("zx1.csv", 0)],
        "[[pairing]]\ninternal = \"cnc/*.sco\"\nexternal = \"rtest/*.csv\"\n",
    );
    write(
        "entry",
        &[n("zx1.csv", 0)],
        &[n("zx1.csv", 0)],
        &format!("{PAIRING}[[test]]\ninternal = \"cnc/zx1.csv\"\nexternal = \"rtest/zx1.csv\"\n"),
    );
    write(
        "missing",
        &[n("zx1.csv", 0)],
        &[n("zx1.csv", 0)],
        "[[pairing]]\ninternal = \"cnc/*.csv\"\n",
    );
    write(
        "outside",
        &[n("zx1.csv", 0)],
        &[n("zx1.csv", 0)],
        "[[pairing]]\ninternal = \"../cnc/*.csv\"\nexternal = \"rtest/*.csv\"\n",
    );
    let cases: [(&str, &[&str]); 8] = [
        (
            "swapped",
            &[
                "swapped/cnc/a1.csv + ",
                "not one test: the internal recording is a zx cw circle at",
                "the external one a xy ccw circle",
                "in recording order (order of the file names) by [[pairing]] #1 of",
            ],
        ),
        (
            "counts",
            &["rtest.toml: [[pairing]] #1 external: 3 internal files match 'cnc/*.csv' but 2 external files"],
        ),
        (
            "partial",
            &["[[pairing]] #1 internal:", "cnc/zx2.csv: no external file of the same stem, while 1 file(s) pair by stem"],
        ),
        (
            "claim",
            &["[[pairing]] #1 internal:", "cnc/zx1.csv and ", "cnc/zx1.txt both claim ", "rtest/zx1.csv as their partner"],
        ),
        ("nomatch", &["[[pairing]] #1 internal: 'cnc/*.sco' matches no file in"]),
        (
            "entry",
            &["[[pairing]] #1 internal: ", "cnc/zx1.csv: already named by [[test]] #1 internal"],
        ),
        ("missing", &["[[pairing]] #1 external: missing: a pairing needs internal and external patterns"]),
        ("outside", &["[[pairing]] #1 internal: '../cnc/*.csv': a pattern names files inside the folder"]),
    ];
    for (folder, needles) in cases {
        let e = evaluate(&d.path(folder)).unwrap_err();
        for n in needles {
            assert!(e.contains(n), "{folder}: '{n}' not in: {e}");
        }
        one_line_error(&common::eij(&["evaluate", &d.s(folder)]), needles);
    }
}
