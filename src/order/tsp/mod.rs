//! Open-path TSP machinery shared by HHA and HGA: construction, local search, exact DP.
//!
//! A node has a start and an end point (equal for a point-like node; the two ends of an open
//! geometry otherwise, swapped when the node is *flipped*) and a projection `p` on the sweep axis.
//! Travelling from node `i` to node `j` costs
//!
//! `c(i, j) = ‖end(i) − start(j)‖ + λ · max(0, p_i − p_j)`,
//!
//! the idle distance plus a directional penalty on moving backwards along the sweep (λ = 0: plain
//! distance). Reversing a run of nodes (flipping its open geometries) leaves its inner distances
//! unchanged and changes its inner penalties by exactly `λ (p_last − p_first)`, so 2-opt and
//! Or-opt moves are evaluated in O(1). The first node may be fixed (a fixed start); the last node
//! may be fixed (a fixed end) or free (an open path with a virtual end node of zero cost).

use super::cost::TravelCost;
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};

/// A node of the path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Start point (unflipped).
    pub s: Pt,
    /// End point (unflipped).
    pub e: Pt,
    /// Projection on the sweep axis, mm.
    pub p: f64,
}

impl Node {
    /// A point-like node.
    pub fn point(q: Pt, p: f64) -> Node {
        Node { s: q, e: q, p }
    }
}

/// A path over nodes with optional fixed ends and a directional weight λ.
///
/// Nodes that are not flippable must have equal start and end points (point-like nodes).
#[derive(Debug, Clone)]
pub struct PathProblem {
    /// The nodes.
    pub nodes: Vec<Node>,
    /// Directional penalty weight λ.
    pub lambda: f64,
    /// The node in position 0 stays first.
    pub fixed_first: bool,
    /// The node in the last position stays last.
    pub fixed_last: bool,
    /// Nodes that may be flipped (open geometries); others keep their orientation.
    pub flippable: Vec<bool>,
    /// Cluster (scan field) of each node, or empty for none; [`NO_CLUSTER`] marks a node outside.
    pub cluster: Vec<u32>,
    /// Added to every edge between two different clusters (seed 000 Algorithm 1).
    pub cluster_penalty: f64,
    /// What travelling between two points costs (Euclidean distance unless set).
    pub metric: TravelCost,
}

/// Cluster of a node that belongs to none (e.g. a start point): its edges carry no penalty.
pub const NO_CLUSTER: u32 = u32::MAX;

/// A tour: node order plus orientation per node.
#[derive(Debug, Clone, PartialEq)]
pub struct Tour {
    /// Node indices in path order.
    pub order: Vec<usize>,
    /// Orientation per node (indexed by node).
    pub flipped: Vec<bool>,
}

impl PathProblem {
    /// A problem over point-like nodes.
    pub fn points(points: &[Pt], proj: &[f64], lambda: f64) -> PathProblem {
        PathProblem {
            nodes: points
                .iter()
                .zip(proj)
                .map(|(&q, &p)| Node::point(q, p))
                .collect(),
            lambda,
            fixed_first: false,
            fixed_last: false,
            flippable: vec![false; points.len()],
            cluster: Vec::new(),
            cluster_penalty: 0.0,
            metric: TravelCost::Distance,
        }
    }
    fn start(&self, t: &Tour, i: usize) -> Pt {
        if t.flipped[i] {
            self.nodes[i].e
        } else {
            self.nodes[i].s
        }
    }
    fn end(&self, t: &Tour, i: usize) -> Pt {
        if t.flipped[i] {
            self.nodes[i].s
        } else {
            self.nodes[i].e
        }
    }
    /// Cost of the edge `i → j` with the tour's orientations.
    pub fn cost(&self, t: &Tour, i: usize, j: usize) -> f64 {
        self.metric.between(self.end(t, i), self.start(t, j))
            + self.lambda * (self.nodes[i].p - self.nodes[j].p).max(0.0)
            + self.cross(i, j)
    }
    /// The cluster penalty of an edge (symmetric, so reversals leave it unchanged).
    fn cross(&self, i: usize, j: usize) -> f64 {
        match (self.cluster.get(i), self.cluster.get(j)) {
            (Some(&a), Some(&b)) if a != b && a != NO_CLUSTER && b != NO_CLUSTER => {
                self.cluster_penalty
            }
            _ => 0.0,
        }
    }
    /// Cost of `i → j` when `i` has orientation `fi` and `j` has `fj`.
    fn cost_o(&self, i: usize, fi: bool, j: usize, fj: bool) -> f64 {
        let a = if fi { self.nodes[i].s } else { self.nodes[i].e };
        let b = if fj { self.nodes[j].e } else { self.nodes[j].s };
        self.metric.between(a, b)
            + self.lambda * (self.nodes[i].p - self.nodes[j].p).max(0.0)
            + self.cross(i, j)
    }
    /// Total cost of a tour.
    pub fn tour_cost(&self, t: &Tour) -> f64 {
        t.order.windows(2).map(|w| self.cost(t, w[0], w[1])).sum()
    }
    /// Travel cost of a tour under the metric (λ and cluster penalties ignored).
    pub fn tour_distance(&self, t: &Tour) -> f64 {
        t.order
            .windows(2)
            .map(|w| self.metric.between(self.end(t, w[0]), self.start(t, w[1])))
            .sum()
    }
}

