//! DXF import through the `dxf` crate (ixmilia): lines, polylines with bulges, arcs, circles,
//! ellipses, splines, nested block inserts with arrays, and TEXT/MTEXT as glyph outlines.
//!
//! Coordinates: DXF units (`$INSUNITS`) become mm; DXF's y axis points up, galvoplan's down, so
//! y is flipped about the drawing's top edge (`y_mm = top − y`): the drawing looks as in CAD,
//! never mirrored, and a profile with the G-code Y flip writes the DXF's own coordinates. A
//! drawing in the first quadrant keeps its position relative to the DXF origin (the page's
//! bottom-left corner); one with negative coordinates, or outside the work area although it
//! would fit, is placed by [`super::place_artwork`] like any artwork (`--place`).
//!
//! Hidden content is not marked: entities on layers that are off or frozen, and entities
//! flagged invisible, are skipped with one summary warning per layer (and one for the invisible
//! ones); [`super::HiddenLayers`] imports hidden layers anyway. As in CAD, an INSERT on a layer
//! that is off still shows its block's entities on other layers (those on layer 0 take the
//! insert's layer, and are off with it); an INSERT on a frozen layer shows nothing.

use super::curves::{bulge_arc, fit_point_spline, Affine, ConicArc, Nurbs, SplineProblem};
use super::dxf_scan::{self, ScannedEntity};
use super::dxf_text::{self, TextRun};
use super::fonts::BUNDLED_CAP_HEIGHT_EM;
use super::svg::too_many_points;
use super::svg::Outline;
use super::{
    guard, normalise, nothing_to_mark, placed, ImportError, ImportOptions, Imported, LayerHidden,
    SkippedLayer, Warning, LIST_MAX, MAX_COORD_MM, MAX_GLYPHS, MAX_POINTS,
};
use crate::document::production::{is_template, parse_template};
use crate::document::{Geometry, Source, TextAlign, TextTemplate};
use crate::geom::{cubic_chords, flatten_cubic, BBox, Pt};
use ::dxf::entities::{Entity, EntityType};
use ::dxf::enums::Units;
use ::dxf::{Block, Drawing};
use rustc_hash::{FxHashMap, FxHashSet};
use std::f64::consts::TAU;

/// Budget of entities visited (block instances multiply a block's entities).
const MAX_VISITS: usize = 2_000_000;
/// Budget of block instances (nested arrays multiply).
const MAX_INSTANCES: usize = 1_000_000;
/// Deepest block nesting followed (a block inserting itself is caught earlier).
const MAX_INSERT_DEPTH: usize = 32;
/// Why an entity off the XY plane is skipped.
const OFF_PLANE: &str = "not parallel to the XY plane (3D)";
/// A normal counts as ±Z when its x and y parts are below this (DXF writes unit vectors).
const NORMAL_TOL: f64 = 1e-9;

/// The entity types the `dxf` crate parses (everything else it skips without a word, so the
/// import scans the file for them to report them).
const PARSED_TYPES: &[&str] = &[
    "3DFACE",
    "3DSOLID",
    "ACAD_PROXY_ENTITY",
    "ARC",
    "ARCALIGNEDTEXT",
    "ATTDEF",
    "ATTRIB",
    "BODY",
    "CIRCLE",
    "DIMENSION",
    "ELLIPSE",
    "HELIX",
    "IMAGE",
    "INSERT",
    "LEADER",
    "LIGHT",
    "LINE",
    "3DLINE",
    "LWPOLYLINE",
    "MLINE",
    "MTEXT",
    "OLEFRAME",
    "OLE2FRAME",
    "POINT",
    "POLYLINE",
    "RAY",
    "REGION",
    "RTEXT",
    "SECTION",
    "SEQEND",
    "SHAPE",
    "SOLID",
    "SPLINE",
    "TEXT",
    "TOLERANCE",
    "TRACE",
    "DGNUNDERLAY",
    "DWFUNDERLAY",
    "PDFUNDERLAY",
    "VERTEX",
    "WIPEOUT",
    "XLINE",
    "ENDSEC",
    "BLOCK",
    "ENDBLK",
    "EOF",
];

