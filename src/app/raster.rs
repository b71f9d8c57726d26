//! The canvas's heavy layers as one image: the shapes of the fields, the artwork, the stage
//! paths, the idle moves and the seams are rasterised in the background for one view, and each
//! frame draws that image, moved and scaled to the view of the frame, until a raster of the
//! current view arrives.
//!
//! Why: a job of 10⁴–10⁵ strokes is 10⁵ line vertices a frame; egui tessellates them on every
//! frame and software OpenGL (llvmpipe, a remote desktop, a VM) spent 70–460 ms a frame on them
//! (issue 24, BENCHMARKS "A canvas that stays fluid"). With the raster, a frame is one textured
//! rectangle, whatever the job's size; the shapes are built only when the content or the view
//! changes, and rasterised off the UI thread.
//!
//! What is never shown: a raster of other content. While the content's raster is not there
//! (after an edit, a new plan), the canvas draws the shapes directly, as without the cache. A
//! raster of another *view* of the same content is shown moved and scaled (a little blurred
//! while zooming) until the sharp one arrives, a fraction of a second later.

use egui::{Color32, ColorImage, Context, Id, Painter, Pos2, Rect, Shape, TextureHandle, Vec2};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// How far beyond the canvas a raster reaches on each side, as a share of the canvas's size: a
/// pan of up to this much shows drawn content, not blank, before the next raster.
const MARGIN_SHARE: f32 = 0.25;

/// A prefix layer (the marks a playback has done) starts a new raster when this many strokes
/// were done since the one shown (drawn directly until then), or when the view changed.
const PREFIX_BATCH: usize = 256;

/// What a raster shows: the content (a fingerprint of everything the layer draws) and the view
/// it was drawn for.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Key {
    content: u64,
    /// Pixels per mm of the view.
    scale: f32,
    /// Screen offset of the machine origin from the canvas's corner, points.
    offset: Vec2,
    /// Size of the canvas, points.
    size: Vec2,
    /// Physical pixels per point.
    pixels_per_point: f32,
}

/// A raster being drawn in the background.
struct Job {
    key: Key,
    /// The image's rectangle relative to the canvas's corner, points (the view of `key`).
    local: Rect,
    /// Items of a prefix layer drawn (0 for a whole layer).
    count: usize,
    /// The raster, once drawn (none: cancelled, or no pixmap of that size).
    done: OnceLock<Option<Drawn>>,
    /// Set when the raster is no longer wanted.
    cancel: AtomicBool,
}

/// A finished raster: the image for the GPU, and for a prefix layer the pixmap the next
/// strokes are drawn onto.
struct Drawn {
    image: ColorImage,
    pixmap: Option<Arc<tiny_skia::Pixmap>>,
}

/// A raster on the GPU.
#[derive(Clone)]
struct Shown {
    key: Key,
    local: Rect,
    count: usize,
    texture: TextureHandle,
    pixmap: Option<Arc<tiny_skia::Pixmap>>,
}

impl Shown {
    /// Draws the raster where its rectangle lies in the view `(scale, offset)` of `rect`.
    fn paint(&self, painter: &Painter, view: (f32, Vec2), rect: Rect) {
        // the raster's rectangle in mm, then on screen in the current view
        let k = view.0 / self.key.scale.max(1e-9);
        let min = rect.min + view.1 + (self.local.min.to_vec2() - self.key.offset) * k;
        let on_screen = Rect::from_min_size(min, self.local.size() * k);
        painter.image(
            self.texture.id(),
            on_screen,
            Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
            Color32::WHITE,
        );
    }
}

/// The raster of one layer of a canvas (kept in egui's memory under the canvas's id).
#[derive(Clone, Default)]
struct Cache {
    shown: Option<Shown>,
    job: Option<Arc<Job>>,
}

