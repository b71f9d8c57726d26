//! The tour as a ring with a depot: a path whose reversals cost the shorter side.
//!
//! The `n` path nodes and one depot node (index `n`) sit in a cyclic array. The path is read from
//! the depot's successor to its predecessor, in the array's direction or against it (`rev`).
//! Reversing the path positions `i..=j` reverses that run of the array *or*, when that is the
//! longer side, the rest of the cycle (which holds the depot) and toggles `rev`: read from the
//! depot in the new direction, both give the same path (the oriented cycle `S C` with `S`
//! reversed in place equals `C` reversed in place read backwards). So a reversal costs
//! `min(L, n + 1 − L)` swaps.
//!
//! Orientation: a flippable node reversed with its run is flipped. The array stores a flip bit per
//! node; the effective flip is `stored ^ (rev && flippable)`. Reversing the complement toggles the
//! complement's stored bits and `rev`, so the complement's effective flips stay and the run's
//! toggle, exactly as reversing the run itself would.

use super::problem::Tour;

/// `x mod m` for `x < 2m`.
#[inline]
fn wrap(x: usize, m: usize) -> usize {
    if x >= m {
        x - m
    } else {
        x
    }
}

/// The path as a cyclic array with a depot (see the module docs).
#[derive(Debug, Clone)]
pub(super) struct Ring {
    /// Node at each array slot; `n + 1` slots, the depot is node `n`.
    seq: Vec<u32>,
    /// Array slot of each node (and of the depot).
    slot: Vec<u32>,
    /// The path runs against the array's direction.
    rev: bool,
    /// Stored flip bit per node (see the module docs); the depot's is never set.
    flip: Vec<bool>,
    /// Whether each node may flip; the depot may not.
    flippable: Vec<bool>,
    /// Some node may flip (else reversals leave every flip bit alone).
    any_flippable: bool,
}

impl Ring {
    /// The ring of a tour (its order and orientations).
    pub(super) fn new(tour: &Tour, flippable: &[bool]) -> Ring {
        let n = tour.order.len();
        let mut seq = Vec::with_capacity(n + 1);
        seq.push(n as u32);
        seq.extend(tour.order.iter().map(|&v| v as u32));
        let mut slot = vec![0u32; n + 1];
        for (k, &v) in seq.iter().enumerate() {
            slot[v as usize] = k as u32;
        }
        let mut flip: Vec<bool> = tour.flipped.clone();
        flip.resize(n + 1, false);
        let mut flippable = flippable.to_vec();
        flippable.resize(n + 1, false);
        flip[n] = false;
        flippable[n] = false;
        Ring {
            seq,
            slot,
            rev: false,
            flip,
            any_flippable: flippable.contains(&true),
            flippable,
        }
    }

    /// Number of path nodes.
    pub(super) fn len(&self) -> usize {
        self.seq.len() - 1
    }

    fn cycle(&self) -> usize {
        self.seq.len()
    }

    fn depot_slot(&self) -> usize {
        self.slot[self.len()] as usize
    }

    /// Array slot of path position `k` (`0..n`).
    fn slot_of_position(&self, k: usize) -> usize {
        let (m, d) = (self.cycle(), self.depot_slot());
        // k < m − 1 and d < m, so one conditional wrap replaces a division
        if self.rev {
            wrap(d + m - 1 - k, m)
        } else {
            wrap(d + 1 + k, m)
        }
    }

    /// The node at path position `k` (`0..n`).
    pub(super) fn at(&self, k: usize) -> usize {
        self.seq[self.slot_of_position(k)] as usize
    }

    /// The path position of node `v`.
    pub(super) fn position(&self, v: usize) -> usize {
        let (m, d, s) = (self.cycle(), self.depot_slot(), self.slot[v] as usize);
        if self.rev {
            wrap(d + m - 1 - s, m)
        } else {
            wrap(s + m - d - 1, m)
        }
    }

    /// The node after `v` on the path, `None` at the end.
    pub(super) fn next(&self, v: usize) -> Option<usize> {
        let k = self.position(v) + 1;
        (k < self.len()).then(|| self.at(k))
    }

    /// The node before `v` on the path, `None` at the start.
    pub(super) fn prev(&self, v: usize) -> Option<usize> {
        let k = self.position(v);
        (k > 0).then(|| self.at(k - 1))
    }

    /// Whether `v` is traversed from its end point to its start point.
    pub(super) fn flipped(&self, v: usize) -> bool {
        self.flip[v] ^ (self.rev && self.flippable[v])
    }

    /// Whether `v` may flip.
    pub(super) fn flippable(&self, v: usize) -> bool {
        self.flippable[v]
    }

    /// Whether some node may flip.
    pub(super) fn any_flippable(&self) -> bool {
        self.any_flippable
    }

    /// Reverses path positions `i..=j` (`i ≤ j < n`), flipping the flippable nodes among them.
    /// Applying the same reversal again undoes it.
    pub(super) fn reverse(&mut self, i: usize, j: usize) {
        debug_assert!(i <= j && j < self.len());
        let m = self.cycle();
        let len = j - i + 1;
        // the run's first slot in array direction
        let first = if self.rev {
            self.slot_of_position(j)
        } else {
            self.slot_of_position(i)
        };
        if 2 * len <= m {
            self.reverse_slots(first, len);
        } else {
            self.reverse_slots((first + len) % m, m - len);
            self.rev = !self.rev;
        }
    }

    /// Reverses `len` array slots from `first` (cyclically), toggling their stored flips.
    fn reverse_slots(&mut self, first: usize, len: usize) {
        let m = self.cycle();
        let (mut a, mut b) = (first, (first + len - 1) % m);
        for _ in 0..len / 2 {
            self.seq.swap(a, b);
            self.slot[self.seq[a] as usize] = a as u32;
            self.slot[self.seq[b] as usize] = b as u32;
            a = if a + 1 == m { 0 } else { a + 1 };
            b = if b == 0 { m - 1 } else { b - 1 };
        }
        if !self.any_flippable {
            return;
        }
        let mut s = first;
        for _ in 0..len {
            let v = self.seq[s] as usize;
            if self.flippable[v] {
                self.flip[v] = !self.flip[v];
            }
            s = if s + 1 == m { 0 } else { s + 1 };
        }
    }

    /// Writes the path (order and orientations) into `tour`.
    pub(super) fn write(&self, tour: &mut Tour) {
        let n = self.len();
        tour.order.clear();
        tour.order.extend((0..n).map(|k| self.at(k)));
        for v in 0..n {
            tour.flipped[v] = self.flipped(v);
        }
    }
}