/// Imports DXF bytes (ASCII or binary); `file` names the source in errors and warnings.
pub fn import_dxf(bytes: &[u8], file: &str, opts: &ImportOptions) -> Result<Imported, ImportError> {
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(ImportError::Empty { file: file.into() });
    }
    let drawing = load(bytes, file)?;
    let scanned = dxf_scan::scan(bytes, |kind| !PARSED_TYPES.contains(&kind));
    let hidden = hidden_layers(scanned.layers, opts);
    let unparsed = scanned.entities;
    let mut warnings = Vec::new();
    let unit_mm = units_mm(drawing.header.default_drawing_units, &mut warnings);
    let mut walk = Walk {
        file,
        opts,
        blocks: drawing.blocks().map(|b| (b.name.as_str(), b)).collect(),
        drawing: &drawing,
        raw: Vec::new(),
        warnings,
        points: 0,
        instances: 0,
        stack: Vec::new(),
        visits: 0,
        warned: FxHashSet::default(),
        hidden,
        skipped: Vec::new(),
        invisible: 0,
        invisible_listed: Vec::new(),
        inserted: FxHashSet::default(),
        glyphs: 0,
        templates: Vec::new(),
        mtext: scanned.mtext.into_iter().collect(),
    };
    let to_mm = Affine::scale(unit_mm, unit_mm);
    for e in drawing.entities() {
        walk.entity(e, &to_mm, None)?;
    }
    let mut warnings = walk.unparsed_warnings(unparsed);
    let (summaries, skipped_layers) = walk.hidden_summaries();
    let Walk {
        raw,
        warnings: walked,
        templates,
        ..
    } = walk;
    warnings.extend(walked);
    warnings.extend(summaries);
    if raw.is_empty() && templates.is_empty() {
        return Err(nothing_to_mark(
            file,
            &warnings,
            "the drawing has no entities",
        ));
    }
    let (geometries, page_mm) = flip(raw);
    // the templates flipped as the geometries: y_mm = page height − y
    let flip_y = Affine {
        m: [1.0, 0.0, 0.0, -1.0, 0.0, page_mm[1]],
    };
    let templates = templates
        .into_iter()
        .map(|mut t| {
            t.frame = flip_y.then(Affine { m: t.frame }).m;
            t
        })
        .collect();
    let imported = Imported {
        geometries,
        warnings,
        page_mm,
        skipped_layers,
        moved_mm: [0.0, 0.0],
        templates,
    };
    placed(imported, file, opts)
}

/// The layers the drawing hides and the import skips (by upper-case name): off or frozen in
/// the layer table and not named by `opts.hidden_layers`.
fn hidden_layers(
    layers: Vec<(String, dxf_scan::LayerState)>,
    opts: &ImportOptions,
) -> FxHashMap<String, LayerHidden> {
    layers
        .into_iter()
        .filter_map(|(name, state)| {
            let why = match (state.off, state.frozen) {
                (false, false) => return None,
                (true, false) => LayerHidden::Off,
                (false, true) => LayerHidden::Frozen,
                (true, true) => LayerHidden::OffAndFrozen,
            };
            (!opts.hidden_layers.includes(&name)).then(|| (name.to_uppercase(), why))
        })
        .collect()
}

/// Parses the drawing; the reader's errors and panics (it has some on malformed headers) become
/// one-line errors with the position: the reader's own, or the line (ASCII) or byte (binary) it
/// had read up to when it failed.
fn load(bytes: &[u8], file: &str) -> Result<Drawing, ImportError> {
    let mut reader = Counting { bytes, pos: 0 };
    let malformed = |cause: String| ImportError::MalformedDxf {
        file: file.into(),
        cause: one_line(&cause),
    };
    match guard::catch_quietly(|| Drawing::load(&mut reader)) {
        Ok(Ok(drawing)) => Ok(drawing),
        Ok(Err(e)) => Err(malformed(e.to_string())),
        Err(panic) => {
            let read = &bytes[..reader.pos.min(bytes.len())];
            let at = if read.starts_with(b"AutoCAD Binary DXF") {
                format!("byte {}", reader.pos)
            } else {
                format!("line {}", read.iter().filter(|&&b| b == b'\n').count() + 1)
            };
            Err(malformed(format!(
                "the DXF reader failed near {at} ({panic})"
            )))
        }
    }
}

/// A reader over bytes that knows how far it has been read.
struct Counting<'b> {
    bytes: &'b [u8],
    pos: usize,
}

impl std::io::Read for Counting<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        let n = rest.len().min(buf.len());
        buf[..n].copy_from_slice(&rest[..n]);
        self.pos += n;
        Ok(n)
    }
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// mm per drawing unit from `$INSUNITS`; unitless and unknown units read as mm with a warning.
fn units_mm(units: Units, warnings: &mut Vec<Warning>) -> f64 {
    let known = match units {
        Units::Millimeters => Some(1.0),
        Units::Centimeters => Some(10.0),
        Units::Meters => Some(1000.0),
        Units::Decimeters => Some(100.0),
        Units::Microns => Some(1e-3),
        Units::Inches => Some(25.4),
        Units::Feet => Some(304.8),
        Units::Mils => Some(0.0254),
        Units::Yards => Some(914.4),
        _ => None,
    };
    known.unwrap_or_else(|| {
        let why = if units == Units::Unitless {
            "the drawing has no units ($INSUNITS unitless)".to_string()
        } else {
            format!("drawing units {units:?} ($INSUNITS) are not supported")
        };
        warnings.push(Warning {
            element: "$INSUNITS".into(),
            line: None,
            message: format!("{why}; read as millimetres"),
            note: false,
        });
        1.0
    })
}