/// Greedy construction ("path cheapest arc"): from the first node, repeatedly the cheapest arc to
/// an unvisited node under `arc(from, to)`; a fixed last node is appended at the end.
pub fn cheapest_arc(
    n: usize,
    first: usize,
    last: Option<usize>,
    arc: &dyn Fn(usize, usize) -> f64,
) -> Vec<usize> {
    let mut used = vec![false; n];
    let mut order = Vec::with_capacity(n);
    used[first] = true;
    order.push(first);
    if let Some(l) = last {
        used[l] = true;
    }
    let mut cur = first;
    let remaining = n - 1 - usize::from(last.is_some_and(|l| l != first));
    for _ in 0..remaining {
        let mut best = (f64::INFINITY, usize::MAX);
        for (j, _) in used.iter().enumerate().filter(|(_, u)| !**u) {
            let c = arc(cur, j);
            if c < best.0 {
                best = (c, j);
            }
        }
        if best.1 == usize::MAX {
            break;
        }
        used[best.1] = true;
        order.push(best.1);
        cur = best.1;
    }
    if let Some(l) = last {
        if l != first {
            order.push(l);
        }
    }
    order
}

/// Exact open path over up to 14 point nodes (Held–Karp): fixed first node, fixed or free last.
pub fn exact_path(
    dist: &dyn Fn(usize, usize) -> f64,
    n: usize,
    first: usize,
    last: Option<usize>,
) -> Vec<usize> {
    if n <= 2 {
        let mut v = vec![first];
        v.extend((0..n).filter(|&k| k != first));
        return v;
    }
    // DP over subsets of the other nodes
    let others: Vec<usize> = (0..n).filter(|&k| k != first).collect();
    let m = others.len();
    let full = 1usize << m;
    let mut dp = vec![f64::INFINITY; full * m];
    let mut from = vec![usize::MAX; full * m];
    for (k, &o) in others.iter().enumerate() {
        dp[(1 << k) * m + k] = dist(first, o);
    }
    for mask in 1..full {
        for k in 0..m {
            let v = dp[mask * m + k];
            if mask & (1 << k) == 0 || !v.is_finite() {
                continue;
            }
            if let Some(l) = last {
                // the fixed last node may only close the path
                if others[k] == l && mask != full - 1 {
                    continue;
                }
            }
            for j in 0..m {
                if mask & (1 << j) != 0 {
                    continue;
                }
                let nm = mask | (1 << j);
                let c = v + dist(others[k], others[j]);
                if c < dp[nm * m + j] {
                    dp[nm * m + j] = c;
                    from[nm * m + j] = k;
                }
            }
        }
    }
    let end_k = match last.and_then(|l| others.iter().position(|&o| o == l)) {
        Some(k) => k,
        None => (0..m)
            .min_by(|&a, &b| dp[(full - 1) * m + a].total_cmp(&dp[(full - 1) * m + b]))
            .unwrap_or(0),
    };
    let mut path = Vec::with_capacity(n);
    let (mut mask, mut k) = (full - 1, end_k);
    while k != usize::MAX {
        path.push(others[k]);
        let prev = from[mask * m + k];
        mask &= !(1 << k);
        k = prev;
    }
    path.push(first);
    path.reverse();
    path
}

