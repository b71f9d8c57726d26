//! The sampled stage + scanner trajectory (docs/DESIGN.md, *Trajectory*): what a controller streams.

use crate::motion::Toolpath;
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
pub fn trajectory_csv(toolpath: &Toolpath, period_s: f64) -> String {
    let end_s = toolpath.duration_s();
    let samples = crate::motion::ticks_covering(end_s, period_s) + 1;
    let mut out = String::with_capacity(samples * 64);
    out.push_str(TRAJECTORY_HEADER);
    out.push('\n');
    let mm_decimals = position_decimals(period_s);
    for k in 0..samples {
        let t_s = k as f64 * period_s;
        push_row(&mut out, t_s, &toolpath.state_at(t_s), 7, mm_decimals);
    }
    out
}

/// Decimals of the positions sampled every `period_s`: 6 (1 nm … 1 µm) at 1 ms, two more for
/// every tenfold shorter period, so that a checker's second differences (a rounding of `e` mm
/// reads as `2e/period²` mm/s²) stay a few mm/s² at most: at 0.1 ms with 6 decimals they read
/// 200 mm/s².
fn position_decimals(period_s: f64) -> usize {
    let tenfolds = (1e-3 / period_s).log10().ceil().max(0.0);
    6 + 2 * tenfolds.min(3.0) as usize
}

/// One CSV row in [`TRAJECTORY_HEADER`]'s columns: time with `t_decimals`, positions (mm) with
/// `mm_decimals`.
fn push_row(
    out: &mut String,
    t_s: f64,
    m: &crate::motion::MachineState,
    t_decimals: usize,
    mm_decimals: usize,
) {
    let (t, p) = (t_decimals, mm_decimals);
    let _ = writeln!(
        out,
        "{t_s:.t$},{:.p$},{:.p$},{:.p$},{:.p$},{}",
        m.stage.x,
        m.stage.y,
        m.scan.x,
        m.scan.y,
        u8::from(m.laser)
    );
}

/// The toolpath's exact states, one CSV row each (the trajectory's columns): the start, every
/// segment's end, every mark vertex, and on the fly the on-the-fly program's samples
/// ([`crate::motion::controller::otf_sample_states`]). Positions are the toolpath's own, so a
/// controller's canonical moves can be checked against them; they are not flipped as the
/// G-code's Y may be.
pub fn waypoints_csv(toolpath: &Toolpath) -> String {
    let states = crate::motion::controller::waypoint_states(toolpath);
    let mut out = String::with_capacity(states.len() * 64 + 64);
    out.push_str(TRAJECTORY_HEADER);
    out.push('\n');
    for (t_s, m) in states {
        // exact states: time to the nanosecond, positions to 0.1 µm
        push_row(&mut out, t_s, &m, 9, 7);
    }
    out
}