impl Cache {
    /// The cache of layer `id` (taken out of egui's memory: [`Cache::store`] puts it back),
    /// with a finished raster taken: shown when it is of `content`, dropped otherwise. A job of
    /// other content is cancelled.
    fn load(ctx: &Context, id: Id, content: u64) -> Self {
        let mut cache: Cache = ctx.data_mut(|d| d.remove_temp(id)).unwrap_or_default();
        let Some(job) = cache.job.take() else {
            return cache;
        };
        if job.key.content != content {
            // the content changed while a raster of the old one is drawn: not wanted any more
            job.cancel.store(true, Ordering::Relaxed);
        }
        if job.done.get().is_none() {
            cache.job = Some(job);
            return cache;
        }
        let (key, local, count) = (job.key, job.local, job.count);
        // the image is moved out when the drawing thread has let go of the job (it does before
        // it asks for the frame), else copied
        let done = match Arc::try_unwrap(job) {
            Ok(job) => job.done.into_inner().flatten(),
            Err(job) => job.done.get().and_then(Option::as_ref).map(|d| Drawn {
                image: d.image.clone(),
                pixmap: d.pixmap.clone(),
            }),
        };
        if let (Some(done), true) = (done, key.content == content) {
            let options = egui::TextureOptions::LINEAR;
            let texture = match cache.shown.take() {
                Some(mut shown) => {
                    shown.texture.set(done.image, options);
                    shown.texture
                }
                None => ctx.load_texture("canvas raster", done.image, options),
            };
            cache.shown = Some(Shown {
                key,
                local,
                count,
                texture,
                pixmap: done.pixmap,
            });
        }
        cache
    }

    /// Puts the cache back into egui's memory under `id`.
    fn store(self, ctx: &Context, id: Id) {
        ctx.data_mut(|d| d.insert_temp(id, self));
    }

    /// The view of `rect` as a raster key of `content`.
    fn want(ctx: &Context, content: u64, view: (f32, Vec2), rect: Rect) -> Key {
        Key {
            content,
            scale: view.0,
            offset: view.1,
            size: rect.size(),
            pixels_per_point: ctx.pixels_per_point(),
        }
    }
}

/// Draws one layer of a canvas in `rect` from its raster when one of `content` is there, else
/// from `shapes` (the layer drawn for the current view, culled to the given screen rectangle);
/// starts a raster of the current view when the one shown is not of it.
pub(super) fn paint(
    ctx: &Context,
    painter: &Painter,
    id: Id,
    content: u64,
    view: (f32, Vec2),
    rect: Rect,
    shapes: &dyn Fn(Rect) -> Vec<Shape>,
) {
    let id = id.with("raster");
    let mut cache = Cache::load(ctx, id, content);
    let want = Cache::want(ctx, content, view, rect);
    let shown_key = cache.shown.as_ref().map(|s| s.key);
    let current = shown_key.is_some_and(|k| k.content == content);
    let mut direct = None;
    if cache.job.is_none() && shown_key != Some(want) {
        if let Some(local) = image_rect(rect.size(), want.pixels_per_point, ctx) {
            let drawn = shapes(local.translate(rect.min.to_vec2()));
            if !current {
                direct = Some(drawn.clone());
            }
            cache.job = start(ctx, want, local, rect.min, drawn, None, 0);
        }
    }
    match cache.shown.as_ref().filter(|_| current) {
        Some(shown) => shown.paint(painter, view, rect),
        None => painter.extend(direct.unwrap_or_else(|| shapes(rect))),
    }
    cache.store(ctx, id);
}

/// Draws a layer of `count` items that grows at its end (the marks of a playback, `content`
/// naming the sequence): the raster of a prefix, the items after it directly on top. A raster
/// of the current view is extended in the background with the items done since (only those
/// are drawn again), one of another view is drawn again whole.
#[allow(clippy::too_many_arguments)]
pub(super) fn paint_prefix(
    ctx: &Context,
    painter: &Painter,
    id: Id,
    content: u64,
    count: usize,
    view: (f32, Vec2),
    rect: Rect,
    shapes: &dyn Fn(std::ops::Range<usize>, Rect) -> Vec<Shape>,
) {
    let id = id.with("prefix raster");
    let mut cache = Cache::load(ctx, id, content);
    let want = Cache::want(ctx, content, view, rect);
    let shown = cache
        .shown
        .as_ref()
        .filter(|s| s.key.content == content && s.count <= count);
    let stale = shown.is_none_or(|s| s.key != want || count - s.count >= PREFIX_BATCH);
    if cache.job.is_none() && stale {
        if let Some(local) = image_rect(rect.size(), want.pixels_per_point, ctx) {
            // extend the raster of this view, else draw the prefix again
            let (base, from) = match shown {
                Some(s) if s.key == want => (s.pixmap.clone(), s.count),
                _ => (None, 0),
            };
            let drawn = shapes(from..count, local.translate(rect.min.to_vec2()));
            cache.job = start(ctx, want, local, rect.min, drawn, base, count);
        }
    }
    match shown {
        Some(s) => {
            s.paint(painter, view, rect);
            painter.extend(shapes(s.count..count, rect));
        }
        None => painter.extend(shapes(0..count, rect)),
    }
    cache.store(ctx, id);
}

