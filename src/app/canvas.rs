//! The work-area canvas: pan and zoom, field selection and dragging, hover information.
//! Drawing is in `super::paint`; the canvas never changes the document, it returns
//! [`CanvasAction`]s that the app turns into commands.

use super::draw::{colour, View};
use super::hit::HitIndex;
use super::paint;
use super::scene::Canvas;
use crate::document::{Geometry, MachineProfile, ScanField};
use crate::geom::{BBox, Pt};
use egui::{Color32, PointerButton, Rect, Sense, Vec2};

/// What a drag is doing.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
enum Drag {
    #[default]
    None,
    Pan,
    /// Moving a field; `grab` is the field centre minus the pointer position at the start.
    Field {
        id: usize,
        grab: Pt,
    },
    /// Moving code `code` of every part: from the pointer at `from` to the pointer at `to`.
    Code {
        code: usize,
        from: Pt,
        to: Pt,
    },
    /// Moving a seam of `axis` (0: vertical) from `from_mm`: the pointer is at `wanted_mm`,
    /// the seam at `at_mm`, as far towards it as its neighbours allow.
    Seam {
        axis: usize,
        from_mm: f64,
        wanted_mm: f64,
        at_mm: f64,
    },
}

/// What ends with a drag: the field drag's undo group, a code or a seam moved.
fn drag_end(drag: Drag) -> Option<CanvasAction> {
    match drag {
        Drag::Field { .. } => Some(CanvasAction::EndDrag),
        Drag::Code { code, from, to } if from.dist(to) > 1e-6 => Some(CanvasAction::MoveCode {
            code,
            by: to.minus(from),
        }),
        // a seam that could not move stays, and says why
        Drag::Seam {
            axis,
            from_mm,
            wanted_mm,
            at_mm,
        } if (at_mm - from_mm).abs() < SEAM_STILL_MM
            && (wanted_mm - from_mm).abs() > SEAM_STILL_MM =>
        {
            Some(CanvasAction::SeamStays {
                axis,
                from_mm,
                to_mm: wanted_mm,
            })
        }
        Drag::Seam {
            axis,
            from_mm,
            wanted_mm,
            at_mm,
        } if (at_mm - from_mm).abs() >= SEAM_STILL_MM => Some(CanvasAction::MoveSeam {
            axis,
            from_mm,
            to_mm: wanted_mm,
        }),
        _ => None,
    }
}

/// The canvas's controls in words, bottom left: what the left button, the middle button, the
/// wheel and F do (a label, so that it can be read out).
fn show_hint(ui: &mut egui::Ui, rect: Rect, editable: bool) {
    let words = if editable {
        "drag: pan · drag a field's free area, a seam or a code: move it · middle-drag: pan · \
         wheel: zoom · F: fit"
    } else {
        "drag or middle-drag: pan · wheel: zoom"
    };
    let font = egui::FontId::proportional(11.0);
    let ink = Color32::from_gray(70);
    let size = ui
        .painter()
        .layout_no_wrap(words.into(), font.clone(), ink)
        .size();
    // bottom right (the scale bar is bottom left)
    let at = rect.right_bottom() + Vec2::new(-8.0 - size.x, -6.0 - size.y);
    let r = Rect::from_min_size(at, size + Vec2::new(2.0, 0.0));
    if !rect.contains_rect(r) {
        return;
    }
    ui.painter()
        .rect_filled(r.expand(3.0), 3.0, Color32::from_white_alpha(210));
    // a child ui of its own: the label takes no room in the canvas's layout (beside a second
    // canvas, the compare view's, it would push that one away)
    let mut child = ui.new_child(egui::UiBuilder::new().max_rect(r));
    child.add(egui::Label::new(egui::RichText::new(words).font(font).color(ink)).selectable(false));
}

/// A seam drag that moves it less than this does not move it, mm (a tenth of what the
/// status says, 0.1 mm).
const SEAM_STILL_MM: f64 = 0.05;

