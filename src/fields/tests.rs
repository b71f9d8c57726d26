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
        msg.contains("geometry 1 ") && msg.contains("geometry 3 ") && msg.contains("80.00 × 10.00"),
        "{msg}"
    );
    let gs = vec![rect(340.0, 10.0, 5.0, 5.0)];
    let msg = place(&gs, &p).unwrap_err().to_string();
    assert_eq!(
        msg,
        "the artwork is 5.0 × 5.0 mm at x 340.0…345.0, y 10.0…15.0 mm, out of reach where it \
         lies: the laser reaches x -35.0…335.0, y -35.0…335.0 mm (300.0 × 300.0 mm base stroke \
         + 70.0 × 70.0 mm scan field); it fits once moved: place it centred on the base stroke \
         or with its top-left corner at x -35.0…330.0, y -35.0…330.0 mm"
    );
}

#[test]
fn lists_stop_at_five_and_huge_artwork_asks_for_a_unit_check() {
    let p = MachineProfile::default();
    // 12 oversize geometries: five named, then the count of the rest
    let gs: Vec<Geometry> = (0..12)
        .map(|i| rect(0.0, 20.0 * i as f64, 80.0, 10.0))
        .collect();
    let msg = place(&gs, &p).unwrap_err().to_string();
    assert!(msg.starts_with("12 geometries are larger"), "{msg}");
    assert!(
        msg.contains("geometry 5 ") && !msg.contains("geometry 6 "),
        "{msg}"
    );
    assert!(msg.ends_with("; … and 7 more"), "{msg}");
    // a drawing in metres read as mm: 17,600 × 11,400 mm
    let gs = vec![rect(0.0, 0.0, 17_600.0, 1.0), rect(0.0, 11_399.0, 1.0, 1.0)];
    let msg = place(&gs, &p).unwrap_err().to_string();
    assert_eq!(
        msg,
        "the artwork is 17600.0 × 11400.0 mm, 48 times the 370.0 × 370.0 mm the laser reaches \
         (300.0 × 300.0 mm base stroke + 70.0 × 70.0 mm scan field): check the drawing's units \
         (DXF $INSUNITS; SVG width, height and viewBox)"
    );
    // a little too large: no unit check, no placement
    let gs = vec![rect(0.0, 0.0, 60.0, 60.0), rect(340.0, 0.0, 60.0, 60.0)];
    let msg = place(&gs, &p).unwrap_err().to_string();
    assert!(
        msg.starts_with("the artwork is 400.0 × 60.0 mm, larger than the 370.0 × 370.0 mm"),
        "{msg}"
    );
}
