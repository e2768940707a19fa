//! The newer input paths under seeded mutations (see `tests/common/mutation.rs`): column maps
//! (`rtest.toml` `[columns]` applied to a file of other names and units), `[[test]]` tables of a
//! folder, and tests recorded by two systems (internal and external file on their own clocks).
//! Every input gives a result or a one-line error naming the source; nothing panics. The seeds
//! are `fuzz/seeds/rtest_layout` (an `rtest.toml`, a line `%%`, a data file),
//! `fuzz/seeds/rtest_folder` and `fuzz/seeds/rtest_split`.

mod common;

use common::mutation::{inputs, mutate, one_line, run, Rng};
use common::{root, Scratch};
use eij::measured::conditions::TestConditions;
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{evaluate_tests, SuiteOptions};
use eij::rtest::{evaluate, CircleSeries, EvalOptions};

/// The conditions and the data of a layout seed (split at the line `%%`).
fn halves(data: &[u8]) -> (&[u8], &[u8]) {
    match data.windows(3).position(|w| w == b"%%\n") {
        Some(i) => (&data[..i], &data[i + 3..]),
        None => (data, &[]),
    }
}

#[test]
fn column_map_mutations() {
    run("rtest_layout", 11, 4000, |data| {
        let (toml, csv) = halves(data);
        let Ok(text) = std::str::from_utf8(toml) else {
            return;
        };
        let cond = match TestConditions::from_toml_str(text, "rtest.toml") {
            Ok(c) => c,
            Err(e) => return one_line(&e, "rtest.toml: "),
        };
        for map in [&cond.columns, &cond.internal_columns] {
            match CircleSeries::from_csv_bytes_with("fuzz.csv", csv, map) {
                Ok(series) => {
                    let opts = EvalOptions {
                        plane: None,
                        radius_mm: cond.radius_mm,
                    };
                    if let Err(e) = evaluate(&series, &opts) {
                        one_line(&e, "fuzz.csv");
                    }
                }
                Err(e) => one_line(&e, "fuzz.csv"),
            }
        }
    });
}

/// A folder with the seed files of a single-file and a two-system test.
fn folder(tag: &str) -> Scratch {
    let s = Scratch::new(tag);
    let fuzz = root().join("fuzz/seeds");
    for (from, to) in [
        ("rtest_series/zx_ccw_50.csv", "a.csv"),
        ("rtest_split/int.csv", "int.csv"),
        ("rtest_split/ext.csv", "ext.csv"),
        ("rtest_folder/rtest.toml", "rtest.toml"),
    ] {
        s.write(to, std::fs::read(fuzz.join(from)).unwrap());
    }
    s
}

/// Expands and evaluates the folder: a suite or one error line that names a file of it.
fn evaluate_folder(s: &Scratch) {
    let dir = s.0.display().to_string();
    let result = expand_tests(std::slice::from_ref(&s.0))
        .and_then(|tests| evaluate_tests(&tests, &SuiteOptions::default()));
    if let Err(e) = result {
        one_line(&e, &dir);
    }
}

#[test]
fn test_table_mutations() {
    let s = folder("mut-table");
    evaluate_folder(&s);
    run("rtest_folder", 12, 600, |data| {
        s.write("rtest.toml", data);
        evaluate_folder(&s);
    });
}

#[test]
fn split_recording_mutations() {
    let s = folder("mut-split");
    s.write(
        "rtest.toml",
        "radius_mm = 2.0\n[[test]]\ninternal = \"int.csv\"\nexternal = \"ext.csv\"\n",
    );
    let _ = std::fs::remove_file(s.path("a.csv"));
    evaluate_folder(&s);
    let seeds = inputs("rtest_split");
    let mut rng = Rng(13);
    for _ in 0..600 {
        // Mutate one of the two files; the other stays as recorded.
        let which = rng.below(seeds.len());
        let name = if std::str::from_utf8(&seeds[which]).is_ok_and(|t| t.contains("_int_mm")) {
            "int.csv"
        } else {
            "ext.csv"
        };
        s.write(name, mutate(&mut rng, &seeds[which]));
        evaluate_folder(&s);
        s.write(name, &seeds[which]);
    }
}
