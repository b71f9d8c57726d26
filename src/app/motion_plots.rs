//! On-the-fly motion, sampled for drawing: the stage route as a polyline for the canvas, and
//! the plots of the scanner offset (against the field limits) and of the stage speed (against
//! the axis limit) over the job's time.

use crate::document::MachineProfile;
use crate::geom::Pt;
use crate::motion::Toolpath;
use egui::Color32;
use egui_plot::{HLine, Legend, Line, LineStyle, Plot, PlotPoints, VLine};

/// Sampling step of the stage route drawn on the canvas, s.
pub const ROUTE_STEP_S: f64 = 5e-3;
/// Sampling step of the motion plots, s (coarser on long jobs, see [`MAX_SAMPLES`]).
pub const PLOT_STEP_S: f64 = 2e-3;
/// The most samples kept for a curve (long jobs are sampled more coarsely).
pub const MAX_SAMPLES: usize = 20_000;
/// Time step of the finite difference that gives the stage speed at a sample, s.
const SPEED_DT_S: f64 = 1e-3;
/// Colour of the stage route and of the stage speed curve (the playback's stage colour).
pub const ROUTE: Color32 = Color32::from_rgb(14, 116, 144);
/// Scanner offset x curve.
const OFFSET_X: Color32 = Color32::from_rgb(234, 88, 12);
/// Scanner offset y curve.
const OFFSET_Y: Color32 = Color32::from_rgb(124, 58, 237);
/// Limits (field reach, axis speed).
const LIMIT: Color32 = Color32::from_rgb(200, 30, 30);
/// The playback time (legible on the plots' dark and light backgrounds).
const NOW: Color32 = Color32::from_rgb(234, 179, 8);

/// Sample times over `[0, duration_s]`: every `step_s`, or coarser so that there are at most
/// `max` of them; the last one is the job's end.
pub fn sample_times_s(duration_s: f64, step_s: f64, max: usize) -> Vec<f64> {
    if duration_s.is_nan() || duration_s <= 0.0 || max < 2 {
        return vec![0.0];
    }
    let step_s = step_s.max(duration_s / (max - 1) as f64);
    let n = (duration_s / step_s).ceil() as usize;
    (0..=n)
        .map(|k| (k as f64 * step_s).min(duration_s))
        .collect()
}

/// The stage's route over the job, sampled every [`ROUTE_STEP_S`] (empty without a route).
pub fn route_points_mm(tp: &Toolpath) -> Vec<Pt> {
    let Some(route) = &tp.route else {
        return Vec::new();
    };
    sample_times_s(tp.duration_s(), ROUTE_STEP_S, MAX_SAMPLES)
        .into_iter()
        .map(|t| route.position(t))
        .collect()
}

/// The motion of an on-the-fly job sampled for plotting.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MotionSamples {
    /// Sample times, s.
    pub t_s: Vec<f64>,
    /// Scanner offset x (tool-centre point − stage) at each sample, mm.
    pub scan_x_mm: Vec<f64>,
    /// Scanner offset y at each sample, mm.
    pub scan_y_mm: Vec<f64>,
    /// Stage speed (norm of the velocity, by a finite difference) at each sample, mm/s.
    pub stage_speed_mm_s: Vec<f64>,
}

impl MotionSamples {
    /// Samples a toolpath with a stage route every [`PLOT_STEP_S`] (at most [`MAX_SAMPLES`]);
    /// `None` for step-and-scan toolpaths.
    pub fn of(tp: &Toolpath) -> Option<Self> {
        let route = tp.route.as_ref()?;
        let mut out = Self::default();
        for t in sample_times_s(tp.duration_s(), PLOT_STEP_S, MAX_SAMPLES) {
            let scan = tp.state_at(t).scan;
            let (t0, t1) = (t - SPEED_DT_S / 2.0, t + SPEED_DT_S / 2.0);
            let speed = route.position(t1).dist(route.position(t0)) / SPEED_DT_S;
            out.t_s.push(t);
            out.scan_x_mm.push(scan.x);
            out.scan_y_mm.push(scan.y);
            out.stage_speed_mm_s.push(speed);
        }
        Some(out)
    }

    /// The largest |scanner offset| over both axes, mm.
    pub fn peak_offset_mm(&self) -> f64 {
        self.scan_x_mm
            .iter()
            .chain(&self.scan_y_mm)
            .fold(0.0, |m, v| m.max(v.abs()))
    }

    /// The largest stage speed, mm/s.
    pub fn peak_speed_mm_s(&self) -> f64 {
        self.stage_speed_mm_s.iter().fold(0.0, |m, &v| m.max(v))
    }

    fn curve(&self, values: &[f64]) -> PlotPoints<'static> {
        self.t_s.iter().zip(values).map(|(&t, &v)| [t, v]).collect()
    }
}

/// The scanner's reach per axis on the fly: half the field less the margin, mm.
pub fn reach_mm(profile: &MachineProfile) -> [f64; 2] {
    profile
        .field_mm
        .map(|f| (f / 2.0 - profile.otf_margin_mm).max(0.0))
}

