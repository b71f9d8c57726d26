//! SVG import (with text laid out in the bundled font) must never panic on any bytes.
#![no_main]

use galvoplan::import::{import_svg, FontSource, ImportOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let opts = ImportOptions {
        fonts: FontSource::BundledOnly,
        ..ImportOptions::default()
    };
    let _ = import_svg(data, "fuzz.svg", &opts);
});
