//! R-Test circle-test CSV: any bytes are read into a series or a one-line error, and a series
//! that reads evaluates to a result or a one-line error; nothing panics.
#![no_main]

use eij::rtest::{evaluate, CircleSeries, EvalOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    match CircleSeries::from_csv_bytes("fuzz.csv", data) {
        Ok(series) => {
            if let Err(e) = evaluate(&series, &EvalOptions::default()) {
                assert_eq!(e.to_string().lines().count(), 1, "{e}");
            }
        }
        Err(e) => assert_eq!(e.to_string().lines().count(), 1, "{e}"),
    }
});