/// The wheel (or a pinch) zooms `view` about the cursor; true when it did.
fn zoom_about_cursor(
    ui: &egui::Ui,
    response: &egui::Response,
    rect: Rect,
    view: &mut View,
) -> bool {
    let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
    let factor = zoom * (scroll / 200.0).exp();
    if (factor - 1.0).abs() > 1e-4 {
        if let Some(cursor) = response.hover_pos() {
            let before = view.to_mm(rect, cursor);
            view.scale = (view.scale * factor).clamp(0.01, 1000.0);
            let after = view.to_screen(rect, before);
            view.offset += cursor - after;
            return true;
        }
    }
    false
}

/// How near a seam the pointer grabs it, px.
const SEAM_GRAB_PX: f32 = 5.0;

/// Pan/zoom and gesture state of a canvas (shared by synchronised canvases).
#[derive(Debug, Clone, Default)]
pub struct CanvasState {
    /// The view.
    pub view: View,
    /// The rectangle of the last frame (screen coordinates).
    pub rect: Option<Rect>,
    /// Fit the content (artwork and fields) on the next frame.
    pub fit_requested: bool,
    /// With `fit_requested`: fit the machine's whole reach with the content (F, *Fit to
    /// view*), so that where the artwork lies on the stage can be seen.
    pub fit_whole: bool,
    /// The operator panned or zoomed since the view was last fitted: a resized canvas then
    /// keeps the view (anchored to its centre) instead of fitting again.
    moved: bool,
    /// The last fit showed the machine's whole reach (a resize fits the same way).
    fitted_whole: bool,
    drag: Drag,
    /// The tray cell the context menu is open for: (cell, it is skipped).
    context_cell: Option<(u32, bool)>,
    /// The undo group of the field drag under way (one undo step per drag).
    pub drag_group: u64,
    /// A field is being dragged.
    pub dragging: bool,
}

/// What the operator did on an editable canvas.
#[derive(Debug, Clone, PartialEq)]
pub enum CanvasAction {
    /// Selected a field (or nothing).
    Select(Option<usize>),
    /// Dragged a field to a new centre (every frame of the drag).
    Move {
        /// Field id.
        id: usize,
        /// Requested centre, mm.
        center: Pt,
    },
    /// A field drag ended.
    EndDrag,
    /// Asked for a new field there (add tool click or double-click).
    Add(Pt),
    /// Left a tray cell out (`skip`), or marked it again, from its context menu.
    SkipCell {
        /// The cell (row by row from 1).
        cell: u32,
        /// Leave it out.
        skip: bool,
    },
    /// Moved a code of the part, on every part (at the end of its drag).
    MoveCode {
        /// The code's index in the production's codes.
        code: usize,
        /// How far, mm.
        by: Pt,
    },
    /// Moved a seam (at the end of its drag).
    MoveSeam {
        /// 0: a vertical seam (x), 1: a horizontal one (y).
        axis: usize,
        /// Where it was, mm.
        from_mm: f64,
        /// Where it was dropped, mm (it goes as far towards it as its neighbours allow).
        to_mm: f64,
    },
    /// Dragged a seam that its neighbours keep where it is.
    SeamStays {
        /// 0: a vertical seam (x), 1: a horizontal one (y).
        axis: usize,
        /// Where it is, mm.
        from_mm: f64,
        /// Where it was dropped, mm.
        to_mm: f64,
    },
}

/// Screen distance within which the pointer "hovers" a geometry, px.
const HOVER_PX: f32 = 6.0;

