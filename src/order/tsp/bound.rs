//! A lower bound on the shortest open path through points: the Held–Karp 1-tree bound with
//! subgradient ascent, so that a path's distance from the optimum can be measured here without
//! an external solver (LKH and Concorde are measuring tools with licences we cannot ship).
//!
//! **The bound.** Add a dummy node `D` at cost 0 from and to every point: an open path through
//! the `n` points is a Hamiltonian cycle through the `n + 1` nodes of equal cost. For any
//! penalties `π` on the points, give the edge `i–j` the cost `c(i, j) + π_i + π_j` and `D–i` the
//! cost `π_i`. A cycle's penalised cost is its cost plus `2 Σ π` (every point has degree 2), and
//! a cycle is a *1-tree* (a spanning tree of the points plus two edges at `D`), so
//!
//! `L(π) = MST_π(points) + (the two least π_i) − 2 Σ π ≤ optimum`
//!
//! for every `π`. The minimum spanning tree is taken over the **complete** graph (Prim, `O(n²)`
//! per evaluation): a tree over a sparse candidate graph could be heavier than the true one and
//! the bound would no longer be one.
//!
//! **The ascent.** `π_i += t (d_i − 2)` with `d_i` the degree of point `i` in the 1-tree and the
//! Polyak step `t = μ (U − L) / Σ (d_i − 2)²` towards an upper bound `U` (a path's length); `μ`
//! starts at 2 and halves after [`STALL_ITERATIONS`] evaluations without a better bound. Every
//! `L(π)` is a valid bound, so the best one seen is returned however early the ascent stops.
//! When every degree is 2 the 1-tree is a path and `L` is the optimum.

use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};

/// Evaluations without a better bound after which the step factor `μ` halves.
const STALL_ITERATIONS: usize = 10;

/// The ascent stops when the step factor falls below this: steps are then far below a µm.
const MU_MIN: f64 = 1e-4;

/// The Held–Karp lower bound on the shortest open path through `points`, mm, after at most
/// `iterations` 1-tree evaluations of `O(n²)` each; `upper_mm` is the length of a known path
/// (it sizes the steps, not the result). Fewer than two points: 0.
pub fn held_karp_open_path(
    points: &[Pt],
    upper_mm: f64,
    iterations: usize,
    ctx: &JobCtx,
) -> Result<f64, Cancelled> {
    let n = points.len();
    if n < 2 {
        return Ok(0.0);
    }
    let mut penalty = vec![0.0; n];
    let mut degree = vec![0u32; n];
    let mut best = f64::NEG_INFINITY;
    let mut mu = 2.0;
    let mut stall = 0;
    for _ in 0..iterations {
        ctx.check()?;
        let bound = one_tree(points, &penalty, &mut degree, ctx)?;
        if bound > best {
            best = bound;
            stall = 0;
        } else {
            stall += 1;
            if stall >= STALL_ITERATIONS {
                mu /= 2.0;
                stall = 0;
            }
        }
        let norm2: f64 = degree.iter().map(|&d| (f64::from(d) - 2.0).powi(2)).sum();
        if norm2 == 0.0 || mu < MU_MIN {
            // every degree 2: the 1-tree is an optimal path
            break;
        }
        let step = mu * (upper_mm - bound).max(0.0) / norm2;
        for (p, &d) in penalty.iter_mut().zip(&degree) {
            *p += step * (f64::from(d) - 2.0);
        }
    }
    Ok(best.max(0.0))
}

/// Points added to the tree between two polls of the cancel token (each scans the points not
/// yet in the tree: at most 256 · 10⁵ distances, some tens of ms, between polls at 10⁵ points).
const POLL_EVERY: usize = 256;

/// `L(π)` (see the module docs) and the degree of every point in the minimum 1-tree.
fn one_tree(
    points: &[Pt],
    penalty: &[f64],
    degree: &mut [u32],
    ctx: &JobCtx,
) -> Result<f64, Cancelled> {
    let n = points.len();
    degree.iter_mut().for_each(|d| *d = 0);
    // Prim over the complete graph; `rest` holds the points not yet in the tree
    let mut key = vec![f64::INFINITY; n];
    let mut parent = vec![0usize; n];
    let mut rest: Vec<usize> = (1..n).collect();
    let mut tree = 0.0;
    let mut u = 0;
    while !rest.is_empty() {
        if rest.len() % POLL_EVERY == 0 {
            ctx.check()?;
        }
        let mut pick = 0;
        for (k, &v) in rest.iter().enumerate() {
            let c = points[u].dist(points[v]) + penalty[u] + penalty[v];
            if c < key[v] {
                key[v] = c;
                parent[v] = u;
            }
            if key[v] < key[rest[pick]] {
                pick = k;
            }
        }
        u = rest.swap_remove(pick);
        tree += key[u];
        degree[u] += 1;
        degree[parent[u]] += 1;
    }
    // the dummy node's two edges: the two least penalties
    let (mut first, mut second) = (0, 1);
    if penalty[second] < penalty[first] {
        std::mem::swap(&mut first, &mut second);
    }
    for v in 2..n {
        if penalty[v] < penalty[first] {
            second = first;
            first = v;
        } else if penalty[v] < penalty[second] {
            second = v;
        }
    }
    degree[first] += 1;
    degree[second] += 1;
    Ok(tree + penalty[first] + penalty[second] - 2.0 * penalty.iter().sum::<f64>())
}
