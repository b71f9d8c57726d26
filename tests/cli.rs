//! The binary: exit codes, one-line errors, outputs written.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::galvoplan;

#[test]
fn plan_writes_gcode_report_preview_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    let demo = common::root()
        .join("assets/examples/demo.svg")
        .display()
        .to_string();
    let out = galvoplan(&[
        "plan",
        &demo,
        "-o",
        &d("job.gcode"),
        "--report",
        &d("job.json"),
        "--preview",
        &d("job.svg"),
        "--export-geometry",
        &d("geom.svg"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d("job.json")).unwrap()).unwrap();
    for key in [
        "idle_mm",
        "marked_mm",
        "base_mm",
        "fields",
        "covered_area_mm2",
        "overlap_pct",
        "direction_changes",
        "solve_s",
    ] {
        assert!(!report["metrics"][key].is_null(), "metrics.{key} missing");
    }
    assert!(report["fields"][0]["center"].is_array() && report["fields"][0]["size"].is_array());
    let gcode = std::fs::read_to_string(d("job.gcode")).unwrap();
    assert_eq!(
        gcode.matches("\nM3\n").count(),
        report["order"].as_array().unwrap().len()
    );
    assert!(std::fs::read_to_string(d("job.svg"))
        .unwrap()
        .contains("<svg"));
    assert!(std::fs::read_to_string(d("geom.svg"))
        .unwrap()
        .contains("<path"));
}

#[test]
fn bad_inputs_exit_nonzero_with_one_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let full = std::fs::read_to_string(common::root().join("assets/examples/demo.svg")).unwrap();
    let dxf = std::fs::read(common::root().join("tests/data/dxf/entities-inch.dxf")).unwrap();
    let garbage: Vec<u8> = (0..3000u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 11) as u8)
        .collect();
    let cases: [(&str, &[u8], &str); 6] = [
        ("truncated.svg", &full.as_bytes()[..full.len() / 3], "malformed XML"),
        ("empty.svg", b"", "empty file"),
        ("notes.svg", b"just some notes\n", "not a valid SVG"),
        (
            "image.svg",
            br#"<svg xmlns="http://www.w3.org/2000/svg" width="10mm" height="10mm"><image x="1" y="5" width="2" height="2" href="a.png"/></svg>"#,
            "no markable geometry",
        ),
        ("truncated.dxf", &dxf[..dxf.len() / 2], "not a valid DXF"),
        ("garbage.dxf", &garbage, "not a valid DXF"),
    ];
    for (name, bytes, what) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        let out_gcode = dir.path().join("x.gcode");
        let out = galvoplan(&[
            "plan",
            &p.display().to_string(),
            "-o",
            &out_gcode.display().to_string(),
        ]);
        assert!(!out.status.success(), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(name) && err.contains(what), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
        assert!(!out_gcode.exists(), "{name}: no output on failure");
    }
}

