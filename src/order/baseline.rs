//! Baseline ordering: fields in creation order, nearest neighbour inside each field.

use super::{OrderError, Ordering};
use crate::document::{Geometry, ScanField, Step};
use crate::geom::Pt;
use crate::job::JobCtx;

/// Fields in creation order; inside a field, repeatedly the geometry whose nearest start choice
/// (any vertex of a closed geometry, either end of an open one) is closest to the current
/// position, started there. The run begins at the first field's top-left corner.
pub fn baseline_order(
    geometries: &[Geometry],
    fields: &[ScanField],
    ctx: &JobCtx,
) -> Result<Ordering, OrderError> {
    let mut out = Ordering::default();
    let mut pos = fields
        .first()
        .map(|f| {
            let b = f.bbox();
            Pt::new(b.min_x, b.min_y)
        })
        .unwrap_or_default();
    for (k, f) in fields.iter().enumerate() {
        ctx.check()?;
        ctx.progress("order", k as u64, fields.len() as u64, "baseline");
        out.field_order.push(f.id);
        let mut left: Vec<usize> = f.geometries.clone();
        while !left.is_empty() {
            let mut best = (f64::INFINITY, 0usize, 0usize);
            for (slot, &gi) in left.iter().enumerate() {
                let g = &geometries[gi];
                for c in 0..g.start_choices() {
                    let d = pos.dist2(g.ends(c).0);
                    if d < best.0 {
                        best = (d, slot, c);
                    }
                }
            }
            let gi = left.swap_remove(best.1);
            let g = &geometries[gi];
            out.steps.push(Step::from_choice(gi, f.id, g, best.2));
            pos = g.ends(best.2).1;
        }
    }
    Ok(out)
}
