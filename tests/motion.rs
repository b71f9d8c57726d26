//! The motion layer end to end: one lowered toolpath behind the G-code dialects, the sampled
//! trajectory and the job time; time-based ordering against distance and the document order;
//! profile versions.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::document::{
    Algo, CostModel, Document, GcodeMode, MachineProfile, Plan, SolverSettings,
};
use galvoplan::export::{trajectory_csv, write_gcode, TRAJECTORY_HEADER};
use galvoplan::geom::{point_segment_dist, Pt};
use galvoplan::import::ImportOptions;
use galvoplan::job::JobCtx;
use galvoplan::motion::Toolpath;
use galvoplan::pipeline::{load_svg, lower_plan, plan_document};

/// Default settings in step-and-scan (the tests of the step lowering).
fn step_settings() -> SolverSettings {
    SolverSettings {
        motion: galvoplan::document::MotionMode::Step,
        ..SolverSettings::default()
    }
}

fn plan_example(name: &str, profile: MachineProfile, settings: SolverSettings) -> (Document, Plan) {
    let path = common::root().join("assets/examples").join(name);
    let (mut doc, _) = load_svg(&path, profile, settings, &ImportOptions::default()).unwrap();
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    common::check_plan(&doc, &plan);
    (doc, plan)
}

/// The marks of a G-code file as tool-centre polylines. `scanner` names the scanner axis words
/// of a stage-scanner file (the tool point is then stage X/Y + scanner offset); `None` reads a
/// tool-centre file.
fn gcode_marks(gcode: &str, scanner: Option<[&str; 2]>) -> Vec<Vec<Pt>> {
    let (mut stage, mut scan, mut tcp) = (Pt::default(), Pt::default(), Pt::default());
    let (mut on, mut marks) = (false, Vec::<Vec<Pt>>::new());
    for line in gcode.lines().filter(|l| !l.starts_with(';')) {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first().copied() {
            Some("M3") | Some("M4") => {
                on = true;
                marks.push(vec![stage.plus(scan).plus(tcp)]);
                continue;
            }
            Some("M5") => {
                on = false;
                continue;
            }
            _ => {}
        }
        for w in &words[1..] {
            let (axis, value) = w.split_at(1);
            let Ok(v) = value.parse::<f64>() else {
                continue;
            };
            match (axis, scanner) {
                ("X", Some(_)) => stage.x = v,
                ("Y", Some(_)) => stage.y = v,
                ("X", None) => tcp.x = v,
                ("Y", None) => tcp.y = v,
                (a, Some([u, _])) if a == u => scan.x = v,
                (a, Some([_, w])) if a == w => scan.y = v,
                _ => {}
            }
        }
        if on && words[0] == "G1" {
            marks.last_mut().unwrap().push(stage.plus(scan).plus(tcp));
        }
    }
    marks
}

fn same_marks(a: &[Vec<Pt>], b: &[Vec<Pt>], tol_mm: f64) {
    assert_eq!(a.len(), b.len(), "mark count");
    for (k, (p, q)) in a.iter().zip(b).enumerate() {
        assert_eq!(p.len(), q.len(), "mark {k}: point count");
        for (x, y) in p.iter().zip(q) {
            assert!(x.dist(*y) <= tol_mm, "mark {k}: {x:?} vs {y:?}");
        }
    }
}

#[test]
fn stage_scanner_gcode_marks_what_the_tcp_gcode_marks() {
    for flip in [false, true] {
        let mut profile = MachineProfile::default();
        profile.gcode.flip_y = flip;
        let (doc, plan) = plan_example("demo.svg", profile, step_settings());
        let toolpath = lower_plan(&doc, &plan).unwrap();
        let tcp = write_gcode(&toolpath, &plan, doc.page_mm[1], "t").unwrap();
        let mut p2 = doc.profile.clone();
        p2.gcode.mode = GcodeMode::StageScanner;
        p2.gcode.scanner_axes = ["A".into(), "B".into()];
        // the same plan written in another dialect (the dialect does not change the timing)
        let mut in_p2 = plan.clone();
        in_p2.profile = p2;
        let split = write_gcode(&toolpath, &in_p2, doc.page_mm[1], "t").unwrap();
        assert!(
            split.contains("G0 A") && split.contains("G1 A"),
            "scanner words"
        );
        let (a, b) = (
            gcode_marks(&tcp, None),
            gcode_marks(&split, Some(["A", "B"])),
        );
        assert_eq!(a.len(), plan.order.len());
        // both are written with 4 decimals: stage + offset rounds twice
        same_marks(&a, &b, 2e-4);
        // in stage-scanner mode every scanner word stays inside the field
        for line in split
            .lines()
            .filter(|l| l.starts_with("G1") || l.starts_with("G0 A"))
        {
            for w in line
                .split_whitespace()
                .filter(|w| w.starts_with('A') || w.starts_with('B'))
            {
                let v: f64 = w[1..].parse().unwrap();
                assert!(v.abs() <= 35.0 + 1e-4, "{line}");
            }
        }
    }
}