#[test]
fn oversize_geometry_is_listed() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("big.svg");
    std::fs::write(
        &p,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="300mm" height="300mm" viewBox="0 0 300 300"><rect id="huge" x="10" y="10" width="100" height="20" stroke="black" fill="none"/><circle cx="200" cy="200" r="5" stroke="black" fill="none"/></svg>"#,
    )
    .unwrap();
    let out = galvoplan(&[
        "plan",
        &p.display().to_string(),
        "-o",
        &dir.path().join("o.gcode").display().to_string(),
        "--motion",
        "step",
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("big.svg") && err.contains("#huge") && err.contains("100.00 × 20.00 mm"),
        "{err}"
    );
    // the default motion (auto) marks it whole on the fly or cut, whichever is faster, and says so
    let auto_report = dir.path().join("auto.json");
    let out = galvoplan(&[
        "plan",
        &p.display().to_string(),
        "-o",
        &dir.path().join("auto.gcode").display().to_string(),
        "--report",
        &auto_report.display().to_string(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("larger than a scan field are"), "{err}");
    let auto: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(auto_report).unwrap()).unwrap();
    assert!(auto["plan"].as_str().unwrap().contains("auto: "), "{auto}");
    let report = dir.path().join("o.json");
    let out = galvoplan(&[
        "plan",
        &p.display().to_string(),
        "-o",
        &dir.path().join("o.gcode").display().to_string(),
        "--report",
        &report.display().to_string(),
        "--split-oversize",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("#huge") && err.contains("split into 2 pieces"),
        "{err}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
    assert_eq!(report["order"].as_array().unwrap().len(), 3);
}

#[test]
fn bench_prints_a_row_per_instance() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("b.json");
    let demo = common::root()
        .join("assets/examples/demo.svg")
        .display()
        .to_string();
    let out = galvoplan(&["bench", &demo, "--json", &json.display().to_string()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.lines().any(|l| l.starts_with("| demo |")), "{table}");
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    assert!(rows[0]["idle_mm"]["mean"].as_f64().unwrap() > 0.0);
}

#[test]
fn plan_writes_a_trajectory_whose_duration_is_the_reported_job_time() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    let demo = common::root()
        .join("assets/examples/demo.svg")
        .display()
        .to_string();
    let run = |period: &str, cost: &str| {
        galvoplan(&[
            "plan",
            &demo,
            "-o",
            &d("job.gcode"),
            "--report",
            &d("job.json"),
            "--trajectory",
            &d("job.csv"),
            "--trajectory-period-ms",
            period,
            "--cost",
            cost,
        ])
    };
    let out = run("0.5", "time");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(d("job.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("t_s,stage_x_mm,stage_y_mm,scan_x_mm,scan_y_mm,laser")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows[0][0], 0.0);
    assert!((rows[1][0] - 0.0005).abs() < 1e-9, "period 0.5 ms");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d("job.json")).unwrap()).unwrap();
    let job_s = report["metrics"]["job_time_s"].as_f64().unwrap();
    let last_s = rows[rows.len() - 1][0];
    assert!(last_s >= job_s - 1e-9 && last_s < job_s + 0.0005 + 1e-9);
    let motion = &report["metrics"]["motion"];
    for key in [
        "stage_route_mm",
        "stage_peak_speed_mm_s",
        "stage_speed_variation_mm_s",
        "scan_peak_offset_mm",
    ] {
        assert!(motion[key].as_f64().unwrap() >= 0.0, "metrics.motion.{key}");
    }
    assert!(motion["scan_peak_offset_mm"].as_f64().unwrap() <= 35.0 + 1e-6);
    let parts = &report["metrics"]["job_time_breakdown_s"];
    let sum: f64 = ["stage", "settle", "jump", "mark", "laser_delays"]
        .iter()
        .map(|k| parts[k].as_f64().unwrap())
        .sum();
    assert!((sum - job_s).abs() < 1e-6);
    // an impossible period is refused before any work, naming the flag's value
    let out = run("0", "time");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("trajectory period 0 ms"), "{err}");
    let out = run("1", "nonsense");
    assert!(!out.status.success());
}

/// The job time a `plan` run reports on stderr ("job time 6.089 s").
fn reported_job_time(out: &std::process::Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let at = err.find("job time ").expect("a job time") + "job time ".len();
    err[at..].split(' ').next().unwrap_or_default().to_string()
}

#[test]
fn a_trajectory_never_changes_the_plans_job_time() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    let root = common::root();
    let clocked = root.join("tests/data/profiles/scan-head-clock.toml");
    let clocked = clocked.display().to_string();
    for svg in ["assets/examples/demo.svg", "assets/examples/oversize.svg"] {
        let svg = root.join(svg).display().to_string();
        for profile in ["seed000", "linuxcnc", clocked.as_str()] {
            let (out, stream) = (d("job.gcode"), d("job.stream"));
            let plan = |extra: &[&str]| {
                let mut args = vec!["plan", &svg, "--profile", profile, "--motion", "auto"];
                args.extend(["-o", out.as_str()]);
                // a plan the linuxcnc profile streams needs its stream
                args.extend(["--stream", stream.as_str()]);
                args.extend(extra);
                galvoplan(&args)
            };
            let without = reported_job_time(&plan(&[]));
            let csv = d("job.csv");
            let with = reported_job_time(&plan(&["--trajectory", &csv]));
            assert_eq!(without, with, "{svg} on {profile}");
            // the trajectory's last sample is the end of that same job
            let text = std::fs::read_to_string(&csv).unwrap();
            let last = text.lines().last().unwrap().split(',').next().unwrap();
            let (last, job): (f64, f64) = (last.parse().unwrap(), with.parse().unwrap());
            assert!(last >= job - 5e-4 && last < job + 1.5e-3, "{last} vs {job}");
        }
    }
    // a profile with a clock samples on it: another period is refused, naming the clock
    let svg = root.join("assets/examples/demo.svg").display().to_string();
    let (out, csv) = (d("job.gcode"), d("job.csv"));
    for profile in ["linuxcnc", clocked.as_str()] {
        let refused = galvoplan(&[
            "plan",
            &svg,
            "--profile",
            profile,
            "--motion",
            "step",
            "-o",
            &out,
            "--trajectory",
            &csv,
            "--trajectory-period-ms",
            "2",
        ]);
        assert!(!refused.status.success());
        let err = String::from_utf8_lossy(&refused.stderr);
        assert!(err.contains("clock of 1 ms"), "{err}");
    }
    // the same period is taken
    let same = galvoplan(&[
        "plan",
        &svg,
        "--profile",
        &clocked,
        "-o",
        &out,
        "--trajectory",
        &csv,
        "--trajectory-period-ms",
        "1",
    ]);
    reported_job_time(&same);
    // the scan head's clock makes the plan: marks start and end on ticks, so the job is longer
    let on = |profile: &str| {
        let t = reported_job_time(&galvoplan(&[
            "plan",
            &svg,
            "--profile",
            profile,
            "--motion",
            "step",
            "-o",
            &out,
        ]));
        t.parse::<f64>().unwrap()
    };
    assert!(on(&clocked) > on("seed000"));
}

