//! The hybrid genetic algorithm (seed 000 §3.3).
//!
//! A chromosome is a geometry order (SCO) and a start choice per geometry (VO; kept per
//! geometry, so a gene carries its vertex wherever crossover puts it). Unseeded, the initial
//! population holds 3·ps random chromosomes plus two special ones (all minimum and all maximum
//! VO), as seed 000 says, and the HHA plan when seeded (the default); a large seeded job gets
//! mutants of the HHA plan (local double bridges, a field's vertices redrawn) instead of the
//! random ones, which each cost a full search and all rank far below the seed. Each is
//! improved by the chromosome enhancement algorithm ([`cea`]).
//! Every generation keeps the best 20 % (elitism), fills the rest with the offspring of
//! 0.5 · 0.8 · ps two-point crossovers of random elite pairs, mutates an offspring with
//! probability 30 % (new random vertices for every geometry of one random field) and enhances
//! every offspring. ps grows by 50 % (to at most 48) after a generation without improvement and
//! shrinks by 20 % (to at least 16) after one with; the run stops after `max_generations`
//! (when set), at the time limit, on cancel, or — without a time limit — after 5 generations
//! without improvement, returning the best plan found so far.
//!
//! **One objective.** Seed 000 ranks chromosomes on idle travel; here the fitness is the plan's
//! objective, handed in by the caller (`order::objective`): the job time under `--cost time`,
//! idle millimetres under `--cost distance`. Enhancement still shortens travel (its local
//! search is a distance TSP), but elitism, the best and the stall test all read the objective,
//! so the seed (HHA's finished plan) can only be replaced by a chromosome that beats it.
//!
//! **Cheap offspring on large jobs.** An offspring differs from its parents only around the
//! crossover's cut points, where the second parent's order skips the middle's genes, and in a
//! mutated field; on a job of more than `LOCAL_ENHANCEMENT_MIN_GEOMETRIES` (or under a time
//! limit: `local_search`) its local search
//! starts from those nodes only (don't-look bits on the rest) and its start choices are
//! re-optimised around them, so a generation costs about the changed part plus O(n)
//! bookkeeping and one O(n) evaluation per offspring, not a search of every node.
//!
//! Random draws happen on the calling thread in a fixed order and enhancement is parallel
//! (rayon) but deterministic, so a seed gives the same plan on any number of threads.

pub mod cea;

use super::{OrderError, Ordering};
use crate::document::{
    GaParams, GenerationRecord, Geometry, MachineProfile, ObjectiveKind, ScanField, SolverSettings,
    Step, VertexMode,
};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use crate::order::tsp::{neighbour_lists, Node, PathProblem};
use cea::{Lineage, Parent, Shared};
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
    /// The objective of the enhanced chromosome (s or mm; lower is fitter).
    pub cost: f64,
}

/// The objective HGA ranks chromosomes on: what it measures and how to compute it from strokes
/// in marking order.
pub struct Fitness<'a> {
    /// What the values are.
    pub kind: ObjectiveKind,
    /// The value of an order (one step per stroke, passes not repeated).
    pub of: &'a (dyn Fn(&[Step]) -> f64 + Sync),
}

/// What an HGA run returns.
#[derive(Debug, Clone)]
pub struct HgaResult {
    /// The best plan's ordering.
    pub ordering: Ordering,
    /// Best and mean objective per generation.
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
        cost: f64::INFINITY,
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
        cost: f64::INFINITY,
    }
}

/// Enhances chromosomes in parallel, each where it differs from its lineage (`None`: all of
/// it); `Err` when cancelled.
fn enhance_all(
    shared: &Shared,
    pop: &mut [Chromosome],
    lineages: &[Option<Lineage>],
    ctx: &JobCtx,
) -> Result<(), Cancelled> {
    pop.par_iter_mut()
        .zip(lineages.par_iter())
        .map(|(c, lineage)| shared.enhance(c, lineage.as_ref(), ctx))
        .collect::<Result<Vec<()>, Cancelled>>()
        .map(|_| ())
}

