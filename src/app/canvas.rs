//! The work-area canvas: base stroke, artwork, scan fields and the planned path.

use crate::document::{Document, Plan};
use crate::geom::Pt;
use egui::{Color32, Pos2, Rect, Sense, Shape, Stroke, Vec2};

/// Pan and zoom of a canvas: screen = origin + mm × scale.
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
        let v = (p - rect.min - self.offset) / self.scale;
        Pt::new(f64::from(v.x), f64::from(v.y))
    }
}

/// Draws a document and optionally a plan.
pub struct Canvas<'a> {
    /// The document.
    pub doc: &'a Document,
    /// The plan to draw over it.
    pub plan: Option<&'a Plan>,
}

impl Canvas<'_> {
    /// Shows the canvas filling the available space; drag pans, the wheel zooms about the cursor,
    /// a double-click fits the view.
    pub fn show(&self, ui: &mut egui::Ui, view: &mut View) -> egui::Response {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        let p = &self.doc.profile;
        let (lo, hi) = (
            Pt::new(-p.field_mm[0] / 2.0, -p.field_mm[1] / 2.0),
            Pt::new(
                p.stroke_mm[0] + p.field_mm[0] / 2.0,
                p.stroke_mm[1] + p.field_mm[1] / 2.0,
            ),
        );
        if view.scale == 0.0 || response.double_clicked() {
            view.fit(rect, lo, hi);
        }
        if response.dragged() {
            view.offset += response.drag_delta();
        }
        if response.hovered() {
            let scroll = ui.ctx().input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                if let Some(cursor) = response.hover_pos() {
                    let before = view.to_mm(rect, cursor);
                    view.scale = (view.scale * (scroll / 200.0).exp()).clamp(0.01, 500.0);
                    let after = view.to_screen(rect, before);
                    view.offset += cursor - after;
                }
            }
        }
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, Color32::from_gray(250));
        let v = *view;
        let s = |q: Pt| v.to_screen(rect, q);
        // reach of the laser, and the base stroke
        painter.rect_stroke(
            Rect::from_two_pos(s(lo), s(hi)),
            0.0,
            Stroke::new(1.0, Color32::from_gray(200)),
            egui::StrokeKind::Middle,
        );
        painter.rect_stroke(
            Rect::from_two_pos(
                s(Pt::new(0.0, 0.0)),
                s(Pt::new(p.stroke_mm[0], p.stroke_mm[1])),
            ),
            0.0,
            Stroke::new(1.0, Color32::from_gray(150)),
            egui::StrokeKind::Middle,
        );
        let fields = self
            .plan
            .map(|pl| &pl.fields[..])
            .unwrap_or(&self.doc.fields[..]);
        for (k, f) in fields.iter().enumerate() {
            let b = f.bbox();
            let r = Rect::from_two_pos(s(Pt::new(b.min_x, b.min_y)), s(Pt::new(b.max_x, b.max_y)));
            painter.rect_filled(r, 0.0, Color32::from_rgba_unmultiplied(59, 130, 246, 20));
            painter.rect_stroke(
                r,
                0.0,
                Stroke::new(1.0, Color32::from_rgb(59, 130, 246)),
                egui::StrokeKind::Middle,
            );
            painter.text(
                r.min + Vec2::new(4.0, 2.0),
                egui::Align2::LEFT_TOP,
                format!("{}", k + 1),
                egui::FontId::proportional(14.0),
                Color32::from_rgb(29, 78, 216),
            );
        }
        for g in &self.doc.geometries {
            let mut pts: Vec<Pos2> = g.points.iter().map(|&q| s(q)).collect();
            let color = if g.closed {
                Color32::from_gray(30)
            } else {
                Color32::from_rgb(120, 60, 0)
            };
            if g.closed {
                if let Some(&f) = pts.first() {
                    pts.push(f);
                }
            }
            painter.add(Shape::line(pts, Stroke::new(1.0, color)));
        }
        if let Some(plan) = self.plan {
            let mut prev: Option<Pt> = None;
            for st in &plan.order {
                let Some(g) = self.doc.geometries.get(st.geometry) else {
                    continue;
                };
                let (a, z) = g.ends(st.choice(g));
                if let Some(pz) = prev {
                    painter.line_segment(
                        [s(pz), s(a)],
                        Stroke::new(1.0, Color32::from_rgb(220, 38, 38)),
                    );
                }
                prev = Some(z);
            }
            if let (Some(first), Some(last)) = (plan.order.first(), plan.order.last()) {
                let g0 = &self.doc.geometries[first.geometry];
                let gl = &self.doc.geometries[last.geometry];
                painter.circle_filled(
                    s(g0.ends(first.choice(g0)).0),
                    5.0,
                    Color32::from_rgb(22, 163, 74),
                );
                painter.circle_filled(
                    s(gl.ends(last.choice(gl)).1),
                    5.0,
                    Color32::from_rgb(220, 38, 38),
                );
            }
        }
        response
    }
}
