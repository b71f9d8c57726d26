//! Travel costs: what one move between two points costs the ordering.

use crate::geom::Pt;
use crate::motion::StageDynamics;

/// The cost of travelling between two points, symmetric in its ends (2-opt reverses runs).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum TravelCost {
    /// Euclidean distance, mm.
    #[default]
    Distance,
    /// Stage time from rest to settled, s: per axis a trapezoid, the slower axis counts, plus
    /// the settling (seed 002's time-based cost; the same timing the toolpath uses).
    StageTime(StageDynamics),
}

impl TravelCost {
    /// The cost from `a` to `b`.
    pub fn between(&self, a: Pt, b: Pt) -> f64 {
        match self {
            TravelCost::Distance => a.dist(b),
            TravelCost::StageTime(stage) => stage.move_time_s(a, b),
        }
    }
}
