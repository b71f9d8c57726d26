//! A machine's axes beyond the X/Y stage: a Z axis and rotary axes A (about X) and B (about
//! Y), each with its own dynamics and travel, and the pose a placement (a scan field) gives
//! them (seed 002's 5-axis machine, docs/REFERENCES.md).
//!
//! Rotary axes are in degrees everywhere an operator sees them (profile files, G-code, reports,
//! the editor): speeds in deg/s, accelerations in deg/s². The time law treats every axis alike
//! (one trapezoid per axis in its own unit, the slowest axis sets the move's time).

use super::profile::AxisLimits;
use super::validate::InvalidValue;
use super::MachineProfile;
use crate::geom::Pt;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Where the extra axes stand for a placement: the Z height and the rotary angles. A flat job's
/// placements are all at the rest pose (zero), which no output writes.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Pose {
    /// Z, mm.
    pub z_mm: f64,
    /// A (rotation about X), degrees.
    pub a_deg: f64,
    /// B (rotation about Y), degrees.
    pub b_deg: f64,
    /// Where the stage's Y stands for this placement when not at its centre, mm: a cylinder's
    /// strip, whose centre lies on the unrolled surface while the stage stays over the
    /// cylinder's axis ([`super::Cylinder`]). None: at the centre.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stage_y_mm: Option<f64>,
}

impl Pose {
    /// The rest pose: nothing beyond X/Y.
    pub fn is_rest(&self) -> bool {
        *self == Pose::default()
    }
    /// Where the stage stands for a placement centred at `centre` in this pose.
    pub fn stage_point(&self, centre: Pt) -> Pt {
        match self.stage_y_mm {
            Some(y) => Pt::new(centre.x, y),
            None => centre,
        }
    }
    /// How far each of Z, A and B moves from this pose to `to` (mm, deg, deg).
    pub fn turn_to(&self, to: &Pose) -> [f64; 3] {
        let (p, q) = (self.values(), to.values());
        [q[0] - p[0], q[1] - p[1], q[2] - p[2]]
    }
    /// The values by axis, in [`ExtraAxisId::ALL`]'s order.
    pub fn values(&self) -> [f64; 3] {
        [self.z_mm, self.a_deg, self.b_deg]
    }
}

/// One of the axes beyond X/Y.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExtraAxisId {
    /// The linear Z axis.
    Z,
    /// Rotary A, about X.
    A,
    /// Rotary B, about Y.
    B,
}

impl ExtraAxisId {
    /// Z, A and B, in that order (a [`Pose`]'s values, a G-code line's words).
    pub const ALL: [ExtraAxisId; 3] = [ExtraAxisId::Z, ExtraAxisId::A, ExtraAxisId::B];
    /// Its G-code word and name (`Z`, `A`, `B`).
    pub fn word(self) -> &'static str {
        match self {
            ExtraAxisId::Z => "Z",
            ExtraAxisId::A => "A",
            ExtraAxisId::B => "B",
        }
    }
    /// Its unit of position (`mm`, `deg`).
    pub fn unit(self) -> &'static str {
        match self {
            ExtraAxisId::Z => "mm",
            ExtraAxisId::A | ExtraAxisId::B => "deg",
        }
    }
    /// The position index in [`Pose::values`].
    pub fn index(self) -> usize {
        self as usize
    }
}

/// An axis beyond X/Y: its dynamics (seed 002's law: nominal feed and acceleration time, or a
/// velocity and acceleration) and its travel. Z is in mm, A and B in degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtraAxis {
    /// Maximum velocity, mm/s or deg/s.
    pub max_velocity: f64,
    /// Maximum acceleration, mm/s² or deg/s².
    pub max_accel: f64,
    /// Settling time after each move of this axis, s.
    pub settle_s: f64,
    /// Travel `[min, max]`, mm or deg; none: endless (a rotary that turns freely).
    pub travel: Option<[f64; 2]>,
}