#[test]
fn on_the_fly_plans_oversize_artwork_without_splitting() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    let svg = common::root()
        .join("assets/examples/oversize.svg")
        .display()
        .to_string();
    let plan = |motion: &str| {
        galvoplan(&[
            "plan",
            &svg,
            "-o",
            &d("job.gcode"),
            "--motion",
            motion,
            "--trajectory",
            &d("job.csv"),
            "--preview",
            &d("job.svg"),
        ])
    };
    // step-and-scan refuses geometries larger than a field unless told to split them
    let out = plan("step");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--split-oversize"));
    let out = plan("on-the-fly");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(d("job.csv")).unwrap();
    // the stage moves while the laser is on
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert!(rows
        .windows(2)
        .any(|w| w[0][5] == 1.0 && w[1][5] == 1.0 && (w[0][1] != w[1][1] || w[0][2] != w[1][2])));
    // the preview draws the stage's route
    let preview = std::fs::read_to_string(d("job.svg")).unwrap();
    assert!(preview.contains("id=\"stage-route\""));
    // bad route settings: a worded error, exit ≠ 0
    let out = galvoplan(&[
        "plan",
        &svg,
        "-o",
        &d("bad.gcode"),
        "--motion",
        "on-the-fly",
        "--stage-route",
        "cetsp-ga",
        "--route-population",
        "0",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("population"));
    assert!(!std::path::Path::new(&d("bad.gcode")).exists());
}

