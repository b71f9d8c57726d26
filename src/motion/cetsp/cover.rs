//! The two constraints of seed 001 (§III-A, §III-C-4), evaluated on a route:
//!
//! * **coverage**: the share of the marked pattern (sampled at [`COVER_STEP_MM`]) within the
//!   padding radius of the route polyline, i.e. inside the route offset by the radius (the
//!   paper's clipper offset, Fig. 5). Each sample first tries the route's leg at the sample's
//!   time and its neighbours, then a grid of the legs (cells of one radius);
//! * **within-radius value**: the share of the tool's marked time during which the tool lies
//!   within the radius of the stage, `|tool(t) − route.position(t)| ≤ r` (the paper: the share
//!   of the pattern before the first point out of bound, Fig. 6). Sampled at every knot and at
//!   [`WITHIN_STEP_S`]; a step counts when both its ends are within.

use super::{pattern, TimedRoute, ToolKnot};
use crate::geom::{BBox, Pt};

/// Spacing of the pattern samples the coverage checks, mm (half the paper's 1 mm resolution).
pub const COVER_STEP_MM: f64 = 0.5;

/// Largest time step of the within-radius samples, s (a tool at 1,000 mm/s moves 2 mm).
pub const WITHIN_STEP_S: f64 = 2e-3;

/// Distance slack of both checks, mm (float noise on points exactly at the radius).
const SLACK_MM: f64 = 1e-9;

/// The samples both constraints are checked on, for one tool path and radius.
#[derive(Debug, Clone)]
pub struct Coverage {
    radius_mm: f64,
    /// Marked pattern samples, in marking order, and the tool time at each.
    cover: Vec<(f64, Pt)>,
    /// Within-radius samples: time and tool position, in time order.
    within: Vec<(f64, Pt)>,
    /// Marked time from sample `k` to `k + 1` (0 where the laser is off in between), s.
    weight_s: Vec<f64>,
}

impl Coverage {
    /// The samples of a tool path for padding radius `radius_mm`.
    pub fn new(tool: &[ToolKnot], radius_mm: f64) -> Self {
        let cover = pattern(tool, COVER_STEP_MM)
            .into_iter()
            .map(|p| (p.t_s, p.at))
            .collect();
        let (mut within, mut weight_s) = (Vec::new(), Vec::new());
        for w in tool.windows(2) {
            let (a, b) = (w[0], w[1]);
            if !a.marking {
                continue;
            }
            let span_s = (b.t_s - a.t_s).max(0.0);
            let steps = (span_s / WITHIN_STEP_S).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let f = k as f64 / steps as f64;
                within.push((a.t_s + span_s * f, a.at.plus(b.at.minus(a.at).scale(f))));
                weight_s.push(if k < steps {
                    span_s / steps as f64
                } else {
                    0.0
                });
            }
        }
        Self {
            radius_mm,
            cover,
            within,
            weight_s,
        }
    }

    /// The padding radius, mm.
    pub fn radius_mm(&self) -> f64 {
        self.radius_mm
    }

    /// Share of the marked pattern samples within the radius of the route polyline (1 for an
    /// empty pattern, 0 for an empty route).
    pub fn coverage(&self, route: &TimedRoute) -> f64 {
        if self.cover.is_empty() {
            return 1.0;
        }
        let pts = &route.points;
        if pts.is_empty() {
            return 0.0;
        }
        let r2 = (self.radius_mm + SLACK_MM).powi(2);
        let grid = LegGrid::new(pts, self.radius_mm);
        let mut cursor = 0;
        let covered = self
            .cover
            .iter()
            .filter(|&&(t_s, p)| {
                cursor = advance(&route.times_s, cursor, t_s);
                let local = cursor.saturating_sub(1)..(cursor + 2).min(pts.len());
                let near = |i: usize| leg_dist2(p, pts, i) <= r2;
                local.clone().any(near) || grid.any_near(p, |i| !local.contains(&i) && near(i))
            })
            .count();
        covered as f64 / self.cover.len() as f64
    }

    /// Share of the tool's marked time during which the tool is within the radius of the stage
    /// (1 when nothing is marked).
    pub fn within_radius(&self, route: &TimedRoute) -> f64 {
        let total_s: f64 = self.weight_s.iter().sum();
        if total_s <= 0.0 {
            return 1.0;
        }
        let r2 = (self.radius_mm + SLACK_MM).powi(2);
        let mut cursor = 0;
        let inside: Vec<bool> = self
            .within
            .iter()
            .map(|&(t_s, p)| {
                cursor = advance(&route.times_s, cursor, t_s);
                stage_at(route, cursor, t_s).dist2(p) <= r2
            })
            .collect();
        let within_s: f64 = (0..inside.len().saturating_sub(1))
            .filter(|&k| inside[k] && inside[k + 1])
            .map(|k| self.weight_s[k])
            .sum();
        (within_s / total_s).min(1.0)
    }
}

