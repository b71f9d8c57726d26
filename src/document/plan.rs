//! Scan fields and plans (ordered strokes plus metrics).

use crate::geom::{BBox, Pt};
use serde::{Deserialize, Serialize};

use super::{Algo, CostModel, Motion, Pose};

/// A scan field: the base parks at `center` and the scanner reaches `size` around it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScanField {
    /// Id, unique within a document (report and G-code comments use it).
    pub id: usize,
    /// Centre in mm = base position.
    pub center: Pt,
    /// Size (x, y) in mm.
    pub size: [f64; 2],
    /// Placed by the operator: automatic placement keeps it.
    #[serde(default)]
    pub locked: bool,
    /// Geometries allocated to this field (indices into the document's geometries).
    #[serde(default)]
    pub geometries: Vec<usize>,
    /// Where the axes beyond X/Y stand while it is marked (a 5-axis or rotary machine); the
    /// rest pose on a flat machine, which files do not write.
    #[serde(default, skip_serializing_if = "Pose::is_rest")]
    pub pose: Pose,
}

impl ScanField {
    /// The area the scanner reaches.
    pub fn bbox(&self) -> BBox {
        BBox::centered(self.center, self.size[0], self.size[1])
    }
}

/// One stroke of a plan: which geometry, in which field, from which vertex, in which direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Step {
    /// Geometry index.
    pub geometry: usize,
    /// Field id.
    pub field: usize,
    /// Start vertex: any vertex of a closed geometry; 0 or the last vertex of an open one.
    pub start_vertex: usize,
    /// Marked backwards (for an open geometry: from its last vertex).
    pub reversed: bool,
}

impl Step {
    /// The step for a start choice as in [`crate::document::Geometry::ends`].
    pub fn from_choice(geometry: usize, field: usize, g: &super::Geometry, choice: usize) -> Step {
        if g.closed {
            Step {
                geometry,
                field,
                start_vertex: choice,
                reversed: false,
            }
        } else {
            Step {
                geometry,
                field,
                start_vertex: if choice == 0 {
                    0
                } else {
                    g.points.len().saturating_sub(1)
                },
                reversed: choice != 0,
            }
        }
    }
    /// The start choice index of this step (inverse of [`Step::from_choice`]).
    pub fn choice(&self, g: &super::Geometry) -> usize {
        if g.closed {
            self.start_vertex
        } else {
            usize::from(self.reversed)
        }
    }
}

/// Wall time per pipeline stage, in s.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StageTimes {
    /// SVG import and normalisation.
    pub import: f64,
    /// Hatch generation.
    pub hatch: f64,
    /// Scan-field placement and allocation.
    pub fields: f64,
    /// Ordering (baseline / HHA / HGA).
    pub order: f64,
    /// Export (G-code, report, preview).
    pub export: f64,
    /// Sum of the stages.
    pub total: f64,
    /// Sub-stages of the ordering (name, s), in run order.
    #[serde(default)]
    pub order_detail: Vec<(String, f64)>,
}

/// Job time by what the machine does, s; the parts add up to the job time.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TimeBreakdown {
    /// Stage moves between fields.
    pub stage: f64,
    /// Stage settling after moves.
    pub settle: f64,
    /// Scanner jumps and jump delays (those not hidden in a stage move).
    pub jump: f64,
    /// Marking.
    pub mark: f64,
    /// Laser on and off delays.
    pub laser_delays: f64,
}

impl TimeBreakdown {
    /// The parts with their names, in display order.
    pub fn parts(&self) -> [(&'static str, f64); 5] {
        [
            ("stage", self.stage),
            ("settle", self.settle),
            ("jump", self.jump),
            ("mark", self.mark),
            ("laser_delays", self.laser_delays),
        ]
    }
    /// The sum of the parts, s.
    pub fn total(&self) -> f64 {
        self.parts().iter().map(|p| p.1).sum()
    }
}

/// The stage's route and the scanner's reach over a job, from the toolpath sampled at a
/// constant period (seed 001 Table IV's figures; `check_trajectory.py` computes the same).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct MotionFigures {
    /// Length of the sampled stage route, mm.
    pub stage_route_mm: f64,
    /// Largest stage speed between two samples (vector), mm/s.
    pub stage_peak_speed_mm_s: f64,
    /// Total variation of the stage speed (Σ |Δ speed| between samples), mm/s.
    pub stage_speed_variation_mm_s: f64,
    /// Largest scanner offset on either axis, mm.
    pub scan_peak_offset_mm: f64,
}

