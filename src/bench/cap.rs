//! Seed 002's experiment (docs/REFERENCES.md, its §7 and Table 3): a layout of placements on a
//! free-form surface, ordered as is, by 3-D Euclidean distance and by 5-axis time, each timed
//! on the 5-axis machine.
//!
//! The surface is a spherical cap over the stage (seed 002's feature has a circular planar
//! projection, its Fig. 4): a sphere of radius `R` whose apex stands over `centre` at Z = 0. A
//! placement at stage position `(x, y)`, `r` from the centre, is on the cap at
//! `z = √(R² − r²) − R`, with the surface normal `n = (x − cₓ, y − c_y, √(R² − r²)) / R`. The head
//! stands along the normal: `A = −asin(n_y)` (about X), `B = atan2(n_x, n_z)` (about Y), so that
//! `R_y(B)·R_x(A)·ẑ = n`.
//!
//! Timing: a move between placements costs the slowest axis's time (each axis's trapezoid,
//! seed 002's eq. 14) plus settling ([`StageDynamics::pose_move_time_s`]); the figures here are
//! the moves alone (what the order changes). Seed 002's times include its marking, the same
//! for every order.

use crate::document::{MachineProfile, Pose, ScanField};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use crate::motion::StageDynamics;
use crate::order::cost::{PoseMap, TravelCost};
use crate::order::tsp::{LocalSearch, LsOptions, PathProblem, Tour};
use serde::Serialize;
use thiserror::Error;

/// A spherical cap over the stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cap {
    /// The sphere's radius, mm.
    pub radius_mm: f64,
    /// Where its apex stands on the stage, mm.
    pub centre: Pt,
}

/// A placement beyond the cap.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("field {field} at ({x:.1}, {y:.1}) mm is {r:.1} mm from the cap's centre, beyond its radius {radius:.1} mm")]
pub struct OffCap {
    /// Field id.
    pub field: usize,
    /// Its centre, mm.
    pub x: f64,
    /// Its centre, mm.
    pub y: f64,
    /// Its distance from the cap's centre, mm.
    pub r: f64,
    /// The cap's radius, mm.
    pub radius: f64,
}

impl Cap {
    /// The pose of a placement at `p` (field `field`, for the error): Z on the cap, the head
    /// along the normal.
    pub fn pose(&self, field: usize, p: Pt) -> Result<Pose, OffCap> {
        let (dx, dy) = (p.x - self.centre.x, p.y - self.centre.y);
        let r = dx.hypot(dy);
        let radius = self.radius_mm;
        if r.is_nan() || r >= radius {
            return Err(OffCap {
                field,
                x: p.x,
                y: p.y,
                r,
                radius,
            });
        }
        let h = (radius * radius - r * r).sqrt();
        let (nx, ny, nz) = (dx / radius, dy / radius, h / radius);
        Ok(Pose {
            z_mm: h - radius,
            a_deg: -ny.asin().to_degrees(),
            b_deg: nx.atan2(nz).to_degrees(),
            stage_y_mm: None,
        })
    }
    /// `fields` laid on the cap: each with its pose.
    pub fn lay(&self, fields: &[ScanField]) -> Result<Vec<ScanField>, OffCap> {
        fields
            .iter()
            .map(|f| {
                Ok(ScanField {
                    pose: self.pose(f.id, f.center)?,
                    ..f.clone()
                })
            })
            .collect()
    }
}

/// One ordering of the experiment.
#[derive(Debug, Clone, Serialize)]
pub struct CapOrder {
    /// How it was ordered (`as is`, `3-D distance`, `5-axis time`).
    pub method: &'static str,
    /// The placements (indices into the laid fields) in visiting order.
    #[serde(skip)]
    pub order: Vec<usize>,
    /// Time of the moves between placements on the profile, s.
    pub move_time_s: f64,
    /// 3-D distance between consecutive placement centres, mm.
    pub distance_3d_mm: f64,
    /// Gain over as is, % (positive: faster).
    pub gain_pct: f64,
}

/// Time of the moves through `fields` in `order` on `stage`, s.
pub fn move_time_s(fields: &[ScanField], order: &[usize], stage: &StageDynamics) -> f64 {
    order
        .windows(2)
        .map(|w| {
            let (a, b) = (&fields[w[0]], &fields[w[1]]);
            stage.pose_move_time_s(a.center, &a.pose, b.center, &b.pose)
        })
        .sum()
}

/// 3-D distance between consecutive placements of `order`, mm.
pub fn distance_3d_mm(fields: &[ScanField], order: &[usize]) -> f64 {
    order
        .windows(2)
        .map(|w| {
            let (a, b) = (&fields[w[0]], &fields[w[1]]);
            a.center.dist(b.center).hypot(a.pose.z_mm - b.pose.z_mm)
        })
        .sum()
}

/// Iterated-local-search kicks per placement for each searched order: on texture-3043 on the cap
/// (R 200 mm) 16 kicks per placement give the same 5-axis time to 0.1 s (420.6 s) in 4× the time.
const KICKS_PER_PLACEMENT: usize = 4;

