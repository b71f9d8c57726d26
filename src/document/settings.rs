//! Solver settings: which field placement and ordering to run, seed, limits, GA parameters.

use super::validate::InvalidValue;
use serde::{Deserialize, Serialize};

/// How scan fields are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum FieldsMode {
    /// Greedy cover in serpentine order (baseline).
    Greedy,
    /// Set cover: fewest fields, then least overlap, then best centring.
    #[default]
    Auto,
    /// The scan-field paper's placement (seed 000 §3.1 in docs/REFERENCES.md): random fields,
    /// removal test, unit moves.
    Paper,
}

/// Which ordering algorithm runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Algo {
    /// Fields and geometries in document order, no optimisation (a reference to compare with).
    #[serde(rename = "as-is")]
    AsIs,
    /// Fields in creation order, nearest neighbour inside each field.
    Baseline,
    /// Hierarchical heuristic algorithm (seed 000 §3.2).
    #[default]
    Hha,
    /// Hybrid genetic algorithm (seed 000 §3.3).
    Hga,
}

impl Algo {
    /// The name used on the command line, in reports and in plan names.
    pub fn label(self) -> &'static str {
        match self {
            Algo::AsIs => "as-is",
            Algo::Baseline => "baseline",
            Algo::Hha => "hha",
            Algo::Hga => "hga",
        }
    }
}

impl SolverSettings {
    /// What a plan made with these settings is, in words: algorithm, cost, motion (with the
    /// stage route on the fly) and, for the searches that draw random numbers, the seed, e.g.
    /// `HGA · job time · on the fly (lsa)`. Plans are named after it.
    pub fn plan_title(&self) -> String {
        self.title_with(None)
    }

    /// [`plan_title`](Self::plan_title) of a plan made in `motion`: under
    /// [`MotionMode::Auto`] it says which motion the solve chose, e.g.
    /// `HHA · job time · auto: on the fly`.
    pub fn plan_title_as(&self, motion: Motion) -> String {
        self.title_with(Some(self.motion_words(motion)))
    }

    /// The title of `plan` made with these settings: [`Self::plan_title_as`] its motion, a
    /// mixed job's in its own words ([`super::Plan::motion_words`]).
    pub fn title_of(&self, plan: &super::Plan) -> String {
        match plan.step_fields.is_empty() {
            true => self.plan_title_as(plan.motion),
            false => self.title_with(Some(plan.motion_words())),
        }
    }

    fn title_with(&self, chosen: Option<String>) -> String {
        let algo = match self.algo {
            Algo::AsIs => "As-is",
            Algo::Baseline => "Baseline",
            Algo::Hha => "HHA",
            Algo::Hga => "HGA",
        };
        // cost and motion in the words of the settings table (the stale reasons say the same)
        let words = |key: &str| {
            super::spec::settings_specs()
                .into_iter()
                .find(|s| s.key == key)
                .map_or_else(String::new, |s| (s.show)(self))
        };
        let cost = words("cost_model");
        let motion = match (self.motion, chosen) {
            (MotionMode::Auto, Some(m)) => format!("auto: {m}"),
            (MotionMode::Auto, None) => words("motion"),
            (MotionMode::Step, _) => self.motion_words(Motion::Step),
            (MotionMode::OnTheFly, _) => self.motion_words(Motion::OnTheFly),
        };
        // the random seed is in a plan's details; the GUI adds it to a name only where two
        // plans differ by seed alone
        format!("{algo} · {cost} · {motion}")
    }

    /// A motion in words, on the fly with seed 001's stage route as the command line spells it
    /// (galvoplan's own route goes without a word; short enough for a plan's name).
    fn motion_words(&self, motion: Motion) -> String {
        match motion {
            Motion::Step => motion.words().to_string(),
            Motion::OnTheFly => match self.stage_route {
                StageRouteKind::Taut => motion.words().to_string(),
                StageRouteKind::Lsa => format!("{} (lsa)", motion.words()),
                StageRouteKind::CetspGa => format!("{} (cetsp-ga)", motion.words()),
            },
        }
    }
}

/// How start vertices are chosen once the order is fixed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum VertexMode {
    /// The vertex estimate alone (seed 000's VEA, docs/REFERENCES.md).
    Vea,
    /// VEA followed by the exact layered-graph shortest path.
    #[default]
    Exact,
}

/// Cost of moving between two points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum CostModel {
    /// Idle distance in mm (laser-off travel, the machine's dynamics ignored).
    Distance,
    /// Machine time from the profile's dynamics (seed 002): the toolpath's job time.
    #[default]
    Time,
}

