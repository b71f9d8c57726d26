//! SVG import through `usvg`: shapes, groups, transforms and `use` resolved; curves flattened;
//! `<text>` laid out with the fonts of [`super::fonts`] and imported as glyph outlines.

use super::fonts::{family_list, miss_warnings, usvg_options, Misses};
use super::{
    normalise, nothing_to_mark, ImportError, ImportOptions, Imported, Warning, MAX_POINTS,
};
use crate::document::{Geometry, Source};
use crate::geom::{flatten_cubic, flatten_quad, Pt};
use rustc_hash::FxHashMap;
use usvg::roxmltree;
use usvg::tiny_skia_path::PathSegment;

/// CSS px (usvg's unit) to mm.
pub(super) const PX_TO_MM: f64 = 25.4 / 96.0;
/// usvg works in f32 px (relative precision ~6e-8, i.e. ~2e-5 mm at 300 mm): coordinates are
/// snapped to this grid (mm) so that "20" in the file reads as 20.0 and not 20.00000056.
const SNAP_MM: f64 = 1e-5;

fn snap(v: f64) -> f64 {
    (v / SNAP_MM).round() * SNAP_MM
}

/// Elements that carry visible content galvoplan cannot mark.
const UNSUPPORTED: &[&str] = &[
    "image",
    "foreignObject",
    "video",
    "audio",
    "canvas",
    "iframe",
];
/// Containers whose children are not drawn directly.
const NOT_RENDERED: &[&str] = &[
    "defs", "symbol", "clipPath", "mask", "marker", "pattern", "metadata",
];

/// Reads and imports an SVG (or SVGZ) file.
pub fn import_svg_file(
    path: &std::path::Path,
    opts: &ImportOptions,
) -> Result<Imported, ImportError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        file: file.clone(),
        source,
    })?;
    import_svg(&bytes, &file, opts)
}

/// Imports SVG bytes; `file` names the source in errors and warnings.
pub fn import_svg(bytes: &[u8], file: &str, opts: &ImportOptions) -> Result<Imported, ImportError> {
    let malformed = |cause: String| ImportError::Malformed {
        file: file.into(),
        cause,
    };
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(ImportError::Empty { file: file.into() });
    }
    let unzipped;
    let bytes = if bytes.starts_with(&[0x1f, 0x8b]) {
        unzipped = usvg::decompress_svgz(bytes).map_err(|e| malformed(e.to_string()))?;
        &unzipped[..]
    } else {
        bytes
    };
    let text =
        std::str::from_utf8(bytes).map_err(|e| malformed(format!("not UTF-8 text ({e})")))?;
    let xml = roxmltree::Document::parse_with_options(
        text,
        roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        },
    )
    .map_err(|e| malformed(format!("malformed XML: {e}")))?;
    let root = xml.root_element();
    if root.tag_name().name() != "svg" {
        return Err(malformed(format!(
            "root element is <{}>, not <svg>",
            root.tag_name().name()
        )));
    }
    check_arc_radii(&xml).map_err(malformed)?;
    let mut warnings = unsupported_content(&xml);
    let (geometries, page_mm, font_warnings) =
        tree_geometries(&xml, opts, opts.chord_tol_mm, MAX_POINTS).map_err(|e| match e {
            TreeError::Malformed(cause) => malformed(cause),
            TreeError::TooLarge => ImportError::TooLarge {
                file: file.into(),
                detail: too_many_points(opts.chord_tol_mm),
            },
        })?;
    warnings.extend(font_warnings);
    if geometries.is_empty() {
        return Err(nothing_to_mark(
            file,
            &warnings,
            "the file has no paths or shapes",
        ));
    }
    Ok(Imported {
        geometries,
        warnings,
        page_mm,
    })
}

/// Geometries, page size in mm and font warnings of one usvg tree.
type TreeGeometries = (Vec<Geometry>, [f64; 2], Vec<Warning>);

/// A flattened subpath: points and whether it is closed.
pub(super) type Outline = (Vec<Pt>, bool);