/// How many of a population of `len` (fittest first) are kept as elite at size `ps`: the elite
/// fraction of `ps`, at least the two parents a crossover needs.
fn elite_count(ga: &GaParams, ps: usize, len: usize) -> usize {
    ((ga.elite_fraction * ps as f64).ceil() as usize).clamp(2, len)
}

fn stats(pop: &[Chromosome]) -> (f64, f64) {
    let best = pop.iter().map(|c| c.cost).fold(f64::INFINITY, f64::min);
    let mean = pop.iter().map(|c| c.cost).sum::<f64>() / pop.len().max(1) as f64;
    (best, mean)
}

/// Runs HGA on allocated fields, ranking chromosomes on `fitness`; `seed_plan` (HHA's finished
/// plan) joins the initial population, so the result is never worse than it on `fitness`.
pub fn hga_order(
    geometries: &[Geometry],
    fields: &[ScanField],
    profile: &MachineProfile,
    settings: &SolverSettings,
    seed_plan: Option<&Ordering>,
    fitness: &Fitness,
    ctx: &JobCtx,
) -> Result<HgaResult, OrderError> {
    let t0 = Instant::now();
    let ga: &GaParams = &settings.ga;
    let shared = shared(geometries, fields, profile, settings, fitness, ctx)?;
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    let mut run = Run {
        ga,
        fields,
        t0,
        limit_s: settings.time_limit_s.unwrap_or(f64::INFINITY),
        local: local_search(geometries.len(), settings.time_limit_s),
        kind: fitness.kind,
        history: Vec::new(),
        ctx,
    };
    let mut ps = ga
        .population
        .clamp(ga.population_min.max(2), ga.population_max.max(2));
    let (mut pop, mut cancelled) = initial_population(
        &shared,
        ps,
        run.local,
        ga.mutation_rate,
        seed_plan,
        &mut rng,
        ctx,
    )?;
    let (mut best, mean) = stats(&pop);
    run.record(0, best, mean, pop.len());
    let mut stall = 0;
    let mut generation = 0;
    while !cancelled && !run.over(generation, stall) {
        generation += 1;
        let (offspring, was_cancelled) = run.offspring(&shared, &pop, ps, &mut rng);
        cancelled = was_cancelled;
        pop.truncate(elite_count(ga, ps, pop.len()));
        pop.extend(offspring);
        pop.sort_by(|a, b| a.cost.total_cmp(&b.cost));
        let (b, mean) = stats(&pop);
        if b < best - 1e-9 * best.abs().max(1.0) {
            best = b;
            stall = 0;
            ps = ((ps as f64 * 0.8).round() as usize).max(ga.population_min);
        } else {
            stall += 1;
            ps = ((ps as f64 * 1.5).round() as usize).min(ga.population_max);
        }
        run.record(generation, best, mean, pop.len());
    }
    let steps = shared.steps(&pop[0]);
    let mut field_order: Vec<usize> = Vec::new();
    for s in &steps {
        if field_order.last() != Some(&s.field) {
            field_order.push(s.field);
        }
    }
    Ok(HgaResult {
        ordering: Ordering { field_order, steps },
        history: run.history,
        cancelled,
    })
}

