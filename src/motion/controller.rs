//! The controller's time law: how long a controller takes for the moves galvoplan writes.
//!
//! For [`ControllerKind::Ideal`] the lowering keeps seed 002's scan-head model (constant mark
//! speed through corners, jumps at jump speed). For [`ControllerKind::Linuxcnc`] every move of
//! a step-and-scan program is timed as LinuxCNC 2.9's trajectory planner (`src/emc/tp/tp.c`,
//! `tc.c`, task's `emccanon.cc`) runs it in exact-path mode (`G61`, which the LinuxCNC dialect
//! writes):
//!
//! * **Limits of one straight move** (`emccanon.cc`, `getStraightVelocity` /
//!   `getStraightAcceleration`): its length `L` is the X/Y(/Z) length when the stage moves,
//!   else the scanner's (U/V) length, else (a machine with rotaries) the A/B length in degrees;
//!   with `dᵢ` each axis's travel (Z, A and B too), the move's speed limit is
//!   `V = L / maxᵢ(|dᵢ| / vmaxᵢ)` and its acceleration `A = L / maxᵢ(|dᵢ| / amaxᵢ)` (per-axis
//!   box scaling). A feed move asks for `min(F, V)`, a rapid for `V`; both are clipped to
//!   `[TRAJ] MAX_LINEAR_VELOCITY` (not a pure rotary move) and to `L / T`
//!   (`tcClampVelocityByLength`), `T` the servo period.
//! * **Exact stop**: in `G61` every move starts and ends at rest, with the full `A` (the planner
//!   halves it only for parabolic blends). The planner advances a move once per servo period by
//!   `tpCalculateTrapezoidalAccel` / `tcUpdateDistFromAccel` (below, [`exact_stop_cycles`]);
//!   the move is done in the period where its remaining distance reaches zero, and the next move
//!   starts in the period after. So a move takes a whole number of periods, at least two for
//!   any move that needs to accelerate and brake.
//! * **Task-level commands**: between two moves the step-and-scan program may have a dwell
//!   (`G4 P`: settling, jump and laser delays next to each other, written as one) and dots
//!   (`M64`, `G4 P<dot dwell>`, `M65`). Task runs them, not the planner (`emctaskmain.cc`): the
//!   first waits for motion to come to rest, then each is issued in turn; a dwell ends at the
//!   first task cycle that finds its time passed (`WAITING_FOR_DELAY`), and an output (`M64`,
//!   `M65`) waits for motion to take the command (`usrmotWriteEmcmotCommand` polls for its echo,
//!   one servo period). The run of commands between two moves takes
//!   [`LinuxcncClock::dwell_s`] and [`LinuxcncClock::dot_s`] summed in order, `first` for the
//!   first command after a move:
//!   - after a move: [`TASK_RESUME_S`] (task finds motion done, and the next move restarts
//!     after the run);
//!   - a dwell first after a move: P rounded up to whole task cycles as they run
//!     ([`TASK_CYCLE_RUN_S`]: `RCS_TIMER::wait` sleeps one `[TASK] CYCLE_TIME` from the end of
//!     its last sleep, and each sleep overruns by the kernel's timer slack), at least one;
//!   - a dwell after an output: P plus [`DWELL_TAIL_S`];
//!   - an output: one servo period ([`LinuxcncClock::output_s`]); `M62`/`M63`, which the
//!     program writes before a move that switches the laser, only after a dwell or a dot
//!     (between moves motion takes it while it runs).
//!
//!   Measured on the simulated machine of the `linuxcnc` profile (1 ms servo period, 1 ms task
//!   cycle): programs of 300 or 500 short scanner jumps (`G0 U1`, `G0 U0`), each followed by
//!   the same commands, against the jumps alone, per jump (ms; law in brackets): `G4 P` of
//!   0.1, 0.5, 0.9, 1.0 ms: 3.20–3.27 [3.23]; of 1.1, 1.5, 2.0 ms: 4.27–4.35 [4.31]; 2.5, 3.0:
//!   5.39, 5.37 [5.38]; 4.0, 4.1: 6.44, 6.40 [6.46]; 5: 7.45 [7.53]; 6: 8.57 [8.61]; 8: 10.75
//!   [10.76]; 10, 10.5: 12.92, 12.91 [12.91]; 20: 22.63 [22.58]. `M65`: 3.17 [3.16]; `M64 M65`:
//!   4.17–4.21 [4.16]; `M64 M65 M64 M65`: 6.15 [6.16]. A dot (`M64`, `G4 P`, `M65`) of 0.1,
//!   0.5, 1, 2, 5 ms: 4.37–4.39, 4.83, 5.37, 6.35, 9.32 [4.39, 4.79, 5.29, 6.29, 9.29]; `M65`
//!   then `G4 P` 0.5, 2, 10 ms: 3.73, 5.29, 13.29 [3.79, 5.29, 13.29]; a laser-delayed dot
//!   (`G4 P0.0001`, `M64`, `G4 P0.0005`, `M65`, `G4 P0.0001`): 5.99–6.09 [6.09]. Root mean
//!   square error 0.04 ms. `M63` between moves: −0.06 [0]; `G4 P0.0001` then `M62` or `M63`:
//!   4.09, 4.18 [4.23]; `G4 P0.002`, `M63`: 5.24 [5.31]; a dot then `M63`: 5.73 [5.79]. With a
//!   0.5 ms servo period the law is off by up to 0.4 ms (`M65` 2.26 [2.66], a 0.1 ms dot 3.36
//!   [3.37], a 2 ms dwell 4.23 [4.31]): its constants hold for the 1 ms periods galvoplan's
//!   configuration writes. Whole jobs (scripts/check-linuxcnc.sh): the five-axis stand-in (a
//!   dot between 0.1 ms laser delays at each of 300 placements) and demo.svg with 0.1/0.1/0.2 ms
//!   laser and jump delays and 5 ms settling run within 0.2 % of the law.
//!
//! The law was checked against the simulated machine (docs/BENCHMARKS.md, *LinuxCNC*): a port of
//! the planner's run-time code to Python reproduced the servo-period counts of exact-stop moves
//! exactly. Tolerances: positions in the period loop are compared to [`POSITION_EPS_MM`], as the
//! planner does (`TP_POS_EPSILON`).

