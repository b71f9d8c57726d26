//! Passes: a layer marked several times repeats its strokes inside each field.

use crate::document::{passes_of, Geometry, Layer, Step};

/// Repeats each layer's strokes for its passes: inside each run of one field, the run's
/// strokes are marked again, in the same order, once for every further pass of their layer
/// (the stage does not move between passes).
pub fn expand_passes(order: &[Step], geometries: &[Geometry], layers: &[Layer]) -> Vec<Step> {
    if layers.iter().all(|l| l.pen.passes <= 1) {
        return order.to_vec();
    }
    let passes = |s: &Step| {
        geometries
            .get(s.geometry)
            .map_or(1, |g| passes_of(layers, g))
    };
    let mut out = Vec::with_capacity(order.len());
    for run in order.chunk_by(|a, b| a.field == b.field) {
        let most = run.iter().map(passes).max().unwrap_or(1);
        for pass in 0..most {
            out.extend(run.iter().filter(|s| passes(s) > pass));
        }
    }
    out
}
