//! Drawing of a [`Canvas`]: base stroke, fields, artwork, uncovered geometries, planned paths
//! (from each plan's lowered toolpath) and the playback of a job.

use super::draw::{colour, screen_line, View, CULL_MARGIN_PX};
use super::motion_plots;
use super::playback;
use super::scene::{Canvas, PathLayer};
use super::toolpaths::Lowered;
use crate::geom::Pt;
use egui::{Align2, Color32, FontId, Painter, Pos2, Rect, Shape, Stroke, StrokeKind, Vec2};

/// A field's number is drawn only when the field is at least this much wider than its label
/// and this tall on screen, px: smaller, the labels of neighbours overlap into a blob.
const LABEL_MIN_H_PX: f32 = 18.0;

/// Width of a digit of a field label, px (13 px proportional font, a little over): the label's
/// width is judged from it before the label is laid out.
const LABEL_CHAR_PX: f32 = 7.5;

/// Open geometries get dots at their ends only when at least this long on screen, px.
const END_DOTS_MIN_PX: f32 = 6.0;

fn lerp(a: Color32, b: Color32, t: f32) -> Color32 {
    let m = |x: u8, y: u8| (f32::from(x) + (f32::from(y) - f32::from(x)) * t).round() as u8;
    Color32::from_rgb(m(a.r(), b.r()), m(a.g(), b.g()), m(a.b(), b.b()))
}

/// Paints the canvas content into `rect`: the background, the heavy layers (from their raster
/// when there is one, see [`super::raster`]), then what is drawn over them every frame (field
/// labels, start and end markers, the playback, the caption and the scale bar).
pub fn paint(painter: &Painter, c: &Canvas<'_>, view: &View, rect: Rect, id: egui::Id) {
    paint_background(painter, c, view, rect);
    super::raster::paint(
        painter.ctx(),
        painter,
        id,
        content_key(c),
        (view.scale, view.offset),
        rect,
        &|clip| heavy_shapes(c, view, rect, clip),
    );
    if c.layers.fields {
        paint_field_labels(painter, c, view, rect);
    }
    if c.layers.path {
        for path in &c.paths {
            if let Ok(lowered) = path.lowered {
                paint_markers(painter, lowered, view, rect);
            }
        }
    }
    if let Some(t_s) = c.playback_t_s {
        let overlaid = c.paths.len() > 1;
        for (k, path) in c.paths.iter().enumerate() {
            if let Ok(l) = path.lowered {
                let done = overlaid.then_some(path.colour);
                let field_mm = c.profile.field_mm;
                playback::paint(painter, id.with(k), l, t_s, field_mm, done, view, rect);
            }
        }
    }
    paint_caption(painter, c, rect);
    paint_scale_bar(painter, view, rect);
}

/// The work area: the laser's reach and the base stroke (dashed, named).
fn paint_background(painter: &Painter, c: &Canvas<'_>, view: &View, rect: Rect) {
    painter.rect_filled(rect, 0.0, Color32::from_gray(252));
    let s = |q: Pt| view.to_screen(rect, q);
    let (lo, hi) = Canvas::reach(&c.profile);
    let [sw, sh] = c.profile.stroke_mm;
    painter.rect_filled(Rect::from_two_pos(s(lo), s(hi)), 0.0, Color32::WHITE);
    painter.rect_stroke(
        Rect::from_two_pos(s(lo), s(hi)),
        0.0,
        Stroke::new(1.0, Color32::from_gray(210)),
        StrokeKind::Middle,
    );
    let corners = [
        Pt::new(0.0, 0.0),
        Pt::new(sw, 0.0),
        Pt::new(sw, sh),
        Pt::new(0.0, sh),
        Pt::new(0.0, 0.0),
    ]
    .map(s);
    painter.extend(Shape::dashed_line(
        &corners,
        Stroke::new(1.0, Color32::from_gray(140)),
        6.0,
        4.0,
    ));
    let Some(cylinder) = c.cylinder else {
        painter.text(
            s(Pt::new(0.0, 0.0)) + Vec2::new(2.0, -2.0),
            Align2::LEFT_BOTTOM,
            format!("base stroke {sw:.0} × {sh:.0} mm"),
            FontId::proportional(11.0),
            Color32::from_gray(120),
        );
        return;
    };
    paint_wrap_lines(painter, cylinder, (lo, hi), rect, &s);
}

