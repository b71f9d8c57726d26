//! Scan-field placement: coverage invariants (property tests), locked fields, determinism,
//! oversize geometries.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::document::{
    FieldsMode, Geometry, MachineProfile, ScanField, SolverSettings, Source,
};
use galvoplan::fields::{place_fields, split_oversize, FieldError};
use galvoplan::geom::Pt;
use galvoplan::job::JobCtx;
use proptest::prelude::*;

fn rect(x: f64, y: f64, w: f64, h: f64) -> Geometry {
    let pts = vec![
        Pt::new(x, y),
        Pt::new(x + w, y),
        Pt::new(x + w, y + h),
        Pt::new(x, y + h),
    ];
    Geometry::new(pts, true, Source::default())
}

fn settings(mode: FieldsMode, seed: u64) -> SolverSettings {
    SolverSettings {
        fields: mode,
        seed,
        ..SolverSettings::default()
    }
}

/// Every geometry allocated exactly once, inside its field; centres inside the stroke.
fn assert_valid(gs: &[Geometry], fields: &[ScanField], p: &MachineProfile) {
    let mut count = vec![0; gs.len()];
    for f in fields {
        assert!(
            f.center.x >= 0.0
                && f.center.x <= p.stroke_mm[0]
                && f.center.y >= 0.0
                && f.center.y <= p.stroke_mm[1]
        );
        for &g in &f.geometries {
            count[g] += 1;
            assert!(
                f.bbox().contains_box(&gs[g].bbox(), 1e-6),
                "geometry {g} outside field {}",
                f.id
            );
        }
    }
    assert!(count.iter().all(|&c| c == 1), "allocation counts {count:?}");
}

fn geometry_set() -> impl Strategy<Value = Vec<Geometry>> {
    proptest::collection::vec(
        (-30.0f64..320.0, -30.0f64..320.0, 0.1f64..60.0, 0.1f64..60.0),
        1..60,
    )
    .prop_map(|v| {
        v.into_iter()
            .map(|(x, y, w, h)| rect(x.min(330.0 - w), y.min(330.0 - h), w, h))
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn every_mode_covers_every_geometry(gs in geometry_set(), seed in 0u64..1000) {
        let p = MachineProfile::default();
        for mode in [FieldsMode::Greedy, FieldsMode::Auto, FieldsMode::Paper] {
            let placed = place_fields(&gs, &p, &settings(mode, seed), &[], &JobCtx::default()).unwrap();
            assert_valid(&gs, &placed.fields, &p);
            prop_assert!(placed.lower_bound <= placed.fields.len(), "{mode:?}: bound {} > {}", placed.lower_bound, placed.fields.len());
        }
    }

    #[test]
    fn locked_fields_stay_and_the_rest_is_covered(gs in geometry_set(), x in 0.0f64..300.0, y in 0.0f64..300.0) {
        let p = MachineProfile::default();
        let locked = ScanField { id: 7, center: Pt::new(x, y), size: p.field_mm, locked: true, geometries: vec![], pose: Default::default(),  };
        for mode in [FieldsMode::Greedy, FieldsMode::Auto, FieldsMode::Paper] {
            let placed = place_fields(&gs, &p, &settings(mode, 3), std::slice::from_ref(&locked), &JobCtx::default()).unwrap();
            assert_valid(&gs, &placed.fields, &p);
            let kept = placed.fields.iter().find(|f| f.id == 7).unwrap();
            prop_assert_eq!(kept.center, locked.center);
            prop_assert!(kept.locked);
            let ids: std::collections::HashSet<usize> = placed.fields.iter().map(|f| f.id).collect();
            prop_assert_eq!(ids.len(), placed.fields.len(), "ids unique");
        }
    }
}

#[test]
fn auto_is_deterministic_and_no_worse_than_paper_on_the_demo() {
    let path = common::root().join("assets/examples/demo.svg");
    let im = galvoplan::import::import_svg_file(&path, &Default::default()).unwrap();
    let p = MachineProfile::default();
    let a = place_fields(
        &im.geometries,
        &p,
        &settings(FieldsMode::Auto, 1),
        &[],
        &JobCtx::default(),
    )
    .unwrap();
    let b = place_fields(
        &im.geometries,
        &p,
        &settings(FieldsMode::Auto, 1),
        &[],
        &JobCtx::default(),
    )
    .unwrap();
    assert_eq!(a, b);
    for seed in 1..4 {
        let paper = place_fields(
            &im.geometries,
            &p,
            &settings(FieldsMode::Paper, seed),
            &[],
            &JobCtx::default(),
        )
        .unwrap();
        assert!(a.fields.len() <= paper.fields.len());
        assert_valid(&im.geometries, &paper.fields, &p);
    }
    let again = place_fields(
        &im.geometries,
        &p,
        &settings(FieldsMode::Paper, 5),
        &[],
        &JobCtx::default(),
    )
    .unwrap();
    let twice = place_fields(
        &im.geometries,
        &p,
        &settings(FieldsMode::Paper, 5),
        &[],
        &JobCtx::default(),
    )
    .unwrap();
    assert_eq!(again, twice, "paper mode is seeded");
}

#[test]
fn cancelled_paper_run_stops() {
    let gs: Vec<Geometry> = (0..200)
        .map(|i| rect((i % 20) as f64 * 14.0, (i / 20) as f64 * 25.0, 4.0, 4.0))
        .collect();
    let ctx = JobCtx::default();
    ctx.cancel_token().cancel();
    let e = place_fields(
        &gs,
        &MachineProfile::default(),
        &settings(FieldsMode::Paper, 1),
        &[],
        &ctx,
    )
    .unwrap_err();
    assert!(matches!(e, FieldError::Cancelled(_)));
}

#[test]
fn oversize_geometries_error_or_split() {
    let p = MachineProfile::default();
    let mut gs = vec![
        rect(10.0, 10.0, 200.0, 30.0),
        rect(50.0, 100.0, 5.0, 5.0),
        rect(100.0, 150.0, 40.0, 120.0),
    ];
    let e = place_fields(
        &gs,
        &p,
        &settings(FieldsMode::Auto, 1),
        &[],
        &JobCtx::default(),
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.starts_with("2 geometries are larger than the 70.0 × 70.0 mm scan field"),
        "{msg}"
    );
    assert!(
        msg.contains("200.00 × 30.00 mm") && msg.contains("40.00 × 120.00 mm"),
        "{msg}"
    );
    let before: f64 = gs.iter().map(Geometry::length_mm).sum();
    let (warnings, _, _) = split_oversize(&mut gs, None, &[], p.field_mm);
    assert_eq!(warnings.len(), 2);
    let after: f64 = gs.iter().map(Geometry::length_mm).sum();
    assert!((before - after).abs() < 1e-9);
    let placed = place_fields(
        &gs,
        &p,
        &settings(FieldsMode::Auto, 1),
        &[],
        &JobCtx::default(),
    )
    .unwrap();
    assert_valid(&gs, &placed.fields, &p);
}
