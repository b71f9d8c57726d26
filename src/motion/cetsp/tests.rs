//! Tests of seed 001's stage routes: the simplifications against hand-computed cases, the LSA
//! route's timing, the GA's determinism, cancel and results; an ignored measurement on the
//! shared on-the-fly benchmarks.
#![allow(clippy::unwrap_used)]

use super::*;
use crate::job::{CancelToken, Cancelled, JobCtx, NoProgress};
use proptest::prelude::*;
use std::sync::Arc;

fn pts(xy: &[(f64, f64)]) -> Vec<Pt> {
    xy.iter().map(|&(x, y)| Pt::new(x, y)).collect()
}

/// Knots of one stroke through `points`, marked at `speed_mm_s`.
fn walk(points: &[Pt], speed_mm_s: f64) -> Vec<ToolKnot> {
    let mut t_s = 0.0;
    let mut knots: Vec<ToolKnot> = Vec::with_capacity(points.len());
    for (i, &at) in points.iter().enumerate() {
        if let Some(prev) = knots.last() {
            t_s += prev.at.dist(at) / speed_mm_s;
        }
        knots.push(ToolKnot {
            t_s,
            at,
            marking: i + 1 < points.len(),
        });
    }
    knots
}

/// A sine wave 400 mm long in x, amplitude 30 mm, at 1 mm steps.
fn wave() -> Vec<ToolKnot> {
    let points: Vec<Pt> = (0..=400)
        .map(|i| {
            let x = i as f64;
            Pt::new(x, 30.0 * (x / 25.0).sin())
        })
        .collect();
    walk(&points, 1000.0)
}

fn small_ga(seed: u64) -> GaParams {
    GaParams {
        population: 12,
        generations: 30,
        seed,
        ..GaParams::default()
    }
}

#[test]
fn rdp_matches_a_hand_computed_case() {
    // chord (0,0)–(8,0): (6,3) is farthest (3 > 1); on (0,0)–(6,3) the point (4,0) is
    // 12/√45 = 1.79 > 1 away; on (0,0)–(4,0) the point (2,0.5) is 0.5 ≤ 1 away
    let p = pts(&[(0.0, 0.0), (2.0, 0.5), (4.0, 0.0), (6.0, 3.0), (8.0, 0.0)]);
    assert_eq!(rdp(&p, 1.0), vec![0, 2, 3, 4]);
    assert_eq!(rdp(&p, 5.0), vec![0, 4]);
    let tri = pts(&[(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)]);
    assert_eq!(rdp(&tri, 0.5), vec![0, 1, 2]);
    assert_eq!(rdp(&tri, 2.0), vec![0, 2]);
}

#[test]
fn rdp_keeps_the_tip_of_a_branch_that_returns() {
    // out 50 mm and back: the chord is 1 mm long, the tip is 50 mm from it
    let p = pts(&[
        (0.0, 0.0),
        (25.0, 0.0),
        (50.0, 0.0),
        (25.0, 1.0),
        (0.0, 1.0),
    ]);
    assert!(rdp(&p, 10.0).contains(&2));
}

#[test]
fn vw_matches_a_hand_computed_case() {
    // areas 1, 0.6, 0.2: (3,0.2) goes; then 1 and 1 are both ≥ 0.5
    let p = pts(&[(0.0, 0.0), (1.0, 1.0), (2.0, 0.0), (3.0, 0.2), (4.0, 0.0)]);
    assert_eq!(vw(&p, 0.5), vec![0, 1, 2, 4]);
    // threshold 1.5: (3,0.2) goes, then the first of the two areas of 1, then the last
    assert_eq!(vw(&p, 1.5), vec![0, 4]);
}

