//! Issue 28's corpus (tests/data/hidden/): what the drawing does not show is not marked, what
//! is left out is said, clipping cuts the geometry, placement, readable errors.
//!
//! The SVGs are hand-written (each says in a comment what it draws). The DXFs are written by
//! [`fixtures`] below with the `dxf` crate, with two edits at the group-code level for what the
//! crate cannot write: a frozen layer (it always writes flag 70 = 0) and HATCH entities (it has
//! no HATCH type). `GALVOPLAN_WRITE_FIXTURES=1 cargo test --test hidden` writes them again;
//! otherwise the test checks that the files in the repository are exactly what it writes.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::galvoplan;

use galvoplan::geom::{BBox, Pt};
use galvoplan::import::{
    import_file, FontSource, HiddenLayers, ImportOptions, Imported, LayerHidden, Place,
};
use std::path::{Path, PathBuf};
use std::process::Command;

fn data(name: &str) -> PathBuf {
    common::root().join("tests/data/hidden").join(name)
}

/// The seed000 machine: 300 × 300 mm stroke, 70 × 70 mm field.
fn opts() -> ImportOptions {
    ImportOptions {
        fonts: FontSource::BundledOnly,
        work_area_mm: Some([300.0, 300.0]),
        field_mm: Some([70.0, 70.0]),
        ..ImportOptions::default()
    }
}

fn import(name: &str, o: &ImportOptions) -> Imported {
    import_file(&data(name), o).unwrap()
}

fn warnings(im: &Imported) -> Vec<String> {
    im.warnings.iter().map(|w| w.to_string()).collect()
}

fn length(pts: &[Pt], closed: bool) -> f64 {
    galvoplan::geom::polyline_length(pts, closed)
}

fn close(a: Pt, b: Pt) -> bool {
    a.dist(b) < 1e-6
}

/// Writes the DXFs of the corpus with the `dxf` crate.
mod fixtures {
    use dxf::entities::{Circle, Entity, EntityType, Insert, Line, LwPolyline};
    use dxf::enums::{AcadVersion, Units};
    use dxf::tables::Layer;
    use dxf::{Block, Color, Drawing, LwPolylineVertex, Point};

    fn drawing(units: Units, layers: &[(&str, bool)]) -> Drawing {
        let mut d = Drawing::new();
        d.header.version = AcadVersion::R2000;
        d.header.default_drawing_units = units;
        for &(name, on) in layers {
            d.add_layer(Layer {
                name: name.into(),
                color: Color::from_index(7),
                is_layer_on: on,
                ..Default::default()
            });
        }
        d
    }

    fn on(layer: &str, specific: EntityType) -> Entity {
        let mut e = Entity::new(specific);
        e.common.layer = layer.into();
        e
    }

    fn circle(layer: &str, x: f64, y: f64, r: f64) -> Entity {
        on(
            layer,
            EntityType::Circle(Circle::new(Point::new(x, y, 0.0), r)),
        )
    }

    fn line(layer: &str, a: (f64, f64), b: (f64, f64)) -> Entity {
        on(
            layer,
            EntityType::Line(Line::new(
                Point::new(a.0, a.1, 0.0),
                Point::new(b.0, b.1, 0.0),
            )),
        )
    }

    fn insert(layer: &str, block: &str, x: f64, y: f64) -> Entity {
        on(
            layer,
            EntityType::Insert(Insert {
                name: block.into(),
                location: Point::new(x, y, 0.0),
                ..Default::default()
            }),
        )
    }

