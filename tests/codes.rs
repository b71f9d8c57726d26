//! Codes that scan: the marks galvoplan makes for DataMatrix, QR and Code 128 are rasterised
//! at the spot's width and read back by an independent decoder (rxing, a port of ZXing).
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::codes::{marks, quiet_box, symbol, Fill};
use galvoplan::document::{
    CodeKind, CodeOptions, CodeSpec, Ecc, MachineProfile, SolverSettings, Stamp, Tray, TraySettings,
};
use galvoplan::geom::Pt;
use galvoplan::import::ImportOptions;
use galvoplan::job::JobCtx;
use galvoplan::pipeline::{load_production, plan_document_lowered};
use rxing::{BarcodeFormat, DecodeHints};

/// Pixels per mm of the raster (a 0.25 mm module is 5 px, the 0.05 mm spot 1 px).
const PX_PER_MM: f32 = 20.0;
const SPOT_MM: f64 = 0.05;

/// The strokes, drawn as a spot of `SPOT_MM` travelling along them (round ends), black on
/// white, over the box `lo`–`hi` (mm) grown by `margin` mm: a luma image.
fn raster(strokes: &[Vec<Pt>], lo: Pt, hi: Pt, margin: f64) -> (Vec<u8>, u32, u32) {
    let (x0, y0) = (lo.x - margin, lo.y - margin);
    let w = ((hi.x - lo.x + 2.0 * margin) as f32 * PX_PER_MM).ceil() as u32;
    let h = ((hi.y - lo.y + 2.0 * margin) as f32 * PX_PER_MM).ceil() as u32;
    let mut pixmap = tiny_skia::Pixmap::new(w, h).unwrap();
    pixmap.fill(tiny_skia::Color::WHITE);
    let mut paint = tiny_skia::Paint::default();
    paint.set_color(tiny_skia::Color::BLACK);
    paint.anti_alias = true;
    let stroke = tiny_skia::Stroke {
        width: SPOT_MM as f32 * PX_PER_MM,
        line_cap: tiny_skia::LineCap::Round,
        line_join: tiny_skia::LineJoin::Round,
        ..tiny_skia::Stroke::default()
    };
    let px = |p: &Pt| ((p.x - x0) as f32 * PX_PER_MM, (p.y - y0) as f32 * PX_PER_MM);
    for s in strokes {
        let mut pb = tiny_skia::PathBuilder::new();
        let (a, b) = px(&s[0]);
        pb.move_to(a, b);
        for p in &s[1..] {
            let (a, b) = px(p);
            pb.line_to(a, b);
        }
        if let Some(path) = pb.finish() {
            pixmap.stroke_path(
                &path,
                &paint,
                &stroke,
                tiny_skia::Transform::identity(),
                None,
            );
        }
    }
    let luma = pixmap.pixels().iter().map(|p| p.red()).collect();
    (luma, w, h)
}

fn format_of(kind: CodeKind) -> BarcodeFormat {
    match kind {
        CodeKind::DataMatrix => BarcodeFormat::DATA_MATRIX,
        CodeKind::Qr => BarcodeFormat::QR_CODE,
        CodeKind::Code128 => BarcodeFormat::CODE_128,
    }
}

/// Decodes the strokes that lie in the code's box; `None` when nothing is read.
fn decode(kind: CodeKind, strokes: &[Vec<Pt>], lo: Pt, hi: Pt, inverted: bool) -> Option<String> {
    let (luma, w, h) = raster(strokes, lo, hi, 2.0);
    let mut hints = DecodeHints {
        AlsoInverted: Some(inverted),
        ..DecodeHints::default()
    };
    rxing::helpers::detect_in_luma_with_hints(luma, w, h, Some(format_of(kind)), &mut hints)
        .ok()
        .map(|r| r.getText().to_string())
}

/// Marks `content` as `kind` with modules of `module_mm` and reads it back.
fn round_trip(kind: CodeKind, content: &str, module_mm: f64, options: CodeOptions) -> String {
    let mut spec = CodeSpec {
        kind,
        content: content.into(),
        at_mm: [0.0, 0.0],
        size_mm: 10.0,
        options,
    };
    let sym = symbol(&spec, content).unwrap();
    spec.size_mm = module_mm * sym.cols as f64;
    let fill = Fill {
        spacing_mm: SPOT_MM,
        spot_mm: SPOT_MM,
    };
    let at = Pt::new(5.0, 5.0);
    let g = marks(&spec, &sym, at, fill, 1, "code", 1).unwrap();
    let strokes: Vec<Vec<Pt>> = g.into_iter().map(|g| g.points).collect();
    let (lo, hi) = quiet_box(&spec, &sym, at);
    decode(kind, &strokes, lo, hi, options.inverted)
        .unwrap_or_else(|| panic!("{kind} {content:?} at {module_mm} mm ({options:?}) not read"))
}

