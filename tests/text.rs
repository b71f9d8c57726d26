//! SVG `<text>` as glyph outlines: fonts, fallback warnings, layers; the label example plans.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use galvoplan::geom::BBox;
use galvoplan::import::{import_svg, FontSource, ImportOptions, Imported};

fn opts() -> ImportOptions {
    ImportOptions {
        fonts: FontSource::BundledOnly,
        ..ImportOptions::default()
    }
}

fn label(attrs: &str, text: &str) -> Imported {
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="40mm" viewBox="0 0 100 40"><text id="sn" x="10" y="20" font-size="10" {attrs}>{text}</text></svg>"#
    );
    import_svg(svg.as_bytes(), "label.svg", &opts()).unwrap()
}

fn bbox(im: &Imported) -> BBox {
    im.geometries
        .iter()
        .fold(BBox::EMPTY, |b, g| b.union(g.bbox()))
}

#[test]
fn label_glyphs_are_closed_outlines() {
    let im = label(r#"font-family="DejaVu Sans""#, "SN 0042-ACME");
    // S N 0 0 4 2 - A C M E: 1+1+2+2+2+1+1+2+1+1+1 contours
    assert_eq!(im.geometries.len(), 15);
    assert!(im.geometries.iter().all(|g| g.closed));
    assert!(im.warnings.is_empty(), "{:?}", im.warnings);
    let b = bbox(&im);
    // cap height 0.729 em of 10 mm (the zeros overshoot by ~1.5 %), baseline at y = 20
    assert!((b.height() - 7.29).abs() < 0.4, "{b:?}");
    assert!((b.max_y - 20.0).abs() < 0.2, "{b:?}");
    assert!(
        (b.min_x - 10.0).abs() < 1.0 && b.width() > 60.0 && b.width() < 90.0,
        "{b:?}"
    );
    assert!(im.geometries.iter().all(|g| g.source.element == "#sn"));
}

#[test]
fn sans_serif_is_dejavu_sans_and_a_missing_family_falls_back_with_a_warning() {
    let named = label(r#"font-family="DejaVu Sans""#, "Ag");
    let generic = label(r#"font-family="sans-serif""#, "Ag");
    assert_eq!(named.geometries, generic.geometries);
    let missing = label(r#"font-family="No Such Font""#, "Ag");
    assert_eq!(missing.geometries, named.geometries);
    assert_eq!(missing.warnings.len(), 1, "{:?}", missing.warnings);
    let w = missing.warnings[0].to_string();
    assert!(
        w.contains("'No Such Font' not found") && w.contains("#sn"),
        "{w}"
    );
}

#[test]
fn anchors_transforms_and_tspans_are_laid_out() {
    let start = bbox(&label(r#"font-family="DejaVu Sans""#, "HI"));
    let end = bbox(&label(
        r#"font-family="DejaVu Sans" text-anchor="end""#,
        "HI",
    ));
    // side bearings keep the ink within about a millimetre of the anchor
    assert!((end.max_x - 10.0).abs() < 1.5 && (start.min_x - 10.0).abs() < 1.5);
    assert!(end.max_x < start.min_x);
    let turned = bbox(&label(
        r#"font-family="DejaVu Sans" transform="rotate(90 10 20)""#,
        "HI",
    ));
    assert!(turned.height() > turned.width());
    let two = label(
        r#"font-family="DejaVu Sans""#,
        r#"H<tspan x="10" dy="12">I</tspan>"#,
    );
    assert_eq!(two.geometries.len(), 2);
    assert!(two.geometries[1].bbox().min_y > two.geometries[0].bbox().max_y);
    // a bold request on the bundled regular face is a warning, not a silent substitution
    let bold = label(r#"font-family="DejaVu Sans" font-weight="bold""#, "H");
    assert!(bold
        .warnings
        .iter()
        .any(|w| w.message.contains("weight 700")));
}

#[test]
fn layers_from_top_level_groups() {
    let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" width="10mm" height="10mm" viewBox="0 0 10 10">
<g id="layer1" inkscape:label="Cut"><g><line x1="0" y1="0" x2="1" y2="0" stroke="red"/></g></g>
<g id="engrave"><line x1="0" y1="1" x2="1" y2="1" stroke="red"/></g>
<line x1="0" y1="2" x2="1" y2="2" stroke="#00ff00"/></svg>"##;
    let im = import_svg(svg.as_bytes(), "l.svg", &opts()).unwrap();
    let layers: Vec<&str> = im
        .geometries
        .iter()
        .map(|g| g.source.layer.as_str())
        .collect();
    assert_eq!(layers, ["Cut", "engrave", "#00ff00"]);
}

#[test]
fn label_example_plans_with_every_glyph_outlined() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/examples/label.svg");
    let im = galvoplan::import::import_file(std::path::Path::new(path), &opts()).unwrap();
    // frame + SN 0042-ACME (15) + LOT 7/B (L O T 7 / B: 1+2+1+1+1+3)
    assert_eq!(im.geometries.len(), 1 + 15 + 9);
    let layers: std::collections::BTreeSet<&str> = im
        .geometries
        .iter()
        .map(|g| g.source.layer.as_str())
        .collect();
    assert_eq!(layers.into_iter().collect::<Vec<_>>(), ["Frame", "Text"]);
}

#[test]
fn huge_text_at_a_fine_tolerance_is_an_error_not_gigabytes() {
    // 600 glyphs of a 26 m em: refused by the vertex budget or, as they run past 1 km, by the
    // coordinate bound; either way at once
    let words = "WMB".repeat(200);
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="40mm"><text x="0" y="0" font-size="100000">{words}</text></svg>"#
    );
    let o = ImportOptions {
        chord_tol_mm: 1e-4,
        ..opts()
    };
    let e = import_svg(svg.as_bytes(), "big.svg", &o)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("big.svg: ")
            && (e.contains("flattens to more than") || e.contains("beyond ±1e6 mm")),
        "{e}"
    );
}
