//! Set cover for `--fields auto`: the fewest fields whose squares hold every geometry.
//!
//! A field covers a geometry exactly when its centre lies in the geometry's *feasible rectangle*
//! (the centres from which the square holds the geometry's bounding box, clipped to the base
//! stroke). Covering geometries is therefore *piercing* their feasible rectangles with the fewest
//! points, and a group of geometries fits one field exactly when its rectangles have a common
//! point (axis-parallel rectangles: pairwise overlap in x and in y suffices). So:
//!
//! 1. greedy piercing: repeatedly the point in the most not-yet-pierced rectangles, found by a
//!    sweep over x with a segment tree over y. The sweep runs per cell of a grid of about the
//!    rectangles' size, and after each field only the cells its rectangles touched are swept
//!    again (a heap keeps every cell's best point), so a field costs `O(k log k)` for the `k`
//!    rectangles near it instead of a sweep over all of them;
//! 2. elimination: try to dissolve each group (smallest first) by moving its members into other
//!    groups whose common rectangle still meets theirs; repeat while it removes groups;
//! 3. a lower bound: rectangles that pairwise do not meet need one field each (a greedy maximal
//!    set of such rectangles, taken in two orders, the larger counts).

use super::reach::Span;
use crate::geom::grid::{expand, BucketGrid, Range1, SCAN_MAX_ITEMS};
use crate::job::{Cancelled, JobCtx};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

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
/// Margin of grid look-ups around a point or rectangle, mm (well above [`MEET_EPS`], so that
/// a look-up returns every rectangle the exact tests could accept).
const LOOKUP_MARGIN_MM: f64 = 1e-6;

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
    fn x_range(&self) -> Range1 {
        (self.x.lo, self.x.hi)
    }
    fn y_range(&self) -> Range1 {
        (self.y.lo, self.y.hi)
    }
}

/// Cell side of the greedy piercing's grid, in sides of the largest rectangle: a field's
/// rectangles share a point, so they touch at most 2 × 2 cells, and on instances with few
/// fields per stroke the grid has so few cells that the sweep per cell costs about what one
/// sweep over all rectangles did.
const GREEDY_CELL_PER_RECT: f64 = 2.0;

/// Fewest cells worth a grid in the greedy piercing; below, one cell (a sweep over all
/// remaining rectangles per field, as without the grid).
const GREEDY_MIN_CELLS: usize = 64;

/// An empty grid over the rectangles `rects[ids]`, with cells `scale` times as large as the
/// largest of them (so that each rectangle touches at most 2 × 2 cells).
fn grid_for(rects: &[FRect], ids: impl Iterator<Item = usize>, scale: f64) -> BucketGrid {
    let (mut x, mut y) = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    let mut cell_mm = [0.0f64; 2];
    for i in ids {
        let r = &rects[i];
        x = (x.0.min(r.x.lo).min(r.x.hi), x.1.max(r.x.lo).max(r.x.hi));
        y = (y.0.min(r.y.lo).min(r.y.hi), y.1.max(r.y.lo).max(r.y.hi));
        cell_mm[0] = cell_mm[0].max((r.x.hi - r.x.lo).abs());
        cell_mm[1] = cell_mm[1].max((r.y.hi - r.y.lo).abs());
    }
    BucketGrid::new(x, y, [cell_mm[0] * scale, cell_mm[1] * scale])
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
    /// Largest value on leaves `a..=b` with its leftmost leaf (`None` for an empty range).
    fn query(&self, a: usize, b: usize) -> Option<(i32, usize)> {
        self.query_rec(1, 0, self.n - 1, a, b)
    }
    fn query_rec(
        &self,
        node: usize,
        l: usize,
        r: usize,
        a: usize,
        b: usize,
    ) -> Option<(i32, usize)> {
        if b < l || r < a || a > b {
            return None;
        }
        if a <= l && r <= b {
            return Some((self.max[node], self.arg[node]));
        }
        let m = (l + r) / 2;
        let best = match (
            self.query_rec(2 * node, l, m, a, b),
            self.query_rec(2 * node + 1, m + 1, r, a, b),
        ) {
            (Some(lt), Some(rt)) => Some(if lt.0 >= rt.0 { lt } else { rt }),
            (lt, None) => lt,
            (None, rt) => rt,
        };
        best.map(|(v, i)| (v + self.lazy[node], i))
    }
}