/// The index of the last turning point whose time is ≤ `t_s` (0 before the first), walking
/// forward from `from` (the queries come in time order).
fn advance(times_s: &[f64], from: usize, t_s: f64) -> usize {
    let mut k = from;
    while k + 1 < times_s.len() && times_s[k + 1] <= t_s {
        k += 1;
    }
    k
}

/// The stage position at `t_s`, with `k` = [`advance`]'s index for `t_s`.
fn stage_at(route: &TimedRoute, k: usize, t_s: f64) -> Pt {
    let n = route.points.len().min(route.times_s.len());
    if n == 0 {
        return Pt::default();
    }
    if k + 1 >= n || t_s <= route.times_s[0] {
        return route.points[k.min(n - 1)];
    }
    route.between(k, t_s)
}

/// Squared distance from `p` to leg `i` of the polyline `pts` (from point `i` to `i + 1`; the
/// last point alone for the last index).
fn leg_dist2(p: Pt, pts: &[Pt], i: usize) -> f64 {
    let a = pts[i];
    let Some(&b) = pts.get(i + 1) else {
        return p.dist2(a);
    };
    let ab = b.minus(a);
    let len2 = ab.dot(ab);
    let f = if len2 > 0.0 {
        (p.minus(a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.dist2(a.plus(ab.scale(f)))
}

/// The legs of a polyline bucketed by the square cells (one radius wide) their bounding boxes
/// touch: a leg within the radius of a point touches the point's cell or one of its 8
/// neighbours.
struct LegGrid {
    origin: Pt,
    cell_mm: f64,
    cols: usize,
    rows: usize,
    cells: Vec<Vec<usize>>,
}

impl LegGrid {
    fn new(pts: &[Pt], radius_mm: f64) -> Self {
        let b = BBox::of(pts);
        let cell_mm = radius_mm.max(f64::MIN_POSITIVE);
        let cols = ((b.width() / cell_mm).floor() as usize) + 1;
        let rows = ((b.height() / cell_mm).floor() as usize) + 1;
        let mut grid = Self {
            origin: Pt::new(b.min_x, b.min_y),
            cell_mm,
            cols,
            rows,
            cells: vec![Vec::new(); cols * rows],
        };
        for i in 0..pts.len() {
            let end = pts.get(i + 1).copied().unwrap_or(pts[i]);
            let (c0, r0) = grid.cell(pts[i]);
            let (c1, r1) = grid.cell(end);
            for r in r0.min(r1)..=r0.max(r1) {
                for c in c0.min(c1)..=c0.max(c1) {
                    grid.cells[r * cols + c].push(i);
                }
            }
        }
        grid
    }

    /// The cell of a point on the polyline (clamped into the grid).
    fn cell(&self, p: Pt) -> (usize, usize) {
        let c = ((p.x - self.origin.x) / self.cell_mm).floor().max(0.0) as usize;
        let r = ((p.y - self.origin.y) / self.cell_mm).floor().max(0.0) as usize;
        (c.min(self.cols - 1), r.min(self.rows - 1))
    }

    /// True when `test` holds for a leg bucketed in `p`'s cell or a neighbour.
    fn any_near(&self, p: Pt, mut test: impl FnMut(usize) -> bool) -> bool {
        let c = ((p.x - self.origin.x) / self.cell_mm).floor();
        let r = ((p.y - self.origin.y) / self.cell_mm).floor();
        if c < -1.0 || r < -1.0 || c > self.cols as f64 || r > self.rows as f64 {
            return false;
        }
        let (c, r) = (c as i64, r as i64);
        for rr in (r - 1).max(0)..=(r + 1).min(self.rows as i64 - 1) {
            for cc in (c - 1).max(0)..=(c + 1).min(self.cols as i64 - 1) {
                if self.cells[rr as usize * self.cols + cc as usize]
                    .iter()
                    .any(|&i| test(i))
                {
                    return true;
                }
            }
        }
        false
    }
}