/// A stretch of a mixed job run in one motion: consecutive strokes of one field marked
/// step-and-scan, or the strokes between such fields marked on the fly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MotionRegion {
    /// How it runs.
    pub motion: Motion,
    /// The ids of its fields, in visiting order.
    pub fields: Vec<usize>,
    /// Its strokes in marking order: `[first, end)` (indices into the report's `order`).
    pub strokes: [usize; 2],
    /// When it starts (the end of the mark before it; 0 for the first), s.
    pub start_s: f64,
    /// When it ends (the end of its last mark; the job's end for the last), s.
    pub end_s: f64,
}

/// Metrics of a plan (definitions in docs/DESIGN.md and `order::metrics`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Laser-off travel between consecutive strokes, mm.
    pub idle_mm: f64,
    /// Marked length, mm.
    pub marked_mm: f64,
    /// Length of the polyline through the field centres in visiting order, mm.
    pub base_mm: f64,
    /// Number of scan fields.
    pub fields: usize,
    /// A lower bound on the number of fields, when known.
    pub fields_lower_bound: Option<usize>,
    /// Area covered by exactly one field, mm².
    pub covered_area_mm2: f64,
    /// 1 − covered / (fields × field area), in %.
    pub overlap_pct: f64,
    /// Sign reversals of the travel direction along the base path.
    pub direction_changes: usize,
    /// Machine time of the job: the lowered toolpath's duration (`motion`), s.
    pub job_time_s: Option<f64>,
    /// The job time by what the machine does, s.
    #[serde(default)]
    pub job_time_breakdown_s: Option<TimeBreakdown>,
    /// The stage's route, its speeds and the scanner's reach, sampled every millisecond.
    #[serde(default)]
    pub motion: Option<MotionFigures>,
    /// A mixed job's stretches, each in its motion, in job order (empty: the whole job runs
    /// the plan's one motion).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub motion_regions: Vec<MotionRegion>,
    /// Wall time per stage, s.
    pub solve_s: StageTimes,
    /// Why a solve that may choose its motion planned only this one (none: it planned every
    /// motion it allows, or was asked for one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion_note: Option<String>,
}

/// What the values of a GA history measure: the plan's objective.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectiveKind {
    /// Idle travel, mm (`--cost distance`; histories made before the objective was recorded).
    #[default]
    IdleMm,
    /// Job time, s (`--cost time`, step-and-scan): the figure the plan's table shows.
    JobTimeS,
    /// Job time as if marked step-and-scan, s: on the fly the GA ranks chromosomes on it (the
    /// job time on the fly needs the stage route); an estimate, not the table's figure.
    StepJobTimeEstimateS,
}

impl ObjectiveKind {
    /// The objective of a solve with this cost model and motion.
    pub fn of(cost: CostModel, motion: Motion) -> Self {
        match (cost, motion) {
            (CostModel::Distance, _) => ObjectiveKind::IdleMm,
            (CostModel::Time, Motion::Step) => ObjectiveKind::JobTimeS,
            (CostModel::Time, Motion::OnTheFly) => ObjectiveKind::StepJobTimeEstimateS,
        }
    }
    /// Its unit.
    pub fn unit(self) -> &'static str {
        match self {
            ObjectiveKind::IdleMm => "mm",
            _ => "s",
        }
    }
    /// What it is, in words, with its unit (a plot's axis label).
    pub fn words(self) -> &'static str {
        match self {
            ObjectiveKind::IdleMm => "Idle travel (mm)",
            ObjectiveKind::JobTimeS => "Job time (s)",
            ObjectiveKind::StepJobTimeEstimateS => "Job time if marked step-and-scan (s, estimate)",
        }
    }
    /// A value with the decimals its unit needs (ms for times, 0.1 mm for travel).
    pub fn show(self, v: f64) -> String {
        match self {
            ObjectiveKind::IdleMm => format!("{v:.1}"),
            _ => format!("{v:.3}"),
        }
    }
    /// The plan's table figure for this objective, when the table has it (an estimate has
    /// none).
    pub fn of_metrics(self, m: &Metrics) -> Option<f64> {
        match self {
            ObjectiveKind::IdleMm => Some(m.idle_mm),
            ObjectiveKind::JobTimeS => m.job_time_s,
            ObjectiveKind::StepJobTimeEstimateS => None,
        }
    }
}

/// One GA generation in a plan's convergence history.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GenerationRecord {
    /// Generation number (0 = initial population).
    pub generation: usize,
    /// Best objective value so far (in `objective`'s unit).
    #[serde(alias = "best_idle_mm")]
    pub best: f64,
    /// Mean objective value of the population.
    #[serde(alias = "mean_idle_mm")]
    pub mean: f64,
    /// What `best` and `mean` measure.
    #[serde(default)]
    pub objective: ObjectiveKind,
    /// Population size.
    pub population: usize,
    /// Seconds since the start of the run.
    pub elapsed_s: f64,
    /// The plan as made (the GA's best, refined and lowered like every plan, or its seed when
    /// that is better): `best` is then the plan's table figure. Only the last record.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub finished: bool,
}

