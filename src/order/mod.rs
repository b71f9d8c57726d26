//! Ordering: which field after which, which geometry after which, where each one starts.

mod as_is;
mod bands;
mod baseline;
pub mod cost;
pub mod hga;
pub mod hha;
pub mod metrics;
mod passes;
pub mod time;
pub mod tsp;
pub mod vertex;

pub use as_is::as_is_order;
pub use baseline::baseline_order;
pub use passes::expand_passes;

use crate::document::{
    Algo, CostModel, GenerationRecord, Geometry, MachineProfile, MotionMode, Plan, PlanInputs,
    ScanField, SolverSettings, Step,
};
use crate::job::{Cancelled, JobCtx};
use crate::motion::{lower_motion, MotionError, OtfError, Toolpath};
use thiserror::Error;

/// Why ordering failed.
#[derive(Debug, Error)]
pub enum OrderError {
    /// The operator cancelled and there is no plan to return.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
    /// A geometry is not allocated to any field.
    #[error("{0} geometries are not allocated to a scan field (first: geometry {1})")]
    Unallocated(usize, usize),
    /// The plan cannot be turned into machine motion.
    #[error(transparent)]
    Lower(#[from] MotionError),
}

/// The ordered strokes of a run, before metrics.
#[derive(Debug, Clone, Default)]
pub struct Ordering {
    /// Field ids in visiting order.
    pub field_order: Vec<usize>,
    /// Strokes in marking order.
    pub steps: Vec<Step>,
}

/// Orders the allocated geometries with the algorithm in `inputs.settings` and returns the
/// plan with its metrics (stage times other than `order` are left for the caller to fill in)
/// and the toolpath they were computed on, so that the caller need not lower the plan again.
/// Every candidate is judged on the inputs' time law, pens and passes included
/// ([`Candidates`]).
pub fn order_plan(
    geometries: &[Geometry],
    fields: &[ScanField],
    inputs: &PlanInputs,
    ctx: &JobCtx,
) -> Result<(Plan, Toolpath), OrderError> {
    check_allocation(geometries.len(), fields)?;
    let (profile, settings) = (&inputs.profile, &inputs.settings);
    let lower = Candidates {
        geometries,
        fields,
        inputs,
        ctx,
    };
    let t0 = std::time::Instant::now();
    let mut detail = Vec::new();
    let (ordering, seed_ordering, history) =
        run_algorithm(geometries, fields, profile, settings, ctx, &mut detail)?;
    let (ordering, taut) = if settings.motion == MotionMode::OnTheFly && settings.algo != Algo::AsIs
    {
        let t = std::time::Instant::now();
        let best = faster_on_the_fly(&lower, ordering)?;
        detail.push(("bands".into(), t.elapsed().as_secs_f64()));
        (best.0, Some(best.1))
    } else {
        (ordering, None)
    };
    let (ordering, toolpath) = if settings.cost_model == CostModel::Time
        && settings.algo != Algo::AsIs
        && settings.motion == MotionMode::Step
    {
        let t = std::time::Instant::now();
        // under HHA a time limit ends the last search (HGA spends it on its generations)
        let until = (settings.algo == Algo::Hha)
            .then(|| hha::deadline(settings, t0, hha::LAST_SEARCH_SHARE))
            .flatten();
        let mut best = time_ordering(&lower, ordering, until)?;
        if let Some(seed) = seed_ordering {
            // HGA's own objective is idle travel: on time, its HHA seed may still be faster
            let other = time_ordering(&lower, seed, until)?;
            best = faster(best, other);
        }
        detail.push(("time".into(), t.elapsed().as_secs_f64()));
        best
    } else {
        let toolpath = match taut {
            Some(toolpath) => toolpath,
            None => lower.toolpath(&ordering)?,
        };
        (ordering, toolpath)
    };
    let order_s = t0.elapsed().as_secs_f64();
    let mut plan = lower.plan(&ordering);
    let mut m = metrics::compute(geometries, &plan.fields, &plan.order, profile, &toolpath);
    m.solve_s.order = order_s;
    m.solve_s.order_detail = detail;
    plan.name = settings.algo.label().into();
    plan.metrics = m;
    plan.history = history;
    Ok((plan, toolpath))
}

/// The one lower-and-compare helper: turns candidate orderings into plans of the solve's
/// inputs (pens, passes, profile, motion) and lowers them, so that every keep-the-faster
/// choice is judged on the time law the plan will have.
struct Candidates<'a> {
    geometries: &'a [Geometry],
    fields: &'a [ScanField],
    inputs: &'a PlanInputs,
    ctx: &'a JobCtx,
}

impl Candidates<'_> {
    /// The plan of an ordering (unnamed, without metrics): its fields in visiting order, its
    /// strokes repeated for their layers' passes.
    fn plan(&self, ordering: &Ordering) -> Plan {
        let order = expand_passes(&ordering.steps, self.geometries, &self.inputs.layers);
        Plan::new(
            self.inputs,
            fields_in_order(self.fields, &ordering.field_order),
            order,
        )
    }
    /// The toolpath of an ordering. A search cancelled with a result (HGA's best so far) still
    /// gets its toolpath; a cancel during the lowering itself (on the fly, seconds on large
    /// jobs) stops it.
    fn toolpath(&self, ordering: &Ordering) -> Result<Toolpath, OrderError> {
        let finish = JobCtx::default();
        let ctx = if self.ctx.is_cancelled() {
            &finish
        } else {
            self.ctx
        };
        match lower_motion(self.geometries, &self.plan(ordering), None, ctx) {
            Err(MotionError::OnTheFly(OtfError::Cancelled(c))) => Err(OrderError::Cancelled(c)),
            other => Ok(other?),
        }
    }
}

