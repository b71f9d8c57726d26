//! SVG import through `usvg`: shapes, groups, transforms and `use` resolved; curves flattened;
//! `<text>` laid out with the fonts of [`super::fonts`] and imported as glyph outlines.
//!
//! Only what the drawing shows is imported: `display:none` content and hidden layers (found
//! by [`super::svg_scan`], which also names what usvg drops without a word) and shapes with
//! `visibility:hidden` are skipped with warnings; `clip-path`, and masks that are plain clips
//! (opaque white shapes, or any opaque shapes for `mask-type:alpha`), cut the geometry
//! ([`super::clip`]): strokes at the clip's boundary, fills (closed outlines) to the clipped
//! region. Content under a mask that is not a plain clip is skipped with a warning.

use super::clip::{Region, Rule};
use super::fonts::{family_list, miss_warnings, usvg_options, Misses};
use super::svg_bounds;
use super::svg_scan;
use super::template::{self, svg_template, SvgChunk};
use super::{
    normalise, nothing_to_mark, placed, short_list, ImportError, ImportOptions, Imported,
    TextError, Warning, MAX_COORD_MM, MAX_POINTS,
};
use crate::document::production::is_template;
use crate::document::{Geometry, Source, TextAlign, TextTemplate};
use crate::geom::{cubic_chords, flatten_cubic, flatten_quad, quad_chords, within_reach_bound, Pt};
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
    let parse = |text| {
        roxmltree::Document::parse_with_options(
            text,
            roxmltree::ParsingOptions {
                allow_dtd: true,
                ..Default::default()
            },
        )
        .map_err(|e| malformed(format!("malformed XML: {e}")))
    };
    let xml = parse(text)?;
    let root = xml.root_element();
    if root.tag_name().name() != "svg" {
        return Err(malformed(format!(
            "root element is <{}>, not <svg>",
            root.tag_name().name()
        )));
    }
    svg_bounds::check(&xml).map_err(|e| ImportError::Bounds {
        file: file.into(),
        detail: e.to_string(),
    })?;
    template::check_svg_texts(&xml).map_err(|e| ImportError::Field {
        file: file.into(),
        detail: e.to_string(),
    })?;
    let scan = svg_scan::scan(&xml, &opts.hidden_layers);
    // hidden layers the options include: shown by editing their display (same lines)
    let edited = (!scan.edits.is_empty()).then(|| svg_scan::apply_edits(text, &scan.edits));
    let reparsed = edited.as_deref().map(parse).transpose()?;
    let xml = reparsed.as_ref().unwrap_or(&xml);
    let mut warnings = scan.warnings;
    let (geometries, page_mm, tree_warnings, templates) =
        tree_geometries(xml, opts, opts.chord_tol_mm, MAX_POINTS, true).map_err(|e| match e {
            TreeError::Malformed(cause) => malformed(cause),
            TreeError::TooLarge(element) => ImportError::TooLarge {
                file: file.into(),
                detail: too_many_points(opts.chord_tol_mm, &element),
            },
            TreeError::Beyond(detail) => ImportError::Bounds {
                file: file.into(),
                detail,
            },
        })?;
    warnings.extend(tree_warnings);
    if geometries.is_empty() && templates.is_empty() {
        return Err(nothing_to_mark(
            file,
            &warnings,
            "the file has no paths or shapes",
        ));
    }
    let imported = Imported {
        geometries,
        warnings,
        page_mm,
        skipped_layers: scan.skipped_layers,
        moved_mm: [0.0, 0.0],
        templates,
    };
    placed(imported, file, opts)
}

/// Geometries, page size in mm, font warnings and texts with fields of one usvg tree.
type TreeGeometries = (Vec<Geometry>, [f64; 2], Vec<Warning>, Vec<TextTemplate>);

/// A flattened subpath: points and whether it is closed.
pub(super) type Outline = (Vec<Pt>, bool);

/// Why a usvg tree gave no geometries.
enum TreeError {
    /// usvg's own error.
    Malformed(String),
    /// More vertices than the budget, reached at this element.
    TooLarge(String),
    /// A point beyond [`MAX_COORD_MM`] after transforms: the element and the point.
    Beyond(String),
}