#[test]
fn every_kind_scans_at_quarter_and_half_millimetre_modules() {
    for module in [0.25, 0.5] {
        for inverted in [false, true] {
            let o = CodeOptions {
                inverted,
                ..CodeOptions::default()
            };
            assert_eq!(
                round_trip(CodeKind::DataMatrix, "GP01001", module, o),
                "GP01001"
            );
            let rect = CodeOptions { rect: true, ..o };
            assert_eq!(
                round_trip(CodeKind::DataMatrix, "LOT-7 0042", module, rect),
                "LOT-7 0042"
            );
            for ecc in [Ecc::L, Ecc::H] {
                let q = CodeOptions { ecc, ..o };
                assert_eq!(
                    round_trip(CodeKind::Qr, "L26-001/1001", module, q),
                    "L26-001/1001"
                );
            }
            assert_eq!(
                round_trip(CodeKind::Code128, "SN 1001-A", module, o),
                "SN 1001-A"
            );
        }
    }
}

#[test]
fn gs1_datamatrix_scans_with_its_element_strings() {
    let o = CodeOptions {
        gs1: true,
        ..CodeOptions::default()
    };
    let udi = "0104012345678901\u{1d}21SN1001";
    let read = round_trip(CodeKind::DataMatrix, udi, 0.25, o);
    // the reader gives the element strings (FNC1 first is the symbology's, not text)
    assert!(
        read.ends_with("21SN1001") && read.contains("0104012345678901"),
        "{read:?}"
    );
}

/// assets/examples/part.svg made into the tray `tray` says, on the default machine and settings.
fn part_tray(tray: TraySettings) -> galvoplan::pipeline::Loaded {
    let part = common::root().join("assets/examples/part.svg");
    load_production(
        &part,
        MachineProfile::default(),
        SolverSettings::default(),
        &ImportOptions::default(),
        &tray,
    )
    .unwrap()
}

/// The tray job of the acceptance: 6 × 8 parts, a DataMatrix and a QR code each with its
/// part's content; every one of the 96 codes, cut out of the planned toolpath's marks at its
/// part, reads as its part's content.
#[test]
fn every_code_of_a_tray_reads_its_part_content_from_the_toolpath() {
    let root = common::root().join("assets/examples");
    let codes = vec![
        CodeSpec::parse("datamatrix:GP{serial:05}@3,3:6").unwrap(),
        CodeSpec::parse("qr:{csv:lot}/{serial}@14,2:9").unwrap(),
    ];
    let loaded = part_tray(TraySettings {
        tray: Some(Tray::parse("6x8@40,32").unwrap()),
        serial: Some(galvoplan::document::Serial::parse("1001").unwrap()),
        data: Some(galvoplan::document::DataTable::read(&root.join("lots.csv")).unwrap()),
        stamp: Some(Stamp::parse("2026-12-07").unwrap()),
        codes: Some(codes.clone()),
        ..TraySettings::default()
    });
    let mut doc = loaded.doc;
    let (_, toolpath) = plan_document_lowered(&mut doc, &JobCtx::default()).unwrap();
    let strokes: Vec<Vec<Pt>> = (0..toolpath.strokes.len())
        .map(|k| toolpath.stroke_points(k).to_vec())
        .filter(|s| s.len() > 1)
        .collect();
    // the part's top-left on the machine: part 1's outline box
    let part1 = doc
        .artwork
        .iter()
        .filter(|g| g.source.part == 1 && g.layer == "outline")
        .flat_map(|g| g.points.iter())
        .fold((f64::INFINITY, f64::INFINITY), |(x, y), p| {
            (x.min(p.x), y.min(p.y))
        });
    assert_eq!(doc.parts.len(), 48);
    let mut read = 0;
    for part in &doc.parts {
        let origin = Pt::new(
            part1.0 + part.position_mm[0] - doc.parts[0].position_mm[0],
            part1.1 + part.position_mm[1] - doc.parts[0].position_mm[1],
        );
        for (spec, content) in codes.iter().zip(&part.codes) {
            let sym = symbol(spec, content).unwrap();
            let at = origin.plus(Pt::new(spec.at_mm[0], spec.at_mm[1]));
            let (lo, hi) = quiet_box(spec, &sym, at);
            let inside: Vec<Vec<Pt>> = strokes
                .iter()
                .filter(|s| {
                    s.iter()
                        .all(|p| p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y)
                })
                .cloned()
                .collect();
            let got = decode(spec.kind, &inside, lo, hi, false);
            assert_eq!(got.as_deref(), Some(content.as_str()), "part {}", part.part);
            read += 1;
        }
    }
    assert_eq!(read, 96);
    assert_eq!(doc.parts[4].codes, ["GP01005", "L26-005/1005"]);
}

