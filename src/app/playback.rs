//! Playback of a plan's toolpath: the state (time, playing, speed; run time only), the control
//! strip above a canvas, and what the canvas draws at the playback time (marks done, the stage
//! with its scan field, the laser spot). Everything drawn comes from
//! [`Toolpath::state_at`](crate::motion::Toolpath::state_at) and the toolpath's strokes.

use super::toolpaths::Lowered;
use crate::geom::Pt;
use crate::motion::SegmentKind;
use egui::{Color32, Painter, Pos2, Rect, RichText, Shape, Stroke, StrokeKind, Vec2};

/// Playback speeds offered, × real time.
pub const SPEEDS_X: &[f64] = &[0.1, 1.0, 10.0, 100.0];

/// At the automatic speed a job plays in at most about this long (real time when it is short).
const AUTO_PLAY_S: f64 = 30.0;

/// Longest frame step taken into account, s (a stalled frame does not jump through the job).
const MAX_FRAME_S: f64 = 0.1;

/// Width of the time slider: what the row leaves beside the time text, within these, px.
const SLIDER_PX: (f32, f32) = (120.0, 520.0);

/// Room kept for the time text at the end of the row, px.
const TIME_TEXT_PX: f32 = 200.0;

/// Room the time label, the narrowest slider and the time text need beside the buttons, px
/// (else they take a row of their own).
const SLIDER_ROW_PX: f32 = 48.0 + SLIDER_PX.0 + TIME_TEXT_PX;

/// Playback state of one view (run time only, never saved).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Playback {
    /// The job time shown, s.
    pub t_s: f64,
    /// Advancing with the frames.
    pub playing: bool,
    /// The speed chosen, × real time; `None`: automatic ([`Playback::auto_speed_x`]).
    pub speed_x: Option<f64>,
}

impl Playback {
    /// Real time, or the slowest offered speed that plays the job within about 30 s.
    pub fn auto_speed_x(duration_s: f64) -> f64 {
        SPEEDS_X
            .iter()
            .copied()
            .filter(|&s| s >= 1.0)
            .find(|&s| duration_s / s <= AUTO_PLAY_S)
            .unwrap_or(SPEEDS_X[SPEEDS_X.len() - 1])
    }

    /// The speed in effect for a job of `duration_s`, × real time.
    pub fn speed_for(&self, duration_s: f64) -> f64 {
        self.speed_x
            .unwrap_or_else(|| Self::auto_speed_x(duration_s))
    }

    /// The time the canvas draws the machine at: `None` before the playback starts (the canvas
    /// then shows the planned path only).
    pub fn shown_t_s(&self) -> Option<f64> {
        (self.playing || self.t_s > 0.0).then_some(self.t_s)
    }

    /// Advances by `frame_s` of wall time at the current speed; stops at the end of the job.
    pub fn advance(&mut self, frame_s: f64, duration_s: f64) {
        self.t_s = self.t_s.clamp(0.0, duration_s.max(0.0));
        if !self.playing {
            return;
        }
        let step_s = frame_s.clamp(0.0, MAX_FRAME_S) * self.speed_for(duration_s);
        self.t_s = (self.t_s + step_s).min(duration_s);
        if self.t_s >= duration_s {
            self.playing = false;
        }
    }
}

/// Text of a time: `t = 1.23 s of 9.87 s`.
pub fn time_text(t_s: f64, duration_s: f64) -> String {
    format!("t = {t_s:.2} s of {duration_s:.2} s")
}