use super::toolpath::{MachineState, ScanMotion, Toolpath, TIME_EPS_S};
use crate::document::{ControllerKind, MachineProfile};

/// Remaining distance below which the planner takes a move as done, mm (`TP_POS_EPSILON`).
pub const POSITION_EPS_MM: f64 = 1e-12;

/// What the first task-level command after a move adds, s: task finds motion at rest (at its
/// next cycle), and motion takes the next move after the run (its command's echo, the
/// planner's first period). Measured (see the module documentation).
pub const TASK_RESUME_S: f64 = 2.16e-3;

/// `[TASK] CYCLE_TIME` of the configuration `galvoplan linuxcnc-config` writes, s.
pub const TASK_CYCLE_S: f64 = 1e-3;

/// A task cycle as it runs on the simulated machine, s: [`TASK_CYCLE_S`] from the end of the
/// last sleep, plus the sleep's overrun (Linux's 50 µs timer slack and the wake-up, 75 µs).
/// Measured: dwells of 1 to 20 ms first after a move took whole numbers of these.
pub const TASK_CYCLE_RUN_S: f64 = TASK_CYCLE_S + 7.5e-5;

/// What a dwell after an output (`M64`/`M65`) adds to its own time, s (measured).
pub const DWELL_TAIL_S: f64 = 1.3e-4;

/// Most servo periods one move is simulated for before the law falls back to the
/// continuous-time trapezoid (a move longer than this many periods is timed to within one
/// period by the trapezoid alone).
const MAX_SIMULATED_CYCLES: u64 = 200_000;

/// The time law of a LinuxCNC machine (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct LinuxcncClock {
    /// Servo period, s.
    pub period_s: f64,
    /// Per axis (X, Y, scanner x, scanner y): speed limit, mm/s.
    pub vmax_mm_s: [f64; 4],
    /// Per axis: acceleration limit, mm/s².
    pub amax_mm_s2: [f64; 4],
    /// `[TRAJ] MAX_LINEAR_VELOCITY`, mm/s.
    pub v_limit_mm_s: f64,
    /// Z, A, B: speed limits (mm/s, deg/s); infinite where the machine has no such axis (it
    /// never moves).
    pub extra_vmax: [f64; 3],
    /// Z, A, B: acceleration limits (mm/s², deg/s²).
    pub extra_amax: [f64; 3],
}

impl LinuxcncClock {
    /// The clock of `profile`'s controller; none for a scan-head controller.
    pub fn of(profile: &MachineProfile) -> Option<Self> {
        if profile.controller.kind != ControllerKind::Linuxcnc {
            return None;
        }
        let scanner_v = profile
            .scanner
            .jump_speed_mm_s
            .max(profile.scanner.mark_speed_mm_s);
        let scanner_a = profile.controller.scanner_accel_mm_s2;
        let vmax_mm_s = [
            profile.axis_x.max_velocity_mm_s,
            profile.axis_y.max_velocity_mm_s,
            scanner_v,
            scanner_v,
        ];
        let extra = crate::document::ExtraAxisId::ALL.map(|id| profile.extra_axis(id));
        Some(Self {
            extra_vmax: extra.map(|a| a.map_or(f64::INFINITY, |a| a.max_velocity)),
            extra_amax: extra.map(|a| a.map_or(f64::INFINITY, |a| a.max_accel)),
            period_s: profile.controller.servo_period_s,
            vmax_mm_s,
            amax_mm_s2: [
                profile.axis_x.max_accel_mm_s2,
                profile.axis_y.max_accel_mm_s2,
                scanner_a,
                scanner_a,
            ],
            // linuxcnc_config writes the fastest linear axis's speed (Z's too: a Z faster than
            // the scanner is not clipped either)
            v_limit_mm_s: vmax_mm_s
                .iter()
                .copied()
                .chain(profile.axis_z.as_ref().map(|z| z.0.max_velocity))
                .fold(0.0, f64::max),
        })
    }

