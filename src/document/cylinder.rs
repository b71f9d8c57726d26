//! A cylinder job (marking around a part on the rotary A axis): the artwork is the *unrolled*
//! surface, x along the cylinder's axis, y around it in mm of arc. The part turns to a strip's
//! angle and the scanner marks the strip from above, where the surface stays within the depth
//! of focus.
//!
//! Geometry (R the radius, the cylinder's axis along X under the head, the focus on its top):
//!
//! * a surface point at arc `y`, with the part turned to `A` degrees, lies at the angle
//!   `φ = y/R − A·π/180` from the top; the scanner sees it at `V = R·sin φ`, at the depth
//!   `R·(1 − cos φ)` below the focus;
//! * it is in focus while `R·(1 − cos φ) ≤ DOF`, i.e. `|φ| ≤ acos(1 − DOF/R)`: a strip in focus is
//!   `2·R·acos(1 − DOF/R)` of arc high (when `DOF ≥ 2R` the whole upper half: `π·R`), capped by
//!   the field;
//! * back from the scanner: `arc = R·(A·π/180 + asin(V/R))`, `axial = X + U`.
//!
//! A straight edge of the unrolled artwork is a curve in the scanner's plane; [`Cylinder::
//! predistort`] subdivides it until the scanner's straight moves land within a chord tolerance
//! of it on the surface.

use super::{MachineProfile, Pose};
use crate::geom::Pt;
use thiserror::Error;

/// A cylinder job the machine or the drawing cannot make.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CylinderError {
    /// Not a diameter.
    #[error("the cylinder's diameter must be a positive number of mm, not {0}")]
    Diameter(f64),
    /// The machine has no rotary A axis.
    #[error("a cylinder job needs an A axis: the machine '{profile}' has {axes}")]
    NoRotary {
        /// The machine's name.
        profile: String,
        /// Its axes in words.
        axes: String,
    },
    /// The profile does not say its depth of focus.
    #[error("a cylinder job needs the scanner's depth of focus ([scanner] depth_of_focus_mm) in the machine '{0}'")]
    NoDepthOfFocus(String),
    /// A drawing taller than the circumference.
    #[error("the drawing spans {height:.2} mm around the cylinder, more than its circumference {circumference:.2} mm (⌀{diameter} mm): it would overlap itself")]
    TooTall {
        /// The drawing's height (its y extent), mm.
        height: f64,
        /// π·D, mm.
        circumference: f64,
        /// D, mm.
        diameter: f64,
    },
    /// On the fly around a cylinder (not made yet).
    #[error("a cylinder is marked step-and-scan, the rotary at rest while a strip is marked: plan it with step-and-scan (or automatic motion)")]
    OnTheFly,
    /// Strips thinner than the laser spot.
    #[error("on ⌀{diameter} mm the strips in focus would be {strip:.3} mm high, thinner than the {spot} mm spot: a larger depth of focus or diameter is needed")]
    ThinStrips {
        /// D, mm.
        diameter: f64,
        /// The strip's height, mm.
        strip: f64,
        /// The spot, mm.
        spot: f64,
    },
}

/// A cylinder on the rotary axis.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cylinder {
    /// Diameter, mm.
    pub diameter_mm: f64,
}

/// How far the scanner's straight moves may land from the unrolled edge they mark, on the
/// surface, mm: half the import's default chord tolerance (0.01 mm), so that flattening and
/// landing together stay within 0.015 mm of the drawing.
pub const LANDING_TOL_MM: f64 = 0.005;

/// A path on the unrolled surface made ready for the scanner ([`Cylinder::predistort`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Predistorted {
    /// The scanner's tool-centre points, mm.
    pub scanner: Vec<Pt>,
    /// The same points on the unrolled surface (the drawn path, refined), mm.
    pub surface: Vec<Pt>,
}

/// Deepest subdivision of one edge (2⁸ pieces): far beyond what a chord tolerance needs on any
/// cylinder a scan field can mark.
const MAX_DEPTH: u32 = 8;