#[test]
fn plan_with_pens_writes_each_layers_power_feed_and_passes() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    let ex = |n: &str| {
        common::root()
            .join("assets/examples")
            .join(n)
            .display()
            .to_string()
    };
    let run = |extra: &[&str], out: &str| {
        let mut args = vec![
            "plan".to_string(),
            ex("two-layers.svg"),
            "-o".into(),
            d(&format!("{out}.gcode")),
            "--report".into(),
            d(&format!("{out}.json")),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = galvoplan(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d(&format!("{out}.json"))).unwrap())
                .unwrap();
        (
            std::fs::read_to_string(d(&format!("{out}.gcode"))).unwrap(),
            report,
        )
    };
    let pens = ex("two-layers.pens.toml");
    let (gcode, report) = run(&["--pens", &pens], "pens");
    assert!(
        gcode.contains("\nM3 S40\n") && gcode.contains("\nM3 S85\n"),
        "both powers"
    );
    assert!(
        gcode.contains(" F90000\n") && gcode.contains(" F36000\n"),
        "both feeds"
    );
    let (plain_gcode, plain) = run(&[], "plain");
    assert!(!plain_gcode.contains(" S85"));
    let job = |r: &serde_json::Value| r["metrics"]["job_time_s"].as_f64().unwrap();
    let mark = |r: &serde_json::Value| {
        r["metrics"]["job_time_breakdown_s"]["mark"]
            .as_f64()
            .unwrap()
    };
    // hatched and marked twice at 600 mm/s: far more marking than the outlines at 1000 mm/s
    assert!(
        mark(&report) > 3.0 * mark(&plain),
        "{} vs {}",
        mark(&report),
        mark(&plain)
    );
    assert!(job(&report) > job(&plain));
    // a bad pens file is one worded line naming the file
    std::fs::write(
        d("bad.toml"),
        "version = 1\n[[layer]]\nname = \"fill\"\nmark_speed_mm_s = -3\n",
    )
    .unwrap();
    let o = galvoplan(&[
        "plan",
        &ex("two-layers.svg"),
        "-o",
        &d("x.gcode"),
        "--pens",
        &d("bad.toml"),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("bad.toml")
            && err.contains("Layer 'fill': Mark speed (mm/s) must be a positive number, not -3"),
        "{err}"
    );
}

