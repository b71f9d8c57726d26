//! Shapes for unit tests.

use crate::document::{Geometry, Source};
use crate::geom::Pt;

/// An axis-aligned rectangle as a closed geometry.
pub(crate) fn rect(x: f64, y: f64, w: f64, h: f64) -> Geometry {
    Geometry::new(
        vec![
            Pt::new(x, y),
            Pt::new(x + w, y),
            Pt::new(x + w, y + h),
            Pt::new(x, y + h),
        ],
        true,
        Source::default(),
    )
}