/// Height of the motion plots with their titles, px, when there is room.
pub const PLOTS_HEIGHT_PX: f32 = 230.0;

/// The two motion plots side by side, `height_px` tall with their titles: scanner offset
/// against the field limits, stage speed against the axis limit; a vertical line at the
/// playback time `t_s` when given.
pub fn show(
    ui: &mut egui::Ui,
    s: &MotionSamples,
    profile: &MachineProfile,
    t_s: Option<f64>,
    height_px: f32,
) {
    let width = ((ui.available_width() - ui.spacing().item_spacing.x) / 2.0).max(120.0);
    let plot_px = (height_px - 2.0 * ui.text_style_height(&egui::TextStyle::Body)).max(60.0);
    ui.horizontal_top(|ui| {
        ui.vertical(|ui| {
            ui.set_width(width);
            offset_plot(ui, s, profile, t_s, plot_px);
        });
        ui.vertical(|ui| {
            ui.set_width(width);
            speed_plot(ui, s, profile, t_s, plot_px);
        });
    });
}

fn offset_plot(
    ui: &mut egui::Ui,
    s: &MotionSamples,
    profile: &MachineProfile,
    t_s: Option<f64>,
    height_px: f32,
) {
    let [rx, ry] = reach_mm(profile);
    ui.label(format!(
        "Scanner offset (tool - stage), mm: peak {:.1} of ±{:.1}",
        s.peak_offset_mm(),
        rx.min(ry)
    ))
    .on_hover_text(format!(
        "Where the laser point is inside the scan field while the stage moves. The scanner \
         can reach up to the red dashed lines: half the field less the profile's on-the-fly \
         margin ({:.1} mm); the planner keeps the offset inside them.",
        profile.otf_margin_mm
    ));
    Plot::new("otf-offset")
        .height(height_px)
        .legend(Legend::default())
        .x_axis_label("t, s")
        .y_axis_label("offset, mm")
        .allow_scroll(false)
        .show(ui, |pui| {
            pui.line(Line::new("x", s.curve(&s.scan_x_mm)).color(OFFSET_X));
            pui.line(Line::new("y", s.curve(&s.scan_y_mm)).color(OFFSET_Y));
            let limits: &[f64] = if rx == ry { &[rx] } else { &[rx, ry] };
            for &r in limits {
                for v in [r, -r] {
                    pui.hline(
                        HLine::new("field limit", v)
                            .color(LIMIT)
                            .style(LineStyle::dashed_loose()),
                    );
                }
            }
            if let Some(t) = t_s {
                pui.vline(VLine::new("playback t", t).color(NOW).width(2.0));
            }
        });
}

fn speed_plot(
    ui: &mut egui::Ui,
    s: &MotionSamples,
    profile: &MachineProfile,
    t_s: Option<f64>,
    height_px: f32,
) {
    let (vx, vy) = (
        profile.axis_x.max_velocity_mm_s,
        profile.axis_y.max_velocity_mm_s,
    );
    ui.label(format!(
        "Stage speed, mm/s: peak {:.0}, limit {:.0} an axis, {:.0} both",
        s.peak_speed_mm_s(),
        vx.max(vy),
        vx.hypot(vy)
    ))
    .on_hover_text(
        "How fast the stage travels along its route (both axes together). Each axis stays \
         within its own limit (dashed), so on a diagonal the combined speed may reach the dotted \
         line.",
    );
    Plot::new("otf-speed")
        .height(height_px)
        .legend(Legend::default())
        .x_axis_label("t, s")
        .y_axis_label("speed, mm/s")
        .allow_scroll(false)
        .include_y(0.0)
        .show(ui, |pui| {
            pui.line(Line::new("stage speed", s.curve(&s.stage_speed_mm_s)).color(ROUTE));
            pui.hline(
                HLine::new("one axis at its limit", vx.max(vy))
                    .color(LIMIT)
                    .style(LineStyle::dashed_loose()),
            );
            pui.hline(
                HLine::new("both axes at their limits", vx.hypot(vy))
                    .color(LIMIT)
                    .style(LineStyle::dotted_loose()),
            );
            if let Some(t) = t_s {
                pui.vline(VLine::new("playback t", t).color(NOW).width(2.0));
            }
        });
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;

    #[test]
    fn sample_times_cover_the_job_and_are_capped() {
        let t = sample_times_s(1.0, 2e-3, MAX_SAMPLES);
        assert_eq!(t.len(), 501);
        assert_eq!(*t.last().unwrap(), 1.0);
        let t = sample_times_s(1000.0, 2e-3, MAX_SAMPLES);
        assert!(t.len() <= MAX_SAMPLES + 1, "{}", t.len());
        assert_eq!(*t.last().unwrap(), 1000.0);
        assert_eq!(sample_times_s(0.0, 2e-3, MAX_SAMPLES), vec![0.0]);
    }

    #[test]
    fn no_samples_without_a_route() {
        assert!(MotionSamples::of(&Toolpath::default()).is_none());
        assert!(route_points_mm(&Toolpath::default()).is_empty());
    }
}
