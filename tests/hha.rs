//! HHA end to end: the brick wall of seed 000 Fig. 2, determinism, checked plans.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::document::{Document, Geometry, MachineProfile, SolverSettings, Source};
use galvoplan::geom::Pt;
use galvoplan::job::JobCtx;
use galvoplan::pipeline::plan_document;

fn rect(x: f64, y: f64, w: f64, h: f64) -> Geometry {
    let pts = vec![
        Pt::new(x, y),
        Pt::new(x + w, y),
        Pt::new(x + w, y + h),
        Pt::new(x, y + h),
    ];
    Geometry::new(pts, true, Source::default())
}

/// Rows of bricks (16 × 7 mm, offset every other row) across 250 mm: several fields wide.
fn brick_wall_rows(rows: usize) -> Document {
    let mut geometries = Vec::new();
    for row in 0..rows {
        let off = if row % 2 == 0 { 0.0 } else { 9.0 };
        let mut x = 20.0 + off;
        while x + 16.0 <= 270.0 {
            geometries.push(rect(x, 20.0 + row as f64 * 9.0, 16.0, 7.0));
            x += 18.0;
        }
    }
    let mut doc = Document {
        geometries,
        page_mm: [300.0, 300.0],
        ..Document::default()
    };
    // seed 000's objectives (idle travel, direction changes) are what these tests check
    doc.settings.cost_model = galvoplan::document::CostModel::Distance;
    doc
}

fn plan_wall(rows: usize, improve: bool) -> (Document, galvoplan::document::Plan) {
    let mut doc = brick_wall_rows(rows);
    doc.settings.hha_improve = improve;
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    common::check_plan(&doc, &plan);
    (doc, plan)
}

#[test]
fn brick_wall_is_swept_field_by_field_in_one_direction() {
    for rows in [2, 3, 4] {
        let (_, plan) = plan_wall(rows, true);
        // the fields are visited left to right along the wall
        let xs: Vec<f64> = plan.fields.iter().map(|f| f.center.x).collect();
        assert!(plan.fields.len() >= 4, "{} fields", plan.fields.len());
        assert!(
            xs.windows(2).all(|w| w[1] > w[0]),
            "fields not swept in one direction: {xs:?}"
        );
        let (_, seed) = plan_wall(rows, false);
        let m = &plan.metrics;
        // no more turns than the seed's HHA, with less idle travel
        assert!(
            m.direction_changes <= seed.metrics.direction_changes,
            "{rows} rows: {} vs seed {}",
            m.direction_changes,
            seed.metrics.direction_changes
        );
        assert!(
            m.idle_mm < seed.metrics.idle_mm,
            "{rows} rows: {} vs seed {}",
            m.idle_mm,
            seed.metrics.idle_mm
        );
        // and far fewer than a nearest-neighbour order
        let mut base = brick_wall_rows(rows);
        base.settings.algo = galvoplan::document::Algo::Baseline;
        let b = plan_document(&mut base, &JobCtx::default()).unwrap();
        assert!(
            m.direction_changes <= b.metrics.direction_changes,
            "{rows} rows: {} vs baseline {}",
            m.direction_changes,
            b.metrics.direction_changes
        );
    }
    // two rows: one steady sweep, not a single turn
    assert_eq!(plan_wall(2, true).1.metrics.direction_changes, 0);
    assert!(plan_wall(3, true).1.metrics.direction_changes <= 4);
}

#[test]
fn hha_is_deterministic_and_beats_the_seed_variant_on_the_demo() {
    let path = common::root().join("assets/examples/demo.svg");
    let run = |improve: bool, vertex: galvoplan::document::VertexMode| {
        // on idle travel: under the time objective the plan is re-searched for job time, and
        // idle travel is free to rise (docs/BENCHMARKS.md)
        let settings = SolverSettings {
            hha_improve: improve,
            vertex,
            cost_model: galvoplan::document::CostModel::Distance,
            ..SolverSettings::default()
        };
        let (mut doc, _) = galvoplan::pipeline::load_svg(
            &path,
            MachineProfile::default(),
            settings,
            &Default::default(),
        )
        .unwrap();
        let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
        common::check_plan(&doc, &plan);
        plan
    };
    use galvoplan::document::VertexMode::{Exact, Vea};
    let a = run(true, Exact);
    let b = run(true, Exact);
    assert_eq!(a.order, b.order, "same input and seed, same plan");
    let seed_hha = run(false, Vea);
    let exact_only = run(false, Exact);
    assert!(
        exact_only.metrics.idle_mm <= seed_hha.metrics.idle_mm + 1e-9,
        "exact vertices never lose to VEA"
    );
    assert!(
        a.metrics.idle_mm < seed_hha.metrics.idle_mm,
        "{} vs seed {}",
        a.metrics.idle_mm,
        seed_hha.metrics.idle_mm
    );
}