impl Cylinder {
    /// Checks a cylinder job of a drawing `height_mm` high around the cylinder on `profile`;
    /// returns the strips' height in focus, mm.
    pub fn check(&self, profile: &MachineProfile, height_mm: f64) -> Result<f64, CylinderError> {
        let d = self.diameter_mm;
        if !(d.is_finite() && d > 0.0) {
            return Err(CylinderError::Diameter(d));
        }
        if profile.axis_a.is_none() {
            return Err(CylinderError::NoRotary {
                profile: profile.name.clone(),
                axes: profile.axes_words(),
            });
        }
        let dof = profile
            .scanner
            .depth_of_focus_mm
            .ok_or_else(|| CylinderError::NoDepthOfFocus(profile.name.clone()))?;
        let circumference = self.circumference_mm();
        if height_mm > circumference {
            return Err(CylinderError::TooTall {
                height: height_mm,
                circumference,
                diameter: d,
            });
        }
        let strip = self.strip_height_mm(dof, profile.field_mm[1]);
        if strip < profile.laser.spot_mm {
            return Err(CylinderError::ThinStrips {
                diameter: d,
                strip,
                spot: profile.laser.spot_mm,
            });
        }
        Ok(strip)
    }
    /// The profile the strips are placed with on the unrolled surface: the machine's, with
    /// fields `strip_mm` high (the strips in focus, [`Cylinder::check`]) and a Y stroke of twice
    /// the circumference, so that a drawing may cross the wrap line (y = π·D) without a cut.
    pub fn work_profile(&self, machine: &MachineProfile, strip_mm: f64) -> MachineProfile {
        let mut p = machine.clone();
        p.field_mm[1] = strip_mm;
        p.stroke_mm[1] = 2.0 * self.circumference_mm();
        p
    }
    /// The profile a job's artwork is placed in: on a cylinder (`cylinder`, with a depth of
    /// focus) the work profile of its strips ([`Cylinder::work_profile`]), else `machine`.
    pub fn reach_profile(
        machine: &MachineProfile,
        cylinder: Option<Cylinder>,
    ) -> std::borrow::Cow<'_, MachineProfile> {
        let work = cylinder.and_then(|c| {
            let dof = machine.scanner.depth_of_focus_mm?;
            Some(c.work_profile(machine, c.strip_height_mm(dof, machine.field_mm[1])))
        });
        match work {
            Some(p) => std::borrow::Cow::Owned(p),
            None => std::borrow::Cow::Borrowed(machine),
        }
    }
    /// The stage's Y while marking: over the cylinder's axis, which lies under the middle of
    /// the Y stroke (0 on a machine without Y).
    pub fn stage_y_mm(machine: &MachineProfile) -> f64 {
        machine.stroke_mm[1] / 2.0
    }
    /// Where the machine stands to mark the strip centred at arc `centre_y_mm`: the part turned
    /// to the strip's angle (beyond 360° across the wrap line: no gap, no double mark), the
    /// stage over the axis, and on a machine with Z the head raised by the radius so that the
    /// focus stays on the cylinder's top (Z 0 focuses at the axis's height).
    pub fn strip_pose(&self, machine: &MachineProfile, centre_y_mm: f64) -> Pose {
        Pose {
            z_mm: if machine.axis_z.is_some() {
                self.radius_mm()
            } else {
                0.0
            },
            a_deg: self.angle_deg(centre_y_mm),
            b_deg: 0.0,
            stage_y_mm: Some(Self::stage_y_mm(machine)),
        }
    }
    /// The surface length between two scanner points with the part at `a_deg` and the stage at
    /// Y `stage_y`, mm: the distance of their unrolled images (a pre-distorted edge is a piece
    /// of a straight unrolled edge).
    pub fn surface_length_mm(&self, p: Pt, q: Pt, a_deg: f64, stage_y: f64) -> f64 {
        self.unrolled(p, a_deg, stage_y)
            .dist(self.unrolled(q, a_deg, stage_y))
    }
    /// The unrolled surface point the scanner's tool-centre point `p` lands on, mm.
    pub fn unrolled(&self, p: Pt, a_deg: f64, stage_y: f64) -> Pt {
        Pt::new(p.x, self.arc_of(p.y - stage_y, a_deg))
    }
    /// The scanner's speed along the pre-distorted edge `p`–`q` that marks the surface at
    /// `surface_mm_s`, mm/s: slower by the edge's length against its surface length (by cos φ
    /// across the strip).
    pub fn scanner_speed_mm_s(
        &self,
        p: Pt,
        q: Pt,
        a_deg: f64,
        stage_y: f64,
        surface_mm_s: f64,
    ) -> f64 {
        let s = self.surface_length_mm(p, q, a_deg, stage_y);
        if s > 0.0 {
            surface_mm_s * p.dist(q) / s
        } else {
            surface_mm_s
        }
    }
    /// The 3-D distance between two points of the unrolled surface on the cylinder, mm: the
    /// chord `√(dx² + (2R·sin(Δθ/2))²)`, Δθ their angle apart (a turn apart is the same point).
    pub fn surface_distance_mm(&self, a: Pt, b: Pt) -> f64 {
        let r = self.radius_mm();
        let dy = 2.0 * r * ((b.y - a.y) / (2.0 * r)).sin().abs();
        (b.x - a.x).hypot(dy)
    }
    /// Radius, mm.
    pub fn radius_mm(&self) -> f64 {
        self.diameter_mm / 2.0
    }
    /// Circumference (the unrolled height), mm.
    pub fn circumference_mm(&self) -> f64 {
        std::f64::consts::PI * self.diameter_mm
    }
    /// The largest angle from the top still in focus, rad: `acos(1 − DOF/R)`.
    pub fn focus_half_angle(&self, dof_mm: f64) -> f64 {
        let r = self.radius_mm();
        (1.0 - dof_mm / r)
            .clamp(-1.0, 1.0)
            .acos()
            .min(std::f64::consts::FRAC_PI_2)
    }
    /// The arc height of a strip in focus, mm: `2·R·acos(1 − DOF/R)`, at most the upper half,
    /// capped by the scan field's height `field_mm` (whose ±half the scanner reaches: the arc
    /// of `V = ±field/2`).
    pub fn strip_height_mm(&self, dof_mm: f64, field_mm: f64) -> f64 {
        let r = self.radius_mm();
        let focus = self.focus_half_angle(dof_mm);
        let reach = (field_mm / 2.0 / r).clamp(-1.0, 1.0).asin();
        2.0 * r * focus.min(reach)
    }
    /// The angle the part turns to for a strip centred at arc `arc_mm`, degrees.
    pub fn angle_deg(&self, arc_mm: f64) -> f64 {
        (arc_mm / self.radius_mm()).to_degrees()
    }
    /// The angle from the top of the surface point at arc `arc_mm` with the part at `a_deg`,
    /// rad.
    pub fn phi(&self, arc_mm: f64, a_deg: f64) -> f64 {
        arc_mm / self.radius_mm() - a_deg.to_radians()
    }
    /// The scanner's V of the surface point at arc `arc_mm` with the part at `a_deg`, mm.
    pub fn scanner_v(&self, arc_mm: f64, a_deg: f64) -> f64 {
        self.radius_mm() * self.phi(arc_mm, a_deg).sin()
    }
    /// The arc where the scanner's V lands with the part at `a_deg`, mm.
    pub fn arc_of(&self, v_mm: f64, a_deg: f64) -> f64 {
        let r = self.radius_mm();
        r * (a_deg.to_radians() + (v_mm / r).clamp(-1.0, 1.0).asin())
    }
    /// How far below the focus the point at arc `arc_mm` lies with the part at `a_deg`, mm.
    pub fn defocus_mm(&self, arc_mm: f64, a_deg: f64) -> f64 {
        self.radius_mm() * (1.0 - self.phi(arc_mm, a_deg).cos())
    }
    /// The unrolled polyline `path` (axial x, arc y) as the scanner's tool-centre points for a
    /// strip with the part at `a_deg` and the stage at Y `stage_y`: each point at
    /// `(x, stage_y + V)`, edges bisected until the straight scanner moves land within
    /// `tol_mm` of the unrolled edge on the surface.
    pub fn predistort(&self, path: &[Pt], a_deg: f64, stage_y: f64, tol_mm: f64) -> Predistorted {
        let mut surface = Vec::with_capacity(path.len());
        if let Some(&first) = path.first() {
            surface.push(first);
        }
        for w in path.windows(2) {
            self.refine(w[0], w[1], a_deg, tol_mm, MAX_DEPTH, &mut surface);
        }
        let scanner = surface
            .iter()
            .map(|p| Pt::new(p.x, stage_y + self.scanner_v(p.y, a_deg)))
            .collect();
        Predistorted { scanner, surface }
    }

    /// Appends the refined unrolled points after `a` up to `b` (an unrolled edge), bisecting
    /// while the scanner's straight move from `a` to `b` lands further than `tol_mm` from the
    /// edge at a quarter, half or three quarters.
    fn refine(&self, a: Pt, b: Pt, a_deg: f64, tol_mm: f64, depth: u32, out: &mut Vec<Pt>) {
        if depth > 0 && self.landing_error_mm(a, b, a_deg) > tol_mm {
            let m = Pt::new((a.x + b.x) / 2.0, (a.y + b.y) / 2.0);
            self.refine(a, m, a_deg, tol_mm, depth - 1, out);
            self.refine(m, b, a_deg, tol_mm, depth - 1, out);
        } else {
            out.push(b);
        }
    }

    /// How far the scanner's straight move between the pre-distorted ends of the unrolled edge
    /// `a`–`b` lands from the edge on the surface (sampled at a quarter, half, three quarters;
    /// the error of a smooth map's chord peaks near the middle), mm.
    pub fn landing_error_mm(&self, a: Pt, b: Pt, a_deg: f64) -> f64 {
        let (va, vb) = (self.scanner_v(a.y, a_deg), self.scanner_v(b.y, a_deg));
        let edge = b.minus(a);
        let len = edge.norm();
        [0.25, 0.5, 0.75]
            .into_iter()
            .map(|t| {
                let landed = Pt::new(a.x + t * edge.x, self.arc_of(va + t * (vb - va), a_deg));
                // distance from the unrolled edge (its line; the landed point stays between
                // the ends' normals)
                if len == 0.0 {
                    landed.dist(a)
                } else {
                    let d = landed.minus(a);
                    (d.x * edge.y - d.y * edge.x).abs() / len
                }
            })
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_cylinder_jobs_are_one_line() {
        let mut rotary = MachineProfile::builtin("rotary").unwrap();
        rotary.scanner.depth_of_focus_mm = Some(0.8);
        let c = Cylinder { diameter_mm: 40.0 };
        assert!((c.check(&rotary, 100.0).unwrap() - 11.35).abs() < 0.01);
        let words = |e: CylinderError| e.to_string();
        let e = words(c.check(&rotary, 130.0).unwrap_err());
        assert!(
            e.contains("spans 130.00 mm around") && e.contains("circumference 125.66 mm"),
            "{e}"
        );
        let e = words(c.check(&MachineProfile::default(), 10.0).unwrap_err());
        assert!(e.contains("needs an A axis") && e.contains("X, Y"), "{e}");
        let e = words(
            Cylinder { diameter_mm: 0.0 }
                .check(&rotary, 1.0)
                .unwrap_err(),
        );
        assert!(e.contains("not 0"), "{e}");
        rotary.scanner.depth_of_focus_mm = Some(1e-7);
        let e = words(c.check(&rotary, 10.0).unwrap_err());
        assert!(e.contains("thinner than the 0.05 mm spot"), "{e}");
        rotary.scanner.depth_of_focus_mm = None;
        assert!(words(c.check(&rotary, 10.0).unwrap_err()).contains("depth_of_focus_mm"));
        // a DOF of zero is refused with the profile
        let e = MachineProfile::from_toml("[scanner]\ndepth_of_focus_mm = 0.0\n", "p.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("Depth of focus (mm) must be a positive number, not 0"),
            "{e}"
        );
        assert!(!e.contains('\n'));
    }

    #[test]
    fn strips_in_focus_follow_the_depth_of_focus_and_the_field() {
        let c = Cylinder { diameter_mm: 40.0 };
        // R 20 mm, DOF 0.8 mm: 2·20·acos(0.96) = 11.35 mm
        let h = c.strip_height_mm(0.8, 70.0);
        assert!((h - 2.0 * 20.0 * 0.96_f64.acos()).abs() < 1e-12, "{h}");
        assert!((h - 11.35).abs() < 0.01);
        // a small field caps it: the arc of V = ±2 mm
        assert!((c.strip_height_mm(0.8, 4.0) - 2.0 * 20.0 * 0.1_f64.asin()).abs() < 1e-12);
        // a deep focus: the upper half at most (the scanner reaches V = ±R)
        assert!((c.strip_height_mm(100.0, 100.0) - std::f64::consts::PI * 20.0).abs() < 1e-9);
    }

    #[test]
    fn a_point_goes_to_the_scanner_and_back() {
        let c = Cylinder { diameter_mm: 40.0 };
        for (arc, a) in [(3.0, 0.0), (31.4, 90.0), (-5.0, 10.0), (125.0, 360.0)] {
            let v = c.scanner_v(arc, a);
            assert!(v.abs() <= 20.0);
            let back = c.arc_of(v, a);
            if c.phi(arc, a).abs() < std::f64::consts::FRAC_PI_2 {
                assert!((back - arc).abs() < 1e-9, "{arc} {a}: {back}");
            }
        }
        assert!((c.defocus_mm(c.angle_deg(7.0).to_radians() * 20.0, 0.0)) >= 0.0);
    }

    #[test]
    fn predistorted_edges_land_within_the_tolerance() {
        let c = Cylinder { diameter_mm: 30.0 };
        let a_deg = c.angle_deg(20.0);
        // a diagonal across the strip, and an arc-wise line
        let path = [Pt::new(0.0, 15.0), Pt::new(8.0, 25.0), Pt::new(8.0, 16.0)];
        let tol = 0.005;
        let out = c.predistort(&path, a_deg, 0.0, tol).scanner;
        assert!(out.len() > path.len());
        // every scanner chord, sampled finely, lands within tol of the unrolled path
        for w in out.windows(2) {
            for k in 0..=20 {
                let t = f64::from(k) / 20.0;
                let (u, v) = (
                    w[0].x + t * (w[1].x - w[0].x),
                    w[0].y + t * (w[1].y - w[0].y),
                );
                let landed = Pt::new(u, c.arc_of(v, a_deg));
                let d = path
                    .windows(2)
                    .map(|e| crate::geom::point_segment_dist(landed, e[0], e[1]))
                    .fold(f64::INFINITY, f64::min);
                assert!(d <= tol * 1.5, "{landed:?} is {d} from the path");
            }
        }
    }
}
