//! The plan's objective, evaluated without lowering: what HGA's fitness and HHA's final choice
//! share with the table.
//!
//! Under `--cost distance` the objective is the idle travel (mm) of the strokes in marking
//! order. Under `--cost time` it is the job time (s). In step-and-scan that time is a sum over
//! the strokes that [`StepTime::job_time_s`] computes with the same rules as
//! `motion::lower` (stage trapezoids and settling on a field change, the scanner's jump hidden
//! in the move when it and its delay fit, else after the settling; jump speed and delay inside
//! a field; laser delays and the pen's mark speed per stroke, passes repeated inside their
//! field). It is exact: it equals the lowered toolpath's `duration_s` up to rounding (the
//! lowering adds the same terms one by one; checked to 1e-9 relative by the tests below and by
//! `tests/hga.rs` on the shared instances). It costs O(strokes) arithmetic with no allocation
//! per stroke, against a lowering's segment list.
//!
//! On the fly the stage never stops, and the job time needs the stage route (seconds to lower on
//! large jobs); the step-and-scan figure is then an estimate used only to rank chromosomes, and
//! the plan's own choice between candidates is made on their lowered toolpaths.

use crate::document::{pen_of, Geometry, Layer, MachineProfile, MarkTiming, Pose, ScanField, Step};
use crate::geom::{is_dot, Pt};
use crate::motion::controller::{LinuxcncClock, TASK_RESUME_S};
use crate::motion::StageDynamics;
use std::collections::HashMap;

/// Job time of a step-and-scan order, without lowering (see the module text).
pub struct StepTime<'a> {
    geometries: &'a [Geometry],
    layers: &'a [Layer],
    /// Each field's centre and pose.
    centre: HashMap<usize, (Pt, Pose)>,
    stage: StageDynamics,
    jump_speed_mm_s: f64,
    jump_delay_s: f64,
    /// Per geometry: laser-on delay + mark + laser-off delay, s (on a controller clock: the
    /// mark alone, a dot as if it followed a dwell; [`StepTime::sum_clocked`] adds the delays
    /// as dwells, and what a dot first after a move adds).
    mark_s: Vec<f64>,
    /// The controller's clock (LinuxCNC), which times moves and dwells as `motion::lower` does
    /// on it.
    clock: Option<LinuxcncClock>,
    laser: crate::document::LaserTiming,
}

impl<'a> StepTime<'a> {
    /// The model for these geometries, fields (by id), layers (pens, passes) and machine.
    pub fn new(
        geometries: &'a [Geometry],
        fields: &[ScanField],
        layers: &'a [Layer],
        profile: &MachineProfile,
    ) -> Self {
        let laser = &profile.laser;
        let clock = LinuxcncClock::of(profile);
        let mark_s = geometries
            .iter()
            .map(|g| {
                let timing = MarkTiming::of(pen_of(layers, g), profile);
                match &clock {
                    Some(c) if is_dot(&g.points) => c.dot_s(timing.dot_dwell_s, false),
                    // every start vertex and direction marks the same edges
                    Some(c) => c.polyline_s(&g.marking_path(0, false), timing.speed_mm_s),
                    None => {
                        laser.on_delay_s
                            + timing.mark_s(&g.points, g.length_mm())
                            + laser.off_delay_s
                    }
                }
            })
            .collect();
        Self {
            geometries,
            layers,
            centre: fields.iter().map(|f| (f.id, (f.center, f.pose))).collect(),
            stage: StageDynamics::of(profile),
            jump_speed_mm_s: profile.scanner.jump_speed_mm_s,
            jump_delay_s: laser.jump_delay_s,
            mark_s,
            clock,
            laser: laser.clone(),
        }
    }

    /// The job time of `steps` (one entry per stroke, passes not yet repeated), s; infinite
    /// when a step names a field or geometry that does not exist.
    pub fn job_time_s(&self, steps: &[Step]) -> f64 {
        if self.layers.iter().any(|l| l.pen.passes > 1) {
            let expanded = super::expand_passes(steps, self.geometries, self.layers);
            self.sum(&expanded)
        } else {
            self.sum(steps)
        }
    }

