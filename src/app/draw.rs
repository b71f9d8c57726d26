//! Drawing helpers every canvas room shares, at the bottom of the GUI's modules: the view
//! transform ([`View`]), the canvas colours ([`colour`]) and lines put on screen with their
//! sub-pixel detail left out ([`screen_line`]). Nothing here imports another file of the GUI.

use crate::geom::Pt;
use egui::{Pos2, Rect, Vec2};

/// Pan and zoom of a canvas: screen = rect corner + offset + mm × scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Pixels per mm (0 until the first fit).
    pub scale: f32,
    /// Screen offset of the machine origin, relative to the canvas rectangle's corner.
    pub offset: Vec2,
}

impl Default for View {
    fn default() -> Self {
        Self {
            scale: 0.0,
            offset: Vec2::ZERO,
        }
    }
}

impl View {
    /// Fits the box `(min, max)` in mm into `rect` with a margin.
    pub fn fit(&mut self, rect: Rect, min: Pt, max: Pt) {
        let w = (max.x - min.x).max(1.0) as f32;
        let h = (max.y - min.y).max(1.0) as f32;
        self.scale = ((rect.width() - 20.0) / w)
            .min((rect.height() - 20.0) / h)
            .max(0.01);
        let used = Vec2::new(w, h) * self.scale;
        self.offset =
            (rect.size() - used) / 2.0 - Vec2::new(min.x as f32, min.y as f32) * self.scale;
    }
    /// mm → screen.
    pub fn to_screen(&self, rect: Rect, p: Pt) -> Pos2 {
        rect.min + self.offset + Vec2::new(p.x as f32, p.y as f32) * self.scale
    }
    /// screen → mm.
    pub fn to_mm(&self, rect: Rect, p: Pos2) -> Pt {
        let v = (p - rect.min - self.offset) / self.scale.max(1e-6);
        Pt::new(f64::from(v.x), f64::from(v.y))
    }
}

/// Colours of the canvas.
pub mod colour {
    use egui::Color32;
    /// Closed geometries.
    pub const CLOSED: Color32 = Color32::from_rgb(30, 41, 59);
    /// Open geometries (also marked with dots at their ends).
    pub const OPEN: Color32 = Color32::from_rgb(21, 128, 61);
    /// Geometries no field holds: a magenta halo around the geometry (drawn in its own
    /// colour), a style no layer colour has, and the words that tell of them.
    pub const UNCOVERED: Color32 = Color32::from_rgb(192, 38, 211);
    /// Width of the uncovered halo, px.
    pub const UNCOVERED_HALO_PX: f32 = 9.0;
    /// A lowering or other error in a canvas caption.
    pub const ERROR: Color32 = Color32::from_rgb(200, 30, 30);
    /// Geometries no field can hold (larger than a field, or beyond the stage's reach).
    pub const OUT_OF_REACH: Color32 = Color32::from_rgb(147, 51, 234);
    /// Scan fields.
    pub const FIELD: Color32 = Color32::from_rgb(79, 70, 229);
    /// Seams (where artwork larger than a field is cut).
    pub const SEAM: Color32 = Color32::from_rgb(153, 27, 27);
    /// The selected field.
    pub const SELECTED: Color32 = Color32::from_rgb(245, 158, 11);
    /// A mixed job's step-and-scan fields (the stage at rest while they are marked): their
    /// fill, and the caption's words about them.
    pub const STILL_FIELD: Color32 = Color32::from_rgb(13, 148, 136);
    /// Idle moves of a single plan, and plan A when two are overlaid.
    pub const PATH_A: Color32 = Color32::from_rgb(234, 88, 12);
    /// Idle moves of plan B when two are overlaid.
    pub const PATH_B: Color32 = Color32::from_rgb(37, 99, 235);
    /// Start marker.
    pub const START: Color32 = Color32::from_rgb(22, 163, 74);
    /// End marker.
    pub const END: Color32 = Color32::from_rgb(190, 18, 60);
    /// First and last colours of marks coloured by order.
    pub const ORDER: [Color32; 2] = [
        Color32::from_rgb(8, 145, 178),
        Color32::from_rgb(162, 28, 175),
    ];
    /// The colour of "stale" marks and notes.
    pub const STALE: Color32 = Color32::from_rgb(180, 83, 9);
}

/// Shapes wholly this far outside the canvas are not drawn, px (line widths and end dots).
pub const CULL_MARGIN_PX: f32 = 8.0;

/// Screen points closer than this to the last one kept are left out of a drawn line, px: the
/// line looks the same, and a zoomed-out job of 10⁵ strokes tessellates thousands of points,
/// not millions.
const DETAIL_PX: f32 = 0.75;

/// `pts` (mm) on screen with the points closer than [`DETAIL_PX`] to the last kept one left out
/// (the last point always kept; closed: back to the first), or none when the whole line lies
/// outside `clip`.
pub fn screen_line<F: Fn(Pt) -> Pos2 + ?Sized>(
    pts: &[Pt],
    closed: bool,
    s: &F,
    clip: Rect,
) -> Option<Vec<Pos2>> {
    let first = *pts.first()?;
    let mut out = Vec::with_capacity(pts.len().min(64));
    let mut bounds = Rect::NOTHING;
    let mut keep = |q: Pos2, out: &mut Vec<Pos2>| {
        bounds.extend_with(q);
        out.push(q);
    };
    keep(s(first), &mut out);
    let n = pts.len();
    for (k, &p) in pts.iter().enumerate().skip(1) {
        let q = s(p);
        let far = out
            .last()
            .is_none_or(|l| (q - *l).length_sq() >= DETAIL_PX * DETAIL_PX);
        if far || k + 1 == n {
            keep(q, &mut out);
        }
    }
    if closed && n > 1 {
        keep(s(first), &mut out);
    }
    bounds
        .expand(CULL_MARGIN_PX)
        .intersects(clip)
        .then_some(out)
}
