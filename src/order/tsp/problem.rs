//! The path problem: nodes, their costs, and a tour over them.

use crate::geom::Pt;
use crate::order::cost::TravelCost;

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

/// Open strokes shorter than this are searched as point-like nodes at their midpoint, mm.
///
/// Moving an end by at most half the stroke's length changes each of its two edges by at most
/// that much (triangle inequality), so the search's cost is within `Σ length` of the true one;
/// the vertex stage that follows every search (VEA, then by default the exact DP) picks the
/// orientation of such strokes for the order found (callers that keep the search's
/// orientations keep the stroke's old one). 10 µm is below a marking spot and a galvanometer's repeatability, while dot
/// patterns (drilling, textures, seed 002's placements) are strokes of a few µm: as points they
/// need no flips and take the engine's all-point path (1,000 dots: 0.288 → 0.170 s of ordering
/// with both; BENCHMARKS, issue 16).
pub const POINT_LIKE_MM: f64 = 0.01;

impl Node {
    /// A point-like node.
    pub fn point(q: Pt, p: f64) -> Node {
        Node { s: q, e: q, p }
    }

    /// The node of an open stroke from `start` to `end` (unflipped), and whether it may flip:
    /// a flippable node, or a point at the midpoint when the stroke is shorter than
    /// [`POINT_LIKE_MM`].
    pub fn open_stroke(start: Pt, end: Pt, p: f64) -> (Node, bool) {
        if start.dist(end) < POINT_LIKE_MM {
            (Node::point(start.plus(end).scale(0.5), p), false)
        } else {
            (
                Node {
                    s: start,
                    e: end,
                    p,
                },
                true,
            )
        }
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
    pub(super) fn cost_o(&self, i: usize, fi: bool, j: usize, fj: bool) -> f64 {
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
