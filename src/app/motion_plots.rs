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
pub(super) const SPEED_DT_S: f64 = 1e-3;
/// Colour of the stage route and of the stage speed curve (the playback's stage colour).
pub const ROUTE: Color32 = Color32::from_rgb(14, 116, 144);
/// Scanner offset x curve.
const OFFSET_X: Color32 = Color32::from_rgb(234, 88, 12);
/// Scanner offset y curve.
const OFFSET_Y: Color32 = Color32::from_rgb(124, 58, 237);
/// Limits (field reach, axis speed).
pub(super) const LIMIT: Color32 = Color32::from_rgb(200, 30, 30);
/// The playback time (legible on the plots' dark and light backgrounds).
pub(super) const NOW: Color32 = Color32::from_rgb(234, 179, 8);

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
    /// The job's figures as the metrics give them (sampled every millisecond): the titles'
    /// peaks, so that a plot and the table say the same.
    pub figures: crate::document::MotionFigures,
}

impl MotionSamples {
    /// Samples a toolpath with a stage route every [`PLOT_STEP_S`] (at most [`MAX_SAMPLES`]);
    /// `None` for step-and-scan toolpaths.
    pub fn of(tp: &Toolpath) -> Option<Self> {
        let route = tp.route.as_ref()?;
        let mut out = Self {
            figures: tp.motion_figures(crate::order::metrics::MOTION_SAMPLE_PERIOD_S),
            ..Self::default()
        };
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
        self.figures.scan_peak_offset_mm
    }