/// Why a usvg tree gave no geometries.
enum TreeError {
    /// usvg's own error.
    Malformed(String),
    /// More vertices than the budget.
    TooLarge,
}

/// Builds the usvg tree of `xml` (text laid out with the options' fonts) and flattens it within
/// `tol_mm` into at most `budget` vertices: the geometries, the page size in mm and the font
/// substitutions as warnings.
fn tree_geometries(
    xml: &roxmltree::Document,
    opts: &ImportOptions,
    tol_mm: f64,
    budget: usize,
) -> Result<TreeGeometries, TreeError> {
    let misses = Misses::default();
    let tree = usvg::Tree::from_xmltree(xml, &usvg_options(opts.fonts, &misses))
        .map_err(|e| TreeError::Malformed(e.to_string()))?;
    // usvg stores sizes as f32 px: round to 0.1 µm so that "100mm" reads as 100
    let round = |v: f32| (f64::from(v) * PX_TO_MM * 1e4).round() / 1e4;
    let page_mm = [round(tree.size().width()), round(tree.size().height())];
    let mut warnings = Vec::new();
    let mut walker = Walker {
        tol_px: tol_mm.max(1e-6) / PX_TO_MM,
        geometries: Vec::new(),
        warnings: &mut warnings,
        path_count: 0,
        text_count: 0,
        layer_names: layer_names(xml),
        text_families: FxHashMap::default(),
        budget,
        overflow: false,
    };
    walker.group(tree.root(), None);
    if walker.overflow {
        return Err(TreeError::TooLarge);
    }
    let geometries = std::mem::take(&mut walker.geometries);
    let families = std::mem::take(&mut walker.text_families);
    warnings.extend(miss_warnings(misses.take(), |requested| {
        families
            .get(requested)
            .cloned()
            .unwrap_or_else(|| "<text>".into())
    }));
    Ok((geometries, page_mm, warnings))
}

/// The error text of an import beyond [`MAX_POINTS`].
pub(super) fn too_many_points(tol_mm: f64) -> String {
    format!("the drawing flattens to more than {MAX_POINTS} vertices at a chord tolerance of {tol_mm} mm")
}

/// Glyph outlines of a small SVG made by the DXF text import: `(points, closed)` per subpath in
/// the SVG's mm, flattened within `tol_mm` into at most `budget` vertices, with the font
/// warnings.
pub(super) fn text_outlines(
    svg: &str,
    opts: &ImportOptions,
    tol_mm: f64,
    budget: usize,
) -> Result<(Vec<Outline>, Vec<Warning>), String> {
    let xml = roxmltree::Document::parse(svg).map_err(|e| e.to_string())?;
    let (geometries, _, warnings) =
        tree_geometries(&xml, opts, tol_mm, budget).map_err(|e| match e {
            TreeError::Malformed(cause) => cause,
            TreeError::TooLarge => format!("more than {budget} vertices"),
        })?;
    let outlines = geometries
        .into_iter()
        .map(|g| (g.points, g.closed))
        .collect();
    Ok((outlines, warnings))
}

/// Layer names of the top-level groups by their `id`: the `inkscape:label` when there is one,
/// else the id itself.
fn layer_names(xml: &roxmltree::Document) -> FxHashMap<String, String> {
    const INKSCAPE: &str = "http://www.inkscape.org/namespaces/inkscape";
    xml.root_element()
        .children()
        .filter(|n| n.is_element() && n.tag_name().name() == "g")
        .filter_map(|n| {
            let id = n.attribute("id")?;
            let label = n.attribute((INKSCAPE, "label")).unwrap_or(id);
            Some((id.to_string(), label.to_string()))
        })
        .collect()
}

fn describe(node: &roxmltree::Node) -> String {
    match node.attribute("id") {
        Some(id) => format!("<{} id=\"{id}\">", node.tag_name().name()),
        None => format!("<{}>", node.tag_name().name()),
    }
}

