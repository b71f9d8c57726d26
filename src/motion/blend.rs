//! Corner blends: a piecewise-linear axis path made acceleration-limited corner by corner.
//!
//! At every vertex the speed jumps by `Δv`; the blend replaces the jump by a ramp of duration
//! `|Δv| / a` centred on the vertex (acceleration `±a` over the ramp). A centred ramp changes
//! the position only while it runs (the areas before and after the vertex cancel), by at most
//! `Δv² / (8 a)`: small corners stay close to the path, only fast reversals need room. Ramps of
//! the same sign that overlap are merged into one ramp of their summed `Δv`, centred at their
//! `Δv`-weighted mean time (which again leaves the position after it unchanged); ramps of
//! opposite signs may overlap (their accelerations cancel there). The result is checked: where
//! three or more ramps would still add up beyond `a`, [`CornerBlends::new`] returns the
//! [`Overload`] spans and the caller slows the path there (slowing a stretch by `f` divides its
//! `Δv`, hence its ramp widths, by `f` and multiplies the time between its vertices by `f`: the
//! overlaps go away).

/// One ramp of the blended speed.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Ramp {
    /// Speed change, mm/s.
    dv_mm_s: f64,
    /// Centre time, s.
    centre_s: f64,
    /// Duration, s.
    width_s: f64,
}

impl Ramp {
    fn start_s(&self) -> f64 {
        self.centre_s - self.width_s / 2.0
    }
    fn end_s(&self) -> f64 {
        self.centre_s + self.width_s / 2.0
    }
    /// `∫_{-∞}^{t}` of the ramp's unit step, s (the ramp's share of the position per mm/s).
    fn integral_s(&self, t_s: f64) -> f64 {
        if t_s <= self.start_s() {
            0.0
        } else if t_s >= self.end_s() {
            t_s - self.centre_s
        } else {
            let u = t_s - self.start_s();
            u * u / (2.0 * self.width_s)
        }
    }
}

/// An axis path with blended corners, at rest before its first and after its last vertex.
#[derive(Debug, Clone, PartialEq)]
pub struct CornerBlends {
    /// Position before the path, mm.
    start_mm: f64,
    /// Ramps in order of their start times.
    ramps: Vec<Ramp>,
    /// `Σ Δv` and `Σ Δv · centre` of the ramps before each index (and of all of them).
    prefix: Vec<(f64, f64)>,
    /// Longest ramp, s.
    longest_s: f64,
}

/// Where overlapping ramps would accelerate beyond the limit: the time spans (s) of the ramps
/// that overlap there.
#[derive(Debug, Clone, PartialEq)]
pub struct Overload {
    /// `(start_s, end_s)` spans, in time order.
    pub spans: Vec<(f64, f64)>,
}

impl CornerBlends {
    /// Blends the corners of `vertices` (non-empty, times strictly increasing) at acceleration
    /// `accel_mm_s2`; the `Overload` spans where overlapping ramps would exceed it.
    pub fn new(vertices: &[(f64, f64)], accel_mm_s2: f64) -> Result<Self, Overload> {
        let Some(&(_, start_mm)) = vertices.first() else {
            return Err(Overload { spans: Vec::new() });
        };
        let mut ramps: Vec<Ramp> = Vec::with_capacity(vertices.len());
        let mut v_before = 0.0;
        for (k, &(t, x)) in vertices.iter().enumerate() {
            let v_after = vertices
                .get(k + 1)
                .map_or(0.0, |&(t1, x1)| (x1 - x) / (t1 - t));
            let dv_mm_s = v_after - v_before;
            v_before = v_after;
            if dv_mm_s == 0.0 {
                continue;
            }
            let mut ramp = Ramp {
                dv_mm_s,
                centre_s: t,
                width_s: dv_mm_s.abs() / accel_mm_s2,
            };
            // merge with earlier ramps of the same sign that overlap it
            while let Some(last) = ramps.last() {
                let same_sign = last.dv_mm_s.signum() == ramp.dv_mm_s.signum();
                if !(same_sign && last.end_s() > ramp.start_s()) {
                    break;
                }
                let dv = last.dv_mm_s + ramp.dv_mm_s;
                ramp = Ramp {
                    dv_mm_s: dv,
                    centre_s: (last.dv_mm_s * last.centre_s + ramp.dv_mm_s * ramp.centre_s) / dv,
                    width_s: dv.abs() / accel_mm_s2,
                };
                ramps.pop();
            }
            ramps.push(ramp);
        }
        ramps.sort_by(|a, b| a.start_s().total_cmp(&b.start_s()));
        let mut prefix = Vec::with_capacity(ramps.len() + 1);
        let (mut dv, mut dvc) = (0.0, 0.0);
        prefix.push((dv, dvc));
        for r in &ramps {
            dv += r.dv_mm_s;
            dvc += r.dv_mm_s * r.centre_s;
            prefix.push((dv, dvc));
        }
        let blends = Self {
            start_mm,
            longest_s: ramps.iter().map(|r| r.width_s).fold(0.0, f64::max),
            ramps,
            prefix,
        };
        let spans: Vec<(f64, f64)> = blends
            .overloaded_at(accel_mm_s2)
            .into_iter()
            .filter_map(|t| blends.active_span(t))
            .collect();
        if spans.is_empty() {
            Ok(blends)
        } else {
            Err(Overload { spans })
        }
    }

