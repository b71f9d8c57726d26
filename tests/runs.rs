//! Runs (issue 24): strokes whose order a fill fixes are planned as one node each, and the plan
//! loses nothing against planning them stroke by stroke; large jobs near their marking floor
//! are not planned on the fly.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::document::{
    Document, Geometry, HatchSettings, HatchStyle, MachineProfile, Motion, MotionMode, Plan,
    RunOrder, SolverSettings,
};
use galvoplan::import::ImportOptions;
use galvoplan::job::JobCtx;
use galvoplan::order::objective::marking_floor_s;
use galvoplan::pipeline::{load_svg, plan_document};
use std::collections::HashMap;

/// A grid of `n` × `n` discs of radius `r_mm`, 14.2 mm apart (the issue's circles).
fn discs_svg(dir: &std::path::Path, n: usize, r_mm: f64) -> std::path::PathBuf {
    let mut s = String::from(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">"#,
    );
    for i in 0..n {
        for j in 0..n {
            s.push_str(&format!(
                r#"<circle cx="{}" cy="{}" r="{r_mm}" fill="none" stroke="black"/>"#,
                10.0 + 14.2 * i as f64,
                10.0 + 14.2 * j as f64
            ));
        }
    }
    s.push_str("</svg>");
    let path = dir.join(format!("discs-{n}.svg"));
    std::fs::write(&path, s).unwrap();
    path
}

fn load(path: &std::path::Path, hatch: HatchSettings, motion: MotionMode) -> Document {
    let settings = SolverSettings {
        hatch: Some(hatch),
        motion,
        ..SolverSettings::default()
    };
    let (doc, _) = load_svg(
        path,
        MachineProfile::default(),
        settings,
        &ImportOptions::default(),
    )
    .unwrap();
    doc
}

/// The runs of a geometry list: key → indices.
fn runs(geometries: &[Geometry]) -> HashMap<(String, u32, String), Vec<usize>> {
    let mut out: HashMap<_, Vec<usize>> = HashMap::new();
    for (i, g) in geometries.iter().enumerate() {
        if let Some(r) = g.run {
            out.entry((g.source.element.clone(), r.id, g.layer.clone()))
                .or_default()
                .push(i);
        }
    }
    out
}

fn job_s(plan: &Plan) -> f64 {
    plan.metrics.job_time_s.unwrap()
}

#[test]
fn a_cross_fill_planned_by_runs_is_as_fast_as_stroke_by_stroke() {
    // border loops and the second family's sweeps are runs
    planned_by_runs_as_fast(HatchStyle::Cross, &[RunOrder::Loop, RunOrder::Sweep]);
}

#[test]
fn a_lines_fill_planned_by_runs_is_as_fast_as_stroke_by_stroke() {
    // a disc's lines, one chord each, are one sweep (fails without runs for `lines`)
    planned_by_runs_as_fast(HatchStyle::Lines, &[RunOrder::Sweep]);
}

/// A 2 × 2 grid of discs filled with `style`: its strokes form runs of each of `orders`, most
/// strokes are in one, each run is listed in one stretch and marked in one go, and the plan is
/// as fast as planning the same strokes one by one.
fn planned_by_runs_as_fast(style: HatchStyle, orders: &[RunOrder]) {
    let dir = tempfile::tempdir().unwrap();
    let svg = discs_svg(dir.path(), 2, 4.0);
    let hatch = HatchSettings::new(style, 0.05);
    let mut doc = load(&svg, hatch, MotionMode::Step);
    let by_runs = plan_document(&mut doc, &JobCtx::default()).unwrap();
    common::check_plan(&doc, &by_runs);
    let found = runs(&doc.geometries);
    let found_orders: Vec<RunOrder> = doc
        .geometries
        .iter()
        .filter_map(|g| g.run.map(|r| r.order))
        .collect();
    for order in orders {
        assert!(found_orders.contains(order), "{style:?}: no {order:?} run");
    }
    let in_runs: usize = found.values().map(Vec::len).sum();
    assert!(
        in_runs * 10 > doc.geometries.len() * 9,
        "{in_runs} of {} strokes in runs",
        doc.geometries.len()
    );
    let position: HashMap<usize, usize> = by_runs
        .order
        .iter()
        .enumerate()
        .map(|(k, s)| (s.geometry, k))
        .collect();
    for members in found.values() {
        assert!(members.windows(2).all(|w| w[1] == w[0] + 1));
        // one field holds each disc: a run is marked in one go
        let mut at: Vec<usize> = members.iter().map(|g| position[g]).collect();
        at.sort_unstable();
        assert!(at.windows(2).all(|w| w[1] == w[0] + 1), "{at:?}");
    }
    // the same strokes without runs, ordered one by one
    let mut loose = doc.clone();
    let geometries: Vec<Geometry> = doc
        .geometries
        .iter()
        .map(|g| g.clone().with_run(None))
        .collect();
    loose.geometries = geometries;
    loose.fields.clear();
    let by_strokes = plan_document(&mut loose, &JobCtx::default()).unwrap();
    common::check_plan(&loose, &by_strokes);
    assert_eq!(by_strokes.order.len(), by_runs.order.len());
    assert!(
        job_s(&by_runs) <= job_s(&by_strokes) * 1.005,
        "by runs {} s, stroke by stroke {} s",
        job_s(&by_runs),
        job_s(&by_strokes)
    );
}