    /// Time of one straight exact-stop move by `d_mm` = (X, Y, scanner x, scanner y) travel:
    /// a feed move at `feed_mm_s`, or a rapid (`None`). Zero for no travel (LinuxCNC drops
    /// zero-length moves).
    pub fn move_s(&self, d_mm: [f64; 4], feed_mm_s: Option<f64>) -> f64 {
        self.move_axes_s(d_mm, [0.0; 3], feed_mm_s)
    }

    /// [`LinuxcncClock::move_s`] with Z, A and B moving too (`turn`: mm, deg, deg).
    pub fn move_axes_s(&self, d_mm: [f64; 4], turn: [f64; 3], feed_mm_s: Option<f64>) -> f64 {
        self.planned_axes(d_mm, turn, feed_mm_s, false)
            .map_or(0.0, |m| {
                let speed = m.requested_mm_s.min(m.max_mm_s);
                exact_stop_cycles(m.length_mm, speed, m.accel_mm_s2, self.period_s) as f64
                    * self.period_s
            })
    }

    /// Time of a polyline marked by the scanner at `feed_mm_s` through `points` (the stage at
    /// rest), one exact-stop move per edge.
    pub fn polyline_s(&self, points: &[crate::geom::Pt], feed_mm_s: f64) -> f64 {
        points
            .windows(2)
            .map(|w| {
                let d = w[1].minus(w[0]);
                self.move_s([0.0, 0.0, d.x, d.y], Some(feed_mm_s))
            })
            .sum()
    }

    /// Time of a dwell of `p_s` (`G4 P`, pauses next to each other written as one), with what
    /// task adds to it; `first`: the first command task runs after a move (else it follows a
    /// dot's output). None for no dwell.
    pub fn dwell_s(&self, p_s: f64, first: bool) -> f64 {
        if p_s <= 0.0 {
            0.0
        } else if first {
            // the dwell starts at the task cycle that found motion done, and ends at the first
            // cycle after its time (a whole-cycle dwell is not taken one cycle late)
            let cycles = (p_s / TASK_CYCLE_RUN_S - 1e-9).ceil().max(1.0);
            TASK_RESUME_S + cycles * TASK_CYCLE_RUN_S
        } else {
            p_s + DWELL_TAIL_S
        }
    }

    /// Time of a dot fired for `dwell_s` (`M64`, `G4 P`, `M65`); `first`: the first command
    /// task runs after a move (else it follows a dwell).
    pub fn dot_s(&self, dwell_s: f64, first: bool) -> f64 {
        let resume = if first { TASK_RESUME_S } else { 0.0 };
        resume + 2.0 * self.output_s() + dwell_s.max(0.0) + DWELL_TAIL_S
    }

    /// Time of a digital output issued after task-level commands, s: task waits for motion to
    /// take it (one servo period). `M64`/`M65` always; `M62`/`M63` (switching the laser with
    /// the next move) only after a dwell or a dot: between moves it is taken while motion runs.
    pub fn output_s(&self) -> f64 {
        self.period_s
    }
}

/// Servo periods LinuxCNC's planner takes for one exact-stop move of `length_mm` at speed
/// `speed_mm_s` and acceleration `accel_mm_s2`, period `period_s`: the planner's own period
/// loop (`tpCalculateTrapezoidalAccel`, `tcUpdateDistFromAccel`, `tpCheckEndCondition`).
///
/// Each period, with `dx` the distance left and `v` the speed: the speed that still stops in
/// `dx` is `vd = −h + √(a(2dx − vT) + h²)`, `h = aT/2` (when the root's argument exceeds `h²`,
/// else `−h`); the new speed moves toward `min(vd, speed)` by at most `aT`; the position
/// advances by the mean speed times `T` (a speed that would go negative ends the move when
/// `dx < vT`). The move ends in the period where `dx` reaches zero.
pub fn exact_stop_cycles(length_mm: f64, speed_mm_s: f64, accel_mm_s2: f64, period_s: f64) -> u64 {
    if length_mm <= POSITION_EPS_MM {
        return 0;
    }
    let (a, t) = (accel_mm_s2, period_s);
    if !(a > 0.0 && t > 0.0 && speed_mm_s > 0.0) {
        return 0;
    }
    let h = a * t / 2.0;
    let mut progress = 0.0;
    let mut v = 0.0_f64;
    for cycle in 1..=MAX_SIMULATED_CYCLES {
        let dx = length_mm - progress;
        let disc = a * (2.0 * dx - v * t) + h * h;
        let vd = if disc > h * h { -h + disc.sqrt() } else { -h };
        let target = vd.clamp(-speed_mm_s, speed_mm_s);
        let acc = ((target - v) / t).clamp(-a, a);
        let next = v + acc * t;
        if next < 0.0 {
            if dx < v * t {
                progress = length_mm;
            }
            v = 0.0;
        } else {
            progress = (progress + (v + next) * 0.5 * t).min(length_mm);
            v = next;
        }
        if length_mm - progress <= POSITION_EPS_MM {
            return cycle;
        }
    }
    // not reached for moves the machine makes (200 s at a 1 ms period): the trapezoid
    (trapezoid_s(length_mm, speed_mm_s, a) / t).ceil() as u64 + 1
}

