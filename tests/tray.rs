//! Production jobs: a part repeated over a tray, serial numbers, dates and CSV data in its
//! texts, one job across the tray; bad production input refused in one line, nothing written.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::document::{
    load_project, save_project, MachineProfile, Numbering, SolverSettings, Stamp, Tray,
    TraySettings,
};
use galvoplan::import::{import_file, ImportOptions};
use galvoplan::pipeline::{expand_production, load_artwork, load_production};
use std::path::{Path, PathBuf};
use std::process::Command;

fn example(name: &str) -> PathBuf {
    common::root().join("assets/examples").join(name)
}

/// Runs the CLI: success, stdout+stderr.
fn galvoplan(args: &[&str], cwd: &Path) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_galvoplan"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn report_parts(report: &Path) -> Vec<serde_json::Value> {
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
    r["parts"].as_array().cloned().unwrap_or_default()
}

#[test]
fn the_cli_tray_is_one_job_with_48_serials_and_data() {
    let dir = tempfile::tempdir().unwrap();
    let part = example("part.svg").display().to_string();
    let lots = example("lots.csv").display().to_string();
    let mut args = vec![
        "plan",
        &part,
        "--array",
        "6x8@40,32",
        "--serial",
        "1001",
        "--data",
        &lots,
        "--date",
        "2026-12-07T14:30",
        "-o",
        "tray.gcode",
        "--report",
        "tray.json",
        "--export-geometry",
        "tray.svg",
        "--parts-log",
        "parts.csv",
    ];
    let (ok, err) = galvoplan(&args, dir.path());
    assert!(ok, "{err}");
    let parts = report_parts(&dir.path().join("tray.json"));
    assert_eq!(parts.len(), 48);
    for (k, p) in parts.iter().enumerate() {
        assert_eq!(p["part"], k + 1);
        assert_eq!(p["serial"], 1001 + k);
        assert_eq!(p["texts"][0], format!("SN {:05}", 1001 + k));
    }
    // one job: fields over the whole tray, each field holding several parts
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("tray.json")).unwrap())
            .unwrap();
    let fields = r["fields"].as_array().unwrap().len();
    assert!((1..48).contains(&fields), "{fields} fields for 48 parts");
    let log = std::fs::read_to_string(dir.path().join("parts.csv")).unwrap();
    assert_eq!(log.lines().count(), 49, "{log}");
    assert!(log
        .lines()
        .nth(1)
        .unwrap()
        .ends_with(",tray.gcode,1,1001,SN 01001"));
    // a second run appends (the header once) and never advances the serials by itself
    let (ok, err) = galvoplan(&args, dir.path());
    assert!(ok, "{err}");
    let log = std::fs::read_to_string(dir.path().join("parts.csv")).unwrap();
    assert_eq!(log.lines().count(), 97);
    assert_eq!(log.matches("date_time").count(), 1);
    assert_eq!(
        report_parts(&dir.path().join("tray.json"))[0]["serial"],
        1001
    );

    // a skipped cell takes no serial and no data row
    args.splice(6..6, ["--skip", "5"]);
    let (ok, err) = galvoplan(&args, dir.path());
    assert!(ok, "{err}");
    let parts = report_parts(&dir.path().join("tray.json"));
    assert_eq!(parts.len(), 47);
    assert_eq!(parts.last().unwrap()["serial"], 1047);
    assert!(parts.iter().all(|p| p["cell"] != 5));
    assert_eq!(parts[4]["cell"], 6);
    assert_eq!(parts[4]["serial"], 1005);
}

