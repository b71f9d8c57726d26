//! Plan metrics. Every report, benchmark and GUI table uses these definitions (docs/DESIGN.md).
//!
//! * `idle_mm`: Σ over consecutive strokes of the straight distance from where one ends to where
//!   the next starts (laser off). The approach from the start position and a final return are
//!   excluded.
//! * `marked_mm`: total marked length.
//! * `base_mm`: length of the polyline through the field centres in visiting order (on a
//!   cylinder, of the chords between them on its surface).
//! * `covered_area_mm2`: area covered by exactly one field (seed 000 §5.1);
//!   `overlap_pct = 100 · (1 − covered / (fields · field area))`.
//! * `direction_changes`: see [`direction_changes`].
//! * `job_time_s`: the lowered toolpath's duration, with `job_time_breakdown_s` by what the
//!   machine does ([`crate::motion`]).

use super::cost::TravelCost;
use crate::document::{Cylinder, Geometry, MachineProfile, Metrics, ScanField, Step};
use crate::geom::Pt;
use crate::motion::Toolpath;

/// Sampling period of the motion figures, s: the trajectory's default period, so that the
/// figures match what `check_trajectory.py` reports for a default `--trajectory`.
pub const MOTION_SAMPLE_PERIOD_S: f64 = 1e-3;

/// Computes all metrics of an ordering; `fields` in visiting order, `toolpath` its lowering;
/// on a `cylinder`, `base_mm` is measured on its surface (the strips' centres 3-D apart).
pub fn compute(
    geometries: &[Geometry],
    fields: &[ScanField],
    steps: &[Step],
    profile: &MachineProfile,
    cylinder: Option<Cylinder>,
    toolpath: &Toolpath,
) -> Metrics {
    let idle_mm = idle_mm(geometries, steps);
    // `+ 0.0`: dots alone sum to −0.0
    let marked_mm = steps
        .iter()
        .map(|s| geometries[s.geometry].length_mm())
        .sum::<f64>()
        + 0.0;
    let centers: Vec<Pt> = fields.iter().map(|f| f.center).collect();
    // `+ 0.0` turns the empty sum (−0.0) into 0.0
    let metric = TravelCost::distance(cylinder);
    let base_mm = centers
        .windows(2)
        .map(|w| metric.between(w[0], w[1]))
        .sum::<f64>()
        + 0.0;
    // the three costly figures side by side (on a 3,043-field job: 150 → about 80 ms, which is
    // also what a cancelled solve waits for before it has its plan)
    let (((covered_area_mm2, overlap_pct), motion), direction_changes) = rayon::join(
        || {
            rayon::join(
                || coverage(fields),
                || toolpath.motion_figures(MOTION_SAMPLE_PERIOD_S),
            )
        },
        || direction_changes(geometries, fields, steps, profile.field_mm),
    );
    Metrics {
        idle_mm,
        marked_mm,
        base_mm,
        fields: fields.len(),
        fields_lower_bound: None,
        covered_area_mm2,
        overlap_pct,
        direction_changes,
        job_time_s: Some(toolpath.duration_s()),
        job_time_breakdown_s: Some(toolpath.breakdown()),
        motion: Some(motion),
        motion_regions: Vec::new(),
        solve_s: Default::default(),
        motion_note: None,
    }
}

/// Start and end point of a step.
pub fn step_ends(geometries: &[Geometry], s: &Step) -> (Pt, Pt) {
    let g = &geometries[s.geometry];
    g.ends(s.choice(g))
}

/// Laser-off travel between consecutive strokes, mm.
pub fn idle_mm(geometries: &[Geometry], steps: &[Step]) -> f64 {
    steps
        .windows(2)
        .map(|w| {
            step_ends(geometries, &w[0])
                .1
                .dist(step_ends(geometries, &w[1]).0)
        })
        .sum::<f64>()
        + 0.0
}

/// Area covered by exactly one field and the overlap percentage (seed 000 §5.1), with each
/// field's own size.
///
/// Exact for axis-aligned fields: a sweep over the x-slabs between field edges, and in each
/// slab over the y-intervals, counting how many fields cover each piece.
pub fn coverage(fields: &[ScanField]) -> (f64, f64) {
    if fields.is_empty() {
        return (0.0, 0.0);
    }
    let boxes: Vec<_> = fields.iter().map(ScanField::bbox).collect();
    let mut xs: Vec<f64> = boxes.iter().flat_map(|b| [b.min_x, b.max_x]).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let mut once = 0.0;
    let mut events: Vec<(f64, i32)> = Vec::new();
    for w in xs.windows(2) {
        let (x0, x1) = (w[0], w[1]);
        if x1 <= x0 {
            continue;
        }
        let xm = (x0 + x1) / 2.0;
        events.clear();
        for b in boxes.iter().filter(|b| b.min_x <= xm && xm <= b.max_x) {
            events.push((b.min_y, 1));
            events.push((b.max_y, -1));
        }
        events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut depth = 0;
        let mut last_y = f64::NEG_INFINITY;
        let mut len_once = 0.0;
        for &(y, d) in &events {
            if depth == 1 {
                len_once += y - last_y;
            }
            depth += d;
            last_y = y;
        }
        once += len_once * (x1 - x0);
    }
    // each field's own size: an on-the-fly region around oversize work is larger than a field
    let full: f64 = fields.iter().map(|f| f.size[0] * f.size[1]).sum();
    let overlap_pct = if full > 0.0 {
        100.0 * (1.0 - once / full)
    } else {
        0.0
    };
    (once, overlap_pct)
}

