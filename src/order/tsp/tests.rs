use super::*;
use crate::geom::Pt;
use crate::job::JobCtx;
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

/// The result of a search: its cost as reported and not above `before`, a permutation, fixed
/// ends kept, only flippable nodes flipped.
fn check_result(prob: &PathProblem, t: &Tour, c: f64, before: f64) -> Result<(), TestCaseError> {
    let n = prob.nodes.len();
    prop_assert!((c - prob.tour_cost(t)).abs() < 1e-6);
    prop_assert!(c <= before + 1e-9);
    let mut s = t.order.clone();
    s.sort();
    prop_assert_eq!(s, (0..n).collect::<Vec<_>>());
    if prob.fixed_first {
        prop_assert_eq!(t.order[0], 0);
    }
    if prob.fixed_last {
        prop_assert_eq!(t.order[n - 1], n - 1);
    }
    for v in 0..n {
        if !prob.flippable[v] {
            prop_assert!(!t.flipped[v]);
        }
    }
    Ok(())
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
        check_result(&prob, &t, c, before)?;
    }
}

/// The exact optimum over every order and every orientation of the flippable nodes.
fn brute_force_oriented(prob: &PathProblem) -> f64 {
    let n = prob.nodes.len();
    let flippable: Vec<usize> = (0..n).filter(|&v| prob.flippable[v]).collect();
    let mut best = f64::INFINITY;
    let mut order: Vec<usize> = (0..n).collect();
    permute(&mut order, 0, &mut |o| {
        if (prob.fixed_first && o[0] != 0) || (prob.fixed_last && o[n - 1] != n - 1) {
            return;
        }
        for mask in 0..1u32 << flippable.len() {
            let mut flipped = vec![false; n];
            for (b, &v) in flippable.iter().enumerate() {
                flipped[v] = mask >> b & 1 == 1;
            }
            let t = Tour {
                order: o.to_vec(),
                flipped,
            };
            best = best.min(prob.tour_cost(&t));
        }
    });
    best
}

fn permute(v: &mut Vec<usize>, k: usize, f: &mut dyn FnMut(&[usize])) {
    if k == v.len() {
        f(v);
        return;
    }
    for i in k..v.len() {
        v.swap(k, i);
        permute(v, k + 1, f);
        v.swap(k, i);
    }
}

/// A small random problem: `n` nodes, every third one an open (flippable) stroke.
fn small_problem(
    seed: u64,
    n: usize,
    lambda: f64,
    fixed_first: bool,
    fixed_last: bool,
) -> PathProblem {
    let a = rnd_points(seed, n);
    let b = rnd_points(seed + 11, n);
    let nodes: Vec<Node> = (0..n)
        .map(|i| {
            if i % 3 == 1 {
                Node {
                    s: a[i],
                    e: a[i].plus(b[i].minus(a[i]).scale(0.2)),
                    p: a[i].x,
                }
            } else {
                Node::point(a[i], a[i].x)
            }
        })
        .collect();
    let flippable = nodes.iter().map(|q| q.s != q.e).collect();
    PathProblem {
        nodes,
        lambda,
        fixed_first,
        fixed_last,
        flippable,
        cluster: Vec::new(),
        cluster_penalty: 0.0,
        metric: Default::default(),
    }
}

#[test]
fn iterated_search_finds_the_exact_optimum_on_small_cases() {
    // golden: brute force over all orders and orientations, with and without fixed ends and
    // the directional penalty
    for seed in 0..12u64 {
        let ends = [(false, false), (true, false), (false, true), (true, true)][seed as usize % 4];
        let lambda = [0.0, 0.7][seed as usize / 4 % 2];
        let prob = small_problem(200 + seed, 7, lambda, ends.0, ends.1);
        let mut t = Tour {
            order: (0..7).collect(),
            flipped: vec![false; 7],
        };
        let ls = LocalSearch::new(&prob, LsOptions::default(), &JobCtx::default()).unwrap();
        let c = ls.iterated(&mut t, 300, seed, &JobCtx::default()).unwrap();
        let opt = brute_force_oriented(&prob);
        assert!(
            (c - opt).abs() < 1e-9,
            "seed {seed} ends {ends:?} λ {lambda}: {c} vs optimum {opt}"
        );
    }
}