/// Continuous-time rest-to-rest trapezoid, s.
fn trapezoid_s(length_mm: f64, speed_mm_s: f64, accel_mm_s2: f64) -> f64 {
    if speed_mm_s * speed_mm_s < accel_mm_s2 * length_mm {
        length_mm / speed_mm_s + speed_mm_s / accel_mm_s2
    } else {
        2.0 * (length_mm / accel_mm_s2).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_stop_takes_whole_periods_near_the_trapezoid() {
        // the planner's loop never beats the continuous trapezoid and loses at most ~2 periods
        let t = 1e-3;
        let cases: &[(f64, f64, f64)] = &[
            (0.3, 1000.0, 1e6),
            (1.0, 1000.0, 1e6),
            (2.0, 1000.0, 1e6),
            (20.0, 1000.0, 1e6),
            (60.0, 5000.0, 1e6),
            (100.0, 500.0, 5000.0),
            (141.4, 707.1, 7071.0),
        ];
        for &(l, v, a) in cases {
            let n = exact_stop_cycles(l, v.min(l / t), a, t);
            let ideal = trapezoid_s(l, v.min(l / t), a) / t;
            assert!(
                n as f64 >= ideal - 1e-9 && (n as f64) <= ideal + 2.5,
                "{l} mm at {v}: {n} periods, trapezoid {ideal}"
            );
        }
        // tiny moves still take two periods (accelerate, brake), as measured
        assert_eq!(exact_stop_cycles(0.3, 300.0, 1e6, t), 2);
        assert_eq!(exact_stop_cycles(0.0, 300.0, 1e6, t), 0);
    }

    #[test]
    fn task_commands_take_what_the_simulated_machine_measured() {
        // per run of commands after a move, ms (the module documentation's table); each
        // within 0.15 ms
        let mut p = MachineProfile::builtin("linuxcnc").unwrap();
        p.controller.servo_period_s = 1e-3;
        let c = LinuxcncClock::of(&p).unwrap();
        let ms = 1e-3;
        let dwell = |p: f64| c.dwell_s(p * ms, true);
        let out = c.period_s;
        let cases = [
            (dwell(0.1), 3.22),
            (dwell(1.0), 3.27),
            (dwell(1.1), 4.27),
            (dwell(2.0), 4.33),
            (dwell(3.0), 5.37),
            (dwell(4.1), 6.40),
            (dwell(10.0), 12.92),
            (dwell(20.0), 22.63),
            (TASK_RESUME_S + out, 3.17),
            (TASK_RESUME_S + 2.0 * out, 4.19),
            (c.dot_s(0.1 * ms, true), 4.38),
            (c.dot_s(2.0 * ms, true), 6.35),
            (TASK_RESUME_S + out + c.dwell_s(2.0 * ms, false), 5.29),
            (dwell(0.1) + c.output_s(), 4.18),
            (dwell(2.0) + c.output_s(), 5.24),
            (
                dwell(0.1) + c.dot_s(0.5 * ms, false) + c.dwell_s(0.1 * ms, false),
                6.04,
            ),
        ];
        for (k, (law, measured)) in cases.into_iter().enumerate() {
            assert!(
                (law / ms - measured).abs() <= 0.15,
                "case {k}: law {} ms, measured {measured} ms",
                law / ms
            );
        }
        // no dwell costs nothing; a dwell of whole cycles is not taken one cycle late
        assert_eq!(c.dwell_s(0.0, true), 0.0);
        assert!(
            (dwell(TASK_CYCLE_RUN_S / ms * 3.0) - TASK_RESUME_S - 3.0 * TASK_CYCLE_RUN_S).abs()
                < 1e-15
        );
    }

    #[test]
    fn box_scaling_of_a_diagonal_and_a_hidden_jump() {
        let mut p = MachineProfile::default();
        p.controller.kind = ControllerKind::Linuxcnc;
        let c = LinuxcncClock::of(&p).unwrap();
        // a 45° stage move runs at √2 × the axis limits along its length: as fast as one axis
        let diagonal = c.move_s([100.0, 100.0, 0.0, 0.0], None);
        let straight = c.move_s([100.0, 0.0, 0.0, 0.0], None);
        assert!((diagonal - straight).abs() <= 2e-3, "{diagonal} {straight}");
        // a scanner jump riding on a stage move does not slow it
        let with_jump = c.move_s([100.0, 0.0, 30.0, -20.0], None);
        assert!(
            (with_jump - straight).abs() <= 1e-3,
            "{with_jump} {straight}"
        );
        // scan-head controllers have no clock
        assert!(LinuxcncClock::of(&MachineProfile::default()).is_none());
    }

    #[test]
    fn rotaries_are_boxed_with_the_stage_and_a_pure_turn_is_not_clipped_by_the_linear_limit() {
        #[allow(clippy::unwrap_used)]
        let mut p = MachineProfile::builtin("five-axis").unwrap();
        p.controller.kind = ControllerKind::Linuxcnc;
        #[allow(clippy::unwrap_used)]
        let c = LinuxcncClock::of(&p).unwrap();
        // B (49.8 deg/s) is the slowest: a 10 mm X move with a 40° turn of B takes B's time
        let b = p.axis_b.as_ref().map_or(0.0, |b| b.0.max_velocity);
        let with_b = c.move_axes_s([10.0, 0.0, 0.0, 0.0], [0.0, 0.0, 40.0], None);
        let b_alone = c.move_axes_s([0.0; 4], [0.0, 0.0, 40.0], None);
        assert!(
            with_b > 40.0 / b && (with_b - b_alone).abs() <= 2e-3,
            "{with_b} {b_alone}"
        );
        // a pure turn's length is in degrees and escapes MAX_LINEAR_VELOCITY (tcPureRotaryCheck)
        let mut slow = c.clone();
        slow.v_limit_mm_s = 1.0;
        let turn = [0.0, 90.0, 0.0];
        assert_eq!(
            slow.move_axes_s([0.0; 4], turn, None),
            c.move_axes_s([0.0; 4], turn, None)
        );
        assert!(slow.move_axes_s([1.0, 0.0, 0.0, 0.0], turn, None) > 1.0);
    }
}

/// Sampling period of an on-the-fly program before merging, s (planned time): the stage's route
/// bends over tens of milliseconds, and a sample every millisecond keeps the merge's error check
/// exact to the stated tolerance between samples (a route's sag over 1 ms at 10⁴ mm/s² is
/// 1.25 µm).
pub const OTF_SAMPLE_S: f64 = 1e-3;

/// Longest run of samples merged into one on-the-fly line: bounds the merge's quadratic check.
const MAX_MERGED_SAMPLES: usize = 400;

/// One line of an on-the-fly program: from the previous line's end to this state, straight in
/// stage and scanner alike, over `duration_s` of planned time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OtfLine {
    /// Planned duration, s (the toolpath's, before any [`crate::motion::Toolpath::stretched`]).
    pub duration_s: f64,
    /// Stage position at the end, mm.
    pub stage: crate::geom::Pt,
    /// Scanner offset at the end, mm.
    pub scan: crate::geom::Pt,
    /// The laser is on along the line.
    pub lit: bool,
    /// The stroke the line marks (index into the toolpath's strokes), when lit.
    pub stroke: Option<usize>,
}

