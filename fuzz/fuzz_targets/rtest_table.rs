//! EIJ table CSV: any bytes are read into rows or a one-line error naming the file.
#![no_main]

use eij::measured::table;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    match table::from_bytes("fuzz.csv", data) {
        Ok(rows) => assert!(!rows.is_empty()),
        Err(e) => {
            let text = e.to_string();
            assert!(text.starts_with("fuzz.csv"), "{text}");
            assert_eq!(text.lines().count(), 1, "{text}");
        }
    }
});