impl ExtraAxis {
    /// Its dynamics as the time law reads them (units are the axis's own).
    pub fn limits(&self) -> AxisLimits {
        AxisLimits {
            max_velocity_mm_s: self.max_velocity,
            max_accel_mm_s2: self.max_accel,
            settle_s: self.settle_s,
        }
    }
}

/// A Z table as written in a profile file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct LinearAxisFile {
    max_velocity_mm_s: f64,
    max_accel_mm_s2: Option<f64>,
    ramp_s: Option<f64>,
    #[serde(default)]
    settle_s: f64,
    travel_mm: Option<[f64; 2]>,
}

/// A rotary table as written in a profile file, in degrees.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct RotaryAxisFile {
    max_velocity_deg_s: f64,
    max_accel_deg_s2: Option<f64>,
    ramp_s: Option<f64>,
    #[serde(default)]
    settle_s: f64,
    travel_deg: Option<[f64; 2]>,
}

/// Why an axis table cannot be read (serde adds the table's place).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AxisFileError {
    /// Both ways of giving the acceleration.
    #[error("give the acceleration or ramp_s, not both")]
    AccelAndRamp,
    /// Neither.
    #[error("give the acceleration or ramp_s (seed 002's acceleration time)")]
    NoAccel,
    /// A ramp time that is not a positive number.
    #[error("ramp_s = {0} must be a positive number")]
    Ramp(f64),
}

fn read_axis(
    max_velocity: f64,
    max_accel: Option<f64>,
    ramp_s: Option<f64>,
) -> Result<f64, AxisFileError> {
    match (max_accel, ramp_s) {
        (Some(_), Some(_)) => Err(AxisFileError::AccelAndRamp),
        (Some(a), None) => Ok(a),
        (None, Some(r)) if r.is_finite() && r > 0.0 => Ok(max_velocity / r),
        (None, Some(r)) => Err(AxisFileError::Ramp(r)),
        (None, None) => Err(AxisFileError::NoAccel),
    }
}

/// A linear Z axis as a profile's `[axis_z]` table: `max_velocity_mm_s`, `max_accel_mm_s2` or
/// `ramp_s`, `settle_s`, `travel_mm = [min, max]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "LinearAxisFile", into = "LinearAxisOut")]
pub struct LinearAxis(pub ExtraAxis);

/// A rotary axis as a profile's `[axis_a]` or `[axis_b]` table, in degrees:
/// `max_velocity_deg_s`, `max_accel_deg_s2` or `ramp_s`, `settle_s`, `travel_deg = [min, max]`
/// (absent: endless).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RotaryAxisFile", into = "RotaryAxisOut")]
pub struct RotaryAxis(pub ExtraAxis);

impl TryFrom<LinearAxisFile> for LinearAxis {
    type Error = AxisFileError;
    fn try_from(f: LinearAxisFile) -> Result<Self, AxisFileError> {
        Ok(LinearAxis(ExtraAxis {
            max_velocity: f.max_velocity_mm_s,
            max_accel: read_axis(f.max_velocity_mm_s, f.max_accel_mm_s2, f.ramp_s)?,
            settle_s: f.settle_s,
            travel: f.travel_mm,
        }))
    }
}

impl TryFrom<RotaryAxisFile> for RotaryAxis {
    type Error = AxisFileError;
    fn try_from(f: RotaryAxisFile) -> Result<Self, AxisFileError> {
        Ok(RotaryAxis(ExtraAxis {
            max_velocity: f.max_velocity_deg_s,
            max_accel: read_axis(f.max_velocity_deg_s, f.max_accel_deg_s2, f.ramp_s)?,
            settle_s: f.settle_s,
            travel: f.travel_deg,
        }))
    }
}

/// A Z table as written.
#[derive(Serialize)]
struct LinearAxisOut {
    max_velocity_mm_s: f64,
    max_accel_mm_s2: f64,
    settle_s: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    travel_mm: Option<[f64; 2]>,
}

