//! Reachability: which base positions let a field cover a geometry.

use super::FieldError;
use crate::document::{Geometry, MachineProfile};
use crate::geom::BBox;

/// A closed interval of base positions on one axis, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    /// Lowest position.
    pub lo: f64,
    /// Highest position.
    pub hi: f64,
}

impl Span {
    /// True when the interval holds at least one position.
    pub fn is_empty(&self) -> bool {
        self.lo > self.hi
    }
    /// Clamps `v` into the interval (`lo` when empty).
    pub fn clamp(&self, v: f64) -> f64 {
        if self.is_empty() {
            self.lo
        } else {
            v.clamp(self.lo, self.hi)
        }
    }
    /// Intersection.
    pub fn meet(&self, o: &Span) -> Span {
        Span {
            lo: self.lo.max(o.lo),
            hi: self.hi.min(o.hi),
        }
    }
}

/// Base positions (x span, y span) from which a field covers the whole box `b`, within the stroke.
pub fn center_range(b: &BBox, profile: &MachineProfile) -> (Span, Span) {
    let [fw, fh] = profile.field_mm;
    let [sw, sh] = profile.stroke_mm;
    let x = Span {
        lo: (b.max_x - fw / 2.0).max(0.0),
        hi: (b.min_x + fw / 2.0).min(sw),
    };
    let y = Span {
        lo: (b.max_y - fh / 2.0).max(0.0),
        hi: (b.min_y + fh / 2.0).min(sh),
    };
    (x, y)
}

/// Fails with every geometry larger than a field, then with every geometry out of reach.
pub fn check_reach(geometries: &[Geometry], profile: &MachineProfile) -> Result<(), FieldError> {
    let [fw, fh] = profile.field_mm;
    let oversize: Vec<String> = geometries
        .iter()
        .enumerate()
        .filter(|(_, g)| {
            let b = g.bbox();
            b.width() > fw + super::INSIDE_EPS_MM || b.height() > fh + super::INSIDE_EPS_MM
        })
        .map(|(i, g)| format!("geometry {i} {}", g.describe()))
        .collect();
    if !oversize.is_empty() {
        return Err(FieldError::Oversize {
            list: oversize,
            field_mm: profile.field_mm,
        });
    }
    let out: Vec<String> = geometries
        .iter()
        .enumerate()
        .filter(|(_, g)| {
            let (x, y) = center_range(&g.bbox(), profile);
            x.lo > x.hi + super::INSIDE_EPS_MM || y.lo > y.hi + super::INSIDE_EPS_MM
        })
        .map(|(i, g)| format!("geometry {i} {}", g.describe()))
        .collect();
    if !out.is_empty() {
        return Err(FieldError::OutOfReach {
            list: out,
            stroke_mm: profile.stroke_mm,
            field_mm: profile.field_mm,
        });
    }
    Ok(())
}
