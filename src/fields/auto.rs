//! `--fields auto`: set cover, then positions with least overlap and best centring.

use super::cover::{cover, FRect};
use super::position::place;
use super::{center_range, FieldError};
use crate::document::{Geometry, MachineProfile, ScanField};
use crate::geom::{BBox, Pt};
use crate::job::JobCtx;

/// Feasible-centre rectangles of every geometry.
pub fn feasible_rects<'a>(
    geometries: impl IntoIterator<Item = &'a Geometry>,
    profile: &MachineProfile,
) -> Vec<FRect> {
    geometries
        .into_iter()
        .map(|g| {
            let (x, y) = center_range(&g.bbox(), profile);
            FRect { x, y }
        })
        .collect()
}

/// New fields covering the geometries in `subset`, positioned together with the (immovable)
/// `locked` fields. Ids start at `first_id`.
pub fn auto_fields(
    geometries: &[Geometry],
    subset: &[usize],
    profile: &MachineProfile,
    locked: &[ScanField],
    first_id: usize,
    ctx: &JobCtx,
) -> Result<Vec<ScanField>, FieldError> {
    let rects = feasible_rects(geometries, profile);
    let groups = cover(&rects, subset.to_vec(), ctx)?;
    // content centre of each group: the centre of its members' common bounding box
    let mut all_rects: Vec<FRect> = Vec::with_capacity(groups.len() + locked.len());
    let mut targets: Vec<Pt> = Vec::with_capacity(all_rects.capacity());
    for g in &groups {
        let b = g
            .members
            .iter()
            .fold(BBox::EMPTY, |acc, &m| acc.union(geometries[m].bbox()));
        all_rects.push(g.rect);
        targets.push(b.center());
    }
    for f in locked {
        let pin = |v: f64| super::reach::Span { lo: v, hi: v };
        all_rects.push(FRect {
            x: pin(f.center.x),
            y: pin(f.center.y),
        });
        targets.push(f.center);
    }
    let centers = place(&all_rects, &targets, profile.field_mm, 30, ctx)?;
    // number the new fields in reading order (bands of half a field, then x)
    let mut new: Vec<Pt> = centers[..groups.len()].to_vec();
    let band = profile.field_mm[1] / 2.0;
    new.sort_by(|a, b| {
        ((a.y / band).floor())
            .total_cmp(&(b.y / band).floor())
            .then(a.x.total_cmp(&b.x))
            .then(a.y.total_cmp(&b.y))
    });
    Ok(new
        .into_iter()
        .enumerate()
        .map(|(k, c)| ScanField {
            id: first_id + k,
            center: c,
            size: profile.field_mm,
            locked: false,
            geometries: Vec::new(),
            pose: Default::default(),
        })
        .collect())
}