/// A cylinder's unrolled surface: its wrap lines (y = 0, one and two turns around, where the
/// surface meets itself) dashed and named, across the reach.
fn paint_wrap_lines(
    painter: &Painter,
    cylinder: crate::document::Cylinder,
    (lo, hi): (Pt, Pt),
    rect: Rect,
    s: &dyn Fn(Pt) -> Pos2,
) {
    let around = cylinder.circumference_mm();
    let colour = Color32::from_rgb(37, 99, 235);
    for turn in 0..=2 {
        let y = f64::from(turn) * around;
        let line = [Pt::new(lo.x, y), Pt::new(hi.x, y)].map(s);
        painter.extend(Shape::dashed_line(
            &line,
            Stroke::new(1.5, colour),
            8.0,
            5.0,
        ));
        let words = match turn {
            0 => format!(
                "cylinder ⌀{} mm unrolled: x along its axis, y around it (0°)",
                crate::geom::format_mm(cylinder.diameter_mm, 3)
            ),
            _ => format!(
                "wrap line: {} turn{} around ({:.1} mm), the surface meets itself",
                turn,
                if turn == 1 { "" } else { "s" },
                y
            ),
        };
        // the words stay on the canvas when the view is panned or zoomed past the line's start;
        // the 0° line's above it, the turns' below theirs, where the drawing seldom reaches
        let at = Pos2::new(line[0].x.max(rect.left()), line[0].y);
        let (offset, align) = match turn {
            0 => (Vec2::new(2.0, -2.0), Align2::LEFT_BOTTOM),
            _ => (Vec2::new(2.0, 2.0), Align2::LEFT_TOP),
        };
        painter.text(
            at + offset,
            align,
            words,
            FontId::proportional(11.0),
            colour,
        );
    }
}

/// A fingerprint of everything [`heavy_shapes`] draws but the view: a raster is shown only for
/// the content it was drawn from. Slices too large to hash every frame (geometries, their
/// colours, coverage) count by identity and length, with the canvas's `revision`, which
/// changes with them; fields, seams, layers and paths by value.
fn content_key(c: &Canvas<'_>) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = rustc_hash::FxHasher::default();
    c.revision.hash(&mut h);
    let slice = |h: &mut rustc_hash::FxHasher, ptr: usize, len: usize| {
        ptr.hash(h);
        len.hash(h);
    };
    slice(&mut h, c.geometries.as_ptr() as usize, c.geometries.len());
    if let Some(colours) = c.colours {
        slice(&mut h, colours.as_ptr() as usize, colours.len());
    }
    slice(&mut h, c.uncovered.as_ptr() as usize, c.uncovered.len());
    slice(
        &mut h,
        c.out_of_reach.as_ptr() as usize,
        c.out_of_reach.len(),
    );
    for f in c.fields {
        (f.id, f.locked, f.geometries.len()).hash(&mut h);
        [f.center.x, f.center.y, f.size[0], f.size[1]]
            .map(f64::to_bits)
            .hash(&mut h);
    }
    for line in c.seams {
        (line.axis, line.at_mm.to_bits()).hash(&mut h);
        for span in &line.spans {
            span.map(f64::to_bits).hash(&mut h);
        }
    }
    c.tiling
        .map(|t| {
            let e = t.extent();
            [e.min_x, e.min_y, e.max_x, e.max_y].map(f64::to_bits)
        })
        .hash(&mut h);
    let l = c.layers;
    [l.fields, l.path, l.arrows, l.base_path, l.order_colours].hash(&mut h);
    c.selected.hash(&mut h);
    (c.stale.is_empty(), c.playback_t_s.is_some()).hash(&mut h);
    for p in &c.paths {
        p.colour.to_array().hash(&mut h);
        match p.lowered {
            Ok(l) => (std::ptr::from_ref(l) as usize, l.toolpath.strokes.len()).hash(&mut h),
            Err(why) => why.hash(&mut h),
        }
    }
    h.finish()
}