/// A flattened path in mm, y up, before placement.
struct Raw {
    points: Vec<Pt>,
    closed: bool,
    source: Source,
}

struct Walk<'d> {
    file: &'d str,
    opts: &'d ImportOptions,
    blocks: FxHashMap<&'d str, &'d Block>,
    drawing: &'d Drawing,
    raw: Vec<Raw>,
    warnings: Vec<Warning>,
    points: usize,
    instances: usize,
    /// Names of the blocks being inserted, outermost first.
    stack: Vec<&'d str>,
    /// Entities visited (instances count again).
    visits: usize,
    /// Warnings given, by element and message.
    warned: FxHashSet<(String, String)>,
    /// Hidden layers skipped, by upper-case name.
    hidden: FxHashMap<String, LayerHidden>,
    /// Entities skipped per hidden layer (name as the entity writes it), in order of the first.
    skipped: Vec<(String, LayerHidden, usize)>,
    /// Entities skipped because they are flagged invisible (each block instance counted).
    invisible: usize,
    /// The first few of them, each named once.
    invisible_listed: Vec<String>,
    /// Blocks inserted where the drawing shows them (upper-case names).
    inserted: FxHashSet<String>,
    /// Characters of text laid out so far (each block instance counted).
    glyphs: usize,
    /// Texts holding fields, in the drawing's y-up mm.
    templates: Vec<TextTemplate>,
    /// Each MTEXT's text as the file writes it, by handle (see `dxf_scan::Scan::mtext`).
    mtext: FxHashMap<String, String>,
}

/// The DXF name of an entity type (its variant name in capitals for the rare ones).
fn type_name(t: &EntityType) -> String {
    let name = match t {
        EntityType::Line(_) => "LINE",
        EntityType::LwPolyline(_) => "LWPOLYLINE",
        EntityType::Polyline(_) => "POLYLINE",
        EntityType::Arc(_) => "ARC",
        EntityType::Circle(_) => "CIRCLE",
        EntityType::Ellipse(_) => "ELLIPSE",
        EntityType::Spline(_) => "SPLINE",
        EntityType::Insert(_) => "INSERT",
        EntityType::Text(_) => "TEXT",
        EntityType::MText(_) => "MTEXT",
        EntityType::ModelPoint(_) => "POINT",
        EntityType::Image(_) => "IMAGE",
        EntityType::Solid(_) => "SOLID",
        EntityType::Face3D(_) => "3DFACE",
        EntityType::Solid3D(_) => "3DSOLID",
        other => {
            let debug = format!("{other:?}");
            return debug
                .split(['(', ' ', '{'])
                .next()
                .unwrap_or("entity")
                .to_ascii_uppercase();
        }
    };
    name.to_string()
}

/// The map from an entity's object coordinate system to world coordinates: identity for a +Z
/// normal, a mirror in x for −Z (DXF's arbitrary axis algorithm); `None` off the XY plane.
fn ocs(normal: &::dxf::Vector) -> Option<Affine> {
    if normal.x.abs() > NORMAL_TOL || normal.y.abs() > NORMAL_TOL || !normal.z.is_finite() {
        return None;
    }
    Some(if normal.z < 0.0 {
        Affine::scale(-1.0, 1.0)
    } else {
        Affine::IDENTITY
    })
}

fn pt(p: &::dxf::Point) -> Pt {
    Pt::new(p.x, p.y)
}

impl<'d> Walk<'d> {
    fn element(&self, kind: &str, e: &Entity) -> String {
        let mut s = format!("{kind} (handle {:X})", e.common.handle.0);
        if let Some(block) = self.stack.last() {
            s.push_str(&format!(" in block {block}"));
        }
        s
    }

    /// How the drawing hides `layer`, when the import skips it.
    fn hidden_layer(&self, layer: &str) -> Option<LayerHidden> {
        if self.hidden.is_empty() {
            return None;
        }
        self.hidden.get(&layer.to_uppercase()).copied()
    }

    /// Counts one entity skipped because it is flagged invisible.
    fn skip_invisible(&mut self, element: String) {
        self.invisible += 1;
        if self.invisible_listed.len() < LIST_MAX && !self.invisible_listed.contains(&element) {
            self.invisible_listed.push(element);
        }
    }

    /// Counts one entity skipped with its hidden layer.
    fn skip_hidden(&mut self, layer: &str, why: LayerHidden) {
        match self
            .skipped
            .iter_mut()
            .find(|(name, _, _)| name.eq_ignore_ascii_case(layer))
        {
            Some((_, _, n)) => *n += 1,
            None => self.skipped.push((layer.to_string(), why, 1)),
        }
    }

