//! The hybrid genetic algorithm (seed 000 §3.3).
//!
//! A chromosome is a geometry order (SCO) and a start choice per geometry (VO; kept per
//! geometry, so a gene carries its vertex wherever crossover puts it). The initial population
//! holds 3·ps random chromosomes plus two special ones (all minimum and all maximum VO) and,
//! optionally, the HHA plan; each is improved by the chromosome enhancement algorithm ([`cea`]).
//! Every generation keeps the best 20 % (elitism), fills the rest with the offspring of
//! 0.5 · 0.8 · ps two-point crossovers of random elite pairs, mutates an offspring with
//! probability 30 % (new random vertices for every geometry of one random field) and enhances
//! every offspring. ps grows by 50 % (to at most 48) after a generation without improvement and
//! shrinks by 20 % (to at least 16) after one with; the run stops after 5 generations without
//! improvement, at the time limit, or on cancel — returning the best plan found so far.
//! Random draws happen on the calling thread in a fixed order and enhancement is parallel
//! (rayon) but deterministic, so a seed gives the same plan on any number of threads.

pub mod cea;

use super::{OrderError, Ordering};
use crate::document::{
    GaParams, GenerationRecord, Geometry, MachineProfile, ScanField, SolverSettings, VertexMode,
};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use crate::order::tsp::{neighbour_lists, Node, PathProblem};
use cea::Shared;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::time::Instant;

/// A candidate plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Chromosome {
    /// Geometry order (sub-cluster order).
    pub sco: Vec<usize>,
    /// Start choice per geometry (vertex order), indexed by geometry.
    pub vo: Vec<usize>,
    /// Idle travel of the enhanced chromosome, mm (the fitness is its reciprocal).
    pub idle_mm: f64,
}

/// What an HGA run returns.
#[derive(Debug, Clone)]
pub struct HgaResult {
    /// The best plan's ordering.
    pub ordering: Ordering,
    /// Best and mean idle per generation.
    pub history: Vec<GenerationRecord>,
    /// True when the run was cancelled (the ordering is the best found until then).
    pub cancelled: bool,
}

fn two_point_crossover(p1: &Chromosome, p2: &Chromosome, a: usize, b: usize) -> Chromosome {
    let n = p1.sco.len();
    let middle = &p1.sco[a..=b];
    let mut taken = vec![false; p1.vo.len()];
    for &g in middle {
        taken[g] = true;
    }
    let mut rest = p2.sco.iter().copied().filter(|&g| !taken[g]);
    let mut sco = Vec::with_capacity(n);
    let mut vo = p2.vo.clone();
    for k in 0..n {
        if k >= a && k <= b {
            let g = p1.sco[k];
            sco.push(g);
            vo[g] = p1.vo[g];
        } else if let Some(g) = rest.next() {
            sco.push(g);
        }
    }
    Chromosome {
        sco,
        vo,
        idle_mm: f64::INFINITY,
    }
}

fn random_chromosome(
    geometries: &[Geometry],
    rng: &mut ChaCha8Rng,
    vo_rule: Option<bool>,
) -> Chromosome {
    let mut sco: Vec<usize> = (0..geometries.len()).collect();
    sco.shuffle(rng);
    let vo = geometries
        .iter()
        .map(|g| match vo_rule {
            Some(false) => 0,
            Some(true) => g.start_choices() - 1,
            None => rng.random_range(0..g.start_choices()),
        })
        .collect();
    Chromosome {
        sco,
        vo,
        idle_mm: f64::INFINITY,
    }
}

/// Enhances chromosomes in parallel; `Err` when cancelled.
fn enhance_all(
    shared: &Shared,
    pop: &mut [Chromosome],
    seeds: &[u64],
    kicks: usize,
    ctx: &JobCtx,
) -> Result<(), Cancelled> {
    pop.par_iter_mut()
        .zip(seeds.par_iter())
        .map(|(c, &s)| shared.enhance(c, s, kicks, ctx))
        .collect::<Result<Vec<()>, Cancelled>>()
        .map(|_| ())
}

