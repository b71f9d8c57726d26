//! Set cover for `--fields auto`: the fewest fields whose squares hold every geometry.
//!
//! A field covers a geometry exactly when its centre lies in the geometry's *feasible rectangle*
//! (the centres from which the square holds the geometry's bounding box, clipped to the base
//! stroke). Covering geometries is therefore *piercing* their feasible rectangles with the fewest
//! points, and a group of geometries fits one field exactly when its rectangles have a common
//! point (axis-parallel rectangles: pairwise overlap in x and in y suffices). So:
//!
//! 1. greedy piercing: repeatedly the point in the most not-yet-pierced rectangles, found by a
//!    sweep over x with a segment tree over y (`O(n log n)` per field);
//! 2. elimination: try to dissolve each group (smallest first) by moving its members into other
//!    groups whose common rectangle still meets theirs; repeat while it removes groups;
//! 3. a lower bound: rectangles that pairwise do not meet need one field each (a greedy maximal
//!    set of such rectangles, taken in two orders, the larger counts).

use super::reach::Span;
use crate::job::{Cancelled, JobCtx};

/// An axis-parallel rectangle of possible field centres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FRect {
    /// x range.
    pub x: Span,
    /// y range.
    pub y: Span,
}

/// Slack for "rectangles meet", mm.
const MEET_EPS: f64 = 1e-9;

impl FRect {
    /// Intersection (may be empty).
    pub fn meet(&self, o: &FRect) -> FRect {
        FRect {
            x: self.x.meet(&o.x),
            y: self.y.meet(&o.y),
        }
    }
    /// True when the rectangle holds a point.
    pub fn is_valid(&self) -> bool {
        self.x.lo <= self.x.hi + MEET_EPS && self.y.lo <= self.y.hi + MEET_EPS
    }
    fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x.lo - MEET_EPS
            && x <= self.x.hi + MEET_EPS
            && y >= self.y.lo - MEET_EPS
            && y <= self.y.hi + MEET_EPS
    }
    fn area_like(&self) -> f64 {
        (self.x.hi - self.x.lo).max(0.0) + (self.y.hi - self.y.lo).max(0.0)
    }
}

/// A group of geometries sharing one field, with the rectangle of centres that covers them all.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// Indices into the rectangle list.
    pub members: Vec<usize>,
    /// Common feasible rectangle of the members.
    pub rect: FRect,
}

/// Segment tree over compressed y: range add, global max with its leftmost position.
struct MaxTree {
    n: usize,
    max: Vec<i32>,
    arg: Vec<usize>,
    lazy: Vec<i32>,
}

impl MaxTree {
    fn new(n: usize) -> Self {
        let size = 4 * n.max(1);
        let mut t = MaxTree {
            n: n.max(1),
            max: vec![0; size],
            arg: vec![0; size],
            lazy: vec![0; size],
        };
        t.build(1, 0, t.n - 1);
        t
    }
    fn build(&mut self, node: usize, l: usize, r: usize) {
        self.arg[node] = l;
        if l < r {
            let m = (l + r) / 2;
            self.build(2 * node, l, m);
            self.build(2 * node + 1, m + 1, r);
        }
    }
    fn add(&mut self, a: usize, b: usize, v: i32) {
        self.add_rec(1, 0, self.n - 1, a, b, v);
    }
    fn add_rec(&mut self, node: usize, l: usize, r: usize, a: usize, b: usize, v: i32) {
        if b < l || r < a {
            return;
        }
        if a <= l && r <= b {
            self.max[node] += v;
            self.lazy[node] += v;
            return;
        }
        let m = (l + r) / 2;
        self.add_rec(2 * node, l, m, a, b, v);
        self.add_rec(2 * node + 1, m + 1, r, a, b, v);
        let (lm, rm) = (self.max[2 * node], self.max[2 * node + 1]);
        if lm >= rm {
            self.max[node] = lm + self.lazy[node];
            self.arg[node] = self.arg[2 * node];
        } else {
            self.max[node] = rm + self.lazy[node];
            self.arg[node] = self.arg[2 * node + 1];
        }
    }
}

