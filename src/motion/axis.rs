//! One stage axis moving point to point from rest to rest with a trapezoidal velocity profile,
//! and the machine's axes built from them: the X/Y stage, and a Z and rotary A/B axes where the
//! profile has them (seed 002 §6.3).
//!
//! Seed 002's eq. 14 is this trapezoid in its terms: with nominal feed `F` and acceleration time
//! `t_a` (so `a = F / t_a`), a displacement `s > F·t_a` takes `s/F + t_a` (= `d/v + v/a`),
//! a shorter one `2·√(s·t_a/F)` (= `2·√(d/a)`, the triangle).

use crate::document::{AxisLimits, ExtraAxisId, MachineProfile, Pose};
use crate::geom::Pt;

/// A rest-to-rest move of one axis: accelerate at `accel`, cruise at `peak` (when the distance
/// allows it), decelerate at `accel`. A move too short to reach full speed is a triangle whose
/// peak is `√(accel · |distance|)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisMove {
    /// Start position, mm.
    pub start_mm: f64,
    /// Signed distance, mm.
    pub distance_mm: f64,
    /// Acceleration used on the ramps, mm/s².
    pub accel_mm_s2: f64,
    /// Speed reached, mm/s (≤ the axis limit).
    pub peak_mm_s: f64,
    /// Duration of one ramp, s.
    pub ramp_s: f64,
    /// Duration of the whole move, s.
    pub duration_s: f64,
}

impl AxisMove {
    /// The time-optimal move from `start_mm` to `end_mm` under `limits`.
    pub fn new(start_mm: f64, end_mm: f64, limits: &AxisLimits) -> AxisMove {
        let (v, a) = (limits.max_velocity_mm_s, limits.max_accel_mm_s2);
        let distance_mm = end_mm - start_mm;
        let d = distance_mm.abs();
        // the ramps alone cover v²/a: below that the move is a triangle
        let peak_mm_s = if d < v * v / a { (a * d).sqrt() } else { v };
        let ramp_s = if d > 0.0 { peak_mm_s / a } else { 0.0 };
        let duration_s = if d == 0.0 {
            0.0
        } else {
            // two ramps cover peak²/a; the rest is cruise at the peak speed
            2.0 * ramp_s + (d - peak_mm_s * peak_mm_s / a) / peak_mm_s
        };
        AxisMove {
            start_mm,
            distance_mm,
            accel_mm_s2: a,
            peak_mm_s,
            ramp_s,
            duration_s,
        }
    }

    /// Position at `t_s` after the start (clamped to the move).
    pub fn position_mm(&self, t_s: f64) -> f64 {
        if self.duration_s <= 0.0 {
            return self.start_mm;
        }
        let t = t_s.clamp(0.0, self.duration_s);
        let a = self.accel_mm_s2;
        let d = self.distance_mm.abs();
        let travelled = if t <= self.ramp_s {
            0.5 * a * t * t
        } else if t <= self.duration_s - self.ramp_s {
            0.5 * a * self.ramp_s * self.ramp_s + self.peak_mm_s * (t - self.ramp_s)
        } else {
            let left = self.duration_s - t;
            d - 0.5 * a * left * left
        };
        self.start_mm + travelled.min(d) * self.distance_mm.signum()
    }
}

/// The axes of a profile that move between placements: all start together, each runs its own
/// time-optimal trapezoid, the slowest one sets the move time (seed 002 §6.3:
/// `d = max(t_x, t_y, t_z, t_A, t_B)`); each axis that moved then settles for its `settle_s`.
#[derive(Debug, Clone, PartialEq)]
pub struct StageDynamics {
    /// X axis limits.
    pub x: AxisLimits,
    /// Y axis limits.
    pub y: AxisLimits,
    /// Z, A and B limits where the profile has the axis (in its unit: mm or deg).
    pub extra: [Option<AxisLimits>; 3],
}

/// A stage move between two positions: the axis moves and the settling after them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageMove {
    /// X axis.
    pub x: AxisMove,
    /// Y axis.
    pub y: AxisMove,
    /// Z, A and B (zero moves on a machine without them; mm or deg).
    pub extra: [AxisMove; 3],
    /// Until every axis stands still, s.
    pub move_s: f64,
    /// From then until every axis that moved has settled, s.
    pub settle_s: f64,
}

