//! One stage axis moving point to point from rest to rest with a trapezoidal velocity profile,
//! and the two-axis stage built from two of them (seed 002 §6.3).

use crate::document::{AxisLimits, MachineProfile};
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

/// The two stage axes of a profile: both start together, each runs its own time-optimal
/// trapezoid, the slower one sets the move time (seed 002 §6.3: cost = max over the axes); each
/// axis that moved then settles for its `settle_s`.
#[derive(Debug, Clone, PartialEq)]
pub struct StageDynamics {
    /// X axis limits.
    pub x: AxisLimits,
    /// Y axis limits.
    pub y: AxisLimits,
}

/// A stage move between two positions: the two axis moves and the settling after them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageMove {
    /// X axis.
    pub x: AxisMove,
    /// Y axis.
    pub y: AxisMove,
    /// Until both axes stand still, s.
    pub move_s: f64,
    /// From then until every axis that moved has settled, s.
    pub settle_s: f64,
}

impl StageMove {
    /// Position at `t_s` after the start.
    pub fn position(&self, t_s: f64) -> Pt {
        Pt::new(self.x.position_mm(t_s), self.y.position_mm(t_s))
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
        }
    }
    /// The move from `from` to `to`.
    pub fn plan_move(&self, from: Pt, to: Pt) -> StageMove {
        let x = AxisMove::new(from.x, to.x, &self.x);
        let y = AxisMove::new(from.y, to.y, &self.y);
        let move_s = x.duration_s.max(y.duration_s);
        let settled = |m: &AxisMove, l: &AxisLimits| {
            if m.distance_mm != 0.0 {
                m.duration_s + l.settle_s
            } else {
                0.0
            }
        };
        let done_s = settled(&x, &self.x).max(settled(&y, &self.y));
        StageMove {
            x,
            y,
            move_s,
            settle_s: (done_s - move_s).max(0.0),
        }
    }
    /// Time from rest at `from` to settled at `to`, s: the stage part of the time cost.
    pub fn move_time_s(&self, from: Pt, to: Pt) -> f64 {
        self.plan_move(from, to).total_s()
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
}
