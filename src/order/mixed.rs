//! Mixed motion (issue 26 item 3): an on-the-fly job with some fields marked step-and-scan,
//! the stage at rest while their strokes are marked ([`Plan::step_fields`]).
//!
//! The tracked route ([`crate::motion::lower_on_the_fly`]) stops the stage for such a field:
//! its samples are clipped to speed zero, and the jumps into and out of it are made in the
//! scanner's frame, tied to the tool at their ends only. Which fields: both lowerings of the
//! *same* order are at hand (the on-the-fly job, and the step-and-scan job of its order), so
//! each stretch of consecutive strokes in one field has a time in each motion (from the end of
//! the stretch before to the end of its own last mark). The fields whose stretches the
//! step-and-scan job marks faster are the candidate; the one that gains most alone is the
//! second. Each is lowered as a whole job and kept only when its job time is shorter:
//! the stretch times are an estimate (a stop changes the route before and after it), job time
//! decides. Nothing is lowered when no stretch gains, so a job whose stage keeps up costs one
//! step-and-scan lowering more.
//!
//! [`Plan::step_fields`]: crate::document::Plan::step_fields

use super::{Candidates, Made, Nodes, OrderError};
use crate::document::{ControllerKind, Motion, PlanInputs, StageRouteKind};
use crate::geom::Pt;
use crate::job::JobCtx;
use crate::motion::{still_reach_mm, MotionError, OtfError, Toolpath, TIME_EPS_S};

/// Jobs of more strokes than this are not tried mixed (the step-and-scan lowering of the
/// on-the-fly order, and up to two more on-the-fly lowerings; the large fills this skips run
/// one motion near their marking floor).
pub const MIXED_STROKES_MAX: usize = super::FLY_SKIP_STROKES_MIN;

/// The faster mixed job of `flying` (an on-the-fly plan of the solve), when there is one: the
/// fields marked step-and-scan and the toolpath. None where no stretch of a field gains, where
/// the machine's controller times its own programs (LinuxCNC), under seed 001's stage routes,
/// on large jobs, or where no mixed job is faster than `flying`.
pub(super) fn faster_mixed(
    nodes: &Nodes,
    inputs: &PlanInputs,
    flying: &Made,
    ctx: &JobCtx,
) -> Result<Option<(Vec<usize>, Toolpath)>, OrderError> {
    let profile = &inputs.profile;
    let tried = profile.controller.kind == ControllerKind::Ideal
        && inputs.settings.stage_route == StageRouteKind::Taut
        && flying.toolpath.strokes.len() <= MIXED_STROKES_MAX
        && !ctx.is_cancelled();
    let Some(reach_mm) = still_reach_mm(profile).filter(|_| tried) else {
        return Ok(None);
    };
    ctx.progress(
        "motion",
        0,
        1,
        "Mixed: trying fields marked step-and-scan in the on-the-fly plan",
    );
    let stepping = Candidates::new(nodes, inputs, Motion::Step, ctx);
    let Ok(step) = stepping.toolpath(&flying.ordering) else {
        // an order step-and-scan cannot mark (a geometry larger than its field)
        return Ok(None);
    };
    let gains = field_gains(&flying.toolpath, &step, reach_mm, profile.stroke_mm);
    let mut all: Vec<usize> = gains.iter().map(|g| g.0).collect();
    all.sort_unstable();
    let Some(&(most, _)) = gains.first() else {
        return Ok(None);
    };
    let flying_lower = Candidates::new(nodes, inputs, Motion::OnTheFly, ctx);
    let lowered = |fields: Vec<usize>| -> Result<Option<(Vec<usize>, Toolpath)>, OrderError> {
        match flying_lower.toolpath_with(&flying.ordering, &fields) {
            Ok(t) => Ok(Some((fields, t))),
            // the stage could not be stopped there: no such job
            Err(OrderError::Lower(MotionError::OnTheFly(OtfError::MixedNotTracked { .. }))) => {
                Ok(None)
            }
            Err(e) => Err(e),
        }
    };
    let (with_all, with_most) = if all.len() > 1 {
        rayon::join(|| lowered(all), || lowered(vec![most]))
    } else {
        (lowered(all), Ok(None))
    };
    let best = [with_all?, with_most?]
        .into_iter()
        .flatten()
        .filter(|(_, t)| t.duration_s() < flying.toolpath.duration_s())
        .min_by(|a, b| a.1.duration_s().total_cmp(&b.1.duration_s()));
    Ok(best)
}

/// The fields whose every stretch (consecutive strokes in that field) `step` marks faster
/// than `flying` (two lowerings of one order), with the time gained, most first; only fields
/// whose stretches each fit in the still reach (`reach_mm` either side of one stage position
/// inside `stroke_mm`).
fn field_gains(
    flying: &Toolpath,
    step: &Toolpath,
    reach_mm: f64,
    stroke_mm: [f64; 2],
) -> Vec<(usize, f64)> {
    let n = flying.strokes.len();
    if step.strokes.len() != n {
        return Vec::new();
    }
    let (fly_end, step_end) = (flying.mark_ends_s(), step.mark_ends_s());
    let mut by_field: std::collections::BTreeMap<usize, (f64, bool)> = Default::default();
    let mut first = 0;
    while first < n {
        let field = flying.strokes[first].field;
        let last = (first..n)
            .take_while(|&k| flying.strokes[k].field == field)
            .last()
            .unwrap_or(first);
        let before = |ends: &[f64]| first.checked_sub(1).map_or(0.0, |k| ends[k]);
        let fly_s = fly_end[last] - before(&fly_end);
        let step_s = step_end[last] - before(&step_end);
        let fits = fits_still(
            (first..=last).flat_map(|k| flying.stroke_points(k)),
            reach_mm,
            stroke_mm,
        );
        let entry = by_field.entry(field).or_insert((0.0, true));
        entry.0 += fly_s - step_s;
        entry.1 &= fits && fly_s - step_s > TIME_EPS_S;
        first = last + 1;
    }
    let mut gains: Vec<(usize, f64)> = by_field
        .into_iter()
        .filter(|(_, (_, ok))| *ok)
        .map(|(field, (gain_s, _))| (field, gain_s))
        .collect();
    gains.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    gains
}

/// Whether one stage position inside `[0, stroke_mm]` keeps every point within `reach_mm` on
/// each axis.
fn fits_still<'a>(
    points: impl Iterator<Item = &'a Pt>,
    reach_mm: f64,
    stroke_mm: [f64; 2],
) -> bool {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for (axis, c) in [p.x, p.y].into_iter().enumerate() {
            lo[axis] = lo[axis].min(c);
            hi[axis] = hi[axis].max(c);
        }
    }
    (0..2).all(|axis| (hi[axis] - reach_mm).max(0.0) <= (lo[axis] + reach_mm).min(stroke_mm[axis]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stretch_fits_when_one_stage_position_reaches_all_of_it() {
        let pts = [Pt::new(10.0, 10.0), Pt::new(19.0, 12.0)];
        assert!(fits_still(pts.iter(), 5.0, [300.0; 2]));
        assert!(!fits_still(pts.iter(), 4.4, [300.0; 2]));
        // near the stroke's edge the stage cannot stand beyond it
        let edge = [Pt::new(-6.0, 10.0), Pt::new(-5.5, 10.0)];
        assert!(!fits_still(edge.iter(), 5.0, [300.0; 2]));
        assert!(fits_still(edge.iter(), 6.5, [300.0; 2]));
    }
}