    /// Warnings for the entity types the `dxf` crate does not read: those in blocks the drawing
    /// never shows (not inserted, or only under a frozen or invisible insert) are dropped, hidden
    /// and invisible ones are counted with the other hidden entities, the rest name their block.
    fn unparsed_warnings(&mut self, unparsed: Vec<ScannedEntity>) -> Vec<Warning> {
        let mut out = Vec::new();
        for e in unparsed {
            if let Some(b) = &e.block {
                if !self.inserted.contains(&b.to_uppercase()) {
                    continue;
                }
            }
            let mut element = format!("{} (handle {})", e.kind, e.handle);
            if let Some(b) = &e.block {
                element.push_str(&format!(" in block {b}"));
            }
            if e.invisible {
                self.skip_invisible(format!("{element} (layer {})", e.layer));
                continue;
            }
            if let Some(why) = self.hidden_layer(&e.layer) {
                self.skip_hidden(&e.layer, why);
                continue;
            }
            out.push(Warning {
                element: format!("{element} (layer {})", e.layer),
                line: e.line,
                message: format!("{} entities are not supported; skipped", e.kind),
                note: false,
            });
        }
        out
    }

    /// One warning per hidden layer and one for the invisible entities; the skipped layers.
    fn hidden_summaries(&self) -> (Vec<Warning>, Vec<SkippedLayer>) {
        let mut out = Vec::new();
        let mut layers = Vec::new();
        for (name, why, n) in &self.skipped {
            let what = if *n == 1 { "entity" } else { "entities" };
            out.push(Warning {
                element: format!("layer {name} {why}"),
                line: None,
                message: format!("{n} {what} skipped (hidden in the drawing)"),
                note: false,
            });
            layers.push(SkippedLayer {
                name: name.clone(),
                why: *why,
                skipped: *n,
            });
        }
        let n = self.invisible;
        if n > 0 {
            let listed = self.invisible_listed.join("; ");
            let more = n - self.invisible_listed.len();
            let tail = if more > 0 {
                format!("; … and {more} more")
            } else {
                String::new()
            };
            out.push(Warning {
                element: "invisible entities".into(),
                line: None,
                message: format!(
                    "{n} {} flagged invisible in the drawing; skipped: {listed}{tail}",
                    if n == 1 { "entity is" } else { "entities are" },
                ),
                note: false,
            });
        }
        (out, layers)
    }

    /// Adds a warning once (a block's entity warns once, not once per insert).
    fn warn(&mut self, element: String, layer: &str, message: impl Into<String>) {
        self.warn_or_note(element, layer, message, false);
    }

    /// [`Self::warn`], or a note (`note`: recorded, not listed among the warnings).
    fn warn_or_note(
        &mut self,
        element: String,
        layer: &str,
        message: impl Into<String>,
        note: bool,
    ) {
        let w = Warning {
            element: format!("{element} (layer {layer})"),
            line: None,
            message: message.into(),
            note,
        };
        if self.warned.insert((w.element.clone(), w.message.clone())) {
            self.warnings.push(w);
        }
    }

    /// Imports one entity under the map `m` (entity coordinates → mm, y up); `parent_layer` is
    /// the layer of the insert above (block entities on layer 0 take it, as in CAD).
    fn entity(
        &mut self,
        e: &'d Entity,
        m: &Affine,
        parent_layer: Option<&str>,
    ) -> Result<(), ImportError> {
        let layer = match parent_layer {
            Some(p) if e.common.layer == "0" => p.to_string(),
            _ => e.common.layer.clone(),
        };
        self.visits += 1;
        if self.visits > MAX_VISITS {
            return Err(ImportError::TooLarge {
                file: self.file.into(),
                detail: format!("more than {MAX_VISITS} entities with the blocks expanded"),
            });
        }
        let kind = type_name(&e.specific);
        let element = self.element(&kind, e);
        if e.common.is_in_paper_space {
            let why = "paper-space entity; skipped (only model space is marked)";
            self.warn(element, &layer, why);
            return Ok(());
        }
        if !e.common.is_visible {
            self.skip_invisible(format!("{element} (layer {layer})"));
            return Ok(());
        }
        if let Some(why) = self.hidden_layer(&layer) {
            // an INSERT on a layer that is off still shows its block's entities on other layers
            let shows_block =
                why == LayerHidden::Off && matches!(e.specific, EntityType::Insert(_));
            if !shows_block {
                self.skip_hidden(&layer, why);
                return Ok(());
            }
        }
        let tol = self.opts.chord_tol_mm.max(1e-6);
        match curve_paths(&e.specific, m, tol) {
            Ok(Some(paths)) => return self.push_paths(paths, &element, &layer),
            Err(CurveError::Beyond) => return Err(self.beyond(&element, &layer)),
            Err(why) => {
                self.warn(element, &layer, format!("{why}; skipped"));
                return Ok(());
            }
            Ok(None) => {}
        }
        let mut paths = Vec::new();
        match &e.specific {
            EntityType::Polyline(p) => self.polyline(e, p, m, tol, &layer, &mut paths),
            EntityType::Insert(ins) => return self.insert(e, ins, m, &layer),
            EntityType::Text(t) => {
                let run = dxf_text::text_run(t, self.drawing, self.opts);
                self.text(run, ocs(&t.normal), m, &element, &layer, &mut paths)?;
            }
            EntityType::MText(t) => {
                let handle = format!("{:X}", e.common.handle.0);
                let raw = self.mtext.get(&handle).map(String::as_str);
                let run = dxf_text::mtext_run(t, raw, self.drawing, self.opts);
                let o = ocs(&t.extrusion_direction);
                self.text(run, o, m, &element, &layer, &mut paths)?;
            }
            EntityType::ModelPoint(_) => {
                self.warn(element, &layer, "a point has nothing to mark; skipped");
                return Ok(());
            }
            _ => {
                let why = format!("{kind} entities are not supported; skipped");
                self.warn(element, &layer, why);
                return Ok(());
            }
        }
        self.push_paths(paths, &element, &layer)
    }

