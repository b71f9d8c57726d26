//! The driver: local search to a local optimum, then iterated local search with segment-local
//! double-bridge kicks, accepting equal or better, bounded by kicks, stall and a deadline.

use super::candidates::neighbour_lists;
use super::engine::{Engine, Halt, IMPROVE_EPS};
use super::problem::{PathProblem, Tour};
use crate::job::{Cancelled, JobCtx};
use rand::{Rng, SeedableRng};
use std::borrow::Cow;
use std::time::Instant;

/// Options of [`local_search`].
#[derive(Debug, Clone, Copy)]
pub struct LsOptions {
    /// Neighbour list length.
    pub neighbours: usize,
    /// Longest run moved by Or-opt (Or-3opt moves runs of any length).
    pub or_max: usize,
}

impl Default for LsOptions {
    fn default() -> Self {
        Self {
            neighbours: 16,
            or_max: 3,
        }
    }
}

/// Longest run of a kick: the two swapped runs each hold 1..=min(this, a third of the path)
/// nodes. Only the six nodes at the three new edges are searched again, so a kick stays local
/// in its repair whatever the runs' lengths; longer runs reach farther. On 1,000 uniform points
/// (5 instances × 2 seeds, 2,000 kicks) the median gap to LKH was 1.10 % with runs of at most
/// 30 nodes, 0.94 % with 100, 0.79 % with a third of the path. The bound keeps the three
/// reversals of a kick short on huge paths.
const KICK_RUN_MAX: usize = 1000;

/// Kicks between two polls of the cancel token and the deadline outside the local search.
const KICK_POLL: usize = 8;

/// How long the iterated local search may go on. It stops at whichever bound comes first.
#[derive(Debug, Clone, Copy)]
pub struct IlsBudget {
    /// Most kicks.
    pub kicks: usize,
    /// Stop after this many kicks in a row without a strict improvement.
    pub stall: usize,
    /// Stop when this instant passes (results then depend on the machine's speed).
    pub deadline: Option<Instant>,
}

impl IlsBudget {
    /// The default budget for a path of `n` nodes: `kicks` when given, else
    /// [`default_kicks`]`(n)`; no stall bound, no deadline.
    pub fn for_nodes(n: usize, kicks: Option<usize>) -> Self {
        Self::kicks(kicks.unwrap_or_else(|| default_kicks(n)))
    }

    /// The same budget with its kick count (when finite) divided by `d`, but not below
    /// `DIVIDED_KICKS_MIN` (small paths keep their whole budget: their kicks are cheap, and a
    /// few kicks leave a small path far from its optimum).
    pub fn divided(self, d: usize) -> Self {
        Self {
            kicks: if self.kicks == usize::MAX {
                self.kicks
            } else {
                (self.kicks / d.max(1)).max(self.kicks.min(DIVIDED_KICKS_MIN))
            },
            ..self
        }
    }

    /// The budget of a path of `n` nodes with an optional deadline: without one,
    /// [`default_kicks`] (deterministic); with one, kicks until the deadline or until
    /// [`STALL_PER_NODE`]` · n` kicks in a row (at least [`STALL_MIN`]) found nothing better.
    pub fn until(n: usize, deadline: Option<Instant>) -> Self {
        match deadline {
            None => Self::kicks(default_kicks(n)),
            Some(t) => Self {
                kicks: usize::MAX,
                stall: (STALL_PER_NODE * n).max(STALL_MIN),
                deadline: Some(t),
            },
        }
    }

    /// Exactly `kicks` kicks (no stall bound, no deadline): deterministic.
    pub fn kicks(kicks: usize) -> Self {
        Self {
            kicks,
            stall: usize::MAX,
            deadline: None,
        }
    }
}

/// Kicks in a row without a strict improvement, per node, after which a search with a deadline
/// stops early (a small path reaches its optimum long before any deadline).
pub const STALL_PER_NODE: usize = 50;

/// Least stall bound of a search with a deadline.
pub const STALL_MIN: usize = 1000;

/// Fewest kicks of a divided budget ([`IlsBudget::divided`]).
pub const DIVIDED_KICKS_MIN: usize = 200;

/// Kicks per node of the default budget.
const KICKS_PER_NODE: usize = 2;

