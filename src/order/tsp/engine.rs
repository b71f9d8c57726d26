//! The local-search engine: a ring tour, exact move costs, a work queue with don't-look bits and a
//! journal of reversals for undo.
//!
//! Every move is made of path reversals (`Ring::reverse`), so one journal undoes any move, kick or
//! abandoned Lin–Kernighan chain. Costs are the problem's own (`PathProblem::cost_o`, with the
//! current orientations), evaluated on the few edges a move changes:
//!
//! * reversing positions `i..=j` changes the edges into `i` and out of `j`; inside the run, the
//!   distances stay (a point-like node has equal ends, a flippable one flips with the run, so the
//!   edge between two reversed nodes joins the same two points) and the cluster penalty is
//!   symmetric; the directional term changes by exactly `λ (p_j − p_i)`, because
//!   `Σ max(0, p_{k+1} − p_k) − Σ max(0, p_k − p_{k+1}) = Σ (p_{k+1} − p_k)` telescopes;
//! * moving a run without reversing it changes only the three edges at its ends and at its target.

use super::problem::PathProblem;
use super::ring::Ring;
use crate::job::JobCtx;
use crate::order::cost::TravelCost;
use std::collections::VecDeque;
use std::time::Instant;

/// A change of cost below `-IMPROVE_EPS` is an improvement (mm or s: far below any resolution).
pub(super) const IMPROVE_EPS: f64 = 1e-9;

/// Queue steps between two polls of the cancel token and the deadline (each step is a few
/// microseconds, so a poll every 32 keeps cancellation far below a millisecond).
const POLL_EVERY: usize = 32;

/// A ring tour with everything the moves share.
pub(super) struct Engine<'p> {
    /// The problem.
    pub(super) prob: &'p PathProblem,
    /// Candidate neighbours of each node.
    pub(super) nbr: &'p [Vec<usize>],
    /// The tour.
    pub(super) ring: Ring,
    /// First movable path position (1 when the first node is fixed).
    pub(super) lo: usize,
    /// Last movable path position (`n − 2` when the last node is fixed).
    pub(super) hi: usize,
    /// Longest run moved by Or-opt.
    pub(super) or_max: usize,
    /// Reversals since the last commit, for undo.
    journal: Vec<(u32, u32)>,
    queue: VecDeque<usize>,
    queued: Vec<bool>,
    /// Nodes touched by the last move (to be queued again).
    pub(super) touched: Vec<usize>,
    /// Stop when this instant passes (checked with the cancel token).
    pub(super) deadline: Option<Instant>,
    /// The cost is plain Euclidean distance (λ = 0, no cluster penalty): edges are computed
    /// directly, the hot path of plain TSPs.
    plain: bool,
    /// `plain`, and no node may flip: every node is a point (`s = e`), so an edge is the
    /// distance between two points whatever the orientations.
    plain_points: bool,
    /// With `plain_points`, each node's point, packed (the hot path reads nothing else);
    /// empty otherwise.
    points: Vec<crate::geom::Pt>,
}

/// Why a local search stopped early.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Halt {
    /// The cancel token was set.
    Cancelled,
    /// The deadline passed.
    Deadline,
}

