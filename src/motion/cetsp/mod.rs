//! Seed 001's stage routes for on-the-fly marking: `lsa` and `cetsp-ga`.
//!
//! Seed 001 (Lee, Tee, Ting, "Route planning through genetic algorithm for multi-axis motion
//! control") plans the route of a slow source device (here: the XY stage) that carries a fast
//! x-y motor (here: the galvo scanner) of padding radius `r`, as a close-enough TSP:
//!
//! * the **pattern** is a sequence of points at 1 mm resolution (§IV). Here it is the tool's
//!   marked path in marking order (the plan's order replaces the paper's nearest algorithm,
//!   Algorithm 3: the route must follow the order in which the scanner marks), each point with
//!   the tool's nominal time there (`Pattern`);
//! * the **LSA points** (`lsa`, §III-B and §III-C-2) are the union of the RDP (Algorithm 1)
//!   and VW (Algorithm 2) simplifications of every 100-point segment of the pattern, thinned by
//!   the half-padding-radius deduction. The `lsa` route ([`lsa_route`]) is the polyline through
//!   them, the paper's benchmark; the stage passes each LSA point at the tool's time there;
//! * the **GA** (`ga`, §III-C) optimises, per LSA point, a turning point within `r` of it and
//!   a movement speed, so that the route covers the pattern within `r` (`cover`), keeps the
//!   tool within `r` of the stage at every instant (the within-radius value) and is short.

mod cover;
mod ga;
mod lsa;

pub use cover::{Coverage, WITHIN_STEP_S};
pub use ga::{cetsp_ga, CetspResult};
pub use lsa::{deduct_half_radius, lsa_indices, rdp, vw};

use crate::geom::Pt;
use thiserror::Error;

/// The paper's pattern resolution: consecutive pattern points are at most this far apart, mm
/// (seed 001 §IV: "resolution 1 mm × 1 mm").
pub const PATTERN_STEP_MM: f64 = 1.0;

/// One knot of the tool-centre point's nominal time law (marks at mark speed, jumps at jump
/// speed), in marking order; `marking` = the laser is on from this knot to the next. The tool
/// moves straight and at constant speed between consecutive knots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolKnot {
    /// Nominal time, s (non-decreasing along the knots).
    pub t_s: f64,
    /// Tool-centre point, mm.
    pub at: Pt,
    /// True when the laser is on from this knot to the next.
    pub marking: bool,
}

pub use crate::document::TimedRoute;

/// The LSA settings (seed 001 §III-C-2).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LsaParams {
    /// Points per segment the RDP and VW simplifications run on (the paper: 100).
    pub segment_points: usize,
    /// RDP distance threshold ε, mm (the paper: 10 mm).
    pub rdp_epsilon_mm: f64,
    /// VW area threshold, mm² (the paper: 10 mm²).
    pub vw_area_mm2: f64,
    /// Padding radius `r`, mm: the scanner's reach around the stage (the caller's choice; half
    /// the field width by default).
    pub padding_radius_mm: f64,
}

/// The paper's segment size for the LSA, points (§III-C-2).
pub const PAPER_SEGMENT_POINTS: usize = 100;
/// The paper's RDP threshold, mm (§III-C-2).
pub const PAPER_RDP_EPSILON_MM: f64 = 10.0;
/// The paper's VW threshold, mm² (§III-C-2).
pub const PAPER_VW_AREA_MM2: f64 = 10.0;

impl LsaParams {
    /// The paper's settings with the given padding radius.
    pub fn paper(padding_radius_mm: f64) -> Self {
        Self {
            segment_points: PAPER_SEGMENT_POINTS,
            rdp_epsilon_mm: PAPER_RDP_EPSILON_MM,
            vw_area_mm2: PAPER_VW_AREA_MM2,
            padding_radius_mm,
        }
    }

    /// Checks the settings (see [`CetspError`]).
    pub fn validate(&self) -> Result<(), CetspError> {
        if self.segment_points < 2 {
            return Err(CetspError::SegmentPoints(self.segment_points));
        }
        non_negative("rdp_epsilon_mm", self.rdp_epsilon_mm)?;
        non_negative("vw_area_mm2", self.vw_area_mm2)?;
        validate_radius(self.padding_radius_mm)
    }
}

/// The GA settings (seed 001 Table II).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GaParams {
    /// Population size μ (the paper: 50).
    pub population: usize,
    /// Generations (the paper: 500).
    pub generations: usize,
    /// Crossover rate p_c (the paper: 1.0).
    pub crossover_rate: f64,
    /// Mutation rate p_m (the paper: 0.5).
    pub mutation_rate: f64,
    /// Seed of the run's random numbers.
    pub seed: u64,
}