/// The faster of two lowered candidates; the first on a tie.
fn faster(a: (Ordering, Toolpath), b: (Ordering, Toolpath)) -> (Ordering, Toolpath) {
    if b.1.duration_s() < a.1.duration_s() {
        b
    } else {
        a
    }
}

/// The ordering of the settings' algorithm, HGA's HHA seed ordering (when it had one) and HGA's
/// convergence history.
fn run_algorithm(
    geometries: &[Geometry],
    fields: &[ScanField],
    profile: &MachineProfile,
    settings: &SolverSettings,
    ctx: &JobCtx,
    detail: &mut Vec<(String, f64)>,
) -> Result<(Ordering, Option<Ordering>, Vec<GenerationRecord>), OrderError> {
    Ok(match settings.algo {
        Algo::AsIs => (as_is_order(geometries, fields, ctx)?, None, Vec::new()),
        Algo::Baseline => (baseline_order(geometries, fields, ctx)?, None, Vec::new()),
        Algo::Hha => {
            let ordering = hha::hha_order(geometries, fields, profile, settings, ctx, detail)?;
            (ordering, None, Vec::new())
        }
        Algo::Hga => {
            let (r, seed) = run_hga(geometries, fields, profile, settings, ctx, detail)?;
            (r.ordering, seed, r.history)
        }
    })
}

/// On the fly: the algorithm's ordering or the sweep of field-wide bands
/// ([`bands::band_order`]), whichever runs faster on the taut route, with that toolpath.
fn faster_on_the_fly(
    lower: &Candidates,
    ordering: Ordering,
) -> Result<(Ordering, Toolpath), OrderError> {
    let by_fields = lower.toolpath(&ordering)?;
    let field_mm = lower.inputs.profile.field_mm;
    let band_mm = field_mm[0].min(field_mm[1]);
    let bands = bands::band_order(lower.geometries, lower.fields, band_mm, lower.ctx)?;
    if bands.steps == ordering.steps {
        return Ok((ordering, by_fields));
    }
    let by_bands = lower.toolpath(&bands)?;
    Ok(faster((ordering, by_fields), (bands, by_bands)))
}

/// HGA, seeded with the HHA plan when the settings say so; returns the seed plan too.
fn run_hga(
    geometries: &[Geometry],
    fields: &[ScanField],
    profile: &MachineProfile,
    settings: &SolverSettings,
    ctx: &JobCtx,
    detail: &mut Vec<(String, f64)>,
) -> Result<(hga::HgaResult, Option<Ordering>), OrderError> {
    let t = std::time::Instant::now();
    let seed_plan = if settings.ga.seed_with_hha {
        Some(hha::hha_order(
            geometries, fields, profile, settings, ctx, detail,
        )?)
    } else {
        None
    };
    detail.push(("hha_seed".into(), t.elapsed().as_secs_f64()));
    let t = std::time::Instant::now();
    let r = hga::hga_order(
        geometries,
        fields,
        profile,
        settings,
        seed_plan.as_ref(),
        ctx,
    )?;
    detail.push(("ga".into(), t.elapsed().as_secs_f64()));
    Ok((r, seed_plan))
}

/// The fields of `order` (ids) in that order.
fn fields_in_order(fields: &[ScanField], order: &[usize]) -> Vec<ScanField> {
    let by_id: std::collections::HashMap<usize, &ScanField> =
        fields.iter().map(|f| (f.id, f)).collect();
    order
        .iter()
        .filter_map(|id| by_id.get(id).map(|&f| f.clone()))
        .collect()
}

/// The distance ordering refined for job time ([`time::refine_for_time`]); the refinement is
/// kept only when its toolpath is not slower, so `--cost time` never loses to `--cost distance`.
/// After a cancel the ordering is returned as it is (the best so far).
fn time_ordering(
    lower: &Candidates,
    ordering: Ordering,
    until: Option<std::time::Instant>,
) -> Result<(Ordering, Toolpath), OrderError> {
    let by_distance = lower.toolpath(&ordering)?;
    let refined = match time::refine_for_time(
        lower.geometries,
        lower.fields,
        &ordering,
        &lower.inputs.profile,
        lower.inputs.settings.seed,
        until,
        lower.ctx,
    ) {
        Ok(refined) => refined,
        Err(Cancelled) => return Ok((ordering, by_distance)),
    };
    let by_time = lower.toolpath(&refined)?;
    // the refinement on a tie: it is what the time objective chose
    Ok(faster((refined, by_time), (ordering, by_distance)))
}

/// Every geometry must be allocated to exactly one field.
pub fn check_allocation(n: usize, fields: &[ScanField]) -> Result<(), OrderError> {
    let mut seen = vec![false; n];
    for f in fields {
        for &g in &f.geometries {
            if let Some(s) = seen.get_mut(g) {
                *s = true;
            }
        }
    }
    let missing: Vec<usize> = seen
        .iter()
        .enumerate()
        .filter(|(_, s)| !**s)
        .map(|(i, _)| i)
        .collect();
    match missing.first() {
        Some(&first) => Err(OrderError::Unallocated(missing.len(), first)),
        None => Ok(()),
    }
}