/// Largest arc radius in path data, in user units (10⁹: 1,000 km in mm, 264 km in px). usvg
/// turns arcs into curves in `f32`, where radii past ~10³⁸ become infinite, and a radius of
/// 10⁴⁰–10¹¹⁷ made it loop for minutes and use gigabytes (found by fuzzing); anything past this
/// bound is not artwork, so the file is refused before usvg sees it.
pub const ARC_RADIUS_MAX: f64 = 1e9;

/// Refuses path data whose arcs have radii beyond [`ARC_RADIUS_MAX`] (or not finite), naming the
/// element and its line. Path data that does not parse is left to usvg (which keeps the part
/// before the error, as the SVG specification asks).
fn check_arc_radii(xml: &roxmltree::Document) -> Result<(), String> {
    for node in xml.descendants().filter(|n| n.is_element()) {
        let Some(d) = node.attribute("d") else {
            continue;
        };
        for segment in svgtypes::PathParser::from(d) {
            let Ok(svgtypes::PathSegment::EllipticalArc { rx, ry, .. }) = segment else {
                continue;
            };
            let worst = rx.abs().max(ry.abs());
            if worst.is_nan() || worst > ARC_RADIUS_MAX {
                let line = xml.text_pos_at(node.range().start).row;
                return Err(format!(
                    "{} (line {line}): an arc radius of {worst:e} user units is beyond {ARC_RADIUS_MAX:e}",
                    describe(&node)
                ));
            }
        }
    }
    Ok(())
}
fn unsupported_content(xml: &roxmltree::Document) -> Vec<Warning> {
    let mut out = Vec::new();
    let mut stack = vec![xml.root_element()];
    while let Some(node) = stack.pop() {
        let name = node.tag_name().name();
        let svg_ns = node
            .tag_name()
            .namespace()
            .is_none_or(|ns| ns == "http://www.w3.org/2000/svg");
        if svg_ns && UNSUPPORTED.contains(&name) {
            let line = xml.text_pos_at(node.range().start).row;
            out.push(Warning {
                element: describe(&node),
                line: Some(line),
                message: format!("<{name}> is not supported and was skipped (convert it to paths)"),
            });
            continue;
        }
        if svg_ns && NOT_RENDERED.contains(&name) {
            continue;
        }
        // reverse so that the stack pops in document order
        let children: Vec<_> = node.children().filter(|c| c.is_element()).collect();
        stack.extend(children.into_iter().rev());
    }
    out
}

struct Walker<'w> {
    tol_px: f64,
    geometries: Vec<Geometry>,
    warnings: &'w mut Vec<Warning>,
    path_count: usize,
    text_count: usize,
    /// Top-level group id → layer name.
    layer_names: FxHashMap<String, String>,
    /// Requested font family list → the first text element asking for it.
    text_families: FxHashMap<String, String>,
    /// Vertices the walk may still produce.
    budget: usize,
    /// Set when the budget ran out (the walk then stops adding geometry).
    overflow: bool,
}

fn paint_hex(paint: &usvg::Paint) -> String {
    match paint {
        usvg::Paint::Color(c) => format!("#{:02x}{:02x}{:02x}", c.red, c.green, c.blue),
        _ => "gradient".into(),
    }
}

