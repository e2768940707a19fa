//! Identification config (`--config`): any text is parsed and applied to the default settings
//! or refused; nothing panics.
#![no_main]

use eij::ident::config::IdentConfig;
use eij::ident::measured::MeasuredOptions;
use eij::ident::Settings;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(config) = toml::from_str::<IdentConfig>(text) {
        let _ = config.apply(&mut Settings::default(), &mut MeasuredOptions::default());
    }
});