    /// The ASCII text, with the header's creation/update times and GUIDs (the crate writes
    /// the clock and random GUIDs) set to fixed values.
    fn text(d: &Drawing) -> String {
        let mut buf = Vec::new();
        d.save(&mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        for i in 0..lines.len().saturating_sub(3) {
            if lines[i].trim() != "9" {
                continue;
            }
            let fixed = match lines[i + 1].trim() {
                "$TDCREATE" | "$TDUCREATE" | "$TDUPDATE" | "$TDUUPDATE" => "2460000.5",
                "$FINGERPRINTGUID" | "$VERSIONGUID" => "{00000000-0000-0000-0000-000000000000}",
                _ => continue,
            };
            lines[i + 3] = fixed.to_string();
        }
        lines.join("\n") + "\n"
    }

    /// Group-code pairs of a DXF text.
    fn pairs(text: &str) -> Vec<(String, String)> {
        let lines: Vec<&str> = text.lines().collect();
        lines
            .chunks(2)
            .map(|c| (c[0].to_string(), c.get(1).unwrap_or(&"").to_string()))
            .collect()
    }

    fn join(pairs: &[(String, String)]) -> String {
        pairs.iter().map(|(c, v)| format!("{c}\n{v}\n")).collect()
    }

    /// Sets flag 70 of the LAYER record `name` to 1 (frozen).
    fn freeze(text: &str, name: &str) -> String {
        let mut p = pairs(text);
        let start = (0..p.len())
            .find(|&i| {
                p[i].0.trim() == "0"
                    && p[i].1 == "LAYER"
                    && p[i + 1..]
                        .iter()
                        .take_while(|q| q.0.trim() != "0")
                        .any(|q| q.0.trim() == "2" && q.1 == name)
            })
            .unwrap();
        let flag = (start + 1..p.len())
            .take_while(|&i| p[i].0.trim() != "0")
            .find(|&i| p[i].0.trim() == "70")
            .unwrap();
        p[flag].1 = format!("{:>6}", 1);
        join(&p)
    }

    /// Replaces the POINT at x = `marker` (see [`marker`]) with a HATCH (handle, layer) on a
    /// triangle.
    fn hatch_for(text: &str, marker: f64, handle: &str, layer: &str) -> String {
        let p = pairs(text);
        let start = (0..p.len())
            .find(|&i| {
                p[i].0.trim() == "0"
                    && p[i].1 == "POINT"
                    && p[i + 1..]
                        .iter()
                        .take_while(|q| q.0.trim() != "0")
                        .any(|q| q.0.trim() == "10" && q.1.trim().parse() == Ok(marker))
            })
            .unwrap();
        let end = (start + 1..p.len())
            .find(|&i| p[i].0.trim() == "0")
            .unwrap();
        let hatch = [
            ("0", "HATCH"),
            ("5", handle),
            ("100", "AcDbEntity"),
            ("8", layer),
            ("100", "AcDbHatch"),
            ("10", "0.0"),
            ("20", "0.0"),
            ("30", "0.0"),
            ("210", "0.0"),
            ("220", "0.0"),
            ("230", "1.0"),
            ("2", "SOLID"),
            ("70", "1"),
            ("71", "0"),
            ("91", "1"),
            ("92", "2"),
            ("72", "1"),
            ("73", "1"),
            ("93", "3"),
            ("10", "0.0"),
            ("20", "0.0"),
            ("10", "4.0"),
            ("20", "0.0"),
            ("10", "0.0"),
            ("20", "4.0"),
            ("97", "0"),
            ("75", "0"),
            ("76", "1"),
            ("98", "0"),
        ];
        let mut out = p[..start].to_vec();
        out.extend(
            hatch
                .iter()
                .map(|(c, v)| (format!("{c:>3}"), v.to_string())),
        );
        out.extend_from_slice(&p[end..]);
        join(&out)
    }

    /// A POINT at x = `id` that [`hatch_for`] replaces by a HATCH.
    fn marker(id: f64) -> Entity {
        on(
            "0",
            EntityType::ModelPoint(dxf::entities::ModelPoint::new(Point::new(id, 0.0, 0.0))),
        )
    }

    /// One visible circle and three hidden ones: on a layer that is off, on a frozen layer,
    /// flagged invisible (mm).
    pub fn hidden_layers() -> String {
        let mut d = drawing(
            Units::Millimeters,
            &[("VISIBLE", true), ("OFF", false), ("FROZEN", true)],
        );
        d.add_entity(circle("VISIBLE", 50.0, 50.0, 10.0));
        d.add_entity(circle("OFF", 100.0, 50.0, 10.0));
        d.add_entity(circle("FROZEN", 150.0, 50.0, 10.0));
        let mut invisible = circle("VISIBLE", 200.0, 50.0, 10.0);
        invisible.common.is_visible = false;
        d.add_entity(invisible);
        freeze(&text(&d), "FROZEN")
    }

    /// Blocks under hidden layers (mm): block DETAIL (a circle on layer 0, a line on VISIBLE, a
    /// HATCH on VISIBLE) inserted on VISIBLE, on OFF and on FROZEN; block UNUSED (a HATCH and a
    /// circle) never inserted; a HATCH in model space on OFF.
    pub fn hidden_blocks() -> String {
        let mut d = drawing(
            Units::Millimeters,
            &[("VISIBLE", true), ("OFF", false), ("FROZEN", true)],
        );
        d.add_block(Block {
            name: "DETAIL".into(),
            layer: "0".into(),
            entities: vec![
                circle("0", 0.0, 0.0, 5.0),
                line("VISIBLE", (-5.0, -5.0), (5.0, 5.0)),
                marker(9001.0),
            ],
            ..Default::default()
        });
        d.add_block(Block {
            name: "UNUSED".into(),
            layer: "0".into(),
            entities: vec![marker(9002.0), circle("VISIBLE", 0.0, 0.0, 2.0)],
            ..Default::default()
        });
        d.add_entity(insert("VISIBLE", "DETAIL", 20.0, 20.0));
        d.add_entity(insert("OFF", "DETAIL", 60.0, 20.0));
        d.add_entity(insert("FROZEN", "DETAIL", 100.0, 20.0));
        d.add_entity(marker(9003.0));
        let t = freeze(&text(&d), "FROZEN");
        let t = hatch_for(&t, 9001.0, "A1", "VISIBLE");
        let t = hatch_for(&t, 9002.0, "A2", "VISIBLE");
        hatch_for(&t, 9003.0, "A3", "OFF")
    }

    /// A 17 × 11 m drawing in metres: its frame and 40 small circles.
    pub fn metres() -> String {
        let mut d = drawing(Units::Meters, &[("FRAME", true)]);
        let v = |x: f64, y: f64| LwPolylineVertex {
            x,
            y,
            ..Default::default()
        };
        let mut frame = LwPolyline {
            vertices: vec![v(0.0, 0.0), v(17.0, 0.0), v(17.0, 11.0), v(0.0, 11.0)],
            ..Default::default()
        };
        frame.set_is_closed(true);
        d.add_entity(on("FRAME", EntityType::LwPolyline(frame)));
        for i in 0..40 {
            let (x, y) = (1.0 + (i % 8) as f64 * 2.0, 1.0 + (i / 8) as f64 * 2.0);
            d.add_entity(circle("FRAME", x, y, 0.1));
        }
        text(&d)
    }
}

#[test]
fn dxf_fixtures_are_what_the_generator_writes() {
    let files = [
        ("hidden-layers.dxf", fixtures::hidden_layers()),
        ("hidden-blocks.dxf", fixtures::hidden_blocks()),
        ("metres.dxf", fixtures::metres()),
    ];
    for (name, text) in files {
        if std::env::var_os("GALVOPLAN_WRITE_FIXTURES").is_some() {
            std::fs::write(data(name), &text).unwrap();
        }
        let stored = std::fs::read_to_string(data(name)).unwrap();
        assert!(
            stored == text,
            "{name} differs from what the generator writes"
        );
    }
}

#[test]
fn dxf_one_visible_circle_of_four_is_marked_and_the_three_hidden_are_warned() {
    let im = import("hidden-layers.dxf", &opts());
    assert_eq!(im.geometries.len(), 1);
    let g = &im.geometries[0];
    assert!(g.closed);
    assert_eq!(g.layer, "VISIBLE");
    let b = g.bbox();
    assert!(
        (b.width() - 20.0).abs() < 0.05 && (b.min_x - 40.0).abs() < 0.05,
        "{b:?}"
    );
    let w = warnings(&im);
    assert_eq!(
        w,
        [
            "layer OFF off: 1 entity skipped (hidden in the drawing)",
            "layer FROZEN frozen: 1 entity skipped (hidden in the drawing)",
            "invisible entities: 1 entity is flagged invisible in the drawing; skipped: CIRCLE \
             (handle 16) (layer VISIBLE)",
        ]
    );
    let skipped: Vec<(&str, LayerHidden, usize)> = im
        .skipped_layers
        .iter()
        .map(|l| (l.name.as_str(), l.why, l.skipped))
        .collect();
    assert_eq!(
        skipped,
        [
            ("OFF", LayerHidden::Off, 1),
            ("FROZEN", LayerHidden::Frozen, 1)
        ]
    );
    // all hidden layers included: three circles; the invisible one stays out
    let all = import(
        "hidden-layers.dxf",
        &ImportOptions {
            hidden_layers: HiddenLayers::IncludeAll,
            ..opts()
        },
    );
    assert_eq!(all.geometries.len(), 3);
    assert_eq!(all.warnings.len(), 1, "{:?}", all.warnings);
    assert!(all.skipped_layers.is_empty());
    // one layer included by name (any case): the GUI's one click
    let one = import(
        "hidden-layers.dxf",
        &ImportOptions {
            hidden_layers: HiddenLayers::Include(vec!["frozen".into()]),
            ..opts()
        },
    );
    let layers: Vec<&str> = one.geometries.iter().map(|g| g.layer.as_str()).collect();
    assert_eq!(layers, ["VISIBLE", "FROZEN"]);
    assert_eq!(one.skipped_layers.len(), 1);
}

#[test]
fn dxf_blocks_under_hidden_layers_show_what_cad_shows_and_unused_blocks_are_quiet() {
    let im = import("hidden-blocks.dxf", &opts());
    // DETAIL on VISIBLE: its circle and line; DETAIL on OFF: only its line (on VISIBLE; the
    // circle on layer 0 takes the insert's layer, off); DETAIL on FROZEN: nothing
    let kinds: Vec<(bool, &str)> = im
        .geometries
        .iter()
        .map(|g| (g.closed, g.layer.as_str()))
        .collect();
    assert_eq!(
        kinds,
        [(true, "VISIBLE"), (false, "VISIBLE"), (false, "VISIBLE")]
    );
    let w = warnings(&im);
    assert_eq!(
        w,
        [
            format!(
                "HATCH (handle A1) in block DETAIL (layer VISIBLE) (line {}): HATCH entities are \
                 not supported; skipped",
                hatch_line("A1")
            )
            .as_str(),
            "layer OFF off: 2 entities skipped (hidden in the drawing)",
            "layer FROZEN frozen: 1 entity skipped (hidden in the drawing)",
        ]
    );
}

/// The line of the HATCH with this handle in hidden-blocks.dxf (the line of its type name).
fn hatch_line(handle: &str) -> usize {
    let text = std::fs::read_to_string(data("hidden-blocks.dxf")).unwrap();
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let at = (0..lines.len())
        .find(|&i| lines[i] == "HATCH" && lines[i + 2] == handle)
        .unwrap();
    at + 1
}

#[test]
fn svg_clipped_rectangle_marks_only_the_part_inside_the_clip() {
    let im = import("clip-rect.svg", &opts());
    assert!(im.warnings.is_empty(), "{:?}", im.warnings);
    assert_eq!(im.geometries.len(), 1);
    let g = &im.geometries[0];
    assert!(!g.closed);
    let want = [
        Pt::new(30.0, 10.0),
        Pt::new(70.0, 10.0),
        Pt::new(70.0, 30.0),
    ];
    assert_eq!(g.points.len(), 3, "{:?}", g.points);
    for (p, q) in g.points.iter().zip(want) {
        assert!(p.dist(q) < 0.05, "{p:?} vs {q:?}");
    }
    assert!((length(&g.points, false) - 60.0).abs() < 0.05);
}

#[test]
fn svg_clip_cases_cut_strokes_and_fills_and_refuse_masks_that_are_not_clips() {
    let im = import("clip-cases.svg", &opts());
    let by = |id: &str| -> Vec<&galvoplan::document::Geometry> {
        im.geometries
            .iter()
            .filter(|g| g.source.element == id)
            .collect()
    };
    // the filled square under a disc clip is the disc: closed, 2π·10 long, centred on (20, 20)
    let filled = by("#filled");
    assert_eq!(filled.len(), 1);
    assert!(filled[0].closed);
    assert!((length(&filled[0].points, true) - 20.0 * std::f64::consts::PI).abs() < 0.05);
    assert!(filled[0]
        .points
        .iter()
        .all(|p| (p.dist(Pt::new(20.0, 20.0)) - 10.0).abs() < 0.05));
    // the left half of a stroked circle (objectBoundingBox units): an open arc, x ≤ 70
    let half = by("#half");
    assert_eq!(half.len(), 1);
    assert!(!half[0].closed);
    assert!((length(&half[0].points, false) - 10.0 * std::f64::consts::PI).abs() < 0.05);
    assert!(half[0].points.iter().all(|p| p.x <= 70.0 + 1e-9));
    let ends = [half[0].points[0], *half[0].points.last().unwrap()];
    assert!(
        ends.iter().any(|&p| close(p, Pt::new(70.0, 10.0))),
        "{ends:?}"
    );
    assert!(
        ends.iter().any(|&p| close(p, Pt::new(70.0, 30.0))),
        "{ends:?}"
    );
    // clip in a translated group's frame, a clipped clip, a mask that is a plain clip
    for (id, a, b) in [
        ("#moved", Pt::new(20.0, 60.0), Pt::new(50.0, 60.0)),
        ("#nested", Pt::new(40.0, 85.0), Pt::new(60.0, 85.0)),
        ("#masked", Pt::new(0.0, 95.0), Pt::new(50.0, 95.0)),
    ] {
        let g = by(id);
        assert_eq!(g.len(), 1, "{id}");
        assert!(
            close(g[0].points[0], a) && close(g[0].points[1], b) && g[0].points.len() == 2,
            "{id}: {:?}",
            g[0].points
        );
    }
    // a grey mask is not a clip: nothing marked, a warning naming the element and the mask
    assert!(by("#faded").is_empty());
    assert_eq!(im.geometries.len(), 5);
    let w = warnings(&im);
    assert_eq!(
        w,
        [
            "#faded (line 33): mask #grey is not a plain clip (a shape that is not opaque white); \
          the masked content was skipped"
        ]
    );
}

#[test]
fn svg_hidden_shapes_layers_and_display_none_are_skipped_and_said() {
    let im = import("visibility.svg", &opts());
    let ids: Vec<&str> = im
        .geometries
        .iter()
        .map(|g| g.source.element.as_str())
        .collect();
    assert_eq!(ids, ["#a", "#c", "#e"]);
    let w = warnings(&im);
    assert_eq!(
        w,
        [
            "<rect id=\"f\"> (line 15): display:none; skipped",
            "layer Engrave hidden (line 17): 2 elements skipped (hidden in the \
             drawing)",
            "visibility:hidden: 2 shapes skipped: #b (line 9); #d (line 12)",
        ]
    );
    assert_eq!(im.skipped_layers.len(), 1);
    assert_eq!(im.skipped_layers[0].why, LayerHidden::Hidden);
    // the hidden layer included: its two circles, on their layer
    let all = import(
        "visibility.svg",
        &ImportOptions {
            hidden_layers: HiddenLayers::IncludeAll,
            ..opts()
        },
    );
    let engrave = all
        .geometries
        .iter()
        .filter(|g| g.layer == "Engrave")
        .count();
    assert_eq!((all.geometries.len(), engrave), (5, 2));
    assert!(all.skipped_layers.is_empty());
}

#[test]
fn svg_broken_use_flowroot_and_clip_reference_are_named_with_their_lines() {
    let im = import("broken-refs.svg", &opts());
    assert_eq!(im.geometries.len(), 1);
    assert_eq!(im.geometries[0].source.element, "#shown");
    let w = warnings(&im);
    assert_eq!(
        w,
        [
            "<use id=\"missing\"> (line 8): refers to #gear, which is not in the file; skipped",
            "<use id=\"external\"> (line 9): refers to 'parts.svg#gear' in another file, which \
             is not read; skipped (put the element in this file)",
            "<flowRoot id=\"flowRoot1\"> (line 10): Inkscape flowed text \"Serial 0042\" is not \
             supported; skipped (in Inkscape: Text ▸ Convert to Text)",
            "<circle id=\"unclipped\"> (line 14): clip-path refers to #lost, which is not in the \
             file; the element was skipped",
        ]
    );
}

#[test]
fn placement_auto_keeps_what_is_in_reach_and_centres_the_331_mm_sheet() {
    let sheet = |place| import("boxes-331x351.svg", &ImportOptions { place, ..opts() });
    let extent = |im: &Imported| {
        im.geometries
            .iter()
            .fold(BBox::EMPTY, |b, g| b.union(g.bbox()))
    };
    // usvg reads coordinates as f32 CSS px: a few 10⁻⁵ mm off at 341 mm
    let near = |got: [f64; 4], want: [f64; 4]| {
        assert!(
            got.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-4),
            "{got:?} vs {want:?}"
        );
    };
    let as_is = sheet(Place::AsIs);
    assert_eq!(as_is.page_mm, [331.0, 351.0]);
    let b = extent(&as_is);
    near(
        [b.min_x, b.min_y, b.max_x, b.max_y],
        [10.0, 10.0, 321.0, 341.0],
    );
    // centred: x −5.5…305.5, y −15.5…315.5, inside the reach −35…335
    for place in [Place::Centre, Place::Auto] {
        let im = sheet(place);
        let [dx, dy] = im.moved_mm;
        near([dx, dy, 0.0, 0.0], [-15.5, -25.5, 0.0, 0.0]);
        let b = extent(&im);
        near(
            [b.min_x, b.min_y, b.max_x, b.max_y],
            [-5.5, -15.5, 305.5, 315.5],
        );
        assert_eq!(im.page_mm, [300.0, 300.0]);
        assert_eq!(
            im.warnings.len(),
            usize::from(place == Place::Auto),
            "{place}"
        );
    }
    let corner = sheet(Place::Corner([0.0, 0.0]));
    let b = extent(&corner);
    assert_eq!([b.min_x, b.min_y], [0.0, 0.0]);
}

