//! Motion: what the machine does and how long it takes.
//!
//! [`lower`] turns a plan into a [`Toolpath`], a sequence of timed [`Segment`]s (stage move,
//! settle, scanner jump, jump delay, laser-on delay, mark, laser-off delay) from which the stage
//! position, the scanner offset, the tool-centre point and the laser state are known at any
//! instant ([`Toolpath::state_at`]). Every output reads the toolpath: the job time and its
//! breakdown in the metrics, the G-code (both dialects), the SVG preview, the sampled trajectory
//! and the GUI's canvas and playback. The ordering's time cost ([`StageDynamics::move_time_s`])
//! is the same stage timing the lowering uses.
//!
//! Timing model (profile units):
//! * stage: per axis a rest-to-rest trapezoid (or triangle) at the axis' velocity and
//!   acceleration limits; both axes start together and the slower sets the move time (seed 002
//!   §6.3); each axis that moved then settles for its `settle_s`;
//! * scanner: jumps in a straight line at jump speed followed by the jump delay; marks at mark
//!   speed between the laser-on and laser-off delays.

mod axis;
mod blend;
pub mod cetsp;
mod clock;
pub mod controller;
mod lower;
mod otf;
mod route;
mod seed_routes;
pub mod taut;
mod toolpath;
mod track;

pub use axis::{AxisMove, StageDynamics, StageMove};
pub use blend::CornerBlends;
pub use clock::ticks_covering;
pub use lower::{lower, LowerError, REACH_TOLERANCE_MM};
pub use otf::{lower_on_the_fly, still_reach_mm, OtfError};
pub use route::{AxisRoute, SmoothedAxis, StageRoute};
pub use seed_routes::plan_stage_route;
pub use toolpath::{
    MachineState, PoseTrack, ScanMotion, Segment, SegmentKind, StageMotion, Stroke, Toolpath,
    TIME_EPS_S,
};

use crate::document::{Geometry, Layer, Motion, Plan};
use crate::job::JobCtx;

/// Why a plan cannot be turned into motion, in either mode.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MotionError {
    /// Step-and-scan.
    #[error(transparent)]
    Step(#[from] LowerError),
    /// On the fly.
    #[error("on the fly: {0}")]
    OnTheFly(#[from] OtfError),
}

/// Lowers a plan on the machine it was planned for (`plan.profile`) in the motion mode it was
/// planned for; with `clock_s`, on that controller clock (every mark starts and ends on a
/// tick: what a trajectory sampled at that period can show).
pub fn lower_motion(
    geometries: &[Geometry],
    plan: &Plan,
    clock_s: Option<f64>,
    ctx: &JobCtx,
) -> Result<Toolpath, MotionError> {
    let profile = &plan.profile;
    let mut path = match plan.motion {
        Motion::Step => {
            let path = lower(geometries, plan, profile)?;
            match clock_s {
                Some(period_s) => path.on_clock(period_s),
                None => path,
            }
        }
        Motion::OnTheFly => {
            let path = lower_on_the_fly(geometries, plan, profile, clock_s, ctx)?;
            let streamed = profile.controller.streamed(Motion::OnTheFly);
            match controller::LinuxcncClock::of(profile).filter(|_| !streamed) {
                // the controller's planner cannot keep the planned pace: the job at its pace
                // (a streamed plan runs at its own, sample by sample)
                Some(clock) => {
                    let (start, lines) = controller::otf_lines(&path, profile.gcode.path_tol_mm);
                    let controller_s = clock.otf_program_s(&start, &lines);
                    let planned_s = path.duration_s();
                    if planned_s > 0.0 {
                        path.stretched(controller_s / planned_s)
                    } else {
                        path
                    }
                }
                None => path,
            }
        }
    };
    label_layers(&mut path, geometries, &plan.layers);
    Ok(path)
}

/// Gives each stroke of `path` the index of its geometry's layer in `layers` (what the G-code
/// reads each pen's power from); no layers leave the strokes on the profile's pen. A toolpath
/// lowered before a plan had its layers becomes the plan's lowering this way when the layers do
/// not change its timing.
pub fn label_layers(path: &mut Toolpath, geometries: &[Geometry], layers: &[Layer]) {
    if layers.is_empty() {
        return;
    }
    for s in &mut path.strokes {
        let layer = geometries.get(s.geometry).map(|g| &g.layer);
        s.layer = layer.and_then(|name| layers.iter().position(|l| &l.name == name));
    }
}

#[cfg(test)]
mod tests;

/// The built-in `linuxcnc` profile with a scan head's delays (laser on 0.1 ms, off 0.2 ms,
/// jump 0.3 ms) and 5 ms of X settling: every pause a LinuxCNC program writes as a dwell.
#[cfg(test)]
pub(crate) fn linuxcnc_with_delays() -> crate::document::MachineProfile {
    let mut profile = crate::document::MachineProfile::builtin("linuxcnc").unwrap();
    profile.laser.on_delay_s = 1e-4;
    profile.laser.off_delay_s = 2e-4;
    profile.laser.jump_delay_s = 3e-4;
    profile.axis_x.settle_s = 5e-3;
    profile
}