/// What every chromosome of a run shares: allocation, the corner, neighbour lists on the
/// geometries' centroids (node 0: the corner), the fitness.
fn shared<'a>(
    geometries: &'a [Geometry],
    fields: &[ScanField],
    profile: &MachineProfile,
    settings: &SolverSettings,
    fitness: &'a Fitness<'a>,
    ctx: &JobCtx,
) -> Result<Shared<'a>, OrderError> {
    let mut field_of = vec![0usize; geometries.len()];
    for f in fields {
        for &g in &f.geometries {
            field_of[g] = f.id;
        }
    }
    let corner = Pt::new(-profile.field_mm[0] / 2.0, -profile.field_mm[1] / 2.0);
    let mut pts = vec![corner];
    pts.extend(geometries.iter().map(Geometry::centroid));
    let mut nprob = PathProblem::points(&pts, &vec![0.0; pts.len()], 0.0);
    nprob.nodes = pts.iter().map(|&q| Node::point(q, 0.0)).collect();
    Ok(Shared {
        geometries,
        field_of,
        corner,
        penalty: profile.field_mm[0].hypot(profile.field_mm[1]),
        neighbours: neighbour_lists(&nprob, 12, ctx)?,
        exact_vertices: settings.vertex == VertexMode::Exact,
        fitness: fitness.of,
    })
}

/// The initial population, enhanced, sorted fittest first, with whether a cancel cut the
/// enhancement short: seed 000's 3·ps random chromosomes and the all-minimum and all-maximum
/// VO ones, plus the seed plan as it is (its cost computed, not enhanced: it is a finished
/// plan). A seeded run that searches locally ([`local_search`]) gets 3·ps + 2 mutants
/// of the seed instead of the random chromosomes, each enhanced where it differs from the seed:
/// random ones take a full search each (≈ 0.2 s on texture-3043's 9,129 strokes, 21 s for the
/// population) and all rank far below the seed.
fn initial_population(
    shared: &Shared,
    ps: usize,
    local: bool,
    mutation_rate: f64,
    seed_plan: Option<&Ordering>,
    rng: &mut ChaCha8Rng,
    ctx: &JobCtx,
) -> Result<(Vec<Chromosome>, bool), OrderError> {
    let geometries = shared.geometries;
    let n = 3 * ps + 2;
    ctx.progress("order", 0, 0, format!("HGA: initial population of {n}"));
    let seed = seed_plan.map(|plan| {
        let mut vo = vec![0; geometries.len()];
        for s in &plan.steps {
            vo[s.geometry] = s.choice(&geometries[s.geometry]);
        }
        Chromosome {
            sco: plan.steps.iter().map(|s| s.geometry).collect(),
            vo,
            cost: (shared.fitness)(&plan.steps),
        }
    });
    let random = seed.is_none() || !local;
    let (mut pop, cancelled) = match &seed {
        _ if random => {
            let mut pop: Vec<Chromosome> = (0..3 * ps)
                .map(|_| random_chromosome(geometries, rng, None))
                .collect();
            pop.push(random_chromosome(geometries, rng, Some(false)));
            pop.push(random_chromosome(geometries, rng, Some(true)));
            let lineages: Vec<Option<Lineage>> = (0..pop.len()).map(|_| None).collect();
            let cancelled = enhance_all(shared, &mut pop, &lineages, ctx).is_err();
            (pop, cancelled)
        }
        None => (Vec::new(), false),
        Some(seed) => {
            let (mut pop, mutated): (Vec<Chromosome>, Vec<Vec<usize>>) = (0..n)
                .map(|_| mutant(seed, shared, mutation_rate, rng))
                .unzip();
            let parent = Parent::of(&seed.sco);
            let lineages: Vec<Option<Lineage>> = mutated
                .iter()
                .map(|m| {
                    Some(Lineage {
                        parents: [&parent, &parent],
                        mutated: m,
                    })
                })
                .collect();
            let cancelled = enhance_all(shared, &mut pop, &lineages, ctx).is_err();
            (pop, cancelled)
        }
    };
    pop.extend(seed);
    pop.retain(|c| c.cost.is_finite());
    if pop.is_empty() {
        return Err(OrderError::Cancelled(Cancelled));
    }
    pop.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    Ok((pop, cancelled))
}