    /// The largest stage speed, mm/s.
    pub fn peak_speed_mm_s(&self) -> f64 {
        self.figures.stage_peak_speed_mm_s
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
    ui.horizontal_top(|ui| {
        ui.vertical(|ui| {
            ui.set_width(width);
            offset_plot(ui, s, profile, t_s, height_px);
        });
        ui.vertical(|ui| {
            ui.set_width(width);
            speed_plot(ui, s, profile, t_s, height_px);
        });
    });
}

/// A plot's title, wrapped (never cut), with its explanation on hover; returns the height
/// left for the plot of a column `height_px` tall (its axis labels counted), at least 60 px.
pub(super) fn title(ui: &mut egui::Ui, text: String, hover: String, height_px: f32) -> f32 {
    let top = ui.cursor().min.y;
    ui.add(egui::Label::new(text).wrap()).on_hover_text(hover);
    let used = ui.cursor().min.y - top;
    (height_px - used - ui.text_style_height(&egui::TextStyle::Body)).max(60.0)
}

/// How far above the highest curve or limit a plot reaches, as a share of it: the legend
/// (top right; the curves only: the limit lines are said in the title) sits in that band,
/// not over the curves.
pub(super) const LEGEND_HEADROOM: f64 = 1.45;

fn offset_plot(
    ui: &mut egui::Ui,
    s: &MotionSamples,
    profile: &MachineProfile,
    t_s: Option<f64>,
    height_px: f32,
) {
    let [rx, ry] = reach_mm(profile);
    let height_px = title(
        ui,
        format!(
            "Scanner offset (tool - stage), mm: peak {:.1} of ±{:.1} (dashed)",
            s.peak_offset_mm(),
            rx.min(ry)
        ),
        format!(
            "Where the laser point is inside the scan field while the stage moves. The scanner \
             can reach up to the red dashed lines: half the field less the profile's on-the-fly \
             margin ({:.1} mm); the planner keeps the offset inside them.",
            profile.otf_margin_mm
        ),
        height_px,
    );
    Plot::new("otf-offset")
        .height(height_px)
        .include_y(rx.max(ry) * (2.0 * LEGEND_HEADROOM - 1.0))
        .include_y(-rx.max(ry))
        .legend(Legend::default())
        .custom_x_axes(vec![time_axis()])
        .x_grid_spacer(time_grid_spacer)
        .y_axis_label("offset, mm")
        .allow_scroll(false)
        .show(ui, |pui| {
            pui.line(Line::new("x", s.curve(&s.scan_x_mm)).color(OFFSET_X));
            pui.line(Line::new("y", s.curve(&s.scan_y_mm)).color(OFFSET_Y));
            let limits: &[f64] = if rx == ry { &[rx] } else { &[rx, ry] };
            for &r in limits {
                for v in [r, -r] {
                    pui.hline(
                        HLine::new("", v)
                            .color(LIMIT)
                            .style(LineStyle::dashed_loose()),
                    );
                }
            }
            if let Some(t) = t_s {
                pui.vline(VLine::new("", t).color(NOW).width(2.0));
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
    let height_px = title(
        ui,
        format!(
            "Stage speed, mm/s: peak {:.0}, limit {:.0} per axis (dashed), {:.0} both (dotted)",
            s.peak_speed_mm_s(),
            vx.max(vy),
            vx.hypot(vy)
        ),
        "How fast the stage travels along its route (both axes together). Each axis stays \
         within its own limit (dashed), so on a diagonal the combined speed may reach the dotted \
         line."
            .into(),
        height_px,
    );
    Plot::new("otf-speed")
        .height(height_px)
        .include_y(vx.hypot(vy).max(s.peak_speed_mm_s()) * LEGEND_HEADROOM)
        .legend(Legend::default())
        .custom_x_axes(vec![time_axis()])
        .x_grid_spacer(time_grid_spacer)
        .y_axis_label("speed, mm/s")
        .allow_scroll(false)
        .include_y(0.0)
        .show(ui, |pui| {
            pui.line(Line::new("stage speed", s.curve(&s.stage_speed_mm_s)).color(ROUTE));
            pui.hline(
                HLine::new("", vx.max(vy))
                    .color(LIMIT)
                    .style(LineStyle::dashed_loose()),
            );
            pui.hline(
                HLine::new("", vx.hypot(vy))
                    .color(LIMIT)
                    .style(LineStyle::dotted_loose()),
            );
            if let Some(t) = t_s {
                pui.vline(VLine::new("", t).color(NOW).width(2.0));
            }
        });
}

/// Labelled time ticks at least this far apart, px (short labels such as "7.5": the time axis
/// shows its labels from 40 px apart, fully from 50 px, instead of egui_plot's 60 to 80).
const TIME_LABEL_PX: f64 = 50.0;
/// Grid lines at least this far apart, px (the plot's default smallest grid spacing).
const GRID_MIN_PX: f64 = 8.0;

/// The time axis of the motion plots: "t, s", tick labels from [`TIME_LABEL_PX`] apart.
pub(super) fn time_axis() -> egui_plot::AxisHints<'static> {
    egui_plot::AxisHints::new_x()
        .label("t, s")
        .label_spacing(40.0..=TIME_LABEL_PX as f32)
        .formatter(|mark, _| time_tick(mark.value, mark.step_size))
}

/// A time tick's label with the decimals its step needs: 0.5 s steps read "0.5", not "0".
fn time_tick(value_s: f64, step_s: f64) -> String {
    let decimals = (-step_s.log10() - 1e-9).ceil().clamp(0.0, 6.0) as usize;
    format!("{value_s:.decimals$}")
}

/// The smallest 1-2-5 step (…, 0.1, 0.2, 0.5, 1, 2, 5, 10, …) of at least `v`.
fn nice_step(v: f64) -> f64 {
    let v = v.max(1e-9);
    let decade = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&s| s >= v * (1.0 - 1e-9))
        .unwrap_or(10.0 * decade)
}

/// Grid of the time axes: labelled 1-2-5 steps at least `TIME_LABEL_PX` apart, so that a
/// job of any length on a plot of any width has several labelled times (a power-of-ten grid
/// leaves only "0" on a narrow plot of a few seconds), with finer unlabelled lines between.
pub fn time_grid_spacer(input: egui_plot::GridInput) -> Vec<egui_plot::GridMark> {
    let per_px = input.base_step_size / GRID_MIN_PX;
    let labelled = nice_step(per_px * TIME_LABEL_PX);
    // 1 → 0.2, 2 → 0.5, 5 → 1: a fifth or a quarter, a divisor of the labelled step
    let mantissa = labelled / 10f64.powf(labelled.log10().floor());
    let fine = labelled
        / if (mantissa - 2.0).abs() < 1e-6 {
            4.0
        } else {
            5.0
        };
    let coarse = labelled * 10.0;
    let (lo, hi) = input.bounds;
    let mut marks = Vec::new();
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo || fine <= 0.0 {
        return marks;
    }
    // a bound on a tick (1.4 s of 0.05 s ticks) is one, rounding aside
    let first = (lo / fine - 1e-9).ceil() as i64;
    let last = (hi / fine + 1e-9).floor() as i64;
    if last - first > 10_000 {
        return marks;
    }
    for k in first..=last {
        let value = k as f64 * fine;
        let on = |step: f64| ((value / step).round() * step - value).abs() < fine * 1e-3;
        let step_size = if on(coarse) {
            coarse
        } else if on(labelled) {
            labelled
        } else {
            fine
        };
        marks.push(egui_plot::GridMark { value, step_size });
    }
    marks
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
    fn time_ticks_are_labelled_on_narrow_plots() {
        assert_eq!(nice_step(0.3), 0.5);
        assert_eq!(nice_step(1.0), 1.0);
        assert_eq!(nice_step(1.01), 2.0);
        assert_eq!(nice_step(7.0), 10.0);
        assert_eq!(time_tick(0.5, 0.5), "0.5");
        assert_eq!(time_tick(1.0, 0.5), "1.0");
        assert_eq!(time_tick(4.0, 2.0), "4");
        assert_eq!(time_tick(0.25, 0.05), "0.25");
        assert_eq!(time_tick(10.0, 10.0), "10");
        // a 7.8 s job on a 250 px plot: 1 s is 32 px, so the labelled step is 2 s
        // (egui_plot's own grid labelled only 0 there)
        let px_per_s = 250.0 / 7.8;
        let marks = time_grid_spacer(egui_plot::GridInput {
            bounds: (-0.2, 8.0),
            base_step_size: GRID_MIN_PX / px_per_s,
        });
        let labelled: Vec<f64> = marks
            .iter()
            .filter(|m| m.step_size * px_per_s >= TIME_LABEL_PX)
            .map(|m| m.value)
            .collect();
        assert_eq!(labelled, vec![0.0, 2.0, 4.0, 6.0, 8.0]);
        // a 1.4 s job on a 600 px plot: every 0.2 s
        let px_per_s = 600.0 / 1.4;
        let marks = time_grid_spacer(egui_plot::GridInput {
            bounds: (0.0, 1.4),
            base_step_size: GRID_MIN_PX / px_per_s,
        });
        let labelled = marks
            .iter()
            .filter(|m| m.step_size * px_per_s >= TIME_LABEL_PX)
            .count();
        assert_eq!(labelled, 8);
    }

    #[test]
    fn no_samples_without_a_route() {
        assert!(MotionSamples::of(&Toolpath::default()).is_none());
        assert!(route_points_mm(&Toolpath::default()).is_empty());
    }
}