#[test]
fn iterated_search_is_deterministic_for_a_seed() {
    let pts = rnd_points(5, 300);
    let prob = PathProblem::points(&pts, &[0.0; 300], 0.0);
    let run = |seed: u64| {
        let mut t = Tour {
            order: (0..300).collect(),
            flipped: vec![false; 300],
        };
        LocalSearch::new(&prob, LsOptions::default(), &JobCtx::default())
            .unwrap()
            .iterated(&mut t, 200, seed, &JobCtx::default())
            .unwrap();
        t
    };
    assert_eq!(run(3), run(3));
}

#[test]
fn a_cancelled_search_returns_an_error_and_a_valid_tour() {
    let pts = rnd_points(6, 200);
    let prob = PathProblem::points(&pts, &[0.0; 200], 0.0);
    let ctx = JobCtx::default();
    ctx.cancel_token().cancel();
    let mut t = Tour {
        order: (0..200).collect(),
        flipped: vec![false; 200],
    };
    let r = LocalSearch::new(&prob, LsOptions::default(), &JobCtx::default())
        .unwrap()
        .iterated(&mut t, 1_000_000, 1, &ctx);
    assert!(r.is_err());
    let mut s = t.order.clone();
    s.sort();
    assert_eq!(s, (0..200).collect::<Vec<_>>());
}

#[test]
fn a_past_deadline_ends_the_kicks_with_a_local_optimum() {
    let pts = rnd_points(7, 200);
    let prob = PathProblem::points(&pts, &[0.0; 200], 0.0);
    let mut t = Tour {
        order: (0..200).collect(),
        flipped: vec![false; 200],
    };
    let budget = IlsBudget::until(200, Some(std::time::Instant::now()));
    let c = LocalSearch::new(&prob, LsOptions::default(), &JobCtx::default())
        .unwrap()
        .iterated_within(&mut t, budget, 1, &JobCtx::default())
        .unwrap();
    assert!((c - prob.tour_cost(&t)).abs() < 1e-6);
    let mut s = t.order.clone();
    s.sort();
    assert_eq!(s, (0..200).collect::<Vec<_>>());
}

#[test]
fn open_path_on_a_grid_is_near_the_optimum() {
    // a 12 × 12 grid of 1 mm spacing: the optimal open path has 143 unit edges
    let pts: Vec<Pt> = (0..144)
        .map(|k| Pt::new((k % 12) as f64, (k / 12) as f64))
        .collect();
    let order = open_path(&pts, IlsBudget::kicks(500), 1, &JobCtx::default()).unwrap();
    let mut s = order.clone();
    s.sort();
    assert_eq!(s, (0..144).collect::<Vec<_>>());
    let len: f64 = order.windows(2).map(|w| pts[w[0]].dist(pts[w[1]])).sum();
    assert!(len < 143.0 * 1.02, "{len} mm for an optimum of 143 mm");
}

#[test]
fn hilbert_order_is_a_permutation() {
    let pts = rnd_points(8, 500);
    let mut o = space_filling_order(&pts);
    o.sort();
    assert_eq!(o, (0..500).collect::<Vec<_>>());
}

proptest! {
    #[test]
    fn ring_reversals_match_a_plain_vector(
        n in 3usize..40,
        ops in proptest::collection::vec((0usize..1000, 0usize..1000), 1..60),
        flip_mask in any::<u64>(),
    ) {
        let flippable: Vec<bool> = (0..n).map(|v| flip_mask >> (v % 64) & 1 == 1).collect();
        let start = Tour { order: (0..n).rev().collect(), flipped: vec![false; n] };
        let mut ring = super::ring::Ring::new(&start, &flippable);
        let mut model = start.clone();
        for (a, b) in ops {
            let (i, j) = ((a % n).min(b % n), (a % n).max(b % n));
            ring.reverse(i, j);
            model.order[i..=j].reverse();
            for k in i..=j {
                let v = model.order[k];
                if flippable[v] {
                    model.flipped[v] = !model.flipped[v];
                }
            }
            let mut got = start.clone();
            ring.write(&mut got);
            prop_assert_eq!(&got, &model);
            for (k, &v) in model.order.iter().enumerate() {
                prop_assert_eq!(ring.position(v), k);
            }
        }
    }

    #[test]
    fn iterated_search_keeps_a_permutation_and_fixed_ends(
        seed in 0u64..10_000,
        n in 3usize..60,
        lambda in 0.0f64..2.0,
        fixed_first in any::<bool>(),
        fixed_last in any::<bool>(),
    ) {
        let prob = small_problem(seed, n, lambda, fixed_first, fixed_last);
        let mut t = Tour { order: (0..n).collect(), flipped: vec![false; n] };
        let before = prob.tour_cost(&t);
        let c = LocalSearch::new(&prob, LsOptions::default(), &JobCtx::default()).unwrap()
            .iterated(&mut t, 50, seed, &JobCtx::default())
            .unwrap();
        check_result(&prob, &t, c, before)?;
    }
}

