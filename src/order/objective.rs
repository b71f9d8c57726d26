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

use crate::document::{pen_of, CostModel, Geometry, Layer, MachineProfile, ScanField, Step};
use crate::geom::Pt;
use crate::motion::StageDynamics;
use std::collections::HashMap;

/// The unit of an objective value.
pub fn unit(cost: CostModel) -> &'static str {
    match cost {
        CostModel::Time => "s",
        CostModel::Distance => "mm",
    }
}

/// Job time of a step-and-scan order, without lowering (see the module text).
pub struct StepTime<'a> {
    geometries: &'a [Geometry],
    layers: &'a [Layer],
    centre: HashMap<usize, Pt>,
    stage: StageDynamics,
    jump_speed_mm_s: f64,
    jump_delay_s: f64,
    /// Per geometry: laser-on delay + mark + laser-off delay, s.
    mark_s: Vec<f64>,
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
        let mark_s = geometries
            .iter()
            .map(|g| {
                let speed = pen_of(layers, g).map_or(profile.scanner.mark_speed_mm_s, |p| {
                    p.mark_speed_mm_s(profile)
                });
                laser.on_delay_s + g.length_mm() / speed + laser.off_delay_s
            })
            .collect();
        Self {
            geometries,
            layers,
            centre: fields.iter().map(|f| (f.id, f.center)).collect(),
            stage: StageDynamics::of(profile),
            jump_speed_mm_s: profile.scanner.jump_speed_mm_s,
            jump_delay_s: laser.jump_delay_s,
            mark_s,
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

    fn sum(&self, steps: &[Step]) -> f64 {
        let mut t = 0.0;
        let (mut stage_at, mut scan_at) = (Pt::default(), Pt::default());
        for (k, s) in steps.iter().enumerate() {
            let (Some(g), Some(&centre)) =
                (self.geometries.get(s.geometry), self.centre.get(&s.field))
            else {
                return f64::INFINITY;
            };
            let (start, end) = g.ends(s.choice(g));
            let offset = start.minus(centre);
            if k == 0 {
                stage_at = centre;
            } else if centre == stage_at {
                t += offset.dist(scan_at) / self.jump_speed_mm_s + self.jump_delay_s;
            } else {
                let mv = self.stage.plan_move(stage_at, centre);
                let jump_s = offset.dist(scan_at) / self.jump_speed_mm_s;
                let hidden = jump_s <= mv.move_s && jump_s + self.jump_delay_s <= mv.total_s();
                t += mv.total_s();
                if !hidden {
                    t += jump_s + self.jump_delay_s;
                }
                stage_at = centre;
            }
            t += self.mark_s[s.geometry];
            scan_at = end.minus(stage_at);
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::{Plan, PlanInputs, SolverSettings};
    use crate::geom::Pt;
    use crate::motion::lower;

    fn square(x: f64, y: f64, s: f64) -> Geometry {
        Geometry::new(
            vec![
                Pt::new(x, y),
                Pt::new(x + s, y),
                Pt::new(x + s, y + s),
                Pt::new(x, y + s),
                Pt::new(x, y),
            ],
            true,
            crate::document::Source::default(),
        )
    }

    #[test]
    fn the_step_time_equals_the_lowered_job_time() {
        let profile = MachineProfile::default();
        let centre = |j: usize| Pt::new(50.0 + 45.0 * j as f64, 40.0 + 37.0 * (j % 3) as f64);
        let gs: Vec<Geometry> = (0..12)
            .map(|k| {
                let c = centre(k / 2);
                if k % 2 == 0 {
                    square(c.x - 20.0, c.y - 10.0, 4.0 + k as f64)
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
        let plan = Plan::new(&inputs, fields.clone(), steps.clone());
        let lowered = lower(&gs, &plan, &profile).unwrap().duration_s();
        let model = StepTime::new(&gs, &fields, &[], &profile).job_time_s(&steps);
        assert!(
            (model - lowered).abs() <= 1e-9 * lowered,
            "{model} vs {lowered}"
        );
    }
}