/// Laser-on rows of a trajectory CSV as tool-centre points.
fn laser_on_points(csv: &str, period_s: f64) -> Vec<Pt> {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some(TRAJECTORY_HEADER));
    let mut out = Vec::new();
    for (k, line) in lines.enumerate() {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        assert_eq!(v.len(), 6);
        assert!((v[0] - k as f64 * period_s).abs() < 1e-6, "constant period");
        if v[5] == 1.0 {
            out.push(Pt::new(v[1] + v[3], v[2] + v[4]));
        }
    }
    out
}

#[test]
fn trajectory_marks_the_gcode_path() {
    let (doc, plan) = plan_example("demo.svg", MachineProfile::default(), step_settings());
    let toolpath = lower_plan(&doc, &plan).unwrap();
    let marks = gcode_marks(
        &write_gcode(&toolpath, &plan, doc.page_mm[1], "t").unwrap(),
        None,
    );
    let period_s = 1e-3;
    let clocked = toolpath.on_clock(period_s);
    let on = laser_on_points(&trajectory_csv(&clocked, period_s, &[]), period_s);
    assert!(!on.is_empty());
    let on_gcode_path = |p: Pt| {
        marks.iter().any(|m| {
            m.windows(2)
                .any(|w| point_segment_dist(p, w[0], w[1]) < 1e-3)
        })
    };
    // every laser-on sample lies on a G-code mark ...
    assert!(on.iter().all(|&p| on_gcode_path(p)));
    // ... and every G-code mark's ends are laser-on samples
    for m in &marks {
        for end in [m[0], m[m.len() - 1]] {
            // the G-code rounds to 4 decimals
            assert!(on.iter().any(|p| p.dist(end) < 1e-4), "{end:?} not sampled");
        }
    }
}

fn job_time(doc: &Document, plan: &Plan) -> f64 {
    let toolpath: Toolpath = lower_plan(doc, plan).unwrap();
    assert_eq!(plan.metrics.job_time_s, Some(toolpath.duration_s()));
    let b = plan.metrics.job_time_breakdown_s.unwrap();
    assert!((b.total() - toolpath.duration_s()).abs() < 1e-9);
    toolpath.duration_s()
}

#[test]
fn time_cost_is_never_slower_than_distance_and_as_is_is_slowest() {
    for example in ["demo.svg", "oversize.svg"] {
        let settings = |algo, cost_model| SolverSettings {
            algo,
            cost_model,
            split_oversize: true,
            ..step_settings()
        };
        let time = |algo, cost| {
            let (doc, plan) =
                plan_example(example, MachineProfile::default(), settings(algo, cost));
            job_time(&doc, &plan)
        };
        let by_time = time(Algo::Hha, CostModel::Time);
        let by_distance = time(Algo::Hha, CostModel::Distance);
        let as_is = time(Algo::AsIs, CostModel::Time);
        assert!(
            by_time <= by_distance,
            "{example}: {by_time} > {by_distance}"
        );
        assert!(as_is > by_time, "{example}: as-is {as_is} vs {by_time}");
    }
}

/// On the fly no time search follows HHA (it runs for step-and-scan only), so HHA's own search
/// must not be cut short there as it is for a lone step-and-scan field: oversize.svg on the fly
/// is one region, and its plan under the default cost is no slower than under distance (it was
/// 8.12 s against 7.84 s when HHA only descended).
#[test]
fn on_the_fly_keeps_hhas_search_on_a_lone_region() {
    let time = |cost_model| {
        let settings = SolverSettings {
            motion: galvoplan::document::MotionMode::OnTheFly,
            cost_model,
            ..SolverSettings::default()
        };
        let (doc, plan) = plan_example("oversize.svg", MachineProfile::default(), settings);
        job_time(&doc, &plan)
    };
    let (by_time, by_distance) = (time(CostModel::Time), time(CostModel::Distance));
    assert!(by_time <= by_distance + 1e-9, "{by_time} > {by_distance}");
}

#[test]
fn time_cost_orders_fields_on_stage_time() {
    // slow y axis: moving along y costs ten times more than along x, so the time plan visits the
    // fields row by row where a distance plan does not care
    let mut profile = MachineProfile::default();
    profile.axis_y.max_velocity_mm_s = 50.0;
    profile.axis_y.max_accel_mm_s2 = 500.0;
    let run = |cost_model| {
        let settings = SolverSettings {
            cost_model,
            ..step_settings()
        };
        let (doc, plan) = plan_example("demo.svg", profile.clone(), settings);
        (lower_plan(&doc, &plan).unwrap().breakdown().stage, plan)
    };
    let (stage_time, plan_t) = run(CostModel::Time);
    let (stage_distance, plan_d) = run(CostModel::Distance);
    assert!(
        stage_time < stage_distance,
        "{stage_time} vs {stage_distance}"
    );
    assert_ne!(
        plan_t.fields.iter().map(|f| f.id).collect::<Vec<_>>(),
        plan_d.fields.iter().map(|f| f.id).collect::<Vec<_>>()
    );
}