#[test]
fn deduction_drops_close_points_but_keeps_essential_ones() {
    // r = 20: half 10. (5,0) is 5 mm from (0,0) and the pattern hugs the chord: dropped;
    // (10,0) is 10 mm away: kept
    let line = pts(&[(0.0, 0.0), (5.0, 0.0), (10.0, 0.0), (30.0, 0.0)]);
    assert_eq!(
        deduct_half_radius(&line, &[0, 1, 2, 3], 20.0),
        vec![0, 2, 3]
    );
    // (5,0) is close to (0,0), but the pattern runs out to (20,0) in between: kept
    let hairpin = pts(&[(0.0, 0.0), (20.0, 0.0), (5.0, 0.0), (20.0, 1.0), (0.0, 1.0)]);
    assert_eq!(
        deduct_half_radius(&hairpin, &[0, 2, 4], 20.0),
        vec![0, 2, 4]
    );
}

#[test]
fn pattern_points_are_at_most_one_mm_apart_and_timed() {
    let tool = walk(&pts(&[(0.0, 0.0), (10.5, 0.0), (10.5, 3.0)]), 100.0);
    let pat = pattern(&tool, PATTERN_STEP_MM);
    assert!(pat.windows(2).all(|w| w[0].at.dist(w[1].at) <= 1.0 + 1e-12));
    let last = pat.last().unwrap();
    assert!((last.t_s - 0.135).abs() < 1e-12);
    assert_eq!(last.at, Pt::new(10.5, 3.0));
}

#[test]
fn lsa_route_passes_its_points_at_their_tool_times() {
    let tool = wave();
    let route = lsa_route(&tool, &LsaParams::paper(20.0));
    assert!(route.points.len() > 5);
    for (&p, &t) in route.points.iter().zip(&route.times_s) {
        assert!(route.position(t).dist(p) < 1e-9);
        assert!(tool_position(&tool, t).dist(p) < 1e-9);
    }
    assert!(route.times_s.windows(2).all(|w| w[0] <= w[1]));
    let check = Coverage::new(&tool, 20.0);
    assert_eq!(check.coverage(&route), 1.0);
}

#[test]
fn timed_route_interpolates_and_clamps() {
    let route = TimedRoute {
        points: pts(&[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)]),
        times_s: vec![1.0, 2.0, 4.0],
    };
    assert_eq!(route.position(0.0), Pt::new(0.0, 0.0));
    assert_eq!(route.position(1.5), Pt::new(5.0, 0.0));
    assert_eq!(route.position(3.0), Pt::new(10.0, 5.0));
    assert_eq!(route.position(9.0), Pt::new(10.0, 10.0));
    assert_eq!(route.length_mm(), 20.0);
    assert_eq!(TimedRoute::default().position(1.0), Pt::default());
}

#[test]
fn coverage_and_within_radius_of_simple_routes() {
    // tool along x from 0 to 100 mm in 1 s; a stage route 5 mm above it, on time
    let tool = walk(&pts(&[(0.0, 0.0), (100.0, 0.0)]), 100.0);
    let check = Coverage::new(&tool, 6.0);
    let on_time = TimedRoute {
        points: pts(&[(0.0, 5.0), (100.0, 5.0)]),
        times_s: vec![0.0, 1.0],
    };
    assert_eq!(check.coverage(&on_time), 1.0);
    assert_eq!(check.within_radius(&on_time), 1.0);
    // the same path, standing still for the first half: covered, but the tool runs away
    let late = TimedRoute {
        points: on_time.points.clone(),
        times_s: vec![0.5, 1.0],
    };
    assert_eq!(check.coverage(&late), 1.0);
    let within = check.within_radius(&late);
    assert!(within > 0.0 && within < 0.1, "{within}");
    // half the pattern out of reach
    let short = TimedRoute {
        points: pts(&[(0.0, 5.0), (50.0, 5.0)]),
        times_s: vec![0.0, 0.5],
    };
    let c = check.coverage(&short);
    assert!((c - 0.5).abs() < 0.05, "{c}");
}