/// A rotary table as written.
#[derive(Serialize)]
struct RotaryAxisOut {
    max_velocity_deg_s: f64,
    max_accel_deg_s2: f64,
    settle_s: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    travel_deg: Option<[f64; 2]>,
}

impl From<LinearAxis> for LinearAxisOut {
    fn from(a: LinearAxis) -> Self {
        let a = a.0;
        Self {
            max_velocity_mm_s: a.max_velocity,
            max_accel_mm_s2: a.max_accel,
            settle_s: a.settle_s,
            travel_mm: a.travel,
        }
    }
}

impl From<RotaryAxis> for RotaryAxisOut {
    fn from(a: RotaryAxis) -> Self {
        let a = a.0;
        Self {
            max_velocity_deg_s: a.max_velocity,
            max_accel_deg_s2: a.max_accel,
            settle_s: a.settle_s,
            travel_deg: a.travel,
        }
    }
}

/// A placement the machine cannot take.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PoseError {
    /// The job turns or lifts an axis the profile does not have.
    #[error("field {field} needs axis {axis} ({} {unit}), which the machine '{profile}' does not have (its axes: {axes})", short(*.value))]
    MissingAxis {
        /// Field id.
        field: usize,
        /// The axis word.
        axis: &'static str,
        /// Its position in the pose.
        value: f64,
        /// Its unit.
        unit: &'static str,
        /// The profile's name.
        profile: String,
        /// The axes the profile has (`X, Y, Z, A, B`).
        axes: String,
    },
    /// A pose outside an axis's travel.
    #[error("field {field}: {axis} {} {unit} is outside axis {axis}'s travel {} to {} {unit}", short(*.value), short(*.min), short(*.max))]
    OutOfTravel {
        /// Field id.
        field: usize,
        /// The axis word.
        axis: &'static str,
        /// Its position in the pose.
        value: f64,
        /// Its unit.
        unit: &'static str,
        /// The travel's ends.
        min: f64,
        /// The travel's ends.
        max: f64,
    },
}

impl MachineProfile {
    /// The profile's axis beyond X/Y, if it has it.
    pub fn extra_axis(&self, id: ExtraAxisId) -> Option<&ExtraAxis> {
        match id {
            ExtraAxisId::Z => self.axis_z.as_ref().map(|a| &a.0),
            ExtraAxisId::A => self.axis_a.as_ref().map(|a| &a.0),
            ExtraAxisId::B => self.axis_b.as_ref().map(|a| &a.0),
        }
    }
    /// The axes beyond X/Y the profile has, in Z, A, B order.
    pub fn extra_axes(&self) -> Vec<ExtraAxisId> {
        ExtraAxisId::ALL
            .into_iter()
            .filter(|&id| self.extra_axis(id).is_some())
            .collect()
    }
    /// The machine moves its stage in Y: a rotary machine whose Y stroke is zero has no Y axis
    /// (the A axis turns the part instead), and its programs carry no Y word.
    pub fn has_y(&self) -> bool {
        !(self.stroke_mm[1] == 0.0 && self.axis_a.is_some())
    }
    /// The machine's axes in words: `X, Y, Z, A, B`.
    pub fn axes_words(&self) -> String {
        let mut words = vec!["X"];
        if self.has_y() {
            words.push("Y");
        }
        words.extend(self.extra_axes().into_iter().map(ExtraAxisId::word));
        words.join(", ")
    }
    /// Checks that the machine can take placement `field`'s pose: every axis it moves exists,
    /// and stands within its travel.
    pub fn check_pose(&self, field: usize, pose: &Pose) -> Result<(), PoseError> {
        for id in ExtraAxisId::ALL {
            let value = pose.values()[id.index()];
            match self.extra_axis(id) {
                None if value != 0.0 => {
                    return Err(PoseError::MissingAxis {
                        field,
                        axis: id.word(),
                        value,
                        unit: id.unit(),
                        profile: self.name.clone(),
                        axes: self.axes_words(),
                    })
                }
                Some(ExtraAxis {
                    travel: Some([min, max]),
                    ..
                }) if !(*min - TRAVEL_EPS..=*max + TRAVEL_EPS).contains(&value) => {
                    return Err(PoseError::OutOfTravel {
                        field,
                        axis: id.word(),
                        value,
                        unit: id.unit(),
                        min: *min,
                        max: *max,
                    })
                }
                _ => {}
            }
        }
        Ok(())
    }
    /// Checks the travels of the axes beyond X/Y: each a range from its minimum to a larger
    /// maximum.
    pub(super) fn validate_extra_axes(&self) -> Result<(), InvalidValue> {
        for id in self.extra_axes() {
            let Some(ExtraAxis {
                travel: Some([min, max]),
                ..
            }) = self.extra_axis(id)
            else {
                continue;
            };
            if !(min.is_finite() && max.is_finite() && min < max) {
                let key = if id == ExtraAxisId::Z {
                    "axis_z.travel_mm".to_string()
                } else {
                    format!("axis_{}.travel_deg", id.word().to_lowercase())
                };
                return Err(InvalidValue::new(
                    format!("Axis {} travel ({})", id.word(), id.unit()),
                    key,
                    format!("{min} to {max}"),
                    "a range from a minimum to a larger maximum",
                ));
            }
        }
        Ok(())
    }
}