/// Jobs of more geometries than this are searched locally: mutants of the seed instead of
/// random chromosomes in the initial population, and offspring enhanced only where they differ
/// from their parents. Below it a full search per chromosome is cheap (≈ 5 ms per 100
/// geometries here) and worth its diversity and depth: with local enhancement throughout, HGA
/// under `--cost distance` ended 1–3 % higher on ISW-200, ISW-489 and rnd-122 (5 seeds).
const LOCAL_ENHANCEMENT_MIN_GEOMETRIES: usize = 2_000;

/// True when the run searches locally: on a large job, and under a time limit (a short limit
/// would otherwise go on the random initial population: with `--time-limit 0.5` on ISW-489 the
/// GA made one generation).
fn local_search(geometries: usize, time_limit_s: Option<f64>) -> bool {
    geometries > LOCAL_ENHANCEMENT_MIN_GEOMETRIES || time_limit_s.is_some()
}

/// Most genes a mutant's double bridge spans, as a share of the order.
const MUTANT_SPAN_SHARE: f64 = 0.05;

/// A mutant of `seed`: one to three local double bridges (three adjacent runs of the order
/// `A B C` become `A C B`, which 2-opt and Or-opt moves cannot undo in one step) and, with
/// the mutation rate, new random start choices for one field; with the mutated genes.
fn mutant(
    seed: &Chromosome,
    shared: &Shared,
    mutation_rate: f64,
    rng: &mut ChaCha8Rng,
) -> (Chromosome, Vec<usize>) {
    let mut c = seed.clone();
    c.cost = f64::INFINITY;
    let n = c.sco.len();
    if n >= 4 {
        let span = ((n as f64 * MUTANT_SPAN_SHARE) as usize).clamp(3, n - 1);
        for _ in 0..rng.random_range(1..=3) {
            let a = rng.random_range(0..n - span);
            let b = a + rng.random_range(1..span - 1);
            let e = a + span;
            let m = rng.random_range(b + 1..e);
            // [a, b) [b, m) [m, e) → [a, b) [m, e) [b, m)
            c.sco[b..e].rotate_left(m - b);
        }
    }
    let geometries = shared.geometries;
    let mut mutated = Vec::new();
    if n > 0 && rng.random_bool(mutation_rate.clamp(0.0, 1.0)) {
        let g = c.sco[rng.random_range(0..n)];
        let field = shared.field_of[g];
        for &h in &c.sco {
            if shared.field_of[h] == field {
                c.vo[h] = rng.random_range(0..geometries[h].start_choices());
                mutated.push(h);
            }
        }
    }
    (c, mutated)
}

/// One run's budget, history and reporting.
struct Run<'a> {
    ga: &'a GaParams,
    fields: &'a [ScanField],
    t0: Instant,
    limit_s: f64,
    /// Search locally ([`local_search`]).
    local: bool,
    kind: ObjectiveKind,
    history: Vec<GenerationRecord>,
    ctx: &'a JobCtx,
}

