//! DXF import: fixtures written by ezdxf (scripts/make_dxf_fixtures.py) against the exact
//! geometry ezdxf computes; units, orientation, placement, warnings and errors.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use galvoplan::geom::{point_segment_dist, Pt};
use galvoplan::import::{
    import_dxf, import_file, FontSource, ImportError, ImportOptions, Imported, Place,
};
use std::path::Path;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/dxf");

fn opts(tol: f64) -> ImportOptions {
    ImportOptions {
        chord_tol_mm: tol,
        fonts: FontSource::BundledOnly,
        work_area_mm: Some([300.0, 300.0]),
        ..ImportOptions::default()
    }
}

fn fixture(name: &str, tol: f64) -> Imported {
    import_file(&Path::new(DATA).join(name), &opts(tol)).unwrap()
}

/// The geometries back in DXF orientation (y up): `y = page height − y_mm`.
fn y_up(im: &Imported) -> Vec<(Vec<Pt>, bool)> {
    im.geometries
        .iter()
        .map(|g| {
            let pts = g
                .points
                .iter()
                .map(|p| Pt::new(p.x, im.page_mm[1] - p.y))
                .collect();
            (pts, g.closed)
        })
        .collect()
}

fn dist_to_path(p: Pt, pts: &[Pt], closed: bool) -> f64 {
    let n = pts.len();
    let segs = if closed { n } else { n - 1 };
    (0..segs)
        .map(|i| point_segment_dist(p, pts[i], pts[(i + 1) % n]))
        .fold(f64::INFINITY, f64::min)
}

fn minimal(entities: &str, insunits: Option<i32>) -> String {
    let header = insunits
        .map(|u| format!("0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n{u}\n0\nENDSEC\n"))
        .unwrap_or_default();
    format!("{header}0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n")
}

fn line(layer: &str, a: (f64, f64), b: (f64, f64)) -> String {
    format!(
        "0\nLINE\n5\n1A\n8\n{layer}\n10\n{}\n20\n{}\n11\n{}\n21\n{}\n",
        a.0, a.1, b.0, b.1
    )
}

fn import_text(text: &str) -> Result<Imported, ImportError> {
    import_dxf(text.as_bytes(), "t.dxf", &opts(0.01))
}

#[test]
fn ezdxf_entities_match_their_exact_geometry_within_the_chord_tolerance() {
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(Path::new(DATA).join("entities-inch.exact.json")).unwrap(),
    )
    .unwrap();
    let curves: Vec<Vec<Pt>> = json["curves"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            c.as_array()
                .unwrap()
                .iter()
                .map(|p| Pt::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
                .collect()
        })
        .collect();
    for tol in [0.01, 0.1] {
        let im = fixture("entities-inch.dxf", tol);
        // 9 entities, OUTER (circle + 2 × INNER of 2), a 3 × 2 array of INNER
        assert_eq!(im.geometries.len(), 9 + 5 + 12);
        let ours = y_up(&im);
        // every exact point has a mark within the tolerance (JSON rounding: 1e-6 mm)
        for c in &curves {
            for &p in c {
                let d = ours
                    .iter()
                    .map(|(pts, closed)| dist_to_path(p, pts, *closed))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    d <= tol + 2e-6,
                    "tol {tol}: exact point {p:?} is {d} mm from the marks"
                );
            }
        }
        // every vertex marked lies on an exact curve (allowing the chords between ezdxf's samples)
        for (k, (pts, _)) in ours.iter().enumerate() {
            for &p in pts {
                let d = curves
                    .iter()
                    .map(|c| dist_to_path(p, c, false))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    d <= 0.005,
                    "tol {tol}: vertex {p:?} of {} is {d} mm off the drawing",
                    im.geometries[k].source.element
                );
            }
        }
    }
}