    fn polyline(
        &mut self,
        e: &Entity,
        p: &::dxf::entities::Polyline,
        m: &Affine,
        tol: f64,
        layer: &str,
        paths: &mut Vec<Outline>,
    ) {
        const CLOSED: i32 = 1;
        const IS_3D: i32 = 8;
        const MESH: i32 = 16 | 64;
        const FRAME_CONTROL_POINT: i32 = 16;
        let element = self.element("POLYLINE", e);
        if p.flags & MESH != 0 {
            self.warn(
                element,
                layer,
                "polygon and polyface meshes (3D) are not supported; skipped",
            );
            return;
        }
        let m = if p.flags & IS_3D != 0 {
            if p.vertices().any(|v| v.location.z != 0.0) {
                self.warn(
                    element.clone(),
                    layer,
                    "3D polyline projected onto the XY plane",
                );
            }
            *m
        } else {
            match ocs(&p.normal) {
                Some(o) => m.then(o),
                None => {
                    self.warn(element, layer, "not parallel to the XY plane (3D); skipped");
                    return;
                }
            }
        };
        let v: Vec<(Pt, f64)> = p
            .vertices()
            .filter(|v| v.flags & FRAME_CONTROL_POINT == 0)
            .map(|v| (pt(&v.location), v.bulge))
            .collect();
        paths.push(bulge_path(&v, p.flags & CLOSED != 0, &m, tol));
    }

    fn insert(
        &mut self,
        e: &'d Entity,
        ins: &'d ::dxf::entities::Insert,
        m: &Affine,
        layer: &str,
    ) -> Result<(), ImportError> {
        let element = self.element("INSERT", e);
        let Some(&block) = self.blocks.get(ins.name.as_str()) else {
            self.warn(
                element,
                layer,
                format!("block '{}' is not defined; skipped", ins.name),
            );
            return Ok(());
        };
        if self.stack.contains(&block.name.as_str()) || self.stack.len() >= MAX_INSERT_DEPTH {
            self.warn(
                element,
                layer,
                format!(
                    "block '{}' inserts itself (or nests deeper than {MAX_INSERT_DEPTH}); skipped",
                    ins.name
                ),
            );
            return Ok(());
        }
        let Some(o) = ocs(&ins.extrusion_direction) else {
            self.warn(element, layer, "not parallel to the XY plane (3D); skipped");
            return Ok(());
        };
        if ins.attributes().next().is_some() {
            self.warn(
                element.clone(),
                layer,
                "block attributes (ATTRIB) are not imported",
            );
        }
        let place = m
            .then(o)
            .then(Affine::translate(ins.location.x, ins.location.y))
            .then(Affine::rotate(ins.rotation.to_radians()));
        let scale = Affine::scale(ins.x_scale_factor, ins.y_scale_factor)
            .then(Affine::translate(-block.base_point.x, -block.base_point.y));
        let (cols, rows) = (ins.column_count.max(1), ins.row_count.max(1));
        self.inserted.insert(block.name.to_uppercase());
        self.stack.push(block.name.as_str());
        for row in 0..rows {
            for col in 0..cols {
                self.instances += 1;
                if self.instances > MAX_INSTANCES {
                    return Err(ImportError::TooLarge {
                        file: self.file.into(),
                        detail: format!(
                            "more than {MAX_INSTANCES} block instances (nested INSERT arrays)"
                        ),
                    });
                }
                let cell = Affine::translate(
                    f64::from(col) * ins.column_spacing,
                    f64::from(row) * ins.row_spacing,
                );
                let inner = place.then(cell).then(scale);
                for child in &block.entities {
                    self.entity(child, &inner, Some(layer))?;
                }
            }
        }
        self.stack.pop();
        Ok(())
    }

