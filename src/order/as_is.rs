//! `--algo as-is`: the document order, no optimisation (seed 002's "not optimised solution").

use super::{OrderError, Ordering};
use crate::document::{Geometry, ScanField, Step};
use crate::job::JobCtx;

/// Fields in the order of the first geometry each holds (by document index), geometries inside a
/// field in document order, each from its first vertex forwards.
pub fn as_is_order(
    geometries: &[Geometry],
    fields: &[ScanField],
    ctx: &JobCtx,
) -> Result<Ordering, OrderError> {
    ctx.check()?;
    let mut live: Vec<(usize, &ScanField)> = fields
        .iter()
        .filter_map(|f| f.geometries.iter().min().map(|&first| (first, f)))
        .collect();
    live.sort_by_key(|(first, f)| (*first, f.id));
    let mut out = Ordering::default();
    for (_, f) in live {
        out.field_order.push(f.id);
        let mut members = f.geometries.clone();
        members.sort_unstable();
        for g in members {
            out.steps
                .push(Step::from_choice(g, f.id, &geometries[g], 0));
        }
    }
    Ok(out)
}
