//! Lowering tests: timing against hand-computed figures, states along the toolpath, the clock.
#![allow(clippy::unwrap_used)]

use super::*;
use crate::document::{
    Algo, Geometry, MachineProfile, Metrics, Plan, PlanInputs, ScanField, Source, Step,
};
use crate::geom::Pt;

fn line(a: Pt, b: Pt) -> Geometry {
    Geometry::new(vec![a, b], false, Source::default())
}

fn field(id: usize, c: Pt) -> ScanField {
    ScanField {
        id,
        center: c,
        size: [70.0, 70.0],
        locked: false,
        geometries: vec![],
        pose: Default::default(),
    }
}

fn step(geometry: usize, field: usize) -> Step {
    Step {
        geometry,
        field,
        start_vertex: 0,
        reversed: false,
    }
}

fn plan(fields: Vec<ScanField>, order: Vec<Step>) -> Plan {
    Plan {
        name: "t".into(),
        algo: Algo::Hha,
        fields,
        order,
        metrics: Metrics::default(),
        history: vec![],
        motion: Default::default(),
        stage_route: None,
        layers: vec![],
        ..Plan::new(
            &PlanInputs::of(&Default::default()),
            Motion::Step,
            vec![],
            vec![],
        )
    }
}

/// Two 10 mm lines in one field, then one in a field 100 mm to the right.
fn job() -> (Vec<Geometry>, Plan) {
    let g = vec![
        line(Pt::new(40.0, 50.0), Pt::new(50.0, 50.0)),
        line(Pt::new(50.0, 60.0), Pt::new(40.0, 60.0)),
        line(Pt::new(140.0, 50.0), Pt::new(150.0, 50.0)),
    ];
    let p = plan(
        vec![
            field(0, Pt::new(50.0, 50.0)),
            field(7, Pt::new(150.0, 50.0)),
        ],
        vec![step(0, 0), step(1, 0), step(2, 7)],
    );
    (g, p)
}

#[test]
fn job_time_adds_up_from_the_profile() {
    let profile = MachineProfile::default();
    let (g, p) = job();
    let tp = lower(&g, &p, &profile).unwrap();
    let (mark, jump) = (
        profile.scanner.mark_speed_mm_s,
        profile.scanner.jump_speed_mm_s,
    );
    let l = &profile.laser;
    let marks = 3.0 * (10.0 / mark + l.on_delay_s + l.off_delay_s);
    let in_field_jump = 10.0 / jump + l.jump_delay_s;
    // 100 mm at 500 mm/s, 5000 mm/s²: cruise, d/v + v/a
    let stage = 100.0 / 500.0 + 500.0 / 5000.0;
    let want = marks + in_field_jump + stage;
    assert!(
        (tp.duration_s() - want).abs() < 1e-12,
        "{} vs {want}",
        tp.duration_s()
    );
    let b = tp.breakdown();
    assert!((b.total() - tp.duration_s()).abs() < 1e-12);
    assert!((b.stage - stage).abs() < 1e-12 && b.settle == 0.0);
    assert!((b.mark - 0.03).abs() < 1e-12);
}

#[test]
fn states_follow_the_plan() {
    let profile = MachineProfile::default();
    let (g, p) = job();
    let tp = lower(&g, &p, &profile).unwrap();
    let s0 = tp.state_at(0.0);
    assert_eq!(s0.stage, Pt::new(50.0, 50.0));
    assert_eq!(s0.tcp(), Pt::new(40.0, 50.0));
    // halfway through the first mark
    let t = profile.laser.on_delay_s + 0.005;
    let s = tp.state_at(t);
    assert!(s.laser && s.tcp().dist(Pt::new(45.0, 50.0)) < 1e-9);
    // the end: the last stroke's end, stage at the second field
    let e = tp.state_at(tp.duration_s());
    assert_eq!(e.stage, Pt::new(150.0, 50.0));
    assert!(e.tcp().dist(Pt::new(150.0, 50.0)) < 1e-9);
    // during the stage move the laser is off and the stage is between the fields
    let mv = tp
        .segments
        .iter()
        .find(|s| s.kind == SegmentKind::StageMove)
        .unwrap();
    let m = tp.state_at(mv.start_s + mv.duration_s / 2.0);
    assert!(!m.laser && m.stage.x > 50.0 && m.stage.x < 150.0);
    // the scanner jumped during the move: no separate jump after it
    assert!(matches!(mv.scan, ScanMotion::Line { .. }));
}

#[test]
fn settling_and_ramp_time_come_from_the_profile() {
    let mut profile = MachineProfile::from_toml(
        "version = 2\n[axis_x]\nmax_velocity_mm_s = 500.0\nramp_s = 0.25\nsettle_s = 0.03\n",
        "p.toml",
    )
    .unwrap();
    assert!((profile.axis_x.max_accel_mm_s2 - 2000.0).abs() < 1e-9);
    profile.axis_y.settle_s = 0.5; // y does not move: no y settling
    let (g, p) = job();
    let tp = lower(&g, &p, &profile).unwrap();
    let b = tp.breakdown();
    assert!((b.settle - 0.03).abs() < 1e-12, "{}", b.settle);
    // 100 mm < v²/a = 125 mm: a triangle, 2·√(d/a)
    assert!(
        (b.stage - 2.0 * (100.0f64 / 2000.0).sqrt()).abs() < 1e-12,
        "{}",
        b.stage
    );
}

