//! Ordering on machine time (`--cost time`, seed 002): a search that starts from the distance
//! plan and accepts only what lowers the job time, so it is never slower than that plan.
//!
//! In step-and-scan the job time is stage time + scanner time. Stage time depends only on the
//! field order: the field path is re-optimised on [`TravelCost::StageTime`] (per axis a
//! trapezoid, the slower axis counts, plus settling — the toolpath's own timing). The scanner
//! jump from one field to the next runs during the stage move, so a field's first and last
//! strokes are free; inside a field a jump costs `distance / jump speed + jump delay`, affine in
//! the distance, so the strokes are ordered on distance with free ends and no directional
//! penalty, and the start vertices chosen exactly per field.

use super::cost::{PoseMap, TravelCost};
use super::hha::{field_runs, refine_field};
use super::metrics::idle_mm;
use super::tsp::{IlsBudget, LocalSearch, LsOptions, PathProblem, Tour};
use super::vertex::optimal_vertices;
use super::Ordering;
use crate::document::{Geometry, MachineProfile, ScanField, Step};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use crate::motion::StageDynamics;
use rayon::prelude::*;
use std::collections::HashMap;
use std::time::Instant;

/// Fewest iterated-local-search kicks on the field path.
const STAGE_KICKS_MIN: usize = 32;

/// Most kicks on the field path: a kick is local (a few hundred µs on 3,043 fields), and
/// texture-3043's stage time falls 422.9 → 421.5 s from 98 to 1,000 kicks (0.4 s of search),
/// only to 420.6 s at 5,000 (1.2 s).
const STAGE_KICKS_MAX: usize = 1000;

/// Improves `ordering` for job time; never makes it slower. The per-field searches stop at
/// `until` (when given) instead of after their default kicks.
pub fn refine_for_time(
    geometries: &[Geometry],
    fields: &[ScanField],
    ordering: &Ordering,
    profile: &MachineProfile,
    seed: u64,
    until: Option<Instant>,
    ctx: &JobCtx,
) -> Result<Ordering, Cancelled> {
    let runs: Vec<&[Step]> = field_runs(&ordering.steps)
        .into_iter()
        .map(|(a, b)| &ordering.steps[a..b])
        .collect();
    let centre: HashMap<usize, Pt> = fields.iter().map(|f| (f.id, f.center)).collect();
    let Some(centres) = runs
        .iter()
        .map(|run| centre.get(&run[0].field).copied())
        .collect::<Option<Vec<Pt>>>()
    else {
        // a step names a field that does not exist: lowering reports it with its step
        return Ok(ordering.clone());
    };
    let poses = PoseMap::new(fields.iter().map(|f| (f.center, f.pose)));
    let visit = path_on_stage_time(&centres, &poses, profile, seed, ctx)?;
    let searches = searches_per_field(visit.len(), until);
    let refined: Vec<Result<Vec<Step>, Cancelled>> = visit
        .par_iter()
        .enumerate()
        .map(|(j, &r)| {
            let seeds: Vec<u64> = (0..searches)
                .map(|m| seed ^ ((j as u64) << 32) ^ ((m as u64) << 48))
                .collect();
            best_free_field_path(geometries, runs[r], &seeds, until, ctx)
        })
        .collect();
    let mut steps = Vec::with_capacity(ordering.steps.len());
    for r in refined {
        steps.extend(r?);
    }
    let field_order = visit.iter().map(|&r| runs[r][0].field).collect();
    Ok(Ordering { field_order, steps })
}

/// The order (indices into `centres`, the stage positions in their current order) that the
/// stage visits them in, re-optimised on stage time (over every axis the placements' `poses`
/// move) with both ends free.
fn path_on_stage_time(
    centres: &[Pt],
    poses: &PoseMap,
    profile: &MachineProfile,
    seed: u64,
    ctx: &JobCtx,
) -> Result<Vec<usize>, Cancelled> {
    let n = centres.len();
    let mut tour = Tour {
        order: (0..n).collect(),
        flipped: vec![false; n],
    };
    if n < 3 {
        return Ok(tour.order);
    }
    let mut prob = PathProblem::points(centres, &vec![0.0; n], 0.0);
    prob.metric = TravelCost::stage_time(StageDynamics::of(profile), poses.clone());
    let kicks = (2 * n).clamp(STAGE_KICKS_MIN, STAGE_KICKS_MAX);
    LocalSearch::new(&prob, LsOptions::default(), ctx)?.iterated(&mut tour, kicks, seed, ctx)?;
    Ok(tour.order)
}

/// Most independent searches of one field under a deadline.
const SEARCHES_PER_FIELD_MAX: usize = 4;

