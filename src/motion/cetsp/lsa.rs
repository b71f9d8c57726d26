//! The line simplification (seed 001 §III-B, §III-C-2): RDP (Algorithm 1) and VW (Algorithm 2)
//! per segment of the pattern, their union, and the half-padding-radius deduction.
//!
//! Every function returns indices into the points it was given, ascending, first and last
//! included: the LSA points are pattern points.

use super::{LsaParams, PatternPt};
use crate::geom::{point_segment_dist, Pt};
use geo::SimplifyIdx;

/// Ramer–Douglas–Peucker (Algorithm 1): the indices of the points kept for distance threshold
/// `epsilon_mm`, by geo's [`SimplifyIdx`]. The farthest point from the chord is kept when it is
/// farther than `epsilon_mm` and both halves are simplified again.
///
/// The distance is to the chord *segment* (geo's point–`Line` distance: the paper's
/// perpendicular distance wherever the foot falls on the chord): a branch that runs out and
/// back within one segment keeps its tip, which the distance to the infinite line could lose.
/// On a tie for the farthest point geo keeps the last one. geo recurses; [`lsa_indices`] calls
/// this on segments of `segment_points` (100) points, so the depth stays below that.
pub fn rdp(points: &[Pt], epsilon_mm: f64) -> Vec<usize> {
    let line: geo::LineString<f64> = points
        .iter()
        .map(|p| geo::coord! { x: p.x, y: p.y })
        .collect();
    line.simplify_idx(epsilon_mm)
}

/// Twice the area of the triangle `a b c`, mm².
fn doubled_area(a: Pt, b: Pt, c: Pt) -> f64 {
    let (u, v) = (b.minus(a), c.minus(a));
    (u.x * v.y - u.y * v.x).abs()
}

/// Visvalingam–Whyatt (Algorithm 2): the indices of the points kept for area threshold
/// `area_mm2`. While the smallest triangle formed by a point and its two remaining neighbours
/// is smaller than the threshold, its middle point is removed (the first such point on ties).
/// Quadratic, as the paper's; it runs on one segment (100 points) at a time.
pub fn vw(points: &[Pt], area_mm2: f64) -> Vec<usize> {
    let mut kept: Vec<usize> = (0..points.len()).collect();
    while kept.len() > 2 {
        let smallest = (1..kept.len() - 1)
            .map(|j| {
                let area = doubled_area(points[kept[j - 1]], points[kept[j]], points[kept[j + 1]]);
                (j, area / 2.0)
            })
            .fold(None, |best: Option<(usize, f64)>, (j, a)| match best {
                Some((_, ba)) if ba <= a => best,
                _ => Some((j, a)),
            });
        match smallest {
            Some((j, area)) if area < area_mm2 => {
                kept.remove(j);
            }
            _ => break,
        }
    }
    kept
}

/// The half-padding-radius deduction (§III-C-2) on the ascending indices `union` into `points`:
/// a point closer than `r / 2` to the previous point kept is removed, unless the pattern from
/// that point to the next candidate strays farther than `r / 2` from the chord between them
/// ("this process considers the pattern, ensuring the retention of essential points"). The
/// first and last indices are always kept. Half the radius is left for the GA's turning points
/// to move (its position mutation moves them within half the radius).
pub fn deduct_half_radius(points: &[Pt], union: &[usize], padding_radius_mm: f64) -> Vec<usize> {
    let half_mm = padding_radius_mm / 2.0;
    let (Some(&first), Some(&last)) = (union.first(), union.last()) else {
        return Vec::new();
    };
    let mut kept = vec![first];
    for w in union.windows(2).skip(1) {
        let (candidate, next) = (w[0], w[1]);
        let prev = kept[kept.len() - 1];
        let close = points[prev].dist(points[candidate]) < half_mm;
        let (a, b) = (points[prev], points[next]);
        let pattern_near = || {
            points[prev..=next]
                .iter()
                .all(|&p| point_segment_dist(p, a, b) <= half_mm)
        };
        if !(close && pattern_near()) {
            kept.push(candidate);
        }
    }
    if last != first {
        kept.push(last);
    }
    kept
}

/// The LSA points of a pattern (§III-C-2): RDP and VW on every segment of
/// `params.segment_points` points (consecutive segments share their end point), their union,
/// then [`deduct_half_radius`]. Indices into `pattern`, ascending.
pub fn lsa_indices(pattern: &[PatternPt], params: &LsaParams) -> Vec<usize> {
    let points: Vec<Pt> = pattern.iter().map(|p| p.at).collect();
    let n = points.len();
    if n <= 2 {
        return (0..n).collect();
    }
    let step = params.segment_points.max(2) - 1;
    let mut in_union = vec![false; n];
    let mut start = 0;
    while start < n - 1 {
        let end = (start + step).min(n - 1);
        let segment = &points[start..=end];
        for i in rdp(segment, params.rdp_epsilon_mm)
            .into_iter()
            .chain(vw(segment, params.vw_area_mm2))
        {
            in_union[start + i] = true;
        }
        start = end;
    }
    let union: Vec<usize> = (0..n).filter(|&i| in_union[i]).collect();
    deduct_half_radius(&points, &union, params.padding_radius_mm)
}