/// The rectangle a raster of a canvas of `size` covers, relative to its corner, points: the
/// canvas with [`MARGIN_SHARE`] around it, less when that would pass the largest texture (none
/// when even the canvas would).
fn image_rect(size: Vec2, pixels_per_point: f32, ctx: &Context) -> Option<Rect> {
    let max_side = ctx.input(|i| i.max_texture_side) as f32;
    let fit = |len: f32| {
        let room = (max_side / pixels_per_point - len) / 2.0;
        (room >= 0.0).then(|| (len * MARGIN_SHARE).min(room).floor())
    };
    let margin = Vec2::new(fit(size.x)?, fit(size.y)?);
    (size.x >= 1.0 && size.y >= 1.0).then(|| Rect::from_min_size(Pos2::ZERO, size).expand2(margin))
}

/// Starts rasterising `shapes` (screen points; the canvas's corner at `corner`) into an image
/// of `local` in a thread of its own: onto a copy of `base` when given (a prefix layer
/// extended; its pixmap is kept for the next extension), else onto a clear one.
fn start(
    ctx: &Context,
    key: Key,
    local: Rect,
    corner: Pos2,
    shapes: Vec<Shape>,
    base: Option<Arc<tiny_skia::Pixmap>>,
    count: usize,
) -> Option<Arc<Job>> {
    let job = Arc::new(Job {
        key,
        local,
        count,
        done: OnceLock::new(),
        cancel: AtomicBool::new(false),
    });
    let (ctx, job_ref) = (ctx.clone(), Arc::clone(&job));
    let origin = corner + local.min.to_vec2();
    let keep = count > 0 || base.is_some();
    let spawned = std::thread::Builder::new()
        .name("canvas raster".into())
        .spawn(move || {
            let size = local.size() * key.pixels_per_point;
            let size_px = [size.x.round() as u32, size.y.round() as u32];
            let pixmap = match base {
                Some(b) if [b.width(), b.height()] == size_px => Some((*b).clone()),
                _ => tiny_skia::Pixmap::new(size_px[0], size_px[1]),
            };
            let drawn = pixmap.and_then(|mut pixmap| {
                rasterise(
                    &shapes,
                    origin,
                    key.pixels_per_point,
                    &mut pixmap,
                    &job_ref.cancel,
                )?;
                Some(Drawn {
                    image: ColorImage::from_rgba_premultiplied(
                        [size_px[0] as usize, size_px[1] as usize],
                        pixmap.data(),
                    ),
                    pixmap: keep.then(|| Arc::new(pixmap)),
                })
            });
            // a second set cannot happen: this thread is the only writer
            let _unused = job_ref.done.set(drawn);
            // let go of the job before the frame that takes it (so it can move the image out)
            drop(job_ref);
            ctx.request_repaint();
        });
    // no thread: the canvas keeps drawing its shapes directly
    spawned.ok().map(|_| job)
}

/// How to paint one batch of shapes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Style {
    Fill(Color32),
    /// Width (px), colour.
    Stroke(f32, Color32),
}

