//! Seed 001's GA for the close-enough TSP of the stage route (§III-C, Table II).
//!
//! * **Representation** (§III-C-1): one gene per LSA point, in pattern order: whether the point
//!   has a turning point, the turning point (within the padding radius of its LSA point) and
//!   the movement speed to the next turning point. The speed is stored relative to the LSA
//!   timing: a leg from LSA point `i` to `j` at speed `s` takes `(t_j − t_i) / s`, so at speed
//!   1 the stage reaches each turning point at its LSA point's tool time wherever the turning
//!   point lies (a moved turning point does not shift the rest of the route in time). The first
//!   turning point is reached at its LSA point's time.
//! * **Initialisation** (§III-C-2): every individual is the LSA route at speed 1 with two random
//!   turning points removed (by the clear operation).
//! * **Improved 2-point crossover** (§III-C-3, Fig. 3): both cut points are LSA points that
//!   have a turning point in both parents; the genes between them (turning points and speeds)
//!   are exchanged.
//! * **Combination mutation** (§III-C-3, Fig. 4): one of clear / change position / change speed,
//!   chosen uniformly, on one random gene.
//! * **Fitness** (§III-C-4, Table I): rank-based; routes that cover the pattern first, by
//!   within-radius value (higher first), then by length (shorter first); routes that do not
//!   cover it are not ranked (kept last). Parents by 2-tournament, survivors (μ + λ).
//!
//! All random draws happen on the calling thread in a fixed order, evaluation is parallel
//! (rayon) and pure: a seed gives the same route on any number of threads.

use super::{Coverage, GaParams, TimedRoute, ToolKnot};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::cmp::Ordering;

/// Largest relative change of a speed by one "change speed" mutation (±10 %; the paper gives
/// no figure).
pub const SPEED_STEP: f64 = 0.1;

/// Slowest relative movement speed a gene may take (half the LSA timing).
pub const MIN_SPEED: f64 = 0.5;

/// Fastest relative movement speed a gene may take (twice the LSA timing).
pub const MAX_SPEED: f64 = 2.0;

/// Turning points removed from each initial individual (§III-C-2: "removes two random turning
/// points from the set to increase the diversity").
pub const INITIAL_REMOVALS: usize = 2;

/// What a `cetsp-ga` run returns.
#[derive(Debug, Clone, PartialEq)]
pub struct CetspResult {
    /// The best route found (the best feasible one when there is one).
    pub route: TimedRoute,
    /// Its coverage (1 = the pattern lies within the radius of the route).
    pub coverage: f64,
    /// Its within-radius value (1 = the tool never leaves the radius around the stage).
    pub within_radius: f64,
    /// Best feasible route length (coverage and within-radius value 1), mm: the initial
    /// population first, then one entry per generation; infinite while none is feasible.
    pub history_mm: Vec<f64>,
}

/// One gene: the turning point of an LSA point, if it has one, and the speed from it on.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Gene {
    active: bool,
    at: Pt,
    speed: f64,
}

/// The constraints' values and the length of an individual's route.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Fitness {
    coverage: f64,
    within: f64,
    length_mm: f64,
}

impl Fitness {
    const UNKNOWN: Fitness = Fitness {
        coverage: 0.0,
        within: 0.0,
        length_mm: f64::INFINITY,
    };

    fn covers(&self) -> bool {
        self.coverage >= 1.0
    }

    fn feasible(&self) -> bool {
        self.covers() && self.within >= 1.0
    }

    /// Table I's order: covering routes by within-radius value, then length; the rest (not
    /// ranked by the paper) after them, by coverage, within-radius value and length.
    fn rank_cmp(&self, o: &Fitness) -> Ordering {
        o.covers()
            .cmp(&self.covers())
            .then_with(|| o.coverage.total_cmp(&self.coverage))
            .then_with(|| o.within.total_cmp(&self.within))
            .then_with(|| self.length_mm.total_cmp(&o.length_mm))
    }
}

#[derive(Debug, Clone, PartialEq)]
struct Individual {
    genes: Vec<Gene>,
    fit: Fitness,
}

/// The LSA points and the checks every individual is evaluated with.
struct Problem<'a> {
    lsa: &'a TimedRoute,
    check: Coverage,
}