/// Most kicks of the default budget (reached from 2,000 nodes on). 1,000 uniform points get
/// 2,000 kicks: 0.12–0.15 s of search on this project's 2-core machine (a kick and its repair
/// take about 55 µs there), a median of +0.8 % above LKH on five sets (best of two seeds;
/// 1,500 kicks gave +0.85 %, 3,000 +0.6 %; BENCHMARKS, issue 24).
const KICKS_MAX: usize = 4000;

/// Bound on `kicks · n` of the default budget, so that a huge path (whose construction and first
/// descent dominate) gets fewer kicks: 4,000 up to 10⁴ nodes, 400 at 10⁵. Raised from 10⁷
/// when a lone field's HHA descent gave way to a Hilbert start (issue 16), and from 2 · 10⁷
/// when the local search got faster: on 10⁴ dots 1,500 kicks gave +2.48 % above LKH, 3,000
/// +2.07 %, 6,000 +1.56 % (BENCHMARKS, issue 24).
const KICK_WORK_MAX: usize = 40_000_000;

/// Kicks of the default budget for a path of `n` nodes: `KICKS_PER_NODE` per node, at least 32,
/// at most `KICKS_MAX` and `KICK_WORK_MAX`` / n` (at least 8).
pub fn default_kicks(n: usize) -> usize {
    (KICKS_PER_NODE * n)
        .clamp(32, KICKS_MAX)
        .min(KICK_WORK_MAX / n.max(1))
        .max(8)
}

/// 2-opt, Or-opt, Or-3opt and Lin–Kernighan chains with neighbour lists and don't-look bits,
/// respecting fixed ends. Improves `tour` in place; returns the new cost.
pub fn local_search(
    prob: &PathProblem,
    tour: &mut Tour,
    opts: LsOptions,
    ctx: &JobCtx,
) -> Result<f64, Cancelled> {
    LocalSearch::new(prob, opts, ctx)?.run(tour, None, ctx)
}

/// A local search with its neighbour lists built once, for repeated runs (iterated local search,
/// the GA's chromosome enhancement).
pub struct LocalSearch<'a> {
    prob: &'a PathProblem,
    nbr: Cow<'a, [Vec<usize>]>,
    opts: LsOptions,
}

impl<'a> LocalSearch<'a> {
    /// Builds the neighbour lists (polling `ctx`: about a second at 10⁵ nodes).
    pub fn new(prob: &'a PathProblem, opts: LsOptions, ctx: &JobCtx) -> Result<Self, Cancelled> {
        Ok(Self {
            prob,
            nbr: Cow::Owned(neighbour_lists(prob, opts.neighbours, ctx)?),
            opts,
        })
    }

    /// A local search with neighbour lists supplied by the caller (shared between runs whose nodes
    /// keep their neighbourhoods, e.g. the GA's chromosomes).
    pub fn with_neighbours(prob: &'a PathProblem, nbr: &'a [Vec<usize>], opts: LsOptions) -> Self {
        Self {
            prob,
            nbr: Cow::Borrowed(nbr),
            opts,
        }
    }

    /// Runs the local search to a local optimum, starting from the nodes in `start` (all when
    /// `None`). On cancellation `tour` holds the (valid, improved) tour reached so far.
    pub fn run(
        &self,
        tour: &mut Tour,
        start: Option<&[usize]>,
        ctx: &JobCtx,
    ) -> Result<f64, Cancelled> {
        let Some(mut eng) = Engine::new(self.prob, &self.nbr, tour, self.opts.or_max) else {
            return Ok(self.prob.tour_cost(tour));
        };
        match start {
            Some(s) => s.iter().for_each(|&v| eng.push(v)),
            None => tour.order.iter().for_each(|&v| eng.push(v)),
        }
        let halt = eng.improve(ctx).err();
        eng.ring.write(tour);
        match halt {
            Some(Halt::Cancelled) => Err(Cancelled),
            _ => Ok(self.prob.tour_cost(tour)),
        }
    }

    /// Iterated local search with exactly `kicks` kicks (see [`LocalSearch::iterated_within`]).
    pub fn iterated(
        &self,
        tour: &mut Tour,
        kicks: usize,
        seed: u64,
        ctx: &JobCtx,
    ) -> Result<f64, Cancelled> {
        self.iterated_within(tour, IlsBudget::kicks(kicks), seed, ctx)
    }

