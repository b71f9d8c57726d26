//! The boundary of the offset region, cut at the chord ends of one or more line families.
//!
//! Zigzag joins run along the boundary from a chord end to the next chord end; the boundary
//! pieces no join uses become border strokes, so that the boundary is marked exactly once.

use super::scan::Scan;
use crate::geom::Pt;

/// A chord end on a loop.
#[derive(Debug, Clone, Copy)]
struct Mark {
    edge: u32,
    t: f64,
    pt: Pt,
    cross: u32,
}

/// Where a crossing sits on its loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Pos {
    /// Loop index.
    pub loop_id: u32,
    /// Index among the loop's sorted marks.
    pub index: u32,
}

/// Region boundary loops with the chord ends of every family, and which pieces are used.
pub(crate) struct Boundary<'a> {
    loops: &'a [Vec<Pt>],
    /// Per loop: marks sorted along the loop.
    marks: Vec<Vec<Mark>>,
    /// Per loop: piece `i` (from mark `i` forwards to mark `i + 1`) is marked by a join.
    used: Vec<Vec<bool>>,
    /// Per family, per crossing: its position.
    pos: Vec<Vec<Pos>>,
    /// Per loop, per mark: the next / previous mark of the same family (cyclic).
    next_same: Vec<Vec<u32>>,
    prev_same: Vec<Vec<u32>>,
}

impl<'a> Boundary<'a> {
    /// The boundary `loops` cut at the crossings of `scans` (family = index in `scans`).
    pub(crate) fn new(loops: &'a [Vec<Pt>], scans: &[&Scan]) -> Self {
        let mut keyed: Vec<Vec<(Mark, u8, u32)>> = vec![Vec::new(); loops.len()];
        for (f, s) in scans.iter().enumerate() {
            for (ci, c) in s.crossings.iter().enumerate() {
                let mark = Mark {
                    edge: c.edge,
                    t: c.t,
                    pt: c.pt,
                    cross: ci as u32,
                };
                keyed[c.loop_id as usize].push((mark, f as u8, ci as u32));
            }
        }
        let mut pos: Vec<Vec<Pos>> = scans
            .iter()
            .map(|s| {
                vec![
                    Pos {
                        loop_id: 0,
                        index: 0
                    };
                    s.crossings.len()
                ]
            })
            .collect();
        let mut marks = Vec::with_capacity(loops.len());
        let mut next_same = Vec::with_capacity(loops.len());
        let mut prev_same = Vec::with_capacity(loops.len());
        for (li, mut ks) in keyed.into_iter().enumerate() {
            ks.sort_by(|a, b| {
                a.0.edge
                    .cmp(&b.0.edge)
                    .then(a.0.t.total_cmp(&b.0.t))
                    .then(a.1.cmp(&b.1))
                    .then(a.2.cmp(&b.2))
            });
            for (i, k) in ks.iter().enumerate() {
                pos[k.1 as usize][k.2 as usize] = Pos {
                    loop_id: li as u32,
                    index: i as u32,
                };
            }
            let m = ks.len();
            let mut next = vec![0u32; m];
            let mut prev = vec![0u32; m];
            for fam in 0..scans.len() as u8 {
                let idx: Vec<usize> = (0..m).filter(|&i| ks[i].1 == fam).collect();
                for (k, &i) in idx.iter().enumerate() {
                    next[i] = idx[(k + 1) % idx.len()] as u32;
                    prev[i] = idx[(k + idx.len() - 1) % idx.len()] as u32;
                }
            }
            next_same.push(next);
            prev_same.push(prev);
            marks.push(ks.into_iter().map(|k| k.0).collect::<Vec<_>>());
        }
        let used = marks.iter().map(|m| vec![false; m.len()]).collect();
        Self {
            loops,
            marks,
            used,
            pos,
            next_same,
            prev_same,
        }
    }

    /// The position of crossing `cross` of family `family`.
    pub(crate) fn pos(&self, family: usize, cross: u32) -> Pos {
        self.pos[family][cross as usize]
    }

    /// The neighbouring mark of the same family, walking forwards or backwards along the loop.
    pub(crate) fn neighbour(&self, p: Pos, forward: bool) -> Pos {
        let l = p.loop_id as usize;
        let index = if forward {
            self.next_same[l][p.index as usize]
        } else {
            self.prev_same[l][p.index as usize]
        };
        Pos { index, ..p }
    }

    /// The crossing (of the mark's family) at `p`.
    pub(crate) fn cross_at(&self, p: Pos) -> u32 {
        self.marks[p.loop_id as usize][p.index as usize].cross
    }

    /// The pieces crossed walking from `a` to `b` (same loop).
    fn pieces(&self, a: Pos, b: Pos, forward: bool) -> impl Iterator<Item = usize> {
        let m = self.marks[a.loop_id as usize].len();
        let (a, b) = (a.index as usize, b.index as usize);
        let count = if forward {
            (b + m - a) % m
        } else {
            (a + m - b) % m
        };
        (0..count).map(move |k| {
            if forward {
                (a + k) % m
            } else {
                (a + m - 1 - k) % m
            }
        })
    }