impl Problem<'_> {
    fn radius_mm(&self) -> f64 {
        self.check.radius_mm()
    }

    /// The individual's route: its turning points with the times its speeds give.
    fn route(&self, genes: &[Gene]) -> TimedRoute {
        let t = &self.lsa.times_s;
        let mut route = TimedRoute::default();
        let mut prev: Option<(usize, f64)> = None;
        for (i, g) in genes.iter().enumerate().filter(|(_, g)| g.active) {
            let time_s = match prev {
                None => t[i],
                Some((p, tp)) => tp + (t[i] - t[p]) / genes[p].speed,
            };
            route.points.push(g.at);
            route.times_s.push(time_s);
            prev = Some((i, time_s));
        }
        route
    }

    fn evaluate(&self, genes: &[Gene]) -> Fitness {
        let route = self.route(genes);
        Fitness {
            coverage: self.check.coverage(&route),
            within: self.check.within_radius(&route),
            length_mm: route.length_mm(),
        }
    }
}

/// Runs seed 001's GA from the `lsa` route (see the module documentation) for padding radius
/// `padding_radius_mm`. Reports progress as stage `route`, one unit a generation; checks the
/// cancel token every generation and before every evaluation. Call [`super::validate`] first:
/// a population of 0 runs as 1, rates are clamped into [0, 1].
pub fn cetsp_ga(
    tool: &[ToolKnot],
    lsa: &TimedRoute,
    padding_radius_mm: f64,
    params: &GaParams,
    ctx: &JobCtx,
) -> Result<CetspResult, Cancelled> {
    let problem = Problem {
        lsa,
        check: Coverage::new(tool, padding_radius_mm),
    };
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let mu = params.population.max(1);
    let mut pop: Vec<Individual> = (0..mu).map(|_| initial(&problem, &mut rng)).collect();
    evaluate_all(&problem, &mut pop, ctx)?;
    pop.sort_by(|a, b| a.fit.rank_cmp(&b.fit));
    let mut history_mm = vec![best_feasible_mm(&pop)];
    for generation in 1..=params.generations {
        ctx.check()?;
        let mut offspring = breed(&problem, &pop, params, &mut rng);
        evaluate_all(&problem, &mut offspring, ctx)?;
        pop.extend(offspring);
        pop.sort_by(|a, b| a.fit.rank_cmp(&b.fit));
        pop.truncate(mu);
        history_mm.push(best_feasible_mm(&pop));
        report(ctx, generation, params.generations, &pop[0].fit);
    }
    let best = &pop[0];
    Ok(CetspResult {
        route: problem.route(&best.genes),
        coverage: best.fit.coverage,
        within_radius: best.fit.within,
        history_mm,
    })
}

fn report(ctx: &JobCtx, generation: usize, generations: usize, best: &Fitness) {
    ctx.progress(
        "route",
        generation as u64,
        generations as u64,
        format!(
            "cetsp-ga generation {generation}: best {:.1} mm, coverage {:.4}, within radius {:.4}",
            best.length_mm, best.coverage, best.within
        ),
    );
}

/// The best feasible length of a population sorted by rank (feasible ones rank first).
fn best_feasible_mm(pop: &[Individual]) -> f64 {
    match pop.first() {
        Some(best) if best.fit.feasible() => best.fit.length_mm,
        _ => f64::INFINITY,
    }
}

fn evaluate_all(problem: &Problem, pop: &mut [Individual], ctx: &JobCtx) -> Result<(), Cancelled> {
    pop.par_iter_mut().try_for_each(|ind| {
        ctx.check()?;
        ind.fit = problem.evaluate(&ind.genes);
        Ok(())
    })
}

/// The LSA route at speed 1 less [`INITIAL_REMOVALS`] random turning points.
fn initial(problem: &Problem, rng: &mut ChaCha8Rng) -> Individual {
    let lsa = problem.lsa;
    let mut genes: Vec<Gene> = lsa
        .points
        .iter()
        .map(|&at| Gene {
            active: true,
            at,
            speed: 1.0,
        })
        .collect();
    for _ in 0..INITIAL_REMOVALS {
        if let Some(k) = pick(rng, &clearable(&genes)) {
            clear(&mut genes, &lsa.times_s, k);
        }
    }
    Individual {
        genes,
        fit: Fitness::UNKNOWN,
    }
}

/// λ = μ offspring: pairs of 2-tournament parents, crossed with probability p_c, each child
/// mutated with probability p_m.
fn breed(
    problem: &Problem,
    pop: &[Individual],
    params: &GaParams,
    rng: &mut ChaCha8Rng,
) -> Vec<Individual> {
    let mut offspring = Vec::with_capacity(pop.len() + 1);
    while offspring.len() < pop.len() {
        let (p1, p2) = (tournament(pop, rng), tournament(pop, rng));
        let (mut c1, mut c2) = (p1.genes.clone(), p2.genes.clone());
        if rng.random_bool(params.crossover_rate.clamp(0.0, 1.0)) {
            crossover(&mut c1, &mut c2, rng);
        }
        for genes in [c1, c2] {
            let mut genes = genes;
            if rng.random_bool(params.mutation_rate.clamp(0.0, 1.0)) {
                mutate(problem, &mut genes, rng);
            }
            offspring.push(Individual {
                genes,
                fit: Fitness::UNKNOWN,
            });
        }
    }
    offspring.truncate(pop.len());
    offspring
}