#[test]
fn layers_warnings_units_and_orientation() {
    let im = fixture("entities-inch.dxf", 0.01);
    let layers: std::collections::BTreeSet<&str> = im
        .geometries
        .iter()
        .map(|g| g.source.layer.as_str())
        .collect();
    assert_eq!(
        layers.into_iter().collect::<Vec<_>>(),
        ["BLOCKS", "CUT", "ENGRAVE"]
    );
    let text: Vec<String> = im.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        text.iter()
            .any(|w| w.contains("HATCH (handle") && w.contains("layer 0")),
        "{text:?}"
    );
    assert!(
        text.iter().any(|w| w.starts_with("POINT (handle")),
        "{text:?}"
    );
    // inches: the first LINE from (0.5, 0.5) in to (3, 0.75) in
    let first = &im.geometries[0];
    let ys: Vec<f64> = first.points.iter().map(|p| im.page_mm[1] - p.y).collect();
    assert!((first.points[0].x - 12.7).abs() < 1e-9 && (ys[0] - 12.7).abs() < 1e-9);
    assert!((first.points[1].x - 76.2).abs() < 1e-9 && (ys[1] - 19.05).abs() < 1e-9);
}

#[test]
fn y_up_is_flipped_never_mirrored_and_the_origin_stays() {
    // an L: foot to the right along y = 0, stem up along x = 0, drawn at (10, 5)
    let im = import_text(&minimal(
        &(line("L", (10.0, 5.0), (30.0, 5.0)) + &line("L", (10.0, 5.0), (10.0, 45.0))),
        Some(4),
    ))
    .unwrap();
    assert_eq!(im.page_mm, [30.0, 45.0]);
    let foot = &im.geometries[0].points;
    let stem = &im.geometries[1].points;
    // the corner is at the bottom (largest y, machine y down), the stem rises to the top edge
    assert_eq!(foot[0], Pt::new(10.0, 40.0));
    assert_eq!(foot[1], Pt::new(30.0, 40.0));
    assert_eq!(stem[1], Pt::new(10.0, 0.0));
    assert!(im.warnings.is_empty(), "{:?}", im.warnings);
}

#[test]
fn drawings_out_of_reach_are_centred_on_the_work_area_with_a_warning() {
    // x −50…10, y −20…0 in the DXF: y_mm = 0 − y, then centred on the 300 × 300 mm work area
    // (no field given: the reach is the work area itself)
    let im = import_text(&minimal(&line("0", (-50.0, -20.0), (10.0, 0.0)), Some(4))).unwrap();
    assert_eq!(
        im.geometries[0].points,
        [Pt::new(120.0, 160.0), Pt::new(180.0, 140.0)]
    );
    assert_eq!(im.moved_mm, [170.0, 140.0]);
    assert_eq!(im.page_mm, [300.0, 300.0]);
    let w: Vec<String> = im.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(
            "artwork: lies out of reach where the file puts it (x -50.0…10.0, y 0.0…20.0 mm"
        ) && w[0].contains("moved by (170, 140) mm"),
        "{w:?}"
    );
    let far = import_text(&minimal(&line("0", (1000.0, 0.0), (1010.0, 10.0)), Some(4))).unwrap();
    assert_eq!(far.geometries[0].points[0], Pt::new(145.0, 155.0));
    // as in the file when asked, even out of reach (the field stage then says so)
    let o = ImportOptions {
        place: Place::AsIs,
        ..opts(0.01)
    };
    let bytes = minimal(&line("0", (1000.0, 0.0), (1010.0, 10.0)), Some(4));
    let kept = import_dxf(bytes.as_bytes(), "far.dxf", &o).unwrap();
    assert_eq!(kept.geometries[0].points[0], Pt::new(1000.0, 10.0));
    assert!(kept.warnings.is_empty());
}

#[test]
fn a_drawing_a_few_micrometres_below_the_origin_is_not_moved_when_the_laser_reaches_it() {
    // LibreCAD's paisley.dxf: 2 µm below y = 0, once reported as "moved by (0.000, 0.000) mm"
    let o = ImportOptions {
        field_mm: Some([70.0, 70.0]),
        ..opts(0.01)
    };
    let bytes = minimal(&line("0", (0.0, -0.002), (100.0, 50.0)), Some(4));
    let im = import_dxf(bytes.as_bytes(), "paisley.dxf", &o).unwrap();
    assert!(im.warnings.is_empty(), "{:?}", im.warnings);
    assert_eq!(im.moved_mm, [0.0, 0.0]);
    assert_eq!(im.geometries[0].points[0], Pt::new(0.0, 50.002));
}

