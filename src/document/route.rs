//! A timed stage route (seed 001's `lsa` and `cetsp-ga` routes), kept in a plan.

use crate::geom::Pt;

/// A stage route: turning points, each with the (nominal tool) time the stage is there; the stage
/// moves straight and at constant speed between consecutive turning points. Times non-decreasing.
/// Before the first time the stage is at the first point, after the last at the last point.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct TimedRoute {
    /// Turning points, mm.
    pub points: Vec<Pt>,
    /// Time the stage is at each turning point, s.
    pub times_s: Vec<f64>,
}

impl TimedRoute {
    /// The stage position at time `t_s` (the origin for an empty route).
    pub fn position(&self, t_s: f64) -> Pt {
        let n = self.points.len().min(self.times_s.len());
        if n == 0 {
            return Pt::default();
        }
        let k = self.times_s[..n].partition_point(|&t| t <= t_s);
        if k == 0 {
            return self.points[0];
        }
        if k == n {
            return self.points[n - 1];
        }
        self.between(k - 1, t_s)
    }

    /// The position at `t_s` on the leg from turning point `i` to `i + 1`, with
    /// `times_s[i] <= t_s < times_s[i + 1]`.
    pub fn between(&self, i: usize, t_s: f64) -> Pt {
        let (t0, t1) = (self.times_s[i], self.times_s[i + 1]);
        let (a, b) = (self.points[i], self.points[i + 1]);
        let span = t1 - t0;
        if span <= 0.0 {
            return b;
        }
        a.plus(b.minus(a).scale(((t_s - t0) / span).clamp(0.0, 1.0)))
    }

    /// Length of the polyline through the turning points, mm.
    pub fn length_mm(&self) -> f64 {
        crate::geom::polyline_length(&self.points, false)
    }
}