#[test]
fn plan_takes_dxf_and_text_labels() {
    let dir = tempfile::tempdir().unwrap();
    for (input, geometries) in [
        ("tests/data/dxf/entities-inch.dxf", 26),
        ("assets/examples/label.svg", 25),
    ] {
        let gcode = dir.path().join("job.gcode").display().to_string();
        let report = dir.path().join("job.json").display().to_string();
        let path = common::root().join(input).display().to_string();
        let out = galvoplan(&["plan", &path, "-o", &gcode, "--report", &report]);
        assert!(
            out.status.success(),
            "{input}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        assert_eq!(r["order"].as_array().unwrap().len(), geometries, "{input}");
    }
}

/// A drawing whose 30 TEXT entities ask for a font that is not installed: one warning line
/// with the count and five of them, not 30 lines. Common CAD fonts (Arial, Times, Courier) are
/// drawn with their closest face without a warning, and the report still records each
/// substitution.
#[test]
fn the_same_font_warning_for_many_texts_is_one_line_and_cad_fonts_map_silently() {
    let dir = tempfile::tempdir().unwrap();
    let gcode = dir.path().join("job.gcode").display().to_string();
    let report = dir.path().join("job.json").display().to_string();
    let path = |f: &str| common::root().join(f).display().to_string();
    let warnings = |out: &std::process::Output| -> Vec<String> {
        String::from_utf8_lossy(&out.stderr)
            .lines()
            .filter(|l| l.contains("warning"))
            .map(str::to_string)
            .collect()
    };
    let out = galvoplan(&[
        "plan",
        &path("tests/data/dxf/fonts-30-texts.dxf"),
        "-o",
        &gcode,
    ]);
    assert!(out.status.success());
    let lines = warnings(&out);
    assert_eq!(lines.len(), 1, "{lines:#?}");
    assert!(
        lines[0].contains("font family 'isocpeur' not found")
            && lines[0].contains("(30 elements: ")
            && lines[0].contains("… and 25 more"),
        "{}",
        lines[0]
    );
    let out = galvoplan(&[
        "plan",
        &path("tests/data/dxf/fonts-cad.dxf"),
        "-o",
        &gcode,
        "--report",
        &report,
    ]);
    assert!(out.status.success());
    assert!(warnings(&out).is_empty(), "{:#?}", warnings(&out));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let recorded: Vec<&str> = r["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| w.as_str())
        .filter(|w| w.contains("is not installed; drawn with its closest"))
        .collect();
    assert_eq!(recorded.len(), 12, "{recorded:#?}");
    assert!(recorded.iter().any(|w| w.contains("'times'")));
    assert!(recorded.iter().any(|w| w.contains("'cour'")));
}

#[test]
fn tsp_orders_a_generated_set_and_measures_it_against_the_held_karp_bound() {
    let dir = tempfile::tempdir().unwrap();
    let stem = dir.path().join("u60").display().to_string();
    let out = galvoplan(&[
        "tsp",
        "--generate",
        "uniform:60",
        "--seed",
        "3",
        "--out",
        &stem,
    ]);
    assert_succeeded(&out);
    let tour = dir.path().join("tour.txt").display().to_string();
    let tsp = format!("{stem}.tsp");
    let out = galvoplan(&["tsp", &tsp, "--bound", "0"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("--bound needs at least 1 iteration"),
        "{err}"
    );
    let out = galvoplan(&["tsp", &tsp, "--bound", "200", "--tour", &tour]);
    assert_succeeded(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    let row: Vec<&str> = text
        .lines()
        .find(|l| l.starts_with("| u60 "))
        .expect("a row for the set")
        .split('|')
        .map(str::trim)
        .collect();
    let (length, bound): (f64, f64) = (row[4].parse().unwrap(), row[6].parse().unwrap());
    // the bound is below every path, and Held–Karp is within a few % on uniform points
    assert!(
        bound > 0.9 * length && bound <= length,
        "{length} mm vs bound {bound}"
    );
    assert!(row[7].ends_with('%'), "gap column: {}", row[7]);
    let mut order: Vec<usize> = std::fs::read_to_string(&tour)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    order.sort_unstable();
    assert_eq!(order, (0..60).collect::<Vec<_>>());
    // the same dots planned on the benchmarks' one-field profile: one field, idle above the bound
    let profile = common::root()
        .join("assets/profiles/tsp-one-field.toml")
        .display()
        .to_string();
    let report = dir.path().join("plan.json").display().to_string();
    let gcode = dir.path().join("plan.gcode").display().to_string();
    let svg = format!("{stem}.svg");
    let out = galvoplan(&[
        "plan",
        &svg,
        "--profile",
        &profile,
        "-o",
        &gcode,
        "--report",
        &report,
    ]);
    assert_succeeded(&out);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(report["metrics"]["fields"], 1);
    let idle = report["metrics"]["idle_mm"].as_f64().unwrap();
    // dots of 2 µm: the marks add at most 2 µm per dot to the path between centroids
    assert!(
        idle >= bound - 60.0 * 0.002,
        "idle {idle} mm below the bound {bound}"
    );
    assert!(
        idle <= 1.05 * length,
        "idle {idle} mm against the engine's {length}"
    );
}

/// Asserts that a run of the binary succeeded (showing its stderr otherwise).
fn assert_succeeded(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn an_output_onto_an_input_is_refused_and_the_input_kept() {
    let dir = tempfile::tempdir().unwrap();
    let art = dir.path().join("art.svg");
    std::fs::copy(common::root().join("assets/examples/demo.svg"), &art).unwrap();
    let before = std::fs::read(&art).unwrap();
    let a = art.display().to_string();
    for args in [
        vec!["plan", &a, "-o", &a],
        vec!["plan", &a, "-o", "/dev/null", "--report", &a],
    ] {
        let out = galvoplan(&args);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("refusing to write"), "{err}");
        assert_eq!(std::fs::read(&art).unwrap(), before);
    }
    // two outputs onto one file are refused too
    let g = dir.path().join("job.gcode").display().to_string();
    let out = galvoplan(&["plan", &a, "-o", &g, "--preview", &g]);
    assert!(!out.status.success());
    assert!(!std::path::Path::new(&g).exists());
}

#[test]
fn the_report_holds_the_plans_profile_pens_and_settings_and_fields_are_numbered_in_visiting_order()
{
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    let root = common::root();
    let art = root
        .join("assets/examples/two-layers.svg")
        .display()
        .to_string();
    let pens = root
        .join("assets/examples/two-layers.pens.toml")
        .display()
        .to_string();
    let out = galvoplan(&[
        "plan",
        &art,
        "--pens",
        &pens,
        "-o",
        &d("j.gcode"),
        "--report",
        &d("j.json"),
    ]);
    assert_succeeded(&out);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d("j.json")).unwrap()).unwrap();
    assert_eq!(r["algo"], "hha");
    assert_eq!(r["profile"]["field_mm"][0], 70.0);
    assert!(r["settings"]["cost_model"].is_string());
    let pens = r["pens"].as_array().unwrap();
    assert_eq!(pens.len(), 2);
    assert!(pens
        .iter()
        .any(|l| l["name"] == "fill" && l["mark_speed_mm_s"] == 600.0));
    // the G-code numbers fields 1…n in visiting order, as the report's field numbers
    let g = std::fs::read_to_string(d("j.gcode")).unwrap();
    let numbers: Vec<usize> = g
        .lines()
        .filter_map(|l| l.strip_prefix("; field "))
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    let n = r["fields"].as_array().unwrap().len();
    assert_eq!(numbers, (1..=n).collect::<Vec<_>>());
    for (k, f) in r["fields"].as_array().unwrap().iter().enumerate() {
        assert_eq!(f["number"], k + 1);
    }
    let summary = String::from_utf8_lossy(&out.stderr);
    assert!(
        !summary.contains("1 fields") && !summary.contains("1 geometries"),
        "{summary}"
    );
}

#[test]
fn linuxcnc_on_the_fly_says_why_its_job_time_is_what_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("job.gcode").display().to_string();
    let svg = common::root().join("assets/examples/oversize.svg");
    let svg = svg.display().to_string();
    // a LinuxCNC machine without the streamer wiring: on the fly is a G93 program
    let text = std::fs::read_to_string(common::root().join("assets/profiles/linuxcnc.toml"));
    let g93 = dir.path().join("linuxcnc-g93.toml");
    let text = text.unwrap().replace("stream_period_s = 0.0001\n", "");
    std::fs::write(&g93, text).unwrap();
    let g93 = g93.display().to_string();
    let run = galvoplan(&[
        "plan",
        &svg,
        "--profile",
        &g93,
        "--motion",
        "on-the-fly",
        "-o",
        &out,
    ]);
    let job_s = reported_job_time(&run);
    let err = String::from_utf8_lossy(&run.stderr);
    let note = err
        .lines()
        .find(|l| l.contains("LinuxCNC runs on-the-fly G-code without look-ahead: "))
        .unwrap_or_else(|| panic!("{err}"));
    let job_s: f64 = job_s.parse().unwrap();
    assert!(note.contains(&format!("{job_s:.2} s on the fly")), "{note}");
    assert!(note.contains("step-and-scan would take"), "{note}");
    // a scan-head profile has no such note
    let run = galvoplan(&["plan", &svg, "--motion", "on-the-fly", "-o", &out]);
    reported_job_time(&run);
    assert!(!String::from_utf8_lossy(&run.stderr).contains("without look-ahead"));
}