#[test]
fn version_1_profiles_upgrade() {
    let path = common::root().join("tests/data/profiles/v1-seed000.toml");
    let old = MachineProfile::load(path.to_str().unwrap()).unwrap();
    let current = MachineProfile::builtin("seed000").unwrap();
    assert_eq!(old, current);
    assert_eq!(old.version, galvoplan::document::PROFILE_VERSION);
    assert_eq!(old.axis_x.settle_s, 0.0);
    assert_eq!(old.gcode.mode, GcodeMode::Tcp);
}

#[test]
fn profile_errors_name_the_value() {
    let both = "version = 2\n[axis_x]\nmax_accel_mm_s2 = 100.0\nramp_s = 0.2\n";
    let e = MachineProfile::from_toml(both, "p.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("p.toml") && e.contains("not both"), "{e}");
    let bad_ramp = "version = 2\n[axis_y]\nramp_s = 0.0\n";
    let e = MachineProfile::from_toml(bad_ramp, "p.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("ramp_s"), "{e}");
    let settle = "version = 2\n[axis_y]\nsettle_s = -1.0\n";
    let e = MachineProfile::from_toml(settle, "p.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("axis_y.settle_s"), "{e}");
    let axes = "version = 2\n[gcode]\nmode = \"stage-scanner\"\nscanner_axes = [\"X\", \"V\"]\n";
    let e = MachineProfile::from_toml(axes, "p.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("scanner_axes"), "{e}");
}

/// A 260 mm serpentine (far larger than the 70 mm field) and a few small squares.
fn serpentine_document() -> Document {
    use galvoplan::document::{Geometry, Source};
    let mut points = Vec::new();
    for row in 0..6 {
        let y = 20.0 + row as f64 * 12.0;
        let (a, b) = if row % 2 == 0 {
            (20.0, 280.0)
        } else {
            (280.0, 20.0)
        };
        points.push(Pt::new(a, y));
        points.push(Pt::new(b, y));
    }
    let mut geometries = vec![Geometry::new(points, false, Source::default())];
    for k in 0..5 {
        let (x, y) = (40.0 + 50.0 * k as f64, 200.0 + 15.0 * (k % 2) as f64);
        let sq = vec![
            Pt::new(x, y),
            Pt::new(x + 4.0, y),
            Pt::new(x + 4.0, y + 4.0),
            Pt::new(x, y + 4.0),
        ];
        geometries.push(Geometry::new(sq, true, Source::default()));
    }
    let mut doc = Document {
        geometries,
        page_mm: [300.0, 300.0],
        ..Document::default()
    };
    doc.settings.motion = galvoplan::document::MotionMode::OnTheFly;
    doc.profile.otf_margin_mm = 5.0;
    doc
}

#[test]
fn on_the_fly_keeps_the_scanner_in_reach_and_the_stage_within_its_limits() {
    let mut doc = serpentine_document();
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    let period_s = 1e-3;
    let path = galvoplan::pipeline::lower_plan_on(&doc, &plan, Some(period_s)).unwrap();
    assert!(path.route.is_some());
    let p = &doc.profile;
    let reach_mm = p.field_mm[0] / 2.0 - p.otf_margin_mm;
    let n = (path.duration_s() / period_s).ceil() as usize;
    let states: Vec<_> = (0..=n)
        .map(|k| path.state_at(k as f64 * period_s))
        .collect();
    // the stage starts at rest: in the first tick it moves no more than from rest at full
    // acceleration, `a·Δt²/2`
    let from_rest_mm = |a: f64| a * period_s * period_s / 2.0 * (1.0 + 1e-6);
    let first = states[1].stage.minus(states[0].stage);
    assert!(
        first.x.abs() <= from_rest_mm(p.axis_x.max_accel_mm_s2),
        "{first:?}"
    );
    assert!(
        first.y.abs() <= from_rest_mm(p.axis_y.max_accel_mm_s2),
        "{first:?}"
    );
    let moved_mm = assert_on_the_fly_feasible(&doc, &path);
    // the stage really follows the work: the serpentine spans 260 mm in x
    assert!(moved_mm > 500.0, "{moved_mm}");
    // the plan's motion figures describe the same route
    let figures = path.motion_figures(period_s);
    // (the loop above stops one sample short: at most one sample of stage travel)
    let last_step_mm = p.axis_x.max_velocity_mm_s.hypot(p.axis_y.max_velocity_mm_s) * period_s;
    assert!((figures.stage_route_mm - moved_mm).abs() <= last_step_mm + 1e-9);
    assert!(
        figures.scan_peak_offset_mm <= reach_mm + 1e-6
            && figures.scan_peak_offset_mm > 0.5 * reach_mm
    );
    let peak = p.axis_x.max_velocity_mm_s.hypot(p.axis_y.max_velocity_mm_s);
    assert!(
        figures.stage_peak_speed_mm_s > 0.0 && figures.stage_peak_speed_mm_s <= peak * (1.0 + 1e-6)
    );
    assert!(plan
        .metrics
        .motion
        .is_some_and(|m| m.stage_route_mm > 500.0));
    // on the clock, the serpentine's two ends are laser-on samples, and every corner lies
    // within half a tick of marking of one
    let on: Vec<Pt> = states.iter().filter(|m| m.laser).map(|m| m.tcp()).collect();
    let serpentine = &doc.geometries[0].points;
    for end in [serpentine[0], serpentine[serpentine.len() - 1]] {
        assert!(on.iter().any(|q| q.dist(end) < 1e-6), "{end:?}");
    }
    let half_tick_mm = p.scanner.mark_speed_mm_s * period_s / 2.0;
    for corner in serpentine {
        assert!(
            on.iter().any(|q| q.dist(*corner) <= half_tick_mm + 1e-9),
            "{corner:?}"
        );
    }
    // no stage-scanner G-code on the fly, a clear error instead
    let mut split = plan.clone();
    split.profile.gcode.mode = GcodeMode::StageScanner;
    let e = write_gcode(&path, &split, 300.0, "t").unwrap_err();
    assert!(e.to_string().contains("step-and-scan"), "{e}");
    assert!(write_gcode(&path, &plan, 300.0, "t").is_ok());
}

#[test]
fn on_the_fly_margin_must_leave_reach() {
    let text = "version = 2\nfield_mm = [70.0, 70.0]\notf_margin_mm = 35.0\n";
    let e = MachineProfile::from_toml(text, "p.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("otf_margin_mm") && e.contains("half the field"),
        "{e}"
    );
}

#[test]
fn on_the_fly_lowering_stops_on_a_cancel() {
    use galvoplan::job::{CancelToken, NoProgress};
    use galvoplan::motion::{lower_on_the_fly, OtfError};
    let mut doc = serpentine_document();
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    let token = CancelToken::new();
    token.cancel();
    let ctx = JobCtx::new(token, std::sync::Arc::new(NoProgress));
    let e = lower_on_the_fly(&doc.geometries, &plan, &doc.profile, None, &ctx).unwrap_err();
    assert!(matches!(e, OtfError::Cancelled(_)), "{e}");
    assert!(lower_on_the_fly(
        &doc.geometries,
        &plan,
        &doc.profile,
        None,
        &JobCtx::default()
    )
    .is_ok());
}

/// Samples `path` every millisecond and checks the on-the-fly invariants: scanner offset in
/// reach, stage in its stroke within its speed and acceleration limits, marks no faster than
/// the mark speed. Returns the stage's route length, mm (the last sample's step excluded).
fn assert_on_the_fly_feasible(doc: &Document, path: &galvoplan::motion::Toolpath) -> f64 {
    let period_s = 1e-3;
    let p = &doc.profile;
    let reach_mm = p.field_mm[0] / 2.0 - p.otf_margin_mm;
    let n = (path.duration_s() / period_s).ceil() as usize;
    let states: Vec<_> = (0..=n)
        .map(|k| path.state_at(k as f64 * period_s))
        .collect();
    let axis = |q: Pt, k: usize| if k == 0 { q.x } else { q.y };
    let limits = [&p.axis_x, &p.axis_y];
    let mut route_mm = 0.0;
    for (j, w) in states.windows(3).enumerate() {
        let o = w[0].scan;
        assert!(
            o.x.abs() <= reach_mm + 1e-6 && o.y.abs() <= reach_mm + 1e-6,
            "{o:?} at {j}"
        );
        for (k, lim) in limits.iter().enumerate() {
            let s = w.iter().map(|m| axis(m.stage, k)).collect::<Vec<_>>();
            assert!((0.0..=p.stroke_mm[k]).contains(&s[0]));
            let v = (s[1] - s[0]) / period_s;
            let a = (s[2] - 2.0 * s[1] + s[0]) / (period_s * period_s);
            assert!(
                v.abs() <= lim.max_velocity_mm_s * (1.0 + 1e-6),
                "{v} at {j}"
            );
            assert!(a.abs() <= lim.max_accel_mm_s2 * 1.001, "{a} at {j}");
        }
        if w[0].laser && w[1].laser {
            let speed = w[1].tcp().dist(w[0].tcp()) / period_s;
            assert!(speed <= p.scanner.mark_speed_mm_s * (1.0 + 1e-6), "{speed}");
        }
        route_mm += w[1].stage.dist(w[0].stage);
    }
    route_mm
}

/// The serpentine planned on the fly with stage route `kind` (a small GA for `cetsp-ga`).
fn plan_with_route(kind: galvoplan::document::StageRouteKind) -> (Document, Plan) {
    let mut doc = serpentine_document();
    doc.settings.stage_route = kind;
    doc.settings.route_ga.population = 12;
    doc.settings.route_ga.generations = 15;
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    (doc, plan)
}

#[test]
fn seed001_routes_are_followed_and_the_taut_string_is_never_longer() {
    use galvoplan::document::StageRouteKind;
    let mut lengths = Vec::new();
    for kind in [
        StageRouteKind::Taut,
        StageRouteKind::Lsa,
        StageRouteKind::CetspGa,
    ] {
        let (doc, plan) = plan_with_route(kind);
        assert_eq!(plan.stage_route.is_some(), kind != StageRouteKind::Taut);
        let path = galvoplan::pipeline::lower_plan(&doc, &plan).unwrap();
        let route_mm = assert_on_the_fly_feasible(&doc, &path);
        if let Some(route) = &plan.stage_route {
            // the stage follows the paper's route: its length is about the polyline's
            let polyline_mm = route.length_mm();
            assert!(
                (route_mm - polyline_mm).abs() <= 0.15 * polyline_mm,
                "{kind:?}: {route_mm} vs {polyline_mm}"
            );
        }
        lengths.push(route_mm);
    }
    assert!(lengths[0] <= lengths[1], "taut {lengths:?}");
    assert!(lengths[0] <= lengths[2], "taut {lengths:?}");
}

#[test]
fn the_route_ga_is_deterministic_and_its_settings_are_checked() {
    use galvoplan::document::StageRouteKind;
    let (_, a) = plan_with_route(StageRouteKind::CetspGa);
    let (_, b) = plan_with_route(StageRouteKind::CetspGa);
    assert_eq!(a.stage_route, b.stage_route);
    let mut doc = serpentine_document();
    doc.settings.stage_route = StageRouteKind::CetspGa;
    doc.settings.route_ga.mutation_rate = 1.5;
    let e = plan_document(&mut doc, &JobCtx::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("mutation"), "{e}");
    // a different seed, another route (the GA is random but seeded)
    let mut doc = serpentine_document();
    doc.settings.stage_route = StageRouteKind::CetspGa;
    doc.settings.route_ga.population = 12;
    doc.settings.route_ga.generations = 15;
    doc.settings.seed = 7;
    let c = plan_document(&mut doc, &JobCtx::default()).unwrap();
    assert!(c.stage_route.is_some());
}

/// The tool's own time for `plan`: marks at mark speed, jumps at jump speed, the delays (what
/// on the fly costs when the stage keeps up everywhere).
fn tool_time_s(doc: &Document, plan: &Plan) -> f64 {
    let (laser, scanner) = (&doc.profile.laser, &doc.profile.scanner);
    let mut last: Option<Pt> = None;
    let mut t_s = 0.0;
    for step in &plan.order {
        let g = &doc.geometries[step.geometry];
        let pts = g.marking_path(step.start_vertex, step.reversed);
        if let Some(from) = last {
            t_s += from.dist(pts[0]) / scanner.jump_speed_mm_s + laser.jump_delay_s;
        }
        let length_mm: f64 = pts.windows(2).map(|w| w[0].dist(w[1])).sum();
        t_s += laser.on_delay_s + length_mm / scanner.mark_speed_mm_s + laser.off_delay_s;
        last = pts.last().copied();
    }
    t_s
}

/// A row of 4 mm squares every 5 mm across the stroke: the tool advances at under 300 mm/s,
/// which the seed000 stage (500 mm/s, 5,000 mm/s²) follows within its 35 mm reach.
fn square_row(pitch_mm: f64) -> Document {
    let geometries = (0..)
        .map(|k| 20.0 + pitch_mm * k as f64)
        .take_while(|&x| x <= 276.0)
        .map(|x| {
            let pts = vec![
                Pt::new(x, 150.0),
                Pt::new(x + 4.0, 150.0),
                Pt::new(x + 4.0, 154.0),
                Pt::new(x, 154.0),
            ];
            galvoplan::document::Geometry::new(pts, true, galvoplan::document::Source::default())
        })
        .collect();
    let mut doc = Document {
        geometries,
        page_mm: [300.0, 300.0],
        ..Document::default()
    };
    doc.settings.motion = galvoplan::document::MotionMode::OnTheFly;
    doc
}

#[test]
fn on_the_fly_slows_nothing_the_stage_can_follow() {
    // the stage keeps up everywhere: the job takes exactly the tool's own time
    let mut doc = square_row(5.0);
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    let path = lower_plan(&doc, &plan).unwrap();
    assert!(path.route.is_some());
    let tool_s = tool_time_s(&doc, &plan);
    assert!(
        (path.duration_s() - tool_s).abs() <= 1e-9 * tool_s,
        "{} against {tool_s}",
        path.duration_s()
    );
    let clocked = galvoplan::pipeline::lower_plan_on(&doc, &plan, Some(1e-3)).unwrap();
    assert_on_the_fly_feasible(&doc, &clocked);
    // squares every 40 mm: the tool would outrun the stage, so it is slowed, and only so much
    // that the stage still keeps it in reach
    let mut doc = square_row(40.0);
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    let path = lower_plan(&doc, &plan).unwrap();
    assert!(path.duration_s() > tool_time_s(&doc, &plan) * 1.01);
    let clocked = galvoplan::pipeline::lower_plan_on(&doc, &plan, Some(1e-3)).unwrap();
    assert_on_the_fly_feasible(&doc, &clocked);
}

/// Seed 002's slow axes with a 4 mm field (the shared benchmarks' texture machine): a 2 mm
/// reach, 218 mm/s, about 900 mm/s².
const SMALL_REACH_PROFILE: &str = r#"
version = 1
name = "small reach"
stroke_mm = [300.0, 300.0]
field_mm = [4.0, 4.0]
[axis_x]
max_velocity_mm_s = 218.0
max_accel_mm_s2 = 912.1
[axis_y]
max_velocity_mm_s = 218.0
max_accel_mm_s2 = 886.2
[scanner]
jump_speed_mm_s = 2000.0
mark_speed_mm_s = 500.0
[laser]
on_delay_s = 0.0001
off_delay_s = 0.0001
jump_delay_s = 0.0002
"#;

/// Cells of three concentric circles (r 0.5, 1 and 1.5 mm) on a hexagonal grid of 5 mm pitch
/// inside a disc of `radius_mm`, each cell alone in a 4 mm field (the texture benchmark's
/// pattern, smaller).
fn texture_cells(radius_mm: f64) -> Document {
    let (c, dy) = (150.0, 5.0 * 3f64.sqrt() / 2.0);
    let mut geometries = Vec::new();
    for row in -10i32..=10 {
        let y = c + row as f64 * dy;
        for col in -10i32..=10 {
            let x = c + col as f64 * 5.0 + if row % 2 != 0 { 2.5 } else { 0.0 };
            if (x - c).hypot(y - c) > radius_mm {
                continue;
            }
            for r in [0.5, 1.0, 1.5] {
                let pts = (0..48)
                    .map(|k| {
                        let a = k as f64 * std::f64::consts::TAU / 48.0;
                        Pt::new(x + r * a.cos(), y + r * a.sin())
                    })
                    .collect();
                geometries.push(galvoplan::document::Geometry::new(
                    pts,
                    true,
                    galvoplan::document::Source::default(),
                ));
            }
        }
    }
    Document {
        geometries,
        page_mm: [300.0, 300.0],
        profile: MachineProfile::from_toml(SMALL_REACH_PROFILE, "small reach").unwrap(),
        ..Document::default()
    }
}

#[test]
fn on_the_fly_beats_step_and_scan_in_a_small_reach() {
    // marking a cell needs the stage within 0.5 mm of its centre, so the scanner must wait
    // for the stage at every cell: the waits go on the jumps just before (the wait-first
    // rule); slowing whole windows of the tool added more than the tool's own time and ended
    // on the taut route, slower than step-and-scan (texture.toml: 598 s against 539 s)
    let mut doc = texture_cells(16.0);
    assert!(doc.geometries.len() >= 60);
    doc.settings.motion = galvoplan::document::MotionMode::Step;
    let step = plan_document(&mut doc, &JobCtx::default()).unwrap();
    let step_s = lower_plan(&doc, &step).unwrap().duration_s();
    doc.settings.motion = galvoplan::document::MotionMode::OnTheFly;
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    let path = lower_plan(&doc, &plan).unwrap();
    assert!(
        path.duration_s() < 0.75 * step_s,
        "on the fly {} s against step-and-scan {step_s} s",
        path.duration_s()
    );
    // on the controller clock (a laser-off tick between marks: sampled every millisecond, the
    // unclocked job's jumps between a cell's circles, 0.65 ms, would fall between samples)
    let clocked = galvoplan::pipeline::lower_plan_on(&doc, &plan, Some(1e-3)).unwrap();
    assert_on_the_fly_feasible(&doc, &clocked);
}

#[test]
fn on_the_fly_marks_a_cell_with_the_stage_centred_for_its_outer_ring() {
    // each cell's rings need the stage within 1.5, 1 and 0.5 mm of its centre: the outer ring
    // goes in the middle, while the stage stands nearest; the middle ring first, as it
    // arrives; the inner ring last, as it leaves (1.0 / 1.5 / 0.5 mm: a shorter job than the
    // distance ordering's, which marks the outer ring first or last)
    let mut doc = texture_cells(16.0);
    doc.settings.motion = galvoplan::document::MotionMode::OnTheFly;
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    let radius = |g: usize| {
        let b = doc.geometries[g].bbox();
        ((b.max_x - b.min_x) / 2.0 * 2.0).round() / 2.0
    };
    let cells: Vec<Vec<f64>> = plan
        .order
        .chunk_by(|a, b| a.field == b.field)
        .map(|run| run.iter().map(|s| radius(s.geometry)).collect())
        .collect();
    assert!(cells.len() >= 20);
    for rings in &cells {
        assert_eq!(rings, &vec![1.0, 1.5, 0.5], "rings in marking order");
    }
    let clocked = galvoplan::pipeline::lower_plan_on(&doc, &plan, Some(1e-3)).unwrap();
    assert_on_the_fly_feasible(&doc, &clocked);
}

#[test]
fn a_mixed_job_holds_the_stage_still_while_its_step_and_scan_fields_are_marked() {
    // demo.svg on the fly, with every other field of its order (those whose strokes one stage
    // position reaches) marked step-and-scan (issue 26 item 3)
    let settings = SolverSettings {
        motion: galvoplan::document::MotionMode::OnTheFly,
        ..SolverSettings::default()
    };
    let (doc, mut plan) = plan_example("demo.svg", MachineProfile::default(), settings);
    let reach_mm = galvoplan::motion::still_reach_mm(&plan.profile).unwrap();
    let fits = |field: usize| {
        let boxes = plan.order.iter().filter(|s| s.field == field);
        let (lo, hi) = boxes.fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), s| {
            let b = doc.geometries[s.geometry].bbox();
            (
                [lo[0].min(b.min_x), lo[1].min(b.min_y)],
                [hi[0].max(b.max_x), hi[1].max(b.max_y)],
            )
        });
        hi[0] - lo[0] < 1.9 * reach_mm && hi[1] - lo[1] < 1.9 * reach_mm
    };
    let chosen: Vec<usize> = plan
        .fields
        .iter()
        .map(|f| f.id)
        .filter(|&f| fits(f))
        .step_by(2)
        .collect();
    assert!(chosen.len() >= 2, "{chosen:?}");
    let flying = lower_plan(&doc, &plan).unwrap();
    plan.step_fields = chosen.clone();
    let path = lower_plan(&doc, &plan).unwrap();
    assert_eq!(path.strokes.len(), flying.strokes.len());
    let mut sorted = chosen.clone();
    sorted.sort_unstable();
    assert_eq!(
        path.still_fields, sorted,
        "the toolpath names its still fields"
    );
    assert!(flying.still_fields.is_empty());
    let regions = path.motion_regions();
    let still: Vec<_> = regions
        .iter()
        .filter(|r| r.motion == galvoplan::document::Motion::Step)
        .collect();
    assert!(still.len() >= chosen.len(), "{regions:?}");
    assert!(regions
        .iter()
        .any(|r| r.motion == galvoplan::document::Motion::OnTheFly));
    assert!((regions.last().unwrap().end_s - path.duration_s()).abs() < 1e-9);
    // the step rule in every step-and-scan stretch: the stage does not move while the laser is
    // on (sampled every 0.1 ms, strictly inside: the region starts where the mark before it
    // ends, and that instant belongs to the mark)
    let mut samples_on = 0;
    for r in &still {
        let mut at: Option<Pt> = None;
        let n = ((r.end_s - r.start_s) / 1e-4).ceil() as usize;
        for k in 0..n {
            let m = path.state_at(r.start_s + (k as f64 + 0.5) * (r.end_s - r.start_s) / n as f64);
            if !m.laser {
                continue;
            }
            samples_on += 1;
            let first = *at.get_or_insert(m.stage);
            assert!(
                m.stage.dist(first) < 1e-6,
                "field {:?}: the stage moved {} mm while marking",
                r.fields,
                m.stage.dist(first)
            );
        }
    }
    assert!(samples_on > 100);
    // the jumps into and out of them are the scanner's own, at most at jump speed
    for seg in &path.segments {
        if let galvoplan::motion::ScanMotion::Line { from, to, move_s } = seg.scan {
            let speed = from.dist(to) / move_s;
            assert!(
                speed <= plan.profile.scanner.jump_speed_mm_s * (1.0 + 1e-5),
                "{speed}"
            );
        }
    }
    // every on-the-fly limit on the controller clock (sampled every millisecond, the
    // unclocked job's short jumps between marks would fall between samples); the trajectory
    // is left in the temp folder for
    // ../shared/tools/check_trajectory.py (demo.svg, assets/profiles/seed000.toml, --mode otf)
    let clocked = galvoplan::pipeline::lower_plan_on(&doc, &plan, Some(1e-3)).unwrap();
    assert_on_the_fly_feasible(&doc, &clocked);
    let csv = trajectory_csv(&clocked, 1e-3, &[]);
    assert!(csv.starts_with(TRAJECTORY_HEADER));
    std::fs::write(std::env::temp_dir().join("galvoplan-mixed-demo.csv"), csv).unwrap();
    // the G-code says how each field runs
    let gcode = write_gcode(&path, &plan, doc.page_mm[1], "t").unwrap();
    let step_comments = gcode
        .lines()
        .filter(|l| l.ends_with("step-and-scan (the stage at rest)"));
    assert!(step_comments.count() >= chosen.len());
    assert!(gcode
        .lines()
        .any(|l| l.starts_with("; field") && l.ends_with(", on the fly")));
}

/// Every progress message of a solve, and a cancel sent when one of them contains `cancel_at`.
struct Watch {
    seen: std::sync::Mutex<Vec<galvoplan::job::Progress>>,
    cancel_at: Option<(&'static str, galvoplan::job::CancelToken)>,
}

impl galvoplan::job::ProgressSink for Watch {
    fn report(&self, p: &galvoplan::job::Progress) {
        if let Some((at, token)) = &self.cancel_at {
            if p.message.contains(at) {
                token.cancel();
            }
        }
        self.seen.lock().unwrap().push(p.clone());
    }
}

/// The oversize example on the fly: several candidate plans (fields, bands, rings centred).
fn solve_watched(
    cancel_at: Option<&'static str>,
) -> (
    Result<Plan, galvoplan::pipeline::PipelineError>,
    Vec<galvoplan::job::Progress>,
) {
    let path = common::root().join("assets/examples/oversize.svg");
    let settings = SolverSettings {
        motion: galvoplan::document::MotionMode::OnTheFly,
        ..SolverSettings::default()
    };
    let profile = MachineProfile::default();
    let (mut doc, _) = load_svg(&path, profile, settings, &ImportOptions::default()).unwrap();
    let token = galvoplan::job::CancelToken::new();
    let watch = std::sync::Arc::new(Watch {
        seen: std::sync::Mutex::new(Vec::new()),
        cancel_at: cancel_at.map(|at| (at, token.clone())),
    });
    let ctx = JobCtx::new(token, watch.clone());
    let plan = plan_document(&mut doc, &ctx);
    let seen = watch.seen.lock().unwrap().clone();
    (plan, seen)
}

#[test]
fn an_on_the_fly_solve_reports_every_candidate_and_never_says_done_early() {
    let (plan, seen) = solve_watched(None);
    plan.unwrap();
    let words: Vec<&str> = seen.iter().map(|p| p.message.as_str()).collect();
    assert!(
        words.iter().all(|w| !w.to_lowercase().contains("done")),
        "{words:?}"
    );
    // each solve side by side (marked whole, cut) says which it is, and counts its candidates
    // up to all of them, after its ordering
    let mut labels: Vec<&str> = words
        .iter()
        .filter(|w| w.contains("on-the-fly candidate plan"))
        .filter_map(|w| w.split_once(": ").map(|(label, _)| label))
        .collect();
    labels.sort_unstable();
    labels.dedup();
    assert!(labels.len() >= 2, "{words:?}");
    for label in labels {
        let own: Vec<_> = seen
            .iter()
            .filter(|p| p.message.starts_with(&format!("{label}: ")))
            .collect();
        let motion: Vec<_> = own.iter().filter(|p| p.stage == "motion").collect();
        let (first, last) = (motion[0], motion[motion.len() - 1]);
        assert_eq!(first.done, 0, "{label}: {words:?}");
        assert!(first.total >= 2, "several candidates: {words:?}");
        assert_eq!(last.done, last.total, "{label}: {words:?}");
        let order_last = own.iter().rposition(|p| p.stage == "order").unwrap();
        let motion_first = own.iter().position(|p| p.stage == "motion").unwrap();
        assert!(order_last < motion_first, "{label}: {words:?}");
        assert!(
            motion.windows(2).all(|w| w[0].done <= w[1].done),
            "{words:?}"
        );
    }
}

#[test]
fn a_cancel_among_the_candidates_keeps_the_fastest_finished() {
    let (whole, _) = solve_watched(None);
    let whole_s = whole.unwrap().metrics.job_time_s.unwrap();
    let (plan, seen) = solve_watched(Some("1 of"));
    let plan = plan.expect("a cancel after the first candidate keeps it");
    let kept_s = plan.metrics.job_time_s.unwrap();
    assert!(kept_s >= whole_s - 1e-9, "{kept_s} vs {whole_s}");
    let words: Vec<&str> = seen.iter().map(|p| p.message.as_str()).collect();
    assert!(
        words
            .iter()
            .any(|w| w.contains("Stopping: keeping the fastest of the")),
        "{words:?}"
    );
    // a cancel before any candidate finished still ends with the first one made
    let (plan, seen) = solve_watched(Some("0 of"));
    plan.expect("the algorithm's ordering is lowered to the end");
    let words: Vec<&str> = seen.iter().map(|p| p.message.as_str()).collect();
    assert!(words.iter().any(|w| w.contains("Stopping")), "{words:?}");
}