    /// A step's field centre and pose and its stroke's start and end; none when the step names
    /// a field or geometry that does not exist.
    fn place(&self, s: &Step) -> Option<(Pt, Pose, Pt, Pt)> {
        let g = self.geometries.get(s.geometry)?;
        let (centre, pose) = *self.centre.get(&s.field)?;
        let (start, end) = g.ends(s.choice(g));
        Some((centre, pose, start, end))
    }

    fn sum(&self, steps: &[Step]) -> f64 {
        if let Some(clock) = &self.clock {
            return self.sum_clocked(steps, clock);
        }
        let mut t = 0.0;
        let (mut stage_at, mut scan_at) = (Pt::default(), Pt::default());
        let mut pose_at = Pose::default();
        for (k, s) in steps.iter().enumerate() {
            let Some((centre, pose, start, end)) = self.place(s) else {
                return f64::INFINITY;
            };
            let offset = start.minus(centre);
            if k == 0 {
                (stage_at, pose_at) = (centre, pose);
            } else if centre == stage_at && pose == pose_at {
                t += offset.dist(scan_at) / self.jump_speed_mm_s + self.jump_delay_s;
            } else {
                let mv = self.stage.plan_pose_move(stage_at, &pose_at, centre, &pose);
                let jump_s = offset.dist(scan_at) / self.jump_speed_mm_s;
                let hidden = jump_s <= mv.move_s && jump_s + self.jump_delay_s <= mv.total_s();
                t += mv.total_s();
                if !hidden {
                    t += jump_s + self.jump_delay_s;
                }
                (stage_at, pose_at) = (centre, pose);
            }
            t += self.mark_s[s.geometry];
            scan_at = end.minus(stage_at);
        }
        t
    }
}

impl StepTime<'_> {
    /// [`StepTime::sum`] on a controller clock, by `motion::lower`'s rules there: a field
    /// change is one coordinated move of stage and scanner (never shorter than the stage's own
    /// trapezoids), a jump is an exact-stop move, pauses next to each other (settling, jump
    /// delay, laser delays) are one dwell, and a dwell or a dot costs more as the first command
    /// after a move.
    fn sum_clocked(&self, steps: &[Step], clock: &LinuxcncClock) -> f64 {
        let mut t = 0.0;
        let (mut stage_at, mut scan_at) = (Pt::default(), Pt::default());
        let mut pose_at = Pose::default();
        // the pauses since the last move or dot (one dwell), and whether a move came last
        // (the program moves to the start first)
        let mut pausing = 0.0;
        let mut moved = true;
        let hold = |pausing: &mut f64, d: f64| {
            if d > 0.0 {
                *pausing += d;
            }
        };
        let end_pauses = |t: &mut f64, pausing: &mut f64, moved: &mut bool| {
            if *pausing > 0.0 {
                *t += clock.dwell_s(*pausing, *moved);
                *pausing = 0.0;
                *moved = false;
            }
        };
        // the laser as the last move or dot left it: a move that switches it after a dwell or
        // a dot waits for its output (M62/M63)
        let mut lit = false;
        let before_move =
            |t: &mut f64, pausing: &mut f64, moved: &mut bool, lit_at: &mut bool, lit: bool| {
                end_pauses(t, pausing, moved);
                if !*moved && lit != *lit_at {
                    *t += clock.output_s();
                }
                *moved = true;
                *lit_at = lit;
            };
        for (k, s) in steps.iter().enumerate() {
            let Some((centre, pose, start, end)) = self.place(s) else {
                return f64::INFINITY;
            };
            let offset = start.minus(centre);
            if k == 0 {
                (stage_at, pose_at) = (centre, pose);
            } else if centre == stage_at && pose == pose_at {
                let j = offset.minus(scan_at);
                let jump_s = clock.move_s([0.0, 0.0, j.x, j.y], None);
                if jump_s > 0.0 {
                    before_move(&mut t, &mut pausing, &mut moved, &mut lit, false);
                    t += jump_s;
                }
                hold(&mut pausing, self.jump_delay_s);
            } else {
                let mv = self.stage.plan_pose_move(stage_at, &pose_at, centre, &pose);
                let (d, j) = (centre.minus(stage_at), offset.minus(scan_at));
                let turn = pose_at.turn_to(&pose);
                before_move(&mut t, &mut pausing, &mut moved, &mut lit, false);
                t += clock
                    .move_axes_s([d.x, d.y, j.x, j.y], turn, None)
                    .max(mv.move_s);
                hold(&mut pausing, mv.settle_s);
                (stage_at, pose_at) = (centre, pose);
            }
            hold(&mut pausing, self.laser.on_delay_s);
            let dot = self
                .geometries
                .get(s.geometry)
                .is_some_and(|g| is_dot(&g.points));
            if dot {
                end_pauses(&mut t, &mut pausing, &mut moved);
                // first after a move: what task adds after one (the dot's own part is in mark_s)
                if moved {
                    t += TASK_RESUME_S;
                }
                (moved, lit) = (false, false);
            } else {
                before_move(&mut t, &mut pausing, &mut moved, &mut lit, true);
            }
            t += self.mark_s[s.geometry];
            hold(&mut pausing, self.laser.off_delay_s);
            scan_at = end.minus(stage_at);
        }
        end_pauses(&mut t, &mut pausing, &mut moved);
        t
    }
}

