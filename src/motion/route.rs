//! A continuous stage route, per axis: tracked through its reachable sets ([`super::track`]),
//! or a piecewise-linear path (the taut string) with blended corners or smoothed by a moving
//! average, so that speed and acceleration stay within the axis limits.
//!
//! Smoothing: `y(t) = (1/W) ∫_{t−W/2}^{t+W/2} x(s) ds`, with `x` held constant before its first
//! and after its last vertex. Then `y'(t) = (x(t+W/2) − x(t−W/2)) / W`, so `|y'| ≤ max |x'|`, and
//! `y''` is the difference of two slopes of `x` over `W`, so `|y''| ≤ (max x' − min x') / W ≤
//! 2 v / W` where `v` bounds `|x'|`: with `W = 2 v / a_max` the acceleration stays within
//! `a_max`. The smoothed path departs from `x` by at most the mean of `|x(s) − x(t)|` over the
//! window, `≤ v · W / 4 = v² / (2 a_max)`, which is the part of the scanner's reach kept for it.

use super::blend::CornerBlends;
use super::track::TrackedAxis;
use crate::geom::Pt;

/// One smoothed axis.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothedAxis {
    /// Vertices `(t_s, x_mm)` of the piecewise-linear path, times strictly increasing.
    vertices: Vec<(f64, f64)>,
    /// `∫ x` from the first vertex to each vertex, mm·s.
    integral: Vec<f64>,
    /// Averaging window, s (0: no smoothing).
    window_s: f64,
}

impl SmoothedAxis {
    /// Smooths `vertices` (non-empty, times strictly increasing) over `window_s`.
    pub fn new(vertices: Vec<(f64, f64)>, window_s: f64) -> Self {
        let mut integral = Vec::with_capacity(vertices.len());
        let mut sum = 0.0;
        for (k, &(t, x)) in vertices.iter().enumerate() {
            if k > 0 {
                let (t0, x0) = vertices[k - 1];
                sum += 0.5 * (x0 + x) * (t - t0);
            }
            integral.push(sum);
        }
        Self {
            vertices,
            integral,
            window_s,
        }
    }

    /// `x(t)`, held constant outside the vertices.
    fn raw(&self, t_s: f64) -> f64 {
        super::taut::position_at(&self.vertices, t_s)
    }

    /// `∫ x` from the first vertex to `t_s` (negative before it).
    fn antiderivative(&self, t_s: f64) -> f64 {
        let (Some(&(t0, x0)), Some(&(tn, xn))) = (self.vertices.first(), self.vertices.last())
        else {
            return 0.0;
        };
        if t_s <= t0 {
            return x0 * (t_s - t0);
        }
        let last = self.vertices.len() - 1;
        if t_s >= tn {
            return self.integral[last] + xn * (t_s - tn);
        }
        let k = self.vertices.partition_point(|v| v.0 <= t_s) - 1;
        let (ta, xa) = self.vertices[k];
        let x = self.raw(t_s);
        self.integral[k] + 0.5 * (xa + x) * (t_s - ta)
    }

    /// The averaging window, s.
    pub fn window_s(&self) -> f64 {
        self.window_s
    }

    /// The smoothed position at `t_s`, mm.
    pub fn position_mm(&self, t_s: f64) -> f64 {
        if self.window_s <= 0.0 {
            return self.raw(t_s);
        }
        let h = self.window_s / 2.0;
        (self.antiderivative(t_s + h) - self.antiderivative(t_s - h)) / self.window_s
    }
}

/// One axis of a stage route: corners blended one by one, or (where overlapping blends would
/// exceed the acceleration) the whole path averaged over one window.
#[derive(Debug, Clone, PartialEq)]
pub enum AxisRoute {
    /// Corner blends ([`CornerBlends`]).
    Blends(CornerBlends),
    /// A moving average ([`SmoothedAxis`]).
    Window(SmoothedAxis),
    /// Tracked through the reachable sets ([`super::track`]): the acceleration constant
    /// between samples.
    Tracked(TrackedAxis),
}

