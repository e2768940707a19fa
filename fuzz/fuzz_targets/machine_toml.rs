//! Machine TOML: any text is validated into a machine or a one-line error naming the file; a
//! machine that validates assembles its closed loop at the reference pose or fails cleanly.
#![no_main]

use eij::control::ClosedLoop;
use eij::machine::Machine;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match Machine::from_toml_str(text, "fuzz.toml") {
        Ok(machine) => {
            let _ = ClosedLoop::new(&machine, &machine.reference_pose());
        }
        Err(e) => {
            let text = e.to_string();
            assert!(text.starts_with("fuzz.toml: "), "{text}");
            assert_eq!(text.lines().count(), 1, "{text}");
        }
    }
});