/// 2-tournament on a population sorted by rank: the better ranked of two random individuals.
fn tournament<'p>(pop: &'p [Individual], rng: &mut ChaCha8Rng) -> &'p Individual {
    let (a, b) = (
        rng.random_range(0..pop.len()),
        rng.random_range(0..pop.len()),
    );
    &pop[a.min(b)]
}

fn pick(rng: &mut ChaCha8Rng, candidates: &[usize]) -> Option<usize> {
    (!candidates.is_empty()).then(|| candidates[rng.random_range(0..candidates.len())])
}

/// Genes whose turning point can be cleared: every active one but the first and the last.
fn clearable(genes: &[Gene]) -> Vec<usize> {
    let n = genes.len();
    (1..n.saturating_sub(1))
        .filter(|&k| genes[k].active)
        .collect()
}

/// Clear (Fig. 4): removes turning point `k`; the previous turning point's speed is recomputed
/// so that the stage still reaches the next one at the same time.
fn clear(genes: &mut [Gene], times_s: &[f64], k: usize) {
    let prev = (0..k).rev().find(|&i| genes[i].active);
    let next = (k + 1..genes.len()).find(|&i| genes[i].active);
    let (Some(p), Some(q)) = (prev, next) else {
        return;
    };
    let duration_s =
        (times_s[k] - times_s[p]) / genes[p].speed + (times_s[q] - times_s[k]) / genes[k].speed;
    let nominal_s = times_s[q] - times_s[p];
    if duration_s > 0.0 && nominal_s > 0.0 {
        genes[p].speed = (nominal_s / duration_s).clamp(MIN_SPEED, MAX_SPEED);
    }
    genes[k].active = false;
}

/// Improved 2-point crossover (Fig. 3): cut at two LSA points with a turning point in both
/// parents, exchange the genes from the first cut up to the second.
fn crossover(c1: &mut [Gene], c2: &mut [Gene], rng: &mut ChaCha8Rng) {
    let common: Vec<usize> = (0..c1.len())
        .filter(|&i| c1[i].active && c2[i].active)
        .collect();
    if common.len() < 2 {
        return;
    }
    let x = rng.random_range(0..common.len());
    let mut y = rng.random_range(0..common.len() - 1);
    if y >= x {
        y += 1;
    }
    let (a, b) = (common[x.min(y)], common[x.max(y)]);
    c1[a..b].swap_with_slice(&mut c2[a..b]);
}

/// Combination mutation (Fig. 4): clear, change position or change speed, uniformly.
fn mutate(problem: &Problem, genes: &mut [Gene], rng: &mut ChaCha8Rng) {
    let active: Vec<usize> = (0..genes.len()).filter(|&i| genes[i].active).collect();
    match rng.random_range(0..3) {
        0 => {
            if let Some(k) = pick(rng, &clearable(genes)) {
                clear(genes, &problem.lsa.times_s, k);
            }
        }
        1 => {
            if let Some(k) = pick(rng, &active) {
                genes[k].at = moved(problem, k, genes[k].at, rng);
            }
        }
        _ => {
            // the last turning point has no leg after it
            if let Some(k) = pick(rng, &active[..active.len().saturating_sub(1)]) {
                let f = 1.0 + rng.random_range(-SPEED_STEP..=SPEED_STEP);
                genes[k].speed = (genes[k].speed * f).clamp(MIN_SPEED, MAX_SPEED);
            }
        }
    }
}

/// Change position: a uniform random point within half the radius of `at`, pulled back within
/// the radius of LSA point `k` if it left it.
fn moved(problem: &Problem, k: usize, at: Pt, rng: &mut ChaCha8Rng) -> Pt {
    let r = problem.radius_mm();
    let rho = r / 2.0 * rng.random::<f64>().sqrt();
    let angle = rng.random_range(0.0..std::f64::consts::TAU);
    let p = at.plus(Pt::new(rho * angle.cos(), rho * angle.sin()));
    let centre = problem.lsa.points[k];
    let off = p.minus(centre);
    let d = off.norm();
    if d > r {
        centre.plus(off.scale(r / d))
    } else {
        p
    }
}
