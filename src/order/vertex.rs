//! Start-vertex choice for a fixed order: seed 000's VEA and an exact layered-graph DP.
//!
//! A closed geometry starts and ends at one of its vertices, an open one at either end. For a
//! fixed order the idle travel is `Σ ‖end(k) − start(k+1)‖`, which depends only on neighbouring
//! choices: the best choices are a shortest path through a layered graph (one layer per geometry,
//! one node per choice), found exactly by dynamic programming in `O(Σ kᵢ·kᵢ₊₁)`. Geometries with
//! more than [`MAX_CANDIDATES`] choices keep only the vertices nearest their neighbours.

use crate::document::{Geometry, Step};
use crate::geom::{point_segment_dist, Pt};
use crate::job::{Cancelled, JobCtx};

/// Choices per geometry considered by the DP before pruning.
pub const MAX_CANDIDATES: usize = 64;

fn ends(g: &Geometry, c: usize) -> (Pt, Pt) {
    g.ends(c)
}

fn set_choice(steps: &mut [Step], geometries: &[Geometry], k: usize, c: usize) {
    let s = steps[k];
    steps[k] = Step::from_choice(s.geometry, s.field, &geometries[s.geometry], c);
}

fn choice(steps: &[Step], geometries: &[Geometry], k: usize) -> usize {
    steps[k].choice(&geometries[steps[k].geometry])
}