#[test]
fn strokes_shorter_than_the_tolerance_are_searched_as_points() {
    let (dot, flips) = Node::open_stroke(Pt::new(1.0, 2.0), Pt::new(1.002, 2.0), 0.5);
    assert!(!flips);
    assert_eq!(dot.s, dot.e);
    assert!((dot.s.x - 1.001).abs() < 1e-12 && dot.p == 0.5);
    let end = Pt::new(2.0 * POINT_LIKE_MM, 0.0);
    let (line, flips) = Node::open_stroke(Pt::new(0.0, 0.0), end, 0.0);
    assert!(flips);
    assert_eq!((line.s, line.e), (Pt::new(0.0, 0.0), end));
}

#[test]
fn the_point_fast_path_gives_the_tours_of_the_general_cost() {
    let n = 400;
    let pts = rnd_points(8, n);
    let plain = PathProblem::points(&pts, &vec![0.0; n], 0.0);
    // the same costs through the general path: one cluster for every node adds no penalty,
    // but a cluster penalty turns the plain-distance shortcuts off
    let mut general = plain.clone();
    general.cluster = vec![0; n];
    general.cluster_penalty = 1.0;
    let run = |prob: &PathProblem| {
        let mut t = Tour {
            order: (0..n).collect(),
            flipped: vec![false; n],
        };
        let c = LocalSearch::new(prob, LsOptions::default(), &JobCtx::default())
            .unwrap()
            .iterated(&mut t, 300, 4, &JobCtx::default())
            .unwrap();
        (t, c)
    };
    let ((t_plain, c_plain), (t_general, c_general)) = (run(&plain), run(&general));
    assert_eq!(t_plain, t_general);
    assert_eq!(c_plain, c_general);
}

#[test]
fn the_held_karp_bound_is_below_the_optimum_and_close_to_it() {
    for seed in 0..6 {
        let pts = rnd_points(200 + seed, 8);
        let prob = PathProblem::points(&pts, &[0.0; 8], 0.0);
        let opt = (0..8)
            .map(|first| brute_force(&prob, first, None))
            .fold(f64::INFINITY, f64::min);
        let bound = held_karp_open_path(&pts, opt * 1.1, 300, &JobCtx::default()).unwrap();
        assert!(
            bound <= opt + 1e-9,
            "seed {seed}: bound {bound} above the optimum {opt}"
        );
        assert!(
            bound >= 0.9 * opt,
            "seed {seed}: bound {bound} far below {opt}"
        );
    }
    // on a line the best 1-tree is the path itself: the bound reaches the optimum
    let line: Vec<Pt> = [3.0, 0.0, 7.0, 1.0, 12.0, 5.0]
        .iter()
        .map(|&x| Pt::new(x, 2.0))
        .collect();
    let bound = held_karp_open_path(&line, 20.0, 300, &JobCtx::default()).unwrap();
    assert!((bound - 12.0).abs() < 1e-3, "{bound} on a 12 mm line");
    let cancelled = JobCtx::default();
    cancelled.cancel_token().cancel();
    assert!(held_karp_open_path(&line, 20.0, 300, &cancelled).is_err());
}

#[test]
fn neighbour_lists_are_the_same_on_any_thread_count_and_stop_on_a_cancel() {
    let n = 3000;
    let pts = rnd_points(9, n);
    let prob = PathProblem::points(&pts, &vec![0.0; n], 0.0);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| neighbour_lists(&prob, 16, &JobCtx::default()).unwrap())
    };
    let one = on(1);
    assert_eq!(one, on(3));
    assert!(one
        .iter()
        .enumerate()
        .all(|(i, l)| l.len() >= 16 && !l.contains(&i)));
    let cancelled = JobCtx::default();
    cancelled.cancel_token().cancel();
    assert!(neighbour_lists(&prob, 16, &cancelled).is_err());
}
