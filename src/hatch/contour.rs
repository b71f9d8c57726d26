//! Contour-parallel fill: rings at inward offsets `0, s, 2s, …` of the offset region, plus gap
//! strokes where the rings leave something unmarked.
//!
//! With `Q_k` the region offset by `k·s` (ring `k` is its boundary) every point whose depth below
//! the offset boundary lies within `s/2` of a multiple of `s` is within `s/2` of a ring, except
//! where the next region `Q_{k+1}` has retreated (near the corners and ends of the medial axis,
//! and where a part is narrower than one spacing). Those gaps are the points of the half-step
//! region `H_k = Q_k ⊖ s/2` farther than `s/2` from `Q_{k+1}`; every such point is within `s/2` of
//! the boundary of `H_k`, so the pieces of that boundary farther than `s/2` from ring `k + 1` are
//! marked as gap strokes ([`super::gaps`]). `∂H_k` is computed only near the spots where it can
//! hold gaps ([`super::spots`]), or for the whole level when the spots cover much of it.

use super::elems::ElemTable;
use super::gaps::NextRing;
use super::region::Region;
use super::spots::{half_step_near_spots, MAX_BOX_SHARE};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

/// The rings and gap strokes of one offset level.
#[derive(Debug, Clone, Default)]
pub(crate) struct Level {
    /// Closed rings (boundary loops of `Q_k`).
    pub rings: Vec<Vec<Pt>>,
    /// Gap strokes between ring `k` and ring `k + 1`: (points, closed).
    pub gaps: Vec<(Vec<Pt>, bool)>,
}

/// Rings and gaps of `region` offset inward by `edge_mm`, `spacing` apart.
///
/// The offsets leapfrog in pairs: `Q_0` and `Q_1` are both offsets of `region` itself, then
/// each pair `Q_{2j}, Q_{2j+1}` comes from the deepest region known, `Q_{2j-1}`, offset by `s`
/// and `2s` side by side (erosions by discs compose, `Q_{k+m} = Q_k ⊖ m·s`). That halves the
/// longest chain of dependent offsets, and every offset starts from the smallest region at hand
/// (fewer vertices, and cavalier_contours' validation queries grow with the offset distance).
/// As soon as `Q_k` and `Q_{k+1}` exist a task finds the gaps of level `k` (flattening the rings
/// it needs once).
pub(crate) fn contour_levels(
    region: &Region,
    edge_mm: f64,
    spacing: f64,
    tol_mm: f64,
    max_levels: usize,
    ctx: &JobCtx,
) -> Result<Vec<Level>, Cancelled> {
    if region.is_empty() {
        return Ok(Vec::new());
    }
    let st = LevelState {
        regions: Mutex::new(Vec::new()),
        rings: Mutex::new(Vec::new()),
        gaps: Mutex::new(Vec::new()),
        first_empty: AtomicUsize::new(max_levels.saturating_add(1)),
        cancelled: AtomicBool::new(false),
        spacing,
        tol_mm,
    };
    rayon::scope(|sc| {
        let st = &st;
        sc.spawn(move |sc| {
            let q1 = region.offset(edge_mm + spacing);
            let q1 = (!q1.is_empty()).then(|| Arc::new(q1));
            if let Some(q1) = st.publish(sc, 1, q1) {
                st.leapfrog(sc, q1, ctx);
            }
        });
        let q0 = region.offset(edge_mm);
        let q0 = (!q0.is_empty()).then(|| Arc::new(q0));
        if let Some(q0) = st.publish(sc, 0, q0) {
            st.ring(0, &q0);
        }
    });
    if st.cancelled.load(Ordering::Relaxed) {
        return Err(Cancelled);
    }
    // levels 0 .. first empty region
    let n = st.first_empty.load(Ordering::Relaxed);
    // a lock is poisoned only by a panicking task, which rayon::scope has re-raised above: the
    // data is whole (every critical section is a resize or a store)
    let mut rings = st
        .rings
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner)
        .into_iter();
    let mut gaps = st
        .gaps
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner)
        .into_iter();
    let mut levels: Vec<Level> = (0..n)
        .map(|_| Level {
            rings: rings
                .next()
                .flatten()
                // `ring` fills a cell as soon as it makes it, so every cell here is filled
                .map(|r| match Arc::try_unwrap(r) {
                    Ok(cell) => cell.into_inner().unwrap_or_default(),
                    Err(shared) => shared.get().cloned().unwrap_or_default(),
                })
                .unwrap_or_default(),
            gaps: gaps.next().flatten().unwrap_or_default(),
        })
        .collect();
    while levels
        .last()
        .is_some_and(|l| l.rings.is_empty() && l.gaps.is_empty())
    {
        levels.pop();
    }
    Ok(levels)
}