#[test]
fn validation_words_bad_settings() {
    let ga = GaParams::default();
    let lsa = LsaParams::paper(35.0);
    assert_eq!(validate(&lsa, &ga, 35.0), Ok(()));
    let zero = GaParams {
        population: 0,
        ..ga.clone()
    };
    assert_eq!(zero.validate(), Err(CetspError::ZeroPopulation));
    let rate = GaParams {
        mutation_rate: 1.5,
        ..ga.clone()
    };
    let e = rate.validate().unwrap_err().to_string();
    assert!(e.contains("mutation_rate") && e.contains("1.5"), "{e}");
    assert_eq!(
        validate(&lsa, &ga, 0.0),
        Err(CetspError::Radius(0.0)),
        "radius"
    );
    assert!(LsaParams::paper(-1.0).validate().is_err());
}

#[test]
fn ga_is_deterministic_on_any_number_of_threads() {
    let tool = wave();
    let lsa = lsa_route(&tool, &LsaParams::paper(20.0));
    let run = || cetsp_ga(&tool, &lsa, 20.0, &small_ga(7), &JobCtx::default()).unwrap();
    let a = run();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let b = one.install(run);
    assert_eq!(a, b);
}

#[test]
fn ga_result_covers_and_is_its_best_feasible_route() {
    let tool = wave();
    let lsa = lsa_route(&tool, &LsaParams::paper(20.0));
    let res = cetsp_ga(&tool, &lsa, 20.0, &small_ga(3), &JobCtx::default()).unwrap();
    assert_eq!(res.coverage, 1.0);
    assert_eq!(res.within_radius, 1.0);
    let check = Coverage::new(&tool, 20.0);
    assert_eq!(check.coverage(&res.route), 1.0);
    assert_eq!(check.within_radius(&res.route), 1.0);
    let last = *res.history_mm.last().unwrap();
    assert!((res.route.length_mm() - last).abs() < 1e-9);
    assert!(res.history_mm.windows(2).all(|w| w[1] <= w[0]));
    assert_eq!(res.history_mm.len(), 31);
    assert!(last <= lsa.length_mm(), "{last} vs {}", lsa.length_mm());
    assert!(res.route.times_s.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn ga_returns_cancelled_when_cancelled() {
    let tool = wave();
    let lsa = lsa_route(&tool, &LsaParams::paper(20.0));
    let token = CancelToken::new();
    token.cancel();
    let ctx = JobCtx::new(token, Arc::new(NoProgress));
    assert_eq!(
        cetsp_ga(&tool, &lsa, 20.0, &GaParams::default(), &ctx),
        Err(Cancelled)
    );
}

#[test]
fn ga_cancel_returns_promptly_mid_run() {
    let tool = wave();
    let lsa = lsa_route(&tool, &LsaParams::paper(20.0));
    let token = CancelToken::new();
    let ctx = JobCtx::new(token.clone(), Arc::new(NoProgress));
    let params = GaParams {
        generations: 1_000_000,
        ..GaParams::default()
    };
    let canceller = std::thread::spawn(move || {
        std::thread::sleep(std::time::Duration::from_millis(100));
        token.cancel();
        std::time::Instant::now()
    });
    let res = cetsp_ga(&tool, &lsa, 20.0, &params, &ctx);
    let returned = std::time::Instant::now();
    let cancelled_at = canceller.join().unwrap();
    assert_eq!(res, Err(Cancelled));
    // generous for a debug build on a shared machine; the release figure is in the report
    assert!(returned.duration_since(cancelled_at).as_millis() < 1000);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn lsa_points_are_a_subsequence_of_the_pattern(
        xy in prop::collection::vec((-100.0f64..100.0, -100.0f64..100.0), 2..40),
        radius in 1.0f64..50.0,
    ) {
        let tool = walk(&pts(&xy), 500.0);
        let route = lsa_route(&tool, &LsaParams::paper(radius));
        let pat = pattern(&tool, PATTERN_STEP_MM);
        let mut rest = pat.iter();
        for (&p, &t) in route.points.iter().zip(&route.times_s) {
            prop_assert!(rest.any(|q| q.at == p && q.t_s == t));
        }
        prop_assert_eq!(route.points.first(), pat.first().map(|q| &q.at));
        prop_assert_eq!(route.points.last(), pat.last().map(|q| &q.at));
    }
}

/// Knots of an imported job's strokes in document order at seed 000's mark speed, jumping
/// between strokes at its jump speed.
fn svg_tool(path: &str) -> Vec<ToolKnot> {
    const MARK_MM_S: f64 = 1000.0;
    const JUMP_MM_S: f64 = 3000.0;
    let imported =
        crate::import::import_svg_file(std::path::Path::new(path), &Default::default()).unwrap();
    let mut knots: Vec<ToolKnot> = Vec::new();
    for g in &imported.geometries {
        let mut points = g.points.clone();
        if g.closed {
            points.push(points[0]);
        }
        let start_s = match knots.last_mut() {
            Some(k) => {
                k.marking = false;
                k.t_s + k.at.dist(points[0]) / JUMP_MM_S
            }
            None => 0.0,
        };
        knots.extend(walk(&points, MARK_MM_S).into_iter().map(|k| ToolKnot {
            t_s: k.t_s + start_s,
            ..k
        }));
    }
    knots
}

/// The measurement of the report: `cargo test --release --no-default-features --lib
/// motion::cetsp::tests::measure_otf_benchmarks -- --ignored --nocapture`.
#[test]
#[ignore]
fn measure_otf_benchmarks() {
    const RADIUS_MM: f64 = 35.0;
    println!("pattern | pattern mm | LSA pts | lsa mm | lsa cov | lsa inR | ga mm | ga/lsa | ga cov | ga inR | ga s");
    for name in ["lissajous", "tree", "spiral"] {
        let tool = svg_tool(&format!("/work/shared/bench/otf/{name}.svg"));
        let pat = pattern(&tool, PATTERN_STEP_MM);
        let pattern_mm: f64 = pat.windows(2).map(|w| w[0].at.dist(w[1].at)).sum();
        let t0 = std::time::Instant::now();
        let lsa = lsa_route(&tool, &LsaParams::paper(RADIUS_MM));
        let lsa_s = t0.elapsed().as_secs_f64();
        let check = Coverage::new(&tool, RADIUS_MM);
        let t0 = std::time::Instant::now();
        let res = cetsp_ga(
            &tool,
            &lsa,
            RADIUS_MM,
            &GaParams::default(),
            &JobCtx::default(),
        );
        let ga_s = t0.elapsed().as_secs_f64();
        let res = res.unwrap();
        println!(
            "{name} | {pattern_mm:.0} | {} | {:.0} | {:.4} | {:.4} | {:.0} | {:.3} | {:.4} | {:.4} | {ga_s:.2} (lsa {lsa_s:.3} s)",
            lsa.points.len(),
            lsa.length_mm(),
            check.coverage(&lsa),
            check.within_radius(&lsa),
            res.route.length_mm(),
            res.route.length_mm() / lsa.length_mm(),
            res.coverage,
            res.within_radius,
        );
    }
    let tool = svg_tool("/work/shared/bench/otf/spiral.svg");
    let lsa = lsa_route(&tool, &LsaParams::paper(RADIUS_MM));
    let token = CancelToken::new();
    let ctx = JobCtx::new(token.clone(), Arc::new(NoProgress));
    let canceller = std::thread::spawn(move || {
        std::thread::sleep(std::time::Duration::from_millis(700));
        token.cancel();
        std::time::Instant::now()
    });
    let res = cetsp_ga(&tool, &lsa, RADIUS_MM, &GaParams::default(), &ctx);
    let returned = std::time::Instant::now();
    let at = canceller.join().unwrap();
    assert_eq!(res, Err(Cancelled));
    println!(
        "spiral cancel latency: {:.1} ms",
        returned.duration_since(at).as_secs_f64() * 1e3
    );
}