/// What the machine does at `t_s`, in words: e.g. `marking stroke 3 of 122, laser on`.
pub fn state_text(l: &Lowered, t_s: f64) -> String {
    let tp = &l.toolpath;
    let Some(seg) = tp.segments.get(tp.segment_at(t_s)) else {
        return "empty job".into();
    };
    let n = tp.strokes.len();
    let next = (l.strokes_done(t_s) + 1).min(n);
    let state = tp.state_at(t_s);
    let doing = match seg.kind {
        _ if t_s >= l.duration_s() => format!("job done: {n} strokes marked"),
        SegmentKind::Mark => format!("marking stroke {next} of {n}"),
        // on the fly the stage never stops at a field: this is the start of its route
        SegmentKind::StageMove if l.on_the_fly() => "stage getting under way on its route".into(),
        SegmentKind::StageMove => "stage moving to the next field".into(),
        SegmentKind::Settle => "stage settling".into(),
        SegmentKind::Jump => format!("scanner jumping to stroke {next} of {n}"),
        SegmentKind::JumpDelay => "scanner settling after a jump".into(),
        SegmentKind::LaserOnDelay => format!("laser-on delay before stroke {next}"),
        SegmentKind::LaserOffDelay => "laser-off delay".into(),
    };
    // a mixed job says which motion the stroke being marked (or next) runs in
    let how = match tp.strokes.get(next.saturating_sub(1)) {
        _ if tp.still_fields.is_empty() || t_s >= l.duration_s() => "",
        Some(s) if tp.marks_still(s.field) => " (step-and-scan field: the stage stops for it)",
        Some(_) => " (on the fly)",
        None => "",
    };
    // Z, A and B where the job turns them
    let pose = l.poses.as_ref().map_or(String::new(), |track| {
        format!(
            ", {}",
            super::words::pose_axes_words(&track.at(t_s), l.pose_axes, 1)
        )
    });
    // a machine without Y: its stage's X alone
    let stage = if l.has_y {
        format!("({:.1}, {:.1})", state.stage.x, state.stage.y)
    } else {
        format!("X {:.1}", state.stage.x)
    };
    format!(
        "{doing}{how}; stage {stage} mm{pose}; laser {}",
        if state.laser { "on" } else { "off" }
    )
}

/// The control strip: Rewind, Play/Pause, speed, time slider and the time in one row, and (with
/// `state_words`) the machine state in words in a second row. The widgets keep their places
/// while the time runs, so nothing moves under the pointer.
/// `job` is the toolpath played (`Err`: why it could not be lowered; `None`: no plan yet).
/// Advances a playing playback and asks for the next frame.
pub fn controls(
    ui: &mut egui::Ui,
    id: &str,
    pb: &mut Playback,
    job: Option<Result<&Lowered, &str>>,
    state_words: bool,
) {
    let lowered = job.and_then(Result::ok);
    let duration_s = lowered.map_or(0.0, Lowered::duration_s);
    if lowered.is_some() {
        let frame_s = f64::from(ui.input(|i| i.stable_dt));
        pb.advance(frame_s, duration_s);
        if pb.playing {
            ui.ctx().request_repaint();
        }
    }
    // on a narrow view the slider and the time go to a second row rather than out of sight
    let slider_row = |ui: &mut egui::Ui, pb: &mut Playback| {
        ui.add_enabled_ui(lowered.is_some(), |ui| time_slider(ui, pb, duration_s));
        if lowered.is_some() {
            ui.label(RichText::new(time_text(pb.t_s, duration_s)).monospace());
        }
    };
    let one_row = ui
        .horizontal(|ui| {
            ui.add_enabled_ui(lowered.is_some(), |ui| buttons(ui, id, pb, duration_s));
            let fits = ui.available_width() >= SLIDER_ROW_PX;
            if fits {
                slider_row(ui, pb);
            }
            fits
        })
        .inner;
    if !one_row {
        ui.horizontal(|ui| slider_row(ui, pb));
    }
    if !state_words && lowered.is_some() {
        return;
    }
    let words = match job {
        Some(Ok(l)) => RichText::new(state_text(l, pb.t_s)),
        Some(Err(why)) => RichText::new(why).color(Color32::from_rgb(200, 30, 30)),
        None => RichText::new("No plan yet: run a solver to play the job back.").weak(),
    };
    ui.add(egui::Label::new(words).truncate());
}