fn path(p: &Path) -> String {
    p.display().to_string()
}

#[test]
fn cli_metres_drawing_fails_in_one_line_with_its_size_and_the_reach() {
    let dir = tempfile::tempdir().unwrap();
    let (dxf, gcode) = (path(&data("metres.dxf")), path(&dir.path().join("m.gcode")));
    // --split-oversize cannot help either: no cut is made (once a warning per cut, then a
    // 1.3 MB line)
    for extra in [&[][..], &["--split-oversize"][..]] {
        let out = galvoplan(&[&["plan", &dxf, "-o", &gcode][..], extra].concat());
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{extra:?}: {err}");
        assert!(
            err.starts_with("galvoplan: error: ")
                && err.contains(
                    "the artwork is 17000.0 × 11000.0 mm, 46 times the 370.0 × 370.0 mm the \
                     laser reaches"
                )
                && err.contains("check the drawing's units"),
            "{err}"
        );
        assert!(err.len() < 400, "{err}");
    }
}

#[test]
fn cli_place_centre_plans_the_331_mm_sheet_and_as_is_refuses_it_with_a_suggestion() {
    let dir = tempfile::tempdir().unwrap();
    let sheet = path(&data("boxes-331x351.svg"));
    let gcode = path(&dir.path().join("s.gcode"));
    let report = path(&dir.path().join("s.json"));
    let out = galvoplan(&[
        "plan", &sheet, "-o", &gcode, "--report", &report, "--place", "centre",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("artwork placed (--place centre): moved by (-15.5, -25.5) mm"),
        "{err}"
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["order"].as_array().unwrap().len(), 50);
    let out = galvoplan(&["plan", &sheet, "-o", &gcode, "--place", "as-is"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains(
            "the artwork is 311.0 × 331.0 mm at x 10.0…321.0, y 10.0…341.0 mm, out of reach"
        ) && err.contains("use --place centre"),
        "{err}"
    );
}

#[test]
fn cli_hidden_layers_are_warned_and_included_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let dxf = path(&data("hidden-layers.dxf"));
    let gcode = path(&dir.path().join("h.gcode"));
    let out = galvoplan(&["plan", &dxf, "-o", &gcode]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    // the two hidden layers' warnings say the same, so they are one line naming both
    assert_eq!(err.matches("galvoplan: warning: ").count(), 2, "{err}");
    assert!(
        err.contains("(2 elements: layer OFF off, layer FROZEN frozen)"),
        "{err}"
    );
    assert!(err.contains(": 1 geometry, "), "{err}");
    assert!(
        err.contains("--include-hidden-layers imports the 2 layers"),
        "{err}"
    );
    let out = galvoplan(&["plan", &dxf, "-o", &gcode, "--include-hidden-layers"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_eq!(err.matches("galvoplan: warning: ").count(), 1, "{err}");
    assert!(err.contains(": 3 geometries, "), "{err}");
}

#[test]
fn cli_prints_progress_lines_when_stderr_is_not_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let demo = path(&common::root().join("assets/examples/demo.svg"));
    let out = Command::new(env!("CARGO_BIN_EXE_galvoplan"))
        .args(["plan", &demo, "-o", &path(&dir.path().join("d.gcode"))])
        .args(["--algo", "hga", "--time-limit", "1"])
        .env("GALVOPLAN_PROGRESS_S", "0.05")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let progress: Vec<&str> = err
        .lines()
        .filter(|l| l.contains(" s in this stage, "))
        .collect();
    assert!(progress.len() >= 3, "{err}");
    assert!(
        progress.iter().any(|l| l.starts_with("galvoplan: order ")),
        "{err}"
    );
}

#[test]
fn glyphs_with_an_empty_contour_are_not_warned_about() {
    // DejaVu Sans' "u" has an empty contour besides its outline: it was one "zero length;
    // skipped" warning per letter
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="40mm" viewBox="0 0 100 40"><text id="t" x="5" y="20" font-size="10" font-family="DejaVu Sans">uuu umu</text></svg>"#;
    let o = ImportOptions {
        fonts: FontSource::BundledOnly,
        ..ImportOptions::default()
    };
    let im = galvoplan::import::import_svg(svg.as_bytes(), "u.svg", &o).unwrap();
    assert!(im.warnings.is_empty(), "{:?}", im.warnings);
    assert_eq!(im.geometries.len(), 6);
    assert!(im.geometries.iter().all(|g| g.closed));
}
