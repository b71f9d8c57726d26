//! The LinuxCNC dialect, its machine configuration and its time law, without LinuxCNC
//! (scripts/check-linuxcnc.sh runs the programs on LinuxCNC itself).
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::document::{Document, MachineProfile, MotionMode, Plan, SolverSettings};
use galvoplan::export::{linuxcnc_config, waypoints_csv, write_gcode};
use galvoplan::import::ImportOptions;
use galvoplan::job::JobCtx;
use galvoplan::motion::controller::{otf_lines, LinuxcncClock};
use galvoplan::motion::Toolpath;
use galvoplan::pipeline::{load_svg, plan_document_lowered};

fn planned(name: &str, motion: MotionMode, profile: MachineProfile) -> (Document, Plan, Toolpath) {
    let settings = SolverSettings {
        motion,
        ..SolverSettings::default()
    };
    let path = common::root().join("assets/examples").join(name);
    let (mut doc, _) = load_svg(&path, profile, settings, &ImportOptions::default()).unwrap();
    let (plan, toolpath) = plan_document_lowered(&mut doc, &JobCtx::default()).unwrap();
    (doc, plan, toolpath)
}

/// The numbers after each of `words` on a G-code line (`G1 U1.5 V-2` → [1.5, -2]).
fn words(line: &str, letters: &[char]) -> Vec<Option<f64>> {
    letters
        .iter()
        .map(|&l| {
            line.split_whitespace()
                .find(|w| w.starts_with(l))
                .and_then(|w| w[1..].parse().ok())
        })
        .collect()
}

#[test]
fn step_and_scan_marks_between_m62_and_m63_in_exact_path_mode() {
    let profile = MachineProfile::builtin("linuxcnc").unwrap();
    let (doc, plan, toolpath) = planned("demo.svg", MotionMode::Step, profile.clone());
    let g = write_gcode(&toolpath, &plan, doc.page_mm[1], "demo").unwrap();
    let lines: Vec<&str> = g.lines().collect();
    assert!(lines[0].starts_with("(galvoplan"), "{}", lines[0]);
    assert!(g.contains("G21 G90 G94") && g.contains("\nG61\n") && g.contains("\nM65 P0\n"));
    assert!(!g.contains("M3") && !g.contains("M5\n") && !g.contains(';'));
    assert!(g.trim_end().ends_with("M2"));
    // the last laser word is the immediate off, after every move
    let last_move = lines
        .iter()
        .rposition(|l| l.starts_with('G') && l.contains('U'));
    let last_off = lines.iter().rposition(|l| *l == "M65 P0");
    assert!(last_off > last_move);
    // no dwells: the profile has no delays
    assert!(!lines.iter().any(|l| l.starts_with("G4 ")));
    // feeds only while lit, rapids only while dark; one G1 per edge of every stroke
    let mut lit = false;
    let mut feeds = 0;
    let half = profile.field_mm[0] / 2.0 + 1e-4;
    for l in &lines {
        match *l {
            "M62 P0" => lit = true,
            "M63 P0" => lit = false,
            _ if l.starts_with("G1 ") => {
                assert!(lit, "feed with the laser off: {l}");
                feeds += 1;
                for v in words(l, &['U', 'V']).into_iter().flatten() {
                    assert!(v.abs() <= half, "{l} outside the field");
                }
            }
            _ if l.starts_with("G0 ") => assert!(!lit, "rapid with the laser on: {l}"),
            _ => {}
        }
    }
    let edges: usize = (0..toolpath.strokes.len())
        .map(|k| toolpath.stroke_points(k).len() - 1)
        .sum();
    assert_eq!(feeds, edges);
    // the job time is the controller's: slower than the scan head's own
    let ideal = planned("demo.svg", MotionMode::Step, MachineProfile::default()).2;
    assert!(toolpath.duration_s() > ideal.duration_s() * 1.1);
}