/// The on-the-fly program of `toolpath`: its start state, then lines through samples every
/// [`OTF_SAMPLE_S`] of planned time, every segment end and every mark vertex, consecutive
/// samples merged while the straight line between them passes within `tol_mm` of each sample
/// in between (stage and tool-centre point) and the laser and stroke stay the same.
pub fn otf_lines(toolpath: &Toolpath, tol_mm: f64) -> (MachineState, Vec<OtfLine>) {
    let samples = otf_samples(toolpath);
    let start = samples.first().map_or(toolpath.state_at(0.0), |s| s.state);
    let k = toolpath.stretch();
    let mut lines = Vec::new();
    let mut i = 0;
    while i + 1 < samples.len() {
        let j = merge_end(&samples, i, tol_mm);
        let (a, b) = (&samples[i], &samples[j]);
        lines.push(OtfLine {
            duration_s: (b.t_s - a.t_s) / k,
            stage: b.state.stage,
            scan: b.state.scan,
            lit: b.lit,
            stroke: b.stroke,
        });
        i = j;
    }
    (start, lines)
}

/// The toolpath's exact states (time, state) at its start, every segment's end and every mark
/// vertex, and on the fly at every sample of its program ([`otf_lines`] before merging).
pub fn waypoint_states(toolpath: &Toolpath) -> Vec<(f64, MachineState)> {
    if toolpath.route.is_some() {
        return otf_samples(toolpath)
            .into_iter()
            .map(|s| {
                let mut m = s.state;
                m.laser = s.lit;
                (s.t_s, m)
            })
            .collect();
    }
    let mut out = Vec::with_capacity(toolpath.segments.len() * 2 + 1);
    if let Some(first) = toolpath.segments.first() {
        out.push((first.start_s, toolpath.state_at(first.start_s)));
    }
    for seg in &toolpath.segments {
        if let ScanMotion::Mark {
            stroke,
            start_frac,
            end_frac,
        } = seg.scan
        {
            // the vertices inside the part of the stroke this segment marks (all of it in
            // step-and-scan, an edge of a cylinder's strip)
            let length = toolpath.strokes.get(stroke).map_or(0.0, |s| s.length_mm);
            let arc = toolpath.stroke_arc_mm(stroke);
            let part = end_frac - start_frac;
            let whole = start_frac == 0.0 && end_frac == 1.0;
            for &a in arc.iter().skip(1).take(arc.len().saturating_sub(2)) {
                let f = if length > 0.0 { a / length } else { 0.0 };
                if length > 0.0 && part > 0.0 && (whole || (f > start_frac && f < end_frac)) {
                    let t_s = seg.start_s + (f - start_frac) / part * seg.duration_s;
                    out.push((t_s, toolpath.state_at(t_s)));
                }
            }
        }
        out.push((seg.end_s(), toolpath.state_at(seg.end_s())));
    }
    out
}