    /// The instants where the summed ramps accelerate faster than `accel_mm_s2` (sweep over
    /// the ramps' start and end events; the middle of each overloaded stretch).
    fn overloaded_at(&self, accel_mm_s2: f64) -> Vec<f64> {
        let mut events: Vec<(f64, f64)> = Vec::with_capacity(2 * self.ramps.len());
        for r in &self.ramps {
            let a = r.dv_mm_s / r.width_s;
            events.push((r.start_s(), a));
            events.push((r.end_s(), -a));
        }
        events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let mut sum = 0.0;
        let mut k = 0;
        let mut out = Vec::new();
        while k < events.len() {
            // apply every event at this instant before judging
            let t = events[k].0;
            while k < events.len() && events[k].0 == t {
                sum += events[k].1;
                k += 1;
            }
            if sum.abs() > accel_mm_s2 * (1.0 + 1e-9) {
                let next = events.get(k).map_or(t, |e| e.0);
                out.push(0.5 * (t + next));
            }
        }
        out
    }

    /// The span of the ramps running at `t_s` (their union), if any: the part of the path
    /// whose corners move the blended position at that instant (a centred ramp changes the
    /// position only while it runs).
    pub fn active_span(&self, t_s: f64) -> Option<(f64, f64)> {
        let first = self
            .ramps
            .partition_point(|r| r.start_s() < t_s - self.longest_s);
        let last = self.ramps.partition_point(|r| r.start_s() <= t_s);
        self.ramps[first..last]
            .iter()
            .filter(|r| r.end_s() >= t_s)
            .fold(None, |span, r| match span {
                None => Some((r.start_s(), r.end_s())),
                Some((a, b)) => Some((f64::min(a, r.start_s()), f64::max(b, r.end_s()))),
            })
    }

    /// The longest ramp, s: how far from a vertex the path may differ from it.
    pub fn longest_s(&self) -> f64 {
        self.longest_s
    }

    /// Position at `t_s`, mm: ramps that started more than the longest ramp ago have ended
    /// and add `Δv (t − centre)` (prefix sums); the few later ones are added one by one.
    pub fn position_mm(&self, t_s: f64) -> f64 {
        let ended = self
            .ramps
            .partition_point(|r| r.start_s() <= t_s - self.longest_s);
        let started = self.ramps.partition_point(|r| r.start_s() <= t_s);
        let (dv, dvc) = self.prefix[ended];
        let recent: f64 = self.ramps[ended..started]
            .iter()
            .map(|r| r.dv_mm_s * r.integral_s(t_s))
            .sum();
        self.start_mm + t_s * dv - dvc + recent
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the position as the sum over every ramp.
    fn direct(b: &CornerBlends, t: f64) -> f64 {
        b.start_mm
            + b.ramps
                .iter()
                .map(|r| r.dv_mm_s * r.integral_s(t))
                .sum::<f64>()
    }

    #[test]
    fn blends_follow_the_path_away_from_corners_within_the_limits() {
        // a zigzag with slow and fast corners
        let verts = vec![
            (0.0, 0.0),
            (1.0, 10.0),
            (1.5, 10.5),
            (2.0, 0.0),
            (3.0, 40.0),
            (4.0, 40.0),
        ];
        let a = 1000.0;
        let b = CornerBlends::new(&verts, a).unwrap();
        assert_eq!(b.active_span(2.5), None);
        let (s0, s1) = b.active_span(3.0).unwrap();
        assert!(s0 < 3.0 && s1 > 3.0);
        let dt = 1e-3;
        let p: Vec<f64> = (0..6000)
            .map(|k| b.position_mm(k as f64 * dt - 1.0))
            .collect();
        for (k, w) in p.windows(3).enumerate() {
            let acc = (w[2] - 2.0 * w[1] + w[0]) / (dt * dt);
            assert!(acc.abs() <= a * 1.0001, "{acc} at {k}");
            let t = k as f64 * dt - 1.0;
            assert!((w[0] - direct(&b, t)).abs() < 1e-9);
        }
        // away from every corner the path is exact: the middle of the last segment
        let x = b.position_mm(3.5 - 0.0);
        assert!((x - 40.0).abs() < 1e-9 || b.longest_s() > 0.5, "{x}");
        let mid = b.position_mm(2.5);
        assert!((mid - 20.0).abs() < 1e-9, "{mid}");
        // at rest before and after
        assert_eq!(b.position_mm(-5.0), 0.0);
        assert!((b.position_mm(50.0) - 40.0).abs() < 1e-9);
        // a corner departs by Δv² / (8a) at most
        let dv = (0.0f64 - 40.0).abs(); // the corner at t = 3: 40 mm/s to 0
        assert!((b.position_mm(4.0) - 40.0).abs() <= dv * dv / (8.0 * a) + 1e-9);
    }
}
