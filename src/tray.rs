//! A production job as one job: the part repeated over its tray, each part's texts shaped with
//! its own serial, date and data (what each piece is: `document::production`).
//!
//! [`expand`] makes the document's `artwork` from its [`Production`]: the part's outlines are
//! imported once and moved to each marked cell; each template is rendered for the part and laid
//! out by the import's text path (`import::shape_template`). The whole tray is then placed on the
//! machine as the import places artwork (`--place`), so fields, ordering, lowering and every
//! export see one job. `doc.parts` records what each part carries.

use crate::document::production::{parse_template, render, Field, PartValues, Piece};
use crate::document::{
    sync_layers, Document, Geometry, PartRecord, PartSlot, Production, ProductionError, Stamp,
};
use crate::geom::{BBox, Pt};
use crate::import::{
    place_artwork, shape_template, ImportOptions, Imported, MAX_GLYPHS, MAX_POINTS,
};
use rayon::prelude::*;

/// The import options a tray's texts are shaped and placed with: the document's machine, its
/// placement, and the chord tolerance the artwork was imported with.
fn options(doc: &Document, prod: &Production) -> ImportOptions {
    ImportOptions {
        chord_tol_mm: prod.chord_tol_mm,
        work_area_mm: Some(doc.profile.stroke_mm),
        field_mm: Some(doc.profile.field_mm),
        place: doc.import.place,
        resolution_mm: 0.1_f64.powi(i32::try_from(doc.profile.gcode.decimals).unwrap_or(i32::MAX)),
        ..ImportOptions::default()
    }
}

/// The templates read into pieces, each checked against the data it needs.
fn pieces(prod: &Production, parts: usize) -> Result<Vec<Vec<Piece>>, ProductionError> {
    let mut out = Vec::with_capacity(prod.templates.len());
    for t in &prod.templates {
        let bad = |why: String| ProductionError::Template {
            element: t.element.clone(),
            line: t.line,
            text: t.text.clone(),
            why,
        };
        let p = parse_template(&t.text).map_err(bad)?;
        for f in &p {
            let Piece::Field(Field::Csv(column)) = f else {
                continue;
            };
            let Some(data) = &prod.data else {
                return Err(bad(format!(
                    "{{csv:{column}}} needs a data file (--data FILE.csv)"
                )));
            };
            if !data.header.iter().any(|h| h == column) {
                return Err(bad(format!(
                    "{}: no column '{column}' (columns: {})",
                    data.file,
                    data.header.join(", ")
                )));
            }
            if data.rows.len() < parts {
                return Err(ProductionError::Data(format!(
                    "{}: {} data rows for {parts} marked parts (row k is part k's)",
                    data.file,
                    data.rows.len()
                )));
            }
        }
        out.push(p);
    }
    Ok(out)
}

/// One part: its record and geometries (the part's outlines moved to its cell, its texts).
fn make_part(
    prod: &Production,
    pieces: &[Vec<Piece>],
    slot: PartSlot,
    stamp: Stamp,
    opts: &ImportOptions,
) -> Result<(PartRecord, Vec<Geometry>, Vec<crate::document::Warning>), ProductionError> {
    let serial = prod.serial.of(slot.part).ok_or_else(|| {
        ProductionError::Tray(format!(
            "the serial of part {} overflows (start {}, step {})",
            slot.part, prod.serial.start, prod.serial.step
        ))
    })?;
    let values = PartValues {
        slot,
        serial,
        stamp,
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
    let mut texts = Vec::with_capacity(pieces.len());
    let mut warnings = Vec::new();
    for (t, p) in prod.templates.iter().zip(pieces) {
        let bad = |why: String| ProductionError::Template {
            element: t.element.clone(),
            line: t.line,
            text: t.text.clone(),
            why,
        };
        let text = render(p, &values).map_err(bad)?;
        let (g, w) = shape_template(&t.moved(slot.offset), &text, slot.part, opts, MAX_POINTS)
            .map_err(bad)?;
        geometries.extend(g);
        warnings.extend(w);
        texts.push(text);
    }
    let record = PartRecord {
        part: slot.part,
        cell: slot.cell,
        col: slot.col,
        row: slot.row,
        position_mm: [slot.offset.x, slot.offset.y],
        serial,
        texts,
    };
    Ok((record, geometries, warnings))
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
    let pieces = pieces(prod, slots.len())?;
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
    let stamp = prod.stamp.unwrap_or(now);
    let opts = options(doc, prod);
    let made: Vec<_> = slots
        .par_iter()
        .map(|&slot| make_part(prod, &pieces, slot, stamp, &opts))
        .collect::<Result<_, _>>()?;
    let mut records = Vec::with_capacity(made.len());
    let mut geometries = Vec::new();
    let mut warnings = Vec::new();
    for (r, g, w) in made {
        records.push(r);
        geometries.extend(g);
        for w in w {
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
    let [sw, sh] = doc.profile.stroke_mm;
    let [fw, fh] = doc.profile.field_mm;
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