/// The three orders of seed 002's experiment on placements `fields` (with their poses) for
/// `profile`: as is (the fields' own order), by 3-D distance (from as is), by 5-axis time (from
/// the 3-D distance order, keeping only what is faster: never slower than it). Deterministic
/// for a seed.
pub fn order_three_ways(
    fields: &[ScanField],
    profile: &MachineProfile,
    seed: u64,
    ctx: &JobCtx,
) -> Result<Vec<CapOrder>, Cancelled> {
    let stage = StageDynamics::of(profile);
    let n = fields.len();
    let centres: Vec<Pt> = fields.iter().map(|f| f.center).collect();
    let poses = PoseMap::new(fields.iter().map(|f| (f.center, f.pose)));
    let as_is: Vec<usize> = (0..n).collect();
    let search = |metric: TravelCost, from: &[usize], seed: u64| -> Result<Vec<usize>, Cancelled> {
        if n < 3 {
            return Ok(from.to_vec());
        }
        let mut prob = PathProblem::points(&centres, &vec![0.0; n], 0.0);
        prob.metric = metric;
        let mut tour = Tour {
            order: from.to_vec(),
            flipped: vec![false; n],
        };
        LocalSearch::new(&prob, LsOptions::default(), ctx)?.iterated(
            &mut tour,
            KICKS_PER_PLACEMENT * n,
            seed,
            ctx,
        )?;
        Ok(tour.order)
    };
    let say = |done: u64, what: &str| {
        ctx.progress("order", done, 2, format!("{n} placements: {what}"));
    };
    say(0, "ordering by 3-D distance");
    let by_distance = search(TravelCost::Distance3d(poses.clone()), &as_is, seed)?;
    say(1, "ordering by 5-axis time");
    let by_time = search(
        TravelCost::PoseTime(stage.clone(), poses),
        &by_distance,
        seed,
    )?;
    say(2, "ordered three ways");
    let base_s = move_time_s(fields, &as_is, &stage);
    let row = |method, order: Vec<usize>| {
        let t = move_time_s(fields, &order, &stage);
        CapOrder {
            method,
            distance_3d_mm: distance_3d_mm(fields, &order),
            move_time_s: t,
            gain_pct: if base_s > 0.0 {
                100.0 * (1.0 - t / base_s)
            } else {
                0.0
            },
            order,
        }
    };
    Ok(vec![
        row("as is", as_is),
        row("3-D distance", by_distance),
        row("5-axis time", by_time),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_head_stands_along_the_normal() {
        let cap = Cap {
            radius_mm: 200.0,
            centre: Pt::new(150.0, 150.0),
        };
        assert_eq!(cap.pose(0, Pt::new(150.0, 150.0)).unwrap(), Pose::default());
        let p = cap.pose(1, Pt::new(250.0, 80.0)).unwrap();
        // R_y(B)·R_x(A)·ẑ is the normal
        let (a, b) = (p.a_deg.to_radians(), p.b_deg.to_radians());
        let d = [a.cos() * b.sin(), -a.sin(), a.cos() * b.cos()];
        let h = (200.0_f64.powi(2) - 100.0_f64.powi(2) - 70.0_f64.powi(2)).sqrt();
        let n = [100.0 / 200.0, -70.0 / 200.0, h / 200.0];
        for k in 0..3 {
            assert!((d[k] - n[k]).abs() < 1e-12, "{d:?} {n:?}");
        }
        assert!((p.z_mm - (h - 200.0)).abs() < 1e-12);
        let e = cap.pose(7, Pt::new(400.0, 150.0)).unwrap_err().to_string();
        assert!(
            e.contains("field 7") && e.contains("beyond its radius 200.0 mm"),
            "{e}"
        );
    }

    #[test]
    fn time_order_is_never_slower_than_distance_order() {
        let cap = Cap {
            radius_mm: 200.0,
            centre: Pt::new(150.0, 150.0),
        };
        // a raster of 12 × 12 placements over the cap
        let fields: Vec<ScanField> = (0..144)
            .map(|k| ScanField {
                id: k,
                center: Pt::new(40.0 + 20.0 * (k % 12) as f64, 40.0 + 20.0 * (k / 12) as f64),
                size: [20.0, 20.0],
                locked: false,
                geometries: vec![],
                pose: Pose::default(),
            })
            .collect();
        let laid = cap.lay(&fields).unwrap();
        let p = MachineProfile::builtin("five-axis").unwrap();
        let rows = order_three_ways(&laid, &p, 1, &JobCtx::default()).unwrap();
        let t: Vec<f64> = rows.iter().map(|r| r.move_time_s).collect();
        assert!(t[2] <= t[1] && t[1] <= t[0], "{t:?}");
        for r in &rows {
            let mut o = r.order.clone();
            o.sort_unstable();
            assert_eq!(o, (0..144).collect::<Vec<_>>());
        }
    }
}