/// Builds the usvg tree of `xml` (text laid out with the options' fonts) and flattens it within
/// `tol_mm` into at most `budget` vertices: the geometries, the page size in mm, the font
/// substitutions as warnings and, with `templates`, the texts holding fields (kept as
/// [`TextTemplate`]s, not outlined; without, every text is outlined as written).
fn tree_geometries(
    xml: &roxmltree::Document,
    opts: &ImportOptions,
    tol_mm: f64,
    budget: usize,
    templates: bool,
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
        id_lines: svg_scan::id_lines(xml),
        text_families: FxHashMap::default(),
        invisible: Vec::new(),
        budget,
        stop: None,
        templates: templates.then(Vec::new),
    };
    walker.group(tree.root(), None, None);
    if let Some(stop) = walker.stop.take() {
        return Err(stop);
    }
    walker.invisible_warning();
    let geometries = std::mem::take(&mut walker.geometries);
    let templates = walker.templates.take().unwrap_or_default();
    let families = std::mem::take(&mut walker.text_families);
    warnings.extend(miss_warnings(misses.take(), |requested| {
        families
            .get(requested)
            .cloned()
            .unwrap_or_else(|| "<text>".into())
    }));
    Ok((geometries, page_mm, warnings, templates))
}

/// The error text of an import beyond [`MAX_POINTS`], reached at `element`.
pub(super) fn too_many_points(tol_mm: f64, element: &str) -> String {
    format!(
        "the drawing flattens to more than {MAX_POINTS} vertices at a chord tolerance of {tol_mm} mm \
         (reached at {element}); raise the chord tolerance or simplify the drawing"
    )
}