/// `dots`: one spot (a mark of one point) at the centre of every marked module, and nothing
/// else: the dark modules, or (inverted) the light ones and the quiet zone.
#[test]
fn dots_put_one_spot_at_each_marked_module_centre() {
    let fill = Fill {
        spacing_mm: SPOT_MM,
        spot_mm: SPOT_MM,
    };
    for (kind, content, inverted) in [
        (CodeKind::DataMatrix, "GP01001", false),
        (CodeKind::Qr, "L26-001/1001", false),
        (CodeKind::DataMatrix, "GP01001", true),
    ] {
        let mut spec = CodeSpec::parse(&format!("{kind}:{content}@0,0:1")).unwrap();
        spec.options.dots = true;
        spec.options.inverted = inverted;
        let sym = symbol(&spec, content).unwrap();
        let module = 0.25;
        spec.size_mm = module * sym.cols as f64;
        let at = Pt::new(5.0, 7.0);
        let g = marks(&spec, &sym, at, fill, 1, "code", 1).unwrap();
        // the centres the spots must stand on
        let q = if inverted { sym.quiet as i64 } else { 0 };
        let mut want = Vec::new();
        for r in -q..sym.rows as i64 + q {
            for c in -q..sym.cols as i64 + q {
                let inside = (0..sym.rows as i64).contains(&r) && (0..sym.cols as i64).contains(&c);
                let dark = inside && sym.is_dark(r as usize, c as usize);
                if dark != inverted {
                    want.push((
                        (c as f64 + 0.5) * module + at.x,
                        (r as f64 + 0.5) * module + at.y,
                    ));
                }
            }
        }
        assert_eq!(g.len(), want.len(), "{kind} inverted {inverted}");
        let key = |x: f64, y: f64| ((x * 1e6).round() as i64, (y * 1e6).round() as i64);
        let mut got: Vec<_> = g
            .iter()
            .map(|g| {
                assert_eq!(g.points.len(), 1, "a dot is one point");
                key(g.points[0].x, g.points[0].y)
            })
            .collect();
        let mut want: Vec<_> = want.into_iter().map(|(x, y)| key(x, y)).collect();
        got.sort_unstable();
        want.sort_unstable();
        assert_eq!(got, want, "{kind} inverted {inverted}");
    }
    // dots smaller than the spot would run together: refused with the least width
    let mut spec = CodeSpec::parse("datamatrix:GP01001@0,0:0.5:dots").unwrap();
    let sym = symbol(&spec, "GP01001").unwrap();
    let big_spot = Fill {
        spacing_mm: SPOT_MM,
        spot_mm: 0.1,
    };
    let e = marks(&spec, &sym, Pt::new(0.0, 0.0), big_spot, 1, "code", 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("at least 1.20 mm wide"), "{e}");
    spec.size_mm = 1.2;
    assert!(marks(&spec, &sym, Pt::new(0.0, 0.0), big_spot, 1, "code", 1).is_ok());
}

/// A dotted code through the whole job: each dot is lowered as a mark of its pen's dwell, and
/// written as a dwell with the laser on.
#[test]
fn dots_are_marked_for_their_pens_dwell_through_the_job() {
    let loaded = part_tray(TraySettings {
        tray: Some(Tray::parse("2x1@40,32").unwrap()),
        serial: Some(galvoplan::document::Serial::parse("1001").unwrap()),
        codes: Some(vec![
            CodeSpec::parse("datamatrix:GP{serial:05}@3,3:6:dots").unwrap()
        ]),
        ..TraySettings::default()
    });
    let mut doc = loaded.doc;
    let codes = doc
        .layers
        .iter_mut()
        .find(|l| l.name == galvoplan::document::CODE_LAYER)
        .expect("the codes' layer");
    codes.pen.dot_dwell_s = Some(2e-3);
    let dots = doc.artwork.iter().filter(|g| g.points.len() == 1).count();
    assert!(dots > 100, "{dots} dots");
    let (plan, toolpath) = plan_document_lowered(&mut doc, &JobCtx::default()).unwrap();
    let dot_marks: Vec<f64> = toolpath
        .segments
        .iter()
        .filter_map(|s| match s.scan {
            galvoplan::motion::ScanMotion::Mark { stroke, .. }
                if toolpath.stroke_points(stroke).len() == 1 =>
            {
                Some(s.duration_s)
            }
            _ => None,
        })
        .collect();
    assert_eq!(dot_marks.len(), dots);
    assert!(dot_marks.iter().all(|d| (d - 2e-3).abs() < 1e-12));
    let gcode = galvoplan::export::write_gcode(&toolpath, &plan, 0.0, "dots").unwrap();
    assert_eq!(gcode.matches("\nG4 P0.002\n").count(), dots);
}