impl<'p> Engine<'p> {
    /// An engine on `tour`; `None` when no node can move (fewer than 3 nodes or fixed ends
    /// leave nothing).
    pub(super) fn new(
        prob: &'p PathProblem,
        nbr: &'p [Vec<usize>],
        tour: &super::Tour,
        or_max: usize,
    ) -> Option<Engine<'p>> {
        let n = tour.order.len();
        if n < 3 || n != prob.nodes.len() {
            return None;
        }
        let lo = usize::from(prob.fixed_first);
        let hi = if prob.fixed_last { n - 2 } else { n - 1 };
        if lo > hi {
            return None;
        }
        let plain = prob.lambda == 0.0
            && (prob.cluster.is_empty() || prob.cluster_penalty == 0.0)
            && prob.metric == TravelCost::Distance;
        let ring = Ring::new(tour, &prob.flippable);
        let plain_points = plain && !ring.any_flippable();
        let points = if plain_points {
            prob.nodes.iter().map(|node| node.s).collect()
        } else {
            Vec::new()
        };
        Some(Engine {
            prob,
            nbr,
            plain_points,
            points,
            ring,
            lo,
            hi,
            or_max,
            journal: Vec::new(),
            queue: VecDeque::new(),
            queued: vec![false; n],
            touched: Vec::new(),
            deadline: None,
            plain,
        })
    }

    /// Every node is a point and the cost is their distance (see `plain_points`).
    pub(super) fn plain_points(&self) -> bool {
        self.plain_points
    }

    /// Number of nodes.
    pub(super) fn len(&self) -> usize {
        self.ring.len()
    }

    /// Cost of the edge `u → v` with the current orientations.
    #[inline(always)]
    pub(super) fn edge(&self, u: usize, v: usize) -> f64 {
        if self.plain_points {
            return self.points[u].dist(self.points[v]);
        }
        self.edge_oriented(u, v)
    }

    /// [`Engine::edge`] with the orientations (not between two points).
    #[inline(never)]
    fn edge_oriented(&self, u: usize, v: usize) -> f64 {
        self.cost_o(u, self.ring.flipped(u), v, self.ring.flipped(v))
    }

    /// The problem's `cost_o`, computed directly when the cost is plain distance.
    #[inline]
    fn cost_o(&self, u: usize, fu: bool, v: usize, fv: bool) -> f64 {
        if self.plain {
            let (a, b) = (&self.prob.nodes[u], &self.prob.nodes[v]);
            let from = if fu { a.s } else { a.e };
            let to = if fv { b.e } else { b.s };
            from.dist(to)
        } else {
            self.prob.cost_o(u, fu, v, fv)
        }
    }

    /// Cost of the edge `u → v` when `u`'s orientation is toggled (`tu`) and/or `v`'s (`tv`).
    #[inline(always)]
    pub(super) fn edge_toggled(&self, u: usize, tu: bool, v: usize, tv: bool) -> f64 {
        if self.plain_points {
            return self.points[u].dist(self.points[v]);
        }
        self.edge_toggled_oriented(u, tu, v, tv)
    }

    /// [`Engine::edge_toggled`] with the orientations (not between two points).
    #[inline(never)]
    fn edge_toggled_oriented(&self, u: usize, tu: bool, v: usize, tv: bool) -> f64 {
        let fu = self.ring.flipped(u) ^ (tu && self.ring.flippable(u));
        let fv = self.ring.flipped(v) ^ (tv && self.ring.flippable(v));
        self.cost_o(u, fu, v, fv)
    }

    /// Cost of the edge into path position `k` (0 at the start).
    #[inline]
    pub(super) fn edge_into(&self, k: usize) -> f64 {
        if k == 0 || k >= self.len() {
            0.0
        } else {
            self.edge(self.ring.at(k - 1), self.ring.at(k))
        }
    }

    /// Exact change of cost from reversing positions `i..=j`, with the new cost of the edge into
    /// `i` and out of `j` (0 where the path ends).
    #[inline]
    pub(super) fn reversal_delta(&self, i: usize, j: usize) -> (f64, f64, f64) {
        let (a, b) = (self.ring.at(i), self.ring.at(j));
        let mut d = self.prob.lambda * (self.prob.nodes[b].p - self.prob.nodes[a].p);
        let mut left = 0.0;
        let mut right = 0.0;
        if i > 0 {
            let p = self.ring.at(i - 1);
            left = self.edge_toggled(p, false, b, true);
            d += left - self.edge(p, a);
        }
        if j + 1 < self.len() {
            let q = self.ring.at(j + 1);
            right = self.edge_toggled(a, true, q, false);
            d += right - self.edge(b, q);
        }
        (d, left, right)
    }

    /// Reverses positions `i..=j` and records it.
    pub(super) fn reverse(&mut self, i: usize, j: usize) {
        self.ring.reverse(i, j);
        self.journal.push((i as u32, j as u32));
    }

    /// Swaps the adjacent runs `i..=k` and `k+1..=m`, keeping their orientations (three
    /// reversals).
    pub(super) fn swap_runs(&mut self, i: usize, k: usize, m: usize) {
        let second = m - k;
        self.reverse(i, m);
        self.reverse(i, i + second - 1);
        self.reverse(i + second, m);
    }

    /// Journal length: a mark to undo back to.
    pub(super) fn mark(&self) -> usize {
        self.journal.len()
    }

    /// Undoes every reversal after `mark`.
    pub(super) fn undo_to(&mut self, mark: usize) {
        while self.journal.len() > mark {
            if let Some((i, j)) = self.journal.pop() {
                self.ring.reverse(i as usize, j as usize);
            }
        }
    }

    /// Forgets the journal (the moves so far are kept for good).
    pub(super) fn commit(&mut self) {
        self.journal.clear();
    }

    /// Queues `v` for a look (once).
    pub(super) fn push(&mut self, v: usize) {
        if !self.queued[v] {
            self.queued[v] = true;
            self.queue.push_back(v);
        }
    }

    /// Whether `k` is a movable position.
    pub(super) fn movable(&self, k: usize) -> bool {
        k >= self.lo && k <= self.hi
    }

    /// Improves the tour until no queued node yields an improving move; returns the total change
    /// of cost. Polls the cancel token and the deadline.
    pub(super) fn improve(&mut self, ctx: &JobCtx) -> Result<f64, Halt> {
        let mut total = 0.0;
        let mut steps = 0usize;
        while let Some(a) = self.queue.pop_front() {
            self.queued[a] = false;
            if steps % POLL_EVERY == 0 {
                self.poll(ctx)?;
            }
            steps += 1;
            self.touched.clear();
            let gain = self
                .flip_in_place(a)
                .or_else(|| self.lin_kernighan(a))
                .or_else(|| self.or_opt(a))
                .or_else(|| self.or_3opt(a));
            if let Some(d) = gain {
                total += d;
                let touched = std::mem::take(&mut self.touched);
                for &v in &touched {
                    self.push(v);
                }
                self.touched = touched;
            }
        }
        Ok(total)
    }

    /// `Err` once the cancel token is set or the deadline has passed.
    pub(super) fn poll(&self, ctx: &JobCtx) -> Result<(), Halt> {
        if ctx.is_cancelled() {
            return Err(Halt::Cancelled);
        }
        match self.deadline {
            Some(t) if Instant::now() >= t => Err(Halt::Deadline),
            _ => Ok(()),
        }
    }

    /// Drops every queued node.
    pub(super) fn clear_queue(&mut self) {
        for v in self.queue.drain(..) {
            self.queued[v] = false;
        }
    }

    /// Exact cost of the whole path.
    pub(super) fn cost(&self) -> f64 {
        (1..self.len()).map(|k| self.edge_into(k)).sum()
    }
}