/// A uniform grid over the nodes' end points, for candidate pools on large instances.
struct EndGrid {
    cell_mm: f64,
    /// Rings beyond this hold nothing.
    span: i64,
    cells: std::collections::HashMap<(i64, i64), Vec<usize>>,
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
            cells: std::collections::HashMap::new(),
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
        let mut seen = std::collections::HashSet::new();
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

/// Candidate neighbours of every node: the `k` nearest by the shortest distance between end
/// points (so that long open strokes find the nodes near either end), plus the two nearest in
/// each quadrant around each end point (so that clusters of coincident points do not hide the
/// rest of the instance). Deterministic: ties by index.
pub fn neighbour_lists(prob: &PathProblem, k: usize) -> Vec<Vec<usize>> {
    let n = prob.nodes.len();
    let k = k.min(n.saturating_sub(1));
    let near = |a: &Node, b: &Node| -> f64 {
        a.s.dist2(b.s)
            .min(a.s.dist2(b.e))
            .min(a.e.dist2(b.s))
            .min(a.e.dist2(b.e))
    };
    // the quadrant search looks at the nearest POOL candidates only
    const POOL: usize = 96;
    let grid = (n > 4 * POOL).then(|| EndGrid::new(&prob.nodes));
    (0..n)
        .map(|i| {
            let a = &prob.nodes[i];
            let pool: Vec<usize> = match &grid {
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
        })
        .collect()
}

/// Options of [`local_search`].
#[derive(Debug, Clone, Copy)]
pub struct LsOptions {
    /// Neighbour list length.
    pub neighbours: usize,
    /// Longest chain moved by Or-opt.
    pub or_max: usize,
}

impl Default for LsOptions {
    fn default() -> Self {
        Self {
            neighbours: 16,
            or_max: 3,
        }
    }
}

const IMPROVE_EPS: f64 = 1e-9;

/// 2-opt and Or-opt with neighbour lists and don't-look bits, respecting fixed ends. Improves
/// `tour` in place; returns the new cost. Cancellation is checked every few hundred moves.
pub fn local_search(
    prob: &PathProblem,
    tour: &mut Tour,
    opts: LsOptions,
    ctx: &JobCtx,
) -> Result<f64, Cancelled> {
    LocalSearch::new(prob, opts).run(tour, None, ctx)
}

/// A local search with its neighbour lists built once, for repeated runs (iterated local search,
/// the GA's chromosome enhancement).
pub struct LocalSearch<'a> {
    prob: &'a PathProblem,
    nbr: std::borrow::Cow<'a, [Vec<usize>]>,
    opts: LsOptions,
}

impl<'a> LocalSearch<'a> {
    /// Builds the neighbour lists.
    pub fn new(prob: &'a PathProblem, opts: LsOptions) -> Self {
        Self {
            prob,
            nbr: std::borrow::Cow::Owned(neighbour_lists(prob, opts.neighbours)),
            opts,
        }
    }

    /// A local search with neighbour lists supplied by the caller (shared between runs whose nodes
    /// keep their neighbourhoods, e.g. the GA's chromosomes).
    pub fn with_neighbours(prob: &'a PathProblem, nbr: &'a [Vec<usize>], opts: LsOptions) -> Self {
        Self {
            prob,
            nbr: std::borrow::Cow::Borrowed(nbr),
            opts,
        }
    }

    /// Runs 2-opt/Or-opt to a local optimum, starting from the nodes in `start` (all when `None`).
    pub fn run(
        &self,
        tour: &mut Tour,
        start: Option<&[usize]>,
        ctx: &JobCtx,
    ) -> Result<f64, Cancelled> {
        let prob = self.prob;
        let n = tour.order.len();
        if n < 3 {
            return Ok(prob.tour_cost(tour));
        }
        let mut pos = vec![0usize; prob.nodes.len()];
        for (k, &v) in tour.order.iter().enumerate() {
            pos[v] = k;
        }
        // movable positions: lo..=hi
        let lo = usize::from(prob.fixed_first);
        let hi = if prob.fixed_last { n - 2 } else { n - 1 };
        if lo > hi {
            return Ok(prob.tour_cost(tour));
        }
        let mut dont_look = vec![false; prob.nodes.len()];
        let mut queue: std::collections::VecDeque<usize> = match start {
            Some(s) => s.iter().copied().collect(),
            None => tour.order.iter().copied().collect(),
        };
        let mut steps = 0usize;
        while let Some(a) = queue.pop_front() {
            if dont_look[a] {
                continue;
            }
            if steps % 32 == 0 {
                ctx.check()?;
            }
            steps += 1;
            let improved = try_two_opt(prob, tour, &mut pos, &self.nbr, a, lo, hi).or_else(|| {
                try_or_opt(prob, tour, &mut pos, &self.nbr, a, lo, hi, self.opts.or_max)
            });
            match improved {
                Some(touched) => {
                    for v in touched {
                        dont_look[v] = false;
                        queue.push_back(v);
                    }
                }
                None => dont_look[a] = true,
            }
        }
        Ok(prob.tour_cost(tour))
    }

