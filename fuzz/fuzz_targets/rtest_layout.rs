//! A column map and a data file (an `rtest.toml`, a line `%%`, the data): conditions or a
//! one-line error naming `rtest.toml`; then a series read with the map and evaluated, or a
//! one-line error naming the data file.
#![no_main]

use eij::measured::conditions::TestConditions;
use eij::rtest::{evaluate, CircleSeries, EvalOptions};
use libfuzzer_sys::fuzz_target;

fn one_line(e: &dyn std::fmt::Display, source: &str) {
    let text = e.to_string();
    assert!(text.starts_with(source), "{text}");
    assert_eq!(text.lines().count(), 1, "{text}");
}

fuzz_target!(|data: &[u8]| {
    let (toml, csv) = match data.windows(3).position(|w| w == b"%%\n") {
        Some(i) => (&data[..i], &data[i + 3..]),
        None => (data, &[][..]),
    };
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