impl StageMove {
    /// Position at `t_s` after the start.
    pub fn position(&self, t_s: f64) -> Pt {
        Pt::new(self.x.position_mm(t_s), self.y.position_mm(t_s))
    }
    /// Pose of Z, A and B at `t_s` after the start.
    pub fn pose(&self, t_s: f64) -> Pose {
        let [z, a, b] = self.extra.map(|m| m.position_mm(t_s));
        Pose {
            z_mm: z,
            a_deg: a,
            b_deg: b,
            stage_y_mm: None,
        }
    }
    /// Move plus settling, s.
    pub fn total_s(&self) -> f64 {
        self.move_s + self.settle_s
    }
}

impl StageDynamics {
    /// The stage of a machine profile.
    pub fn of(profile: &MachineProfile) -> Self {
        Self {
            x: profile.axis_x.clone(),
            y: profile.axis_y.clone(),
            extra: ExtraAxisId::ALL.map(|id| profile.extra_axis(id).map(|a| a.limits())),
        }
    }
    /// The move from `from` to `to` (Z, A and B at rest).
    pub fn plan_move(&self, from: Pt, to: Pt) -> StageMove {
        self.plan_pose_move(from, &Pose::default(), to, &Pose::default())
    }
    /// The move from `from` at `from_pose` to `to` at `to_pose`. An axis the machine does not
    /// have does not move ([`MachineProfile::check_pose`] refuses a pose that needs it). `from`
    /// and `to` are placements' centres: the stage goes where their poses put it
    /// ([`Pose::stage_point`]).
    pub fn plan_pose_move(&self, from: Pt, from_pose: &Pose, to: Pt, to_pose: &Pose) -> StageMove {
        let (from, to) = (from_pose.stage_point(from), to_pose.stage_point(to));
        let x = AxisMove::new(from.x, to.x, &self.x);
        let y = AxisMove::new(from.y, to.y, &self.y);
        let (p, q) = (from_pose.values(), to_pose.values());
        let extra = [0, 1, 2].map(|k| match &self.extra[k] {
            Some(l) => AxisMove::new(p[k], q[k], l),
            None => AxisMove::new(p[k], p[k], &self.x),
        });
        let mut move_s = x.duration_s.max(y.duration_s);
        let settled = |m: &AxisMove, l: &AxisLimits| {
            if m.distance_mm != 0.0 {
                m.duration_s + l.settle_s
            } else {
                0.0
            }
        };
        let mut done_s = settled(&x, &self.x).max(settled(&y, &self.y));
        for (m, l) in extra.iter().zip(&self.extra) {
            if let Some(l) = l {
                move_s = move_s.max(m.duration_s);
                done_s = done_s.max(settled(m, l));
            }
        }
        StageMove {
            x,
            y,
            extra,
            move_s,
            settle_s: (done_s - move_s).max(0.0),
        }
    }
    /// Time from rest at `from` to settled at `to`, s: the stage part of the time cost.
    pub fn move_time_s(&self, from: Pt, to: Pt) -> f64 {
        self.plan_move(from, to).total_s()
    }
    /// Time from rest at `from` (`from_pose`) to settled at `to` (`to_pose`), s: the slowest
    /// axis's time (seed 002's 5-axis time cost).
    pub fn pose_move_time_s(&self, from: Pt, from_pose: &Pose, to: Pt, to_pose: &Pose) -> f64 {
        self.plan_pose_move(from, from_pose, to, to_pose).total_s()
    }
    /// The machine moves axes beyond X/Y.
    pub fn has_extra(&self) -> bool {
        self.extra.iter().any(Option::is_some)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis(v: f64, a: f64) -> AxisLimits {
        AxisLimits {
            max_velocity_mm_s: v,
            max_accel_mm_s2: a,
            settle_s: 0.0,
        }
    }

    #[test]
    fn trapezoid_and_triangle_times() {
        // short move: triangle, 2·√(d/a)
        assert!((AxisMove::new(0.0, 1.0, &axis(100.0, 100.0)).duration_s - 0.2).abs() < 1e-12);
        // long move: d/v + v/a
        assert!((AxisMove::new(0.0, -300.0, &axis(100.0, 1000.0)).duration_s - 3.1).abs() < 1e-12);
    }

    #[test]
    fn positions_follow_the_profile() {
        let l = axis(100.0, 1000.0);
        for (from, to) in [(10.0, 310.0), (50.0, 45.0), (0.0, 0.0)] {
            let m = AxisMove::new(from, to, &l);
            assert_eq!(m.position_mm(0.0), from);
            assert!((m.position_mm(m.duration_s) - to).abs() < 1e-9);
            // sampled speed and acceleration stay within the limits
            let dt = 1e-3;
            let n = (m.duration_s / dt).ceil() as usize + 2;
            let p: Vec<f64> = (0..n).map(|k| m.position_mm(k as f64 * dt)).collect();
            for w in p.windows(3) {
                let v = (w[1] - w[0]) / dt;
                let acc = (w[2] - 2.0 * w[1] + w[0]) / (dt * dt);
                assert!(v.abs() <= 100.0 + 1e-6, "{v}");
                assert!(acc.abs() <= 1000.0 * (1.0 + 1e-6), "{acc}");
            }
        }
    }

    #[test]
    fn slower_axis_sets_the_time_and_settling_follows_the_moving_axes() {
        let mut st = StageDynamics {
            x: axis(100.0, 1000.0),
            y: axis(50.0, 1000.0),
            extra: [None, None, None],
        };
        st.y.settle_s = 0.05;
        let m = st.plan_move(Pt::new(0.0, 0.0), Pt::new(100.0, 100.0));
        assert!((m.move_s - (100.0 / 50.0 + 50.0 / 1000.0)).abs() < 1e-12);
        assert!((m.settle_s - 0.05).abs() < 1e-12);
        // only x moves: y's settling does not apply
        let m = st.plan_move(Pt::new(0.0, 0.0), Pt::new(100.0, 0.0));
        assert_eq!(m.settle_s, 0.0);
        assert_eq!(st.move_time_s(Pt::new(3.0, 4.0), Pt::new(3.0, 4.0)), 0.0);
    }

    /// Seed 002's eq. 14 for one axis: `s/F + t_a` beyond `F·t_a`, else `2·√(s·t_a/F)`.
    fn eq14_s(s: f64, f_nom: f64, t_a: f64) -> f64 {
        if s > f_nom * t_a {
            s / f_nom + t_a
        } else {
            2.0 * (s * t_a / f_nom).sqrt()
        }
    }

    #[test]
    fn a_move_whose_slowest_axis_is_b_costs_bs_eq_14_time() {
        let p = MachineProfile::builtin("five-axis").unwrap();
        let st = StageDynamics::of(&p);
        let b = p.axis_b.as_ref().unwrap();
        let (f_b, t_b) = (b.0.max_velocity, b.0.max_velocity / b.0.max_accel);
        let from = Pose::default();
        // 40 mm in X (≈ 0.42 s) and 5 mm in Z, while B turns 60° (≈ 1.36 s): B sets the time
        let to = Pose {
            z_mm: 5.0,
            a_deg: 10.0,
            b_deg: 60.0,
            stage_y_mm: None,
        };
        let m = st.plan_pose_move(Pt::new(100.0, 100.0), &from, Pt::new(140.0, 100.0), &to);
        let want = eq14_s(60.0, f_b, t_b);
        assert!((m.move_s - want).abs() < 1e-12, "{} vs {want}", m.move_s);
        assert!(m.x.duration_s < want && m.extra[1].duration_s < want);
        assert!(
            (st.pose_move_time_s(Pt::new(100.0, 100.0), &from, Pt::new(140.0, 100.0), &to) - want)
                .abs()
                < 1e-12
        );
        // a short B move is the triangle
        let small = Pose {
            b_deg: 2.0,
            ..Pose::default()
        };
        let m = st.plan_pose_move(Pt::default(), &from, Pt::default(), &small);
        assert!((m.move_s - eq14_s(2.0, f_b, t_b)).abs() < 1e-12);
        // X alone follows eq. 14 with X's own law (seed 002 Table 2: 218 mm/s, 0.239 s)
        let m = st.plan_move(Pt::default(), Pt::new(200.0, 0.0));
        assert!((m.move_s - eq14_s(200.0, 218.0, 0.239)).abs() < 1e-9);
        // the pose is followed along the move
        let m = st.plan_pose_move(Pt::default(), &from, Pt::default(), &to);
        assert_eq!(m.pose(0.0), from);
        let end = m.pose(m.move_s);
        assert!((end.b_deg - 60.0).abs() < 1e-9 && (end.z_mm - 5.0).abs() < 1e-9);
    }
}