#[test]
fn on_the_fly_lines_last_the_planned_time_and_stay_within_the_tolerance() {
    // a LinuxCNC machine without the streamer wiring: on the fly is an inverse-time program
    let mut profile = MachineProfile::builtin("linuxcnc").unwrap();
    profile.controller.stream_period_s = None;
    let tol = profile.gcode.path_tol_mm;
    let (doc, plan, toolpath) = planned("oversize.svg", MotionMode::OnTheFly, profile.clone());
    assert!(toolpath.route.is_some());
    let g = write_gcode(&toolpath, &plan, doc.page_mm[1], "oversize").unwrap();
    assert!(g.contains("\nG93\n") && g.contains(&format!("G64 P{tol}")));
    // inverse-time feeds add up to the planned time; the toolpath runs at the controller's pace
    let minutes: f64 = g
        .lines()
        .filter(|l| l.starts_with("G1 "))
        .map(|l| 1.0 / words(l, &['F'])[0].unwrap())
        .sum();
    let planned_s = toolpath.duration_s() / toolpath.stretch();
    assert!(
        (minutes * 60.0 - planned_s).abs() <= 1e-6 * planned_s,
        "{} vs {planned_s}",
        minutes * 60.0
    );
    assert!(toolpath.stretch() >= 1.0);
    let clock = LinuxcncClock::of(&profile).unwrap();
    let (start, lines) = otf_lines(&toolpath, tol);
    let controller_s = clock.otf_program_s(&start, &lines);
    assert!(
        (controller_s - toolpath.duration_s()).abs() <= 1e-6 * controller_s,
        "{controller_s} vs {}",
        toolpath.duration_s()
    );
    // every waypoint lies within the tolerance of the line through it (in planned time)
    let waypoints: Vec<Vec<f64>> = waypoints_csv(&toolpath, &[])
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let k = toolpath.stretch();
    let mut t_end = 0.0;
    let mut from = [start.stage.x, start.stage.y, start.scan.x, start.scan.y];
    let mut w = 0;
    for line in &lines {
        let t0 = t_end;
        t_end += line.duration_s * k;
        let to = [line.stage.x, line.stage.y, line.scan.x, line.scan.y];
        while w < waypoints.len() && waypoints[w][0] <= t_end + 1e-9 {
            let r = &waypoints[w];
            let u = if t_end > t0 {
                ((r[0] - t0) / (t_end - t0)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let p: Vec<f64> = (0..4).map(|i| from[i] + (to[i] - from[i]) * u).collect();
            let stage = (p[0] - r[1]).hypot(p[1] - r[2]);
            let tcp = (p[0] + p[2] - r[1] - r[3]).hypot(p[1] + p[3] - r[2] - r[4]);
            assert!(
                stage <= tol + 1e-6 && tcp <= tol + 1e-6, // the CSV holds positions to 0.1 µm
                "at {}: {stage} {tcp}",
                r[0]
            );
            w += 1;
        }
        from = to;
    }
    assert_eq!(w, waypoints.len());
}

#[test]
fn the_configuration_is_the_profiles_machine() {
    let mut profile = MachineProfile::builtin("linuxcnc").unwrap();
    profile.gcode.power_output = Some(2);
    profile.controller.servo_period_s = 5e-4;
    let files = linuxcnc_config(&profile);
    let text = |name: &str| {
        files
            .iter()
            .find(|f| f.name == name)
            .map(|f| f.text.clone())
            .unwrap()
    };
    let ini = text("galvoplan.ini");
    assert!(ini.contains("KINEMATICS = trivkins coordinates=XYUV"));
    assert!(ini.contains("COORDINATES = XYUV") && ini.contains("JOINTS = 4"));
    assert!(ini.contains("SERVO_PERIOD = 500000"));
    assert!(ini.contains("[AXIS_U]\nMIN_LIMIT = -35.001\nMAX_LIMIT = 35.001\nMAX_VELOCITY = 5000"));
    assert!(ini.contains("[JOINT_0]") && ini.contains("[JOINT_3]"));
    assert!(ini.contains("MAX_ACCELERATION = 1000000"));
    let hal = text("galvoplan.hal");
    assert!(hal.contains("num_aio=4") && hal.contains("base_period_nsec=[EMCMOT]BASE_PERIOD"));
    assert!(hal.contains("joint.3.motor-pos-cmd => joint.3.motor-pos-fb"));
    assert!(files
        .iter()
        .any(|f| f.name == "galvoplan-run.py" && f.executable));
    assert!(text("README.txt").contains("xy2mod"));
    // the stream: in the base thread, its period the profile's; the joints, the laser (gated
    // by the stream's state) and the power through it; an underrun is an E-stop
    assert!(ini.contains("BASE_PERIOD = 100000") && ini.contains("HALFILE = galvoplan-stream.hal"));
    let stream = text("galvoplan-stream.hal");
    for line in [
        "loadrt streamer depth=20000 cfg=ffffbbf",
        "addf streamer.0 base-thread",
        "net st-select motion.digital-out-01 => streamer.0.enable mux2.0.sel",
        "net laser-gate st-laser-or.out",
        "net estop-loop st-enable.out => iocontrol.0.emc-enable-in",
        "net st-end streamer.0.pin.5 => motion.digital-in-00",
        "net st-p3 streamer.0.pin.3 => mux2.3.in1",
        "net st-power streamer.0.pin.6 => mux2.4.in1",
    ] {
        assert!(stream.contains(line), "{line}");
    }
    let timers = text("galvoplan-timers.hal");
    assert!(timers.contains("loadrt and2 names=tm-laser-move,tm-job,st-active"));
    // without a stream: the laser is motion's output alone
    profile.controller.stream_period_s = None;
    let files = linuxcnc_config(&profile);
    let hal = &files
        .iter()
        .find(|f| f.name == "galvoplan.hal")
        .unwrap()
        .text;
    assert!(hal.contains("net laser-gate motion.digital-out-00"));
    assert!(hal.contains("net laser-power motion.analog-out-02"));
    assert!(!files.iter().any(|f| f.name == "galvoplan-stream.hal"));
}

#[test]
fn a_streamed_plan_is_its_own_states_on_the_streams_clock() {
    use galvoplan::export::{stream_text, StreamError};
    let profile = MachineProfile::builtin("linuxcnc").unwrap();
    let period_s = profile.controller.stream_period_s.unwrap();
    let (doc, plan, toolpath) = planned("oversize.svg", MotionMode::OnTheFly, profile.clone());
    let (text, f) = stream_text(&toolpath, &plan).unwrap();
    let lines: Vec<Vec<&str>> = text.lines().map(|l| l.split(' ').collect()).collect();
    assert_eq!(lines.len(), f.samples);
    assert_eq!(f.period_s, period_s);
    // the plan's own states, sample by sample, and its end marked on the last line only
    for (k, cols) in lines.iter().enumerate() {
        assert_eq!(cols.len(), 6);
        let m = toolpath.state_at(k as f64 * period_s);
        let v: Vec<f64> = cols[..4].iter().map(|c| c.parse().unwrap()).collect();
        let want = [m.stage.x, m.stage.y, m.scan.x, m.scan.y];
        assert!(v.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6), "{k}");
        assert_eq!(cols[4], if m.laser { "1" } else { "0" });
        assert_eq!(cols[5] == "1", k + 1 == lines.len());
    }
    // the laser switches on a sample (the plan is made on the stream's clock): where a mark
    // begins after something else, and ends before something else
    let mark = |i: usize| {
        toolpath
            .segments
            .get(i)
            .is_some_and(|s| s.kind == galvoplan::motion::SegmentKind::Mark)
    };
    let on_tick = |t: f64| ((t / period_s) - (t / period_s).round()).abs() < 1e-6;
    for (i, seg) in toolpath
        .segments
        .iter()
        .enumerate()
        .filter(|(i, _)| mark(*i))
    {
        assert!(
            i == 0 || mark(i - 1) || on_tick(seg.start_s),
            "{}",
            seg.start_s
        );
        assert!(mark(i + 1) || on_tick(seg.end_s()), "{}", seg.end_s());
    }
    // between samples the joints stay within the path tolerance of the planned path, also on
    // a pattern of sharp turns (the marks slow there)
    assert!(
        f.max_deviation_mm <= profile.gcode.path_tol_mm,
        "{}",
        f.max_deviation_mm
    );
    let settings = SolverSettings {
        motion: MotionMode::OnTheFly,
        ..SolverSettings::default()
    };
    let lissajous = common::root().join("tests/data/linuxcnc/lissajous.svg");
    let (mut ldoc, _) = load_svg(
        &lissajous,
        profile.clone(),
        settings,
        &ImportOptions::default(),
    )
    .unwrap();
    let (lplan, lpath) = plan_document_lowered(&mut ldoc, &JobCtx::default()).unwrap();
    let (_, lf) = stream_text(&lpath, &lplan).unwrap();
    assert!(
        lf.max_deviation_mm <= profile.gcode.path_tol_mm,
        "{}",
        lf.max_deviation_mm
    );
    // the program hands the joints over and waits for the stream's last sample
    let g = write_gcode(&toolpath, &plan, doc.page_mm[1], "oversize").unwrap();
    assert!(g.contains("\nM64 P1\nM66 P0 L3 Q") && g.contains("\nM65 P1\n"));
    assert!(!g.contains("G93") && !g.contains("\nG1 "));
    // a sample beyond the machine's limits is refused
    let mut small = plan.clone();
    small.profile.stroke_mm = [100.0, 100.0];
    let e = stream_text(&toolpath, &small).unwrap_err();
    assert!(
        matches!(e, StreamError::Beyond { ref axis, .. } if axis == "X" || axis == "Y"),
        "{e}"
    );
    // a step-and-scan plan is not streamed
    let (_, step, step_path) = planned("demo.svg", MotionMode::Step, profile);
    assert!(matches!(
        stream_text(&step_path, &step),
        Err(StreamError::NotStreamed { .. })
    ));
}

#[test]
fn linuxcnc_profile_values_are_checked_by_name() {
    let bad = "version = 3\n[gcode]\nmode = \"linuxcnc\"\nlaser_output = 99\n";
    let e = MachineProfile::from_toml(bad, "p.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("Laser output") && e.contains("99"), "{e}");
    let bad = "version = 3\n[controller]\nkind = \"linuxcnc\"\nservo_period_s = 0.5\n";
    let e = MachineProfile::from_toml(bad, "p.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("Servo period"), "{e}");
    // LinuxCNC's time law times only the LinuxCNC program
    let bad = "version = 3\n[controller]\nkind = \"linuxcnc\"\n";
    let e = MachineProfile::from_toml(bad, "p.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("Controller") && e.contains("dialect"), "{e}");
    // version-2 files stay valid, on the scan head's timing
    let p = MachineProfile::from_toml("version = 2\n", "p.toml").unwrap();
    assert!(LinuxcncClock::of(&p).is_none());
}

#[test]
fn power_goes_to_the_analog_output_with_the_pen() {
    let mut profile = MachineProfile::builtin("linuxcnc").unwrap();
    profile.gcode.power_output = Some(1);
    profile.gcode.power = Some(40.0);
    let (doc, plan, toolpath) = planned("demo.svg", MotionMode::Step, profile);
    let g = write_gcode(&toolpath, &plan, doc.page_mm[1], "demo").unwrap();
    let first_power = g.find("M67 E1 Q40").expect("power word");
    let first_mark = g.find("M62 P0").unwrap();
    assert!(first_power < first_mark);
    assert!(g.contains("M68 E1 Q0\n"), "power off at the end");
}

#[test]
fn linuxcnc_config_writes_the_machine_and_refuses_a_file_for_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("machine");
    let run = |args: &[&std::ffi::OsStr]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_galvoplan"))
            .args(args)
            .output()
            .unwrap()
    };
    let r = run(&[
        "linuxcnc-config".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    for name in [
        "galvoplan.ini",
        "galvoplan.hal",
        "galvoplan-timers.hal",
        "galvoplan-run.py",
    ] {
        assert!(out.join(name).is_file(), "{name}");
    }
    let ini = std::fs::read_to_string(out.join("galvoplan.ini")).unwrap();
    assert!(ini.contains("DISPLAY = ./galvoplan-run.py"));
    // a file where the folder should be: an error naming it, nothing written
    let file = dir.path().join("a-file");
    std::fs::write(&file, "keep me").unwrap();
    let r = run(&[
        "linuxcnc-config".as_ref(),
        "--out".as_ref(),
        file.as_os_str(),
    ]);
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("a-file") && err.contains("not a folder"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep me");
    // an unknown profile is named
    let r = run(&[
        "linuxcnc-config".as_ref(),
        "--profile".as_ref(),
        "nope".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(String::from_utf8_lossy(&r.stderr).contains("nope"));
}

/// The workbench's G-code export of a streamed plan writes its stream beside the program.
#[cfg(feature = "gui")]
#[test]
fn the_workbench_exports_a_streamed_plans_stream_beside_its_program() {
    use galvoplan::app::files::{export, stream_path, ExportKind};
    let profile = MachineProfile::builtin("linuxcnc").unwrap();
    let (doc, plan, toolpath) = planned("oversize.svg", MotionMode::OnTheFly, profile);
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("job.ngc");
    export(&doc, &plan, Some(&toolpath), ExportKind::Gcode, &program).unwrap();
    let stream = std::fs::read_to_string(stream_path(&program)).unwrap();
    let (want, _) = galvoplan::export::stream_text(&toolpath, &plan).unwrap();
    assert_eq!(stream, want);
    assert!(std::fs::read_to_string(&program)
        .unwrap()
        .contains("M64 P1"));
}

/// The 5-axis stand-in that scripts/check-linuxcnc.sh runs on LinuxCNC (seed 002's machine,
/// XYZABUV): it plans on a LinuxCNC copy of the five-axis profile, every stage move carries Z,
/// A and B, the waypoints have their columns, and `linuxcnc-config` makes the 7-joint machine.
#[test]
fn the_five_axis_stand_in_plans_for_an_xyzabuv_machine() {
    let dir = tempfile::tempdir().unwrap();
    let mut profile = MachineProfile::builtin("five-axis").unwrap();
    profile.gcode.mode = galvoplan::document::GcodeMode::Linuxcnc;
    profile.controller.kind = galvoplan::document::ControllerKind::Linuxcnc;
    profile.controller.servo_period_s = 1e-3;
    let p = dir.path().join("five-axis-linuxcnc.toml");
    std::fs::write(&p, profile.to_toml().unwrap()).unwrap();
    let (ngc, csv, cfg) = (
        dir.path().join("s.ngc"),
        dir.path().join("s.csv"),
        dir.path().join("machine"),
    );
    let project = common::root().join("tests/data/linuxcnc/five-axis-stand-in.galvoplan");
    let run = |args: &[&std::ffi::OsStr]| {
        let r = std::process::Command::new(env!("CARGO_BIN_EXE_galvoplan"))
            .args(args)
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    };
    run(&[
        "plan".as_ref(),
        project.as_os_str(),
        "--profile".as_ref(),
        p.as_os_str(),
        "--cost".as_ref(),
        "time".as_ref(),
        "--motion".as_ref(),
        "step".as_ref(),
        "-o".as_ref(),
        ngc.as_os_str(),
        "--waypoints".as_ref(),
        csv.as_os_str(),
    ]);
    let g = std::fs::read_to_string(&ngc).unwrap();
    let moves: Vec<&str> = g.lines().filter(|l| l.starts_with("G0 ")).collect();
    assert_eq!(moves.len(), 300, "one stage move per placement");
    for m in &moves {
        let w = words(m, &['X', 'Y', 'Z', 'A', 'B', 'U', 'V']);
        assert!(w.iter().all(Option::is_some), "{m}");
    }
    // dots at rest: on, dwell, off, never a lit move
    assert_eq!(g.matches("M64 P0\nG4 P").count(), 300);
    // every dwell is its pauses' own time (the laser delays, the dot's dwell), without what
    // LinuxCNC's task adds to it (the toolpath's time has that)
    let (l, dot) = (
        &profile.laser,
        galvoplan::document::MarkTiming::of(None, &profile).dot_dwell_s,
    );
    for p in g.lines().filter_map(|l| l.strip_prefix("G4 P")) {
        let p: f64 = p.parse().unwrap();
        assert!(
            [l.on_delay_s, l.off_delay_s, dot]
                .iter()
                .any(|d| (p - d).abs() < 1e-7),
            "G4 P{p}"
        );
    }
    assert!(!g.contains("M62") && !g.contains("G1 "));
    let waypoints = std::fs::read_to_string(&csv).unwrap();
    assert!(waypoints
        .starts_with("t_s,stage_x_mm,stage_y_mm,scan_x_mm,scan_y_mm,laser,z_mm,a_deg,b_deg\n"));
    run(&[
        "linuxcnc-config".as_ref(),
        "--profile".as_ref(),
        p.as_os_str(),
        "--out".as_ref(),
        cfg.as_os_str(),
    ]);
    let ini = std::fs::read_to_string(cfg.join("galvoplan.ini")).unwrap();
    assert!(ini.contains("coordinates=XYZABUV\nJOINTS = 7\n"), "{ini}");
}