/// The heavy layers as shapes for `view` over the canvas `rect`, left out where wholly outside
/// `clip` (screen): fields, artwork, the stage's path or route, idle moves and seams.
pub(super) fn heavy_shapes(c: &Canvas<'_>, view: &View, rect: Rect, clip: Rect) -> Vec<Shape> {
    let mut shapes = Vec::new();
    if c.layers.fields {
        field_shapes(&mut shapes, c, view, rect, clip);
    }
    artwork_shapes(&mut shapes, c, view, rect, clip);
    // during a playback the planned path steps back behind the machine
    let path_fade = if c.playback_t_s.is_some() { 0.35 } else { 1.0 };
    for (k, path) in c.paths.iter().enumerate() {
        let Ok(lowered) = path.lowered else { continue };
        if c.layers.base_path && lowered.on_the_fly() {
            let col = if k == 0 {
                motion_plots::ROUTE
            } else {
                path.colour
            };
            route_shapes(
                &mut shapes,
                lowered,
                view,
                rect,
                col.gamma_multiply(path_fade),
            );
        } else if c.layers.base_path && k == 0 {
            base_path_shapes(&mut shapes, lowered, view, rect, path_fade);
        }
        if c.layers.path {
            idle_move_shapes(&mut shapes, c, path, lowered, view, rect, clip);
        }
    }
    // seams over the planned paths: an idle move along a seam must not hide it
    if c.layers.fields {
        seam_shapes(&mut shapes, c, view, rect);
    }
    shapes
}

/// A field's rectangle on screen, none when wholly outside `clip`.
fn field_on_screen(
    f: &crate::document::ScanField,
    view: &View,
    rect: Rect,
    clip: Rect,
) -> Option<Rect> {
    let s = |q: Pt| view.to_screen(rect, q);
    let b = f.bbox();
    let r = Rect::from_two_pos(s(Pt::new(b.min_x, b.min_y)), s(Pt::new(b.max_x, b.max_y)));
    r.expand(CULL_MARGIN_PX).intersects(clip).then_some(r)
}

/// The outline of field `f`: the selected one thick and amber, locked ones thicker.
fn field_stroke(c: &Canvas<'_>, f: &crate::document::ScanField) -> Stroke {
    if c.selected == Some(f.id) {
        Stroke::new(2.5, colour::SELECTED)
    } else {
        Stroke::new(
            if f.locked { 2.0 } else { 1.0 },
            colour::FIELD.gamma_multiply(0.8),
        )
    }
}

/// The toolpath of the first plan drawn, when it is a mixed job (its fields tinted by motion).
fn mixed_toolpath<'a>(c: &Canvas<'a>) -> Option<&'a crate::motion::Toolpath> {
    let first = c.paths.first()?.lowered.ok()?;
    (!first.toolpath.still_fields.is_empty()).then_some(&first.toolpath)
}

fn field_shapes(shapes: &mut Vec<Shape>, c: &Canvas<'_>, view: &View, rect: Rect, clip: Rect) {
    let fill = Color32::from_rgba_unmultiplied(79, 70, 229, 16);
    let [r, g, b, _] = colour::STILL_FIELD.to_array();
    let still_fill = Color32::from_rgba_unmultiplied(r, g, b, 48);
    let mixed = mixed_toolpath(c);
    for f in c.fields {
        if let Some(r) = field_on_screen(f, view, rect, clip) {
            let still = mixed.is_some_and(|t| t.marks_still(f.id));
            shapes.push(Shape::rect_filled(
                r,
                0.0,
                if still { still_fill } else { fill },
            ));
        }
    }
    for f in c.fields {
        if let Some(r) = field_on_screen(f, view, rect, clip) {
            let stroke = field_stroke(c, f);
            shapes.push(Shape::rect_stroke(r, 0.0, stroke, StrokeKind::Middle));
            shapes.push(Shape::circle_filled(
                view.to_screen(rect, f.center),
                2.0,
                stroke.color,
            ));
        }
    }
}

/// Field numbers (and "locked"), where legible: over the artwork, every frame.
fn paint_field_labels(painter: &Painter, c: &Canvas<'_>, view: &View, rect: Rect) {
    let mut numbers = None;
    for f in c.fields {
        let Some(r) = field_on_screen(f, view, rect, rect) else {
            continue;
        };
        let selected = c.selected == Some(f.id);
        // a label only where it is legible: the field wider than it and tall enough (judged
        // for a one-digit label first, before the numbers are counted)
        let est_w = |chars: usize| chars as f32 * LABEL_CHAR_PX + 6.0;
        if !selected && (r.height() < LABEL_MIN_H_PX || r.width() < est_w(1) * 1.5) {
            continue;
        }
        let numbers =
            numbers.get_or_insert_with(|| super::words::field_numbers(c.fields, c.visiting));
        let number = numbers.get(&f.id).copied().unwrap_or_default();
        // a scan field shows its number; a region larger than the scan field says so
        let name = match c.field_word(f) {
            "field" => format!("{number}"),
            word => format!("{word} {number}"),
        };
        let text = if f.locked {
            format!("{name} locked")
        } else {
            name
        };
        if !selected && r.width() < est_w(text.chars().count()) * 1.5 {
            continue;
        }
        let galley = painter.layout_no_wrap(text, FontId::proportional(13.0), Color32::WHITE);
        let at = r.min + Vec2::new(3.0, 3.0);
        let bg = Rect::from_min_size(at, galley.size() + Vec2::new(6.0, 2.0));
        painter.rect_filled(
            bg,
            3.0,
            if selected {
                colour::SELECTED
            } else {
                colour::FIELD.gamma_multiply(0.85)
            },
        );
        painter.galley(at + Vec2::new(3.0, 1.0), galley, Color32::WHITE);
    }
}