/// What the chains and tasks of [`contour_levels`] share.
struct LevelState {
    /// `Q_k` by level once known: `Some(None)` when empty.
    regions: Slots<Option<Arc<Region>>>,
    /// Flattened rings by level, made once by whichever task needs them first.
    rings: Slots<Arc<OnceLock<Vec<Vec<Pt>>>>>,
    gaps: Slots<Vec<(Vec<Pt>, bool)>>,
    /// The lowest level known to be empty (or beyond the level limit).
    first_empty: AtomicUsize,
    cancelled: AtomicBool,
    spacing: f64,
    tol_mm: f64,
}

impl LevelState {
    /// From `q = Q_1`: `Q_{2j} = Q_{2j-1} ⊖ s` and `Q_{2j+1} = Q_{2j-1} ⊖ 2s` side by side (the
    /// latter is the base of the next pair) while the regions last.
    fn leapfrog<'s>(&'s self, sc: &rayon::Scope<'s>, mut q: Arc<Region>, ctx: &JobCtx) {
        let mut k = 1;
        loop {
            if ctx.check().is_err() {
                self.cancelled.store(true, Ordering::Relaxed);
                return;
            }
            if self.cancelled.load(Ordering::Relaxed) {
                return;
            }
            let first_empty = self.first_empty.load(Ordering::Relaxed);
            let offset = |m: f64, level: usize| {
                (level < first_empty)
                    .then(|| q.offset(m * self.spacing))
                    .filter(|n| !n.is_empty())
                    .map(Arc::new)
            };
            // both offsets of the pair before the level tasks they unlock
            let (even, odd) = rayon::join(|| offset(1.0, k + 1), || offset(2.0, k + 2));
            self.publish(sc, k + 1, even);
            k += 2;
            match self.publish(sc, k, odd) {
                Some(n) => q = n,
                None => return,
            }
        }
    }

    /// Records `Q_k` and starts the level tasks it completes; returns it back.
    fn publish<'s>(
        &'s self,
        sc: &rayon::Scope<'s>,
        k: usize,
        q: Option<Arc<Region>>,
    ) -> Option<Arc<Region>> {
        if q.is_none() {
            self.first_empty.fetch_min(k, Ordering::Relaxed);
        }
        let mut regions = self.regions.lock().unwrap_or_else(PoisonError::into_inner);
        if regions.len() <= k + 1 {
            regions.resize_with(k + 2, || None);
        }
        regions[k] = Some(q.clone());
        // level j needs Q_j (not empty) and Q_{j+1}
        for j in [k.checked_sub(1), Some(k)].into_iter().flatten() {
            if let (Some(Some(lo)), Some(hi)) = (&regions[j], &regions[j + 1]) {
                let (lo, hi) = (lo.clone(), hi.clone());
                sc.spawn(move |_| self.level(j, &lo, hi.as_deref()));
            }
        }
        q
    }

    /// Ring `k` flattened (made on first use).
    fn ring(&self, k: usize, q: &Region) -> Arc<OnceLock<Vec<Vec<Pt>>>> {
        let cell = {
            let mut rings = self.rings.lock().unwrap_or_else(PoisonError::into_inner);
            if rings.len() <= k {
                rings.resize_with(k + 1, || None);
            }
            rings[k].get_or_insert_with(Default::default).clone()
        };
        cell.get_or_init(|| q.flatten(self.tol_mm));
        cell
    }

    /// The gaps of level `k` (and ring `k + 1`, flattened on the way).
    fn level(&self, k: usize, q: &Region, next: Option<&Region>) {
        let (s, tol_mm) = (self.spacing, self.tol_mm);
        let next_ring = next.map(|n| self.ring(k + 1, n));
        let g = match (next, next_ring.as_ref().and_then(|r| r.get())) {
            (Some(n), Some(nr)) if !nr.is_empty() => {
                let ring_k = self.ring(k, q);
                let rk = ring_k.get().map(Vec::as_slice).unwrap_or_default();
                level_gaps(q, n, rk, nr, s, tol_mm, MAX_BOX_SHARE)
            }
            _ => q
                .offset_flattened_marked(s / 2.0, tol_mm, |_| false)
                .into_iter()
                .map(|(l, _)| (l, true))
                .collect(),
        };
        store(&self.gaps, k, g);
    }
}

