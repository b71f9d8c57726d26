//! Node and segment moves: a flip in place (an open stroke marked the other way round), Or-opt
//! (a short run moved next to a neighbour, either way round) and Or-3opt (the sequential 3-opt
//! move that swaps two adjacent runs without reversing either: a segment insertion of any
//! length).

use super::engine::{Engine, IMPROVE_EPS};

/// Candidates looked at for each end of an Or-3opt move (the nearest of the neighbour list).
const OR3_CANDIDATES: usize = 6;

/// Neighbours of a run's first node next to which Or-opt tries to put the run (the nearest of
/// its list). On 1,000 uniform points (5 instances × 2 seeds, 1,500 kicks) 5 and 8 gave the
/// same tours within their spread, 5 in 10 % less time; 16 was a third slower.
const OR_CANDIDATES: usize = 5;

/// Where Or-opt puts a run: after position `after` (before position 0 when `None`).
#[derive(Debug, Clone, Copy)]
struct Insertion {
    after: Option<usize>,
    reversed: bool,
}

impl Engine<'_> {
    /// Flips `a` where it is (an open stroke marked the other way round) when that lowers the
    /// cost; returns the change.
    pub(super) fn flip_in_place(&mut self, a: usize) -> Option<f64> {
        let k = self.ring.position(a);
        if !self.ring.flippable(a) || !self.movable(k) {
            return None;
        }
        let (d, _, _) = self.reversal_delta(k, k);
        if d >= -IMPROVE_EPS {
            return None;
        }
        self.touched.push(a);
        self.touched.extend(self.ring.prev(a));
        self.touched.extend(self.ring.next(a));
        self.reverse(k, k);
        Some(d)
    }

    /// Moves a run of 1..=`or_max` nodes starting at `a` next to one of `a`'s neighbours, in
    /// either orientation, when that lowers the cost; returns the change.
    pub(super) fn or_opt(&mut self, a: usize) -> Option<f64> {
        let n = self.len();
        let i = self.ring.position(a);
        for len in 1..=self.or_max {
            let j = i + len - 1;
            if j >= n || !self.movable(i) || !self.movable(j) {
                break;
            }
            // cost removed with the run, and the edge that closes the gap
            let mut removal = -self.edge_into(i) - self.edge_into(j + 1);
            if i > 0 && j + 1 < n {
                removal += self.edge(self.ring.at(i - 1), self.ring.at(j + 1));
            }
            if let Some((ins, d)) = self.best_insertion(a, i, j, removal) {
                self.touched.extend([self.ring.at(i), self.ring.at(j)]);
                self.touched
                    .extend(i.checked_sub(1).map(|k| self.ring.at(k)));
                self.touched
                    .extend((j + 1 < n).then(|| self.ring.at(j + 1)));
                self.apply_insertion(i, j, ins);
                return Some(d);
            }
        }
        None
    }

    /// The first improving insertion of the run `i..=j` next to a neighbour of `a`.
    fn best_insertion(
        &mut self,
        a: usize,
        i: usize,
        j: usize,
        removal: f64,
    ) -> Option<(Insertion, f64)> {
        let n = self.len();
        let (first, last) = (self.ring.at(i), self.ring.at(j));
        let lambda = self.prob.lambda;
        for &v in self.nbr[a].iter().take(OR_CANDIDATES) {
            let k = self.ring.position(v);
            if k >= i && k <= j {
                continue;
            }
            // between positions (k, k+1) or (k−1, k): x before the run, y after it
            for (x, y) in [(Some(k), k + 1), (k.checked_sub(1), k)] {
                let y = (y < n).then_some(y);
                if x.is_some_and(|x| x + 1 >= i && x <= j)
                    || y.is_some_and(|y| y >= i && y <= j + 1)
                {
                    continue;
                }
                let too_early = x.map_or(self.lo > 0, |x| x + 1 < self.lo);
                if too_early
                    || y.is_some_and(|y| y > self.hi + 1)
                    || (y.is_none() && self.prob.fixed_last)
                {
                    continue;
                }
                let (xn, yn) = (x.map(|x| self.ring.at(x)), y.map(|y| self.ring.at(y)));
                let old = match (xn, yn) {
                    (Some(p), Some(q)) => self.edge(p, q),
                    _ => 0.0,
                };
                for reversed in [false, true] {
                    let (h, l) = if reversed {
                        (last, first)
                    } else {
                        (first, last)
                    };
                    let mut add = -old;
                    if let Some(p) = xn {
                        add += self.edge_toggled(p, false, h, reversed);
                    }
                    if let Some(q) = yn {
                        add += self.edge_toggled(l, reversed, q, false);
                    }
                    if reversed {
                        // the run's own directional terms, see the engine's docs
                        add += lambda * (self.prob.nodes[last].p - self.prob.nodes[first].p);
                    }
                    if removal + add < -IMPROVE_EPS {
                        self.touched.extend(xn);
                        self.touched.extend(yn);
                        return Some((Insertion { after: x, reversed }, removal + add));
                    }
                }
            }
        }
        None
    }

    /// Moves the run `i..=j` as `ins` says, by reversals.
    fn apply_insertion(&mut self, i: usize, j: usize, ins: Insertion) {
        let len = j - i + 1;
        match ins.after {
            Some(x) if x > j => {
                // [run][j+1..=x] → [j+1..=x][run]
                self.reverse(i, x);
                let moved = x - j;
                self.reverse(i, i + moved - 1);
                if !ins.reversed {
                    self.reverse(i + moved, x);
                }
            }
            after => {
                // [x+1..i−1][run] → [run][x+1..i−1]
                let start = after.map_or(0, |x| x + 1);
                self.reverse(start, j);
                self.reverse(start + len, j);
                if !ins.reversed {
                    self.reverse(start, start + len - 1);
                }
            }
        }
    }

    /// Or-3opt from `t1`: cut `t1–t2`, `t3–t4` and `t5–t6` and swap the runs `t2..t5` and
    /// `t6..t3` (mirrored on the other side of `t1`), keeping their orientations: the new edges
    /// are `t2–t3`, `t4–t5` and `t6–t1`. Returns the change of cost.
    pub(super) fn or_3opt(&mut self, t1: usize) -> Option<f64> {
        for forward in [true, false] {
            if let Some(d) = self.or_3opt_side(t1, forward) {
                return Some(d);
            }
        }
        None
    }

    /// Path neighbour of `v` on the `forward` side.
    fn beside(&self, v: usize, forward: bool) -> Option<usize> {
        if forward {
            self.ring.next(v)
        } else {
            self.ring.prev(v)
        }
    }

    /// Cost of the edge `u–v` in path direction (`u` before `v` when `forward`).
    fn edge_dir(&self, u: usize, v: usize, forward: bool) -> f64 {
        if forward {
            self.edge(u, v)
        } else {
            self.edge(v, u)
        }
    }

    fn or_3opt_side(&mut self, t1: usize, forward: bool) -> Option<f64> {
        let t2 = self.beside(t1, forward)?;
        let k2 = self.ring.position(t2);
        let cut12 = self.edge_dir(t1, t2, forward);
        // positions ordered along the search direction
        let ahead = |a: usize, b: usize| if forward { a > b } else { a < b };
        for &t3 in self.nbr[t2].iter().take(OR3_CANDIDATES) {
            let k3 = self.ring.position(t3);
            if t3 == t1 || !ahead(k3, k2) {
                continue;
            }
            let Some(t4) = self.beside(t3, forward) else {
                continue;
            };
            // new edge t3 → t2 (t3's run comes before t2's in path direction)
            let g1 = cut12 - self.edge_dir(t3, t2, forward);
            if g1 <= IMPROVE_EPS {
                continue;
            }
            let g2 = g1 + self.edge_dir(t3, t4, forward);
            for &t5 in self.nbr[t4].iter().take(OR3_CANDIDATES) {
                let k5 = self.ring.position(t5);
                // t5 in t2..t3 (t2 included, t3 excluded), so that t6 exists in t2..=t3
                if t5 == t3 || ahead(k2, k5) || !ahead(k3, k5) {
                    continue;
                }
                let Some(t6) = self.beside(t5, forward) else {
                    continue;
                };
                let d = self.edge_dir(t5, t4, forward) + self.edge_dir(t1, t6, forward)
                    - self.edge_dir(t5, t6, forward)
                    - g2;
                if d < -IMPROVE_EPS && self.or_3opt_apply(k2, k5, k3, forward) {
                    self.touched.extend([t1, t2, t3, t4, t5, t6]);
                    return Some(d);
                }
            }
        }
        None
    }

    /// Swaps the runs `k2..=k5` and `k5+1..=k3` (mirrored when not `forward`), if movable.
    fn or_3opt_apply(&mut self, k2: usize, k5: usize, k3: usize, forward: bool) -> bool {
        let (i, k, m) = if forward {
            (k2, k5, k3)
        } else {
            (k3, k5 - 1, k2)
        };
        if !self.movable(i) || !self.movable(m) {
            return false;
        }
        self.swap_runs(i, k, m);
        true
    }
}