/// The seams: a thin line across the tiling's extent, solid and thick through marked area
/// (unlike the dashed idle moves).
fn seam_shapes(shapes: &mut Vec<Shape>, c: &Canvas<'_>, view: &View, rect: Rect) {
    let Some(extent) = c.tiling.map(crate::geom::tiling::Tiling::extent) else {
        return;
    };
    let s = |q: Pt| view.to_screen(rect, q);
    let at = |axis: usize, across: f64, along: f64| {
        if axis == 0 {
            s(Pt::new(across, along))
        } else {
            s(Pt::new(along, across))
        }
    };
    for line in c.seams {
        let (lo, hi) = if line.axis == 0 {
            (extent.min_y, extent.max_y)
        } else {
            (extent.min_x, extent.max_x)
        };
        shapes.push(Shape::line_segment(
            [at(line.axis, line.at_mm, lo), at(line.axis, line.at_mm, hi)],
            Stroke::new(1.0, colour::SEAM.gamma_multiply(0.6)),
        ));
        for span in &line.spans {
            let (a, b) = (
                at(line.axis, line.at_mm, span[0]),
                at(line.axis, line.at_mm, span[1]),
            );
            shapes.push(Shape::line_segment([a, b], Stroke::new(2.5, colour::SEAM)));
        }
    }
}

fn artwork_shapes(shapes: &mut Vec<Shape>, c: &Canvas<'_>, view: &View, rect: Rect, clip: Rect) {
    let s = |q: Pt| view.to_screen(rect, q);
    // marks coloured by their position in the first plan's toolpath (ranked once, when lowered)
    let rank: Option<&[f32]> = c
        .paths
        .first()
        .and_then(|p| p.lowered.ok())
        .filter(|_| c.layers.order_colours && c.layers.path)
        .map(|l| l.rank_by_geometry.as_slice());
    // during a playback the artwork is faded: the marks done are drawn over it
    let fade = if c.playback_t_s.is_some() { 0.3 } else { 1.0 };
    shapes.reserve(c.geometries.len() + c.uncovered.len());
    // not covered yet: a translucent magenta halo under the geometry, which keeps its colour
    // (no layer colour can be mistaken for it: no geometry is drawn with a halo otherwise)
    let halo = Stroke::new(
        colour::UNCOVERED_HALO_PX,
        colour::UNCOVERED.gamma_multiply(0.45),
    );
    for &k in c.uncovered.iter().filter(|k| !c.out_of_reach.contains(k)) {
        let Some(g) = c.geometries.get(k) else {
            continue;
        };
        let Some(pts) = screen_line(&g.points, g.closed, &s, clip) else {
            continue;
        };
        if pts.len() == 1 {
            let r = colour::UNCOVERED_HALO_PX / 2.0;
            shapes.push(Shape::circle_filled(pts[0], r, halo.color));
        } else {
            shapes.push(Shape::line(pts, halo));
        }
    }
    for (k, g) in c.geometries.iter().enumerate() {
        if g.points.is_empty() {
            continue;
        }
        let base = match c.colours.and_then(|cs| cs.get(k)) {
            Some(&layer) => layer,
            None if g.closed => colour::CLOSED,
            None => colour::OPEN,
        };
        // layer colours (several layers or a hatch) win over the colours by order
        let by_layer = c.colours.is_some();
        let col = match &rank {
            Some(r) if !by_layer && r.get(k).is_some_and(|&x| x >= 0.0) => {
                lerp(colour::ORDER[0], colour::ORDER[1], r[k])
            }
            _ => base,
        }
        .gamma_multiply(fade);
        let Some(pts) = screen_line(&g.points, g.closed, &s, clip) else {
            continue;
        };
        let (a, z) = (pts[0], pts[pts.len() - 1]);
        if !g.closed && (z - a).length() >= END_DOTS_MIN_PX {
            for end in [a, z] {
                shapes.push(Shape::circle_filled(end, 1.8, col));
            }
        }
        if pts.len() == 1 {
            shapes.push(Shape::circle_filled(pts[0], 1.5, col));
        } else {
            shapes.push(Shape::line(pts, Stroke::new(1.2, col)));
        }
    }
    for &k in c.out_of_reach {
        if let Some(pts) =
            (c.geometries.get(k)).and_then(|g| screen_line(&g.points, g.closed, &s, clip))
        {
            // no field can hold it: dashed purple, apart from the halo of "not covered yet"
            let stroke = Stroke::new(3.0, colour::OUT_OF_REACH);
            shapes.extend(Shape::dashed_line(&pts, stroke, 6.0, 4.0));
        }
    }
}