/// A lower bound on the step-and-scan job time of any order of these strokes on these fields
/// (s): no ordering, HHA's, HGA's or an exhaustive one, can beat it. It is the sum of
///
/// * every stroke's marking and laser delays, once per pass (fixed by the strokes);
/// * the stage's moves: the stage visits every distinct field centre, so its moves form a path
///   through them, at least a minimum spanning tree of the centres under the stage's move time
///   (settling included; Prim, O(fields²));
/// * the scanner's jumps inside fields: every stroke of a field but the one marked first is
///   reached by a jump from another stroke of that field, at least the jump delay plus the
///   distance between the two strokes' bounding boxes at jump speed; the field's largest such
///   term is left out (the first stroke's jump may hide in the stage move). In a field of more
///   than [`EXACT_GAPS_MAX`] strokes the distance is taken as 0 (the jump delay alone: still a
///   bound, found in O(strokes) instead of O(strokes²); dense fills, where such fields occur,
///   have overlapping boxes and gaps near 0 anyway).
///
/// The gap between a plan's job time and this bound is the most any better order could gain.
pub fn step_job_time_lower_bound_s(
    geometries: &[Geometry],
    fields: &[ScanField],
    layers: &[Layer],
    profile: &MachineProfile,
) -> f64 {
    let model = StepTime::new(geometries, fields, layers, profile);
    let marking: f64 = geometries
        .iter()
        .zip(&model.mark_s)
        .map(|(g, t)| t * f64::from(crate::document::passes_of(layers, g)))
        .sum();
    let mut centres: Vec<(Pt, Pose)> = Vec::new();
    for f in fields.iter().filter(|f| !f.geometries.is_empty()) {
        if !centres.contains(&(f.center, f.pose)) {
            centres.push((f.center, f.pose));
        }
    }
    let stage = spanning_tree_s(&centres, &model.stage);
    let jumps: f64 = fields
        .iter()
        .map(|f| {
            if f.geometries.len() > EXACT_GAPS_MAX {
                return f.geometries.len().saturating_sub(1) as f64 * model.jump_delay_s;
            }
            let boxes: Vec<crate::geom::BBox> = f
                .geometries
                .iter()
                .filter_map(|&g| geometries.get(g).map(Geometry::bbox))
                .collect();
            let nearest: Vec<f64> = (0..boxes.len())
                .map(|i| {
                    let gap = (0..boxes.len())
                        .filter(|&j| j != i)
                        .map(|j| box_gap_mm(&boxes[i], &boxes[j]))
                        .fold(f64::INFINITY, f64::min);
                    gap / model.jump_speed_mm_s + model.jump_delay_s
                })
                .filter(|t| t.is_finite())
                .collect();
            let largest = nearest.iter().copied().fold(0.0, f64::max);
            nearest.iter().sum::<f64>() - largest
        })
        .sum();
    marking + stage + jumps
}