/// Each bad production input: exit ≠ 0, at most 3 lines naming the problem, nothing written.
#[test]
fn bad_production_input_is_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let part = example("part.svg");
    let text = std::fs::read_to_string(&part).unwrap();
    let write = |name: &str, body: String| {
        std::fs::write(d.join(name), body).unwrap();
        name.to_string()
    };
    let typo = write("typo.svg", text.replace("{serial:05}", "{seriall}"));
    let brace = write("brace.svg", text.replace("{serial:05}", "{serial:05"));
    let column = write("column.svg", text.replace("{serial:05}", "{csv:lott}"));
    let short = write("short.csv", "lot,op\nA,1\nB,2\n".into());
    let lots = example("lots.csv").display().to_string();
    let part = part.display().to_string();
    let cases: Vec<(Vec<&str>, &[&str])> = vec![
        (
            vec!["plan", &typo],
            &[
                "typo.svg",
                "line 8",
                "SN {seriall}",
                "unknown field {seriall}",
            ],
        ),
        (vec!["plan", &brace], &["brace.svg", "line 8", "unbalanced"]),
        (
            vec!["plan", &column, "--data", &lots],
            &["lots.csv", "no column 'lott'", "columns: lot, op"],
        ),
        (
            vec!["plan", &part, "--array", "6x8"],
            &["--array", "COLSxROWS@PITCH_X,PITCH_Y"],
        ),
        (
            vec!["plan", &part, "--array", "6x8@40,32", "--skip", "3,x"],
            &["--skip", "3,x"],
        ),
        (
            vec!["plan", &part, "--array", "6x8@40,32", "--skip", "49"],
            &["cell 49", "cells 1 to 48"],
        ),
        (
            vec!["plan", &part, "--date", "07.12.2026"],
            &["--date", "YYYY-MM-DD"],
        ),
        (
            vec!["plan", &part, "--array", "20x20@40,32"],
            &["tray", "larger than", "the machine reaches"],
        ),
    ];
    for (mut args, says) in cases {
        args.extend(["-o", "out.gcode", "--report", "out.json"]);
        let (ok, err) = galvoplan(&args, d);
        assert!(!ok, "{args:?} was accepted");
        let lines = err.trim_end().lines().count();
        assert!((1..=3).contains(&lines), "{args:?}: {lines} lines:\n{err}");
        for s in says {
            assert!(err.contains(s), "{args:?}: '{s}' not in:\n{err}");
        }
        assert!(!d.join("out.gcode").exists() && !d.join("out.json").exists());
    }
    // fewer data rows than marked parts
    let (ok, err) = galvoplan(&["plan", &column, "-o", "o.gcode"], d);
    assert!(!ok && err.contains("--data"), "{err}");
    let rows = write("rows.svg", text.replace("{serial:05}", "{csv:lot}"));
    let (ok, err) = galvoplan(
        &[
            "plan",
            &rows,
            "--array",
            "6x8@40,32",
            "--data",
            &short,
            "-o",
            "o.gcode",
        ],
        d,
    );
    assert!(!ok, "accepted");
    assert!(
        err.contains("short.csv: 2 data rows for 48 marked parts"),
        "{err}"
    );
    assert!(err.trim_end().lines().count() <= 3, "{err}");
}

fn part_svg_tray(tray: &str, numbering: Option<Numbering>) -> galvoplan::pipeline::Loaded {
    let mut t = Tray::parse(tray).unwrap();
    if let Some(n) = numbering {
        t.numbering = n;
    }
    load_production(
        &example("part.svg"),
        MachineProfile::default(),
        SolverSettings::default(),
        &ImportOptions::default(),
        &TraySettings {
            tray: Some(t),
            stamp: Some(Stamp::parse("2026-12-07").unwrap()),
            ..TraySettings::default()
        },
    )
    .unwrap()
}

#[test]
fn serpentine_numbering_runs_back_along_every_other_row() {
    let doc = part_svg_tray("3x2@40,32", Some(Numbering::Serpentine)).doc;
    let cells: Vec<u32> = doc.parts.iter().map(|p| p.cell).collect();
    assert_eq!(cells, [1, 2, 3, 6, 5, 4]);
    assert_eq!(doc.parts[3].texts[0], "SN 00004");
    // part 4 is in cell 6: its text lies in the last column of the second row
    let text_of = |part: u32| {
        doc.artwork
            .iter()
            .filter(|g| g.source.part == part && g.source.element.contains("sn"))
            .flat_map(|g| g.points.iter())
            .fold(f64::INFINITY, |m, p| m.min(p.x))
    };
    assert!(
        (text_of(4) - text_of(3)).abs() < 1e-6,
        "part 4 below part 3"
    );
    assert!((text_of(4) - text_of(6) - 80.0).abs() < 1e-6);
}

#[test]
fn the_parts_are_the_part_moved_not_imported_again() {
    let one = load_artwork(
        &example("part.svg"),
        MachineProfile::default(),
        SolverSettings::default(),
        &ImportOptions::default(),
    )
    .unwrap()
    .doc;
    let doc = part_svg_tray("2x2@40,32", None).doc;
    let statics = |d: &galvoplan::document::Document, part: u32| -> Vec<Vec<(f64, f64)>> {
        d.artwork
            .iter()
            .filter(|g| g.source.part == part && !g.source.element.contains("sn"))
            .map(|g| g.points.iter().map(|p| (p.x, p.y)).collect())
            .collect()
    };
    let moved: Vec<Vec<(f64, f64)>> = statics(&one, 1)
        .into_iter()
        .map(|g| g.into_iter().map(|(x, y)| (x + 40.0, y + 32.0)).collect())
        .collect();
    assert_eq!(statics(&doc, 4), moved);
    assert_eq!(doc.parts.len(), 4);
}

