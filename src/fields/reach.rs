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

/// A drawing this many times larger than the reach is likely in the wrong units.
const UNITS_SUSPECT_RATIO: f64 = 10.0;

/// The message of [`FieldError::Artwork`]: the artwork's size and place against the reach, and
/// what to do (place it, or check its units when it is over ten times the machine).
pub(super) fn artwork_message(extent: &[f64; 4], stroke: &[f64; 2], field: &[f64; 2]) -> String {
    let [x0, y0, x1, y1] = *extent;
    let (w, h) = (x1 - x0, y1 - y0);
    let reach = [stroke[0] + field[0], stroke[1] + field[1]];
    let parts = format!(
        "{:.1} × {:.1} mm base stroke + {:.1} × {:.1} mm scan field",
        stroke[0], stroke[1], field[0], field[1]
    );
    let size = format!("the artwork is {w:.1} × {h:.1} mm");
    let ratio = (w / reach[0]).max(h / reach[1]);
    if ratio > UNITS_SUSPECT_RATIO {
        format!(
            "{size}, {ratio:.0} times the {:.1} × {:.1} mm the laser reaches ({parts}): check the drawing's units (DXF $INSUNITS; SVG width, height and viewBox)",
            reach[0], reach[1]
        )
    } else if ratio > 1.0 {
        format!(
            "{size}, larger than the {:.1} × {:.1} mm the laser reaches ({parts}): scale it down or split the drawing into jobs that fit",
            reach[0], reach[1]
        )
    } else {
        format!(
            "{size} at x {x0:.1}…{x1:.1}, y {y0:.1}…{y1:.1} mm, out of reach where it lies: the laser reaches x {:.1}…{:.1}, y {:.1}…{:.1} mm ({parts}); it fits once moved: place it centred on the base stroke or with its top-left corner at x {:.1}…{:.1}, y {:.1}…{:.1} mm",
            -field[0] / 2.0,
            stroke[0] + field[0] / 2.0,
            -field[1] / 2.0,
            stroke[1] + field[1] / 2.0,
            -field[0] / 2.0,
            stroke[0] + field[0] / 2.0 - w,
            -field[1] / 2.0,
            stroke[1] + field[1] / 2.0 - h,
        )
    }
}

impl FieldError {
    /// True for artwork that fits within the reach but lies outside it where the file puts it:
    /// placing it elsewhere on the machine would help.
    pub fn fits_once_moved(&self) -> bool {
        match self {
            FieldError::Artwork {
                extent_mm,
                stroke_mm,
                field_mm,
            } => {
                let [x0, y0, x1, y1] = *extent_mm;
                x1 - x0 <= stroke_mm[0] + field_mm[0] && y1 - y0 <= stroke_mm[1] + field_mm[1]
            }
            _ => false,
        }
    }
}

/// Fails when the artwork as a whole is not within the laser's reach: larger than it, or in the
/// wrong place ([`FieldError::Artwork`], with its size against the reach).
pub fn check_artwork(geometries: &[Geometry], profile: &MachineProfile) -> Result<(), FieldError> {
    let extent = geometries
        .iter()
        .fold(BBox::EMPTY, |b, g| b.union(g.bbox()));
    let [sw, sh] = profile.stroke_mm;
    let [fw, fh] = profile.field_mm;
    let eps = super::INSIDE_EPS_MM;
    let in_reach = extent.min_x >= -fw / 2.0 - eps
        && extent.min_y >= -fh / 2.0 - eps
        && extent.max_x <= sw + fw / 2.0 + eps
        && extent.max_y <= sh + fh / 2.0 + eps;
    if !extent.is_empty() && !in_reach {
        return Err(FieldError::Artwork {
            extent_mm: [extent.min_x, extent.min_y, extent.max_x, extent.max_y],
            stroke_mm: profile.stroke_mm,
            field_mm: profile.field_mm,
        });
    }
    Ok(())
}

/// Fails when the artwork as a whole is not within the laser's reach ([`check_artwork`]), then
/// with every geometry larger than a field, then with every geometry out of reach.
pub fn check_reach(geometries: &[Geometry], profile: &MachineProfile) -> Result<(), FieldError> {
    check_artwork(geometries, profile)?;
    let [fw, fh] = profile.field_mm;
    let oversize: Vec<String> = geometries
        .iter()
        .enumerate()
        .filter(|(_, g)| {
            let b = g.bbox();
            b.width() > fw + super::INSIDE_EPS_MM || b.height() > fh + super::INSIDE_EPS_MM
        })
        .map(|(i, g)| format!("geometry {} {}", i + 1, g.describe()))
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
        .map(|(i, g)| format!("geometry {} {}", i + 1, g.describe()))
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
