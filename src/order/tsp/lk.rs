//! Lin–Kernighan-style variable-depth moves, made of sequential 2-opt reversals.
//!
//! From a base `t1` and its path neighbour `t2` (either side), the edge `t1–t2` is removed and
//! `t2` joined to a candidate `t3`; of `t3`'s path neighbours, the one `t4` that keeps a path
//! (`t4` on the `t2` side of `t3`) is cut off and the path closed by `t1–t4`. That is one 2-opt
//! reversal; the chain goes on from `t1–t4` as the new `t1–t2` edge. With the *open gain*
//! `G = (cost before the chain − cost now) + cost(t1–t4)`, a step is explored only while
//! `G − cost(t2–t3) > 0` and `G_next > 0` (the gain criterion of Lin and Kernighan), the chain
//! stops at the first step that lowers the cost (first improvement, as LKH does) and
//! otherwise follows the one step of most open gain up to [`MAX_DEPTH`], also as LKH does (on
//! 1,000 uniform points, trying the best 3 or 5 steps at the first level gave the same tours
//! after 2,000 kicks, within the spread of three instances, in 15–30 % more time). Depth 3
//! reaches the sequential 3-opt moves made of reversals; the pure segment moves are in
//! `moves.rs`.
//!
//! When `t3` lies beyond `t1` the reversal holds `t1` itself (the run from `t3` to `t1`), so `t1`'s
//! new neighbour `t4` is on its other side: the chain continues in the mirrored direction.

use super::engine::{Engine, IMPROVE_EPS};

/// Deepest chain, in reversals.
const MAX_DEPTH: usize = 6;

/// Candidates of `t2` considered at each step (the nearest of its neighbour list).
const CANDIDATES: usize = 8;

/// One step of a chain: reverse positions `i..=j`, after which `t4` is `t1`'s new neighbour.
#[derive(Debug, Clone, Copy)]
struct Step {
    i: usize,
    j: usize,
    t3: usize,
    t4: Option<usize>,
    /// `t4` follows `t1` (else it precedes it) after the step.
    forward: bool,
    /// Change of cost of the chain with this step.
    delta: f64,
    /// Cost of the new edge `t1–t4`.
    closing: f64,
    /// Cost of the new edge `t2–t3`.
    joined: f64,
}

impl Engine<'_> {
    /// Tries an improving Lin–Kernighan chain from `t1`; returns the change of cost.
    pub(super) fn lin_kernighan(&mut self, t1: usize) -> Option<f64> {
        for forward in [true, false] {
            let t2 = if forward {
                self.ring.next(t1)
            } else {
                self.ring.prev(t1)
            };
            let Some(t2) = t2 else { continue };
            let closing = if forward {
                self.edge(t1, t2)
            } else {
                self.edge(t2, t1)
            };
            let mark = self.mark();
            if let Some(d) = self.chain(t1, t2, forward, 0.0, closing, 0) {
                self.touched.extend([t1, t2]);
                return Some(d);
            }
            self.undo_to(mark);
        }
        None
    }

    /// The reversal that joins `t2` to `t3` (see the module docs), if it stays in the movable
    /// positions.
    fn chain_step(&self, t1: usize, t2: usize, t3: usize, forward: bool) -> Option<Step> {
        let r = &self.ring;
        let (k1, k2, k3) = (r.position(t1), r.position(t2), r.position(t3));
        let n = self.len();
        // (i, j, t4 position, does t1's side flip)
        let (i, j, k4, mirrored) = if forward {
            if k3 > k2 {
                (k2, k3 - 1, Some(k3 - 1), false)
            } else {
                (k3, k1, k3.checked_sub(1), true)
            }
        } else if k3 < k2 {
            (k3 + 1, k2, Some(k3 + 1), false)
        } else {
            (k1, k3, (k3 + 1 < n).then_some(k3 + 1), true)
        };
        if k4 == Some(k2) || !self.movable(i) || !self.movable(j) {
            return None;
        }
        let (delta, left, right) = self.reversal_delta(i, j);
        // the new edge t1–t4 is the boundary on t1's side, t2–t3 the other one
        let (closing, joined) = if forward {
            (left, right)
        } else {
            (right, left)
        };
        Some(Step {
            i,
            j,
            t3,
            t4: k4.map(|k| r.at(k)),
            forward: forward ^ mirrored,
            delta,
            closing,
            joined,
        })
    }

    /// Extends a chain whose tour now holds the edge `t1–t2` (`t2` after `t1` when `forward`),
    /// `delta` below/above the cost before the chain, `closing` the cost of `t1–t2`.
    fn chain(
        &mut self,
        t1: usize,
        t2: usize,
        forward: bool,
        delta: f64,
        closing: f64,
        depth: usize,
    ) -> Option<f64> {
        let open_gain = closing - delta;
        // the step of most open gain, cost(t3–t4) − cost(t2–t3) (Lin–Kernighan's rule); ties
        // go to the lower t3 so that the chain does not depend on the neighbour lists' order
        let open = |s: &Step| s.closing - s.delta;
        let mut best: Option<Step> = None;
        for &t3 in self.nbr[t2].iter().take(CANDIDATES) {
            if t3 == t1 || t3 == t2 {
                continue;
            }
            // between points the added edge t2–t3 costs their distance whatever the step:
            // the gain criterion below, checked before the step is worked out (same chains;
            // with the packed points of `Engine::edge`, 27 % less search time on 1,000 uniform
            // points)
            if self.plain_points() && open_gain - self.edge(t2, t3) <= IMPROVE_EPS {
                continue;
            }
            let Some(mut s) = self.chain_step(t1, t2, t3, forward) else {
                continue;
            };
            // gain criterion on the added edge t2–t3: open gain minus its cost stays positive
            if open_gain - s.joined <= IMPROVE_EPS {
                continue;
            }
            s.delta += delta;
            if s.delta < -IMPROVE_EPS {
                self.reverse(s.i, s.j);
                self.touched.push(t3);
                self.touched.extend(s.t4);
                return Some(s.delta);
            }
            let better = best
                .as_ref()
                .is_none_or(|b| open(&s).total_cmp(&open(b)).then(b.t3.cmp(&s.t3)).is_gt());
            if s.t4.is_some() && open(&s) > IMPROVE_EPS && better {
                best = Some(s);
            }
        }
        if depth + 1 >= MAX_DEPTH {
            return None;
        }
        let s = best?;
        let t4 = s.t4?;
        let mark = self.mark();
        self.reverse(s.i, s.j);
        if let Some(d) = self.chain(t1, t4, s.forward, s.delta, s.closing, depth + 1) {
            self.touched.extend([s.t3, t4]);
            return Some(d);
        }
        self.undo_to(mark);
        None
    }
}