impl Run<'_> {
    /// True when the run should stop before `generation + 1`: at the cap, out of time, or —
    /// without a time limit — stalled. An operator who gives the GA a time limit gives it that
    /// time: the stall does not end the run then.
    fn over(&self, generation: usize, stall: usize) -> bool {
        let stalled = !self.limit_s.is_finite() && stall >= self.ga.stall_generations;
        stalled
            || self.ga.max_generations.is_some_and(|m| generation >= m)
            || self.t0.elapsed().as_secs_f64() >= self.limit_s
    }

    /// Records a generation and reports it: best and mean in the objective's unit, and how far
    /// the run has got (of the generation cap, or of the time limit).
    fn record(&mut self, g: usize, best: f64, mean: f64, population: usize) {
        let elapsed_s = self.t0.elapsed().as_secs_f64();
        self.history.push(GenerationRecord {
            generation: g,
            best,
            mean,
            objective: self.kind,
            population,
            elapsed_s,
            finished: false,
        });
        if let Some(r) = self.ctx.recorder() {
            r.generation(g, best, mean);
        }
        let unit = self.kind.unit();
        let (done, total, of) = match self.ga.max_generations {
            Some(m) => (g as u64, m as u64, format!(" of {m}")),
            None => (g as u64, 0, String::new()),
        };
        let time = if self.limit_s.is_finite() {
            format!(", {elapsed_s:.1} of {:.1} s", self.limit_s)
        } else {
            format!(", {elapsed_s:.1} s")
        };
        self.ctx.progress(
            "order",
            done,
            total,
            format!(
                "HGA generation {g}{of}{time}: best {} {unit}, mean {} {unit}, population \
                 {population}",
                self.kind.show(best),
                self.kind.show(mean)
            ),
        );
    }

    /// The offspring of one generation, enhanced from their changed nodes, with whether a
    /// cancel cut the enhancement short (the unfinished ones are dropped).
    fn offspring(
        &self,
        shared: &Shared,
        pop: &[Chromosome],
        ps: usize,
        rng: &mut ChaCha8Rng,
    ) -> (Vec<Chromosome>, bool) {
        let ga = self.ga;
        let geometries = shared.geometries;
        let elite = &pop[..elite_count(ga, ps, pop.len())];
        // each elite parent's successors, once for all its offspring (local search only)
        let parents: Vec<Parent> = if self.local {
            elite.iter().map(|c| Parent::of(&c.sco)).collect()
        } else {
            Vec::new()
        };
        let crossovers = ((0.5 * (1.0 - ga.elite_fraction) * ps as f64).round() as usize).max(1);
        let n = geometries.len();
        let mut offspring = Vec::with_capacity(2 * crossovers);
        let mut lineages = Vec::with_capacity(2 * crossovers);
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
            for (i1, i2) in [(i, j), (j, i)] {
                let mut child = two_point_crossover(&elite[i1], &elite[i2], a, b);
                let mut mutated: &[usize] = &[];
                if rng.random_bool(ga.mutation_rate.clamp(0.0, 1.0)) && !self.fields.is_empty() {
                    let f = &self.fields[rng.random_range(0..self.fields.len())];
                    for &g in &f.geometries {
                        child.vo[g] = rng.random_range(0..geometries[g].start_choices());
                    }
                    mutated = &f.geometries;
                }
                lineages.push(self.local.then(|| Lineage {
                    parents: [&parents[i1], &parents[i2]],
                    mutated,
                }));
                offspring.push(child);
            }
        }
        let cancelled = enhance_all(shared, &mut offspring, &lineages, self.ctx).is_err();
        offspring.retain(|c| c.cost.is_finite());
        (offspring, cancelled)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_offspring_is_searched_from_where_it_differs_from_both_parents() {
        let (p1, p2) = (
            Parent::of(&[0, 1, 2, 3, 4, 5, 6]),
            Parent::of(&[6, 5, 4, 3, 2, 1, 0]),
        );
        let from = |mutated: &'static [usize]| Lineage {
            parents: [&p1, &p2],
            mutated,
        };
        // p1's middle 2..=4 kept, the rest in p2's order: 6 5 | 2 3 4 | 1 0
        // 5→2 and 4→1 are new (neither parent has them); 6→5, 2→3, 3→4, 1→0 are inherited
        assert_eq!(
            from(&[]).changed_nodes(&[6, 5, 2, 3, 4, 1, 0]),
            vec![2, 3, 5, 6]
        );
        // a mutated gene joins (node = gene + 1); a first gene of neither parent adds the corner
        assert_eq!(
            from(&[3]).changed_nodes(&[5, 6, 0, 1, 2, 3, 4]),
            vec![0, 1, 4, 7]
        );
    }

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
            cost: 0.0,
        };
        let p2 = Chromosome {
            sco: vec![1, 0, 6, 4, 5, 3, 2],
            vo: vo2,
            cost: 0.0,
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
