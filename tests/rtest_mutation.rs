//! The R-Test loaders (series, EIJ table, rtest.toml) under seeded mutations of the fuzz seeds
//! (see `tests/common/mutation.rs`): a value or a one-line error naming the source, never a
//! panic.

mod common;

use common::mutation::{one_line, run};
use eij::measured::conditions::TestConditions;
use eij::measured::table;
use eij::rtest::{evaluate, CircleSeries, EvalOptions};

#[test]
fn rtest_series_mutations() {
    run(
        "rtest_series",
        1,
        3000,
        |data| match CircleSeries::from_csv_bytes("fuzz.csv", data) {
            Ok(series) => {
                if let Err(e) = evaluate(&series, &EvalOptions::default()) {
                    one_line(&e, "fuzz.csv");
                }
            }
            Err(e) => one_line(&e, "fuzz.csv"),
        },
    );
}

#[test]
fn rtest_table_mutations() {
    run("rtest_table", 2, 50_000, |data| {
        if let Err(e) = table::from_bytes("fuzz.csv", data) {
            one_line(&e, "fuzz.csv");
        }
    });
}

#[test]
fn rtest_conditions_mutations() {
    run("rtest_conditions", 5, 50_000, |data| {
        let Ok(text) = std::str::from_utf8(data) else {
            return;
        };
        if let Err(e) = TestConditions::from_toml_str(text, "rtest.toml") {
            one_line(&e, "rtest.toml: ");
        }
    });
}