/// Shapes (screen points, `origin` at the image's corner) drawn onto `pixmap` (none when
/// cancelled: the pixmap then holds a part). Consecutive shapes of one style are one path: overlaps
/// within a batch are painted once (a translucent line crossing itself is not darker there).
/// Shapes without a raster form here (text, meshes, curves) are left out: the heavy layers have
/// none (a unit test of `paint` holds them to that).
pub(super) fn rasterise(
    shapes: &[Shape],
    origin: Pos2,
    pixels_per_point: f32,
    pixmap: &mut tiny_skia::Pixmap,
    cancel: &AtomicBool,
) -> Option<()> {
    let px = |p: Pos2| {
        let q = (p - origin) * pixels_per_point;
        (q.x, q.y)
    };
    let mut batch = Batch {
        style: None,
        path: tiny_skia::PathBuilder::new(),
        pixels_per_point,
    };
    let mut stack: Vec<std::slice::Iter<'_, Shape>> = vec![shapes.iter()];
    let mut count = 0_usize;
    while let Some(top) = stack.last_mut() {
        let Some(shape) = top.next() else {
            stack.pop();
            continue;
        };
        count += 1;
        if count % 4096 == 0 && cancel.load(Ordering::Relaxed) {
            return None;
        }
        match shape {
            Shape::Vec(v) => stack.push(v.iter()),
            Shape::LineSegment { points, stroke } => {
                batch.style(pixmap, Style::Stroke(stroke.width, stroke.color));
                batch.polyline(points.iter().map(|&p| px(p)), false);
            }
            Shape::Path(p) => {
                if p.fill != Color32::TRANSPARENT {
                    batch.style(pixmap, Style::Fill(p.fill));
                    batch.polyline(p.points.iter().map(|&q| px(q)), true);
                }
                if let egui::epaint::ColorMode::Solid(colour) = p.stroke.color {
                    if let Some(style) = stroke_style(p.stroke.width, colour) {
                        batch.style(pixmap, style);
                        batch.polyline(p.points.iter().map(|&q| px(q)), p.closed);
                    }
                }
            }
            Shape::Circle(c) => {
                let (x, y) = px(c.center);
                let r = c.radius * pixels_per_point;
                if c.fill != Color32::TRANSPARENT {
                    batch.style(pixmap, Style::Fill(c.fill));
                    batch.path.push_circle(x, y, r);
                }
                if let Some(style) = stroke_style(c.stroke.width, c.stroke.color) {
                    batch.style(pixmap, style);
                    batch.path.push_circle(x, y, r);
                }
            }
            Shape::Rect(r) => {
                // the heavy layers' rectangles are square-cornered (fields)
                let (x0, y0) = px(r.rect.min);
                let (x1, y1) = px(r.rect.max);
                let rect = tiny_skia::Rect::from_ltrb(x0, y0, x1, y1);
                if r.fill != Color32::TRANSPARENT {
                    batch.style(pixmap, Style::Fill(r.fill));
                    if let Some(rect) = rect {
                        batch.path.push_rect(rect);
                    }
                }
                let grow = match r.stroke_kind {
                    egui::StrokeKind::Inside => -r.stroke.width / 2.0,
                    egui::StrokeKind::Middle => 0.0,
                    egui::StrokeKind::Outside => r.stroke.width / 2.0,
                } * pixels_per_point;
                let outline =
                    tiny_skia::Rect::from_ltrb(x0 - grow, y0 - grow, x1 + grow, y1 + grow);
                if let (Some(style), Some(outline)) =
                    (stroke_style(r.stroke.width, r.stroke.color), outline)
                {
                    batch.style(pixmap, style);
                    batch.path.push_rect(outline);
                }
            }
            _ => {}
        }
    }
    batch.flush(pixmap);
    Some(())
}

/// The style of a stroke, none when it paints nothing.
fn stroke_style(width: f32, colour: Color32) -> Option<Style> {
    (width > 0.0 && colour != Color32::TRANSPARENT).then_some(Style::Stroke(width, colour))
}

/// True when every shape in `shapes` has a raster form in [`rasterise`].
#[cfg(test)]
pub(super) fn supported(shapes: &[Shape]) -> bool {
    shapes.iter().all(|s| match s {
        Shape::Vec(v) => supported(v),
        Shape::Noop
        | Shape::LineSegment { .. }
        | Shape::Path(_)
        | Shape::Circle(_)
        | Shape::Rect(_) => true,
        _ => false,
    })
}