impl Walker<'_> {
    /// Walks a group; `layer` is the layer name of the top-level group above, if any.
    fn group(&mut self, g: &usvg::Group, layer: Option<&str>) {
        let named = self.layer_names.get(g.id()).cloned();
        let layer = named.as_deref().or(layer);
        for node in g.children() {
            match node {
                usvg::Node::Group(child) => self.group(child, layer),
                usvg::Node::Path(p) => {
                    self.path_count += 1;
                    let element = if p.id().is_empty() {
                        format!("path #{}", self.path_count)
                    } else {
                        format!("#{}", p.id())
                    };
                    self.path(p, &element, layer);
                }
                usvg::Node::Text(t) => self.text(t, layer),
                // Images were reported from the XML scan, with their line numbers.
                usvg::Node::Image(_) => {}
            }
        }
    }

    /// A text element: its glyph outlines (closed subpaths) as paths named after the element.
    fn text(&mut self, t: &usvg::Text, layer: Option<&str>) {
        self.text_count += 1;
        let element = if t.id().is_empty() {
            format!("text #{}", self.text_count)
        } else {
            format!("#{}", t.id())
        };
        for span in t.chunks().iter().flat_map(|c| c.spans()) {
            self.text_families
                .entry(family_list(span.font().families()))
                .or_insert_with(|| format!("<text> {element}"));
        }
        for node in t.flattened().children() {
            if let usvg::Node::Path(p) = node {
                self.path(p, &element, layer);
            }
        }
    }

    /// The flattened subpaths of a path, `None` when the vertex budget ran out.
    fn subpaths(
        &mut self,
        p: &usvg::Path,
        map: impl Fn(usvg::tiny_skia_path::Point) -> Pt,
    ) -> Option<Vec<Outline>> {
        // chord tolerance in mm, applied after the transform
        let tol_mm = self.tol_px * PX_TO_MM;
        let mut subpaths: Vec<Outline> = Vec::new();
        let mut cur: Vec<Pt> = Vec::new();
        let mut closed = false;
        let mut done = 0;
        for seg in p.data().segments() {
            match seg {
                PathSegment::MoveTo(q) => {
                    // a lone point (e.g. the start left behind by Z) is not a subpath
                    if cur.len() > 1 {
                        done += cur.len();
                        subpaths.push((std::mem::take(&mut cur), closed));
                    }
                    cur.clear();
                    closed = false;
                    cur.push(map(q));
                }
                PathSegment::LineTo(q) => cur.push(map(q)),
                PathSegment::QuadTo(c, q) => {
                    let p0 = cur.last().copied().unwrap_or_default();
                    flatten_quad(p0, map(c), map(q), tol_mm, &mut cur);
                }
                PathSegment::CubicTo(c1, c2, q) => {
                    let p0 = cur.last().copied().unwrap_or_default();
                    flatten_cubic(p0, map(c1), map(c2), map(q), tol_mm, &mut cur);
                }
                PathSegment::Close => {
                    closed = true;
                    if let Some(&first) = cur.first() {
                        done += cur.len();
                        subpaths.push((std::mem::take(&mut cur), true));
                        // a segment after Z starts at the subpath's first point
                        cur.push(first);
                        closed = false;
                    }
                }
            }
            if done + cur.len() > self.budget {
                self.overflow = true;
                return None;
            }
        }
        if cur.len() > 1 {
            done += cur.len();
            subpaths.push((cur, closed));
        }
        self.budget -= done;
        Some(subpaths)
    }

    fn path(&mut self, p: &usvg::Path, element: &str, layer: Option<&str>) {
        if self.overflow {
            return;
        }
        let layer = match (layer, p.stroke(), p.fill()) {
            (Some(name), _, _) => name.to_string(),
            (None, Some(s), _) => paint_hex(s.paint()),
            (None, None, Some(f)) => format!("fill {}", paint_hex(f.paint())),
            (None, None, None) => "none".into(),
        };
        let t = p.abs_transform();
        let map = |q: usvg::tiny_skia_path::Point| -> Pt {
            let (x, y) = (f64::from(q.x), f64::from(q.y));
            Pt::new(
                snap((f64::from(t.sx) * x + f64::from(t.kx) * y + f64::from(t.tx)) * PX_TO_MM),
                snap((f64::from(t.ky) * x + f64::from(t.sy) * y + f64::from(t.ty)) * PX_TO_MM),
            )
        };
        let Some(subpaths) = self.subpaths(p, map) else {
            return;
        };
        for (sub_index, (pts, closed)) in subpaths.into_iter().enumerate() {
            let source = Source {
                element: element.to_string(),
                subpath: sub_index,
                layer: layer.clone(),
            };
            match normalise(pts, closed) {
                Ok((pts, closed)) => self.geometries.push(Geometry::new(pts, closed, source)),
                Err(why) => self.warnings.push(Warning {
                    element: format!("{element} subpath {sub_index}"),
                    line: None,
                    message: format!("{why}; skipped"),
                }),
            }
        }
    }
}