    /// Iterated local search: a local optimum, then kicks (two short adjacent runs swapped, a
    /// local double bridge) each followed by local search around it, keeping the result when it
    /// is not worse. Deterministic for a given `seed` unless the deadline ends it. On
    /// cancellation `tour` holds the best tour so far.
    pub fn iterated_within(
        &self,
        tour: &mut Tour,
        budget: IlsBudget,
        seed: u64,
        ctx: &JobCtx,
    ) -> Result<f64, Cancelled> {
        let Some(mut eng) = Engine::new(self.prob, &self.nbr, tour, self.opts.or_max) else {
            return Ok(self.prob.tour_cost(tour));
        };
        eng.deadline = budget.deadline;
        tour.order.iter().for_each(|&v| eng.push(v));
        let mut halt = eng.improve(ctx).err();
        eng.commit();
        if halt.is_none() {
            halt = kick_loop(&mut eng, budget, seed, ctx).err();
        }
        eng.ring.write(tour);
        match halt {
            Some(Halt::Cancelled) => Err(Cancelled),
            _ => Ok(self.prob.tour_cost(tour)),
        }
    }
}

/// The kicks of the iterated local search, on a tour at a local optimum.
fn kick_loop(eng: &mut Engine, budget: IlsBudget, seed: u64, ctx: &JobCtx) -> Result<(), Halt> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut cost = eng.cost();
    let mut stall = 0usize;
    for k in 0..budget.kicks {
        if stall >= budget.stall {
            break;
        }
        if k % KICK_POLL == 0 {
            eng.poll(ctx)?;
        }
        let Some(kick) = double_bridge(eng, &mut rng) else {
            break;
        };
        let repaired = eng.improve(ctx);
        let next = cost + kick + repaired.unwrap_or(f64::INFINITY);
        // accept equal or better: plateaus are crossed, the cost never rises
        if next <= cost {
            stall = if next < cost - IMPROVE_EPS {
                0
            } else {
                stall + 1
            };
            cost = next;
        } else {
            eng.undo_to(0);
            eng.clear_queue();
            stall += 1;
        }
        eng.commit();
        repaired?;
    }
    Ok(())
}

/// A local double bridge: two adjacent random runs of 1..=[`KICK_RUN_MAX`] nodes swapped; the
/// nodes at the three new edges are queued. Returns the change of cost, `None` when the movable
/// part is too short.
fn double_bridge(eng: &mut Engine, rng: &mut rand_chacha::ChaCha8Rng) -> Option<f64> {
    let span = eng.hi + 1 - eng.lo;
    if span < 4 {
        return None;
    }
    let max_len = (span / 3).clamp(1, KICK_RUN_MAX);
    let (l1, l2) = (rng.random_range(1..=max_len), rng.random_range(1..=max_len));
    let a = rng.random_range(eng.lo..=eng.hi + 1 - (l1 + l2));
    let c = a + l1 + l2;
    let before = eng.edge_into(a) + eng.edge_into(a + l1) + eng.edge_into(c);
    eng.swap_runs(a, a + l1 - 1, c - 1);
    let after = eng.edge_into(a) + eng.edge_into(a + l2) + eng.edge_into(c);
    let n = eng.len();
    for k in [
        a.saturating_sub(1),
        a,
        a + l2 - 1,
        a + l2,
        c - 1,
        c.min(n - 1),
    ] {
        let v = eng.ring.at(k);
        eng.push(v);
    }
    Some(after - before)
}

/// A plain open path through `points` on distance, both ends free: a Hilbert-curve start, then
/// iterated local search within `budget`. Returns the order.
pub fn open_path(
    points: &[crate::geom::Pt],
    budget: IlsBudget,
    seed: u64,
    ctx: &JobCtx,
) -> Result<Vec<usize>, Cancelled> {
    let n = points.len();
    let prob = PathProblem::points(points, &vec![0.0; n], 0.0);
    let mut tour = Tour {
        order: super::construct::space_filling_order(points),
        flipped: vec![false; n],
    };
    LocalSearch::new(&prob, LsOptions::default(), ctx)?
        .iterated_within(&mut tour, budget, seed, ctx)?;
    Ok(tour.order)
}
