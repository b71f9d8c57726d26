//! DXF import (ASCII and binary, text included) must never panic on any bytes.
#![no_main]

use galvoplan::import::{import_dxf, FontSource, ImportOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let opts = ImportOptions {
        fonts: FontSource::BundledOnly,
        work_area_mm: Some([300.0, 300.0]),
        ..ImportOptions::default()
    };
    let _ = import_dxf(data, "fuzz.dxf", &opts);
});