/// The stage path: the stage positions of the strokes in marking order.
fn base_path_shapes(shapes: &mut Vec<Shape>, l: &Lowered, view: &View, rect: Rect, fade: f32) {
    let mut pts: Vec<Pos2> = Vec::new();
    let mut last: Option<Pt> = None;
    for st in &l.toolpath.strokes {
        if last != Some(st.stage) {
            pts.push(view.to_screen(rect, st.stage));
            last = Some(st.stage);
        }
    }
    if pts.len() > 1 {
        shapes.extend(Shape::dashed_line(
            &pts,
            Stroke::new(2.0, colour::FIELD.gamma_multiply(0.6 * fade)),
            2.0,
            4.0,
        ));
    }
}

/// The stage route of an on-the-fly job: a solid line through the sampled stage positions.
fn route_shapes(shapes: &mut Vec<Shape>, l: &Lowered, view: &View, rect: Rect, col: Color32) {
    let pts: Vec<Pos2> = l
        .route_mm
        .iter()
        .map(|&p| view.to_screen(rect, p))
        .collect();
    if pts.len() > 1 {
        shapes.push(Shape::line(pts, Stroke::new(2.5, col.gamma_multiply(0.8))));
    }
}

/// Idle moves between consecutive strokes (dashed, with arrows).
fn idle_move_shapes(
    shapes: &mut Vec<Shape>,
    c: &Canvas<'_>,
    path: &PathLayer<'_>,
    l: &Lowered,
    view: &View,
    rect: Rect,
    clip: Rect,
) {
    let s = |q: Pt| view.to_screen(rect, q);
    let col = if !c.stale.is_empty() {
        path.colour.gamma_multiply(0.45)
    } else {
        path.colour
    };
    let col = if c.playback_t_s.is_some() {
        col.gamma_multiply(0.35)
    } else {
        col
    };
    let tp = &l.toolpath;
    let ends = |k: usize| {
        let p = l.points(k);
        p.first().copied().zip(p.last().copied())
    };
    for k in 1..tp.strokes.len() {
        let (Some((_, z)), Some((a, _))) = (ends(k - 1), ends(k)) else {
            continue;
        };
        let (p0, p1) = (s(z), s(a));
        if Rect::from_two_pos(p0, p1)
            .expand(CULL_MARGIN_PX)
            .intersects(clip)
        {
            idle_move(shapes, p0, p1, col, c.layers.arrows);
        }
    }
}

/// The start `S` and end `E` of a planned path.
fn paint_markers(painter: &Painter, l: &Lowered, view: &View, rect: Rect) {
    let ends = |k: usize| {
        let p = l.points(k);
        p.first().copied().zip(p.last().copied())
    };
    let n = l.toolpath.strokes.len();
    if let (Some((start, _)), Some((_, end))) = (ends(0), n.checked_sub(1).and_then(ends)) {
        let s = |q: Pt| view.to_screen(rect, q);
        start_end_markers(painter, s(start), s(end));
    }
}

fn idle_move(shapes: &mut Vec<Shape>, p0: Pos2, p1: Pos2, col: Color32, arrows: bool) {
    let len = (p1 - p0).length();
    if len > 0.5 {
        shapes.extend(Shape::dashed_line(
            &[p0, p1],
            Stroke::new(1.3, col),
            5.0,
            3.0,
        ));
    }
    if arrows && len > 28.0 {
        let dir = (p1 - p0) / len;
        let tip = p0 + (p1 - p0) * 0.55;
        let back = tip - dir * 7.0;
        let side = Vec2::new(-dir.y, dir.x) * 3.5;
        shapes.push(Shape::convex_polygon(
            vec![tip, back + side, back - side],
            col,
            Stroke::NONE,
        ));
    }
}

