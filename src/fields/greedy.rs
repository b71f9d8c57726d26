//! The baseline cover: serpentine sweep, one field per first-uncovered geometry.

use super::{center_range, FieldError, INSIDE_EPS_MM};
use crate::document::{Geometry, MachineProfile, ScanField};
use crate::geom::{BBox, Pt};
use crate::job::JobCtx;

/// Greedy cover: take the unassigned geometries in serpentine order of their bounding boxes
/// (bands one field high; left to right, then right to left), open a field whose corner sits at
/// the first one's bounding-box corner (top-left going right, top-right going left; shifted back
/// into the base stroke while that geometry stays covered), assign to it every unassigned
/// geometry lying wholly inside, repeat. Only the geometries in `subset` are covered (field ids
/// count from 0). Assumes [`super::check_reach`] passed.
pub fn greedy_fields(
    geometries: &[Geometry],
    subset: &[usize],
    profile: &MachineProfile,
    ctx: &JobCtx,
) -> Result<Vec<ScanField>, FieldError> {
    let [fw, fh] = profile.field_mm;
    let boxes: Vec<BBox> = geometries.iter().map(Geometry::bbox).collect();
    let top = subset
        .iter()
        .map(|&i| boxes[i].min_y)
        .fold(f64::INFINITY, f64::min);
    let band = |b: &BBox| ((b.min_y - top) / fh).floor().max(0.0) as i64;
    let mut order: Vec<usize> = subset.to_vec();
    order.sort_by(|&a, &b| {
        let (ba, bb) = (&boxes[a], &boxes[b]);
        let (ra, rb) = (band(ba), band(bb));
        ra.cmp(&rb)
            .then_with(|| {
                if ra % 2 == 0 {
                    ba.min_x.total_cmp(&bb.min_x)
                } else {
                    bb.max_x.total_cmp(&ba.max_x)
                }
            })
            .then(a.cmp(&b))
    });
    let mut assigned = vec![false; geometries.len()];
    let mut fields: Vec<ScanField> = Vec::new();
    for (k, &first) in order.iter().enumerate() {
        if assigned[first] {
            continue;
        }
        if k % 256 == 0 {
            ctx.check()?;
            ctx.progress("fields", k as u64, order.len() as u64, "greedy cover");
        }
        let b = &boxes[first];
        let going_right = band(b) % 2 == 0;
        let want = Pt::new(
            if going_right {
                b.min_x + fw / 2.0
            } else {
                b.max_x - fw / 2.0
            },
            b.min_y + fh / 2.0,
        );
        let (xs, ys) = center_range(b, profile);
        let center = Pt::new(xs.clamp(want.x), ys.clamp(want.y));
        let field_box = BBox::centered(center, fw, fh);
        let mut members = Vec::new();
        // members in the sweep order: the rest of `order` from here
        for &g in &order[k..] {
            if !assigned[g] && field_box.contains_box(&boxes[g], INSIDE_EPS_MM) {
                assigned[g] = true;
                members.push(g);
            }
        }
        fields.push(ScanField {
            id: fields.len(),
            center,
            size: profile.field_mm,
            locked: false,
            geometries: members,
            pose: Default::default(),
        });
    }
    Ok(fields)
}