/// The point lying in the most rectangles of `active` (indices into `rects`): (x, y, count).
fn deepest_point(rects: &[FRect], active: &[usize]) -> (f64, f64, usize) {
    let mut ys: Vec<f64> = active
        .iter()
        .flat_map(|&i| [rects[i].y.lo, rects[i].y.hi])
        .collect();
    ys.sort_by(f64::total_cmp);
    ys.dedup();
    let yi = |v: f64| ys.partition_point(|&q| q < v);
    // events: (x, kind 0 = add / 1 = remove, rect)
    let mut ev: Vec<(f64, u8, usize)> = Vec::with_capacity(active.len() * 2);
    for &i in active {
        ev.push((rects[i].x.lo, 0, i));
        ev.push((rects[i].x.hi, 1, i));
    }
    ev.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut tree = MaxTree::new(ys.len());
    let mut best = (0i32, 0.0, 0.0);
    let mut k = 0;
    while k < ev.len() {
        let x = ev[k].0;
        let mut j = k;
        while j < ev.len() && ev[j].0 == x && ev[j].1 == 0 {
            let r = &rects[ev[j].2];
            tree.add(yi(r.y.lo), yi(r.y.hi), 1);
            j += 1;
        }
        if tree.max[1] > best.0 {
            best = (tree.max[1], x, ys.get(tree.arg[1]).copied().unwrap_or(0.0));
        }
        while j < ev.len() && ev[j].0 == x {
            let r = &rects[ev[j].2];
            if ev[j].1 == 1 {
                tree.add(yi(r.y.lo), yi(r.y.hi), -1);
            } else {
                tree.add(yi(r.y.lo), yi(r.y.hi), 1);
            }
            j += 1;
        }
        k = j;
    }
    (best.1, best.2, best.0.max(0) as usize)
}

/// Greedy piercing of `rects[active]`: returns the groups.
fn greedy(rects: &[FRect], mut active: Vec<usize>, ctx: &JobCtx) -> Result<Vec<Group>, Cancelled> {
    let total = active.len();
    let mut groups = Vec::new();
    while !active.is_empty() {
        ctx.check()?;
        ctx.progress(
            "fields",
            (total - active.len()) as u64,
            total as u64,
            "set cover",
        );
        let (x, y, _) = deepest_point(rects, &active);
        let (mut hit, rest): (Vec<usize>, Vec<usize>) =
            active.iter().partition(|&&i| rects[i].contains(x, y));
        if hit.is_empty() {
            // numerical corner case: pierce the first rectangle on its own
            hit.push(active[0]);
        }
        let rest: Vec<usize> = rest.into_iter().filter(|i| !hit.contains(i)).collect();
        let rect = hit
            .iter()
            .skip(1)
            .fold(rects[hit[0]], |acc, &i| acc.meet(&rects[i]));
        groups.push(Group { members: hit, rect });
        active = rest;
    }
    Ok(groups)
}

fn group_rect(rects: &[FRect], members: &[usize]) -> Option<FRect> {
    let first = rects.get(*members.first()?)?;
    let r = members
        .iter()
        .skip(1)
        .fold(*first, |acc, &i| acc.meet(&rects[i]));
    r.is_valid().then_some(r)
}