impl Canvas<'_> {
    /// What the canvas calls field `f` ([`super::words::field_word`]); a cylinder's strips are
    /// fields (a cylinder is never marked on the fly), whatever the diameter typed since.
    pub fn field_word(&self, f: &crate::document::ScanField) -> &'static str {
        if self.cylinder.is_some() {
            "field"
        } else {
            super::words::field_word(f, &self.profile)
        }
    }

    /// Reach of the laser: the base stroke grown by half a field.
    pub fn reach(profile: &MachineProfile) -> (Pt, Pt) {
        let [fw, fh] = profile.field_mm;
        let [sw, sh] = profile.stroke_mm;
        (
            Pt::new(-fw / 2.0, -fh / 2.0),
            Pt::new(sw + fw / 2.0, sh + fh / 2.0),
        )
    }

    /// What "fit to view" shows: the artwork and the fields (the laser's reach when empty),
    /// with a small margin.
    pub fn content_bounds(&self) -> (Pt, Pt) {
        let b = self
            .geometries
            .iter()
            .map(Geometry::bbox)
            .chain(self.fields.iter().map(ScanField::bbox))
            .fold(BBox::EMPTY, BBox::union);
        if b.is_empty() || !b.width().is_finite() {
            return Self::reach(&self.profile);
        }
        let m = 0.03 * b.width().max(b.height()).max(1.0);
        (
            Pt::new(b.min_x - m, b.min_y - m),
            Pt::new(b.max_x + m, b.max_y + m),
        )
    }

    /// Shows the canvas in `size` (the available space when `None`); returns the response and
    /// the operator's actions. Drag pans (or moves the field under the pointer when editable),
    /// the middle button always pans, the wheel zooms about the cursor.
    pub fn show(
        &self,
        ui: &mut egui::Ui,
        state: &mut CanvasState,
        size: Option<Vec2>,
    ) -> (egui::Response, Vec<CanvasAction>) {
        let size = size.unwrap_or_else(|| ui.available_size());
        let (rect, response) = ui.allocate_exact_size(size, Sense::click_and_drag());
        let label = match self.parts.iter().filter(|b| b.part.is_some()).count() {
            0 => self.label.to_string(),
            n => format!("{}: a tray of {n} parts, numbered 1 to {n}", self.label),
        };
        response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, &label));
        let mut actions = Vec::new();
        if let Some(old) = state.rect.filter(|old| old.size() != rect.size()) {
            if state.moved {
                // keep the content anchored to the centre when the canvas is resized
                state.view.offset += (rect.size() - old.size()) / 2.0;
            } else {
                // a view the operator has not moved follows the canvas: fitted again
                state.fit_requested = true;
                state.fit_whole |= state.fitted_whole;
            }
        }
        if state.view.scale == 0.0 || state.fit_requested {
            // the caption (top left) keeps its own band above the content
            let caption_px = paint::caption_px(ui.painter(), self, rect.width());
            let below_caption = Rect::from_min_max(
                rect.min + Vec2::Y * caption_px.min(rect.height() * 0.5),
                rect.max,
            );
            let (lo, hi) = self.content_bounds();
            let (lo, hi) = if state.fit_whole {
                let (rlo, rhi) = Canvas::reach(&self.profile);
                (
                    Pt::new(lo.x.min(rlo.x), lo.y.min(rlo.y)),
                    Pt::new(hi.x.max(rhi.x), hi.y.max(rhi.y)),
                )
            } else {
                (lo, hi)
            };
            state.view.fit(below_caption, lo, hi);
            state.fitted_whole = state.fit_whole;
            state.fit_whole = false;
            state.moved = false;
            state.view.offset += below_caption.min - rect.min;
            state.fit_requested = false;
        }
        state.rect = Some(rect);
        self.interact(ui, &response, rect, state, &mut actions);
        let painter = ui.painter_at(rect);
        paint::paint(&painter, self, &state.view, rect, response.id);
        self.paint_parts(&painter, &state.view, rect);
        self.paint_codes(&painter, &state.view, rect, state.drag);
        self.part_menu(&response, rect, state, &mut actions);
        self.paint_seam_drag(ui, &painter, rect, state);
        if state.drag == Drag::None {
            self.paint_grab(ui, &painter, &response, rect, &state.view);
        }
        show_hint(ui, rect, self.editable);
        let response = if state.drag == Drag::None {
            self.hover_info(response, rect, &state.view)
        } else {
            response
        };
        (response, actions)
    }

    /// The seam being dragged, across the work area, with where it is and, when its neighbours
    /// stop it short of the pointer, why.
    fn paint_seam_drag(
        &self,
        ui: &egui::Ui,
        painter: &egui::Painter,
        rect: Rect,
        state: &CanvasState,
    ) {
        if let Drag::Seam {
            axis,
            from_mm,
            wanted_mm,
            at_mm,
        } = state.drag
        {
            // the seam being moved, across the work area
            let (lo, hi) = Canvas::reach(&self.profile);
            let (a, b) = if axis == 0 {
                (Pt::new(at_mm, lo.y), Pt::new(at_mm, hi.y))
            } else {
                (Pt::new(lo.x, at_mm), Pt::new(hi.x, at_mm))
            };
            let s = |q: Pt| state.view.to_screen(rect, q);
            painter.line_segment([s(a), s(b)], egui::Stroke::new(2.0, colour::SEAM));
            if let Some(p) = ui.input(|i| i.pointer.hover_pos()) {
                // white on the seam's colour: readable over dark hatch
                let which = if axis == 0 { "x" } else { "y" };
                let stops = self
                    .tiling
                    .and_then(|t| {
                        crate::fields::seam_stop_reason(
                            t,
                            axis,
                            from_mm,
                            wanted_mm,
                            self.cell_max_mm,
                        )
                    })
                    .map(|why| format!("\nstops here: {why}"))
                    .unwrap_or_default();
                let galley = painter.layout_no_wrap(
                    format!("seam {which} = {at_mm:.1} mm{stops}"),
                    egui::FontId::proportional(13.0),
                    egui::Color32::WHITE,
                );
                // beside the pointer, kept inside the canvas
                let size = galley.size() + Vec2::new(6.0, 2.0);
                let mut at = p + Vec2::new(12.0, -12.0 - galley.size().y);
                at.x = at.x.min(rect.right() - size.x).max(rect.left());
                at.y = at.y.max(rect.top()).min(rect.bottom() - size.y);
                let bg = Rect::from_min_size(at, size);
                painter.rect_filled(bg, 3.0, colour::SEAM);
                painter.galley(at + Vec2::new(3.0, 1.0), galley, egui::Color32::WHITE);
            }
        }
    }

    /// The field a press under the pointer would move, outlined before the press (a press on
    /// the artwork, a seam or a code moves something else).
    fn paint_grab(
        &self,
        ui: &egui::Ui,
        painter: &egui::Painter,
        response: &egui::Response,
        rect: Rect,
        view: &View,
    ) {
        if !self.editable || self.add_tool {
            return;
        }
        let Some(p) = response.hover_pos() else {
            return;
        };
        let at = view.to_mm(rect, p);
        let tol = f64::from(HOVER_PX / view.scale.max(1e-6));
        // a seam a press would move: drawn thick across the tiling before the press
        let seam = self.seam_at(at, f64::from(SEAM_GRAB_PX / view.scale));
        if let (Some((axis, at_mm)), Some(t)) = (seam, self.tiling) {
            let e = t.extent();
            let (a, b) = if axis == 0 {
                (Pt::new(at_mm, e.min_y), Pt::new(at_mm, e.max_y))
            } else {
                (Pt::new(e.min_x, at_mm), Pt::new(e.max_x, at_mm))
            };
            let s = |q: Pt| view.to_screen(rect, q);
            painter.line_segment([s(a), s(b)], egui::Stroke::new(3.0, colour::SELECTED));
        }
        let elsewhere = seam.is_some()
            || self.code_at(at, f64::from(4.0 / view.scale)).is_some()
            || self.geometry_at(ui.ctx(), response.id, at, tol).is_some();
        let Some(f) = self.field_at(at).filter(|f| !f.locked && !elsewhere) else {
            return;
        };
        let b = f.bbox();
        let r = Rect::from_two_pos(
            view.to_screen(rect, Pt::new(b.min_x, b.min_y)),
            view.to_screen(rect, Pt::new(b.max_x, b.max_y)),
        );
        painter.rect_stroke(
            r,
            0.0,
            egui::Stroke::new(3.0, colour::SELECTED),
            egui::StrokeKind::Middle,
        );
        ui.ctx().set_cursor_icon(egui::CursorIcon::Grab);
    }

    fn interact(
        &self,
        ui: &egui::Ui,
        response: &egui::Response,
        rect: Rect,
        state: &mut CanvasState,
        actions: &mut Vec<CanvasAction>,
    ) {
        if response.drag_started() {
            let origin = ui.input(|i| i.pointer.press_origin());
            let primary =
                self.editable && response.drag_started_by(PointerButton::Primary) && !self.add_tool;
            state.drag = match origin.filter(|_| primary) {
                Some(o) => {
                    let at = state.view.to_mm(rect, o);
                    let tol = f64::from(HOVER_PX / state.view.scale.max(1e-6));
                    let on_artwork = self.geometry_at(ui.ctx(), response.id, at, tol).is_some();
                    self.drag_from(at, &state.view, on_artwork, actions)
                }
                None => Drag::Pan,
            };
        }
        if response.dragged() {
            let at = response
                .interact_pointer_pos()
                .map(|p| state.view.to_mm(rect, p));
            match (state.drag, at) {
                (Drag::Pan | Drag::None, _) => {
                    state.view.offset += response.drag_delta();
                    state.moved |= response.drag_delta() != Vec2::ZERO;
                }
                (drag, Some(at)) => state.drag = self.drag_to(drag, at, actions),
                (_, None) => {}
            }
        }
        if response.drag_stopped() {
            actions.extend(drag_end(state.drag));
            state.drag = Drag::None;
        }
        let view = &mut state.view;
        if self.editable && state.drag == Drag::None {
            let grab = response.hover_pos().is_some_and(|p| {
                let mm = view.to_mm(rect, p);
                self.seam_at(mm, f64::from(SEAM_GRAB_PX / view.scale))
                    .is_some()
                    || self.code_at(mm, f64::from(4.0 / view.scale)).is_some()
            });
            if grab {
                ui.ctx().set_cursor_icon(egui::CursorIcon::Grab);
            }
        }
        if self.editable {
            if let Some(p) = response.interact_pointer_pos() {
                let mm = view.to_mm(rect, p);
                if response.double_clicked() || (response.clicked() && self.add_tool) {
                    actions.push(CanvasAction::Add(mm));
                } else if response.clicked() {
                    actions.push(CanvasAction::Select(self.field_at(mm).map(|f| f.id)));
                }
            }
        }
        if response.hovered() && zoom_about_cursor(ui, response, rect, &mut state.view) {
            state.moved = true;
        }
    }

    /// What a primary drag from `at` (mm) moves: a code, a seam, an unlocked field (selected
    /// too) when the press is not `on_artwork`, or the view.
    fn drag_from(
        &self,
        at: Pt,
        view: &View,
        on_artwork: bool,
        actions: &mut Vec<CanvasAction>,
    ) -> Drag {
        if let Some(c) = self.code_at(at, f64::from(4.0 / view.scale)) {
            return Drag::Code {
                code: c.code,
                from: at,
                to: at,
            };
        }
        if let Some((axis, from_mm)) = self.seam_at(at, f64::from(SEAM_GRAB_PX / view.scale)) {
            return Drag::Seam {
                axis,
                from_mm,
                wanted_mm: from_mm,
                at_mm: from_mm,
            };
        }
        // a press on the artwork pans; only one on a field's free area moves the field
        if on_artwork {
            return Drag::Pan;
        }
        match self.field_at(at) {
            Some(f) => {
                actions.push(CanvasAction::Select(Some(f.id)));
                if f.locked {
                    Drag::Pan
                } else {
                    Drag::Field {
                        id: f.id,
                        grab: f.center.minus(at),
                    }
                }
            }
            None => Drag::Pan,
        }
    }

    /// `drag` followed to the pointer at `at` (mm); a field's move is an action each frame.
    fn drag_to(&self, drag: Drag, at: Pt, actions: &mut Vec<CanvasAction>) -> Drag {
        match drag {
            Drag::Code { code, from, .. } => Drag::Code { code, from, to: at },
            Drag::Field { id, grab } => {
                actions.push(CanvasAction::Move {
                    id,
                    center: at.plus(grab),
                });
                drag
            }
            Drag::Seam { axis, from_mm, .. } => {
                let to_mm = if axis == 0 { at.x } else { at.y };
                // where the seam will land: as far as its neighbours allow
                let at_mm = self
                    .tiling
                    .and_then(|t| {
                        crate::fields::move_seam(t, axis, from_mm, to_mm, self.cell_max_mm)
                    })
                    .map_or(to_mm, |(_, at)| at);
                Drag::Seam {
                    axis,
                    from_mm,
                    wanted_mm: to_mm,
                    at_mm,
                }
            }
            Drag::Pan | Drag::None => drag,
        }
    }

    /// The seam within `tol_mm` of `p` (along the tiling's extent): its axis and position.
    pub fn seam_at(&self, p: Pt, tol_mm: f64) -> Option<(usize, f64)> {
        let extent = self.tiling?.extent();
        self.seams
            .iter()
            .filter(|l| {
                let (across, along, lo, hi) = if l.axis == 0 {
                    (p.x, p.y, extent.min_y, extent.max_y)
                } else {
                    (p.y, p.x, extent.min_x, extent.max_x)
                };
                (across - l.at_mm).abs() <= tol_mm && along >= lo - tol_mm && along <= hi + tol_mm
            })
            .min_by(|a, b| {
                let d = |l: &crate::geom::seam::SeamLine| {
                    (if l.axis == 0 { p.x } else { p.y } - l.at_mm).abs()
                };
                d(a).total_cmp(&d(b))
            })
            .map(|l| (l.axis, l.at_mm))
    }

    /// The field under a point: of those holding it, the one with the nearest centre.
    pub fn field_at(&self, p: Pt) -> Option<&ScanField> {
        self.fields
            .iter()
            .filter(|f| f.bbox().contains_pt(p, 0.0))
            .min_by(|a, b| p.dist2(a.center).total_cmp(&p.dist2(b.center)))
    }

    /// The geometry nearest to `p` within `tol_mm`, found through a grid over the geometries
    /// kept in `ctx`'s memory under `id` while the artwork stays the same.
    pub fn geometry_at(
        &self,
        ctx: &egui::Context,
        id: egui::Id,
        p: Pt,
        tol_mm: f64,
    ) -> Option<usize> {
        type Kept = (usize, usize, u64, std::sync::Arc<HitIndex>);
        let id = id.with("hit index");
        let key = (
            self.geometries.as_ptr() as usize,
            self.geometries.len(),
            self.revision,
        );
        let kept: Option<Kept> = ctx.data(|d| d.get_temp(id));
        let index = match kept {
            Some((ptr, len, rev, index)) if (ptr, len, rev) == key => index,
            _ => {
                let index = std::sync::Arc::new(HitIndex::new(self.geometries));
                let kept: Kept = (key.0, key.1, key.2, std::sync::Arc::clone(&index));
                ctx.data_mut(|d| d.insert_temp(id, kept));
                index
            }
        };
        index.nearest(self.geometries, p, tol_mm)
    }

    /// The code whose marks' box holds `p` (grown by `tol_mm`), mm.
    fn code_at(&self, p: Pt, tol_mm: f64) -> Option<&super::tray_panel::CodeBox> {
        self.codes.iter().find(|c| c.bbox.contains_pt(p, tol_mm))
    }

    /// The tray cell at `p`, mm.
    fn part_at(&self, p: Pt) -> Option<&super::tray_panel::PartBox> {
        self.parts.iter().find(|b| b.bbox.contains_pt(p, 0.0))
    }

    /// Each marked part's number at its top-left corner; skipped cells greyed.
    fn paint_parts(&self, painter: &egui::Painter, view: &View, rect: Rect) {
        for b in self.parts {
            let s = |x: f64, y: f64| view.to_screen(rect, Pt::new(x, y));
            let r =
                Rect::from_two_pos(s(b.bbox.min_x, b.bbox.min_y), s(b.bbox.max_x, b.bbox.max_y));
            match b.part {
                None => {
                    painter.rect_filled(r, 2.0, Color32::from_black_alpha(60));
                    if r.width() > 40.0 {
                        painter.text(
                            r.center(),
                            egui::Align2::CENTER_CENTER,
                            format!("cell {} skipped", b.cell),
                            egui::FontId::proportional(11.0),
                            Color32::from_gray(70),
                        );
                    }
                }
                Some(n) if r.width() > 14.0 => {
                    painter.text(
                        r.left_top() + Vec2::new(2.0, 1.0),
                        egui::Align2::LEFT_TOP,
                        n.to_string(),
                        egui::FontId::proportional(11.0),
                        Color32::from_rgb(29, 78, 216),
                    );
                }
                Some(_) => {}
            }
        }
    }

    /// Each code's box, thin; the code being dragged outlined where it will go on every part,
    /// with its move in mm.
    fn paint_codes(&self, painter: &egui::Painter, view: &View, rect: Rect, drag: Drag) {
        let moving = match drag {
            Drag::Code { code, from, to } => Some((code, to.minus(from))),
            _ => None,
        };
        let code_colour = Color32::from_rgb(124, 58, 237);
        for c in self.codes {
            let s = |x: f64, y: f64| view.to_screen(rect, Pt::new(x, y));
            let b = &c.bbox;
            let r = Rect::from_two_pos(s(b.min_x, b.min_y), s(b.max_x, b.max_y)).expand(1.0);
            match moving {
                Some((k, d)) if k == c.code => {
                    let to = Rect::from_two_pos(
                        s(b.min_x + d.x, b.min_y + d.y),
                        s(b.max_x + d.x, b.max_y + d.y),
                    )
                    .expand(1.0);
                    let stroke = egui::Stroke::new(2.0, code_colour);
                    painter.rect_stroke(to, 1.0, stroke, egui::StrokeKind::Outside);
                    if c.part == 1 {
                        painter.text(
                            to.right_top() + Vec2::new(4.0, 0.0),
                            egui::Align2::LEFT_TOP,
                            format!("{}: moved {:+.2}, {:+.2} mm", c.name, d.x, d.y),
                            egui::FontId::proportional(12.0),
                            code_colour,
                        );
                    }
                }
                _ if r.width() > 6.0 => {
                    let stroke = egui::Stroke::new(1.0, code_colour.gamma_multiply(0.6));
                    painter.rect_stroke(r, 1.0, stroke, egui::StrokeKind::Outside);
                }
                _ => {}
            }
        }
    }

    /// The context menu of a tray cell: *Skip this part* or *Mark this part*.
    fn part_menu(
        &self,
        response: &egui::Response,
        rect: Rect,
        state: &mut CanvasState,
        actions: &mut Vec<CanvasAction>,
    ) {
        if !self.editable || self.parts.is_empty() {
            return;
        }
        if response.secondary_clicked() {
            state.context_cell = response
                .interact_pointer_pos()
                .map(|p| state.view.to_mm(rect, p))
                .and_then(|p| self.part_at(p))
                .map(|b| (b.cell, b.part.is_none()));
        }
        let Some((cell, skipped)) = state.context_cell else {
            return;
        };
        response.context_menu(|ui| {
            let (button, skip) = if skipped {
                ("Mark this part", false)
            } else {
                ("Skip this part", true)
            };
            if ui
                .button(button)
                .on_hover_text("a skipped cell takes no part, no serial and no data row")
                .clicked()
            {
                actions.push(CanvasAction::SkipCell { cell, skip });
                ui.close();
            }
        });
    }

    /// The hover lines of stroke `k`: what shape it is and its layer, where it came from, its
    /// field and its place in each plan shown.
    fn stroke_lines(&self, k: usize, lines: &mut Vec<String>) {
        let g = &self.geometries[k];
        lines.push(format!(
            "{}, layer {}",
            g.shape_words(),
            super::layers::layer_label(&g.layer)
        ));
        // where it came from, by the drawing's own name when it gives one (an SVG id)
        let from = match g.source.element.strip_prefix('#') {
            Some(id) => format!(", from '{id}'"),
            None => String::new(),
        };
        lines.push(format!(
            "  stroke {} of the job{from}, {} vertices",
            k + 1,
            g.points.len()
        ));
        match self.fields.iter().find(|f| f.geometries.contains(&k)) {
            Some(f) => lines.push(format!(
                "  allocated to {} {}",
                self.field_word(f),
                super::words::field_number(self.fields, self.visiting, f.id)
            )),
            None if self.out_of_reach.contains(&k) => lines.push(
                "  no scan field can hold it: larger than a field or beyond the stage's reach"
                    .into(),
            ),
            None if self.uncovered.contains(&k) => {
                lines.push("  not covered by any field (magenta halo): add one, or re-place".into())
            }
            None => {}
        }
        for path in &self.paths {
            let Ok(l) = path.lowered else { continue };
            if let Some(i) = l.stroke_of_geometry(k) {
                let n = l.toolpath.strokes.len();
                lines.push(format!("  {}: stroke {} of {n}", path.plan.name, i + 1));
            }
        }
    }

    fn hover_info(&self, response: egui::Response, rect: Rect, view: &View) -> egui::Response {
        let Some(pos) = response.hover_pos() else {
            return response;
        };
        let p = view.to_mm(rect, pos);
        let tol = f64::from(HOVER_PX / view.scale.max(1e-6));
        let geometry = self.geometry_at(&response.ctx, response.id, p, tol);
        let field = self.field_at(p).filter(|_| self.layers.fields);
        let part = self.part_at(p);
        let mut lines = vec![format!("x {:.2} mm, y {:.2} mm", p.x, p.y)];
        if let Some(b) = part {
            lines.extend(b.words.iter().cloned());
        }
        if let Some(k) = geometry {
            self.stroke_lines(k, &mut lines);
        }
        if let Some((axis, at_mm)) = self
            .seam_at(p, f64::from(SEAM_GRAB_PX / view.scale))
            .filter(|_| self.editable)
        {
            let which = if axis == 0 { "x" } else { "y" };
            lines.push(format!(
                "seam {which} = {at_mm:.1} mm: drag it to move it (as far as its neighbours allow)"
            ));
        }
        if let Some(f) = field {
            let word = self.field_word(f);
            let size = if word == "field" {
                String::new()
            } else {
                // larger than the scan field: the stage carries the scan field across it
                format!(", {:.0} × {:.0} mm", f.size[0], f.size[1])
            };
            lines.push(format!(
                "{word} {}: centre ({:.2}, {:.2}) mm{size}, {}{}",
                super::words::field_number(self.fields, self.visiting, f.id),
                f.center.x,
                f.center.y,
                super::words::count(f.geometries.len(), "stroke", "strokes"),
                if f.locked { ", locked" } else { "" }
            ));
            let pose = super::words::pose_words(&f.pose, &self.profile);
            if !pose.is_empty() {
                lines.push(format!("  pose {pose}"));
            }
            if word == "region" {
                let [w, h] = self.profile.field_mm;
                lines.push(format!(
                    "  a region: larger than the {w:.0} × {h:.0} mm scan field, marked on the fly \
                     while the stage moves"
                ));
            }
        }
        if geometry.is_none() && field.is_none() && part.is_none() {
            return response;
        }
        response.on_hover_ui_at_pointer(|ui| {
            for l in &lines {
                ui.label(l);
            }
        })
    }
}
