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

// Work in progress (branch `cylinder`, issue 51), the way planned for the pipeline:
//
// * `Document.cylinder: Option<Cylinder>` (a job input, like the tray; in `PlanInputs` and the
//   plan, so that a change makes plans stale and the lowering knows it); `--cylinder D` in the
//   CLI, a Cylinder section in the GUI.
// * Placement on the unrolled plane: a placement profile with `field_mm = [field_w, strip
//   height]` and `stroke_mm = [stroke_x, drawing height]`; oversize strokes cut at the strips'
//   borders (seams, as `--split-oversize`). Each field gets `pose.a_deg = angle_deg(centre y)`
//   (beyond 360° where the drawing crosses the wrap line: no gap, no double mark).
// * Stage position of a strip: `(centre x, stage Y over the cylinder's axis)`, not the unrolled
//   centre: one mapping (`ScanField` → stage position) used by the lowering, `StepTime`, the
//   time-order field path and the lower bound, so that no Y move is timed for a strip change.
// * Lowering: the marking path pre-distorted by its field's angle (`predistort`, the chord
//   tolerance of the import); each scanner edge timed at the pen's speed on the *surface*
//   (its unrolled length / speed): per-edge Mark parts (`start_frac`, `end_frac`), as on the
//   fly; G-code `F` per `G1` from the same ratio.
// * Distance on a cylinder: chord between strip centres on the surface,
//   `√(dx² + (2R·sin(Δθ/2))²)`.
// * Outputs: report `cylinder {diameter, dof, strip height}`, each field's `a_deg`; the
//   trajectory's `a_deg` column (exists); LinuxCNC: XAUV (exists), a cylinder job in
//   check-linuxcnc.sh.
// * Acceptance test: map every program move back (sampled along moves): axial = X + U,
//   arc = R·(A·π/180 + asin(V/R)); within 0.02 mm of the flattened artwork, covered once.

use super::MachineProfile;
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
    #[error("the drawing is {height:.2} mm high around the cylinder, more than its circumference {circumference:.2} mm (⌀{diameter} mm)")]
    TooTall {
        /// The drawing's height (its y extent), mm.
        height: f64,
        /// π·D, mm.
        circumference: f64,
        /// D, mm.
        diameter: f64,
    },
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
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    /// Diameter, mm.
    pub diameter_mm: f64,
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
    /// strip at axial `centre_x`, stage Y `stage_y`, part at `a_deg`: each point at
    /// `(x, stage_y + V)`, edges subdivided until the straight scanner moves land within
    /// `tol_mm` of the unrolled edge on the surface.
    pub fn predistort(&self, path: &[Pt], a_deg: f64, stage_y: f64, tol_mm: f64) -> Vec<Pt> {
        let at = |p: Pt| Pt::new(p.x, stage_y + self.scanner_v(p.y, a_deg));
        let mut out = Vec::with_capacity(path.len());
        if let Some(&first) = path.first() {
            out.push(at(first));
        }
        for w in path.windows(2) {
            self.refine(w[0], w[1], a_deg, tol_mm, MAX_DEPTH, &at, &mut out);
        }
        out
    }

    /// Appends the pre-distorted points after `a` up to `b` (an unrolled edge), bisecting
    /// while the scanner's straight move from `a` to `b` lands further than `tol_mm` from the
    /// edge at a quarter, half or three quarters.
    #[allow(clippy::too_many_arguments)]
    fn refine(
        &self,
        a: Pt,
        b: Pt,
        a_deg: f64,
        tol_mm: f64,
        depth: u32,
        at: &dyn Fn(Pt) -> Pt,
        out: &mut Vec<Pt>,
    ) {
        if depth > 0 && self.landing_error_mm(a, b, a_deg) > tol_mm {
            let m = Pt::new((a.x + b.x) / 2.0, (a.y + b.y) / 2.0);
            self.refine(a, m, a_deg, tol_mm, depth - 1, at, out);
            self.refine(m, b, a_deg, tol_mm, depth - 1, at, out);
        } else {
            out.push(at(b));
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
            e.contains("130.00 mm high") && e.contains("circumference 125.66 mm"),
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
        let out = c.predistort(&path, a_deg, 0.0, tol);
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
