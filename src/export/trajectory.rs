//! The sampled stage + scanner trajectory (docs/DESIGN.md, *Trajectory*): what a controller streams.

use crate::document::ExtraAxisId;
use crate::motion::{PoseTrack, Toolpath};
use std::fmt::Write;
use thiserror::Error;

/// CSV header of a trajectory file.
pub const TRAJECTORY_HEADER: &str = "t_s,stage_x_mm,stage_y_mm,scan_x_mm,scan_y_mm,laser";

/// Shortest sampling period accepted, s: below a microsecond the file of a minute's job holds
/// 60 million rows.
pub const MIN_PERIOD_S: f64 = 1e-6;

/// Longest sampling period accepted, s: a controller clock slower than 100 ms cannot follow a
/// scanner.
pub const MAX_PERIOD_S: f64 = 0.1;

/// An impossible sampling period.
#[derive(Debug, Error, PartialEq)]
#[error("trajectory period {period_ms} ms must lie between {} and {} ms", MIN_PERIOD_S * 1e3, MAX_PERIOD_S * 1e3)]
pub struct PeriodError {
    /// The period asked for, ms.
    pub period_ms: f64,
}

/// Checks a sampling period given in ms; returns it in s.
pub fn trajectory_period_s(period_ms: f64) -> Result<f64, PeriodError> {
    let period_s = period_ms * 1e-3;
    if period_s.is_finite() && (MIN_PERIOD_S..=MAX_PERIOD_S).contains(&period_s) {
        Ok(period_s)
    } else {
        Err(PeriodError { period_ms })
    }
}

/// Samples `toolpath` every `period_s` from t = 0 to its end (the last sample at or after the
/// end): one CSV row per sample, tool-centre point = stage + scan, laser 0/1. The toolpath is
/// sampled, never changed: on a profile with a controller clock (and `period_s` that clock)
/// every mark starts and ends on a sample; a continuous plan's marks shorter than a period may
/// fall between samples (sample it finer to see them).
///
/// A machine with axes beyond X/Y (`axes`, the profile's [`crate::document::MachineProfile::extra_axes`])
/// has a column for each after `laser` (`z_mm`, `a_deg`, `b_deg`); a flat machine's header is
/// [`TRAJECTORY_HEADER`] exactly.
pub fn trajectory_csv(toolpath: &Toolpath, period_s: f64, axes: &[ExtraAxisId]) -> String {
    let end_s = toolpath.duration_s();
    let samples = crate::motion::ticks_covering(end_s, period_s) + 1;
    let mut out = String::with_capacity(samples * 64);
    push_header(&mut out, axes);
    let mm_decimals = position_decimals(period_s);
    let track = (!axes.is_empty()).then(|| toolpath.pose_track());
    for k in 0..samples {
        let t_s = k as f64 * period_s;
        let extra = extra_axes(track.as_ref(), t_s, axes);
        push_row(
            &mut out,
            t_s,
            &toolpath.state_at(t_s),
            &extra,
            7,
            mm_decimals,
        );
    }
    out
}

/// The header, with a column per axis beyond X/Y.
fn push_header(out: &mut String, axes: &[ExtraAxisId]) {
    out.push_str(TRAJECTORY_HEADER);
    for id in axes {
        let _ = write!(out, ",{}_{}", id.word().to_lowercase(), id.unit());
    }
    out.push('\n');
}

/// The positions of `axes` (beyond X/Y) at `t_s` on `track` (none without a track).
fn extra_axes(track: Option<&PoseTrack>, t_s: f64, axes: &[ExtraAxisId]) -> Vec<f64> {
    let Some(track) = track else {
        return Vec::new();
    };
    let pose = track.at(t_s).values();
    axes.iter().map(|id| pose[id.index()]).collect()
}

/// Decimals of the positions sampled every `period_s`: 6 (1 nm … 1 µm) at 1 ms, two more for
/// every tenfold shorter period, so that a checker's second differences (a rounding of `e` mm
/// reads as `2e/period²` mm/s²) stay a few mm/s² at most: at 0.1 ms with 6 decimals they read
/// 200 mm/s².
fn position_decimals(period_s: f64) -> usize {
    let tenfolds = (1e-3 / period_s).log10().ceil().max(0.0);
    6 + 2 * tenfolds.min(3.0) as usize
}

/// One CSV row in [`TRAJECTORY_HEADER`]'s columns, then the `extra` axes' positions: time with
/// `t_decimals`, positions (mm, deg) with `mm_decimals`.
fn push_row(
    out: &mut String,
    t_s: f64,
    m: &crate::motion::MachineState,
    extra: &[f64],
    t_decimals: usize,
    mm_decimals: usize,
) {
    let (t, p) = (t_decimals, mm_decimals);
    let _ = write!(
        out,
        "{t_s:.t$},{:.p$},{:.p$},{:.p$},{:.p$},{}",
        m.stage.x,
        m.stage.y,
        m.scan.x,
        m.scan.y,
        u8::from(m.laser)
    );
    for v in extra {
        let _ = write!(out, ",{v:.p$}");
    }
    out.push('\n');
}

/// The toolpath's exact states, one CSV row each (the trajectory's columns): the start, every
/// segment's end, every mark vertex, and on the fly the on-the-fly program's samples
/// ([`crate::motion::controller::otf_sample_states`]). Positions are the toolpath's own, so a
/// controller's canonical moves can be checked against them; they are not flipped as the
/// G-code's Y may be.
pub fn waypoints_csv(toolpath: &Toolpath, axes: &[ExtraAxisId]) -> String {
    let states = crate::motion::controller::waypoint_states(toolpath);
    let mut out = String::with_capacity(states.len() * 64 + 64);
    push_header(&mut out, axes);
    let track = (!axes.is_empty()).then(|| toolpath.pose_track());
    for (t_s, m) in states {
        // exact states: time to the nanosecond, positions to 0.1 µm
        let extra = extra_axes(track.as_ref(), t_s, axes);
        push_row(&mut out, t_s, &m, &extra, 9, 7);
    }
    out
}