/// A position in words: three decimals at most, no trailing zeros.
fn short(v: f64) -> String {
    crate::geom::format_mm(v, 3)
}

/// A pose this close outside an axis's travel is within it (decimals written to files), mm or
/// deg.
const TRAVEL_EPS: f64 = 1e-9;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotary_tables_read_in_degrees_with_ramp_or_accel() {
        let p = MachineProfile::from_toml(
            "[axis_a]\nmax_velocity_deg_s = 120.0\nramp_s = 0.2\n[axis_b]\nmax_velocity_deg_s = 50.0\nmax_accel_deg_s2 = 300.0\ntravel_deg = [-90.0, 90.0]\n",
            "p.toml",
        )
        .unwrap();
        let a = p.extra_axis(ExtraAxisId::A).unwrap();
        assert!((a.max_accel - 600.0).abs() < 1e-12 && a.travel.is_none());
        assert_eq!(
            p.extra_axis(ExtraAxisId::B).unwrap().travel,
            Some([-90.0, 90.0])
        );
        assert_eq!(p.axes_words(), "X, Y, A, B");
        // written back in degrees, read back the same
        let text = p.to_toml().unwrap();
        assert!(
            text.contains("max_velocity_deg_s") && text.contains("travel_deg"),
            "{text}"
        );
        assert_eq!(MachineProfile::from_toml(&text, "q").unwrap(), p);
    }

    #[test]
    fn poses_need_their_axes_within_travel() {
        let mut p = MachineProfile::builtin("five-axis").unwrap();
        assert!(p
            .check_pose(
                0,
                &Pose {
                    z_mm: -10.0,
                    a_deg: 20.0,
                    b_deg: -30.0,
                    stage_y_mm: None,
                }
            )
            .is_ok());
        let e = p
            .check_pose(
                4,
                &Pose {
                    b_deg: 170.0,
                    ..Pose::default()
                },
            )
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("field 4: B 170 deg is outside axis B's travel"),
            "{e}"
        );
        p.axis_b = None;
        let e = p
            .check_pose(
                4,
                &Pose {
                    b_deg: 10.0,
                    ..Pose::default()
                },
            )
            .unwrap_err();
        assert!(
            e.to_string().contains("needs axis B") && e.to_string().contains("X, Y, Z, A)"),
            "{e}"
        );
    }

    #[test]
    fn a_rotary_with_zero_speed_is_refused_in_one_line() {
        let e = MachineProfile::from_toml(
            "[axis_a]\nmax_velocity_deg_s = 0.0\nmax_accel_deg_s2 = 100.0\n",
            "p.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("Axis A max velocity (deg/s)") && e.contains("not 0"),
            "{e}"
        );
        assert!(!e.contains('\n'));
    }
}
