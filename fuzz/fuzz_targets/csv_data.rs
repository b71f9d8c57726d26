//! CSV data files of production jobs must load or give an error, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = galvoplan::document::DataTable::parse(data, "fuzz.csv");
});