    /// Iterated local search: local optimum, then `kicks` times a local double bridge (two short
    /// consecutive segments swapped) followed by local search around it, keeping the better tour.
    /// Deterministic for a given `seed`.
    pub fn iterated(
        &self,
        tour: &mut Tour,
        kicks: usize,
        seed: u64,
        ctx: &JobCtx,
    ) -> Result<f64, Cancelled> {
        use rand::{Rng, SeedableRng};
        let mut best = self.run(tour, None, ctx)?;
        let n = tour.order.len();
        let lo = usize::from(self.prob.fixed_first);
        let hi_excl = if self.prob.fixed_last { n - 1 } else { n };
        if hi_excl < lo + 4 {
            return Ok(best);
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        for k in 0..kicks {
            if k % 64 == 0 {
                ctx.check()?;
            }
            let span = hi_excl - lo;
            let max_len = (span / 3).clamp(1, 30);
            let (l1, l2) = (rng.random_range(1..=max_len), rng.random_range(1..=max_len));
            if l1 + l2 > span {
                continue;
            }
            let a = rng.random_range(lo..=hi_excl - (l1 + l2));
            let (b, c) = (a + l1, a + l1 + l2);
            // double bridge, kept local: … [a,b) [b,c) … → … [b,c) [a,b) …
            let mut trial = tour.clone();
            let mut seg: Vec<usize> = Vec::with_capacity(c - a);
            seg.extend_from_slice(&tour.order[b..c]);
            seg.extend_from_slice(&tour.order[a..b]);
            trial.order[a..c].copy_from_slice(&seg);
            let touched: Vec<usize> = [
                a.saturating_sub(1),
                a,
                a + l2 - 1,
                a + l2,
                c - 1,
                c.min(n - 1),
            ]
            .into_iter()
            .map(|q| trial.order[q])
            .collect();
            let cost = self.run(&mut trial, Some(&touched), ctx)?;
            if cost < best - IMPROVE_EPS {
                best = cost;
                *tour = trial;
            }
        }
        Ok(best)
    }
}

/// Cost of the edge into position `k` (from `k−1`), 0 at the start.
fn edge_in(prob: &PathProblem, t: &Tour, k: usize) -> f64 {
    if k == 0 {
        0.0
    } else {
        prob.cost(t, t.order[k - 1], t.order[k])
    }
}

/// Reverses positions `i..=j`, flipping flippable nodes; updates `pos`.
fn reverse(prob: &PathProblem, t: &mut Tour, pos: &mut [usize], i: usize, j: usize) {
    t.order[i..=j].reverse();
    for k in i..=j {
        let v = t.order[k];
        pos[v] = k;
        if prob.flippable[v] {
            t.flipped[v] = !t.flipped[v];
        }
    }
}

/// Change of cost from reversing positions `i..=j` (with flips).
fn reverse_delta(prob: &PathProblem, t: &Tour, i: usize, j: usize) -> f64 {
    let n = t.order.len();
    let (a, b) = (t.order[i], t.order[j]);
    let fa = t.flipped[a] ^ prob.flippable[a];
    let fb = t.flipped[b] ^ prob.flippable[b];
    let mut d = prob.lambda * (prob.nodes[b].p - prob.nodes[a].p);
    // inner distances change only where a node is not flippable (its ends differ per direction
    // only when flippable; point-like nodes have equal ends), so they are unchanged
    if i > 0 {
        let p = t.order[i - 1];
        d += prob.cost_o(p, t.flipped[p], b, fb) - prob.cost(t, p, a);
    }
    if j + 1 < n {
        let q = t.order[j + 1];
        d += prob.cost_o(a, fa, q, t.flipped[q]) - prob.cost(t, b, q);
    }
    d
}

fn try_two_opt(
    prob: &PathProblem,
    t: &mut Tour,
    pos: &mut [usize],
    nbr: &[Vec<usize>],
    a: usize,
    lo: usize,
    hi: usize,
) -> Option<Vec<usize>> {
    let i = pos[a];
    for &v in &nbr[a] {
        let j = pos[v];
        // new edge a → v: reverse (i+1 ..= j) when v lies after a
        if j > i && i + 1 >= lo && j <= hi {
            let d = reverse_delta(prob, t, i + 1, j);
            if d < -IMPROVE_EPS {
                let touched = touched_around(t, i, j + 1);
                reverse(prob, t, pos, i + 1, j);
                return Some(touched);
            }
        }
        // new edge v → a: reverse (j ..= i−1) when v lies before a
        if j < i && j >= lo && i <= hi + 1 {
            let d = reverse_delta(prob, t, j, i - 1);
            if d < -IMPROVE_EPS {
                let touched = touched_around(t, j.saturating_sub(1), i);
                reverse(prob, t, pos, j, i - 1);
                return Some(touched);
            }
        }
    }
    None
}

fn touched_around(t: &Tour, i: usize, j: usize) -> Vec<usize> {
    let n = t.order.len();
    [i, i + 1, j.saturating_sub(1), j]
        .into_iter()
        .filter(|&k| k < n)
        .map(|k| t.order[k])
        .collect()
}

/// Moves a chain of 1..=max nodes starting at `a` to sit next to one of `a`'s neighbours,
/// in either orientation, when that lowers the cost.
#[allow(clippy::too_many_arguments)]
fn try_or_opt(
    prob: &PathProblem,
    t: &mut Tour,
    pos: &mut [usize],
    nbr: &[Vec<usize>],
    a: usize,
    lo: usize,
    hi: usize,
    max: usize,
) -> Option<Vec<usize>> {
    let n = t.order.len();
    let i = pos[a];
    for len in 1..=max {
        let j = i + len - 1; // chain = positions i..=j
        if i < lo || j > hi || j >= n {
            break;
        }
        let (first, last) = (t.order[i], t.order[j]);
        // removal gain
        let before = if i > 0 { Some(t.order[i - 1]) } else { None };
        let after = if j + 1 < n {
            Some(t.order[j + 1])
        } else {
            None
        };
        let mut remove = -edge_in(prob, t, i)
            - if j + 1 < n {
                edge_in(prob, t, j + 1)
            } else {
                0.0
            };
        if let (Some(p), Some(q)) = (before, after) {
            remove += prob.cost(t, p, q);
        }
        for &v in &nbr[a] {
            let k = pos[v];
            if k >= i && k <= j {
                continue;
            }
            // insert between positions (k, k+1) or (k−1, k)
            for (x, y) in [(Some(k), k + 1), (k.checked_sub(1), k)] {
                // x = position of the node before the chain, y = position of the node after it
                let xb = x;
                let yb = if y < n { Some(y) } else { None };
                // skip insertions touching the chain itself
                if xb.is_some_and(|x| x >= i.saturating_sub(1) && x <= j)
                    || yb.is_some_and(|y| y >= i && y <= j + 1)
                {
                    continue;
                }
                // fixed ends: nothing before position lo, nothing after hi
                let too_early = match xb {
                    None => lo > 0,
                    Some(x) => x + 1 < lo,
                };
                if too_early || yb.is_some_and(|y| y > hi + 1) {
                    continue;
                }
                if yb.is_none() && prob.fixed_last {
                    continue;
                }
                let xn = xb.map(|x| t.order[x]);
                let yn = yb.map(|y| t.order[y]);
                let old = match (xn, yn) {
                    (Some(p), Some(q)) => prob.cost(t, p, q),
                    _ => 0.0,
                };
                for rev in [false, true] {
                    let (h, hf, l, lf) = if rev {
                        let hf = t.flipped[last] ^ prob.flippable[last];
                        let lf = t.flipped[first] ^ prob.flippable[first];
                        (last, hf, first, lf)
                    } else {
                        (first, t.flipped[first], last, t.flipped[last])
                    };
                    let mut add = -old;
                    if let Some(p) = xn {
                        add += prob.cost_o(p, t.flipped[p], h, hf);
                    }
                    if let Some(q) = yn {
                        add += prob.cost_o(l, lf, q, t.flipped[q]);
                    }
                    if rev {
                        add += prob.lambda * (prob.nodes[last].p - prob.nodes[first].p);
                    }
                    if remove + add < -IMPROVE_EPS {
                        let mut touched: Vec<usize> = vec![first, last];
                        touched.extend(before);
                        touched.extend(after);
                        touched.extend(xn);
                        touched.extend(yn);
                        apply_or(prob, t, pos, i, j, xb, rev);
                        return Some(touched);
                    }
                }
            }
        }
    }
    None
}

/// Moves the chain at positions `i..=j` to after position `x` (before position 0 when `None`).
fn apply_or(
    prob: &PathProblem,
    t: &mut Tour,
    pos: &mut [usize],
    i: usize,
    j: usize,
    x: Option<usize>,
    rev: bool,
) {
    let mut chain: Vec<usize> = t.order.drain(i..=j).collect();
    if rev {
        chain.reverse();
        for &v in &chain {
            if prob.flippable[v] {
                t.flipped[v] = !t.flipped[v];
            }
        }
    }
    let at = match x {
        None => 0,
        Some(x) if x < i => x + 1,
        Some(x) => x + 1 - chain.len(),
    };
    t.order.splice(at..at, chain);
    for (k, &v) in t.order.iter().enumerate() {
        pos[v] = k;
    }
}

#[cfg(test)]
mod tests;