#[test]
fn a_large_fill_near_its_floor_is_not_planned_on_the_fly() {
    let dir = tempfile::tempdir().unwrap();
    // 16 discs of 12 mm, cross at 0.01 mm: about 38,000 strokes
    let svg = discs_svg(dir.path(), 4, 6.0);
    let hatch = HatchSettings::new(HatchStyle::Cross, 0.01);
    let mut doc = load(&svg, hatch, MotionMode::Auto);
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    assert!(doc.geometries.len() > 20_000, "{}", doc.geometries.len());
    assert_eq!(plan.motion, Motion::Step);
    let detail = &plan.metrics.solve_s.order_detail;
    assert!(
        detail
            .iter()
            .any(|(k, _)| k.starts_with("on the fly: not planned")),
        "{detail:?}"
    );
    assert!(
        plan.metrics.motion_note.is_some()
            && doc.warnings.iter().any(|w| w
                .message
                .starts_with("on the fly: not planned: step-and-scan takes")),
        "{:?}",
        doc.warnings
    );
    // on the fly could gain less than 2 %: the step plan is within that of the floor
    let floor = marking_floor_s(&doc.geometries, &doc.layers, &doc.profile);
    let job = job_s(&plan);
    assert!(
        floor <= job && job - floor < 0.02 * job,
        "floor {floor} s, job {job} s"
    );
}

#[test]
fn the_marking_floor_is_below_both_motions() {
    let dir = tempfile::tempdir().unwrap();
    let svg = discs_svg(dir.path(), 2, 3.0);
    for motion in [MotionMode::Step, MotionMode::OnTheFly] {
        let hatch = HatchSettings::new(HatchStyle::Zigzag, 0.2);
        let mut doc = load(&svg, hatch, motion);
        let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
        let floor = marking_floor_s(&doc.geometries, &doc.layers, &doc.profile);
        let b = plan.metrics.job_time_breakdown_s.unwrap();
        if motion == MotionMode::Step {
            // marks at their pens' speed and the laser delays are in the floor (on the fly
            // may slow marks)
            assert!(floor >= b.mark + b.laser_delays - 1e-9, "{floor} {b:?}");
        }
        assert!(floor <= job_s(&plan) + 1e-9, "{motion:?}: {floor} {b:?}");
    }
}

#[test]
fn fills_cut_on_a_tiling_plan_by_runs_into_valid_jobs() {
    // a field smaller than the shapes: fills are cut at seams, runs split at cells
    let path = common::root().join("tests/data/hatch/apmcm-multi.svg");
    for style in [HatchStyle::Zigzag, HatchStyle::Cross, HatchStyle::Lines] {
        for angle_deg in [0.0, 30.0, 90.0] {
            let settings = SolverSettings {
                hatch: Some(HatchSettings {
                    angle_deg,
                    ..HatchSettings::new(style, 0.4)
                }),
                split_oversize: true,
                motion: MotionMode::Step,
                ..SolverSettings::default()
            };
            let profile = MachineProfile {
                field_mm: [20.0, 20.0],
                ..MachineProfile::default()
            };
            let (mut doc, _) =
                load_svg(&path, profile, settings, &ImportOptions::default()).unwrap();
            let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
            common::check_plan(&doc, &plan);
            assert!(
                doc.geometries.iter().any(|g| g.run.is_some()),
                "{style:?} at {angle_deg}°: no runs"
            );
            // each stretch of a run lies in one tiling cell: it fits a field
            let key = |g: &Geometry| g.run.map(|r| (r, g.source.element.clone(), g.pass));
            let gs = &doc.geometries;
            let mut k = 0;
            while k < gs.len() {
                let end = k + gs[k..].iter().take_while(|g| key(g) == key(&gs[k])).count();
                if key(&gs[k]).is_some() {
                    let b = gs[k..end]
                        .iter()
                        .fold(galvoplan::geom::BBox::EMPTY, |b, g| b.union(g.bbox()));
                    assert!(
                        b.width() <= 20.0 && b.height() <= 20.0,
                        "{style:?} at {angle_deg}°: run stretch {k}..{end} is {b:?}"
                    );
                }
                k = end;
            }
        }
    }
}
