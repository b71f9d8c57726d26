//! A production job as one job: the part repeated over its tray, each part's texts shaped with
//! its own serial, date and data (what each piece is: `document::production`).
//!
//! [`expand`] makes the document's `artwork` from its [`Production`]: the part's outlines are
//! imported once and moved to each marked cell; each template is rendered for the part and laid
//! out by the import's text path (`import::shape_template`). The whole tray is then placed on the
//! machine as the import places artwork (`--place`), so fields, ordering, lowering and every
//! export see one job. `doc.parts` records what each part carries.

use crate::codes::{marks, quiet_box, symbol, Fill};
use crate::document::production::{
    parse_template, render, Field, PartValues, Piece, TemplateError,
};
use crate::document::{
    sync_layers, Document, Geometry, PartRecord, PartSlot, Production, ProductionError, Stamp,
    CODE_LAYER,
};
use crate::geom::{BBox, Pt};
use crate::import::{
    place_artwork, shape_template, ImportOptions, Imported, MAX_GLYPHS, MAX_POINTS,
};
use rayon::prelude::*;

/// The import options a tray's texts are shaped and placed with: the document's machine, its
/// placement, and the chord tolerance the artwork was imported with.
fn options(doc: &Document, prod: &Production) -> ImportOptions {
    // around a cylinder: its unrolled surface
    let reach = doc.reach_profile();
    ImportOptions {
        chord_tol_mm: prod.chord_tol_mm,
        work_area_mm: Some(reach.stroke_mm),
        field_mm: Some(reach.field_mm),
        place: doc.import.place,
        resolution_mm: doc.profile.resolution_mm(),
        ..ImportOptions::default()
    }
}

/// A text of the production (a template or a code's content) read into pieces and checked
/// against the data it needs; `bad` makes the error naming the text.
fn read_checked(
    text: &str,
    prod: &Production,
    parts: usize,
    bad: impl Fn(String) -> ProductionError,
) -> Result<Vec<Piece>, ProductionError> {
    let wrong = |e: TemplateError| bad(e.to_string());
    let p = parse_template(text).map_err(wrong)?;
    for f in &p {
        let Piece::Field(Field::Csv(column)) = f else {
            continue;
        };
        let Some(data) = &prod.data else {
            return Err(wrong(TemplateError::NoData {
                column: column.clone(),
            }));
        };
        data.check_column(column).map_err(wrong)?;
        if data.rows.len() < parts {
            return Err(ProductionError::Data(format!(
                "{}: {} data rows for {parts} marked parts (row k is part k's)",
                data.file,
                data.rows.len()
            )));
        }
    }
    Ok(p)
}

/// The templates and the codes' contents read into pieces, each checked against its data.
type Pieces = (Vec<Vec<Piece>>, Vec<Vec<Piece>>);

fn pieces(prod: &Production, parts: usize) -> Result<Pieces, ProductionError> {
    let texts = prod
        .templates
        .iter()
        .map(|t| {
            read_checked(&t.text, prod, parts, |why| ProductionError::Template {
                element: t.element.clone(),
                line: t.line,
                text: t.text.clone(),
                why,
            })
        })
        .collect::<Result<_, _>>()?;
    let codes = prod
        .codes
        .iter()
        .map(|c| {
            read_checked(&c.content, prod, parts, |why| ProductionError::Code {
                text: format!("{}:{}", c.kind, c.content),
                why,
            })
        })
        .collect::<Result<_, _>>()?;
    Ok((texts, codes))
}

/// What every part of one expansion shares.
struct Job<'a> {
    prod: &'a Production,
    /// Each template read into pieces.
    pieces: Vec<Vec<Piece>>,
    /// Each code's content read into pieces.
    code_pieces: Vec<Vec<Piece>>,
    stamp: Stamp,
    opts: ImportOptions,
    /// How codes are filled.
    fill: Fill,
    /// The part's top-left (its outlines' bounding box), in the file's coordinates: where
    /// codes are placed from.
    origin: Pt,
}

/// One part: its record and geometries (the part's outlines moved to its cell, its texts, its
/// codes).
type Made = (PartRecord, Vec<Geometry>, Vec<crate::document::Warning>);