/// The toolpath's state at one instant of an on-the-fly program.
#[derive(Debug, Clone, Copy)]
struct Sample {
    t_s: f64,
    state: MachineState,
    /// The laser is on over the span that ends here.
    lit: bool,
    /// The span that ends here marks this stroke.
    stroke: Option<usize>,
}

/// Slack when counting whole sample periods in a segment, in periods.
const SAMPLE_COUNT_TOL: f64 = 1e-6;

/// Samples of an on-the-fly toolpath (see [`otf_lines`]), in the toolpath's time.
fn otf_samples(toolpath: &Toolpath) -> Vec<Sample> {
    let k = toolpath.stretch();
    let period_s = OTF_SAMPLE_S * k;
    let mut out: Vec<Sample> = Vec::with_capacity(
        (toolpath.duration_s() / period_s) as usize + toolpath.segments.len() * 2 + 1,
    );
    let Some(first) = toolpath.segments.first() else {
        return out;
    };
    out.push(Sample {
        t_s: first.start_s,
        state: toolpath.state_at(first.start_s),
        lit: false,
        stroke: None,
    });
    let mut times = Vec::new();
    for seg in &toolpath.segments {
        // counted in planned time, with a tolerance: a stretched toolpath (times × k, rounded)
        // samples exactly as the one it was stretched from (a segment of exactly 50 periods
        // must not become 51)
        let planned_s = seg.duration_s / k;
        if planned_s <= TIME_EPS_S {
            continue;
        }
        times.clear();
        let n = (planned_s / OTF_SAMPLE_S - SAMPLE_COUNT_TOL)
            .ceil()
            .max(1.0) as usize;
        for j in 1..n {
            times.push(seg.start_s + j as f64 * seg.duration_s / n as f64);
        }
        let stroke = match seg.scan {
            ScanMotion::Mark {
                stroke,
                start_frac,
                end_frac,
            } => {
                let length = toolpath.strokes.get(stroke).map_or(0.0, |s| s.length_mm);
                if length > 0.0 && end_frac > start_frac {
                    for &a in toolpath.stroke_arc_mm(stroke) {
                        let u = (a / length - start_frac) / (end_frac - start_frac);
                        if u > 1e-9 && u < 1.0 - 1e-9 {
                            times.push(seg.start_s + u * seg.duration_s);
                        }
                    }
                }
                Some(stroke)
            }
            _ => None,
        };
        times.sort_by(f64::total_cmp);
        times.push(seg.end_s());
        for &t_s in &times {
            out.push(Sample {
                t_s,
                state: toolpath.state_at(t_s),
                lit: stroke.is_some(),
                stroke,
            });
        }
    }
    out
}

/// The last sample `j > i` such that the line from sample `i` to `j`, in time, passes within
/// `tol_mm` of every sample between them (stage and tool-centre point), with the laser and the
/// stroke the same over all of them.
fn merge_end(samples: &[Sample], i: usize, tol_mm: f64) -> usize {
    let a = samples[i].state;
    let t0 = samples[i].t_s;
    let first = samples[i + 1];
    let mut best = i + 1;
    let last = (i + MAX_MERGED_SAMPLES).min(samples.len() - 1);
    for j in i + 2..=last {
        let b = samples[j];
        if b.lit != first.lit || b.stroke != first.stroke {
            break;
        }
        let span = b.t_s - t0;
        let fits = samples[i + 1..j].iter().all(|s| {
            let u = if span > 0.0 { (s.t_s - t0) / span } else { 1.0 };
            let stage = a.stage.plus(b.state.stage.minus(a.stage).scale(u));
            let scan = a.scan.plus(b.state.scan.minus(a.scan).scale(u));
            stage.dist(s.state.stage) <= tol_mm && stage.plus(scan).dist(s.state.tcp()) <= tol_mm
        });
        if !fits {
            break;
        }
        best = j;
    }
    best
}

