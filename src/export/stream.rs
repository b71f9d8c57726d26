//! The stream of a streamed on-the-fly plan (docs/GCODE.md, *Streamed on the fly*): what
//! LinuxCNC's `streamer` feeds its joints, one line per period of the profile's
//! `[controller] stream_period_s`: `X Y U V laser end [power]`.
//!
//! The lines are the plan's own states on that clock (the plan is lowered on it: every mark
//! starts and ends on a sample), not a path planned again. `end` is 1 on the last line only:
//! the program waits for it (`M66`) before it takes the joints back, and the machine's HAL tells
//! an underrun (the FIFO empty before `end`) from the stream's end by it.
//!
//! Between two samples the joints move in a straight line, while a curved mark bends: the
//! largest distance between the streamed path and the planned one is measured here
//! ([`StreamFigures::max_deviation_mm`]) by sampling the plan at [`DEVIATION_SUBSAMPLES`]
//! points between consecutive laser-on samples. It is `v²·T²/(8·r)` for a mark of radius `r`
//! at speed `v` on a period `T` (a chord's sagitta): 0.08 mm for a 1.5 mm radius at 1,000 mm/s
//! on 1 ms, 0.0008 mm on 0.1 ms.

use crate::document::{MachineProfile, Plan};
use crate::motion::{ScanMotion, Toolpath};
use std::fmt::Write;
use thiserror::Error;

/// Points of the plan compared with the straight line between two consecutive samples.
pub const DEVIATION_SUBSAMPLES: usize = 8;

/// Headroom beyond the stroke and the field a sample may take, mm (the LinuxCNC machine's
/// limits carry the same, [`super::linuxcnc_config::LIMIT_MARGIN_MM`]).
const LIMIT_SLACK_MM: f64 = super::linuxcnc_config::LIMIT_MARGIN_MM;

/// Why a plan cannot be streamed.
#[derive(Debug, Error, PartialEq)]
pub enum StreamError {
    /// The plan is not a streamed on-the-fly plan.
    #[error("the plan is not streamed: its profile's controller streams on-the-fly plans only (LinuxCNC with [controller] stream_period_s), and this one is {motion}")]
    NotStreamed {
        /// The plan's motion in words.
        motion: String,
    },
    /// A sample beyond the machine's limits (the stream bypasses LinuxCNC's soft limits).
    #[error("sample {sample} (t = {t_s:.4} s): {axis} = {value_mm:.4} mm is beyond the machine's limits {min_mm:.3} .. {max_mm:.3} mm")]
    Beyond {
        /// The sample's number (from 0).
        sample: usize,
        /// Its time, s.
        t_s: f64,
        /// The axis word.
        axis: String,
        /// The value, mm.
        value_mm: f64,
        /// The lower limit, mm.
        min_mm: f64,
        /// The upper limit, mm.
        max_mm: f64,
    },
}

/// What a stream holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamFigures {
    /// Its period, s.
    pub period_s: f64,
    /// Its lines.
    pub samples: usize,
    /// The largest distance between the path streamed (straight between samples) and the
    /// planned path, where the laser is on, mm.
    pub max_deviation_mm: f64,
}