/// How the machine should move while it marks: one motion, or whichever runs the job faster.
/// The command line's default is [`MotionMode::Auto`]; a document's (and a project file's
/// without the key) is step-and-scan, as before automatic motion existed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum MotionMode {
    /// The faster of step-and-scan and on the fly, judged on the lowered job time (and, where
    /// geometries are larger than a field, of marking them whole or cut at field borders).
    #[serde(rename = "auto")]
    Auto,
    /// Step-and-scan: the stage stops at every field, the scanner marks it.
    #[default]
    #[serde(rename = "step")]
    Step,
    /// On the fly: the stage moves on a continuous route while the scanner marks.
    #[serde(rename = "on-the-fly")]
    OnTheFly,
}

impl MotionMode {
    /// The motions a solve tries: both for [`MotionMode::Auto`], else the one asked for.
    pub fn candidates(self) -> &'static [Motion] {
        match self {
            MotionMode::Auto => &[Motion::Step, Motion::OnTheFly],
            MotionMode::Step => &[Motion::Step],
            MotionMode::OnTheFly => &[Motion::OnTheFly],
        }
    }
    /// True when on-the-fly marking is among the motions tried.
    pub fn may_fly(self) -> bool {
        self != MotionMode::Step
    }
}

/// How a plan's machine moves while it marks (what it is lowered, shown and exported as).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Motion {
    /// Step-and-scan: the stage stops at every field, the scanner marks it.
    #[default]
    #[serde(rename = "step")]
    Step,
    /// On the fly: the stage moves on a continuous route while the scanner marks.
    #[serde(rename = "on-the-fly")]
    OnTheFly,
}

impl Motion {
    /// What it is, in words (the settings table's words).
    pub fn words(self) -> &'static str {
        match self {
            Motion::Step => "step-and-scan",
            Motion::OnTheFly => "on the fly",
        }
    }
}

impl From<Motion> for MotionMode {
    fn from(m: Motion) -> Self {
        match m {
            Motion::Step => MotionMode::Step,
            Motion::OnTheFly => MotionMode::OnTheFly,
        }
    }
}

/// The stage route of on-the-fly marking.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum StageRouteKind {
    /// galvoplan's own: per axis the stage tracks the laser point within the scanner's reach at
    /// the axis limits, slowing the marking only where it cannot keep up (the taut string, the
    /// shortest route, blended, where tracking does not settle). The name is kept for saved
    /// projects.
    #[default]
    #[serde(rename = "taut")]
    Taut,
    /// Line-simplified route: the polyline through the simplified pattern points (seed 001's
    /// benchmark, docs/REFERENCES.md).
    #[serde(rename = "lsa")]
    Lsa,
    /// Genetic-algorithm route: a close-enough TSP through those points (seed 001's GA).
    #[serde(rename = "cetsp-ga")]
    CetspGa,
}

/// Settings of seed 001's route GA and of its padding radius (the paper's defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RouteGaSettings {
    /// Population size (paper: 50).
    pub population: usize,
    /// Generations (paper: 500).
    pub generations: usize,
    /// Crossover rate p_c (paper: 1.0).
    pub crossover_rate: f64,
    /// Mutation rate p_m (paper: 0.5).
    pub mutation_rate: f64,
    /// Padding radius, mm (none: half the field's smaller side, the circle inscribed in it).
    pub padding_radius_mm: Option<f64>,
}

impl Default for RouteGaSettings {
    fn default() -> Self {
        // seed 001 Table II
        Self {
            population: 50,
            generations: 500,
            crossover_rate: 1.0,
            mutation_rate: 0.5,
            padding_radius_mm: None,
        }
    }
}

/// Parameters of the hybrid genetic algorithm (seed 000 §3.3.6 defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GaParams {
    /// Initial population size `ps`.
    pub population: usize,
    /// Smallest population size.
    pub population_min: usize,
    /// Largest population size.
    pub population_max: usize,
    /// Fraction of the population kept as elite.
    pub elite_fraction: f64,
    /// Mutation probability.
    pub mutation_rate: f64,
    /// Stop after this many generations without improvement.
    pub stall_generations: usize,
    /// Stop after this many generations (none: only the stall, the time limit or a cancel end
    /// the run).
    pub max_generations: Option<usize>,
    /// Seed the population with the HHA plan.
    pub seed_with_hha: bool,
}

impl Default for GaParams {
    fn default() -> Self {
        Self {
            population: 32,
            population_min: 16,
            population_max: 48,
            elite_fraction: 0.2,
            mutation_rate: 0.3,
            stall_generations: 5,
            max_generations: None,
            seed_with_hha: true,
        }
    }
}

