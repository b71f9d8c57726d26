//! SVG import through `usvg`: shapes, groups, transforms and `use` resolved; curves flattened.

use super::{ImportError, Warning};
use crate::document::{Geometry, Source};
use crate::geom::{flatten_cubic, flatten_quad, polyline_length, Pt};
use usvg::roxmltree;
use usvg::tiny_skia_path::PathSegment;

/// CSS px (usvg's unit) to mm.
const PX_TO_MM: f64 = 25.4 / 96.0;
/// usvg works in f32 px (relative precision ~6e-8, i.e. ~2e-5 mm at 300 mm): coordinates are
/// snapped to this grid (mm) so that "20" in the file reads as 20.0 and not 20.00000056.
const SNAP_MM: f64 = 1e-5;

fn snap(v: f64) -> f64 {
    (v / SNAP_MM).round() * SNAP_MM
}

/// Subpaths shorter than this (mm) are degenerate: below the exported G-code's resolution.
const MIN_LENGTH_MM: f64 = 1e-3;
/// Points closer than this are one point (mm).
const SAME_POINT_MM: f64 = 1e-6;

/// Import options.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportOptions {
    /// Maximum distance between a curve and its flattened polyline, mm.
    pub chord_tol_mm: f64,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self { chord_tol_mm: 0.01 }
    }
}

/// The result of an import.
#[derive(Debug, Clone, Default)]
pub struct Imported {
    /// Geometries in document order.
    pub geometries: Vec<Geometry>,
    /// Skipped elements and degenerate paths.
    pub warnings: Vec<Warning>,
    /// Page size in mm (width, height).
    pub page_mm: [f64; 2],
}

/// Elements that carry visible content galvoplan cannot mark.
const UNSUPPORTED: &[&str] = &[
    "text",
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
    let mut warnings = unsupported_content(&xml);
    let tree = usvg::Tree::from_xmltree(&xml, &usvg::Options::default())
        .map_err(|e| malformed(e.to_string()))?;
    // usvg stores sizes as f32 px: round to 0.1 µm so that "100mm" reads as 100
    let round = |v: f32| (f64::from(v) * PX_TO_MM * 1e4).round() / 1e4;
    let page_mm = [round(tree.size().width()), round(tree.size().height())];
    let mut walker = Walker {
        tol_px: opts.chord_tol_mm.max(1e-6) / PX_TO_MM,
        geometries: Vec::new(),
        warnings: &mut warnings,
        path_count: 0,
        labels: group_labels(&xml),
        layer: None,
    };
    walker.group(tree.root(), true);
    let geometries = walker.geometries;
    if geometries.is_empty() {
        let detail = if warnings.is_empty() {
            "the file has no paths or shapes".to_string()
        } else {
            let listed: Vec<String> = warnings.iter().take(3).map(|w| w.to_string()).collect();
            let more = warnings.len().saturating_sub(3);
            format!(
                "only skipped content: {}{}",
                listed.join("; "),
                if more > 0 {
                    format!("; and {more} more")
                } else {
                    String::new()
                }
            )
        };
        return Err(ImportError::NothingToMark {
            file: file.into(),
            detail,
        });
    }
    Ok(Imported {
        geometries,
        warnings,
        page_mm,
    })
}

fn describe(node: &roxmltree::Node) -> String {
    match node.attribute("id") {
        Some(id) => format!("<{} id=\"{id}\">", node.tag_name().name()),
        None => format!("<{}>", node.tag_name().name()),
    }
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
    /// `inkscape:label` of groups by id.
    labels: std::collections::HashMap<String, String>,
    /// The layer of the top-level group being walked (its label, else its id).
    layer: Option<String>,
}

/// Inkscape's namespace, whose `label` names a layer.
const INKSCAPE_NS: &str = "http://www.inkscape.org/namespaces/inkscape";

/// `inkscape:label` of every `<g>` with an id and a label.
fn group_labels(xml: &roxmltree::Document) -> std::collections::HashMap<String, String> {
    xml.descendants()
        .filter(|n| n.has_tag_name("g"))
        .filter_map(|n| {
            let label = n.attribute((INKSCAPE_NS, "label"))?;
            Some((n.attribute("id")?.to_string(), label.to_string()))
        })
        .collect()
}