fn start_end_markers(painter: &Painter, ps: Pos2, pe: Pos2) {
    painter.circle(ps, 7.0, colour::START, Stroke::new(1.5, Color32::WHITE));
    painter.text(
        ps,
        Align2::CENTER_CENTER,
        "S",
        FontId::proportional(10.0),
        Color32::WHITE,
    );
    let r = Rect::from_center_size(pe, Vec2::splat(13.0));
    painter.rect(
        r,
        2.0,
        colour::END,
        Stroke::new(1.5, Color32::WHITE),
        StrokeKind::Outside,
    );
    painter.text(
        pe,
        Align2::CENTER_CENTER,
        "E",
        FontId::proportional(10.0),
        Color32::WHITE,
    );
}

/// The caption's lines (text and colour), top to bottom: the canvas's name, per plan its
/// figures, the stage route's legend (on the fly) and the machine's state (during a playback,
/// or `playback_room`: a line as long as one, for making room), a stale note, the uncovered
/// and out-of-reach geometries.
fn caption(c: &Canvas<'_>, playback_room: bool) -> Vec<(String, Color32)> {
    let mut lines = vec![(c.label.to_string(), Color32::from_gray(40))];
    for (k, p) in c.paths.iter().enumerate() {
        lines.push((plan_caption(p), p.colour));
        if let Ok(l) = p.lowered {
            if l.on_the_fly() && c.layers.base_path {
                let col = if k == 0 {
                    motion_plots::ROUTE
                } else {
                    p.colour
                };
                lines.push((
                    "solid line in this colour: the stage's route while the scanner marks".into(),
                    col,
                ));
            }
        }
        match (p.lowered, c.playback_t_s) {
            (Err(why), _) => lines.push((why.to_string(), colour::ERROR)),
            (Ok(l), Some(t_s)) => lines.push((
                format!(
                    "{}: {}",
                    playback::time_text(t_s.min(l.duration_s()), l.duration_s()),
                    playback::state_text(l, t_s)
                ),
                Color32::from_gray(40),
            )),
            (Ok(l), None) if playback_room => lines.push((
                format!(
                    "{}: {}",
                    playback::time_text(l.duration_s(), l.duration_s()),
                    playback::state_text(l, 0.0)
                ),
                Color32::from_gray(40),
            )),
            (Ok(_), None) => {}
        }
    }
    if let Some(t) = mixed_toolpath(c).filter(|_| c.layers.fields) {
        lines.push((
            format!(
                "tinted green: {} marked step-and-scan (the stage at rest), the rest on the fly",
                super::words::count(t.still_fields.len(), "field", "fields")
            ),
            colour::STILL_FIELD,
        ));
    }
    if let Some(first) = c.stale.first() {
        let more = match c.stale.len() {
            1 => String::new(),
            n => format!(" (and {} more)", n - 1),
        };
        lines.push((
            format!("stale plan: {first} since it was made{more}"),
            colour::STALE,
        ));
    }
    let near = c
        .uncovered
        .iter()
        .filter(|k| !c.out_of_reach.contains(k))
        .count();
    if near > 0 {
        lines.push((
            format!(
                "{} not covered by a field (magenta halo)",
                super::words::count(near, "stroke", "strokes")
            ),
            colour::UNCOVERED,
        ));
    }
    if !c.out_of_reach.is_empty() {
        lines.push((
            format!(
                "{} no scan field can hold (dashed purple)",
                super::words::count(c.out_of_reach.len(), "stroke", "strokes")
            ),
            colour::OUT_OF_REACH,
        ));
    }
    lines
}

/// Font of the caption.
fn caption_font() -> FontId {
    FontId::proportional(13.0)
}

/// The caption's lines laid out for a canvas `width_px` wide: wrapped, never cut.
fn caption_galleys(
    painter: &Painter,
    c: &Canvas<'_>,
    width_px: f32,
    playback_room: bool,
) -> Vec<std::sync::Arc<egui::Galley>> {
    let wrap_px = (width_px - 2.0 * CAPTION_MARGIN_PX - 8.0).max(40.0);
    caption(c, playback_room)
        .into_iter()
        .map(|(text, col)| painter.layout(text, caption_font(), col, wrap_px))
        .collect()
}

/// Margin of the caption from the canvas's corner, px.
const CAPTION_MARGIN_PX: f32 = 6.0;

fn paint_caption(painter: &Painter, c: &Canvas<'_>, rect: Rect) {
    let mut y = rect.min.y + CAPTION_MARGIN_PX;
    for galley in caption_galleys(painter, c, rect.width(), false) {
        let r = Rect::from_min_size(
            Pos2::new(rect.min.x + CAPTION_MARGIN_PX, y),
            galley.size() + Vec2::new(8.0, 4.0),
        );
        painter.rect_filled(r, 3.0, Color32::from_white_alpha(225));
        painter.galley(r.min + Vec2::new(4.0, 2.0), galley, Color32::from_gray(40));
        y = r.max.y + 2.0;
    }
}