/// The result of one ordering run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// Display name (e.g. "HHA #1").
    pub name: String,
    /// The algorithm that made it.
    pub algo: Algo,
    /// The fields it was planned on, in visiting order.
    pub fields: Vec<ScanField>,
    /// Strokes in marking order.
    pub order: Vec<Step>,
    /// Its metrics.
    pub metrics: Metrics,
    /// GA convergence history (empty for other algorithms).
    #[serde(default)]
    pub history: Vec<GenerationRecord>,
    /// The tray's parts it marks, with what each carries (empty: not a production job).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub parts: Vec<super::PartRecord>,
    /// The motion it was planned for: it is lowered, shown and exported that way whatever the
    /// current setting (projects from before on-the-fly marking are step-and-scan).
    #[serde(default)]
    pub motion: Motion,
    /// Mixed motion (on the fly only): the ids of the fields marked step-and-scan inside the
    /// on-the-fly job, the stage at rest while their strokes are marked and moving between
    /// them (issue 26). Empty: the whole job runs [`Plan::motion`].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub step_fields: Vec<usize>,
    /// On the fly with seed 001's routes (`lsa`, `cetsp-ga`): the stage route the lowering
    /// follows (none: the taut string, computed by the lowering itself).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stage_route: Option<super::TimedRoute>,
    /// The layers and pens it was planned with (mark speeds, powers, passes, hatch): it is
    /// lowered and exported with them whatever the current layer table. Empty (plans from
    /// before pens): every geometry with the profile's speed, feed and power.
    #[serde(default)]
    pub layers: Vec<super::Layer>,
    /// The machine profile it was planned for: its figures, its lowering and its exports are
    /// of this profile, whatever the document's current one (project version 3; older
    /// projects' plans get the document's profile on load).
    #[serde(default)]
    pub profile: super::MachineProfile,
    /// The solver settings it was planned with (cost, motion, route, seed, …; `algo` and
    /// `motion` are the plan's own).
    #[serde(default)]
    pub settings: super::SolverSettings,
    /// The revision of the document's geometries it was planned on
    /// ([`super::Document::plan_geometries`]).
    #[serde(default)]
    pub geometry_rev: u64,
    /// The tiling its geometries were cut on (none: nothing larger than a field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tiling: Option<crate::geom::tiling::Tiling>,
    /// What cutting at the tiling's seams did (cuts, seams, length marked twice).
    #[serde(default)]
    pub seams: crate::geom::seam::SeamStats,
}

impl Plan {
    /// A plan of `order` on `fields` (in visiting order) made from `inputs` to run in `motion`,
    /// before metrics.
    pub fn new(
        inputs: &super::PlanInputs,
        motion: Motion,
        fields: Vec<ScanField>,
        order: Vec<Step>,
    ) -> Plan {
        Plan {
            name: String::new(),
            algo: inputs.settings.algo,
            fields,
            order,
            metrics: Metrics::default(),
            history: Vec::new(),
            parts: Vec::new(),
            motion,
            step_fields: Vec::new(),
            stage_route: None,
            layers: inputs.layers.clone(),
            profile: inputs.profile.clone(),
            settings: inputs.settings.clone(),
            geometry_rev: inputs.geometry_rev,
            tiling: None,
            seams: Default::default(),
        }
    }
    /// How the plan runs, in words: its motion, and for a mixed job how many of its fields
    /// are marked step-and-scan.
    pub fn motion_words(&self) -> String {
        match (self.motion, self.step_fields.len()) {
            (Motion::OnTheFly, n) if n > 0 => format!(
                "mixed: on the fly, {n} of {} fields step-and-scan",
                self.fields.len()
            ),
            (motion, _) => motion.words().to_string(),
        }
    }
    /// The pen of geometry `g` in this plan (none: the profile's settings).
    pub fn pen(&self, g: &super::Geometry) -> Option<&super::Pen> {
        super::pen_of(&self.layers, g)
    }
    /// How geometry `g` is marked in time in this plan on `profile`.
    pub fn mark_timing(
        &self,
        g: &super::Geometry,
        profile: &super::MachineProfile,
    ) -> super::MarkTiming {
        super::MarkTiming::of(self.pen(g), profile)
    }
    /// Mark speed of geometry `g` in this plan on `profile`, mm/s.
    pub fn mark_speed_mm_s(&self, g: &super::Geometry, profile: &super::MachineProfile) -> f64 {
        self.pen(g).map_or(profile.scanner.mark_speed_mm_s, |p| {
            p.mark_speed_mm_s(profile)
        })
    }
}