/// One move as LinuxCNC's planner holds it.
#[derive(Debug, Clone, Copy)]
struct PlannedMove {
    length_mm: f64,
    /// Requested speed (feed or inverse time), mm/s.
    requested_mm_s: f64,
    /// Axis and length limit (`V` clipped to `L / T`), mm/s.
    max_mm_s: f64,
    /// Acceleration `A` (halved for a parabolic blend), mm/s².
    accel_mm_s2: f64,
}

impl LinuxcncClock {
    /// The limits of a straight move by `d_mm` asking for `requested` mm/s of its length
    /// (none: a rapid), and its length; none for no travel.
    fn planned(&self, d_mm: [f64; 4], requested: Option<f64>, blend: bool) -> Option<PlannedMove> {
        self.planned_axes(d_mm, [0.0; 3], requested, blend)
    }

    /// [`LinuxcncClock::planned`] with Z, A and B: the length is the X/Y/Z length when they
    /// move, else the scanner's, else the rotaries' (`emccanon.cc`'s order: cartesian, then
    /// U/V/W, then A/B/C); every axis is scaled into its own box either way. `[TRAJ]
    /// MAX_LINEAR_VELOCITY` clips every move but a pure rotary one (`tpGetMaxTargetVel` skips
    /// it when `tcPureRotaryCheck`: no X/Y/Z and no U/V/W travel), whose length is in degrees;
    /// 2.9's task reads no angular limit (`MAX_ANGULAR_VELOCITY` is the GUIs' jog limit).
    /// Measured on the simulated XYZABUV machine (scripts/check-linuxcnc.sh, five-axis job):
    /// the stand-in's 299 exact-stop G0 moves of X, Y, Z, A and B together between placements
    /// (a program of those moves alone) took 42.147 s, the law 42.135 s (+0.03 %).
    fn planned_axes(
        &self,
        d_mm: [f64; 4],
        turn: [f64; 3],
        requested: Option<f64>,
        blend: bool,
    ) -> Option<PlannedMove> {
        let xyz = d_mm[0].hypot(d_mm[1]).hypot(turn[0]);
        let uv = d_mm[2].hypot(d_mm[3]);
        let ab = turn[1].hypot(turn[2]);
        let pure_rotary = xyz <= POSITION_EPS_MM && uv <= POSITION_EPS_MM;
        let length_mm = [xyz, uv, ab]
            .into_iter()
            .find(|l| *l > POSITION_EPS_MM)
            .unwrap_or(0.0);
        if length_mm <= POSITION_EPS_MM {
            return None;
        }
        let slowest = |limits: &[f64; 4], extra: &[f64; 3]| {
            d_mm.iter()
                .zip(limits)
                .chain(turn.iter().zip(extra))
                .map(|(d, l)| d.abs() / l)
                .fold(0.0, f64::max)
        };
        let v_axes = length_mm / slowest(&self.vmax_mm_s, &self.extra_vmax);
        let accel = length_mm / slowest(&self.amax_mm_s2, &self.extra_amax);
        Some(PlannedMove {
            length_mm,
            requested_mm_s: requested.unwrap_or(v_axes),
            max_mm_s: v_axes.min(length_mm / self.period_s).min(if pure_rotary {
                f64::INFINITY
            } else {
                self.v_limit_mm_s
            }),
            accel_mm_s2: if blend { accel * 0.5 } else { accel },
        })
    }

    /// How long LinuxCNC takes for the on-the-fly program of `lines` (from `start`), blended
    /// (`G64`) in inverse time (`G93`): each line asks for its length over its planned duration.
    pub fn otf_program_s(&self, start: &MachineState, lines: &[OtfLine]) -> f64 {
        let mut at = [start.stage.x, start.stage.y, start.scan.x, start.scan.y];
        let mut moves = Vec::with_capacity(lines.len());
        for l in lines {
            let to = [l.stage.x, l.stage.y, l.scan.x, l.scan.y];
            let d = [to[0] - at[0], to[1] - at[1], to[2] - at[2], to[3] - at[3]];
            at = to;
            let xy = d[0].hypot(d[1]);
            let length = if xy > POSITION_EPS_MM {
                xy
            } else {
                d[2].hypot(d[3])
            };
            // LinuxCNC: rate = max(0.1, L·F) per minute, F = 1/duration in minutes
            let requested = (length * 60.0 / l.duration_s.max(1e-12)).max(0.1) / 60.0;
            if let Some(m) = self.planned(d, Some(requested), true) {
                moves.push(m);
            }
        }
        blended_cycles(&moves, self.period_s) as f64 * self.period_s
    }
}

/// A move in the planner's queue, and its run-time state (`TC_STRUCT`'s fields that matter).
#[derive(Debug, Clone, Copy)]
struct Running {
    m: PlannedMove,
    progress_mm: f64,
    v_mm_s: f64,
    on_final_decel: bool,
    blending_next: bool,
    splitting: bool,
    remove: bool,
}

