//! The speeds of a machine's axes over a step-and-scan job whose fields turn Z, A or B: each
//! axis as a share of its own limit, so that mm/s and deg/s share one plot and the axis that
//! sets a move's time (at 100 %) stands out.

use super::motion_plots::{
    sample_times_s, time_axis, time_grid_spacer, title, LEGEND_HEADROOM, LIMIT, MAX_SAMPLES, NOW,
    PLOT_STEP_S, SPEED_DT_S,
};
use crate::document::{ExtraAxisId, MachineProfile};
use crate::motion::{PoseTrack, Toolpath};
use egui::Color32;
use egui_plot::{HLine, Legend, Line, LineStyle, Plot, PlotPoints, VLine};

/// One curve per axis, in X, Y, Z, A, B order.
const COLOURS: [Color32; 5] = [
    Color32::from_rgb(234, 88, 12),
    Color32::from_rgb(124, 58, 237),
    Color32::from_rgb(14, 116, 144),
    Color32::from_rgb(22, 163, 74),
    Color32::from_rgb(219, 39, 119),
];

/// Each axis's speed over the job, sampled.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AxisSamples {
    /// Sample times, s.
    pub t_s: Vec<f64>,
    /// Per axis (X, Y, Z, A, B): |speed| at each sample, mm/s or deg/s.
    pub speed: [Vec<f64>; 5],
    /// Per axis: the highest sampled speed, mm/s or deg/s (the title's peaks).
    pub peak: [f64; 5],
}

impl AxisSamples {
    /// Samples a toolpath that turns or lifts an axis beyond X/Y, where Z, A and B stand on
    /// `track` (its [`Toolpath::pose_track`]), every [`PLOT_STEP_S`] (at most
    /// [`MAX_SAMPLES`]); `None` on the fly.
    pub fn of(tp: &Toolpath, track: &PoseTrack) -> Option<Self> {
        if tp.route.is_some() {
            return None;
        }
        let at = |t: f64| {
            let stage = tp.state_at(t).stage;
            let [z, a, b] = track.at(t).values();
            [stage.x, stage.y, z, a, b]
        };
        let mut out = Self::default();
        for t in sample_times_s(tp.duration_s(), PLOT_STEP_S, MAX_SAMPLES) {
            let (p0, p1) = (at(t - SPEED_DT_S / 2.0), at(t + SPEED_DT_S / 2.0));
            out.t_s.push(t);
            for k in 0..5 {
                let v = (p1[k] - p0[k]).abs() / SPEED_DT_S;
                out.speed[k].push(v);
                out.peak[k] = out.peak[k].max(v);
            }
        }
        Some(out)
    }
}

/// The axes of `profile` that the plot shows: (name, index into the samples, speed limit,
/// unit).
fn axes(profile: &MachineProfile) -> Vec<(&'static str, usize, f64, &'static str)> {
    let mut out = vec![("X", 0, profile.axis_x.max_velocity_mm_s, "mm/s")];
    if profile.has_y() {
        out.push(("Y", 1, profile.axis_y.max_velocity_mm_s, "mm/s"));
    }
    for id in ExtraAxisId::ALL {
        if let Some(a) = profile.extra_axis(id) {
            let unit = if id == ExtraAxisId::Z {
                "mm/s"
            } else {
                "deg/s"
            };
            out.push((id.word(), 2 + id.index(), a.max_velocity, unit));
        }
    }
    out
}

/// The plot, `height_px` tall with its title; a vertical line at the playback time `t_s`.
pub fn show(
    ui: &mut egui::Ui,
    s: &AxisSamples,
    profile: &MachineProfile,
    t_s: Option<f64>,
    height_px: f32,
) {
    let axes = axes(profile);
    let share = |k: usize, limit: f64| -> Vec<f64> {
        s.speed[k].iter().map(|v| 100.0 * v / limit).collect()
    };
    let peaks: Vec<String> = axes
        .iter()
        .map(|&(name, k, limit, _)| format!("{name} {:.0} %", 100.0 * s.peak[k] / limit))
        .collect();
    let limits: Vec<String> = axes
        .iter()
        .map(|&(name, _, limit, unit)| format!("{name} {limit:.1} {unit}"))
        .collect();
    let height_px = title(
        ui,
        format!(
            "Axis speeds, % of each axis's limit (dashed 100 %): peak {}",
            peaks.join(", ")
        ),
        format!(
            "How fast each axis moves between fields, as a share of its own speed limit ({}). \
             All axes of a move start and stop together; the one that reaches 100 % takes the \
             longest and sets the move's time.",
            limits.join(", ")
        ),
        height_px,
    );
    Plot::new("axis-speeds")
        .height(height_px)
        .include_y(100.0 * LEGEND_HEADROOM)
        .include_y(0.0)
        .legend(Legend::default())
        .custom_x_axes(vec![time_axis()])
        .x_grid_spacer(time_grid_spacer)
        .y_axis_label("speed, % of limit")
        .allow_scroll(false)
        .show(ui, |pui| {
            for &(name, k, limit, _) in &axes {
                let points: PlotPoints<'static> = s
                    .t_s
                    .iter()
                    .zip(share(k, limit))
                    .map(|(&t, v)| [t, v])
                    .collect();
                pui.line(Line::new(name, points).color(COLOURS[k]));
            }
            // 2 px: the grid line at 100 % under it must not fill its gaps
            pui.hline(
                HLine::new("", 100.0)
                    .color(LIMIT)
                    .width(2.0)
                    .style(LineStyle::dashed_loose()),
            );
            if let Some(t) = t_s {
                pui.vline(VLine::new("", t).color(NOW).width(2.0));
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::{Geometry, Motion, Plan, PlanInputs, Pose, ScanField, Source, Step};
    use crate::geom::Pt;

    #[test]
    fn a_turning_job_is_sampled_and_b_reaches_its_limit() {
        let profile = MachineProfile::builtin("five-axis").unwrap();
        let dot = |x: f64| Geometry::new(vec![Pt::new(x, 100.0)], false, Source::default());
        let field = |id: usize, x: f64, b: f64| ScanField {
            id,
            center: Pt::new(x, 100.0),
            size: [70.0, 70.0],
            locked: true,
            geometries: vec![id],
            pose: Pose {
                b_deg: b,
                ..Pose::default()
            },
        };
        let geometries = vec![dot(100.0), dot(110.0)];
        let order = (0..2)
            .map(|k| Step {
                geometry: k,
                field: k,
                start_vertex: 0,
                reversed: false,
            })
            .collect();
        let plan = Plan::new(
            &PlanInputs::of(&Default::default()),
            Motion::Step,
            vec![field(0, 100.0, 0.0), field(1, 110.0, 90.0)],
            order,
        );
        let tp = crate::motion::lower(&geometries, &plan, &profile).unwrap();
        let s = AxisSamples::of(&tp, &tp.pose_track()).unwrap();
        let b_peak = s.speed[4].iter().copied().fold(0.0, f64::max);
        let b_limit = profile.axis_b.as_ref().unwrap().0.max_velocity;
        assert!(
            (b_peak / b_limit - 1.0).abs() < 0.01,
            "{b_peak} of {b_limit}"
        );
        assert!(s.speed[0].iter().all(|v| *v < 218.0 * 1.01));
        // a flat job has no such plot
        let flat = MachineProfile::default();
        let mut plan = plan.clone();
        plan.fields
            .iter_mut()
            .for_each(|f| f.pose = Pose::default());
        let tp = crate::motion::lower(&geometries, &plan, &flat).unwrap();
        assert!(!tp.moves_extra_axes());
    }
}