fn buttons(ui: &mut egui::Ui, id: &str, pb: &mut Playback, duration_s: f64) {
    if ui
        .button("Rewind")
        .on_hover_text("Back to the start of the job (the canvas shows the planned path)")
        .clicked()
    {
        *pb = Playback {
            speed_x: pb.speed_x,
            ..Playback::default()
        };
    }
    let (text, hint) = if pb.playing {
        ("Pause", "Stop the playback here")
    } else {
        ("Play", "Play the job on the canvas as the machine runs it")
    };
    if ui
        .add(egui::Button::new(text).min_size(Vec2::new(56.0, 0.0)))
        .on_hover_text(hint)
        .clicked()
    {
        if !pb.playing && pb.t_s >= duration_s {
            pb.t_s = 0.0;
        }
        pb.playing = !pb.playing;
    }
    let l = ui.label("Speed");
    let speed_text = |s: f64| format!("{s}×");
    let current = match pb.speed_x {
        Some(s) => speed_text(s),
        None => format!("auto ({})", speed_text(Playback::auto_speed_x(duration_s))),
    };
    egui::ComboBox::from_id_salt(format!("{id}-speed"))
        .selected_text(current)
        .width(96.0)
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut pb.speed_x, None, "auto");
            for &s in SPEEDS_X {
                ui.selectable_value(&mut pb.speed_x, Some(s), speed_text(s));
            }
        })
        .response
        .labelled_by(l.id)
        .on_hover_text("× real time; auto: real time, faster when the job is long");
}

/// The time slider, as wide as the row leaves beside the time text.
fn time_slider(ui: &mut egui::Ui, pb: &mut Playback, duration_s: f64) {
    let l = ui.label("Time");
    let room_px = ui.available_width() - TIME_TEXT_PX;
    ui.spacing_mut().slider_width = room_px.clamp(SLIDER_PX.0, SLIDER_PX.1);
    ui.add(
        egui::Slider::new(&mut pb.t_s, 0.0..=duration_s.max(1e-9))
            .show_value(false)
            .smart_aim(false),
    )
    .labelled_by(l.id)
    .on_hover_text("Job time shown on the canvas; drag to scrub");
}

/// Colour of the marks done (single plan; overlaid plans use their own colours).
const DONE: Color32 = Color32::from_rgb(17, 24, 39);
/// Colour of the laser spot.
const LASER: Color32 = Color32::from_rgb(220, 38, 38);
/// Colour of the stage marker and its scan field (apart from the placed fields' indigo).
const STAGE: Color32 = Color32::from_rgb(14, 116, 144);
/// Fill of the scan field around the stage.
const STAGE_FILL: Color32 = Color32::from_rgba_premultiplied(2, 16, 20, 36);

/// Draws the job at `t_s` in `rect` seen through `view`: marks done (the current one up to the
/// tool point), the stage as a cross with the scan-field outline (`field_mm`) around it, and
/// the laser spot (filled when the laser is on, hollow when off). `done` is `None` for the
/// single-plan colour. The marks done are kept as a raster under `id` that grows with them
/// (`raster::paint_prefix`): a frame draws only the marks since the last raster, not all.
#[allow(clippy::too_many_arguments)]
pub fn paint(
    painter: &Painter,
    id: egui::Id,
    l: &Lowered,
    t_s: f64,
    field_mm: [f64; 2],
    done: Option<Color32>,
    view: &super::draw::View,
    rect: Rect,
) {
    let to_screen = |q: Pt| view.to_screen(rect, q);
    let tp = &l.toolpath;
    let marks = Stroke::new(2.2, done.unwrap_or(DONE));
    let n_done = l.strokes_done(t_s);
    let content = {
        use std::hash::{Hash, Hasher};
        let mut h = rustc_hash::FxHasher::default();
        (std::ptr::from_ref(l) as usize, tp.strokes.len()).hash(&mut h);
        marks.color.to_array().hash(&mut h);
        h.finish()
    };
    let marks_done = |range: std::ops::Range<usize>, clip: Rect| -> Vec<Shape> {
        range
            .filter_map(|k| {
                // at screen resolution, and none off the canvas
                super::draw::screen_line(l.points(k), false, &to_screen, clip)
                    .map(|pts| polyline(pts.into_iter(), marks))
            })
            .collect()
    };
    super::raster::paint_prefix(
        painter.ctx(),
        painter,
        id,
        content,
        n_done,
        (view.scale, view.offset),
        rect,
        &marks_done,
    );
    let state = tp.state_at(t_s);
    // on a cylinder: the surface under the head, the strip in focus around it
    let (tcp, stage_at) = l.shown_at(t_s);
    let field_mm = match l.unrolled.as_ref().and_then(|u| u.strip_mm) {
        Some(strip) => [field_mm[0], strip],
        None => field_mm,
    };
    if let Some(&(start_s, end_s)) = l.mark_s.get(n_done) {
        if state.laser && t_s >= start_s && end_s > start_s {
            let u = (t_s - start_s) / (end_s - start_s);
            let pts = partial(l.points(n_done), u, tcp);
            painter.add(polyline(pts.into_iter().map(to_screen), marks));
        }
    }
    let stage = to_screen(stage_at);
    let half = Pt::new(field_mm[0] / 2.0, field_mm[1] / 2.0);
    let r = Rect::from_two_pos(
        to_screen(stage_at.minus(half)),
        to_screen(stage_at.plus(half)),
    );
    painter.rect(
        r,
        0.0,
        STAGE_FILL,
        Stroke::new(2.5, STAGE),
        StrokeKind::Middle,
    );
    let arm = 10.0;
    let cross = Stroke::new(2.5, STAGE);
    painter.line_segment([stage - Vec2::X * arm, stage + Vec2::X * arm], cross);
    painter.line_segment([stage - Vec2::Y * arm, stage + Vec2::Y * arm], cross);
    let spot = to_screen(tcp);
    if state.laser {
        painter.circle(spot, 6.0, LASER, Stroke::new(1.5, Color32::WHITE));
    } else {
        painter.circle(spot, 6.0, Color32::WHITE, Stroke::new(2.5, LASER));
    }
}