#[test]
fn out_of_reach_and_missing_fields_are_errors() {
    let profile = MachineProfile::default();
    let (g, mut p) = job();
    p.fields[1].center = Pt::new(200.0, 50.0);
    let e = lower(&g, &p, &profile).unwrap_err();
    assert!(
        matches!(
            e,
            LowerError::OutOfReach {
                geometry: 2,
                field: 7,
                ..
            }
        ),
        "{e}"
    );
    let (g, mut p) = job();
    p.order[2].field = 3;
    assert_eq!(
        lower(&g, &p, &profile).unwrap_err(),
        LowerError::NoField { step: 2, field: 3 }
    );
}

#[test]
fn on_the_clock_marks_start_and_end_on_ticks() {
    let profile = MachineProfile::default();
    let (g, p) = job();
    let tp = lower(&g, &p, &profile).unwrap();
    let period = 1e-3;
    let clocked = tp.on_clock(period);
    assert!(clocked.duration_s() >= tp.duration_s());
    // per mark at most two ticks of waiting and one of slower marking
    assert!(clocked.duration_s() <= tp.duration_s() + 3.0 * 3.0 * period);
    for s in clocked
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Mark)
    {
        for t in [s.start_s, s.end_s()] {
            let ticks = t / period;
            assert!((ticks - ticks.round()).abs() < 1e-6, "{t}");
        }
        // marked no faster than the mark speed
        let len = clocked.strokes[match s.scan {
            ScanMotion::Mark { stroke, .. } => stroke,
            _ => unreachable!(),
        }]
        .length_mm;
        assert!(len / s.duration_s <= profile.scanner.mark_speed_mm_s * (1.0 + 1e-9));
        // the samples at both ends are on, at the stroke's ends
        assert!(clocked.state_at(s.start_s).laser && clocked.state_at(s.end_s()).laser);
    }
    // contiguous segments
    for w in clocked.segments.windows(2) {
        assert!((w[0].end_s() - w[1].start_s).abs() < 1e-12);
    }
}

/// On a LinuxCNC clock, pauses next to each other are one dwell, timed as task runs it (first
/// after a move: task's resume and whole task cycles; after a dot's output: its time and a
/// tail), a dot costs its two outputs; the step-time model equals the lowering, and the program
/// writes each dwell with the pauses' own times, not the law's.
#[test]
fn linuxcnc_dwells_and_dots_are_timed_by_task_and_written_with_their_own_times() {
    use super::controller::{DWELL_TAIL_S, TASK_CYCLE_RUN_S, TASK_RESUME_S};
    let profile = super::linuxcnc_with_delays();
    let dot = |p: Pt| Geometry::new(vec![p], false, Source::default());
    // two dots and a line in one field, a dot in a field 100 mm to the right
    let g = vec![
        dot(Pt::new(45.0, 50.0)),
        dot(Pt::new(50.0, 55.0)),
        line(Pt::new(40.0, 60.0), Pt::new(50.0, 60.0)),
        dot(Pt::new(150.0, 50.0)),
    ];
    let fields = vec![
        field(0, Pt::new(50.0, 50.0)),
        field(7, Pt::new(150.0, 50.0)),
    ];
    let steps = vec![step(0, 0), step(1, 0), step(2, 0), step(3, 7)];
    let mut p = plan(fields.clone(), steps.clone());
    p.profile = profile.clone();
    let tp = lower(&g, &p, &profile).unwrap();
    let clock = super::controller::LinuxcncClock::of(&profile).unwrap();
    let dwell = crate::document::MarkTiming::of(None, &profile).dot_dwell_s;
    // dwells: on delay (first after the move to the start), off delay (after a dot), jump and
    // on delay (after a jump) twice, off delay (after the line), settling and on delay (after
    // the stage move: 5.1 ms, five task cycles), off delay (after a dot); the line's M62 and
    // the M63 after it wait for motion (after a dwell each)
    let tc = TASK_CYCLE_RUN_S;
    let tail = 2e-4 + DWELL_TAIL_S;
    let holds = 5.0 * TASK_RESUME_S + 9.0 * tc + 3.0 * tail + 2.0 * clock.output_s();
    let held: f64 = tp
        .segments
        .iter()
        .filter(|s| {
            matches!(
                s.kind,
                SegmentKind::Settle
                    | SegmentKind::JumpDelay
                    | SegmentKind::LaserOnDelay
                    | SegmentKind::LaserOffDelay
            )
        })
        .map(|s| s.duration_s)
        .sum();
    assert!((held - holds).abs() < 1e-12, "{held} vs {holds}");
    // dots, each after a dwell: M64, the dwell and its tail, M65
    let dots: Vec<f64> = tp
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Mark)
        .map(|s| s.duration_s)
        .collect();
    let one = 2.0 * clock.period_s + dwell + DWELL_TAIL_S;
    for k in [0, 1, 3] {
        assert!((dots[k] - one).abs() < 1e-12, "{dots:?}");
    }
    assert_eq!(one, clock.dot_s(dwell, false));
    // the step-time model takes the same time
    let model =
        crate::order::objective::StepTime::new(&g, &fields, &[], &profile).job_time_s(&steps);
    assert!(
        (model - tp.duration_s()).abs() <= 1e-9 * tp.duration_s(),
        "{model} vs {}",
        tp.duration_s()
    );
    // the program's dwells: the pauses' own times, added where they are next to each other
    let gcode = crate::export::write_gcode(&tp, &p, 297.0, "t").unwrap();
    let dwells: Vec<&str> = gcode
        .lines()
        .filter_map(|l| l.strip_prefix("G4 P"))
        .collect();
    let d = crate::geom::format_mm(dwell, 7);
    let want = [
        "0.0001", &d, "0.0002", "0.0004", &d, "0.0002", "0.0004", "0.0002", "0.0051", &d, "0.0002",
    ];
    assert_eq!(dwells, want, "{gcode}");
}