/// Consecutive shapes of one style, gathered into one path.
struct Batch {
    style: Option<Style>,
    path: tiny_skia::PathBuilder,
    pixels_per_point: f32,
}

impl Batch {
    /// Paints what was gathered when `style` differs from the batch's.
    fn style(&mut self, pixmap: &mut tiny_skia::Pixmap, style: Style) {
        if self.style != Some(style) {
            self.flush(pixmap);
            self.style = Some(style);
        }
    }

    fn polyline(&mut self, mut pts: impl Iterator<Item = (f32, f32)>, closed: bool) {
        let Some((x, y)) = pts.next() else {
            return;
        };
        self.path.move_to(x, y);
        for (x, y) in pts {
            self.path.line_to(x, y);
        }
        if closed {
            self.path.close();
        }
    }

    fn flush(&mut self, pixmap: &mut tiny_skia::Pixmap) {
        let path = std::mem::take(&mut self.path).finish();
        let (Some(style), Some(path)) = (self.style, path) else {
            return;
        };
        let paint = |c: Color32| {
            let [r, g, b, a] = c.to_srgba_unmultiplied();
            let mut paint = tiny_skia::Paint::default();
            paint.set_color_rgba8(r, g, b, a);
            paint.anti_alias = true;
            paint
        };
        let id = tiny_skia::Transform::identity();
        match style {
            Style::Fill(c) => {
                pixmap.fill_path(&path, &paint(c), tiny_skia::FillRule::Winding, id, None);
            }
            Style::Stroke(width, c) => {
                let stroke = tiny_skia::Stroke {
                    width: width * self.pixels_per_point,
                    line_cap: tiny_skia::LineCap::Round,
                    line_join: tiny_skia::LineJoin::Round,
                    ..tiny_skia::Stroke::default()
                };
                pixmap.stroke_path(&path, &paint(c), &stroke, id, None);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::Stroke;

    fn pixel(img: &ColorImage, x: usize, y: usize) -> Color32 {
        img.pixels[y * img.size[0] + x]
    }

    #[test]
    fn shapes_land_where_the_view_puts_them() {
        let shapes = vec![
            Shape::line_segment(
                [Pos2::new(110.0, 120.0), Pos2::new(150.0, 120.0)],
                Stroke::new(2.0, Color32::RED),
            ),
            Shape::Vec(vec![Shape::circle_filled(
                Pos2::new(130.0, 140.0),
                3.0,
                Color32::BLUE,
            )]),
        ];
        assert!(supported(&shapes));
        let cancel = AtomicBool::new(false);
        // the image's corner at (100, 100), two pixels a point
        let mut pixmap = tiny_skia::Pixmap::new(120, 100).unwrap();
        rasterise(&shapes, Pos2::new(100.0, 100.0), 2.0, &mut pixmap, &cancel).unwrap();
        let img = ColorImage::from_rgba_premultiplied([120, 100], pixmap.data());
        // the line: y 120 → 40 px, x 110…150 → 20…100 px
        assert_eq!(pixel(&img, 60, 40), Color32::RED);
        assert_eq!(pixel(&img, 60, 46), Color32::TRANSPARENT);
        assert_eq!(pixel(&img, 10, 40), Color32::TRANSPARENT);
        // the circle (in a nested Vec): centre (30, 40) points → (60, 80) px
        assert_eq!(pixel(&img, 60, 80), Color32::BLUE);
        assert_eq!(pixel(&img, 60, 90), Color32::TRANSPARENT);
    }

    #[test]
    fn a_cancelled_raster_is_none_and_text_is_not_supported() {
        let many: Vec<Shape> = (0..10_000)
            .map(|k| Shape::circle_filled(Pos2::new(k as f32 % 50.0, 5.0), 1.0, Color32::RED))
            .collect();
        let cancel = AtomicBool::new(true);
        let mut pixmap = tiny_skia::Pixmap::new(50, 10).unwrap();
        assert!(rasterise(&many, Pos2::ZERO, 1.0, &mut pixmap, &cancel).is_none());
        assert!(!supported(&[Shape::Mesh(Default::default())]));
    }
}