fn paint_hex(paint: &usvg::Paint) -> String {
    match paint {
        usvg::Paint::Color(c) => format!("#{:02x}{:02x}{:02x}", c.red, c.green, c.blue),
        _ => "gradient".into(),
    }
}

impl Walker<'_> {
    /// Walks a group; `top` while no named group encloses it (the first named group on the
    /// way down is the layer).
    fn group(&mut self, g: &usvg::Group, top: bool) {
        for node in g.children() {
            match node {
                usvg::Node::Group(child) if top && !child.id().is_empty() => {
                    let id = child.id();
                    let name = self
                        .labels
                        .get(id)
                        .cloned()
                        .unwrap_or_else(|| id.to_string());
                    let outer = self.layer.replace(name);
                    self.group(child, false);
                    self.layer = outer;
                }
                usvg::Node::Group(child) => self.group(child, top),
                usvg::Node::Path(p) => self.path(p),
                // Text and images were reported from the XML scan, with their line numbers.
                usvg::Node::Image(_) | usvg::Node::Text(_) => {}
            }
        }
    }

    fn path(&mut self, p: &usvg::Path) {
        self.path_count += 1;
        let element = if p.id().is_empty() {
            format!("path #{}", self.path_count)
        } else {
            format!("#{}", p.id())
        };
        let layer = match (p.stroke(), p.fill()) {
            (Some(s), _) => paint_hex(s.paint()),
            (None, Some(f)) => format!("fill {}", paint_hex(f.paint())),
            (None, None) => "none".into(),
        };
        let t = p.abs_transform();
        let map = |q: usvg::tiny_skia_path::Point| -> Pt {
            let (x, y) = (f64::from(q.x), f64::from(q.y));
            Pt::new(
                snap((f64::from(t.sx) * x + f64::from(t.kx) * y + f64::from(t.tx)) * PX_TO_MM),
                snap((f64::from(t.ky) * x + f64::from(t.sy) * y + f64::from(t.ty)) * PX_TO_MM),
            )
        };
        // chord tolerance in mm, applied after the transform
        let tol_mm = self.tol_px * PX_TO_MM;
        let mut subpaths: Vec<(Vec<Pt>, bool)> = Vec::new();
        let mut cur: Vec<Pt> = Vec::new();
        let mut closed = false;
        for seg in p.data().segments() {
            match seg {
                PathSegment::MoveTo(q) => {
                    // a lone point (e.g. the start left behind by Z) is not a subpath
                    if cur.len() > 1 {
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
                        subpaths.push((std::mem::take(&mut cur), true));
                        // a segment after Z starts at the subpath's first point
                        cur.push(first);
                        closed = false;
                    }
                }
            }
        }
        if cur.len() > 1 {
            subpaths.push((cur, closed));
        }
        for (sub_index, (pts, closed)) in subpaths.into_iter().enumerate() {
            let source = Source {
                element: element.clone(),
                subpath: sub_index,
                layer: layer.clone(),
            };
            match normalise(pts, closed) {
                Ok((pts, closed)) => {
                    // the top-level group, else the stroke colour
                    let name = self.layer.as_deref().unwrap_or(&layer);
                    let g = Geometry::new(pts, closed, source).with_layer(name);
                    self.geometries.push(g);
                }
                Err(why) => self.warnings.push(Warning {
                    element: format!("{element} subpath {sub_index}"),
                    line: None,
                    message: format!("{why}; skipped"),
                }),
            }
        }
    }
}

/// Drops repeated points, detects implicit closing, rejects degenerate subpaths.
fn normalise(pts: Vec<Pt>, closed: bool) -> Result<(Vec<Pt>, bool), &'static str> {
    if pts.iter().any(|p| !p.is_finite()) {
        return Err("non-finite coordinates (NaN or infinity)");
    }
    let mut out: Vec<Pt> = Vec::with_capacity(pts.len());
    for p in pts {
        if out.last().is_none_or(|q| q.dist(p) > SAME_POINT_MM) {
            out.push(p);
        }
    }
    let mut closed = closed;
    if out.len() > 2 {
        if let (Some(a), Some(b)) = (out.first(), out.last()) {
            if a.dist(*b) <= SAME_POINT_MM {
                out.pop();
                closed = true;
            }
        }
    }
    if out.len() < 2 || polyline_length(&out, closed) < MIN_LENGTH_MM {
        return Err("zero length (shorter than 1 µm)");
    }
    Ok((out, closed))
}
