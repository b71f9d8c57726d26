//! Ordering: which field after which, which geometry after which, where each one starts.

mod baseline;
pub mod hga;
pub mod hha;
pub mod metrics;
pub mod tsp;
pub mod vertex;

pub use baseline::baseline_order;

use crate::document::{Algo, Geometry, MachineProfile, Plan, ScanField, SolverSettings, Step};
use crate::job::{Cancelled, JobCtx};
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
}

/// The ordered strokes of a run, before metrics.
#[derive(Debug, Clone, Default)]
pub struct Ordering {
    /// Field ids in visiting order.
    pub field_order: Vec<usize>,
    /// Strokes in marking order.
    pub steps: Vec<Step>,
}

/// Orders the allocated geometries with the algorithm in `settings` and returns the plan with
/// its metrics (stage times other than `order` are left for the caller to fill in).
pub fn order_plan(
    geometries: &[Geometry],
    fields: &[ScanField],
    profile: &MachineProfile,
    settings: &SolverSettings,
    ctx: &JobCtx,
) -> Result<Plan, OrderError> {
    check_allocation(geometries.len(), fields)?;
    let t0 = std::time::Instant::now();
    let mut detail = Vec::new();
    let mut history = Vec::new();
    let ordering = match settings.algo {
        Algo::Baseline => baseline_order(geometries, fields, ctx)?,
        Algo::Hha => hha::hha_order(geometries, fields, profile, settings, ctx, &mut detail)?,
        Algo::Hga => {
            let t = std::time::Instant::now();
            let seed_plan = if settings.ga.seed_with_hha {
                Some(hha::hha_order(
                    geometries,
                    fields,
                    profile,
                    settings,
                    ctx,
                    &mut detail,
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
            history = r.history;
            r.ordering
        }
    };
    let order_s = t0.elapsed().as_secs_f64();
    let by_id = |id: usize| fields.iter().find(|f| f.id == id).cloned();
    let plan_fields: Vec<ScanField> = ordering
        .field_order
        .iter()
        .filter_map(|&id| by_id(id))
        .collect();
    let mut m = metrics::compute(geometries, &plan_fields, &ordering.steps, profile);
    m.solve_s.order = order_s;
    m.solve_s.order_detail = detail;
    Ok(Plan {
        name: format!("{:?}", settings.algo).to_lowercase(),
        algo: settings.algo,
        fields: plan_fields,
        order: ordering.steps,
        metrics: m,
        history,
    })
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