/// The gap strokes between ring `k` (of `q`, flattened `ring_k`) and ring `k + 1` (of `next`,
/// flattened `ring_next`): from the half-step boundary near the spots, or from all of it when
/// the spots' boxes cover more than `max_share` of the level.
fn level_gaps(
    q: &Region,
    next: &Region,
    ring_k: &[Vec<Pt>],
    ring_next: &[Vec<Pt>],
    s: f64,
    tol_mm: f64,
    max_share: f64,
) -> Vec<(Vec<Pt>, bool)> {
    let at_s = ElemTable::new(next, q.frame.len_units(s));
    let mut g = Vec::new();
    match half_step_near_spots(q, ring_k, &at_s, s, tol_mm, max_share) {
        Some(h) => {
            // only ring k + 1 near the boxes is ever within reach of their pieces
            let reach = NextRing::near(ring_next, s, &h.boxes);
            for (l, closed) in &h.pieces {
                reach.far_runs(l, *closed, None, &mut g);
            }
        }
        None => full_gaps(q, next, &NextRing::new(ring_next, s), s, tol_mm, &mut g),
    }
    g
}

/// The gap strokes from the whole half-step boundary, skipping what provably lies `s/2` from
/// ring `k + 1`.
fn full_gaps(
    q: &Region,
    next: &Region,
    reach: &NextRing,
    s: f64,
    tol_mm: f64,
    out: &mut Vec<(Vec<Pt>, bool)>,
) {
    let at_half = ElemTable::new(next, q.frame.len_units(s / 2.0));
    for (l, skip) in q.offset_flattened_marked(s / 2.0, tol_mm, |e| at_half.covers(e)) {
        reach.far_runs(&l, true, Some(&skip), out);
    }
}

/// Results of parallel tasks by level.
type Slots<T> = Mutex<Vec<Option<T>>>;

/// Puts `v` into slot `k`.
fn store<T>(slots: &Slots<T>, k: usize, v: T) {
    // see contour_levels: a poisoned lock still holds whole data
    let mut s = slots.lock().unwrap_or_else(PoisonError::into_inner);
    if s.len() <= k {
        s.resize_with(k + 1, || None);
    }
    s[k] = Some(v);
}

#[cfg(test)]
mod tests {
    use super::super::region::{resolve, Frame};
    use super::*;
    use crate::document::FillRule;
    use crate::geom::polyline_length;

