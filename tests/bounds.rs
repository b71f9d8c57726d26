//! Hostile files (tests/data/hostile/): each is refused at once with one short error naming the
//! element and where it is, by the library and by the CLI, and nothing is written.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::import::{import_file, ImportOptions, MAX_GLYPHS};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn hostile(name: &str) -> PathBuf {
    common::root().join("tests/data/hostile").join(name)
}

/// Plans `input` with the CLI into `dir`: the exit status and stderr; a hang guard of 20 s
/// (the refusals take milliseconds: speed is measured in docs/BENCHMARKS.md, not here).
fn plan(input: &Path, dir: &Path) -> (bool, String, Duration) {
    let t0 = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_galvoplan"))
        .arg("plan")
        .arg(input)
        .arg("-o")
        .arg(dir.join("out.gcode"))
        .arg("--report")
        .arg(dir.join("out.json"))
        .output()
        .unwrap();
    let took = t0.elapsed();
    assert!(
        took < Duration::from_secs(20),
        "{}: {took:?}",
        input.display()
    );
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        took,
    )
}

/// The CLI refuses `input` in at most 3 lines that contain every one of `names`, and writes
/// nothing.
fn refused(input: &Path, names: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let (ok, stderr, _) = plan(input, dir.path());
    assert!(!ok, "{}: accepted", input.display());
    let lines = stderr.trim_end().lines().count();
    assert!((1..=3).contains(&lines), "{lines} lines:\n{stderr}");
    for name in names {
        assert!(stderr.contains(name), "{name} not in:\n{stderr}");
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "wrote files"
    );
}

/// demo.svg with a path starting at x = 4.7·10⁶⁰ (a fuzzer's edit): it took 65 s and 24 GB
/// before the OOM killer ended galvoplan.
#[test]
fn a_coordinate_of_1e60_is_refused_naming_the_path() {
    let f = hostile("demo-huge-coordinate.svg");
    refused(
        &f,
        &["<path>", "line 124", "a coordinate of 4.6667e60", "beyond"],
    );
    let e = import_file(&f, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(!e.contains('\n'), "{e}");
}

#[test]
fn a_circle_of_radius_1e300_is_refused() {
    refused(
        &hostile("circle-r1e300.svg"),
        &[
            "<circle id=\"huge\">",
            "line 4",
            "the r of 1.0000e300 user units",
        ],
    );
}

#[test]
fn a_dxf_arc_of_radius_1e50_is_refused() {
    refused(
        &hostile("arc-r1e50.dxf"),
        &["ARC (handle 2F)", "layer PARTS", "beyond"],
    );
}

/// Writes `svg` to a file in `dir` and imports it with `opts`: the error.
fn import_error(dir: &Path, svg: &str, opts: &ImportOptions) -> String {
    let f = dir.join("t.svg");
    std::fs::write(&f, svg).unwrap();
    import_file(&f, opts).unwrap_err().to_string()
}

/// A transform may take sane numbers beyond the bound: the walk refuses the point it maps there.
#[test]
fn a_point_beyond_the_bound_after_transforms_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let e = import_error(
        dir.path(),
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
<g transform="scale(1e8)"><path id="far" d="M 0 0 L 10 10 C 20 0 30 0 40 10"/></g>
</svg>"#,
        &ImportOptions::default(),
    );
    assert!(e.contains("#far") && e.contains("after transforms"), "{e}");
    assert!(!e.contains('\n'), "{e}");
}

fn write_text(dir: &Path, name: &str, chars: usize) -> PathBuf {
    let f = dir.join(name);
    let text = "WMB".repeat(chars / 3);
    std::fs::write(
        &f,
        format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm"><text id="long" x="0" y="20" font-size="4">{text}</text></svg>"#
        ),
    )
    .unwrap();
    f
}

#[test]
fn a_text_of_a_million_glyphs_is_refused_before_it_is_shaped() {
    let dir = tempfile::tempdir().unwrap();
    let f = write_text(dir.path(), "million.svg", 1_000_000);
    refused(
        &f,
        &["<text id=\"long\">", "line 1", &MAX_GLYPHS.to_string()],
    );
}

/// A DXF whose texts add up past the glyph budget is refused at the entity that crosses it.
#[test]
fn dxf_text_is_bounded_per_file() {
    let mut lines: Vec<String> = ["0", "SECTION", "2", "ENTITIES"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let per = 9_000; // under the per-entity limit
    for k in 0..(MAX_GLYPHS / per + 1) {
        let h = format!("{:X}", 0x100 + k);
        for s in [
            "0",
            "TEXT",
            "5",
            &h,
            "8",
            "0",
            "10",
            "0",
            "20",
            &(k * 10).to_string(),
            "30",
            "0",
            "40",
            "2.5",
            "1",
            &"X".repeat(per),
        ] {
            lines.push(s.to_string());
        }
    }
    lines.extend(["0", "ENDSEC", "0", "EOF"].map(String::from));
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("texts.dxf");
    std::fs::write(&f, lines.join("\n") + "\n").unwrap();
    let e = import_file(&f, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("TEXT (handle") && e.contains("characters"),
        "{e}"
    );
}

/// Curves within the bound (900 m wide) at the finest tolerance take about 10⁶ vertices each:
/// the sixth would pass the import's budget and is refused before it is flattened, naming the
/// element.
#[test]
fn flattening_is_budgeted_per_curve_before_it_runs() {
    let dir = tempfile::tempdir().unwrap();
    let o = ImportOptions {
        chord_tol_mm: 1e-6,
        ..ImportOptions::default()
    };
    let t0 = Instant::now();
    let e = import_error(
        dir.path(),
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 1 1">
<g transform="scale(1e3)"><path id="wide" d="M 0 0 C 9 0 0 9 9 9 C 0 9 9 0 0 0 C 9 0 0 9 9 9 C 0 9 9 0 0 0 C 9 0 0 9 9 9 C 0 9 9 0 0 0"/></g>
</svg>"#,
        &o,
    );
    assert!(
        e.contains("#wide") && e.contains("raise the chord tolerance"),
        "{e}"
    );
    assert!(t0.elapsed() < Duration::from_secs(20));
}

/// Hatching is bounded per job: 200 small circles at a 0.1 µm spacing would make about
/// 2.8 · 10⁷ lines (each circle well within the per-region bound): refused before any is made.
#[test]
fn hatching_is_bounded_per_job() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("dots.svg");
    let circles: String = (0..200)
        .map(|k| {
            format!(
                "<circle cx=\"{}\" cy=\"{}\" r=\"2.5\"/>",
                10 + (k % 20) * 10,
                10 + (k / 20) * 10
            )
        })
        .collect();
    std::fs::write(
        &f,
        format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="250mm" height="150mm" viewBox="0 0 250 150" fill="none" stroke="black">{circles}</svg>"#
        ),
    )
    .unwrap();
    let t0 = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_galvoplan"))
        .arg("plan")
        .arg(&f)
        .args(["--hatch", "lines:0.0001", "--hatch-shapes", "apart", "-o"])
        .arg(dir.path().join("o.gcode"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("beyond the 1e7 of one job"), "{err}");
    assert!(err.trim_end().lines().count() <= 3, "{err}");
    assert!(t0.elapsed() < Duration::from_secs(20));
}
