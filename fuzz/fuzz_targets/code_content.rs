//! `--code` specs and code contents must give a symbol or an error, never panic: the spec is
//! read, then its content (fields left as written) encoded as its kind.
#![no_main]

use galvoplan::codes::symbol;
use galvoplan::document::CodeSpec;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(spec) = CodeSpec::parse(text) {
        let _ = symbol(&spec, &spec.content);
    }
});
