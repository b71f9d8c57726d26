//! Candidate neighbours: which nodes a move may connect.

use super::problem::{Node, PathProblem};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};

/// A uniform grid over the nodes' end points, for candidate pools on large instances.
struct EndGrid {
    cell_mm: f64,
    /// Rings beyond this hold nothing.
    span: i64,
    cells: FxHashMap<(i64, i64), Vec<usize>>,
}

impl EndGrid {
    fn new(nodes: &[Node]) -> Self {
        let mut b = crate::geom::BBox::EMPTY;
        for q in nodes {
            b.extend(q.s);
            b.extend(q.e);
        }
        // about four nodes per cell
        let cell_mm = ((b.width().max(1e-3) * b.height().max(1e-3)) / nodes.len().max(1) as f64
            * 4.0)
            .sqrt()
            .max(1e-3);
        let span = ((b.width().max(b.height())) / cell_mm).ceil() as i64 + 2;
        let mut g = EndGrid {
            cell_mm,
            span,
            cells: FxHashMap::default(),
        };
        for (i, q) in nodes.iter().enumerate() {
            let (ks, ke) = (g.key(q.s), g.key(q.e));
            g.cells.entry(ks).or_default().push(i);
            if ke != ks {
                g.cells.entry(ke).or_default().push(i);
            }
        }
        g
    }
    fn key(&self, p: Pt) -> (i64, i64) {
        (
            (p.x / self.cell_mm).floor() as i64,
            (p.y / self.cell_mm).floor() as i64,
        )
    }
    /// At least `want` other nodes found in growing rings around both ends of `a` (one ring more
    /// once enough are found, so that nearer nodes in the corners are not missed).
    fn around(&self, a: &Node, me: usize, want: usize) -> Vec<usize> {
        let mut seen = FxHashSet::default();
        let mut out = Vec::new();
        let centres = [self.key(a.s), self.key(a.e)];
        let mut extra = None;
        for ring in 0i64.. {
            for &(cx, cy) in &centres {
                for dx in -ring..=ring {
                    for dy in -ring..=ring {
                        if dx.abs() != ring && dy.abs() != ring {
                            continue;
                        }
                        if let Some(v) = self.cells.get(&(cx + dx, cy + dy)) {
                            for &j in v {
                                if j != me && seen.insert(j) {
                                    out.push(j);
                                }
                            }
                        }
                    }
                }
            }
            match extra {
                Some(stop) if ring >= stop => break,
                None if out.len() >= want => extra = Some(ring + 1),
                _ => {}
            }
            if ring > self.span {
                break;
            }
        }
        out
    }
}

/// Nodes whose lists are built between two polls of the cancel token (10⁵ nodes take about a
/// second on one core).
const POLL_EVERY: usize = 1024;

/// The quadrant search looks at the nearest this many candidates of a node only.
const POOL: usize = 96;

/// Candidate neighbours of every node: the `k` nearest by the shortest distance between end
/// points (so that long open strokes find the nodes near either end), plus the two nearest in
/// each quadrant around each end point (so that clusters of coincident points do not hide the
/// rest of the instance). Deterministic (ties by index) on any number of threads; polls `ctx`.
pub fn neighbour_lists(
    prob: &PathProblem,
    k: usize,
    ctx: &JobCtx,
) -> Result<Vec<Vec<usize>>, Cancelled> {
    let n = prob.nodes.len();
    let k = k.min(n.saturating_sub(1));
    let grid = (n > 4 * POOL).then(|| EndGrid::new(&prob.nodes));
    (0..n)
        .into_par_iter()
        .map(|i| {
            if i % POLL_EVERY == 0 {
                ctx.check()?;
            }
            Ok(node_list(prob, grid.as_ref(), i, k))
        })
        .collect()
}

/// Shortest distance between the end points of two nodes, squared.
fn near(a: &Node, b: &Node) -> f64 {
    a.s.dist2(b.s)
        .min(a.s.dist2(b.e))
        .min(a.e.dist2(b.s))
        .min(a.e.dist2(b.e))
}

/// Node `i`'s list (see [`neighbour_lists`]).
fn node_list(prob: &PathProblem, grid: Option<&EndGrid>, i: usize, k: usize) -> Vec<usize> {
    let n = prob.nodes.len();
    let a = &prob.nodes[i];
    let pool: Vec<usize> = match grid {
        Some(g) => g.around(a, i, POOL),
        None => (0..n).filter(|&j| j != i).collect(),
    };
    let mut c: Vec<(f64, usize)> = pool
        .into_iter()
        .map(|j| (near(a, &prob.nodes[j]), j))
        .collect();
    let cmp = |x: &(f64, usize), y: &(f64, usize)| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1));
    if c.len() > POOL {
        c.select_nth_unstable_by(POOL, cmp);
        c.truncate(POOL);
    }
    c.sort_by(cmp);
    let mut out: Vec<usize> = c.iter().take(k).map(|x| x.1).collect();
    let origins: &[Pt] = if a.s == a.e {
        &[a.s][..]
    } else {
        &[a.s, a.e][..]
    };
    for &o in origins {
        let mut per_quadrant = [0usize; 4];
        for &(_, j) in &c {
            let b = &prob.nodes[j];
            let q = b.s.plus(b.e).scale(0.5).minus(o);
            if q.x == 0.0 && q.y == 0.0 {
                continue;
            }
            let quad = usize::from(q.x < 0.0) * 2 + usize::from(q.y < 0.0);
            if per_quadrant[quad] < 2 {
                per_quadrant[quad] += 1;
                if !out.contains(&j) {
                    out.push(j);
                }
            }
            if per_quadrant.iter().all(|&m| m >= 2) {
                break;
            }
        }
    }
    out
}