fn make_part(job: &Job, slot: PartSlot) -> Result<Made, ProductionError> {
    let prod = job.prod;
    let serial = prod.serial.of(slot.part).ok_or_else(|| {
        ProductionError::Tray(format!(
            "the serial of part {} overflows (start {}, step {})",
            slot.part, prod.serial.start, prod.serial.step
        ))
    })?;
    let values = PartValues {
        slot,
        serial,
        stamp: job.stamp,
        data: prod.data.as_ref(),
    };
    let mut geometries: Vec<Geometry> = prod
        .part
        .iter()
        .map(|g| {
            let mut g = g.clone();
            for p in &mut g.points {
                *p = p.plus(slot.offset);
            }
            g.source.part = slot.part;
            g
        })
        .collect();
    let mut texts = Vec::with_capacity(job.pieces.len());
    let mut warnings = Vec::new();
    for (t, p) in prod.templates.iter().zip(&job.pieces) {
        let bad = |why: String| ProductionError::Template {
            element: t.element.clone(),
            line: t.line,
            text: t.text.clone(),
            why,
        };
        let text = render(p, &values).map_err(|e| bad(e.to_string()))?;
        let (g, w) = shape_template(
            &t.moved(slot.offset),
            &text,
            slot.part,
            &job.opts,
            MAX_POINTS,
        )
        .map_err(|e| bad(e.to_string()))?;
        geometries.extend(g);
        warnings.extend(w);
        texts.push(text);
    }
    let mut codes = Vec::with_capacity(prod.codes.len());
    for (k, (spec, p)) in prod.codes.iter().zip(&job.code_pieces).enumerate() {
        let bad = |why: String| ProductionError::Code {
            text: format!("{}:{}", spec.kind, spec.content),
            why,
        };
        let content = render(p, &values).map_err(|e| bad(e.to_string()))?;
        let sym = symbol(spec, &content).map_err(|e| bad(e.to_string()))?;
        let at = job
            .origin
            .plus(Pt::new(spec.at_mm[0], spec.at_mm[1]))
            .plus(slot.offset);
        let element = format!("{} code {}", spec.kind, k + 1);
        // a run id of its own for each code of each part
        let run_id = slot.part.wrapping_mul(64).wrapping_add(k as u32);
        geometries.extend(
            marks(spec, &sym, at, job.fill, slot.part, &element, run_id)
                .map_err(|e| bad(e.to_string()))?,
        );
        codes.push(content);
    }
    let record = PartRecord {
        part: slot.part,
        cell: slot.cell,
        col: slot.col,
        row: slot.row,
        position_mm: [slot.offset.x, slot.offset.y],
        serial,
        texts,
        codes,
    };
    Ok((record, geometries, warnings))
}

/// How the codes of `doc` are filled: the codes layer's hatch spacing when its pen has a
/// hatch, else the profile's spot; always inset by half the spot.
fn code_fill(doc: &Document) -> Fill {
    let spot = doc.profile.laser.spot_mm;
    let spacing = doc
        .layers
        .iter()
        .find(|l| l.name == CODE_LAYER)
        .and_then(|l| l.pen.hatch.as_ref())
        .map_or(spot, |h| h.spacing_mm);
    Fill {
        spacing_mm: spacing,
        spot_mm: spot,
    }
}

/// A warning for each code whose quiet zone holds artwork of the part (texts included),
/// naming both: the zone must stay unmarked for the code to scan.
fn quiet_zone_warnings(job: &Job, first: &Made) -> Vec<crate::document::Warning> {
    let mut out = Vec::new();
    let (record, geometries, _) = first;
    for (k, (spec, content)) in job.prod.codes.iter().zip(&record.codes).enumerate() {
        let Ok(sym) = symbol(spec, content) else {
            continue;
        };
        let at = job.origin.plus(Pt::new(spec.at_mm[0], spec.at_mm[1]));
        let (lo, hi) = quiet_box(spec, &sym, at);
        let element = format!("{} code {}", spec.kind, k + 1);
        let inside = |p: &Pt| p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y;
        if let Some(g) = geometries
            .iter()
            .filter(|g| g.layer != CODE_LAYER)
            .find(|g| g.points.iter().any(inside))
        {
            out.push(crate::document::Warning {
                element: element.clone(),
                line: None,
                message: format!(
                    "its quiet zone ({:.2}, {:.2}) to ({:.2}, {:.2}) mm holds {} of the part: \
                     move one of them, or the code may not scan",
                    lo.x, lo.y, hi.x, hi.y, g.source.element
                ),
                note: false,
            });
        }
    }
    out
}

