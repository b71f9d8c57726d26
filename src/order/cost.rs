//! Travel costs: what one move between two points costs the ordering.

use crate::document::{Cylinder, Pose};
use crate::geom::Pt;
use crate::motion::StageDynamics;
use std::collections::HashMap;
use std::sync::Arc;

/// The poses of placements by their X/Y position (placements of one job stand at different
/// X/Y; a position not in the map is at the rest pose).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PoseMap(Arc<HashMap<[u64; 2], Pose>>);

impl PoseMap {
    /// The poses of `placements` (X/Y position, pose); empty when every pose is the rest pose.
    pub fn new(placements: impl IntoIterator<Item = (Pt, Pose)>) -> Self {
        let map: HashMap<[u64; 2], Pose> = placements
            .into_iter()
            .filter(|(_, pose)| !pose.is_rest())
            .map(|(p, pose)| (key(p), pose))
            .collect();
        Self(Arc::new(map))
    }
    /// The pose at `p`.
    pub fn at(&self, p: Pt) -> Pose {
        self.0.get(&key(p)).copied().unwrap_or_default()
    }
    /// No placement leaves the rest pose.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

fn key(p: Pt) -> [u64; 2] {
    [p.x.to_bits(), p.y.to_bits()]
}

/// The cost of travelling between two points, symmetric in its ends (2-opt reverses runs).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum TravelCost {
    /// Euclidean distance, mm.
    #[default]
    Distance,
    /// Stage time from rest to settled, s: per axis a trapezoid, the slower axis counts, plus
    /// the settling (seed 002's time-based cost; the same timing the toolpath uses).
    StageTime(StageDynamics),
    /// [`TravelCost::StageTime`] over every axis the placements move: X, Y and the Z, A, B of
    /// their poses (seed 002's 5-axis time, the slowest axis counts).
    PoseTime(StageDynamics, PoseMap),
    /// Euclidean distance in 3-D between placements (X, Y and the poses' Z), mm: seed 002's
    /// "3D Euclidean" ordering, blind to the rotary axes.
    Distance3d(PoseMap),
    /// The 3-D distance between points of a cylinder's unrolled surface, on the cylinder
    /// ([`Cylinder::surface_distance_mm`]), mm.
    Surface(Cylinder),
}

impl TravelCost {
    /// The cost from `a` to `b`.
    pub fn between(&self, a: Pt, b: Pt) -> f64 {
        match self {
            TravelCost::Distance => a.dist(b),
            TravelCost::StageTime(stage) => stage.move_time_s(a, b),
            TravelCost::PoseTime(stage, poses) => {
                stage.pose_move_time_s(a, &poses.at(a), b, &poses.at(b))
            }
            TravelCost::Distance3d(poses) => {
                let dz = poses.at(a).z_mm - poses.at(b).z_mm;
                a.dist(b).hypot(dz)
            }
            TravelCost::Surface(cylinder) => cylinder.surface_distance_mm(a, b),
        }
    }
    /// The distance between placements: on a cylinder's surface, else in the plane.
    pub fn distance(cylinder: Option<Cylinder>) -> Self {
        cylinder.map_or(TravelCost::Distance, TravelCost::Surface)
    }
    /// The cost of moving the stage between placements: stage time over every axis the
    /// placements use.
    pub fn stage_time(stage: StageDynamics, poses: PoseMap) -> Self {
        if poses.is_empty() {
            TravelCost::StageTime(stage)
        } else {
            TravelCost::PoseTime(stage, poses)
        }
    }
}