/// Dissolves groups whose members all fit into other groups; repeats while it helps.
fn eliminate(rects: &[FRect], groups: &mut Vec<Group>, ctx: &JobCtx) -> Result<(), Cancelled> {
    loop {
        ctx.check()?;
        let mut order: Vec<usize> = (0..groups.len()).collect();
        order.sort_by_key(|&g| (groups[g].members.len(), g));
        let mut removed = None;
        for &f in &order {
            let mut trial: Vec<FRect> = groups.iter().map(|g| g.rect).collect();
            let mut moves: Vec<(usize, usize)> = Vec::new();
            let mut ok = true;
            for &m in &groups[f].members {
                let mut best: Option<(f64, usize)> = None;
                for (h, r) in trial.iter().enumerate() {
                    if h == f {
                        continue;
                    }
                    let meet = r.meet(&rects[m]);
                    if meet.is_valid() {
                        let score = meet.area_like();
                        if best.is_none_or(|(s, _)| score > s) {
                            best = Some((score, h));
                        }
                    }
                }
                match best {
                    Some((_, h)) => {
                        trial[h] = trial[h].meet(&rects[m]);
                        moves.push((m, h));
                    }
                    None => {
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                for (m, h) in moves {
                    groups[h].members.push(m);
                    groups[h].rect = trial[h];
                }
                removed = Some(f);
                break;
            }
        }
        match removed {
            Some(f) => {
                groups.remove(f);
            }
            None => return Ok(()),
        }
    }
}

/// Covers all `rects` with few groups (greedy piercing, then elimination), deterministic.
pub fn cover(rects: &[FRect], active: Vec<usize>, ctx: &JobCtx) -> Result<Vec<Group>, Cancelled> {
    let mut groups = greedy(rects, active, ctx)?;
    eliminate(rects, &mut groups, ctx)?;
    for g in &mut groups {
        g.members.sort_unstable();
        if let Some(r) = group_rect(rects, &g.members) {
            g.rect = r;
        }
    }
    Ok(groups)
}

/// A lower bound on the number of points piercing all `rects`: the size of a set of rectangles
/// no two of which meet (greedy, in two orders; the larger set counts).
pub fn lower_bound(rects: &[FRect]) -> usize {
    let pick = |order: &[usize]| -> usize {
        let mut chosen: Vec<FRect> = Vec::new();
        for &i in order {
            let r = rects[i];
            if chosen.iter().all(|c| !c.meet(&r).is_valid()) {
                chosen.push(r);
            }
        }
        chosen.len()
    };
    let mut by_hi: Vec<usize> = (0..rects.len()).collect();
    by_hi.sort_by(|&a, &b| {
        rects[a]
            .x
            .hi
            .total_cmp(&rects[b].x.hi)
            .then(rects[a].y.hi.total_cmp(&rects[b].y.hi))
    });
    let mut by_size: Vec<usize> = (0..rects.len()).collect();
    by_size.sort_by(|&a, &b| {
        rects[a]
            .area_like()
            .total_cmp(&rects[b].area_like())
            .then(a.cmp(&b))
    });
    pick(&by_hi).max(pick(&by_size))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(x0: f64, x1: f64, y0: f64, y1: f64) -> FRect {
        FRect {
            x: Span { lo: x0, hi: x1 },
            y: Span { lo: y0, hi: y1 },
        }
    }

    #[test]
    fn deepest_point_of_three() {
        let rects = [
            r(0.0, 2.0, 0.0, 2.0),
            r(1.0, 3.0, 1.0, 3.0),
            r(1.5, 4.0, -1.0, 1.2),
        ];
        let (x, y, c) = deepest_point(&rects, &[0, 1, 2]);
        assert_eq!(c, 3);
        assert!(rects.iter().all(|q| q.contains(x, y)));
    }

    #[test]
    fn cover_is_exact_on_separated_clusters_and_matches_bound() {
        // four clusters of five mutually overlapping rectangles
        let mut rects = Vec::new();
        for c in 0..4 {
            let (cx, cy) = ((c % 2) as f64 * 100.0, (c / 2) as f64 * 100.0);
            for k in 0..5 {
                let d = k as f64;
                rects.push(r(cx + d, cx + 10.0 + d, cy - d, cy + 10.0 - d));
            }
        }
        let groups = cover(&rects, (0..rects.len()).collect(), &JobCtx::default()).unwrap();
        assert_eq!(groups.len(), 4);
        assert_eq!(lower_bound(&rects), 4);
        for g in &groups {
            for &m in &g.members {
                assert!(rects[m].meet(&g.rect).is_valid());
            }
        }
    }

    #[test]
    fn elimination_removes_a_needless_group() {
        // greedy takes the deep middle first and then needs two more; two suffice
        let rects = [
            r(0.0, 1.0, 0.0, 1.0),
            r(0.5, 3.0, 0.0, 1.0),
            r(2.5, 3.5, 0.0, 1.0),
            r(0.9, 2.6, 0.0, 1.0),
        ];
        let groups = cover(&rects, vec![0, 1, 2, 3], &JobCtx::default()).unwrap();
        assert_eq!(groups.len(), 2);
    }
}