/// Independent searches per field: one without a deadline (deterministic for a seed on any
/// number of threads); with one, the threads the fields leave idle each run a search of their
/// own (different seeds, the shortest kept) until the deadline. Results under a deadline
/// already depend on the machine's speed; now also on its thread count. On one 1,000-point
/// field with `--time-limit 1` and 2 threads: median +0.37 % above LKH instead of +0.49 %
/// (seeds 1–3 × 5 point sets; seed 1 alone +0.54 → +0.37 %; BENCHMARKS, issue 16).
fn searches_per_field(fields: usize, until: Option<Instant>) -> usize {
    match until {
        Some(_) => (rayon::current_num_threads() / fields.max(1)).clamp(1, SEARCHES_PER_FIELD_MAX),
        None => 1,
    }
}

/// [`free_field_path`] with each seed (in parallel), keeping the lowest idle (the first of
/// equals).
pub(crate) fn best_free_field_path(
    geometries: &[Geometry],
    run: &[Step],
    seeds: &[u64],
    until: Option<Instant>,
    ctx: &JobCtx,
) -> Result<Vec<Step>, Cancelled> {
    let run_idle_mm = idle_mm(geometries, run);
    let candidates: Vec<Result<(Vec<Step>, f64), Cancelled>> = seeds
        .par_iter()
        .map(|&seed| free_field_path(geometries, run, run_idle_mm, seed, until, ctx))
        .collect();
    let mut best: Option<(Vec<Step>, f64)> = None;
    for c in candidates {
        let (steps, idle) = c?;
        if best.as_ref().is_none_or(|(_, b)| idle < *b) {
            best = Some((steps, idle));
        }
    }
    Ok(best.map_or_else(|| run.to_vec(), |(steps, _)| steps))
}

/// One field's strokes as a free open path on distance (λ = 0), exact start vertices, with its
/// idle travel in mm; the old run (of idle `run_idle_mm`) is kept when that is not shorter.
fn free_field_path(
    geometries: &[Geometry],
    run: &[Step],
    run_idle_mm: f64,
    seed: u64,
    until: Option<Instant>,
    ctx: &JobCtx,
) -> Result<(Vec<Step>, f64), Cancelled> {
    if run.len() < 2 {
        return Ok((run.to_vec(), run_idle_mm));
    }
    let mut next = refine_field(
        geometries,
        run,
        None,
        None,
        Pt::new(1.0, 0.0),
        0.0,
        seed,
        IlsBudget::until(run.len(), until),
        ctx,
    )?;
    let idle = optimal_vertices(geometries, &mut next, ctx)?;
    Ok(if idle < run_idle_mm {
        (next, idle)
    } else {
        (run.to_vec(), run_idle_mm)
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::document::Source;

    fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(f)
    }

    #[test]
    fn idle_threads_search_a_field_again_only_under_a_deadline() {
        let soon = Some(Instant::now());
        assert_eq!(on_threads(3, || searches_per_field(1, None)), 1);
        assert_eq!(on_threads(3, || searches_per_field(1, soon)), 3);
        assert_eq!(on_threads(4, || searches_per_field(2, soon)), 2);
        assert_eq!(on_threads(2, || searches_per_field(5, soon)), 1);
        assert_eq!(
            on_threads(16, || searches_per_field(1, soon)),
            SEARCHES_PER_FIELD_MAX
        );
    }

    #[test]
    fn the_best_of_several_searches_is_no_longer_than_the_first() {
        // 60 dots in a scrambled order
        let geometries: Vec<Geometry> = (0..60)
            .map(|k| {
                let (x, y) = (((k * 37) % 60) as f64, ((k * 11) % 7) as f64 * 9.0);
                Geometry::new(
                    vec![Pt::new(x, y), Pt::new(x + 0.002, y)],
                    false,
                    Source::default(),
                )
            })
            .collect();
        let run: Vec<Step> = (0..60)
            .map(|g| Step::from_choice(g, 0, &geometries[g], 0))
            .collect();
        let ctx = JobCtx::default();
        let first = free_field_path(&geometries, &run, idle_mm(&geometries, &run), 5, None, &ctx)
            .unwrap()
            .0;
        let best = best_free_field_path(&geometries, &run, &[5, 6, 7], None, &ctx).unwrap();
        assert!(idle_mm(&geometries, &best) <= idle_mm(&geometries, &first) + 1e-9);
        let mut seen: Vec<usize> = best.iter().map(|s| s.geometry).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..60).collect::<Vec<_>>());
        assert_eq!(
            best_free_field_path(&geometries, &run, &[5], None, &ctx).unwrap(),
            first
        );
    }
}
