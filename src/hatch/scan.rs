//! Scanlines: the chords that parallel hatch lines cut out of a region.
//!
//! In the hatch frame `u` runs along the lines and `v` across them. Lines sit at
//! `v_j = v_min + g + j·spacing`, with the leftover `g` split evenly between the two extremes (so
//! the first and last lines are between half a spacing and a spacing from the boundary). An edge
//! crosses line `j` when `min(v_a, v_b) ≤ v_j < max(v_a, v_b)` (half-open, so vertices on a line
//! are counted consistently and every loop crosses every line an even number of times); the sorted
//! crossings of a line pair up into chords (even-odd, which the clean loops of a region satisfy).

use crate::geom::Pt;

/// One crossing of a scanline with a boundary loop.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Crossing {
    /// Loop index.
    pub loop_id: u32,
    /// Edge index: the crossing lies on the edge from vertex `edge` to vertex `edge + 1`.
    pub edge: u32,
    /// Position along the edge, 0..=1.
    pub t: f64,
    /// The point in mm.
    pub pt: Pt,
    /// Scanline index.
    pub line: u32,
    /// Walking the loop forwards from here leads to larger `v` (into the band after the line).
    pub forward_down: bool,
}

/// A chord: the part of a scanline inside the region, between two crossings.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Chord {
    /// Crossing at the smaller `u`.
    pub lo: u32,
    /// Crossing at the larger `u`.
    pub hi: u32,
}

/// The chords of one family of parallel lines.
#[derive(Debug, Clone)]
pub(crate) struct Scan {
    /// All crossings; chords refer to them by index.
    pub crossings: Vec<Crossing>,
    /// Chords of each line, sorted by `u`.
    pub lines: Vec<Vec<Chord>>,
}

/// The scan would need more lines than the limit.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TooManyLines(pub usize);

/// Cuts `loops` (closed, clean) with parallel lines at `angle_rad`, `spacing` apart.
pub(crate) fn scan(
    loops: &[Vec<Pt>],
    angle_rad: f64,
    spacing: f64,
    max_lines: usize,
) -> Result<Scan, TooManyLines> {
    let dir = Pt::new(angle_rad.cos(), angle_rad.sin());
    let normal = Pt::new(-dir.y, dir.x);
    let vs: Vec<Vec<f64>> = loops
        .iter()
        .map(|l| l.iter().map(|p| p.dot(normal)).collect())
        .collect();
    let (mut v_min, mut v_max) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vs.iter().flatten() {
        v_min = v_min.min(*v);
        v_max = v_max.max(*v);
    }
    let mut out = Scan {
        crossings: Vec::new(),
        lines: Vec::new(),
    };
    if v_max.partial_cmp(&v_min) != Some(std::cmp::Ordering::Greater) {
        return Ok(out);
    }
    let extent = v_max - v_min;
    let n_f = (extent / spacing).floor();
    if n_f > max_lines as f64 {
        return Err(TooManyLines(n_f as usize));
    }
    let n = n_f as usize;
    if n == 0 {
        return Ok(out);
    }
    let v0 = v_min + (extent - (n - 1) as f64 * spacing) / 2.0;
    let line_v = |j: usize| v0 + j as f64 * spacing;
    let mut per_line: Vec<Vec<(f64, u32)>> = vec![Vec::new(); n];
    for (li, (l, lv)) in loops.iter().zip(&vs).enumerate() {
        let m = l.len();
        for i in 0..m {
            let (a, b) = (l[i], l[(i + 1) % m]);
            let (va, vb) = (lv[i], lv[(i + 1) % m]);
            if va == vb {
                continue;
            }
            let (lo, hi) = (va.min(vb), va.max(vb));
            // first line with v ≥ lo, then every line with v < hi
            let mut j = ((lo - v0) / spacing).ceil().max(0.0) as usize;
            while j > 0 && line_v(j - 1) >= lo {
                j -= 1;
            }
            while j < n && line_v(j) < lo {
                j += 1;
            }
            let (ua, ub) = (a.dot(dir), b.dot(dir));
            while j < n && line_v(j) < hi {
                let t = ((line_v(j) - va) / (vb - va)).clamp(0.0, 1.0);
                let id = out.crossings.len() as u32;
                out.crossings.push(Crossing {
                    loop_id: li as u32,
                    edge: i as u32,
                    t,
                    pt: a.plus(b.minus(a).scale(t)),
                    line: j as u32,
                    forward_down: vb > va,
                });
                per_line[j].push((ua + (ub - ua) * t, id));
                j += 1;
            }
        }
    }
    out.lines = per_line
        .into_iter()
        .map(|mut xs| {
            xs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            xs.chunks_exact(2)
                .map(|w| Chord {
                    lo: w[0].1,
                    hi: w[1].1,
                })
                .collect()
        })
        .collect();
    Ok(out)
}

impl Scan {
    /// The end points of a chord (lo, hi).
    pub(crate) fn ends(&self, c: Chord) -> (Pt, Pt) {
        (
            self.crossings[c.lo as usize].pt,
            self.crossings[c.hi as usize].pt,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_with_hole_chords() {
        let outer = vec![
            Pt::new(0.0, 0.0),
            Pt::new(10.0, 0.0),
            Pt::new(10.0, 10.0),
            Pt::new(0.0, 10.0),
        ];
        let hole = vec![
            Pt::new(3.0, 3.0),
            Pt::new(3.0, 7.0),
            Pt::new(7.0, 7.0),
            Pt::new(7.0, 3.0),
        ];
        let s = scan(&[outer, hole], 0.0, 1.0, 1000).unwrap();
        // extent 10 → 10 lines at 0.5, 1.5, ... 9.5
        assert_eq!(s.lines.len(), 10);
        let first = s.ends(s.lines[0][0]);
        assert!((first.0.y - 0.5).abs() < 1e-12 && first.0.x.abs() < 1e-12);
        assert!((first.1.x - 10.0).abs() < 1e-12);
        // lines through the hole have two chords
        assert_eq!(s.lines[5].len(), 2);
        assert_eq!(s.lines.iter().map(Vec::len).sum::<usize>(), 10 + 4);
        for line in &s.lines {
            for c in line {
                let (a, b) = s.ends(*c);
                assert!(b.x > a.x);
            }
        }
        assert!(scan(
            &[vec![
                Pt::new(0.0, 0.0),
                Pt::new(1.0, 0.0),
                Pt::new(0.0, 1e9)
            ]],
            0.0,
            1.0,
            1000
        )
        .is_err());
    }

    #[test]
    fn rotated_lines_are_parallel_and_spaced() {
        let sq = vec![
            Pt::new(0.0, 0.0),
            Pt::new(10.0, 0.0),
            Pt::new(10.0, 10.0),
            Pt::new(0.0, 10.0),
        ];
        let a = 30f64.to_radians();
        let s = scan(&[sq], a, 0.7, 1000).unwrap();
        let n = Pt::new(-a.sin(), a.cos());
        let vs: Vec<f64> = s
            .lines
            .iter()
            .map(|l| s.crossings[l[0].lo as usize].pt.dot(n))
            .collect();
        for w in vs.windows(2) {
            assert!((w[1] - w[0] - 0.7).abs() < 1e-9);
        }
        for l in &s.lines {
            for c in l {
                let (p, q) = s.ends(*c);
                let d = q.minus(p);
                assert!((d.x * a.sin() - d.y * a.cos()).abs() < 1e-9);
            }
        }
    }
}
