//! Operator edits of the scan fields: move, add, delete, lock, re-place automatically.
//! Every edit re-allocates the geometries and returns what is left uncovered.

use super::{allocate, place_fields, Allocation, FieldError};
use crate::document::{Document, FieldsMode, ScanField};
use crate::geom::Pt;
use crate::job::JobCtx;
use thiserror::Error;

/// An edit that cannot be applied.
#[derive(Debug, Error, PartialEq)]
pub enum EditError {
    /// No field has that id.
    #[error("no scan field with id {0}")]
    NoSuchField(usize),
    /// The field is locked.
    #[error("scan field {0} is locked; unlock it first")]
    Locked(usize),
}

fn clamp_center(doc: &Document, c: Pt) -> Pt {
    let [sw, sh] = doc.reach_profile().stroke_mm;
    let fin = |v: f64| if v.is_finite() { v } else { 0.0 };
    Pt::new(fin(c.x).clamp(0.0, sw), fin(c.y).clamp(0.0, sh))
}

fn slot(doc: &Document, id: usize) -> Result<usize, EditError> {
    doc.fields
        .iter()
        .position(|f| f.id == id)
        .ok_or(EditError::NoSuchField(id))
}

/// Re-allocates all geometries to the current fields.
pub fn reallocate(doc: &mut Document) -> Allocation {
    allocate(&doc.geometries, &mut doc.fields)
}

/// Moves a field (its centre is kept inside the base stroke). Locked fields do not move.
pub fn move_field(doc: &mut Document, id: usize, center: Pt) -> Result<Allocation, EditError> {
    let k = slot(doc, id)?;
    if doc.fields[k].locked {
        return Err(EditError::Locked(id));
    }
    doc.fields[k].center = clamp_center(doc, center);
    Ok(reallocate(doc))
}

/// Adds a field at `center`; returns its id and the allocation.
pub fn add_field(doc: &mut Document, center: Pt) -> (usize, Allocation) {
    let id = doc.fields.iter().map(|f| f.id + 1).max().unwrap_or(0);
    let center = clamp_center(doc, center);
    doc.fields.push(ScanField {
        id,
        center,
        size: doc.reach_profile().field_mm,
        locked: false,
        geometries: Vec::new(),
        pose: Default::default(),
    });
    (id, reallocate(doc))
}

/// Deletes a field (locked ones too: deleting is explicit).
pub fn delete_field(doc: &mut Document, id: usize) -> Result<Allocation, EditError> {
    let k = slot(doc, id)?;
    doc.fields.remove(k);
    Ok(reallocate(doc))
}

/// Locks or unlocks a field.
pub fn set_locked(doc: &mut Document, id: usize, locked: bool) -> Result<(), EditError> {
    let k = slot(doc, id)?;
    doc.fields[k].locked = locked;
    Ok(())
}

/// Replaces the unlocked fields by an automatic placement (the document's mode; `greedy` is
/// promoted to `auto`) that keeps the locked fields and covers what they leave uncovered.
pub fn replace_automatically(doc: &mut Document, ctx: &JobCtx) -> Result<Allocation, FieldError> {
    let locked: Vec<ScanField> = doc.fields.iter().filter(|f| f.locked).cloned().collect();
    let mut settings = doc.settings.clone();
    if settings.fields == FieldsMode::Greedy {
        settings.fields = FieldsMode::Auto;
    }
    let placement = place_fields(
        &doc.geometries,
        &doc.reach_profile(),
        &settings,
        &locked,
        ctx,
    )?;
    doc.fields = placement.fields;
    Ok(reallocate(doc))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::tests_support::rect;

    fn doc() -> Document {
        Document {
            geometries: vec![rect(10.0, 10.0, 5.0, 5.0), rect(100.0, 10.0, 5.0, 5.0)],
            ..Document::default()
        }
    }

    #[test]
    fn edits_reallocate_and_report_uncovered() {
        let mut d = doc();
        let (a, al) = add_field(&mut d, Pt::new(35.0, 35.0));
        assert_eq!(al.uncovered, vec![1]);
        let (b, al) = add_field(&mut d, Pt::new(80.0, 35.0));
        assert!(al.uncovered.is_empty());
        assert_eq!(d.fields[1].geometries, vec![1]);
        // moving field b away uncovers geometry 1
        let al = move_field(&mut d, b, Pt::new(250.0, 250.0)).unwrap();
        assert_eq!(al.uncovered, vec![1]);
        set_locked(&mut d, a, true).unwrap();
        assert_eq!(
            move_field(&mut d, a, Pt::new(0.0, 0.0)),
            Err(EditError::Locked(a))
        );
        assert_eq!(delete_field(&mut d, 99), Err(EditError::NoSuchField(99)));
        // re-place keeps the locked field and covers the rest
        let al = replace_automatically(&mut d, &JobCtx::default()).unwrap();
        assert!(al.uncovered.is_empty());
        assert!(d
            .fields
            .iter()
            .any(|f| f.id == a && f.locked && f.center == Pt::new(35.0, 35.0)));
        let al = delete_field(&mut d, a).unwrap();
        assert_eq!(al.uncovered, vec![0]);
        // centres stay inside the base stroke
        let (c, _) = add_field(&mut d, Pt::new(-50.0, 1e9));
        let f = d.fields.iter().find(|f| f.id == c).unwrap();
        assert_eq!(f.center, Pt::new(0.0, 300.0));
    }
}