impl Default for GaParams {
    /// The paper's settings (Table II), seed 1.
    fn default() -> Self {
        let paper = crate::document::RouteGaSettings::default();
        Self {
            population: paper.population,
            generations: paper.generations,
            crossover_rate: paper.crossover_rate,
            mutation_rate: paper.mutation_rate,
            seed: 1,
        }
    }
}

impl GaParams {
    /// Checks the settings (see [`CetspError`]).
    pub fn validate(&self) -> Result<(), CetspError> {
        if self.population == 0 {
            return Err(CetspError::ZeroPopulation);
        }
        rate("crossover_rate", self.crossover_rate)?;
        rate("mutation_rate", self.mutation_rate)
    }
}

/// Checks both settings and the padding radius the GA is given.
pub fn validate(lsa: &LsaParams, ga: &GaParams, padding_radius_mm: f64) -> Result<(), CetspError> {
    lsa.validate()?;
    ga.validate()?;
    validate_radius(padding_radius_mm)
}

/// Bad settings for the stage routes.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CetspError {
    /// The GA has no population.
    #[error("the route GA's population must be at least 1 (it is 0)")]
    ZeroPopulation,
    /// A rate outside [0, 1].
    #[error("the route GA's {name} must be a probability in [0, 1] (it is {value})")]
    Rate {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A padding radius that is not positive.
    #[error("the padding radius must be a positive length in mm (it is {0})")]
    Radius(f64),
    /// A threshold below zero or not a number.
    #[error("the LSA's {name} must be zero or more (it is {value})")]
    Threshold {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// Segments too short to simplify.
    #[error("the LSA's segments need at least 2 points (segment_points is {0})")]
    SegmentPoints(usize),
}

fn rate(name: &'static str, value: f64) -> Result<(), CetspError> {
    if (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(CetspError::Rate { name, value })
    }
}

fn non_negative(name: &'static str, value: f64) -> Result<(), CetspError> {
    if value >= 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(CetspError::Threshold { name, value })
    }
}

fn validate_radius(r_mm: f64) -> Result<(), CetspError> {
    if r_mm > 0.0 && r_mm.is_finite() {
        Ok(())
    } else {
        Err(CetspError::Radius(r_mm))
    }
}

/// A pattern point: where the tool marks, and when.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatternPt {
    /// Position, mm.
    pub at: Pt,
    /// Nominal tool time there, s.
    pub t_s: f64,
}

/// The pattern: the tool's marked points in marking order, marks resampled so that consecutive
/// points of one mark are at most `step_mm` apart (seed 001's pattern points V_P). Knots that
/// neither start nor end a mark (jump-only knots) are left out.
pub fn pattern(tool: &[ToolKnot], step_mm: f64) -> Vec<PatternPt> {
    let mut out: Vec<PatternPt> = Vec::new();
    for w in tool.windows(2) {
        let (a, b) = (w[0], w[1]);
        if !a.marking {
            continue;
        }
        let pieces = (a.at.dist(b.at) / step_mm).ceil().max(1.0) as usize;
        for k in 0..=pieces {
            let f = k as f64 / pieces as f64;
            let p = PatternPt {
                at: a.at.plus(b.at.minus(a.at).scale(f)),
                t_s: a.t_s + (b.t_s - a.t_s) * f,
            };
            if out.last() != Some(&p) {
                out.push(p);
            }
        }
    }
    out
}

/// The tool's position at `t_s` (clamped to its first and last knot).
pub fn tool_position(tool: &[ToolKnot], t_s: f64) -> Pt {
    let n = tool.len();
    if n == 0 {
        return Pt::default();
    }
    let k = tool.partition_point(|k| k.t_s <= t_s);
    if k == 0 {
        return tool[0].at;
    }
    if k == n {
        return tool[n - 1].at;
    }
    let (a, b) = (tool[k - 1], tool[k]);
    let span = b.t_s - a.t_s;
    if span <= 0.0 {
        return b.at;
    }
    a.at.plus(b.at.minus(a.at).scale((t_s - a.t_s) / span))
}

/// Seed 001's `lsa` route: the polyline through the LSA points, each passed at the tool's time
/// there. Call [`LsaParams::validate`] first; bad settings give a route, not a panic (a
/// non-positive radius deducts nothing).
pub fn lsa_route(tool: &[ToolKnot], params: &LsaParams) -> TimedRoute {
    let pat = pattern(tool, PATTERN_STEP_MM);
    let keep = lsa_indices(&pat, params);
    TimedRoute {
        points: keep.iter().map(|&i| pat[i].at).collect(),
        times_s: keep.iter().map(|&i| pat[i].t_s).collect(),
    }
}

#[cfg(test)]
mod tests;