/// The stream of `plan` lowered to `toolpath` (see the module documentation), with its
/// figures; every sample is checked against the machine's stroke and field first.
pub fn stream_text(
    toolpath: &Toolpath,
    plan: &Plan,
) -> Result<(String, StreamFigures), StreamError> {
    let profile = &plan.profile;
    let period_s = match profile.controller.stream_period_s {
        Some(p) if profile.controller.streamed(plan.motion) && toolpath.route.is_some() => p,
        _ => {
            return Err(StreamError::NotStreamed {
                motion: plan.motion_words(),
            })
        }
    };
    let end_s = toolpath.duration_s();
    let samples = crate::motion::ticks_covering(end_s, period_s) + 1;
    let power = profile.gcode.power_output.is_some();
    let mut out = String::with_capacity(samples * 48);
    let mut max_deviation_mm: f64 = 0.0;
    let mut last: Option<crate::motion::MachineState> = None;
    for k in 0..samples {
        let t_s = k as f64 * period_s;
        let m = toolpath.state_at(t_s);
        check_limits(profile, k, t_s, &m)?;
        if let Some(prev) = last.filter(|p| p.laser && m.laser) {
            max_deviation_mm =
                max_deviation_mm.max(deviation_mm(toolpath, t_s - period_s, period_s, &prev, &m));
        }
        let end = u8::from(k + 1 == samples);
        let _ = write!(
            out,
            "{:.6} {:.6} {:.6} {:.6} {} {end}",
            m.stage.x,
            m.stage.y,
            m.scan.x,
            m.scan.y,
            u8::from(m.laser)
        );
        if power {
            let _ = write!(out, " {}", power_at(toolpath, plan, t_s, m.laser));
        }
        out.push('\n');
        last = Some(m);
    }
    let figures = StreamFigures {
        period_s,
        samples,
        max_deviation_mm,
    };
    Ok((out, figures))
}

/// The largest distance from the planned tool-centre path between `t0_s` and `t0_s + period_s`
/// to the straight move from sample `a` to sample `b` (sampled at [`DEVIATION_SUBSAMPLES`]
/// instants).
fn deviation_mm(
    toolpath: &Toolpath,
    t0_s: f64,
    period_s: f64,
    a: &crate::motion::MachineState,
    b: &crate::motion::MachineState,
) -> f64 {
    let (p, q) = (a.tcp(), b.tcp());
    (1..DEVIATION_SUBSAMPLES)
        .map(|i| {
            let f = i as f64 / DEVIATION_SUBSAMPLES as f64;
            let planned = toolpath.state_at(t0_s + f * period_s).tcp();
            // the path's distance from the joints' straight move (where along it the tool is
            // at an instant is the pace, not the path)
            crate::geom::point_segment_dist(planned, p, q)
        })
        .fold(0.0, f64::max)
}

/// The power of the pen marking at `t_s` (0 with the laser off), as the program's `M67` words.
fn power_at(toolpath: &Toolpath, plan: &Plan, t_s: f64, laser: bool) -> f64 {
    if !laser {
        return 0.0;
    }
    let seg = &toolpath.segments[toolpath.segment_at(t_s)];
    let layer = match seg.scan {
        ScanMotion::Mark { stroke, .. } => toolpath.strokes.get(stroke).and_then(|s| s.layer),
        _ => None,
    };
    let pen = layer.and_then(|l| plan.layers.get(l)).map(|l| &l.pen);
    pen.map_or(plan.profile.gcode.power, |p| p.power(&plan.profile))
        .unwrap_or(0.0)
}

/// `m` within the stroke and the field (the LinuxCNC machine's soft limits, which a stream
/// bypasses).
fn check_limits(
    profile: &MachineProfile,
    sample: usize,
    t_s: f64,
    m: &crate::motion::MachineState,
) -> Result<(), StreamError> {
    let [sx, sy] = profile.stroke_mm;
    let [hx, hy] = [profile.field_mm[0] / 2.0, profile.field_mm[1] / 2.0];
    let words = &profile.gcode.scanner_axes;
    let axes = [
        ("X".to_string(), m.stage.x, 0.0, sx),
        ("Y".to_string(), m.stage.y, 0.0, sy),
        (words[0].trim().to_uppercase(), m.scan.x, -hx, hx),
        (words[1].trim().to_uppercase(), m.scan.y, -hy, hy),
    ];
    for (axis, value_mm, lo, hi) in axes {
        let (min_mm, max_mm) = (lo - LIMIT_SLACK_MM, hi + LIMIT_SLACK_MM);
        if !(min_mm..=max_mm).contains(&value_mm) {
            return Err(StreamError::Beyond {
                sample,
                t_s,
                axis,
                value_mm,
                min_mm,
                max_mm,
            });
        }
    }
    Ok(())
}