/// Makes `doc.artwork` (and `doc.parts`) from `doc.production`, placed on the machine as the
/// document's import says; nothing to do without a production. On an error the document is
/// unchanged. `now` is the date and time fields show when the production fixes none.
pub fn expand(doc: &mut Document, now: Stamp) -> Result<(), ProductionError> {
    let Some(prod) = doc.production.as_ref() else {
        return Ok(());
    };
    prod.tray.validate()?;
    let slots = prod.tray.parts();
    let (pieces, code_pieces) = pieces(prod, slots.len())?;
    let glyphs: usize = prod
        .templates
        .iter()
        .map(|t| t.text.chars().filter(|c| !c.is_whitespace()).count())
        .sum::<usize>()
        .saturating_mul(slots.len());
    if glyphs > MAX_GLYPHS {
        return Err(ProductionError::Tray(format!(
            "{} parts × their texts make about {glyphs} characters, beyond the {MAX_GLYPHS} \
             galvoplan lays out in one job",
            slots.len()
        )));
    }
    let origin = prod
        .part
        .iter()
        .fold(BBox::EMPTY, |b, g| b.union(BBox::of(&g.points)));
    let job = Job {
        prod,
        pieces,
        code_pieces,
        stamp: prod.stamp.unwrap_or(now),
        opts: options(doc, prod),
        fill: code_fill(doc),
        origin: if origin.is_empty() {
            Pt::new(0.0, 0.0)
        } else {
            Pt::new(origin.min_x, origin.min_y)
        },
    };
    let made: Vec<Made> = slots
        .par_iter()
        .map(|&slot| make_part(&job, slot))
        .collect::<Result<_, _>>()?;
    let quiet = made
        .first()
        .map(|m| quiet_zone_warnings(&job, m))
        .unwrap_or_default();
    let opts = job.opts;
    let mut records = Vec::with_capacity(made.len());
    let mut geometries = Vec::new();
    let mut warnings = Vec::new();
    for (r, g, w) in made {
        records.push(r);
        geometries.extend(g);
        for w in w.into_iter().chain(quiet.iter().cloned()) {
            if !warnings.contains(&w) {
                warnings.push(w);
            }
        }
    }
    check_reach(doc, &geometries, prod)?;
    let mut placed = Imported {
        geometries,
        page_mm: doc.page_mm,
        ..Imported::default()
    };
    place_artwork(&mut placed, &opts).map_err(|e| ProductionError::Tray(e.to_string()))?;
    let moved = Pt::new(placed.moved_mm[0], placed.moved_mm[1]);
    for r in &mut records {
        r.position_mm = [r.position_mm[0] + moved.x, r.position_mm[1] + moved.y];
    }
    // the import's notes about a single part's placement no longer apply: the tray's replace
    // them; font warnings of the texts are kept once each
    doc.warnings
        .retain(|w| !placed.warnings.iter().any(|p| p.element == w.element));
    for w in placed.warnings.into_iter().chain(warnings) {
        if !doc.warnings.contains(&w) {
            doc.warnings.push(w);
        }
    }
    doc.page_mm = placed.page_mm;
    doc.artwork = placed.geometries;
    sync_layers(&mut doc.layers, &doc.artwork, &doc.settings.default_pen());
    doc.derived_with = None;
    doc.parts = records;
    Ok(())
}

/// Refuses a tray larger than the machine reaches (the base stroke grown by half a field on
/// every side), with both sizes.
fn check_reach(
    doc: &Document,
    geometries: &[Geometry],
    prod: &Production,
) -> Result<(), ProductionError> {
    let b = geometries
        .iter()
        .fold(BBox::EMPTY, |b, g| b.union(BBox::of(&g.points)));
    if b.is_empty() {
        return Err(ProductionError::Tray("the part has nothing to mark".into()));
    }
    let reach = doc.reach_profile();
    let [sw, sh] = reach.stroke_mm;
    let [fw, fh] = reach.field_mm;
    let (rw, rh) = (sw + fw, sh + fh);
    let (w, h) = (b.max_x - b.min_x, b.max_y - b.min_y);
    const SLACK_MM: f64 = 1e-6;
    if w > rw + SLACK_MM || h > rh + SLACK_MM {
        return Err(ProductionError::Tray(format!(
            "the tray is {w:.1} × {h:.1} mm ({} × {} parts at {} × {} mm), larger than the \
             {rw:.1} × {rh:.1} mm the machine reaches",
            prod.tray.cols, prod.tray.rows, prod.tray.pitch_mm[0], prod.tray.pitch_mm[1]
        )));
    }
    Ok(())
}