fn stats(pop: &[Chromosome]) -> (f64, f64) {
    let best = pop.iter().map(|c| c.idle_mm).fold(f64::INFINITY, f64::min);
    let mean = pop.iter().map(|c| c.idle_mm).sum::<f64>() / pop.len().max(1) as f64;
    (best, mean)
}

/// Runs HGA on allocated fields; `seed_plan` (e.g. the HHA result) joins the initial population.
pub fn hga_order(
    geometries: &[Geometry],
    fields: &[ScanField],
    profile: &MachineProfile,
    settings: &SolverSettings,
    seed_plan: Option<&Ordering>,
    ctx: &JobCtx,
) -> Result<HgaResult, OrderError> {
    let t0 = Instant::now();
    let ga: &GaParams = &settings.ga;
    let mut field_of = vec![0usize; geometries.len()];
    for f in fields {
        for &g in &f.geometries {
            field_of[g] = f.id;
        }
    }
    let corner = Pt::new(-profile.field_mm[0] / 2.0, -profile.field_mm[1] / 2.0);
    // neighbour lists on the geometries' centroids, shared by every chromosome (node 0: corner)
    let mut pts = vec![corner];
    pts.extend(geometries.iter().map(Geometry::centroid));
    let mut nprob = PathProblem::points(&pts, &vec![0.0; pts.len()], 0.0);
    nprob.nodes = pts.iter().map(|&q| Node::point(q, 0.0)).collect();
    let shared = Shared {
        geometries,
        field_of,
        corner,
        penalty: profile.field_mm[0].hypot(profile.field_mm[1]),
        neighbours: neighbour_lists(&nprob, 12, ctx)?,
        exact_vertices: settings.vertex == VertexMode::Exact,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    let limit_s = settings.time_limit_s.unwrap_or(f64::INFINITY);
    let mut ps = ga
        .population
        .clamp(ga.population_min.max(2), ga.population_max.max(2));
    // initial population: 3·ps random, all-minimum and all-maximum VO, the seed plan
    let mut pop: Vec<Chromosome> = (0..3 * ps)
        .map(|_| random_chromosome(geometries, &mut rng, None))
        .collect();
    pop.push(random_chromosome(geometries, &mut rng, Some(false)));
    pop.push(random_chromosome(geometries, &mut rng, Some(true)));
    let seeds: Vec<u64> = (0..pop.len()).map(|_| rng.random()).collect();
    ctx.progress(
        "order",
        0,
        0,
        format!("HGA: initial population of {}", pop.len()),
    );
    let mut history = Vec::new();
    let mut cancelled = enhance_all(&shared, &mut pop, &seeds, 0, ctx).is_err();
    if let Some(plan) = seed_plan {
        let mut vo = vec![0; geometries.len()];
        for s in &plan.steps {
            vo[s.geometry] = s.choice(&geometries[s.geometry]);
        }
        let steps = plan.steps.clone();
        let idle_mm = super::metrics::idle_mm(geometries, &steps);
        pop.push(Chromosome {
            sco: steps.iter().map(|s| s.geometry).collect(),
            vo,
            idle_mm,
        });
    }
    pop.retain(|c| c.idle_mm.is_finite());
    if pop.is_empty() {
        return Err(OrderError::Cancelled(Cancelled));
    }
    pop.sort_by(|a, b| a.idle_mm.total_cmp(&b.idle_mm));
    let (mut best, mean) = stats(&pop);
    let record = |g: usize, best: f64, mean: f64, ps: usize, h: &mut Vec<GenerationRecord>| {
        h.push(GenerationRecord {
            generation: g,
            best_idle_mm: best,
            mean_idle_mm: mean,
            population: ps,
            elapsed_s: t0.elapsed().as_secs_f64(),
        });
        if let Some(r) = ctx.recorder() {
            r.generation(g, best, mean);
        }
        ctx.progress(
            "order",
            g as u64,
            0,
            format!("HGA generation {g}: best {best:.1} mm, mean {mean:.1} mm, population {ps}"),
        );
    };
    record(0, best, mean, pop.len(), &mut history);
    let mut stall = 0;
    let mut generation = 0;
    while !cancelled && stall < ga.stall_generations && t0.elapsed().as_secs_f64() < limit_s {
        generation += 1;
        let elite_n = ((ga.elite_fraction * ps as f64).ceil() as usize).clamp(2, pop.len());
        let elite: Vec<Chromosome> = pop[..elite_n].to_vec();
        let crossovers = ((0.5 * (1.0 - ga.elite_fraction) * ps as f64).round() as usize).max(1);
        let n = geometries.len();
        let mut offspring = Vec::with_capacity(2 * crossovers);
        for _ in 0..crossovers {
            let i = rng.random_range(0..elite.len());
            let mut j = rng.random_range(0..elite.len() - 1);
            if j >= i {
                j += 1;
            }
            let (mut a, mut b) = (rng.random_range(0..n), rng.random_range(0..n));
            if a > b {
                std::mem::swap(&mut a, &mut b);
            }
            for (p1, p2) in [(&elite[i], &elite[j]), (&elite[j], &elite[i])] {
                let mut child = two_point_crossover(p1, p2, a, b);
                if rng.random_bool(ga.mutation_rate.clamp(0.0, 1.0)) && !fields.is_empty() {
                    let f = &fields[rng.random_range(0..fields.len())];
                    for &g in &f.geometries {
                        child.vo[g] = rng.random_range(0..geometries[g].start_choices());
                    }
                }
                offspring.push(child);
            }
        }
        let seeds: Vec<u64> = (0..offspring.len()).map(|_| rng.random()).collect();
        cancelled = enhance_all(&shared, &mut offspring, &seeds, 0, ctx).is_err();
        offspring.retain(|c| c.idle_mm.is_finite());
        let mut next = elite;
        next.extend(offspring);
        next.sort_by(|a, b| a.idle_mm.total_cmp(&b.idle_mm));
        pop = next;
        let (b, mean) = stats(&pop);
        if b < best - 1e-9 {
            best = b;
            stall = 0;
            ps = ((ps as f64 * 0.8).round() as usize).max(ga.population_min);
        } else {
            stall += 1;
            ps = ((ps as f64 * 1.5).round() as usize).min(ga.population_max);
        }
        record(generation, best, mean, pop.len(), &mut history);
    }
    let winner = &pop[0];
    let steps = shared.steps(winner);
    let mut field_order: Vec<usize> = Vec::new();
    for s in &steps {
        if field_order.last() != Some(&s.field) {
            field_order.push(s.field);
        }
    }
    Ok(HgaResult {
        ordering: Ordering { field_order, steps },
        history,
        cancelled,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossover_matches_the_seed_example() {
        // seed 000 Eq. 14–17: parents (14) and (15), cut at 2..=4
        let mut vo1 = vec![0; 7];
        let mut vo2 = vec![0; 7];
        for (g, v) in [0, 1, 2, 3, 5, 4, 6].iter().zip([9, 19, 6, 7, 0, 8, 1]) {
            vo1[*g] = v;
        }
        for (g, v) in [1, 0, 6, 4, 5, 3, 2].iter().zip([14, 8, 0, 8, 0, 7, 6]) {
            vo2[*g] = v;
        }
        let p1 = Chromosome {
            sco: vec![0, 1, 2, 3, 5, 4, 6],
            vo: vo1,
            idle_mm: 0.0,
        };
        let p2 = Chromosome {
            sco: vec![1, 0, 6, 4, 5, 3, 2],
            vo: vo2,
            idle_mm: 0.0,
        };
        // os1 takes the middle from p1 and the rest from p2 (the seed's naming swaps the parents)
        let os1 = two_point_crossover(&p2, &p1, 2, 4);
        let os2 = two_point_crossover(&p1, &p2, 2, 4);
        assert_eq!(os1.sco, vec![0, 1, 6, 4, 5, 2, 3]);
        assert_eq!(os2.sco, vec![1, 0, 2, 3, 5, 6, 4]);
        let vo_in_order = |c: &Chromosome| c.sco.iter().map(|&g| c.vo[g]).collect::<Vec<_>>();
        assert_eq!(vo_in_order(&os1), vec![9, 19, 0, 8, 0, 6, 7]);
        assert_eq!(vo_in_order(&os2), vec![14, 8, 6, 7, 0, 0, 8]);
    }
}