    fn text(
        &mut self,
        run: TextRun,
        ocs: Option<Affine>,
        m: &Affine,
        element: &str,
        layer: &str,
        paths: &mut Vec<Outline>,
    ) -> Result<(), ImportError> {
        let Some(o) = ocs else {
            self.warn(element.to_string(), layer, OFF_PLANE);
            return Ok(());
        };
        let frame = m.then(o).then(run.frame);
        let scale = frame_scale(&frame);
        let height_mm = run.height * scale;
        if !height_mm.is_finite() || height_mm > MAX_COORD_MM {
            return Err(self.beyond(element, layer));
        }
        self.glyphs += run
            .lines
            .iter()
            .map(|l| l.chars().filter(|c| !c.is_whitespace()).count())
            .sum::<usize>();
        if self.glyphs > MAX_GLYPHS {
            return Err(ImportError::Bounds {
                file: self.file.into(),
                detail: format!(
                    "{element} on layer {layer}: the drawing's text reaches {} characters, \
                     beyond the {MAX_GLYPHS} galvoplan lays out in one file",
                    self.glyphs
                ),
            });
        }
        if run.lines.iter().any(|l| is_template(l)) {
            return self.template(&run, &frame, element, layer);
        }
        let tol_local = self.opts.chord_tol_mm.max(1e-6) / scale.max(1e-12);
        let budget = MAX_POINTS.saturating_sub(self.points);
        match dxf_text::outlines(&run, self.opts, tol_local, budget) {
            Ok((outlines, warnings)) => {
                for w in warnings {
                    self.warn_or_note(element.to_string(), layer, w.message, w.note);
                }
                paths.extend(
                    outlines
                        .into_iter()
                        .map(|(p, closed)| (p.iter().map(|&q| frame.apply(q)).collect(), closed)),
                );
            }
            Err(why) => self.warn(
                element.to_string(),
                layer,
                format!("text not laid out: {why}; skipped"),
            ),
        }
        Ok(())
    }

    /// A TEXT or MTEXT holding fields (read after MTEXT's own codes are stripped), kept as a
    /// template in the drawing's y-up mm (`frame`: text frame → mm); the import flips it with
    /// the geometries.
    fn template(
        &mut self,
        run: &TextRun,
        frame: &Affine,
        element: &str,
        layer: &str,
    ) -> Result<(), ImportError> {
        let text = run.lines.join("\n");
        if let Err(why) = parse_template(&text) {
            return Err(ImportError::Field {
                file: self.file.into(),
                detail: format!("{element} on layer {layer} text \"{text}\": {why}"),
            });
        }
        let (h, v) = run.anchor;
        self.templates.push(TextTemplate {
            text,
            element: element.to_string(),
            line: None,
            layer: layer.to_string(),
            family: run.family.clone(),
            em: run.height / BUNDLED_CAP_HEIGHT_EM,
            pitch: run.pitch,
            align: match h {
                dxf_text::HAnchor::Start => TextAlign::Start,
                dxf_text::HAnchor::Middle => TextAlign::Middle,
                dxf_text::HAnchor::End => TextAlign::End,
            },
            first_baseline: dxf_text::first_baseline(run.lines.len(), run.height, run.pitch, v),
            frame: frame.m,
        });
        Ok(())
    }

    /// The error for an entity beyond [`MAX_COORD_MM`]: the file is refused, naming it.
    fn beyond(&self, element: &str, layer: &str) -> ImportError {
        ImportError::Bounds {
            file: self.file.into(),
            detail: format!(
                "{element} on layer {layer}: {BEYOND}; galvoplan reads drawings within it"
            ),
        }
    }

    fn push_paths(
        &mut self,
        paths: Vec<(Vec<Pt>, bool)>,
        element: &str,
        layer: &str,
    ) -> Result<(), ImportError> {
        for (subpath, (points, closed)) in paths.into_iter().enumerate() {
            self.points += points.len();
            if self.points > MAX_POINTS {
                return Err(ImportError::TooLarge {
                    file: self.file.into(),
                    detail: too_many_points(self.opts.chord_tol_mm, element),
                });
            }
            if !points.iter().all(|&p| bounded(p)) {
                return Err(self.beyond(element, layer));
            }
            match normalise(points, closed) {
                Ok((points, closed)) => self.raw.push(Raw {
                    points,
                    closed,
                    source: Source {
                        element: element.to_string(),
                        subpath,
                        layer: layer.to_string(),
                        part: 0,
                    },
                }),
                Err(why) => self.warn(
                    format!("{element} subpath {subpath}"),
                    layer,
                    format!("{why}; skipped"),
                ),
            }
        }
        Ok(())
    }
}