/// Height of the caption on a canvas `width_px` wide, with room for the machine's state of a
/// playback, px.
pub fn caption_px(painter: &Painter, c: &Canvas<'_>, width_px: f32) -> f32 {
    let lines = caption_galleys(painter, c, width_px, true);
    let line_px = |g: &std::sync::Arc<egui::Galley>| g.size().y + 6.0;
    // before the first solve: room for a plan's figures and its playback state, so that the
    // first plan's caption does not cover the content fitted now
    let plan_room = match (c.paths.is_empty(), lines.first()) {
        (true, Some(title)) => 2.0 * line_px(title),
        _ => 0.0,
    };
    CAPTION_MARGIN_PX + lines.iter().map(line_px).sum::<f32>() + plan_room
}

/// A plan's caption, led by the figure that decides: its job time.
fn plan_caption(p: &PathLayer<'_>) -> String {
    let m = &p.plan.metrics;
    let job = m
        .job_time_s
        .or(p.lowered.ok().map(Lowered::duration_s))
        .map_or("job time unknown".to_string(), |t| {
            format!("job time {t:.2} s")
        });
    // a plan named for what it is already says its motion (older plans' names do not)
    let motion = |words: &str| {
        if p.plan.name.contains(words) {
            String::new()
        } else {
            format!(" · {words}")
        }
    };
    match p.lowered {
        Ok(l) if l.on_the_fly() => format!(
            "{}: {job}{} · idle travel {:.0} mm · stage route {:.0} mm",
            p.plan.name,
            motion("on the fly"),
            m.idle_mm,
            // the metrics' figure (sampled every millisecond), the drawn route's length else
            m.motion
                .map_or_else(|| route_length_mm(&l.route_mm), |f| f.stage_route_mm)
        ),
        lowered => format!(
            "{}: {job}{} · idle travel {:.0} mm · stage travel {:.0} mm · {} scan fields",
            p.plan.name,
            if lowered.is_ok() {
                motion("step-and-scan")
            } else {
                String::new()
            },
            m.idle_mm,
            m.base_mm,
            m.fields
        ),
    }
}

/// Length of a polyline, mm.
fn route_length_mm(pts: &[Pt]) -> f64 {
    pts.windows(2).map(|w| w[0].dist(w[1])).sum()
}