/// A lower bound on the job time of these strokes in any motion and any order (s): every
/// stroke's marking and laser delays, once per pass, and a jump delay before every stroke but
/// the first. Neither motion can beat it: on the fly the tool keeps the scanner's time law or
/// a slower one (its jumps, delays and marks are only ever stretched), and step-and-scan adds
/// stage moves and jump travel to it. On a controller clock the laser and jump delays are left
/// out (still a bound).
pub fn marking_floor_s(geometries: &[Geometry], layers: &[Layer], profile: &MachineProfile) -> f64 {
    let model = StepTime::new(geometries, &[], layers, profile);
    let mut strokes = 0.0;
    let mut marking = 0.0;
    for (g, t) in geometries.iter().zip(&model.mark_s) {
        let passes = f64::from(crate::document::passes_of(layers, g));
        strokes += passes;
        marking += t * passes;
    }
    if model.clock.is_some() {
        return marking;
    }
    marking + (strokes - 1.0).max(0.0) * model.jump_delay_s
}

/// Largest field whose strokes' nearest gaps [`step_job_time_lower_bound_s`] computes exactly
/// (pairwise: 4 million box gaps at this size, about 10 ms).
pub const EXACT_GAPS_MAX: usize = 2000;

/// The least distance between two boxes (0 when they overlap), mm.
fn box_gap_mm(a: &crate::geom::BBox, b: &crate::geom::BBox) -> f64 {
    let dx = (b.min_x - a.max_x).max(a.min_x - b.max_x).max(0.0);
    let dy = (b.min_y - a.max_y).max(a.min_y - b.max_y).max(0.0);
    dx.hypot(dy)
}