/// Share of the field width the path may fall back before it counts as a direction change.
pub const DIRECTION_HYSTERESIS: f64 = 0.1;

/// Number of direction changes of the TCP path along the base path (seed 000 §2.3).
///
/// The sweep is followed through the geometries' centroids in marking order. Each move from one
/// centroid to the next is projected onto the *local base direction* of the field being left:
/// the unit vector from that field's centre to the next field's centre (for the last field, from
/// the previous field's centre; with a single field, from the first to the last centroid). The
/// projections add up to the progress `s` along the base path. A direction change is counted
/// when `s` falls back from its running extreme by more than [`DIRECTION_HYSTERESIS`] × the
/// field width (7 mm on a 70 mm field) — local back-and-forth the scanner absorbs inside its
/// field is not a change; turning back across the work is. A plan that sweeps steadily from field
/// to field scores 0; a nearest-neighbour order that wanders back and forth scores high.
pub fn direction_changes(
    geometries: &[Geometry],
    fields: &[ScanField],
    steps: &[Step],
    field_mm: [f64; 2],
) -> usize {
    if steps.len() < 3 {
        return 0;
    }
    let centroids: Vec<Pt> = steps
        .iter()
        .map(|s| geometries[s.geometry].centroid())
        .collect();
    let fallback = {
        let d = centroids[centroids.len() - 1].minus(centroids[0]);
        if d.norm() > 0.0 {
            d.scale(1.0 / d.norm())
        } else {
            Pt::new(1.0, 0.0)
        }
    };
    let dir_of = |field_id: usize| -> Pt {
        let k = fields.iter().position(|f| f.id == field_id);
        let (a, b) = match k {
            Some(k) if k + 1 < fields.len() => (fields[k].center, fields[k + 1].center),
            Some(k) if k > 0 => (fields[k - 1].center, fields[k].center),
            _ => return fallback,
        };
        let d = b.minus(a);
        if d.norm() > 0.0 {
            d.scale(1.0 / d.norm())
        } else {
            fallback
        }
    };
    let band = DIRECTION_HYSTERESIS * field_mm[0];
    let mut progress = 0.0f64;
    // heading: +1 forwards, −1 backwards, 0 not yet known; `extreme` is the running max (heading
    // forwards) or min (backwards) since the last change
    let mut heading = 0.0f64;
    let (mut hi, mut lo) = (0.0f64, 0.0f64);
    let mut changes = 0;
    for (w, s) in centroids.windows(2).zip(steps) {
        progress += w[1].minus(w[0]).dot(dir_of(s.field));
        if heading >= 0.0 {
            hi = hi.max(progress);
        }
        if heading <= 0.0 {
            lo = lo.min(progress);
        }
        if heading > 0.0 && progress < hi - band {
            changes += 1;
            heading = -1.0;
            lo = progress;
        } else if heading < 0.0 && progress > lo + band {
            changes += 1;
            heading = 1.0;
            hi = progress;
        } else if heading == 0.0 {
            if progress > lo + band {
                heading = 1.0;
                hi = progress;
            } else if progress < hi - band {
                heading = -1.0;
                lo = progress;
            }
        }
    }
    changes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::tests_support::rect;

    fn field(id: usize, x: f64, y: f64) -> ScanField {
        ScanField {
            id,
            center: Pt::new(x, y),
            size: [70.0, 70.0],
            locked: false,
            geometries: vec![],
            pose: Default::default(),
        }
    }

    #[test]
    fn coverage_of_two_overlapping_fields() {
        let f = [field(0, 35.0, 35.0), field(1, 70.0, 35.0)];
        let (once, pct) = coverage(&f);
        // overlap strip 35 × 70 is covered twice
        assert!((once - (2.0 * 4900.0 - 2.0 * 35.0 * 70.0)).abs() < 1e-9);
        assert!((pct - 50.0).abs() < 1e-9);
        let (once, pct) = coverage(&f[..1]);
        assert!((once - 4900.0).abs() < 1e-9 && pct.abs() < 1e-12);
    }

    #[test]
    fn idle_and_direction_changes() {
        let gs: Vec<Geometry> = (0..4)
            .map(|i| rect(i as f64 * 10.0, 0.0, 2.0, 2.0))
            .collect();
        let f = [field(0, 35.0, 35.0)];
        let steps = |order: &[usize]| -> Vec<Step> {
            order
                .iter()
                .map(|&g| Step {
                    geometry: g,
                    field: 0,
                    start_vertex: 0,
                    reversed: false,
                })
                .collect()
        };
        let sweep = steps(&[0, 1, 2, 3]);
        assert!((idle_mm(&gs, &sweep) - 30.0).abs() < 1e-12);
        assert_eq!(direction_changes(&gs, &f, &sweep, [70.0, 70.0]), 0);
        let zig = steps(&[0, 2, 1, 3]);
        assert_eq!(direction_changes(&gs, &f, &zig, [70.0, 70.0]), 2);
        // falling back less than 7 mm is not a change
        let gs2: Vec<Geometry> = [0.0, 10.0, 5.0, 20.0]
            .iter()
            .map(|&x| rect(x, 0.0, 2.0, 2.0))
            .collect();
        assert_eq!(
            direction_changes(&gs2, &f, &steps(&[0, 1, 2, 3]), [70.0, 70.0]),
            0
        );
    }
}