impl AxisRoute {
    /// The acceleration-limited route through `vertices` (speed at most their peak).
    pub fn smooth(vertices: Vec<(f64, f64)>, accel_mm_s2: f64) -> Self {
        match CornerBlends::new(&vertices, accel_mm_s2) {
            Ok(blends) => AxisRoute::Blends(blends),
            Err(_) => {
                let window_s = 2.0 * super::taut::peak_speed_mm_s(&vertices) / accel_mm_s2;
                AxisRoute::Window(SmoothedAxis::new(vertices, window_s))
            }
        }
    }
    /// Position at `t_s`, mm.
    pub fn position_mm(&self, t_s: f64) -> f64 {
        match self {
            AxisRoute::Blends(b) => b.position_mm(t_s),
            AxisRoute::Window(w) => w.position_mm(t_s),
            AxisRoute::Tracked(a) => a.position_mm(t_s),
        }
    }
    /// The stretch of the path (route time, s) whose corners move the route at `t_s`.
    pub fn active_span(&self, t_s: f64) -> Option<(f64, f64)> {
        match self {
            AxisRoute::Blends(b) => b.active_span(t_s),
            AxisRoute::Window(w) => Some((t_s - w.window_s() / 2.0, t_s + w.window_s() / 2.0)),
            AxisRoute::Tracked(_) => None,
        }
    }
    /// How long before or after a vertex the route may depart from the path, s (the longest
    /// blend, or the window).
    pub fn reach_s(&self) -> f64 {
        match self {
            AxisRoute::Blends(b) => b.longest_s(),
            AxisRoute::Window(w) => w.window_s(),
            AxisRoute::Tracked(_) => 0.0,
        }
    }
}

/// The stage route of an on-the-fly job: two smoothed axes on a time base shifted by
/// `offset_s` (job time = route time + offset, so the stage can start from rest).
#[derive(Debug, Clone, PartialEq)]
pub struct StageRoute {
    /// X axis.
    pub x: AxisRoute,
    /// Y axis.
    pub y: AxisRoute,
    /// Job time at route time 0, s.
    pub offset_s: f64,
}

impl StageRoute {
    /// Stage position at job time `t_s`.
    pub fn position(&self, t_s: f64) -> Pt {
        let tau = t_s - self.offset_s;
        Pt::new(self.x.position_mm(tau), self.y.position_mm(tau))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_keeps_speed_and_limits_acceleration_and_departure() {
        // a zigzag at ±v: slope changes of 2v
        let v = 100.0;
        let verts: Vec<(f64, f64)> = (0..12)
            .map(|k| (k as f64 * 0.5, if k % 2 == 0 { 0.0 } else { v * 0.5 }))
            .collect();
        let a_max = 2000.0;
        let w = 2.0 * v / a_max;
        let ax = SmoothedAxis::new(verts.clone(), w);
        let dt = 1e-3;
        let p: Vec<f64> = (0..6000)
            .map(|k| ax.position_mm(k as f64 * dt - 0.2))
            .collect();
        for w3 in p.windows(3) {
            let speed = (w3[1] - w3[0]) / dt;
            let acc = (w3[2] - 2.0 * w3[1] + w3[0]) / (dt * dt);
            assert!(speed.abs() <= v * (1.0 + 1e-9) + 1e-6, "{speed}");
            assert!(acc.abs() <= a_max * 1.0001, "{acc}");
        }
        let worst = (0..6000)
            .map(|k| {
                let t = k as f64 * dt - 0.2;
                (ax.position_mm(t) - ax.raw(t)).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst <= v * w / 4.0 + 1e-9, "{worst}");
        // at rest before the path: no motion
        assert_eq!(ax.position_mm(-1.0), ax.position_mm(-0.9));
    }
}