/// Settings of one planning run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SolverSettings {
    /// Field placement.
    pub fields: FieldsMode,
    /// Ordering algorithm.
    pub algo: Algo,
    /// Random seed (all randomised stages are deterministic for a given seed).
    pub seed: u64,
    /// Time limit for the ordering stage in s (none: the algorithm's own termination).
    pub time_limit_s: Option<f64>,
    /// Directional penalty weight (seed 000 Eq. 7; 0.1 is used with one field).
    pub direction_weight: f64,
    /// Start-vertex choice.
    pub vertex: VertexMode,
    /// HHA beyond the seed: directional local search, exact vertices, alternation. Off: the
    /// seed's HHA (path cheapest arc on Eq. 7 costs, VEA) for comparison.
    pub hha_improve: bool,
    /// Cost model.
    pub cost_model: CostModel,
    /// Step-and-scan or on the fly.
    pub motion: MotionMode,
    /// The stage route on the fly.
    pub stage_route: StageRouteKind,
    /// Seed 001's route GA (`cetsp-ga`) and padding radius (`lsa`, `cetsp-ga`).
    pub route_ga: RouteGaSettings,
    /// Cut geometries larger than a field at field borders instead of failing.
    pub split_oversize: bool,
    /// GA parameters.
    pub ga: GaParams,
    /// Hatch fills for closed regions (none: outlines only).
    #[serde(default)]
    pub hatch: Option<super::HatchSettings>,
    /// The seam form of the default pen (layers no pen library names): how strokes are cut
    /// where they cross a seam of the tiling.
    #[serde(default)]
    pub seam: crate::geom::seam::SeamForm,
    /// A cylinder job: the artwork is the unrolled surface of this cylinder on the rotary A
    /// axis (`--cylinder`); none: a flat job.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cylinder: Option<super::Cylinder>,
}

impl SolverSettings {
    /// The pen of layers nothing else names: defaults, with these settings' hatch (`--hatch`)
    /// and seam form (`--seam`).
    pub fn default_pen(&self) -> super::Pen {
        super::Pen {
            hatch: self.hatch.clone(),
            seam: self.seam,
            ..super::Pen::default()
        }
    }
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            fields: FieldsMode::default(),
            algo: Algo::default(),
            seed: 1,
            time_limit_s: None,
            direction_weight: 0.5,
            vertex: VertexMode::default(),
            hha_improve: true,
            cost_model: CostModel::default(),
            motion: MotionMode::default(),
            stage_route: StageRouteKind::default(),
            route_ga: RouteGaSettings::default(),
            split_oversize: false,
            ga: GaParams::default(),
            hatch: None,
            seam: Default::default(),
            cylinder: None,
        }
    }
}

impl SolverSettings {
    /// Checks ranges; the error names the first bad value in the GUI's words.
    pub fn validate(&self) -> Result<(), InvalidValue> {
        super::spec::check_all(&super::spec::settings_specs(), self)?;
        super::spec::check_all(&super::spec::cylinder_specs(), self)?;
        let ga = &self.ga;
        if !(ga.population_min <= ga.population && ga.population <= ga.population_max) {
            return Err(InvalidValue::new(
                "GA population",
                "ga.population",
                ga.population,
                format!(
                    "between GA population min ({}) and max ({})",
                    ga.population_min, ga.population_max
                ),
            ));
        }
        if let Some(h) = &self.hatch {
            h.check().map_err(|e| e.within("Default hatch", "hatch"))?;
        }
        Ok(())
    }
}

/// The smallest GA population: a crossover needs two parents.
pub const MIN_POPULATION: usize = 2;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_errors_are_worded() {
        assert!(SolverSettings::default().validate().is_ok());
        let mut s = SolverSettings {
            direction_weight: -1.0,
            ..SolverSettings::default()
        };
        let e = s.validate().unwrap_err();
        assert_eq!(
            e.to_string(),
            "Direction weight must be zero or a positive number, not -1"
        );
        s.direction_weight = 0.5;
        s.ga.population = 100;
        assert!(s
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("GA population must be between"));
        s.ga.population = 32;
        s.time_limit_s = Some(0.0);
        assert_eq!(s.validate().unwrap_err().key, "time_limit_s");
        s.time_limit_s = None;
        s.ga.mutation_rate = 2.0;
        assert_eq!(s.validate().unwrap_err().what, "GA mutation rate");
        s.ga.mutation_rate = 0.3;
        s.ga.stall_generations = 0;
        assert!(s.validate().is_err());
        s.ga.stall_generations = 5;
        s.hatch = Some(crate::document::HatchSettings::new(
            crate::document::HatchStyle::Lines,
            0.0,
        ));
        let e = s.validate().unwrap_err().to_string();
        assert!(e.starts_with("Default hatch: Hatch spacing (mm)"), "{e}");
    }
}
