//! `--record` (alias `--rerun`): HHA and HGA runs write a non-empty, decodable .rrd (feature
//! `rerun`, on in the shipped build).
#![cfg(feature = "rerun")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use rerun::external::re_log_encoding::DecoderApp;
use std::process::Command;

fn record(algo: &str, flag: &str, dir: &std::path::Path) -> std::path::PathBuf {
    let rrd = dir.join(format!("{algo}.rrd"));
    let demo = common::root().join("assets/examples/demo.svg");
    let out = Command::new(env!("CARGO_BIN_EXE_galvoplan"))
        .args(["plan", &demo.display().to_string(), "-o"])
        .arg(dir.join(format!("{algo}.gcode")))
        .args(["--algo", algo, "--time-limit", "3", flag])
        .arg(&rrd)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    rrd
}

fn decoded_messages(path: &std::path::Path) -> usize {
    let bytes = std::fs::read(path).unwrap();
    assert!(
        bytes.len() > 1000,
        "{} is only {} bytes",
        path.display(),
        bytes.len()
    );
    assert_eq!(&bytes[..4], b"RRF2", "rerun file magic");
    let reader = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut n = 0;
    for msg in DecoderApp::decode_eager(reader).unwrap() {
        let _decoded = msg.expect("every message decodes");
        n += 1;
    }
    n
}

#[test]
fn hha_and_hga_recordings_are_written_and_readable() {
    let dir = tempfile::tempdir().unwrap();
    let hha = decoded_messages(&record("hha", "--record", dir.path()));
    let hga = decoded_messages(&record("hga", "--rerun", dir.path()));
    assert!(hha >= 4, "artwork, fields, marks, idle: {hha} messages");
    assert!(
        hga > hha,
        "HGA adds the convergence series: {hga} vs {hha} messages"
    );
}
