//! Pen files (TOML, a pen per layer) must load or give an error, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = galvoplan::document::PenLibrary::from_toml(text, "fuzz.pens.toml");
    }
});
