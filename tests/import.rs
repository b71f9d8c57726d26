//! SVG import: element kinds, transforms, units, warnings and errors.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use galvoplan::geom::{BBox, Pt};
use galvoplan::import::{import_svg, ImportError, ImportOptions, Imported};

fn svg(body: &str) -> String {
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="100mm" height="100mm" viewBox="0 0 100 100"><g fill="none" stroke="black">{body}</g></svg>"#
    )
}

fn import(text: &str) -> Imported {
    import_svg(text.as_bytes(), "t.svg", &ImportOptions::default()).unwrap()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

fn assert_box(b: BBox, min_x: f64, min_y: f64, max_x: f64, max_y: f64) {
    let tol = 1e-3;
    assert!(
        close(b.min_x, min_x, tol)
            && close(b.min_y, min_y, tol)
            && close(b.max_x, max_x, tol)
            && close(b.max_y, max_y, tol),
        "box {b:?} != ({min_x}, {min_y}, {max_x}, {max_y})"
    );
}

#[test]
fn every_element_kind() {
    let im = import(&svg(r#"<path d="M10 10 L20 10 L20 20"/>
           <rect x="1" y="2" width="3" height="4"/>
           <rect x="10" y="30" width="20" height="10" rx="2"/>
           <circle cx="50" cy="50" r="5"/>
           <ellipse cx="70" cy="50" rx="6" ry="3"/>
           <line x1="0" y1="90" x2="10" y2="95"/>
           <polyline points="20,90 25,95 30,90"/>
           <polygon points="40,90 45,95 50,90"/>"#));
    let g = &im.geometries;
    assert_eq!(g.len(), 8);
    let closed: Vec<bool> = g.iter().map(|g| g.closed).collect();
    assert_eq!(closed, [false, true, true, true, true, false, false, true]);
    assert_box(g[1].bbox(), 1.0, 2.0, 4.0, 6.0);
    assert!(close(g[1].length_mm(), 14.0, 1e-6));
    // rounded rect: straight parts plus four quarter circles of radius 2
    let rr = 2.0 * (20.0 - 4.0) + 2.0 * (10.0 - 4.0) + 2.0 * std::f64::consts::PI * 2.0;
    assert!(close(g[2].length_mm(), rr, 0.03), "{}", g[2].length_mm());
    assert!(close(
        g[3].length_mm(),
        2.0 * std::f64::consts::PI * 5.0,
        0.03
    ));
    assert_box(g[4].bbox(), 64.0, 47.0, 76.0, 53.0);
    assert!(close(g[5].length_mm(), 125f64.sqrt(), 1e-6));
    assert_eq!(g[6].points.len(), 3);
    assert!(close(g[7].length_mm(), 2.0 * 50f64.sqrt() + 10.0, 1e-6));
    assert!(im.warnings.is_empty());
    assert_eq!((im.page_mm[0], im.page_mm[1]), (100.0, 100.0));
}

#[test]
fn flattened_circle_stays_within_chord_tolerance() {
    for tol in [0.001, 0.01, 0.1] {
        let im = import_svg(
            svg(r#"<circle cx="50" cy="50" r="20"/>"#).as_bytes(),
            "t.svg",
            &ImportOptions {
                chord_tol_mm: tol,
                ..ImportOptions::default()
            },
        )
        .unwrap();
        let g = &im.geometries[0];
        // vertices on the curve (within usvg's own Bézier approximation of the circle, ~0.03 %)
        let c = Pt::new(50.0, 50.0);
        for w in g.points.windows(2) {
            let mid = w[0].plus(w[1]).scale(0.5);
            let sagitta = 20.0 - mid.dist(c);
            assert!(sagitta <= tol + 20.0 * 3e-4, "tol {tol}: sagitta {sagitta}");
        }
    }
}

#[test]
fn subpaths_and_implicit_closing() {
    let im = import(&svg(
        r#"<path d="M0 0 L10 0 L10 10 Z M20 0 L30 0 L30 10 L20 0 M40 0 L50 0"/>"#,
    ));
    let g = &im.geometries;
    assert_eq!(g.len(), 3);
    assert!(g[0].closed && g[1].closed && !g[2].closed);
    assert_eq!(g[1].points.len(), 3, "repeated closing point dropped");
    assert_eq!(g[0].source.subpath, 0);
    assert_eq!(g[2].source.subpath, 2);
}

#[test]
fn nested_transforms_and_use() {
    let im = import(&svg(
        r##"<defs><rect id="r" x="0" y="0" width="2" height="1"/></defs>
           <g transform="translate(10 20)"><g transform="scale(2)"><use xlink:href="#r"/></g></g>
           <use xlink:href="#r" x="50" y="50"/>
           <g transform="rotate(90 0 0) translate(30 -40)"><line x1="0" y1="0" x2="5" y2="0"/></g>"##,
    ));
    let g = &im.geometries;
    assert_eq!(g.len(), 3);
    assert_box(g[0].bbox(), 10.0, 20.0, 14.0, 22.0);
    assert_box(g[1].bbox(), 50.0, 50.0, 52.0, 51.0);
    // rotate(90): (x, y) -> (-y, x); the line from (30,-40)-(35,-40) maps to (40,30)-(40,35)
    assert_box(g[2].bbox(), 40.0, 30.0, 40.0, 35.0);
}

#[test]
fn units_to_mm() {
    // (root attributes, mm per user unit, page width in mm)
    let cases = [
        (
            r#"width="10cm" height="10cm" viewBox="0 0 10 10""#,
            10.0,
            100.0,
        ),
        (r#"width="4in" height="4in" viewBox="0 0 4 4""#, 25.4, 101.6),
        (
            r#"width="72pt" height="72pt" viewBox="0 0 72 72""#,
            25.4 / 72.0,
            25.4,
        ),
        (r#"width="72pt" height="72pt""#, 25.4 / 96.0, 25.4),
        (r#"width="96px" height="96px""#, 25.4 / 96.0, 25.4),
        (r#"width="96" height="96""#, 25.4 / 96.0, 25.4),
        (
            r#"width="50mm" height="50mm" viewBox="0 0 100 100""#,
            0.5,
            50.0,
        ),
    ];
    for (attrs, mm_per_unit, page) in cases {
        let text = format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" {attrs}><line x1="1" y1="1" x2="2" y2="1" stroke="black"/></svg>"#
        );
        let im = import(&text);
        let g = &im.geometries[0];
        assert!(
            close(g.length_mm(), mm_per_unit, 1e-5),
            "{attrs}: {}",
            g.length_mm()
        );
        assert!(close(g.points[0].x, mm_per_unit, 1e-5), "{attrs}");
        assert!(
            close(im.page_mm[0], page, 1e-3),
            "{attrs}: page {:?}",
            im.page_mm
        );
    }
}

#[test]
fn layers_from_stroke_colour() {
    let im = import(&svg(
        r##"<line x1="0" y1="0" x2="1" y2="0" stroke="#ff0000"/><line x1="0" y1="1" x2="1" y2="1"/>"##,
    ));
    assert_eq!(im.geometries[0].source.layer, "#ff0000");
    assert_eq!(im.geometries[1].source.layer, "#000000");
}

#[test]
fn unsupported_content_is_warned_not_dropped_silently() {
    let im = import(&svg(r#"<line x1="0" y1="0" x2="1" y2="0"/>
<image x="0" y="0" width="5" height="5" href="data:image/png;base64,AAAA"/>
<foreignObject id="fo" width="5" height="5"/>"#));
    assert_eq!(im.geometries.len(), 1);
    assert_eq!(im.warnings.len(), 2);
    let w = im.warnings[1].to_string();
    assert!(
        w.contains("<foreignObject id=\"fo\">") && w.contains("line 3"),
        "{w}"
    );
    assert!(im.warnings[0].to_string().contains("<image>"));
}

#[test]
fn degenerate_paths_are_warned_and_skipped() {
    let im = import(&svg(
        r#"<path id="dot" d="M5 5 L5 5"/><line x1="0" y1="0" x2="1" y2="0"/>"#,
    ));
    assert_eq!(im.geometries.len(), 1);
    assert_eq!(im.warnings.len(), 1);
    assert!(
        im.warnings[0].to_string().contains("#dot")
            && im.warnings[0].message.contains("zero length")
    );
}

#[test]
fn bad_files_name_the_file_and_the_problem() {
    let err = |bytes: &[u8]| import_svg(bytes, "bad.svg", &ImportOptions::default()).unwrap_err();
    let e = err(b"");
    assert!(matches!(e, ImportError::Empty { .. }));
    assert_eq!(e.to_string(), "bad.svg: empty file");
    let full = svg(r#"<line x1="0" y1="0" x2="1" y2="0"/>"#);
    let e = err(&full.as_bytes()[..full.len() / 2]).to_string();
    assert!(
        e.starts_with("bad.svg: not a valid SVG: malformed XML"),
        "{e}"
    );
    let e = err(b"hello, world\n").to_string();
    assert!(e.starts_with("bad.svg: not a valid SVG"), "{e}");
    let e = err(b"<html><body/></html>").to_string();
    assert!(e.contains("root element is <html>"), "{e}");
    let e = err(svg(r#"<image x="1" y="1" width="2" height="2" href="a.png"/>"#).as_bytes())
        .to_string();
    assert!(
        e.starts_with("bad.svg: no markable geometry") && e.contains("<image>"),
        "{e}"
    );
    let e = err(&[0xff, 0xfe, 0x00, 0x41]).to_string();
    assert!(e.contains("not UTF-8"), "{e}");
    for e in [err(b""), err(b"<svg")] {
        assert!(!e.to_string().contains('\n'));
    }
}

/// Arc radii of 10⁴⁰–10¹¹⁷ made usvg loop for minutes and use gigabytes (found by fuzzing,
/// docs/FUZZING.md): such a file is refused before usvg sees it, naming the element and line.
#[test]
fn absurd_arc_radii_are_refused_before_usvg() {
    for radius in ["1e40", "7e117", "-1e80", "1e10"] {
        let text = svg(&format!(
            "<path id=\"a\" d=\"M 40 240 A{radius} 15 10 0 0 1 70\"/>"
        ));
        let t0 = std::time::Instant::now();
        let e = import_svg(text.as_bytes(), "t.svg", &ImportOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("<path id=\"a\"") && e.contains("arc radius"),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");
        assert!(t0.elapsed().as_secs_f64() < 1.0);
    }
    // a large but real radius still imports (a nearly straight arc)
    let text = svg("<path d=\"M 10 10 A 1e6 1e6 0 0 1 60 10\"/>");
    assert_eq!(import(&text).geometries.len(), 1);
    // the fuzzer's file itself
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/svg/fuzz/oom-huge-arc-radius.svg");
    let e = import_svg(
        &std::fs::read(path).unwrap(),
        "f.svg",
        &ImportOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("arc radius"), "{e}");
}