#[test]
fn unitless_is_mm_with_a_warning_and_centimetres_scale() {
    let im = import_text(&minimal(&line("0", (0.0, 0.0), (10.0, 0.0)), None)).unwrap();
    assert!((im.geometries[0].length_mm() - 10.0).abs() < 1e-12);
    assert!(im.warnings.iter().any(|w| w.element == "$INSUNITS"));
    let cm = import_text(&minimal(&line("0", (0.0, 0.0), (10.0, 0.0)), Some(5))).unwrap();
    assert!((cm.geometries[0].length_mm() - 100.0).abs() < 1e-12);
}

#[test]
fn fit_point_spline_of_an_r2018_file_passes_through_its_fit_points() {
    let im = fixture("fit-spline-r2018.dxf", 0.01);
    let fit: Vec<[f64; 2]> = serde_json::from_str(
        &std::fs::read_to_string(Path::new(DATA).join("fit-spline-r2018.fit.json")).unwrap(),
    )
    .unwrap();
    let ours = y_up(&im);
    assert_eq!(ours.len(), 1);
    for f in fit {
        let d = dist_to_path(Pt::new(f[0], f[1]), &ours[0].0, false);
        assert!(d < 1e-9, "fit point {f:?} is {d} mm away");
    }
    assert_eq!(im.geometries[0].source.layer, "FIT");
}

#[test]
fn text_and_mtext_become_glyph_outlines() {
    let im = fixture("text.dxf", 0.01);
    // SN 0042-ACME: 15 contours, ROT: 5, LOT 7 / BATCH 12: 5 + 10
    assert_eq!(im.geometries.len(), 35);
    assert!(im.geometries.iter().all(|g| g.closed));
    let serial: Vec<_> = im
        .geometries
        .iter()
        .filter(|g| g.source.layer == "TEXT")
        .take(15)
        .collect();
    let b = serial
        .iter()
        .fold(galvoplan::geom::BBox::EMPTY, |b, g| b.union(g.bbox()));
    // 5 mm cap height (round glyphs overshoot a little), starting at x = 10
    assert!((b.height() - 5.0).abs() < 0.25, "{b:?}");
    assert!((b.min_x - 10.0).abs() < 0.8, "{b:?}");
    // the rotated word reads upwards: taller than wide
    let rot = im
        .geometries
        .iter()
        .filter(|g| g.source.element.contains("TEXT"))
        .skip(15)
        .take(5);
    let r = rot.fold(galvoplan::geom::BBox::EMPTY, |b, g| b.union(g.bbox()));
    assert!(r.height() > 2.0 * r.width(), "{r:?}");
    assert!(im.geometries.iter().any(|g| g.source.layer == "MTEXT"));
}

#[test]
fn malformed_files_give_one_line_errors_never_panics() {
    let good = std::fs::read(Path::new(DATA).join("entities-inch.dxf")).unwrap();
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("truncated", good[..good.len() / 2].to_vec()),
        (
            "garbage",
            (0..4000u32)
                .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
                .collect(),
        ),
        (
            "bad number",
            minimal("0\nLINE\n10\nabc\n", Some(4)).into_bytes(),
        ),
        (
            "binary sentinel only",
            b"AutoCAD Binary DXF\r\n\x1a\x00\x01\x02".to_vec(),
        ),
    ];
    for (what, bytes) in cases {
        match import_dxf(&bytes, "bad.dxf", &opts(0.01)) {
            Err(e) => {
                let msg = e.to_string();
                assert!(msg.starts_with("bad.dxf: "), "{what}: {msg}");
                assert!(!msg.contains('\n'), "{what}: {msg}");
            }
            Ok(im) => panic!("{what}: imported {} geometries", im.geometries.len()),
        }
    }
    let e = import_dxf(&good[..good.len() / 2], "bad.dxf", &opts(0.01)).unwrap_err();
    assert!(e.to_string().contains("not a valid DXF"), "{e}");
}

