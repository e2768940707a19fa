//! The machine file loader under seeded mutations of the fuzz seeds (see
//! `tests/common/mutation.rs`): a machine or a one-line error naming the file, never a panic.

mod common;

use common::mutation::{one_line, run};
use eij::machine::Machine;

#[test]
fn machine_toml_mutations() {
    run("machine_toml", 3, 20_000, |data| {
        let Ok(text) = std::str::from_utf8(data) else {
            return;
        };
        if let Err(e) = Machine::from_toml_str(text, "fuzz.toml") {
            one_line(&e, "fuzz.toml: ");
        }
    });
}