/// The sweep over `rects[active]`: the sorted distinct y edges, and the x events
/// `(x, 0 = add | 1 = remove, rect)` sorted by x, adds before removes, then by rectangle.
fn sweep_setup(rects: &[FRect], active: &[usize]) -> (Vec<f64>, Vec<(f64, u8, usize)>) {
    let mut ys: Vec<f64> = active
        .iter()
        .flat_map(|&i| [rects[i].y.lo, rects[i].y.hi])
        .collect();
    ys.sort_by(f64::total_cmp);
    ys.dedup();
    let mut ev: Vec<(f64, u8, usize)> = Vec::with_capacity(active.len() * 2);
    for &i in active {
        ev.push((rects[i].x.lo, 0, i));
        ev.push((rects[i].x.hi, 1, i));
    }
    ev.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    (ys, ev)
}

/// The point lying in the most rectangles of `active` (indices into `rects`): (x, y, count).
///
/// Among the deepest points it is the one with the smallest x, then the smallest y (both are
/// sides of rectangles holding it). The reference for [`deepest_point_in_cell`].
fn deepest_point(rects: &[FRect], active: &[usize]) -> (f64, f64, usize) {
    let (ys, ev) = sweep_setup(rects, active);
    let yi = |v: f64| ys.partition_point(|&q| q < v);
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

/// [`deepest_point`] restricted to one cell of `grid` (column `col`, row `row`): the deepest
/// candidate point of the sweep over `rects[active]` (x at a rectangle's side, y at a
/// rectangle's edge) lying in that cell, then the one with the smallest x, then the smallest y:
/// (count, x, y), `None` when no such point lies in a rectangle. Every rectangle holding a point
/// of the cell must be in `active`; then the best of all cells' answers is exactly
/// [`deepest_point`]'s answer on all the rectangles (the sweep is the same, a point's count is
/// the same in its cell, and the overall deepest point is a candidate of its own cell).
fn deepest_point_in_cell(
    rects: &[FRect],
    active: &[usize],
    grid: &BucketGrid,
    col: usize,
    row: usize,
) -> Option<(i32, f64, f64)> {
    let (ys, ev) = sweep_setup(rects, active);
    // the leaves whose y lies in this row (contiguous: the row is monotone in y)
    let first_leaf = ys.partition_point(|&v| grid.row(v) < row);
    let end_leaf = ys.partition_point(|&v| grid.row(v) <= row);
    if first_leaf >= end_leaf {
        return None;
    }
    let yi = |v: f64| ys.partition_point(|&q| q < v);
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
        if grid.col(x) == col {
            if let Some((depth, leaf)) = tree.query(first_leaf, end_leaf - 1) {
                if depth > best.0 {
                    best = (depth, x, ys.get(leaf).copied().unwrap_or(0.0));
                }
            }
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
    (best.0 > 0).then_some(best)
}

/// A cell's deepest point in the heap of [`greedy`]: deeper first, then smaller x, then smaller
/// y (the order of [`deepest_point`]); `version` tells whether the cell changed since.
#[derive(Debug, Clone, Copy)]
struct CellBest {
    depth: i32,
    x: f64,
    y: f64,
    cell: usize,
    version: u32,
}

impl Ord for CellBest {
    fn cmp(&self, o: &Self) -> Ordering {
        self.depth
            .cmp(&o.depth)
            .then(o.x.total_cmp(&self.x))
            .then(o.y.total_cmp(&self.y))
            .then(o.cell.cmp(&self.cell))
            .then(self.version.cmp(&o.version))
    }
}

impl PartialOrd for CellBest {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl PartialEq for CellBest {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}

impl Eq for CellBest {}

/// Greedy piercing of `rects[active]`: repeatedly the deepest point of the rectangles not yet
/// pierced ([`deepest_point`]), grouping the rectangles that hold it (in `active`'s order).
/// The deepest point is kept per grid cell and recomputed only in the cells whose rectangles
/// changed; the groups are exactly [`greedy_reference`]'s.
fn greedy(rects: &[FRect], active: Vec<usize>, ctx: &JobCtx) -> Result<Vec<Group>, Cancelled> {
    greedy_on_grid(rects, active, GREEDY_CELL_PER_RECT, GREEDY_MIN_CELLS, ctx)
}

/// [`greedy`] with cells `cell_per_rect` times the largest rectangle, or one cell when that
/// makes fewer than `min_cells`.
fn greedy_on_grid(
    rects: &[FRect],
    active: Vec<usize>,
    cell_per_rect: f64,
    min_cells: usize,
    ctx: &JobCtx,
) -> Result<Vec<Group>, Cancelled> {
    let total = active.len();
    let mut alive = vec![false; rects.len()];
    let mut rank = vec![0usize; rects.len()];
    for (k, &i) in active.iter().enumerate() {
        if alive[i] {
            // a repeated index: the per-rectangle bookkeeping below does not apply
            return greedy_reference(rects, active, ctx);
        }
        alive[i] = true;
        rank[i] = k;
    }
    let mut grid = grid_for(rects, active.iter().copied(), cell_per_rect);
    if grid.len() < min_cells {
        // rectangles touching several of a few cells would be swept several times over
        grid = BucketGrid::single();
    }
    for &i in &active {
        grid.insert(i, rects[i].x_range(), rects[i].y_range());
    }
    let cells = grid.len();
    let evaluate =
        |grid: &mut BucketGrid, alive: &[bool], cell: usize| -> Option<(i32, f64, f64)> {
            grid.bucket_mut(cell).retain(|&i| alive[i]);
            let (col, row) = grid.col_row(cell);
            let members = grid.bucket(cell);
            if members.is_empty() {
                return None;
            }
            deepest_point_in_cell(rects, members, grid, col, row)
        };
    let mut version = vec![0u32; cells];
    let mut heap: BinaryHeap<CellBest> = BinaryHeap::new();
    for cell in 0..cells {
        if let Some((depth, x, y)) = evaluate(&mut grid, &alive, cell) {
            heap.push(CellBest {
                depth,
                x,
                y,
                cell,
                version: 0,
            });
        }
    }
    let mut groups = Vec::new();
    let mut left = total;
    let mut first = 0;
    let mut dirty = Vec::new();
    let mut is_dirty = vec![false; cells];
    while left > 0 {
        ctx.check()?;
        ctx.progress("fields", (total - left) as u64, total as u64, "set cover");
        let (x, y) = loop {
            match heap.peek() {
                Some(b) if b.version != version[b.cell] => {
                    heap.pop();
                }
                Some(b) => break (b.x, b.y),
                None => break (0.0, 0.0),
            }
        };
        let mut hit: Vec<usize> = Vec::new();
        let cells_near = grid.cells_of(
            expand((x, x), LOOKUP_MARGIN_MM),
            expand((y, y), LOOKUP_MARGIN_MM),
        );
        for cell in cells_near {
            hit.extend(
                grid.bucket(cell)
                    .iter()
                    .copied()
                    .filter(|&i| alive[i] && rects[i].contains(x, y)),
            );
        }
        // a rectangle in several of the cells comes once per cell
        hit.sort_unstable_by_key(|&i| rank[i]);
        hit.dedup();
        if hit.is_empty() {
            // numerical corner case: pierce the first rectangle on its own
            while first < total && !alive[active[first]] {
                first += 1;
            }
            if let Some(&i) = active.get(first) {
                hit.push(i);
            }
        }
        let Some(&head) = hit.first() else {
            break;
        };
        let rect = hit
            .iter()
            .skip(1)
            .fold(rects[head], |acc, &i| acc.meet(&rects[i]));
        for &i in &hit {
            alive[i] = false;
            for cell in grid.cells_of(rects[i].x_range(), rects[i].y_range()) {
                if !is_dirty[cell] {
                    is_dirty[cell] = true;
                    dirty.push(cell);
                }
            }
        }
        left -= hit.len();
        for cell in dirty.drain(..) {
            is_dirty[cell] = false;
            version[cell] += 1;
            if let Some((depth, x, y)) = evaluate(&mut grid, &alive, cell) {
                heap.push(CellBest {
                    depth,
                    x,
                    y,
                    cell,
                    version: version[cell],
                });
            }
        }
        groups.push(Group { members: hit, rect });
    }
    Ok(groups)
}

/// Greedy piercing of `rects[active]` with a sweep over all remaining rectangles per field:
/// the definition [`greedy`] follows (and its fallback when `active` repeats an index).
fn greedy_reference(
    rects: &[FRect],
    mut active: Vec<usize>,
    ctx: &JobCtx,
) -> Result<Vec<Group>, Cancelled> {
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
///
/// Groups are tried smallest first; each member moves to the group whose (trial) common
/// rectangle keeps the most room with it, the first such group on ties. The groups a member
/// can join are looked up in a grid over the group rectangles (which only shrink here).
fn eliminate(rects: &[FRect], groups: &mut Vec<Group>, ctx: &JobCtx) -> Result<(), Cancelled> {
    // cells of the members' size: a member's look-up touches at most 2 × 2 of them (few
    // groups are scanned instead)
    let grid = (groups.len() > SCAN_MAX_ITEMS).then(|| {
        let members = groups.iter().flat_map(|g| g.members.iter().copied());
        let mut grid = grid_for(rects, members, 1.0);
        for (h, g) in groups.iter().enumerate() {
            grid.insert(h, g.rect.x_range(), g.rect.y_range());
        }
        grid
    });
    // groups keep their index until the end (a dissolved one is marked dead), so that index
    // order, which decides ties, is the order of the remaining groups
    let mut alive = vec![true; groups.len()];
    // every live group's rectangle, changed only while a dissolution is tried
    let mut trial: Vec<FRect> = groups.iter().map(|g| g.rect).collect();
    let mut saved: Vec<(usize, FRect)> = Vec::new();
    let mut moves: Vec<(usize, usize)> = Vec::new();
    let mut near = Vec::new();
    loop {
        ctx.check()?;
        let mut order: Vec<usize> = (0..groups.len()).filter(|&g| alive[g]).collect();
        order.sort_by_key(|&g| (groups[g].members.len(), g));
        let mut removed = None;
        for &f in &order {
            moves.clear();
            let mut ok = true;
            for &m in &groups[f].members {
                let r = &rects[m];
                match &grid {
                    Some(grid) => grid.query(
                        expand(r.x_range(), LOOKUP_MARGIN_MM),
                        expand(r.y_range(), LOOKUP_MARGIN_MM),
                        &mut near,
                    ),
                    None => {
                        near.clear();
                        near.extend(0..groups.len());
                    }
                }
                let mut best: Option<(f64, usize)> = None;
                for &h in &near {
                    if h == f || !alive[h] {
                        continue;
                    }
                    let meet = trial[h].meet(r);
                    if meet.is_valid() {
                        let score = meet.area_like();
                        if best.is_none_or(|(s, _)| score > s) {
                            best = Some((score, h));
                        }
                    }
                }
                match best {
                    Some((_, h)) => {
                        if saved.iter().all(|&(k, _)| k != h) {
                            saved.push((h, trial[h]));
                        }
                        trial[h] = trial[h].meet(r);
                        moves.push((m, h));
                    }
                    None => {
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                saved.clear();
                for &(m, h) in &moves {
                    groups[h].members.push(m);
                    groups[h].rect = trial[h];
                }
                removed = Some(f);
                break;
            }
            for (h, r) in saved.drain(..) {
                trial[h] = r;
            }
        }
        match removed {
            Some(f) => alive[f] = false,
            None => break,
        }
    }
    let mut k = 0;
    groups.retain(|_| {
        k += 1;
        alive[k - 1]
    });
    Ok(())
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
/// no two of which meet (greedy, in two orders; the larger set counts). Once many are chosen,
/// the chosen rectangles are looked up in a grid.
pub fn lower_bound(rects: &[FRect]) -> usize {
    let pick = |order: &[usize]| -> usize {
        let mut grid: Option<BucketGrid> = None;
        let mut chosen: Vec<FRect> = Vec::new();
        let mut near = Vec::new();
        for &i in order {
            let r = rects[i];
            let free = match &grid {
                Some(grid) => {
                    grid.query(
                        expand(r.x_range(), LOOKUP_MARGIN_MM),
                        expand(r.y_range(), LOOKUP_MARGIN_MM),
                        &mut near,
                    );
                    near.iter().all(|&c| !chosen[c].meet(&r).is_valid())
                }
                None => chosen.iter().all(|c| !c.meet(&r).is_valid()),
            };
            if free {
                if let Some(grid) = &mut grid {
                    grid.insert(chosen.len(), r.x_range(), r.y_range());
                }
                chosen.push(r);
                if grid.is_none() && chosen.len() > SCAN_MAX_ITEMS {
                    let mut g = grid_for(rects, 0..rects.len(), 1.0);
                    for (k, c) in chosen.iter().enumerate() {
                        g.insert(k, c.x_range(), c.y_range());
                    }
                    grid = Some(g);
                }
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
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Dissolves groups whose members all fit into other groups; repeats while it helps.
    fn eliminate_reference(
        rects: &[FRect],
        groups: &mut Vec<Group>,
        ctx: &JobCtx,
    ) -> Result<(), Cancelled> {
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

    /// A lower bound on the number of points piercing all `rects`: the size of a set of rectangles
    /// no two of which meet (greedy, in two orders; the larger set counts).
    fn lower_bound_reference(rects: &[FRect]) -> usize {
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

    /// Random rectangles on a coarse lattice (many shared sides, so ties are frequent), some
    /// degenerate (points, segments) and some inverted by less than the slack.
    fn random_rects(rng: &mut ChaCha8Rng, n: usize, extent: i32, size: i32) -> Vec<FRect> {
        (0..n)
            .map(|_| {
                let c = |rng: &mut ChaCha8Rng| rng.random_range(0..extent) as f64 * 0.25;
                let (x, y) = (c(rng), c(rng));
                let (w, h) = (
                    rng.random_range(0..=size) as f64 * 0.25,
                    rng.random_range(0..=size) as f64 * 0.25,
                );
                let mut q = r(x, x + w, y, y + h);
                match rng.random_range(0..20) {
                    0 => q.x.lo = q.x.hi + 0.5 * MEET_EPS,
                    1 => q.y.hi = q.y.lo - 0.5 * MEET_EPS,
                    _ => {}
                }
                q
            })
            .collect()
    }

    #[test]
    fn greedy_by_cells_matches_the_full_sweep() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let ctx = JobCtx::default();
        for round in 0..60 {
            let n = rng.random_range(1..250);
            let extent = rng.random_range(4..400);
            let size = rng.random_range(0..40);
            let rects = random_rects(&mut rng, n, extent, size);
            // a subset in a scrambled order
            let mut active: Vec<usize> = (0..n).filter(|_| rng.random_range(0..10) > 0).collect();
            for k in (1..active.len()).rev() {
                active.swap(k, rng.random_range(0..=k));
            }
            let slow = greedy_reference(&rects, active.clone(), &ctx).unwrap();
            for (scale, min_cells) in [(0.5, 0), (1.0, 0), (3.0, 0)] {
                let on_grid = greedy_on_grid(&rects, active.clone(), scale, min_cells, &ctx);
                assert_eq!(on_grid.unwrap(), slow, "round {round}, cells {scale}");
            }
            let fast = greedy(&rects, active.clone(), &ctx).unwrap();
            assert_eq!(fast, slow, "round {round}");
            let (mut fast, mut slow) = (fast, slow);
            eliminate(&rects, &mut fast, &ctx).unwrap();
            eliminate_reference(&rects, &mut slow, &ctx).unwrap();
            assert_eq!(fast, slow, "round {round}");
            assert_eq!(
                lower_bound(&rects),
                lower_bound_reference(&rects),
                "round {round}"
            );
        }
    }

    #[test]
    fn repeated_indices_fall_back_to_the_full_sweep() {
        let rects = [r(0.0, 2.0, 0.0, 2.0), r(1.0, 3.0, 1.0, 3.0)];
        let ctx = JobCtx::default();
        assert_eq!(
            greedy(&rects, vec![1, 0, 1], &ctx).unwrap(),
            greedy_reference(&rects, vec![1, 0, 1], &ctx).unwrap()
        );
    }
}