#[test]
fn nothing_to_mark_and_self_inserting_blocks() {
    let e = import_text(&minimal("0\nPOINT\n5\n2\n8\n0\n10\n1\n20\n1\n", Some(4))).unwrap_err();
    assert!(matches!(e, ImportError::NothingToMark { .. }), "{e}");
    assert!(e.to_string().contains("POINT"), "{e}");
    let blocks =
        "0\nSECTION\n2\nBLOCKS\n0\nBLOCK\n2\nB\n10\n0\n20\n0\n0\nINSERT\n2\nB\n10\n1\n20\n0\n\
                  0\nLINE\n10\n0\n20\n0\n11\n1\n21\n0\n0\nENDBLK\n0\nENDSEC\n";
    let text = format!(
        "{blocks}{}",
        minimal("0\nINSERT\n8\n0\n2\nB\n10\n0\n20\n0\n", Some(4))
    );
    let im = import_text(&text).unwrap();
    assert_eq!(im.geometries.len(), 1);
    assert!(
        im.warnings
            .iter()
            .any(|w| w.message.contains("inserts itself")),
        "{:?}",
        im.warnings
    );
}

#[test]
fn import_file_chooses_by_extension_then_content() {
    let dir = tempfile::tempdir().unwrap();
    let as_txt = dir.path().join("drawing.txt");
    std::fs::write(
        &as_txt,
        minimal(&line("0", (0.0, 0.0), (10.0, 0.0)), Some(4)),
    )
    .unwrap();
    assert_eq!(
        import_file(&as_txt, &opts(0.01)).unwrap().geometries.len(),
        1
    );
    let svg_named_dxf = dir.path().join("x.dxf");
    std::fs::write(&svg_named_dxf, "<svg xmlns='http://www.w3.org/2000/svg'/>").unwrap();
    let e = import_file(&svg_named_dxf, &opts(0.01))
        .unwrap_err()
        .to_string();
    assert!(e.contains("x.dxf") && e.contains("DXF"), "{e}");
    let unknown = dir.path().join("x.bin");
    std::fs::write(&unknown, [1u8, 2, 3]).unwrap();
    let e = import_file(&unknown, &opts(0.01)).unwrap_err().to_string();
    assert!(e.contains("unknown format"), "{e}");
}

/// Inputs the fuzzer (docs/FUZZING.md) found making the reader panic: each must be an error.
#[test]
fn fuzz_regressions_are_errors() {
    let header = |var: &str, value: &str| {
        format!("0\nSECTION\n2\nHEADER\n9\n{var}\n40\n{value}\n0\nENDSEC\n0\nEOF\n")
    };
    // a creation date beyond chrono's range: the dxf crate panics in TimeDelta::seconds
    for (var, value) in [
        ("$TDCREATE", "1e300"),
        ("$TDUPDATE", "-1e300"),
        ("$TDUCREATE", "1e17"),
    ] {
        let e = import_text(&header(var, value)).unwrap_err().to_string();
        assert!(
            e.starts_with("t.dxf: not a valid DXF: the DXF reader failed near line"),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");
    }
}

/// The fuzzer's crash files themselves (tests/data/dxf/fuzz/): errors, no panic.
#[test]
fn fuzz_crash_files_are_errors() {
    let dir = Path::new(DATA).join("fuzz");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        let t0 = std::time::Instant::now();
        if let Err(e) = import_dxf(&bytes, "crash.dxf", &opts(0.01)) {
            assert!(!e.to_string().contains('\n'), "{}: {e}", path.display());
        }
        // the slow-unit and oom files took 10 s and 2.4 GB before the text size check
        assert!(t0.elapsed().as_secs_f64() < 5.0, "{}", path.display());
    }
}