/// Glyph outlines of a small SVG made by the DXF text import: `(points, closed)` per subpath in
/// the SVG's mm, flattened within `tol_mm` into at most `budget` vertices, with the font
/// warnings.
pub(super) fn text_outlines(
    svg: &str,
    opts: &ImportOptions,
    tol_mm: f64,
    budget: usize,
) -> Result<(Vec<Outline>, Vec<Warning>), TextError> {
    let xml =
        roxmltree::Document::parse(svg).map_err(|e| TextError::Markup { why: e.to_string() })?;
    let (geometries, _, warnings, _) =
        tree_geometries(&xml, opts, tol_mm, budget, false).map_err(|e| match e {
            TreeError::Malformed(why) => TextError::Layout { why },
            TreeError::Beyond(detail) => TextError::Beyond { detail },
            TreeError::TooLarge(_) => TextError::TooManyPoints { budget },
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

/// What makes a mask more than a plain clip (its content is then skipped with a warning).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
enum MaskError {
    /// A group in the mask with opacity, a mask or filters of its own.
    #[error("groups with opacity, masks or filters")]
    GroupEffects,
    /// A stroked shape in the mask.
    #[error("a stroked shape")]
    Stroked,
    /// A luminance mask's shape that is not opaque white.
    #[error("a shape that is not opaque white")]
    NotOpaqueWhite,
    /// An alpha mask's shape that is not opaque.
    #[error("a shape that is not opaque")]
    NotOpaque,
    /// An image in the mask.
    #[error("an image")]
    Image,
}

struct Walker<'w> {
    tol_px: f64,
    geometries: Vec<Geometry>,
    warnings: &'w mut Vec<Warning>,
    path_count: usize,
    text_count: usize,
    /// Top-level group id → layer name.
    layer_names: FxHashMap<String, String>,
    /// Element id → its line in the file.
    id_lines: FxHashMap<String, u32>,
    /// Shapes skipped for `visibility:hidden`: name and line.
    invisible: Vec<(String, Option<u32>)>,
    /// Requested font family list → the first text element asking for it.
    text_families: FxHashMap<String, String>,
    /// Vertices the walk may still produce.
    budget: usize,
    /// Set when the walk must stop (the budget ran out, or a point lies beyond the bound); it
    /// then adds no more geometry.
    stop: Option<TreeError>,
    /// Texts holding fields, kept as templates (none: every text is outlined as written).
    templates: Option<Vec<TextTemplate>>,
}

fn paint_hex(paint: &usvg::Paint) -> String {
    match paint {
        usvg::Paint::Color(c) => format!("#{:02x}{:02x}{:02x}", c.red, c.green, c.blue),
        _ => "gradient".into(),
    }
}

/// A usvg transform (CSS px) followed by px → mm, snapped to the import's grid.
fn to_mm(t: usvg::Transform) -> impl Fn(usvg::tiny_skia_path::Point) -> Pt {
    move |q| {
        let (x, y) = (f64::from(q.x), f64::from(q.y));
        Pt::new(
            snap((f64::from(t.sx) * x + f64::from(t.kx) * y + f64::from(t.tx)) * PX_TO_MM),
            snap((f64::from(t.ky) * x + f64::from(t.sy) * y + f64::from(t.ty)) * PX_TO_MM),
        )
    }
}

/// A clip or mask shape in errors: `#id`, or what it is.
fn shape_name(p: &usvg::Path) -> String {
    if p.id().is_empty() {
        "a clip or mask shape".into()
    } else {
        format!("#{}", p.id())
    }
}

fn rule(r: usvg::FillRule) -> Rule {
    match r {
        usvg::FillRule::NonZero => Rule::NonZero,
        usvg::FillRule::EvenOdd => Rule::EvenOdd,
    }
}

/// True for a closed outline, by its flag or by its ends meeting.
fn is_ring(pts: &[Pt], closed: bool) -> bool {
    closed
        || (pts.len() > 2
            && pts
                .first()
                .zip(pts.last())
                .is_some_and(|(a, b)| a.dist(*b) <= super::SAME_POINT_MM))
}

impl Walker<'_> {
    /// Walks a group; `layer` is the layer name of the top-level group above, if any, `clip`
    /// the region the groups above clip to.
    fn group(&mut self, g: &usvg::Group, layer: Option<&str>, clip: Option<&Region>) {
        if self.stop.is_some() {
            return;
        }
        let named = self.layer_names.get(g.id()).cloned();
        let layer = named.as_deref().or(layer);
        let mut own: Option<Region> = None;
        if let Some(cp) = g.clip_path() {
            own = self.clip_region(cp, g.abs_transform());
        }
        if let Some(m) = g.mask() {
            match self.mask_region(m, g.abs_transform()) {
                Ok(r) => own = Some(own.map_or(r.clone(), |o| o.intersect(&r))),
                Err(why) => {
                    let (element, line) = self.group_name(g);
                    self.warnings.push(Warning {
                        element,
                        line,
                        message: format!(
                            "mask #{} is not a plain clip ({why}); the masked content was skipped",
                            m.id()
                        ),
                        note: false,
                    });
                    return;
                }
            }
        }
        if self.stop.is_some() {
            return;
        }
        let combined = match (clip, own) {
            (Some(a), Some(b)) => Some(a.intersect(&b)),
            (a, b) => b.or_else(|| a.cloned()),
        };
        let clip = combined.as_ref();
        for node in g.children() {
            match node {
                usvg::Node::Group(child) => self.group(child, layer, clip),
                usvg::Node::Path(p) => {
                    self.path_count += 1;
                    let element = if p.id().is_empty() {
                        format!("path #{}", self.path_count)
                    } else {
                        format!("#{}", p.id())
                    };
                    self.path(p, &element, layer, false, clip);
                }
                usvg::Node::Text(t) => self.text(t, layer, clip),
                // Images were reported from the XML scan, with their line numbers.
                usvg::Node::Image(_) => {}
            }
        }
    }

    /// A name for a group in warnings: its id, else the id of the first element in it with one.
    fn group_name(&self, g: &usvg::Group) -> (String, Option<u32>) {
        fn first_id(g: &usvg::Group) -> Option<String> {
            if !g.id().is_empty() {
                return Some(g.id().to_string());
            }
            g.children().iter().find_map(|n| match n {
                usvg::Node::Group(c) => first_id(c),
                other => (!other.id().is_empty()).then(|| other.id().to_string()),
            })
        }
        match first_id(g) {
            Some(id) => {
                let line = self.id_lines.get(&id).copied();
                (format!("#{id}"), line)
            }
            None => ("an element without id".into(), None),
        }
    }

    /// The region a clip path lets through, for an element whose transform is `base`; `None`
    /// when the vertex budget ran out.
    fn clip_region(&mut self, cp: &usvg::ClipPath, base: usvg::Transform) -> Option<Region> {
        let t = base.pre_concat(cp.transform());
        let mut region = self.filled_region(cp.root(), t)?;
        if let Some(inner) = cp.clip_path() {
            region = region.intersect(&self.clip_region(inner, base)?);
        }
        Some(region)
    }

    /// The union of the fills of a clip path's content (under `t`, the clip path's frame).
    fn filled_region(&mut self, g: &usvg::Group, t: usvg::Transform) -> Option<Region> {
        let mut region = Region::default();
        for node in g.children() {
            let r = match node {
                usvg::Node::Group(child) => {
                    let mut r = self.filled_region(child, t)?;
                    if let Some(cp) = child.clip_path() {
                        r = r
                            .intersect(&self.clip_region(cp, t.pre_concat(child.abs_transform()))?);
                    }
                    r
                }
                usvg::Node::Path(p) if p.is_visible() => {
                    let fill_rule = p.fill().map_or(Rule::NonZero, |f| rule(f.rule()));
                    let contours: Vec<Vec<Pt>> = self
                        .subpaths(p, to_mm(t.pre_concat(p.abs_transform())), &shape_name(p))?
                        .into_iter()
                        .map(|(pts, _)| pts)
                        .collect();
                    Region::filled(&contours, fill_rule)
                }
                usvg::Node::Text(text) => self.filled_region(text.flattened(), t)?,
                _ => continue,
            };
            region = region.union(&r);
        }
        Some(region)
    }

    /// The region a mask lets through when it is a plain clip (opaque white shapes; for
    /// `mask-type:alpha` any opaque shapes), for an element whose transform is `base`; `Err`
    /// with what makes it more than a clip.
    fn mask_region(&mut self, m: &usvg::Mask, base: usvg::Transform) -> Result<Region, MaskError> {
        let r = m.rect();
        let corner = |x: f32, y: f32| to_mm(base)(usvg::tiny_skia_path::Point::from_xy(x, y));
        let rect = Region::quad([
            corner(r.left(), r.top()),
            corner(r.right(), r.top()),
            corner(r.right(), r.bottom()),
            corner(r.left(), r.bottom()),
        ]);
        let content = self.mask_content(m.root(), base, m.kind())?;
        let mut region = content.intersect(&rect);
        if let Some(inner) = m.mask() {
            region = region.intersect(&self.mask_region(inner, base)?);
        }
        Ok(region)
    }

    fn mask_content(
        &mut self,
        g: &usvg::Group,
        base: usvg::Transform,
        kind: usvg::MaskType,
    ) -> Result<Region, MaskError> {
        let mut region = Region::default();
        for node in g.children() {
            let r = match node {
                usvg::Node::Group(child) => {
                    if child.opacity().get() < 1.0
                        || child.mask().is_some()
                        || !child.filters().is_empty()
                    {
                        return Err(MaskError::GroupEffects);
                    }
                    let mut r = self.mask_content(child, base, kind)?;
                    if let Some(cp) = child.clip_path() {
                        let clip = self
                            .clip_region(cp, base.pre_concat(child.abs_transform()))
                            .unwrap_or_default();
                        r = r.intersect(&clip);
                    }
                    r
                }
                usvg::Node::Path(p) => {
                    if !p.is_visible() {
                        continue;
                    }
                    if p.stroke().is_some() {
                        return Err(MaskError::Stroked);
                    }
                    let Some(f) = p.fill() else {
                        continue;
                    };
                    let opaque_white = match f.paint() {
                        usvg::Paint::Color(c) => {
                            f.opacity().get() >= 1.0
                                && (kind == usvg::MaskType::Alpha
                                    || (c.red, c.green, c.blue) == (255, 255, 255))
                        }
                        _ => false,
                    };
                    if !opaque_white {
                        return Err(match kind {
                            usvg::MaskType::Luminance => MaskError::NotOpaqueWhite,
                            usvg::MaskType::Alpha => MaskError::NotOpaque,
                        });
                    }
                    let map = to_mm(base.pre_concat(p.abs_transform()));
                    let Some(subpaths) = self.subpaths(p, map, &shape_name(p)) else {
                        return Ok(Region::default());
                    };
                    let contours: Vec<Vec<Pt>> = subpaths.into_iter().map(|(pts, _)| pts).collect();
                    Region::filled(&contours, rule(f.rule()))
                }
                usvg::Node::Text(t) => self.mask_content(t.flattened(), base, kind)?,
                usvg::Node::Image(_) => return Err(MaskError::Image),
            };
            region = region.union(&r);
        }
        Ok(region)
    }

    /// A text element: its glyph outlines (closed subpaths) as paths named after the element.
    fn text(&mut self, t: &usvg::Text, layer: Option<&str>, clip: Option<&Region>) {
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
        if self.templates.is_some() && t.chunks().iter().any(|c| is_template(c.text())) {
            self.template(t, element, layer);
            return;
        }
        // the outline glyphs (colour glyphs come as groups of their own, not read)
        for node in t.flattened().children() {
            if let usvg::Node::Path(p) = node {
                self.path(p, &element, layer, true, clip);
            }
        }
    }

    /// A text holding fields: one template per chunk (a chunk is a run of text with its own
    /// position), shaped per part later.
    fn template(&mut self, t: &usvg::Text, element: String, layer: Option<&str>) {
        let a = t.abs_transform();
        let transform = [a.sx, a.ky, a.kx, a.sy, a.tx, a.ty].map(f64::from);
        let line = (!t.id().is_empty())
            .then(|| self.id_lines.get(t.id()).copied())
            .flatten();
        let mut made = Vec::new();
        for c in t.chunks() {
            let Some(span) = c.spans().first() else {
                continue;
            };
            if c.text().trim().is_empty() {
                continue;
            }
            let layer = match (layer, span.stroke(), span.fill()) {
                (Some(name), _, _) => name.to_string(),
                (None, Some(s), _) => paint_hex(s.paint()),
                (None, None, Some(f)) => format!("fill {}", paint_hex(f.paint())),
                (None, None, None) => "none".into(),
            };
            let align = match c.anchor() {
                usvg::TextAnchor::Start => TextAlign::Start,
                usvg::TextAnchor::Middle => TextAlign::Middle,
                usvg::TextAnchor::End => TextAlign::End,
            };
            let chunk = SvgChunk {
                text: c.text(),
                at: (
                    f64::from(c.x().unwrap_or(0.0)),
                    f64::from(c.y().unwrap_or(0.0)),
                ),
                align,
                family: family_list(span.font().families()),
                em_px: f64::from(span.font_size().get()),
                transform,
            };
            made.push(svg_template(&chunk, element.clone(), line, layer, PX_TO_MM));
        }
        if let Some(templates) = self.templates.as_mut() {
            templates.extend(made);
        }
    }

    /// The flattened subpaths of a path (`element` names it in errors), `None` when the walk
    /// stops here: a point beyond [`MAX_COORD_MM`] after transforms, or a curve that would take
    /// more vertices than the budget has left (both checked before anything is flattened).
    fn subpaths(
        &mut self,
        p: &usvg::Path,
        map: impl Fn(usvg::tiny_skia_path::Point) -> Pt,
        element: &str,
    ) -> Option<Vec<Outline>> {
        if self.stop.is_some() {
            return None;
        }
        // chord tolerance in mm, applied after the transform
        let tol_mm = self.tol_px * PX_TO_MM;
        let mut subpaths: Vec<Outline> = Vec::new();
        let mut cur: Vec<Pt> = Vec::new();
        let mut closed = false;
        let mut done = 0;
        for seg in p.data().segments() {
            let (ends, chords) = match seg {
                PathSegment::MoveTo(q) | PathSegment::LineTo(q) => ([map(q); 3], 1),
                PathSegment::QuadTo(c, q) => {
                    let p0 = cur.last().copied().unwrap_or_default();
                    let (c, q) = (map(c), map(q));
                    ([c, q, q], quad_chords(p0, c, q, tol_mm))
                }
                PathSegment::CubicTo(c1, c2, q) => {
                    let p0 = cur.last().copied().unwrap_or_default();
                    let (c1, c2, q) = (map(c1), map(c2), map(q));
                    ([c1, c2, q], cubic_chords(p0, c1, c2, q, tol_mm))
                }
                PathSegment::Close => ([cur.first().copied().unwrap_or_default(); 3], 1),
            };
            if let Some(far) = ends.iter().find(|q| !within_reach_bound(**q)) {
                self.stop = Some(TreeError::Beyond(format!(
                    "{element}: a point at ({:e}, {:e}) mm after transforms is beyond \
                     ±{MAX_COORD_MM:e} mm",
                    far.x, far.y
                )));
                return None;
            }
            if chords > self.budget.saturating_sub(done + cur.len()) {
                self.stop = Some(TreeError::TooLarge(element.to_string()));
                return None;
            }
            let [c1, c2, q] = ends;
            match seg {
                PathSegment::MoveTo(_) => {
                    // a lone point (e.g. the start left behind by Z) is not a subpath
                    if cur.len() > 1 {
                        done += cur.len();
                        subpaths.push((std::mem::take(&mut cur), closed));
                    }
                    cur.clear();
                    closed = false;
                    cur.push(q);
                }
                PathSegment::LineTo(_) => cur.push(q),
                PathSegment::QuadTo(..) => {
                    let p0 = cur.last().copied().unwrap_or_default();
                    flatten_quad(p0, c1, q, tol_mm, &mut cur);
                }
                PathSegment::CubicTo(..) => {
                    let p0 = cur.last().copied().unwrap_or_default();
                    flatten_cubic(p0, c1, c2, q, tol_mm, &mut cur);
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
        }
        if cur.len() > 1 {
            done += cur.len();
            subpaths.push((cur, closed));
        }
        self.budget -= done;
        Some(subpaths)
    }

    /// The outlines of a path inside a clip region: a filled path's closed outlines become the
    /// filled area inside the region (its boundary, hatched like any closed outline); strokes
    /// (open outlines, and every outline of an unfilled path) are cut at the region's boundary.
    fn clipped(p: &usvg::Path, subpaths: Vec<Outline>, region: &Region) -> Vec<Outline> {
        let mut out = Vec::new();
        match p.fill() {
            Some(fill) => {
                let (rings, open): (Vec<Outline>, Vec<Outline>) =
                    subpaths.into_iter().partition(|(pts, c)| is_ring(pts, *c));
                let contours: Vec<Vec<Pt>> = rings.iter().map(|(pts, _)| pts.clone()).collect();
                match region.clip_fill(&contours, rule(fill.rule())) {
                    None => out.extend(rings),
                    Some(loops) => out.extend(loops.into_iter().map(|l| (l, true))),
                }
                for (pts, _) in open {
                    match region.clip_stroke(&pts, false) {
                        None => out.push((pts, false)),
                        Some(pieces) => out.extend(pieces.into_iter().map(|q| (q, false))),
                    }
                }
            }
            None => {
                for (pts, closed) in subpaths {
                    match region.clip_stroke(&pts, closed) {
                        None => out.push((pts, closed)),
                        Some(pieces) => out.extend(pieces.into_iter().map(|q| (q, false))),
                    }
                }
            }
        }
        out
    }

    /// A path's outlines as geometries; `glyphs` for the outlines of text (a glyph with an empty
    /// contour, e.g. DejaVu Sans' "u", is not worth a warning); `clip` the region it is clipped
    /// to.
    fn path(
        &mut self,
        p: &usvg::Path,
        element: &str,
        layer: Option<&str>,
        glyphs: bool,
        clip: Option<&Region>,
    ) {
        if self.stop.is_some() {
            return;
        }
        if !p.is_visible() {
            let line = self.id_lines.get(p.id()).copied();
            if !self.invisible.iter().any(|(e, _)| e == element) {
                self.invisible.push((element.to_string(), line));
            }
            return;
        }
        let layer = match (layer, p.stroke(), p.fill()) {
            (Some(name), _, _) => name.to_string(),
            (None, Some(s), _) => paint_hex(s.paint()),
            (None, None, Some(f)) => format!("fill {}", paint_hex(f.paint())),
            (None, None, None) => "none".into(),
        };
        let Some(mut subpaths) = self.subpaths(p, to_mm(p.abs_transform()), element) else {
            return;
        };
        if let Some(region) = clip {
            subpaths = Self::clipped(p, subpaths, region);
        }
        for (sub_index, (pts, closed)) in subpaths.into_iter().enumerate() {
            let source = Source {
                element: element.to_string(),
                subpath: sub_index,
                layer: layer.clone(),
                part: 0,
            };
            match normalise(pts, closed) {
                Ok((pts, closed)) => self.geometries.push(Geometry::new(pts, closed, source)),
                Err(_) if glyphs => {}
                Err(why) => self.warnings.push(Warning {
                    element: format!("{element} subpath {sub_index}"),
                    line: None,
                    message: format!("{why}; skipped"),
                    note: false,
                }),
            }
        }
    }

    /// One warning for the shapes skipped for `visibility:hidden`.
    fn invisible_warning(&mut self) {
        match self.invisible.as_slice() {
            [] => {}
            [(element, line)] => self.warnings.push(Warning {
                element: element.clone(),
                line: *line,
                message: "visibility:hidden; skipped".into(),
                note: false,
            }),
            many => {
                let names: Vec<String> = many
                    .iter()
                    .map(|(e, line)| match line {
                        Some(l) => format!("{e} (line {l})"),
                        None => e.clone(),
                    })
                    .collect();
                self.warnings.push(Warning {
                    element: "visibility:hidden".into(),
                    line: None,
                    message: format!(
                        "{} shapes skipped: {}",
                        many.len(),
                        short_list(&names, "; ")
                    ),
                    note: false,
                });
            }
        }
    }
}