#[test]
fn a_template_survives_a_project_save_and_reopen() {
    let mut doc = part_svg_tray("3x2@40,32", None).doc;
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("tray.galvoplan");
    save_project(&doc, &file).unwrap();
    let mut back = load_project(&file).unwrap();
    assert_eq!(back.production, doc.production);
    let t = &back.production.as_ref().unwrap().templates[0];
    assert_eq!(t.text, "SN {serial:05}");
    // made again from the template, the same artwork
    expand_production(&mut back).unwrap();
    expand_production(&mut doc).unwrap();
    assert_eq!(back.artwork, doc.artwork);
    assert_eq!(back.parts, doc.parts);
}

/// MTEXT keeps braces for its own formatting: its codes are stripped first, then the fields
/// read (`\{` is how MTEXT writes a brace).
#[test]
fn mtext_with_format_braces_and_a_field() {
    let dxf = "0\nSECTION\n2\nENTITIES\n\
        0\nLWPOLYLINE\n5\n2A\n8\n0\n90\n4\n70\n1\n10\n0\n20\n0\n10\n30\n20\n0\n10\n30\n20\n20\n10\n0\n20\n20\n\
        0\nMTEXT\n5\n2B\n8\nTEXT\n10\n2\n20\n5\n40\n3\n71\n7\n1\n{\\fArial|b1;SN} \\{serial:04\\}\n\
        0\nENDSEC\n0\nEOF\n";
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("m.dxf");
    std::fs::write(&f, dxf).unwrap();
    let im = import_file(&f, &ImportOptions::default()).unwrap();
    assert_eq!(im.templates.len(), 1, "{:?}", im.warnings);
    assert_eq!(im.templates[0].text, "SN {serial:04}");
    assert!(im.templates[0].element.contains("MTEXT (handle 2B)"));
    let loaded = load_production(
        &f,
        MachineProfile::default(),
        SolverSettings::default(),
        &ImportOptions::default(),
        &TraySettings {
            tray: Some(Tray::parse("2x1@40,0").unwrap()),
            serial: Some(galvoplan::document::Serial { start: 7, step: 3 }),
            ..TraySettings::default()
        },
    )
    .unwrap();
    let texts: Vec<&str> = loaded
        .doc
        .parts
        .iter()
        .map(|p| p.texts[0].as_str())
        .collect();
    assert_eq!(texts, ["SN 0007", "SN 0010"]);
    // the glyphs of part 2 are those of part 1's layout moved by the pitch, on the TEXT layer
    let glyphs = |part: u32| {
        loaded
            .doc
            .artwork
            .iter()
            .filter(|g| g.source.part == part && g.layer == "TEXT")
            .count()
    };
    assert!(glyphs(1) > 4 && glyphs(2) > 4);
}

/// Codes on the parts: bad codes refused in one line naming the code, nothing written; a code
/// whose quiet zone holds the part's text warns, naming both.
#[test]
fn bad_codes_are_one_line_and_a_crowded_quiet_zone_warns() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let part = example("part.svg").display().to_string();
    let long = format!("qr:{}@14,2:9", "x".repeat(5000));
    for (code, says) in [
        (long.as_str(), "does not fit a QR code at any size"),
        ("code128:Grüße@3,3:20", "cannot encode 'ü'"),
        ("datamatrix:GP{serial:05}@3,3:0.5", "at least 1.20 mm wide"),
        ("aztec:x@1,1:5", "unknown kind 'aztec'"),
        ("qr:x@1,1:5:rect", "unknown option 'rect' for qr"),
        ("datamatrix:{seriall}@1,1:5", "unknown field {seriall}"),
    ] {
        let (ok, err) = galvoplan(
            &[
                "plan",
                &part,
                "--code",
                code,
                "-o",
                "out.gcode",
                "--report",
                "out.json",
            ],
            d,
        );
        assert!(!ok, "{code} accepted");
        assert!(err.contains(says), "{code}: '{says}' not in:\n{err}");
        assert!(err.trim_end().lines().count() <= 3, "{err}");
        assert!(!d.join("out.gcode").exists());
    }
    let (ok, err) = galvoplan(
        &[
            "plan",
            &part,
            "--code",
            "datamatrix:GP{serial:05}@3,17:6",
            "-o",
            "out.gcode",
        ],
        d,
    );
    assert!(ok, "{err}");
    assert!(
        err.contains("datamatrix code 1") && err.contains("quiet zone") && err.contains("#sn"),
        "{err}"
    );
}
