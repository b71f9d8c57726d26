//! Machines with axes beyond X/Y (Z, A, B): seed 002's experiment, the stand-in planned end to
//! end, its outputs, and bad input in one line.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{galvoplan, one_line_error};

use std::path::Path;
use std::process::Output;

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// demo.svg's layout on seed000's 70 mm fields, laid on a cap of radius 200 mm: a stand-in
/// project in `dir`; returns its path.
fn stand_in(dir: &Path) -> String {
    let demo = common::root().join("assets/examples/demo.svg");
    let project = dir.join("cap.galvoplan").display().to_string();
    let json = dir.join("cap.json").display().to_string();
    // 35 mm fields: a few dozen placements
    let layout = dir.join("layout.toml");
    std::fs::write(&layout, "version = 5\nfield_mm = [35.0, 35.0]\n").unwrap();
    let table = ok(&galvoplan(&[
        "cap-bench",
        &demo.display().to_string(),
        "--layout-profile",
        &layout.display().to_string(),
        "--project",
        &project,
        "--json",
        &json,
    ]));
    assert!(table.contains("| 5-axis time |"), "{table}");
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let t: Vec<f64> = (0..3)
        .map(|k| rows[k]["move_time_s"].as_f64().unwrap())
        .collect();
    // 5-axis time ≤ 3-D distance ≤ as is (within 0.1 %: a stochastic search)
    assert!(t[2] <= t[1] * 1.001 && t[1] <= t[0] * 1.001, "{t:?}");
    project
}

#[test]
fn the_stand_in_is_planned_on_time_with_its_poses_in_every_output() {
    let dir = tempfile::tempdir().unwrap();
    let project = stand_in(dir.path());
    let d = |n: &str| dir.path().join(n).display().to_string();
    let mut job_s = Vec::new();
    for cost in ["distance", "time"] {
        ok(&galvoplan(&[
            "plan",
            &project,
            "--profile",
            "five-axis",
            "--cost",
            cost,
            "-o",
            &d(&format!("{cost}.ngc")),
            "--report",
            &d(&format!("{cost}.json")),
            "--trajectory",
            &d(&format!("{cost}.csv")),
        ]));
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d(&format!("{cost}.json"))).unwrap())
                .unwrap();
        job_s.push(report["metrics"]["job_time_s"].as_f64().unwrap());
        // the report carries each field's pose
        assert!(report["fields"][0]["pose"]["b_deg"].is_number(), "{report}");
    }
    assert!(job_s[1] <= job_s[0] * 1.001, "{job_s:?}");
    // the program moves Z, A and B with the stage; the trajectory has their columns
    let gcode = std::fs::read_to_string(d("time.ngc")).unwrap();
    let stage = gcode.lines().find(|l| l.starts_with("G0 X")).unwrap();
    for w in [" Y", " Z", " A", " B"] {
        assert!(stage.contains(w), "{stage}");
    }
    let csv = std::fs::read_to_string(d("time.csv")).unwrap();
    assert!(
        csv.starts_with("t_s,stage_x_mm,stage_y_mm,scan_x_mm,scan_y_mm,laser,z_mm,a_deg,b_deg\n")
    );
    // without --profile a project is planned on its own machine
    ok(&galvoplan(&["plan", &project, "-o", &d("own.ngc")]));
    let own = std::fs::read_to_string(d("own.ngc")).unwrap();
    assert!(own
        .lines()
        .any(|l| l.starts_with("G0 X") && l.contains(" B")));
}

#[test]
fn a_pose_the_profile_cannot_take_is_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let project = stand_in(dir.path());
    let d = |n: &str| dir.path().join(n).display().to_string();
    // the job needs Z, A and B: a flat profile has none of them
    let err = one_line_error(&galvoplan(&[
        "plan",
        &project,
        "--profile",
        "seed000",
        "--cost",
        "time",
        "-o",
        &d("a.ngc"),
    ]));
    assert!(
        err.contains("needs axis Z") && err.contains("(its axes: X, Y)"),
        "{err}"
    );
    assert!(!Path::new(&d("a.ngc")).exists());
    // B's travel narrowed to ±1°: the fields' tilts are outside it
    let five = galvoplan::document::MachineProfile::builtin("five-axis").unwrap();
    let mut narrow = five.clone();
    if let Some(b) = narrow.axis_b.as_mut() {
        b.0.travel = Some([-1.0, 1.0]);
    }
    let profile = d("narrow.toml");
    std::fs::write(&profile, narrow.to_toml().unwrap()).unwrap();
    let err = one_line_error(&galvoplan(&[
        "plan",
        &project,
        "--profile",
        &profile,
        "-o",
        &d("b.ngc"),
    ]));
    assert!(
        err.contains("is outside axis B's travel -1 to 1 deg") && !err.contains("0000"),
        "{err}"
    );
    // on the fly cannot turn them
    let err = one_line_error(&galvoplan(&[
        "plan",
        &project,
        "--profile",
        "five-axis",
        "--motion",
        "on-the-fly",
        "-o",
        &d("c.ngc"),
    ]));
    assert!(err.contains("step-and-scan"), "{err}");
}

#[test]
fn a_rotary_with_zero_speed_is_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let profile = dir.path().join("p.toml");
    std::fs::write(
        &profile,
        "version = 5\n[axis_b]\nmax_velocity_deg_s = 0.0\nramp_s = 0.2\n",
    )
    .unwrap();
    let demo = common::root().join("assets/examples/demo.svg");
    let err = one_line_error(&galvoplan(&[
        "plan",
        &demo.display().to_string(),
        "--profile",
        &profile.display().to_string(),
        "-o",
        &dir.path().join("x.ngc").display().to_string(),
    ]));
    assert!(
        err.contains("Axis B max velocity (deg/s) must be a positive number, not 0"),
        "{err}"
    );
}

#[test]
fn built_in_machines_name_their_axes() {
    use galvoplan::document::MachineProfile;
    let five = MachineProfile::builtin("five-axis").unwrap();
    assert_eq!(five.axes_words(), "X, Y, Z, A, B");
    let rotary = MachineProfile::builtin("rotary").unwrap();
    assert_eq!(rotary.axes_words(), "X, A");
    // seed 002's Table 2: B at 0.87 rad/s with 0.156 s, in degrees
    let b = &five.axis_b.as_ref().unwrap().0;
    assert!((b.max_velocity - 0.87_f64.to_degrees()).abs() < 1e-9);
    assert!((b.max_velocity / b.max_accel - 0.156).abs() < 1e-12);
    let a = &rotary.axis_a.as_ref().unwrap().0;
    assert_eq!(
        (a.max_velocity, a.max_accel, a.travel),
        (360.0, 3600.0, None)
    );
}
