//! Seed 001's stage routes for on-the-fly marking (`lsa`, `cetsp-ga`), planned on the tool's
//! nominal time law of a plan ([`super::cetsp`]). The lowering then follows the route within
//! a band ([`super::otf`]); the taut string needs no such step.

use super::cetsp::{cetsp_ga, lsa_route, validate, GaParams, LsaParams, TimedRoute};
use super::otf::{nominal_tool_knots, OtfError};
use crate::document::{Geometry, MachineProfile, Plan, RouteGaSettings, StageRouteKind};
use crate::job::JobCtx;

/// The stage route of `plan` for `kind` (none for the taut string, which the lowering makes
/// itself). `seed` seeds the GA.
pub fn plan_stage_route(
    geometries: &[Geometry],
    plan: &Plan,
    profile: &MachineProfile,
    kind: StageRouteKind,
    settings: &RouteGaSettings,
    seed: u64,
    ctx: &JobCtx,
) -> Result<Option<TimedRoute>, OtfError> {
    if kind == StageRouteKind::Taut {
        return Ok(None);
    }
    let radius_mm = settings
        .padding_radius_mm
        .unwrap_or(profile.field_mm[0].min(profile.field_mm[1]) / 2.0);
    let lsa = LsaParams::paper(radius_mm);
    let ga = GaParams {
        population: settings.population,
        generations: settings.generations,
        crossover_rate: settings.crossover_rate,
        mutation_rate: settings.mutation_rate,
        seed,
    };
    validate(&lsa, &ga, radius_mm)?;
    let tool = nominal_tool_knots(geometries, plan, profile)?;
    let route = lsa_route(&tool, &lsa);
    Ok(Some(match kind {
        StageRouteKind::CetspGa => cetsp_ga(&tool, &route, radius_mm, &ga, ctx)?.route,
        _ => route,
    }))
}