/// Why a curve entity is not imported: [`CurveError::Beyond`] refuses the file, the others skip
/// the entity with a warning.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum CurveError {
    /// A point, radius or text height past [`MAX_COORD_MM`].
    #[error("{}", BEYOND)]
    Beyond,
    /// Not in the XY plane.
    #[error("{}", OFF_PLANE)]
    OffPlane,
    /// A spline of negative degree.
    #[error("negative degree")]
    NegativeDegree,
    /// A spline whose definition does not hold (counts, knots, weights).
    #[error("invalid spline: {0}")]
    InvalidSpline(SplineProblem),
    /// A spline that cannot be flattened (its reason).
    #[error("{0}")]
    Flatten(&'static str),
    /// A fit-point spline that flattens to more than [`MAX_POINTS`] vertices.
    #[error(
        "flattens to more than {MAX_POINTS} vertices at a chord tolerance of {tol} drawing \
         units; raise the chord tolerance"
    )]
    TooManyPoints {
        /// The chord tolerance, drawing units.
        tol: f64,
    },
    /// A spline with neither control points nor fit points.
    #[error("spline without control points or fit points")]
    Empty,
}

/// The paths of a curve entity (LINE, LWPOLYLINE, ARC, CIRCLE, ELLIPSE, SPLINE) under `m`,
/// flattened within `tol` mm; `Ok(None)` for other entities, `Err` with the reason to skip one.
fn curve_paths(t: &EntityType, m: &Affine, tol: f64) -> Result<Option<Vec<Outline>>, CurveError> {
    let planar = |n: &::dxf::Vector| ocs(n).map(|o| m.then(o)).ok_or(CurveError::OffPlane);
    let path = match t {
        EntityType::Line(l) => (vec![m.apply(pt(&l.p1)), m.apply(pt(&l.p2))], false),
        EntityType::LwPolyline(p) => {
            let m = planar(&p.extrusion_direction)?;
            let v: Vec<(Pt, f64)> = p
                .vertices
                .iter()
                .map(|v| (Pt::new(v.x, v.y), v.bulge))
                .collect();
            bulge_path(&v, p.flags & 1 != 0, &m, tol)
        }
        EntityType::Arc(a) => {
            let m = planar(&a.normal)?;
            let mut sweep = (a.end_angle - a.start_angle).rem_euclid(360.0);
            if sweep == 0.0 {
                sweep = 360.0;
            }
            let (a0, sweep) = (a.start_angle.to_radians(), sweep.to_radians());
            let arc = ConicArc::circle(pt(&a.center), a.radius, a0, sweep);
            (conic_path(&bounded_arc(arc.mapped(&m))?, tol), false)
        }
        EntityType::Circle(c) => {
            let arc = ConicArc::circle(pt(&c.center), c.radius, 0.0, TAU);
            (
                closed_conic(&bounded_arc(arc.mapped(&planar(&c.normal)?))?, tol),
                true,
            )
        }
        EntityType::Ellipse(el) => ellipse_path(el, m, tol)?,
        EntityType::Spline(s) => return spline_paths(s, m, tol).map(Some),
        _ => return Ok(None),
    };
    Ok(Some(vec![path]))
}

/// An ELLIPSE (WCS centre and major axis; the normal's sign sets the direction).
fn ellipse_path(
    el: &::dxf::entities::Ellipse,
    m: &Affine,
    tol: f64,
) -> Result<Outline, CurveError> {
    ocs(&el.normal).ok_or(CurveError::OffPlane)?;
    let major = Pt::new(el.major_axis.x, el.major_axis.y);
    let side = if el.normal.z < 0.0 { -1.0 } else { 1.0 };
    let minor = Pt::new(-major.y, major.x).scale(el.minor_axis_ratio * side);
    let mut sweep = (el.end_parameter - el.start_parameter).rem_euclid(TAU);
    if sweep < 1e-12 {
        sweep = TAU;
    }
    let arc = ConicArc {
        c: pt(&el.center),
        u: major,
        v: minor,
        t0: el.start_parameter,
        t1: el.start_parameter + sweep,
    }
    .mapped(m);
    let arc = bounded_arc(arc)?;
    Ok(if sweep == TAU {
        (closed_conic(&arc, tol), true)
    } else {
        (conic_path(&arc, tol), false)
    })
}

/// Largest stretch of an affine map's linear part.
fn frame_scale(a: &Affine) -> f64 {
    let u = a.apply_vec(Pt::new(1.0, 0.0));
    let v = a.apply_vec(Pt::new(0.0, 1.0));
    u.norm() + v.norm()
}

/// A polyline with bulges (each vertex's bulge bends the segment to the next one).
fn bulge_path(v: &[(Pt, f64)], closed: bool, m: &Affine, tol: f64) -> Outline {
    let mut out = Vec::with_capacity(v.len());
    let Some(&(first, _)) = v.first() else {
        return (out, closed);
    };
    out.push(m.apply(first));
    let n = v.len();
    let segments = if closed { n } else { n.saturating_sub(1) };
    for i in 0..segments {
        let (p0, bulge) = v[i];
        let p1 = v[(i + 1) % n].0;
        // an arc beyond the coordinate limit is not flattened: its end point is, and the path
        // is refused with it (`push_paths`) when that end lies beyond the limit too
        match bulge_arc(p0, p1, bulge).and_then(|a| bounded_arc(a.mapped(m)).ok()) {
            Some(arc) => arc.flatten(tol, &mut out),
            None => out.push(m.apply(p1)),
        }
    }
    if closed && n > 1 {
        // the closing segment ends on the first vertex, which the geometry does not repeat
        out.pop();
    }
    (out, closed)
}

