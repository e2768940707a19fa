//! The identification config under seeded mutations of the fuzz seeds (see
//! `tests/common/mutation.rs`): settings or an error, never a panic.

mod common;

use common::mutation::run;
use eij::ident::config::IdentConfig;
use eij::ident::{MeasuredOptions, Settings};

#[test]
fn ident_config_mutations() {
    run("ident_config", 4, 50_000, |data| {
        let Ok(text) = std::str::from_utf8(data) else {
            return;
        };
        if let Ok(config) = toml::from_str::<IdentConfig>(text) {
            let _ = config.apply(&mut Settings::default(), &mut MeasuredOptions::default());
        }
    });
}
