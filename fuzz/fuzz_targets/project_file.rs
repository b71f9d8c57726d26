//! Project files (versioned JSON) must load or give an error, never panic. Goes through
//! `load_project`, the path the CLI and GUI take (a file in /dev/shm, written and removed each
//! run, so that none is left behind).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

fn scratch() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let dir = if std::path::Path::new("/dev/shm").is_dir() {
            PathBuf::from("/dev/shm")
        } else {
            std::env::temp_dir()
        };
        dir.join(format!("galvoplan-fuzz-{}.galvoplan", std::process::id()))
    })
}

fuzz_target!(|data: &[u8]| {
    let path = scratch();
    if std::fs::write(path, data).is_ok() {
        let _ = galvoplan::document::load_project(path);
        let _ = std::fs::remove_file(path);
    }
});
