//! `rtest.toml`: any text gives conditions or a one-line error naming the file.
#![no_main]

use eij::measured::conditions::TestConditions;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Err(e) = TestConditions::from_toml_str(text, "rtest.toml") {
        let text = e.to_string();
        assert!(text.starts_with("rtest.toml: "), "{text}");
        assert_eq!(text.lines().count(), 1, "{text}");
    }
});