fn polyline(pts: impl Iterator<Item = Pos2>, stroke: Stroke) -> Shape {
    let pts: Vec<Pos2> = pts.collect();
    match pts.as_slice() {
        [p] => Shape::circle_filled(*p, stroke.width / 2.0, stroke.color),
        _ => Shape::line(pts, stroke),
    }
}

/// The points of a stroke marked up to fraction `u` of its length, ending at `tool`.
fn partial(points: &[Pt], u: f64, tool: Pt) -> Vec<Pt> {
    let total_mm: f64 = points.windows(2).map(|w| w[0].dist(w[1])).sum();
    let target_mm = u.clamp(0.0, 1.0) * total_mm;
    let mut out = Vec::with_capacity(points.len() + 1);
    let mut arc_mm = 0.0;
    for (k, &p) in points.iter().enumerate() {
        if k > 0 {
            arc_mm += p.dist(points[k - 1]);
        }
        if arc_mm > target_mm {
            break;
        }
        out.push(p);
    }
    out.push(tool);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advance_plays_at_the_speed_and_stops_at_the_end() {
        let mut pb = Playback::default();
        assert_eq!(pb.shown_t_s(), None);
        pb.advance(0.05, 10.0);
        assert_eq!(pb.t_s, 0.0, "paused: no time passes");
        pb.playing = true;
        pb.speed_x = Some(10.0);
        pb.advance(0.05, 10.0);
        assert!((pb.t_s - 0.5).abs() < 1e-12);
        assert_eq!(pb.shown_t_s(), Some(pb.t_s));
        pb.advance(5.0, 10.0);
        assert!((pb.t_s - 1.5).abs() < 1e-12, "a stalled frame counts 0.1 s");
        for _ in 0..20 {
            pb.advance(0.1, 10.0);
        }
        assert_eq!(pb.t_s, 10.0);
        assert!(!pb.playing);
    }

    #[test]
    fn auto_speed_is_real_time_for_short_jobs() {
        assert_eq!(Playback::auto_speed_x(9.0), 1.0);
        assert_eq!(Playback::auto_speed_x(200.0), 10.0);
        assert_eq!(Playback::auto_speed_x(1e6), 100.0);
    }

    #[test]
    fn partial_stroke_ends_at_the_tool() {
        let pts = [Pt::new(0.0, 0.0), Pt::new(10.0, 0.0), Pt::new(10.0, 10.0)];
        let p = partial(&pts, 0.75, Pt::new(10.0, 5.0));
        assert_eq!(p, vec![pts[0], pts[1], Pt::new(10.0, 5.0)]);
        assert_eq!(partial(&pts, 0.0, pts[0]), vec![pts[0], pts[0]]);
    }
}