/// Why an entity is refused: a point, radius or text height past [`MAX_COORD_MM`] (1 km).
const BEYOND: &str = "a coordinate, radius or text height beyond ±1e6 mm (1 km)";

fn bounded(p: Pt) -> bool {
    crate::geom::within_reach_bound(p)
}

/// The arc when it lies within the coordinate limit (checked before it is flattened).
fn bounded_arc(arc: ConicArc) -> Result<ConicArc, CurveError> {
    let reach = arc.u.norm() + arc.v.norm();
    let ok = arc.t0.is_finite() && arc.t1.is_finite() && reach <= MAX_COORD_MM && bounded(arc.c);
    if ok {
        Ok(arc)
    } else {
        Err(CurveError::Beyond)
    }
}

fn conic_path(arc: &ConicArc, tol: f64) -> Vec<Pt> {
    let mut out = vec![arc.at(arc.t0)];
    arc.flatten(tol, &mut out);
    out
}

fn closed_conic(arc: &ConicArc, tol: f64) -> Vec<Pt> {
    let mut out = conic_path(arc, tol);
    out.pop();
    out
}

fn spline_paths(
    s: &::dxf::entities::Spline,
    m: &Affine,
    tol: f64,
) -> Result<Vec<Outline>, CurveError> {
    if s.normal.x.abs() > NORMAL_TOL || s.normal.y.abs() > NORMAL_TOL {
        return Err(CurveError::OffPlane);
    }
    let closed = s.flags & 1 != 0;
    if !s.control_points.is_empty() {
        let degree = usize::try_from(s.degree_of_curve).map_err(|_| CurveError::NegativeDegree)?;
        let ctrl: Vec<Pt> = s.control_points.iter().map(|p| m.apply(pt(p))).collect();
        if !ctrl.iter().all(|&p| bounded(p)) {
            return Err(CurveError::Beyond);
        }
        let nurbs = Nurbs::new(degree, s.knot_values.clone(), &ctrl, &s.weight_values)
            .map_err(CurveError::InvalidSpline)?;
        let paths = nurbs
            .flatten(tol, MAX_POINTS)
            .map_err(CurveError::Flatten)?;
        let closed = closed && paths.len() == 1;
        Ok(paths.into_iter().map(|p| (p, closed)).collect())
    } else if s.fit_points.len() >= 2 {
        let fit: Vec<Pt> = s.fit_points.iter().map(pt).collect();
        let tangent = |t: &::dxf::Point| {
            let v = pt(t);
            (v.norm() > 0.0).then_some(v)
        };
        let spans = fit_point_spline(&fit, tangent(&s.start_tangent), tangent(&s.end_tangent));
        let mapped: Vec<[Pt; 4]> = spans.iter().map(|b| b.map(|p| m.apply(p))).collect();
        if !mapped.iter().flatten().all(|&p| bounded(p)) {
            return Err(CurveError::Beyond);
        }
        let chords = mapped.iter().fold(0usize, |n, &[p0, p1, p2, p3]| {
            n.saturating_add(cubic_chords(p0, p1, p2, p3, tol))
        });
        if chords > MAX_POINTS {
            return Err(CurveError::TooManyPoints { tol });
        }
        let mut out = vec![m.apply(fit[0])];
        for [p0, p1, p2, p3] in mapped {
            flatten_cubic(p0, p1, p2, p3, tol, &mut out);
        }
        Ok(vec![(out, closed)])
    } else {
        Err(CurveError::Empty)
    }
}

/// Flips y (up → down) about the page's top: the page's bottom-left corner is the DXF origin
/// and its top-right corner `[max x, max y]` (at least 0), so `y_mm = page height − y`.
/// Placement on the machine follows ([`super::place_artwork`]).
fn flip(raw: Vec<Raw>) -> (Vec<Geometry>, [f64; 2]) {
    let b = raw
        .iter()
        .fold(BBox::EMPTY, |b, r| b.union(BBox::of(&r.points)));
    let page_mm = [b.max_x.max(0.0), b.max_y.max(0.0)];
    let geometries = raw
        .into_iter()
        .map(|r| {
            let pts = r
                .points
                .iter()
                .map(|p| Pt::new(p.x, page_mm[1] - p.y))
                .collect();
            Geometry::new(pts, r.closed, r.source)
        })
        .collect();
    (geometries, page_mm)
}