impl Running {
    fn new(m: PlannedMove) -> Self {
        Self {
            m,
            progress_mm: 0.0,
            v_mm_s: 0.0,
            on_final_decel: false,
            blending_next: false,
            splitting: false,
            remove: false,
        }
    }
    fn target_mm_s(&self) -> f64 {
        self.m.requested_mm_s.min(self.m.max_mm_s)
    }
    /// One period of `tpCalculateTrapezoidalAccel` + `tcUpdateDistFromAccel` +
    /// `tpCheckEndCondition` for a parabolic-blend move (final speed 0).
    fn step(&mut self, t: f64) {
        let a = self.m.accel_mm_s2;
        let dx = self.m.length_mm - self.progress_mm;
        let h = a * t / 2.0;
        let disc = a * (2.0 * dx - self.v_mm_s * t) + h * h;
        let vd = if disc > h * h { -h + disc.sqrt() } else { -h };
        let vt = self.target_mm_s();
        let acc = ((vd.clamp(-vt, vt) - self.v_mm_s) / t).clamp(-a, a);
        let next = self.v_mm_s + acc * t;
        if next < 0.0 {
            if dx < self.v_mm_s * t {
                self.progress_mm = self.m.length_mm;
            }
            self.v_mm_s = 0.0;
        } else {
            self.progress_mm =
                (self.progress_mm + (self.v_mm_s + next) * 0.5 * t).min(self.m.length_mm);
            self.v_mm_s = next;
        }
        self.on_final_decel = (vd - self.v_mm_s).abs() < 1e-8 && acc < 0.0;
        // end condition
        let dx = self.m.length_mm - self.progress_mm;
        if dx <= POSITION_EPS_MM {
            self.progress_mm = self.m.length_mm;
            self.splitting = true;
            return;
        }
        let v_avg = self.v_mm_s / 2.0;
        let mut dt: f64 = 1e-12 / 2.0;
        if v_avg > 1e-8 {
            dt = dt.max(dx / v_avg);
        } else if dx > v_avg * t {
            return;
        }
        let a_f = -self.v_mm_s / dt;
        let a_c = a_f.clamp(-a, a);
        if a_c != a_f {
            let disc = (self.v_mm_s / a_c).powi(2) + 2.0 / a_c * dx;
            if disc < 0.0 {
                return;
            }
            dt = if disc < 1e-24 {
                -self.v_mm_s / a_c
            } else if a_c > 0.0 {
                -self.v_mm_s / a_c + disc.sqrt()
            } else {
                -self.v_mm_s / a_c - disc.sqrt()
            };
        }
        if dt < t {
            if dt < 1e-12 {
                self.progress_mm = self.m.length_mm;
            }
            self.splitting = true;
        }
    }
    /// `tpComputeBlendVelocity` for U/V moves (no tolerance bound: LinuxCNC takes their
    /// blend angle as 90°).
    fn blend_mm_s(&self, next: &Running, last_in_queue: bool) -> f64 {
        let tri = |r: &Running, half: bool| {
            let l = if half {
                r.m.length_mm / 2.0
            } else {
                r.m.length_mm
            };
            (r.m.accel_mm_s2 * l).sqrt()
        };
        let vr = tri(self, false).min(self.target_mm_s());
        let vr_next = tri(next, last_in_queue).min(next.target_mm_s());
        let (a, a_next) = (self.m.accel_mm_s2, next.m.accel_mm_s2);
        let t_run = (self.m.length_mm / vr).min(next.m.length_mm / vr_next);
        let t_blend = (vr / a).max(vr_next / a_next);
        vr.min(t_run.min(t_blend) * a)
    }
}

/// Servo periods LinuxCNC's planner takes for `moves` blended parabolically (`G64`, moves of
/// the U/V axes): the planner's period loop (`tpRunCycle`): the active move advances; once it
/// brakes for its end below the blend speed, the next move advances in the same period; a move
/// that ends within a period hands the period to the next (split cycle).
fn blended_cycles(moves: &[PlannedMove], period_s: f64) -> u64 {
    let mut queue: std::collections::VecDeque<Running> =
        moves.iter().map(|&m| Running::new(m)).collect();
    let mut cycles = 0;
    while let Some(mut tc) = queue.pop_front() {
        loop {
            cycles += 1;
            if tc.splitting {
                tc.remove = true;
                if let Some(nx) = queue.front_mut() {
                    nx.step(period_s);
                }
            } else {
                tc.step(period_s);
                let last = queue.len() == 1;
                if let Some(nx) = queue.front_mut() {
                    let vb = tc.blend_mm_s(nx, last);
                    tc.blending_next |= tc.on_final_decel && tc.v_mm_s < vb;
                    if tc.blending_next {
                        nx.step(period_s);
                    }
                }
            }
            if tc.remove {
                break;
            }
            if cycles > MAX_SIMULATED_CYCLES * 50 {
                return cycles;
            }
        }
    }
    cycles
}