    fn disc(r: f64, n: usize) -> Vec<Pt> {
        (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                Pt::new(r * a.cos(), r * a.sin())
            })
            .collect()
    }

    #[test]
    fn square_rings_and_centre_gap() {
        // 10 × 10 square: rings at 0, 1, .., 4 mm in, half-sizes 5, 4, .., 1; the centre is
        // reached by the last ring (1 mm half-size: corners at √2 > 0.5 but the centre is 1 away)
        let sq = vec![
            Pt::new(0.0, 0.0),
            Pt::new(10.0, 0.0),
            Pt::new(10.0, 10.0),
            Pt::new(0.0, 10.0),
        ];
        let loops = resolve(&[sq], FillRule::EvenOdd);
        let r = Region::new(&loops, Frame::new(&loops, 1.0));
        let levels = contour_levels(&r, 0.0, 1.0, 1e-4, 100, &JobCtx::default()).unwrap();
        assert_eq!(levels.len(), 5);
        let ring_len: f64 = levels
            .iter()
            .flat_map(|l| &l.rings)
            .map(|p| polyline_length(p, true))
            .sum();
        assert!((ring_len - 4.0 * (10.0 + 8.0 + 6.0 + 4.0 + 2.0)).abs() < 1e-6);
        // corners of every ring leave wedges: gap strokes exist around the corners
        assert!(levels.iter().any(|l| !l.gaps.is_empty()));
        // the innermost level (2 × 2) has a 1 × 1 half-step square and no next ring: a closed gap
        let last = levels.last().unwrap();
        assert_eq!(last.gaps.len(), 1);
        assert!(last.gaps[0].1);
    }

    #[test]
    fn disc_rings_have_no_gaps_until_the_centre() {
        let loops = resolve(&[disc(5.3, 720)], FillRule::EvenOdd);
        let r = Region::new(&loops, Frame::new(&loops, 1.0));
        let levels = contour_levels(&r, 0.0, 1.0, 1e-4, 100, &JobCtx::default()).unwrap();
        // radii 5.3, 4.3, .., 0.3: six rings
        assert_eq!(levels.len(), 6);
        assert!(levels.iter().all(|l| l.gaps.is_empty()));
    }

    /// Every point of each stroke set within `tol` of the other set, and equal total lengths.
    fn assert_same_strokes(a: &[(Vec<Pt>, bool)], b: &[(Vec<Pt>, bool)], tol: f64, what: &str) {
        let segs = |v: &[(Vec<Pt>, bool)]| -> Vec<(Pt, Pt)> {
            let mut out = Vec::new();
            for (l, closed) in v {
                let m = l.len();
                let n = if *closed { m } else { m.saturating_sub(1) };
                out.extend((0..n).map(|i| (l[i], l[(i + 1) % m])));
            }
            out
        };
        let len =
            |v: &[(Vec<Pt>, bool)]| -> f64 { v.iter().map(|(l, c)| polyline_length(l, *c)).sum() };
        let (sa, sb) = (segs(a), segs(b));
        for (from, to, name) in [(&sa, &sb, "local"), (&sb, &sa, "full")] {
            for &(p, q) in from.iter() {
                for k in 0..=4 {
                    let x = p.plus(q.minus(p).scale(k as f64 / 4.0));
                    let d = to
                        .iter()
                        .map(|&(u, v)| crate::geom::point_segment_dist(x, u, v))
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        d <= tol,
                        "{what}: {name} gap point {x:?} is {d} from the other set"
                    );
                }
            }
        }
        let (la, lb) = (len(a), len(b));
        assert!(
            (la - lb).abs() <= 0.02 * la.max(lb) + 2.0 * tol,
            "{what}: lengths {la} vs {lb}"
        );
    }

    /// Gaps from the half-step boundary near the spots (forced even where the whole level would
    /// be cheaper) are the gaps from the whole half-step boundary, level by level.
    #[test]
    fn gaps_near_spots_equal_gaps_from_the_whole_half_step() {
        let mut shapes: Vec<(String, Vec<Vec<Pt>>, f64)> = Vec::new();
        for (file, s) in [
            ("tests/data/hatch/attachment1_graph1.csv", 0.7),
            ("tests/data/hatch/attachment2_graph2.csv", 0.4),
        ] {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
            let c = crate::bench::hatch::read_contours(&path).unwrap();
            shapes.push((file.into(), c, s));
        }
        // a star with a star hole and a square hole
        let star = crate::geom::star_polygon;
        let outer = star(
            Pt::new(0.0, 0.0),
            &[9.0, 5.0, 8.0, 4.5, 10.0, 6.0, 7.5, 3.5],
            0.3,
        );
        let hole = star(Pt::new(1.0, 0.5), &[2.0, 1.0, 2.5, 1.2, 1.8], 0.1);
        let sq = vec![
            Pt::new(-3.0, -3.0),
            Pt::new(-1.5, -3.0),
            Pt::new(-1.5, -1.5),
            Pt::new(-3.0, -1.5),
        ];
        shapes.push(("stars".into(), vec![outer, hole, sq], 0.3));
        for (name, c, s) in shapes {
            let loops = resolve(&c, FillRule::EvenOdd);
            let tol = s * 1e-3;
            let mut q = Region::new(&loops, Frame::new(&loops, s)).offset(s);
            let mut level = 0;
            while !q.is_empty() {
                let n = q.offset(s);
                let (rk, rn) = (q.flatten(tol), n.flatten(tol));
                if n.is_empty() || rn.is_empty() {
                    break;
                }
                let local = level_gaps(&q, &n, &rk, &rn, s, tol, f64::INFINITY);
                let mut full = Vec::new();
                full_gaps(&q, &n, &NextRing::new(&rn, s), s, tol, &mut full);
                assert_same_strokes(&local, &full, 0.02 * s, &format!("{name} level {level}"));
                q = n;
                level += 1;
            }
            assert!(level >= 3, "{name}: only {level} levels");
        }
    }
}