fn paint_scale_bar(painter: &Painter, view: &View, rect: Rect) {
    // the largest 1-2-5 length that stays under 120 px
    let max_mm = 120.0 / view.scale.max(1e-6);
    let mut len = 1e-3_f32;
    for k in -3..5 {
        for m in [1.0, 2.0, 5.0] {
            let v = m * 10f32.powi(k);
            if v <= max_mm {
                len = v;
            }
        }
    }
    let px = len * view.scale;
    let y = rect.max.y - 12.0;
    let x0 = rect.min.x + 12.0;
    let stroke = Stroke::new(2.0, Color32::from_gray(60));
    painter.line_segment([Pos2::new(x0, y), Pos2::new(x0 + px, y)], stroke);
    for x in [x0, x0 + px] {
        painter.line_segment([Pos2::new(x, y - 4.0), Pos2::new(x, y + 1.0)], stroke);
    }
    painter.text(
        Pos2::new(x0 + px / 2.0, y - 4.0),
        Align2::CENTER_BOTTOM,
        format!("{len} mm"),
        FontId::proportional(11.0),
        Color32::from_gray(60),
    );
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::job::JobCtx;
    use crate::pipeline::order_document_lowered;
    use std::sync::atomic::AtomicBool;

    /// The demo's canvas with one plan drawn.
    fn demo_canvas<'a>(
        doc: &'a crate::document::Document,
        plan: &'a crate::document::Plan,
        lowered: &'a Lowered,
    ) -> Canvas<'a> {
        Canvas {
            label: "test",
            geometries: &doc.geometries,
            profile: std::borrow::Cow::Borrowed(&doc.profile),
            cylinder: None,
            fields: &doc.fields,
            seams: &[],
            tiling: None,
            cell_max_mm: [0.0; 2],
            visiting: None,
            colours: None,
            out_of_reach: &[1],
            paths: vec![PathLayer {
                plan,
                lowered: Ok(lowered),
                colour: colour::PATH_A,
            }],
            uncovered: &[0, 1],
            selected: doc.fields.first().map(|f| f.id),
            editable: true,
            add_tool: false,
            layers: Default::default(),
            stale: &[],
            playback_t_s: None,
            parts: &[],
            codes: &[],
            revision: 0,
        }
    }

    /// Every shape of the heavy layers (fields, halos, out-of-reach dashes, artwork, stage
    /// path, idle moves with arrows) has a raster form, and the raster of the demo's plan
    /// covers the canvas where the artwork is.
    #[test]
    fn heavy_layers_rasterise_whole() {
        let doc = super::super::session::tests::demo().doc().clone();
        let (plan, toolpath) = order_document_lowered(&doc, &JobCtx::default()).unwrap();
        let lowered = Lowered::new(toolpath);
        let canvas = demo_canvas(&doc, &plan, &lowered);
        let rect = Rect::from_min_size(Pos2::new(10.0, 20.0), Vec2::new(400.0, 300.0));
        let mut view = View::default();
        view.fit(rect, Pt::new(0.0, 0.0), Pt::new(300.0, 300.0));
        let shapes = heavy_shapes(&canvas, &view, rect, rect);
        assert!(shapes.len() > doc.geometries.len());
        assert!(super::super::raster::supported(&shapes));
        let mut pixmap = tiny_skia::Pixmap::new(400, 300).unwrap();
        super::super::raster::rasterise(
            &shapes,
            rect.min,
            1.0,
            &mut pixmap,
            &AtomicBool::new(false),
        )
        .unwrap();
        let painted = pixmap.pixels().iter().filter(|p| p.alpha() > 0).count();
        assert!(painted > 1000, "{painted} pixels painted");
        // the content key follows what is drawn, not the view
        let key = content_key(&canvas);
        let unselected = Canvas {
            selected: None,
            ..canvas
        };
        assert_ne!(content_key(&unselected), key);
    }

    /// A mixed job's caption says how many fields run step-and-scan, in their tint, and the
    /// playback says which motion the stroke marked runs in; a one-motion job says neither.
    /// (The words only: tests/motion.rs lowers a real mixed job.)
    #[test]
    fn a_mixed_job_names_its_step_and_scan_fields() {
        let doc = super::super::session::tests::demo().doc().clone();
        let (plan, toolpath) = order_document_lowered(&doc, &JobCtx::default()).unwrap();
        let first_field = toolpath.strokes[0].field;
        let other = toolpath.strokes.iter().position(|s| s.field != first_field);
        let mid_mark_s = |tp: &crate::motion::Toolpath, stroke: usize| {
            let seg = tp.segments.iter().find(|seg| {
                seg.kind == crate::motion::SegmentKind::Mark
                    && matches!(seg.scan, crate::motion::ScanMotion::Mark { stroke: k, .. } if k == stroke)
            });
            seg.map(|seg| seg.start_s + seg.duration_s / 2.0).unwrap()
        };
        let single = Lowered::new(toolpath.clone());
        let tinted = |c: &Canvas<'_>| {
            caption(c, false)
                .into_iter()
                .filter(|(text, colour)| {
                    text.starts_with("tinted green") && *colour == colour::STILL_FIELD
                })
                .map(|(text, _)| text)
                .collect::<Vec<_>>()
        };
        assert!(tinted(&demo_canvas(&doc, &plan, &single)).is_empty());
        let t0 = mid_mark_s(&single.toolpath, 0);
        assert!(!playback::state_text(&single, t0).contains("step-and-scan"));

        let mut mixed = toolpath;
        mixed.still_fields = vec![first_field];
        let mixed = Lowered::new(mixed);
        let canvas = demo_canvas(&doc, &plan, &mixed);
        assert_eq!(
            tinted(&canvas),
            vec!["tinted green: 1 field marked step-and-scan (the stage at rest), the rest on the fly"]
        );
        let text = playback::state_text(&mixed, mid_mark_s(&mixed.toolpath, 0));
        assert!(text.starts_with("marking stroke 1 of"), "{text}");
        assert!(
            text.contains("(step-and-scan field: the stage stops for it)"),
            "{text}"
        );
        if let Some(k) = other {
            let text = playback::state_text(&mixed, mid_mark_s(&mixed.toolpath, k));
            assert!(text.contains(" (on the fly);"), "{text}");
        }
        // the fields layer hidden: no words about its tint
        let mut hidden = demo_canvas(&doc, &plan, &mixed);
        hidden.layers.fields = false;
        assert!(tinted(&hidden).is_empty());
    }
}