/// Weight of a minimum spanning tree of `points` (placements) under the stage's move time over
/// every axis (Prim), s.
fn spanning_tree_s(points: &[(Pt, Pose)], stage: &StageDynamics) -> f64 {
    let n = points.len();
    if n < 2 {
        return 0.0;
    }
    let mut best = vec![f64::INFINITY; n];
    let mut done = vec![false; n];
    let mut total = 0.0;
    let mut next = 0;
    for _ in 0..n {
        done[next] = true;
        let mut pick: Option<usize> = None;
        for j in 0..n {
            if done[j] {
                continue;
            }
            let ((a, pa), (b, pb)) = (&points[next], &points[j]);
            best[j] = best[j].min(stage.pose_move_time_s(*a, pa, *b, pb));
            if pick.is_none_or(|k| best[j] < best[k]) {
                pick = Some(j);
            }
        }
        match pick {
            Some(k) => {
                total += best[k];
                next = k;
            }
            None => break,
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::{Plan, PlanInputs, SolverSettings};
    use crate::fields::tests_support::rect;
    use crate::geom::Pt;
    use crate::motion::lower;

    #[test]
    fn the_step_time_equals_the_lowered_job_time() {
        step_time_equals_lowered(&MachineProfile::default());
    }

    #[test]
    fn the_step_time_on_a_controller_clock_equals_the_lowered_job_time() {
        // LinuxCNC's exact-stop moves, with delays and settling as dwells (merged where
        // adjacent), as the lowering times them
        step_time_equals_lowered(&crate::motion::linuxcnc_with_delays());
        step_time_equals_lowered(&MachineProfile::builtin("linuxcnc").unwrap());
    }

    fn step_time_equals_lowered(profile: &MachineProfile) {
        let profile = profile.clone();
        let centre = |j: usize| Pt::new(50.0 + 45.0 * j as f64, 40.0 + 37.0 * (j % 3) as f64);
        let gs: Vec<Geometry> = (0..12)
            .map(|k| {
                let c = centre(k / 2);
                if k % 2 == 0 {
                    let side = 4.0 + k as f64;
                    rect(c.x - 20.0, c.y - 10.0, side, side)
                } else {
                    // an open stroke: reversed on odd choices
                    Geometry::new(
                        vec![
                            Pt::new(c.x + 5.0, c.y + 8.0),
                            Pt::new(c.x + 9.0, c.y - 12.0),
                        ],
                        false,
                        crate::document::Source::default(),
                    )
                }
            })
            .collect();
        let fields: Vec<ScanField> = (0..6)
            .map(|j| ScanField {
                id: j,
                center: centre(j),
                size: profile.field_mm,
                geometries: vec![2 * j, 2 * j + 1],
                locked: false,
                pose: Default::default(),
            })
            .collect();
        let steps: Vec<Step> = (0..12)
            .map(|g| Step::from_choice(g, g / 2, &gs[g], (g / 2) % gs[g].start_choices()))
            .collect();
        let inputs = PlanInputs {
            geometry_rev: 0,
            profile: profile.clone(),
            layers: Vec::new(),
            settings: SolverSettings::default(),
        };
        let plan = Plan::new(
            &inputs,
            crate::document::Motion::Step,
            fields.clone(),
            steps.clone(),
        );
        let lowered = lower(&gs, &plan, &profile).unwrap().duration_s();
        let model = StepTime::new(&gs, &fields, &[], &profile).job_time_s(&steps);
        assert!(
            (model - lowered).abs() <= 1e-9 * lowered,
            "{model} vs {lowered}"
        );
    }

    #[test]
    fn the_lower_bound_of_a_large_field_counts_its_jump_delays_and_stays_below_the_job() {
        // rows of 0.5 mm squares 1 mm apart in one field: beyond the exact-gap size the jumps
        // count their delays only; either way the bound is below the lowered job time
        let profile = MachineProfile::default();
        let bound_and_time = |n: usize| {
            let gs: Vec<Geometry> = (0..n)
                .map(|k| rect((k % 60) as f64, (k / 60) as f64, 0.5, 0.5))
                .collect();
            let field = ScanField {
                id: 0,
                center: Pt::new(30.0, 30.0),
                size: profile.field_mm,
                geometries: (0..n).collect(),
                locked: false,
                pose: Default::default(),
            };
            let steps: Vec<Step> = (0..n).map(|g| Step::from_choice(g, 0, &gs[g], 0)).collect();
            let inputs = PlanInputs {
                geometry_rev: 0,
                profile: profile.clone(),
                layers: Vec::new(),
                settings: SolverSettings::default(),
            };
            let fields = vec![field];
            let plan = Plan::new(
                &inputs,
                crate::document::Motion::Step,
                fields.clone(),
                steps,
            );
            let job_s = lower(&gs, &plan, &profile).unwrap().duration_s();
            let bound_s = step_job_time_lower_bound_s(&gs, &fields, &[], &profile);
            let marking_s: f64 = StepTime::new(&gs, &fields, &[], &profile)
                .mark_s
                .iter()
                .sum();
            (bound_s, job_s, marking_s)
        };
        let (exact, job, marking) = bound_and_time(EXACT_GAPS_MAX);
        assert!(exact <= job, "{exact} > {job}");
        // the nearest square is 0.5 mm away: more than the delays alone
        let delays = (EXACT_GAPS_MAX - 1) as f64 * profile.laser.jump_delay_s;
        assert!(exact - marking > delays + 1e-9);
        let (large, job, marking) = bound_and_time(EXACT_GAPS_MAX + 1);
        assert!(large <= job, "{large} > {job}");
        let delays = EXACT_GAPS_MAX as f64 * profile.laser.jump_delay_s;
        assert!(
            (large - marking - delays).abs() < 1e-9,
            "{large} {marking} {delays}"
        );
    }
}
