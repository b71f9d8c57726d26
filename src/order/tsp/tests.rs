use super::*;
use proptest::prelude::*;

fn rnd_points(seed: u64, n: usize) -> Vec<Pt> {
    let mut x = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..n)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let a = (x >> 11) as f64 / (1u64 << 53) as f64;
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let b = (x >> 11) as f64 / (1u64 << 53) as f64;
            Pt::new(a * 100.0, b * 100.0)
        })
        .collect()
}

fn brute_force(prob: &PathProblem, first: usize, last: Option<usize>) -> f64 {
    fn rec(
        prob: &PathProblem,
        t: &mut Tour,
        used: &mut Vec<bool>,
        last: Option<usize>,
        best: &mut f64,
    ) {
        let n = prob.nodes.len();
        if t.order.len() == n {
            *best = best.min(prob.tour_cost(t));
            return;
        }
        for v in 0..n {
            if used[v] || (Some(v) == last && t.order.len() != n - 1) {
                continue;
            }
            used[v] = true;
            t.order.push(v);
            rec(prob, t, used, last, best);
            t.order.pop();
            used[v] = false;
        }
    }
    let n = prob.nodes.len();
    let mut t = Tour {
        order: vec![first],
        flipped: vec![false; n],
    };
    let mut used = vec![false; n];
    used[first] = true;
    let mut best = f64::INFINITY;
    rec(prob, &mut t, &mut used, last, &mut best);
    best
}

#[test]
fn exact_path_matches_brute_force() {
    for seed in 0..6 {
        let pts = rnd_points(seed, 8);
        let prob = PathProblem::points(&pts, &[0.0; 8], 0.0);
        let d = |i: usize, j: usize| pts[i].dist(pts[j]);
        for last in [None, Some(5)] {
            let order = exact_path(&d, 8, 2, last);
            let t = Tour {
                order: order.clone(),
                flipped: vec![false; 8],
            };
            assert_eq!(order[0], 2);
            if let Some(l) = last {
                assert_eq!(*order.last().unwrap(), l);
            }
            assert!(
                (prob.tour_cost(&t) - brute_force(&prob, 2, last)).abs() < 1e-9,
                "seed {seed} last {last:?}"
            );
        }
    }
}

#[test]
fn cheapest_arc_visits_all_and_keeps_ends() {
    let pts = rnd_points(3, 20);
    let order = cheapest_arc(20, 4, Some(9), &|i, j| pts[i].dist(pts[j]));
    assert_eq!(order.len(), 20);
    assert_eq!((order[0], order[19]), (4, 9));
    let mut s = order.clone();
    s.sort();
    assert_eq!(s, (0..20).collect::<Vec<_>>());
}

#[test]
fn local_search_reaches_near_optimum_on_small_cases() {
    for seed in 0..10 {
        let pts = rnd_points(100 + seed, 9);
        let mut prob = PathProblem::points(&pts, &[0.0; 9], 0.0);
        prob.fixed_first = true;
        prob.fixed_last = true;
        let mut t = Tour {
            order: (0..9).collect(),
            flipped: vec![false; 9],
        };
        let c = local_search(&prob, &mut t, LsOptions::default(), &JobCtx::default()).unwrap();
        let opt = brute_force(&prob, 0, Some(8));
        assert!(c <= opt * 1.10 + 1e-9, "seed {seed}: {c} vs optimum {opt}");
    }
}

#[test]
fn directional_penalty_prefers_a_sweep() {
    // two rows of points 30 mm apart: without a penalty the best path runs along one row and
    // back along the other; with it, the path sweeps forwards across both rows
    let mut pts = Vec::new();
    for k in 0..10 {
        pts.push(Pt::new(k as f64 * 10.0, 0.0));
        pts.push(Pt::new(k as f64 * 10.0 + 5.0, 30.0));
    }
    let proj: Vec<f64> = pts.iter().map(|p| p.x).collect();
    let back_travel = |lambda: f64| -> f64 {
        let mut prob = PathProblem::points(&pts, &proj, lambda);
        prob.fixed_first = true;
        let mut t = Tour {
            order: (0..20).collect(),
            flipped: vec![false; 20],
        };
        local_search(&prob, &mut t, LsOptions::default(), &JobCtx::default()).unwrap();
        t.order
            .windows(2)
            .map(|w| (proj[w[0]] - proj[w[1]]).max(0.0))
            .sum()
    };
    let free = back_travel(0.0);
    let directed = back_travel(5.0);
    assert!(
        free >= 80.0,
        "without penalty the path returns along the second row ({free} mm back)"
    );
    assert!(
        directed <= 30.0,
        "with penalty it sweeps forwards ({directed} mm back)"
    );
}

proptest! {
    #[test]
    fn local_search_is_consistent(
        seed in 0u64..10_000,
        n in 3usize..40,
        lambda in 0.0f64..2.0,
        fixed_first in any::<bool>(),
        fixed_last in any::<bool>(),
        open_mask in any::<u64>(),
    ) {
        let a = rnd_points(seed, n);
        let b = rnd_points(seed + 7, n);
        let nodes: Vec<Node> = (0..n)
            .map(|i| if open_mask >> (i % 64) & 1 == 1 { Node { s: a[i], e: b[i], p: a[i].x } } else { Node::point(a[i], a[i].x) })
            .collect();
        let flippable: Vec<bool> = nodes.iter().map(|q| q.s != q.e).collect();
        let prob = PathProblem { nodes, lambda, fixed_first, fixed_last, flippable, cluster: Vec::new(), cluster_penalty: 0.0, metric: Default::default() };
        let mut t = Tour { order: (0..n).collect(), flipped: vec![false; n] };
        let before = prob.tour_cost(&t);
        let c = local_search(&prob, &mut t, LsOptions::default(), &JobCtx::default()).unwrap();
        prop_assert!((c - prob.tour_cost(&t)).abs() < 1e-6);
        prop_assert!(c <= before + 1e-9);
        let mut s = t.order.clone();
        s.sort();
        prop_assert_eq!(s, (0..n).collect::<Vec<_>>());
        if fixed_first { prop_assert_eq!(t.order[0], 0); }
        if fixed_last { prop_assert_eq!(t.order[n - 1], n - 1); }
        for v in 0..n {
            if !prob.flippable[v] { prop_assert!(!t.flipped[v]); }
        }
    }
}