    /// True when no piece between `a` and `b` is used yet.
    pub(crate) fn is_free(&self, a: Pos, b: Pos, forward: bool) -> bool {
        if a.loop_id != b.loop_id || a.index == b.index {
            return false;
        }
        let used = &self.used[a.loop_id as usize];
        self.pieces(a, b, forward).all(|i| !used[i])
    }

    /// Marks the pieces between `a` and `b` as used and appends the boundary points after `a`'s
    /// point up to and including `b`'s point to `out`.
    pub(crate) fn take(&mut self, a: Pos, b: Pos, forward: bool, out: &mut Vec<Pt>) {
        let pieces: Vec<usize> = self.pieces(a, b, forward).collect();
        for i in pieces {
            self.used[a.loop_id as usize][i] = true;
        }
        self.walk(a, b, forward, out);
    }

    /// Appends the loop points strictly after mark `a` up to mark `b` (inclusive).
    fn walk(&self, a: Pos, b: Pos, forward: bool, out: &mut Vec<Pt>) {
        let l = &self.loops[a.loop_id as usize];
        let marks = &self.marks[a.loop_id as usize];
        let (ma, mb) = (marks[a.index as usize], marks[b.index as usize]);
        let (e1, e2) = (ma.edge as usize, mb.edge as usize);
        let mut push = |p: Pt| {
            if out.last().is_none_or(|q| q.dist2(p) > 1e-24) {
                out.push(p);
            }
        };
        if forward {
            if b.index > a.index {
                l[e1 + 1..=e2].iter().for_each(|&p| push(p));
            } else {
                l[e1 + 1..].iter().for_each(|&p| push(p));
                l[..=e2].iter().for_each(|&p| push(p));
            }
        } else if b.index < a.index {
            l[e2 + 1..=e1].iter().rev().for_each(|&p| push(p));
        } else {
            l[..=e1].iter().rev().for_each(|&p| push(p));
            l[e2 + 1..].iter().rev().for_each(|&p| push(p));
        }
        push(mb.pt);
    }

    /// The boundary pieces no join uses, merged into maximal polylines; loops without any used
    /// piece come back whole and closed. Each item is `(points, closed)`.
    #[cfg(test)]
    pub(crate) fn unused(&self) -> Vec<(Vec<Pt>, bool)> {
        self.unused_by_loop()
            .into_iter()
            .map(|(_, pts, closed)| (pts, closed))
            .collect()
    }

    /// [`Boundary::unused`] with each item's loop index first; the pieces of a loop come in
    /// its order.
    pub(crate) fn unused_by_loop(&self) -> Vec<(u32, Vec<Pt>, bool)> {
        let mut out = Vec::new();
        for (li, l) in self.loops.iter().enumerate() {
            let used = &self.used[li];
            let m = used.len();
            if used.iter().all(|u| !u) {
                out.push((li as u32, l.clone(), true));
                continue;
            }
            for start in 0..m {
                if used[start] || !used[(start + m - 1) % m] {
                    continue;
                }
                let mut end = start;
                while !used[end % m] {
                    end += 1;
                }
                let a = Pos {
                    loop_id: li as u32,
                    index: start as u32,
                };
                let b = Pos {
                    loop_id: li as u32,
                    index: (end % m) as u32,
                };
                let mut pts = vec![self.marks[li][start].pt];
                self.walk(a, b, true, &mut pts);
                out.push((li as u32, pts, false));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::super::scan::scan;
    use super::*;
    use crate::geom::polyline_length;

    fn square() -> Vec<Pt> {
        vec![
            Pt::new(0.0, 0.0),
            Pt::new(10.0, 0.0),
            Pt::new(10.0, 10.0),
            Pt::new(0.0, 10.0),
        ]
    }

    #[test]
    fn joins_and_complement_cover_the_loop_once() {
        let loops = vec![square()];
        let s = scan(&loops, 0.0, 1.0, 100).unwrap();
        let mut b = Boundary::new(&loops, &[&s]);
        // join the right ends of lines 0 and 1
        let x = s.lines[0][0].hi;
        let p = b.pos(0, x);
        let fwd = s.crossings[x as usize].forward_down;
        let q = b.neighbour(p, fwd);
        let y = s.lines[1][0].hi;
        assert_eq!(q, b.pos(0, y));
        assert!(b.is_free(p, q, fwd));
        let mut pts = vec![s.crossings[x as usize].pt];
        b.take(p, q, fwd, &mut pts);
        assert_eq!(pts.len(), 2);
        assert!((polyline_length(&pts, false) - 1.0).abs() < 1e-12);
        assert!(!b.is_free(p, q, fwd));
        let rest = b.unused();
        assert_eq!(rest.len(), 1);
        assert!(!rest[0].1);
        let total = polyline_length(&rest[0].0, false) + 1.0;
        assert!((total - 40.0).abs() < 1e-9, "{total}");
        // the complement starts where the join ends and ends where it starts
        assert!(rest[0].0[0].dist(Pt::new(10.0, 1.5)) < 1e-12);
        assert!(rest[0].0.last().unwrap().dist(Pt::new(10.0, 0.5)) < 1e-12);
    }
}