/// Seed 000 §3.2.3: an initial vertex per geometry nearest the next geometry (the last one:
/// nearest the previous), then the vertex enhancement algorithm: every closed geometry takes the
/// vertex closest to the segment from the previous geometry's end to the next one's start, every
/// open one is reversed when that shortens the idle travel; repeated until nothing changes.
pub fn vea(geometries: &[Geometry], steps: &mut [Step], ctx: &JobCtx) -> Result<(), Cancelled> {
    let n = steps.len();
    if n == 0 {
        return Ok(());
    }
    // initial choice: nearest vertex to the neighbouring geometry's vertices
    for k in 0..n {
        let g = &geometries[steps[k].geometry];
        let other = if k + 1 < n {
            &geometries[steps[k + 1].geometry]
        } else if k > 0 {
            &geometries[steps[k - 1].geometry]
        } else {
            continue;
        };
        let mut best = (f64::INFINITY, 0);
        for c in 0..g.start_choices() {
            let q = if k + 1 < n {
                ends(g, c).1
            } else {
                ends(g, c).0
            };
            for &v in &other.points {
                let d = q.dist2(v);
                if d < best.0 {
                    best = (d, c);
                }
            }
        }
        set_choice(steps, geometries, k, best.1);
    }
    for _round in 0..100 {
        ctx.check()?;
        let mut changed = false;
        for k in 0..n {
            let g = &geometries[steps[k].geometry];
            let prev_end = (k > 0).then(|| {
                ends(
                    &geometries[steps[k - 1].geometry],
                    choice(steps, geometries, k - 1),
                )
                .1
            });
            let next_start = (k + 1 < n).then(|| {
                ends(
                    &geometries[steps[k + 1].geometry],
                    choice(steps, geometries, k + 1),
                )
                .0
            });
            let cur = choice(steps, geometries, k);
            let cost = |c: usize| -> f64 {
                let (s, e) = ends(g, c);
                if g.closed {
                    match (prev_end, next_start) {
                        (Some(a), Some(b)) => point_segment_dist(s, a, b),
                        (Some(a), None) => s.dist(a),
                        (None, Some(b)) => s.dist(b),
                        (None, None) => 0.0,
                    }
                } else {
                    prev_end.map_or(0.0, |a| a.dist(s)) + next_start.map_or(0.0, |b| e.dist(b))
                }
            };
            let mut best = (cost(cur), cur);
            for c in 0..g.start_choices() {
                let v = cost(c);
                if v < best.0 - 1e-12 {
                    best = (v, c);
                }
            }
            if best.1 != cur {
                set_choice(steps, geometries, k, best.1);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    Ok(())
}

/// Candidate choices of geometry `k`: all of them, or (when more than [`MAX_CANDIDATES`]) the
/// vertices nearest the neighbours' centroids plus the current choice.
fn candidates(geometries: &[Geometry], steps: &[Step], k: usize) -> Vec<usize> {
    let g = &geometries[steps[k].geometry];
    let m = g.start_choices();
    if m <= MAX_CANDIDATES {
        return (0..m).collect();
    }
    let mut out = vec![choice(steps, geometries, k)];
    let half = MAX_CANDIDATES / 2;
    for nb in [k.checked_sub(1), (k + 1 < steps.len()).then_some(k + 1)]
        .into_iter()
        .flatten()
    {
        let target = geometries[steps[nb].geometry].centroid();
        let mut by: Vec<(f64, usize)> = (0..m).map(|c| (ends(g, c).0.dist2(target), c)).collect();
        by.select_nth_unstable_by(half, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        out.extend(by[..half].iter().map(|x| x.1));
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Exact (within the candidate sets) best choices for the fixed order: a shortest path through
/// the layered graph. Returns the idle travel of the result, mm.
pub fn optimal_vertices(
    geometries: &[Geometry],
    steps: &mut [Step],
    ctx: &JobCtx,
) -> Result<f64, Cancelled> {
    optimal_vertices_between(geometries, steps, None, None, ctx)
}

/// [`optimal_vertices`] for a run of steps inside a longer order whose neighbours keep their
/// choices: the idle travel counted includes the move from `before` (the previous stroke's
/// end) to the run's first start and from the run's last end to `after` (the next stroke's
/// start). Exact for the run given its neighbours (within the candidate sets); returns that
/// idle travel, mm.
pub fn optimal_vertices_between(
    geometries: &[Geometry],
    steps: &mut [Step],
    before: Option<Pt>,
    after: Option<Pt>,
    ctx: &JobCtx,
) -> Result<f64, Cancelled> {
    let n = steps.len();
    if n == 0 {
        return Ok(before.zip(after).map_or(0.0, |(a, b)| a.dist(b)));
    }
    let cands: Vec<Vec<usize>> = (0..n).map(|k| candidates(geometries, steps, k)).collect();
    let g0 = &geometries[steps[0].geometry];
    let mut cost: Vec<f64> = cands[0]
        .iter()
        .map(|&c| before.map_or(0.0, |a| a.dist(ends(g0, c).0)))
        .collect();
    let mut back: Vec<Vec<u32>> = Vec::with_capacity(n);
    back.push(Vec::new());
    for k in 1..n {
        if k % 1024 == 0 {
            ctx.check()?;
        }
        let (gp, gc) = (
            &geometries[steps[k - 1].geometry],
            &geometries[steps[k].geometry],
        );
        let prev_ends: Vec<Pt> = cands[k - 1].iter().map(|&c| ends(gp, c).1).collect();
        let mut next = vec![f64::INFINITY; cands[k].len()];
        let mut arg = vec![0u32; cands[k].len()];
        for (b, &c) in cands[k].iter().enumerate() {
            let s = ends(gc, c).0;
            for (a, &pe) in prev_ends.iter().enumerate() {
                let v = cost[a] + pe.dist(s);
                if v < next[b] {
                    next[b] = v;
                    arg[b] = a as u32;
                }
            }
        }
        cost = next;
        back.push(arg);
    }
    if let Some(b) = after {
        let gl = &geometries[steps[n - 1].geometry];
        for (v, &c) in cost.iter_mut().zip(&cands[n - 1]) {
            *v += ends(gl, c).1.dist(b);
        }
    }
    let (mut best_b, best) = cost
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))
        .map(|(b, &v)| (b, v))
        .unwrap_or((0, 0.0));
    for k in (0..n).rev() {
        let c = cands[k][best_b];
        set_choice(steps, geometries, k, c);
        if k > 0 {
            best_b = back[k][best_b] as usize;
        }
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::Source;
    use crate::order::metrics::idle_mm;

    fn poly(pts: &[(f64, f64)], closed: bool) -> Geometry {
        Geometry::new(
            pts.iter().map(|&(x, y)| Pt::new(x, y)).collect(),
            closed,
            Source::default(),
        )
    }

    fn shapes(seed: u64) -> Vec<Geometry> {
        let mut x = seed.wrapping_add(3);
        let mut r = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 * 50.0
        };
        (0..5)
            .map(|k| {
                let n = 2 + k % 3;
                let pts: Vec<(f64, f64)> = (0..n).map(|_| (r(), r())).collect();
                poly(&pts, k % 2 == 0)
            })
            .collect()
    }

    fn brute(geometries: &[Geometry], steps: &mut Vec<Step>, k: usize, best: &mut f64) {
        if k == steps.len() {
            *best = best.min(idle_mm(geometries, steps));
            return;
        }
        for c in 0..geometries[steps[k].geometry].start_choices() {
            set_choice(steps, geometries, k, c);
            brute(geometries, steps, k + 1, best);
        }
    }

    #[test]
    fn dp_is_optimal_against_brute_force_and_beats_vea() {
        for seed in 0..20 {
            let gs = shapes(seed);
            let mut steps: Vec<Step> = (0..gs.len())
                .map(|g| Step::from_choice(g, 0, &gs[g], 0))
                .collect();
            let mut best = f64::INFINITY;
            brute(&gs, &mut steps.clone(), 0, &mut best);
            let mut v = steps.clone();
            vea(&gs, &mut v, &JobCtx::default()).unwrap();
            let dp = optimal_vertices(&gs, &mut steps, &JobCtx::default()).unwrap();
            assert!(
                (dp - best).abs() < 1e-9,
                "seed {seed}: dp {dp} brute {best}"
            );
            assert!((idle_mm(&gs, &steps) - dp).abs() < 1e-9);
            assert!(dp <= idle_mm(&gs, &v) + 1e-9);
        }
    }

    #[test]
    fn an_anchored_window_is_optimal_given_its_neighbours() {
        for seed in 0..20 {
            let gs = shapes(seed);
            // the middle three strokes are re-optimised; the first and last keep their choices
            let mut steps: Vec<Step> = (0..gs.len())
                .map(|g| Step::from_choice(g, 0, &gs[g], g % gs[g].start_choices()))
                .collect();
            let end_of = |s: &Step| gs[s.geometry].ends(s.choice(&gs[s.geometry]));
            let (before, after) = (end_of(&steps[0]).1, end_of(&steps[4]).0);
            let mut best = f64::INFINITY;
            let mut middle = steps[1..4].to_vec();
            let mut probe = steps.clone();
            brute_window(&gs, &mut probe, &mut middle, 0, &mut best);
            let got = optimal_vertices_between(
                &gs,
                &mut steps[1..4],
                Some(before),
                Some(after),
                &JobCtx::default(),
            )
            .unwrap();
            let whole = idle_mm(&gs, &steps);
            assert!((got - whole).abs() < 1e-9, "seed {seed}: {got} vs {whole}");
            assert!(
                (whole - best).abs() < 1e-9,
                "seed {seed}: {whole} vs brute {best}"
            );
        }
    }

    /// Brute force over the choices of `middle` (steps 1..4 of `all`), scoring the whole order.
    fn brute_window(
        gs: &[Geometry],
        all: &mut Vec<Step>,
        middle: &mut Vec<Step>,
        k: usize,
        best: &mut f64,
    ) {
        if k == middle.len() {
            all[1..4].copy_from_slice(middle);
            *best = best.min(idle_mm(gs, all));
            return;
        }
        for c in 0..gs[middle[k].geometry].start_choices() {
            set_choice(middle, gs, k, c);
            brute_window(gs, all, middle, k + 1, best);
        }
    }

    #[test]
    fn vea_picks_the_vertex_between_neighbours() {
        let gs = vec![
            poly(&[(0.0, 0.0), (1.0, 0.0)], false),
            poly(&[(11.0, 8.0), (12.0, -6.0), (10.0, 2.0)], true),
            poly(&[(20.0, 0.0), (21.0, 0.0)], false),
        ];
        let mut steps: Vec<Step> = (0..3).map(|g| Step::from_choice(g, 0, &gs[g], 0)).collect();
        vea(&gs, &mut steps, &JobCtx::default()).unwrap();
        // the triangle starts at its vertex nearest the line from (1,0) to (20,0)
        assert_eq!(steps[1].start_vertex, 2);
    }
}
