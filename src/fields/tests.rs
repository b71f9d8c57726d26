use super::tests_support::rect;
use super::*;

fn place(gs: &[Geometry], p: &MachineProfile) -> Result<Placement, FieldError> {
    let settings = SolverSettings {
        fields: FieldsMode::Greedy,
        ..SolverSettings::default()
    };
    place_fields(gs, p, &settings, &[], &JobCtx::default())
}

fn covered_once(gs: &[Geometry], fields: &[ScanField]) {
    let mut seen = vec![0; gs.len()];
    for f in fields {
        for &g in &f.geometries {
            seen[g] += 1;
            assert!(
                f.bbox().contains_box(&gs[g].bbox(), 1e-6),
                "geometry {g} outside field {}",
                f.id
            );
        }
        assert!(
            f.center.x >= 0.0 && f.center.x <= 300.0 && f.center.y >= 0.0 && f.center.y <= 300.0
        );
    }
    assert!(seen.iter().all(|&c| c == 1), "{seen:?}");
}

#[test]
fn greedy_covers_everything_once() {
    let gs: Vec<Geometry> = (0..50)
        .map(|i| rect((i % 10) as f64 * 29.0, (i / 10) as f64 * 55.0, 5.0, 3.0))
        .collect();
    let p = MachineProfile::default();
    let fields = place(&gs, &p).unwrap().fields;
    covered_once(&gs, &fields);
    assert!(fields.len() < 50);
}

#[test]
fn edge_artwork_shifts_field_into_stroke() {
    // artwork at the far corner: the laser reaches it only with the base at its limit
    let gs = vec![rect(-30.0, 320.0, 4.0, 4.0), rect(330.0, -34.0, 3.0, 3.0)];
    let p = MachineProfile::default();
    let fields = place(&gs, &p).unwrap().fields;
    covered_once(&gs, &fields);
}

#[test]
fn oversize_and_out_of_reach_are_listed() {
    let p = MachineProfile::default();
    let gs = vec![
        rect(0.0, 0.0, 80.0, 10.0),
        rect(100.0, 100.0, 5.0, 5.0),
        rect(10.0, 10.0, 5.0, 75.0),
    ];
    let e = place(&gs, &p).unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("2 geometries are larger"), "{msg}");
    assert!(
        msg.contains("geometry 0") && msg.contains("geometry 2") && msg.contains("80.00 × 10.00"),
        "{msg}"
    );
    let gs = vec![rect(340.0, 10.0, 5.0, 5.0)];
    let msg = place(&gs, &p).unwrap_err().to_string();
    assert!(
        msg.contains("out of reach") && msg.contains("geometry 0"),
        "{msg}"
    );
}
