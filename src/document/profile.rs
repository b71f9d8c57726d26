//! Machine profiles: stroke, scan field, dynamics, laser timing and G-code dialect (TOML).

use super::axes::{LinearAxis, RotaryAxis};
use super::validate::InvalidValue;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Current profile format version.
///
/// * 1: stroke, field, axis velocity and acceleration, scanner, laser, G-code words.
/// * 2: an axis may give `ramp_s` (seed 002 Table 2's t_a, rest to full speed) instead of
///   `max_accel_mm_s2`, and a `settle_s` after each move; `[gcode] mode` (`tcp` or
///   `stage-scanner`) and `scanner_axes`; `otf_margin_mm` for on-the-fly marking. Every
///   version-1 file is a valid version-2 file.
/// * 3: `[gcode] mode = "linuxcnc"` with `laser_output`, `power_output`, `path_tol_mm`; a
///   `[controller]` table (the controller's time law). Every version-2 file is a valid
///   version-3 file.
/// * 4: `[controller] clock_period_s`, a scan head's clock (plans made on it), and
///   `stream_period_s`, a LinuxCNC machine that streams on-the-fly plans. Every version-3 file
///   is a valid version-4 file.
/// * 5: axes beyond X/Y, `[axis_z]`, `[axis_a]`, `[axis_b]` (document/axes.rs), each with its
///   own dynamics and travel. Every version-4 file is a valid version-5 file.
pub const PROFILE_VERSION: u32 = 5;

/// Limits of one base-stage axis (seed 002, Table 2 style).
///
/// In a profile file the acceleration is given either as `max_accel_mm_s2` or as `ramp_s`, the
/// time from rest to full speed (seed 002 Table 2's t_a): `max_accel = max_velocity / ramp_s`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(try_from = "AxisLimitsFile")]
pub struct AxisLimits {
    /// Maximum velocity in mm/s.
    pub max_velocity_mm_s: f64,
    /// Maximum acceleration in mm/s².
    pub max_accel_mm_s2: f64,
    /// Settling time after each move of this axis, s.
    pub settle_s: f64,
}

impl Default for AxisLimits {
    fn default() -> Self {
        Self {
            max_velocity_mm_s: 500.0,
            max_accel_mm_s2: 5_000.0,
            settle_s: 0.0,
        }
    }
}

/// An axis table as written in a profile file: acceleration or ramp time.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct AxisLimitsFile {
    #[serde(default = "default_velocity_mm_s")]
    max_velocity_mm_s: f64,
    max_accel_mm_s2: Option<f64>,
    ramp_s: Option<f64>,
    #[serde(default)]
    settle_s: f64,
}

fn default_velocity_mm_s() -> f64 {
    AxisLimits::default().max_velocity_mm_s
}

/// Why an axis table of a profile file cannot be read (serde adds the table's place).
#[derive(Debug, Clone, PartialEq, Error)]
enum AxisLimitsError {
    /// Both ways of giving the acceleration.
    #[error("give max_accel_mm_s2 or ramp_s, not both")]
    AccelAndRamp,
    /// A ramp time that is not a positive number.
    #[error("ramp_s = {ramp_s} must be a positive number")]
    Ramp {
        /// The ramp time given, s.
        ramp_s: f64,
    },
}

impl TryFrom<AxisLimitsFile> for AxisLimits {
    type Error = AxisLimitsError;
    fn try_from(f: AxisLimitsFile) -> Result<Self, AxisLimitsError> {
        let max_accel_mm_s2 = match (f.max_accel_mm_s2, f.ramp_s) {
            (Some(_), Some(_)) => return Err(AxisLimitsError::AccelAndRamp),
            (Some(a), None) => a,
            (None, Some(ramp_s)) => {
                if !(ramp_s.is_finite() && ramp_s > 0.0) {
                    return Err(AxisLimitsError::Ramp { ramp_s });
                }
                f.max_velocity_mm_s / ramp_s
            }
            (None, None) => AxisLimits::default().max_accel_mm_s2,
        };
        Ok(AxisLimits {
            max_velocity_mm_s: f.max_velocity_mm_s,
            max_accel_mm_s2,
            settle_s: f.settle_s,
        })
    }
}

/// Scanner speeds.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct ScannerSpeeds {
    /// Jump (laser off) speed in mm/s.
    pub jump_speed_mm_s: f64,
    /// Mark (laser on) speed in mm/s.
    pub mark_speed_mm_s: f64,
    /// How far the surface may lie below the focus and still mark as in focus, mm: the height
    /// of a strip around a cylinder follows from it (document/cylinder.rs). None: not known
    /// (cylinder jobs need it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_of_focus_mm: Option<f64>,
}

impl Default for ScannerSpeeds {
    fn default() -> Self {
        Self {
            jump_speed_mm_s: 5_000.0,
            mark_speed_mm_s: 1_000.0,
            depth_of_focus_mm: None,
        }
    }
}

/// Laser timing.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct LaserTiming {
    /// Delay after switching on, in s.
    pub on_delay_s: f64,
    /// Delay after switching off, in s.
    pub off_delay_s: f64,
    /// Settling delay after a scanner jump, in s.
    pub jump_delay_s: f64,
    /// The laser spot's diameter on the work, mm: codes without a pen of their own are filled
    /// at this spacing, inset by half of it.
    #[serde(default = "default_spot_mm")]
    pub spot_mm: f64,
    /// How long the laser fires at a dot (a mark of one spot: a dotted code's module), s;
    /// pens may set their own.
    #[serde(default = "default_dot_dwell_s")]
    pub dot_dwell_s: f64,
}

/// A dot of a dotted code: half a millisecond, a typical point time of a fibre laser.
fn default_dot_dwell_s() -> f64 {
    0.5e-3
}

/// A galvo's typical focused spot, mm.
fn default_spot_mm() -> f64 {
    0.05
}

impl Default for LaserTiming {
    fn default() -> Self {
        Self {
            on_delay_s: 100e-6,
            off_delay_s: 100e-6,
            jump_delay_s: 200e-6,
            spot_mm: default_spot_mm(),
            dot_dwell_s: default_dot_dwell_s(),
        }
    }
}

/// What the G-code drives.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "kebab-case")]
pub enum GcodeMode {
    /// The tool-centre-point path on X/Y (the controller splits stage and scanner itself).
    #[default]
    Tcp,
    /// The stage on X/Y once per field; scanner jumps and marks in field-local coordinates on
    /// the two [`GcodeDialect::scanner_axes`] words.
    StageScanner,
    /// LinuxCNC (docs/GCODE.md, *LinuxCNC*): stage X/Y and scanner axes as coordinated axes of
    /// one machine, the laser gated by a digital output (`M62`/`M63 P..`), delays as dwells;
    /// on the fly the whole job as timed X/Y/U/V segments in inverse time (`G93`).
    Linuxcnc,
}

/// G-code dialect options. The defaults produce the contract in docs/DESIGN.md.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct GcodeDialect {
    /// Word that switches the laser on (`M3` or `M4`).
    pub laser_on: String,
    /// Word that switches the laser off.
    pub laser_off: String,
    /// Laser power written after the on word with the power word (`M3 S80`); none when
    /// absent. A layer's pen may set its own.
    pub power: Option<f64>,
    /// The word that carries the power (`S`).
    pub power_word: String,
    /// Marking feed in mm/min written on `G1`.
    pub feed_mm_min: f64,
    /// Decimal places for coordinates.
    pub decimals: usize,
    /// Mirror Y about the page height (for y-up machines).
    pub flip_y: bool,
    /// Tool-centre path or stage + scanner axes.
    pub mode: GcodeMode,
    /// Axis words of the scanner in `stage-scanner` and `linuxcnc` mode (x, y).
    pub scanner_axes: [String; 2],
    /// LinuxCNC: the digital output that gates the laser (`M62`/`M63 P<n>`).
    pub laser_output: u32,
    /// LinuxCNC: the analog output that carries the power (`M67 E<n> Q<power>`, synchronised
    /// with the next move); none: the power word, as in the other dialects.
    pub power_output: Option<u32>,
    /// LinuxCNC: how far the controller's path may leave the toolpath, mm: the blending
    /// tolerance (`G64 P..`) and, on the fly, the tolerance within which samples are merged
    /// into one segment.
    pub path_tol_mm: f64,
}

impl Default for GcodeDialect {
    fn default() -> Self {
        Self {
            laser_on: "M3".into(),
            laser_off: "M5".into(),
            power: None,
            power_word: "S".into(),
            feed_mm_min: 60_000.0,
            decimals: 4,
            flip_y: false,
            mode: GcodeMode::Tcp,
            scanner_axes: ["U".into(), "V".into()],
            laser_output: 0,
            power_output: None,
            path_tol_mm: 0.005,
        }
    }
}

/// Which controller runs the job, and so how galvoplan times it.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ControllerKind {
    /// A scan-head controller (seed 002's model): the scanner marks at constant speed through
    /// corners, jumps at jump speed, delays as given.
    #[default]
    Ideal,
    /// LinuxCNC's trajectory planner (motion/controller.rs): every move accelerates and
    /// brakes at the axes' limits, blends corners within the path tolerance, and takes whole
    /// servo periods.
    Linuxcnc,
}

/// The controller and its time law.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct Controller {
    /// Which controller.
    pub kind: ControllerKind,
    /// Servo period (the controller's clock), s.
    pub servo_period_s: f64,
    /// Scanner axes' acceleration as the controller drives them, mm/s².
    pub scanner_accel_mm_s2: f64,
    /// A scan-head controller's clock period, s: when given, every plan is made on it (each
    /// mark starts and ends on a tick), and a trajectory is sampled on it. None: the plan is
    /// continuous. A LinuxCNC controller's clock is its servo period.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clock_period_s: Option<f64>,
    /// A LinuxCNC controller that streams on-the-fly plans: the period of the thread that takes
    /// one sample of X, Y, U, V and the laser from a realtime FIFO (LinuxCNC's `streamer` in
    /// motmod's base thread; docs/GCODE.md, *Streamed on the fly*), s. On-the-fly plans are made
    /// on it. None: on the fly is an inverse-time (`G93`) program, run at LinuxCNC's pace.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stream_period_s: Option<f64>,
}

impl Controller {
    /// The controller's clock period for a plan in `motion`, s, if it has one: the stream's
    /// period for a streamed on-the-fly plan, else LinuxCNC's servo period, or the scan head's
    /// clock when the profile gives one.
    pub fn clock_s(&self, motion: super::Motion) -> Option<f64> {
        match self.kind {
            ControllerKind::Linuxcnc => Some(
                self.streamed(motion)
                    .then_some(self.stream_period_s)
                    .flatten()
                    .unwrap_or(self.servo_period_s),
            ),
            ControllerKind::Ideal => self.clock_period_s,
        }
    }

    /// A plan in `motion` is streamed to a LinuxCNC machine's joints, not run as G-code.
    pub fn streamed(&self, motion: super::Motion) -> bool {
        self.kind == ControllerKind::Linuxcnc
            && motion == super::Motion::OnTheFly
            && self.stream_period_s.is_some()
    }

    /// The clock the lowering puts marks on for a plan in `motion`
    /// ([`crate::motion::Toolpath::on_clock`]): the scan head's, or a LinuxCNC stream's.
    /// LinuxCNC's time law already counts every move of its programs in whole servo periods.
    pub fn marks_clock_s(&self, motion: super::Motion) -> Option<f64> {
        match self.kind {
            ControllerKind::Linuxcnc => self.stream_period_s.filter(|_| self.streamed(motion)),
            ControllerKind::Ideal => self.clock_period_s,
        }
    }
}

impl Default for Controller {
    fn default() -> Self {
        Self {
            kind: ControllerKind::Ideal,
            servo_period_s: 1e-3,
            scanner_accel_mm_s2: 1e6,
            clock_period_s: None,
            stream_period_s: None,
        }
    }
}

/// A redundant laser-marking machine: base stage plus galvanometer scanner.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct MachineProfile {
    /// Format version ([`PROFILE_VERSION`]).
    pub version: u32,
    /// Display name.
    pub name: String,
    /// Base-stage stroke (x, y) in mm: field centres range over `[0, stroke]`.
    pub stroke_mm: [f64; 2],
    /// Scan-field size (x, y) in mm.
    pub field_mm: [f64; 2],
    /// Base-stage X axis.
    pub axis_x: AxisLimits,
    /// Base-stage Y axis.
    pub axis_y: AxisLimits,
    /// A Z axis (the head's height), if the machine has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_z: Option<LinearAxis>,
    /// A rotary A axis (about X), if the machine has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_a: Option<RotaryAxis>,
    /// A rotary B axis (about Y), if the machine has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_b: Option<RotaryAxis>,
    /// Scanner speeds.
    pub scanner: ScannerSpeeds,
    /// Laser timing.
    pub laser: LaserTiming,
    /// G-code output options.
    pub gcode: GcodeDialect,
    /// The controller that runs the job and its time law.
    pub controller: Controller,
    /// On-the-fly marking: following-error headroom kept inside the field, mm (the scanner
    /// offset stays within half the field less this).
    pub otf_margin_mm: f64,
}

impl Default for MachineProfile {
    fn default() -> Self {
        Self {
            version: PROFILE_VERSION,
            name: "Reference machine: 300 mm stage, 70 mm field".into(),
            stroke_mm: [300.0, 300.0],
            field_mm: [70.0, 70.0],
            axis_x: AxisLimits::default(),
            axis_y: AxisLimits::default(),
            axis_z: None,
            axis_a: None,
            axis_b: None,
            scanner: ScannerSpeeds::default(),
            laser: LaserTiming::default(),
            gcode: GcodeDialect::default(),
            controller: Controller::default(),
            otf_margin_mm: 0.0,
        }
    }
}

/// Errors reading or validating a profile.
#[derive(Debug, Error)]
pub enum ProfileError {
    /// The file could not be read.
    #[error("{file}: cannot read profile: {source}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The TOML did not parse.
    #[error("{file}: invalid profile: {msg}")]
    Parse {
        /// The file.
        file: String,
        /// Parser message (with line and column).
        msg: String,
    },
    /// A value is out of range.
    #[error("{file}: invalid profile: {msg}")]
    Invalid {
        /// The file.
        file: String,
        /// What is wrong.
        msg: String,
    },
    /// No built-in profile by that name.
    #[error("no built-in profile named '{0}' (known: {known})", known = BUILTIN.iter().map(|b| b.0).collect::<Vec<_>>().join(", "))]
    Unknown(String),
}

/// Built-in profiles: (name, TOML text).
pub const BUILTIN: &[(&str, &str)] = &[
    (
        "seed000",
        include_str!("../../assets/profiles/seed000.toml"),
    ),
    (
        "small-field",
        include_str!("../../assets/profiles/small-field.toml"),
    ),
    (
        "linuxcnc",
        include_str!("../../assets/profiles/linuxcnc.toml"),
    ),
    (
        "five-axis",
        include_str!("../../assets/profiles/five-axis.toml"),
    ),
    ("rotary", include_str!("../../assets/profiles/rotary.toml")),
];

/// Brings a profile table of an earlier format version to [`PROFILE_VERSION`], one step per
/// version; a table without `version` is taken as current. Later versions are left for
/// [`MachineProfile::validate`] to reject.
fn upgrade(table: &mut toml::Table) {
    let Some(version) = table.get("version").and_then(toml::Value::as_integer) else {
        return;
    };
    if (1..=4).contains(&version) {
        // 1 → 2, 2 → 3, 3 → 4 and 4 → 5 only added fields, each with a default that keeps the
        // earlier behaviour (acceleration as given, no settling, tool-centre G-code, ideal
        // controller, no scan-head clock, no axes beyond X/Y)
        table.insert("version".into(), toml::Value::Integer(5));
    }
}

impl MachineProfile {
    /// The G-code's resolution, mm: a unit in its last decimal (offsets below it are not made).
    pub fn resolution_mm(&self) -> f64 {
        0.1_f64.powi(i32::try_from(self.gcode.decimals).unwrap_or(i32::MAX))
    }

    /// Parses and validates a profile from TOML text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Self, ProfileError> {
        let parse_error = |e: toml::de::Error| ProfileError::Parse {
            file: file.into(),
            msg: e.to_string().replace('\n', " "),
        };
        let mut table: toml::Table = toml::from_str(text).map_err(parse_error)?;
        upgrade(&mut table);
        let p: MachineProfile = table.try_into().map_err(parse_error)?;
        p.validate().map_err(|e| ProfileError::Invalid {
            file: file.into(),
            msg: e.with_key(),
        })?;
        Ok(p)
    }
    /// Reads a profile file, or a built-in profile when `path` names one.
    pub fn load(path: &str) -> Result<Self, ProfileError> {
        if let Some((name, text)) = BUILTIN.iter().find(|(n, _)| *n == path) {
            return Self::from_toml(text, name);
        }
        let text = std::fs::read_to_string(path).map_err(|source| ProfileError::Io {
            file: path.into(),
            source,
        })?;
        Self::from_toml(&text, path)
    }
    /// A built-in profile by name.
    pub fn builtin(name: &str) -> Result<Self, ProfileError> {
        BUILTIN
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| ProfileError::Unknown(name.into()))
            .and_then(|(n, t)| Self::from_toml(t, n))
    }
    /// Serialises to TOML.
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        toml::to_string_pretty(self)
    }
    /// Checks ranges; the error names the first bad value in the GUI's words.
    pub fn validate(&self) -> Result<(), InvalidValue> {
        if self.version == 0 || self.version > PROFILE_VERSION {
            return Err(InvalidValue::new(
                "Profile version",
                "version",
                self.version,
                format!("between 1 and {PROFILE_VERSION} (this build)"),
            ));
        }
        super::spec::check_all(&super::spec::profile_specs(), self)?;
        self.validate_extra_axes()?;
        let half_field_mm = self.field_mm[0].min(self.field_mm[1]) / 2.0;
        if self.otf_margin_mm >= half_field_mm {
            return Err(InvalidValue::new(
                "On-the-fly margin (mm)",
                "otf_margin_mm",
                self.otf_margin_mm,
                format!("less than half the field ({half_field_mm} mm)"),
            ));
        }
        if let Some(stream_s) = self.controller.stream_period_s {
            // the stream runs in motmod's base thread, whose period divides the servo period
            let ratio = self.controller.servo_period_s / stream_s;
            if (ratio - ratio.round()).abs() > 1e-6 || ratio < 0.5 {
                return Err(InvalidValue::new(
                    "Stream period",
                    "controller.stream_period_s",
                    stream_s,
                    format!(
                        "a whole fraction of the servo period ({} s)",
                        self.controller.servo_period_s
                    ),
                ));
            }
        }
        if self.controller.kind == ControllerKind::Linuxcnc
            && self.gcode.mode != GcodeMode::Linuxcnc
        {
            // the time law is that of the program the LinuxCNC dialect writes (G61 exact
            // stops, G93 lines): any other program would run at another pace than the one shown
            return Err(InvalidValue::new(
                "Controller",
                "controller.kind",
                "LinuxCNC",
                "the scan-head controller unless the G-code dialect is LinuxCNC",
            ));
        }
        let [u, v] = &self.gcode.scanner_axes;
        if self.gcode.mode != GcodeMode::Tcp
            && (u == v || [u, v].iter().any(|w| ["X", "Y"].contains(&w.trim())))
        {
            return Err(InvalidValue::new(
                "Scanner axis words",
                "gcode.scanner_axes",
                format!("{u} and {v}"),
                "two different words other than X and Y",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_parse_and_seed_machine_matches_paper() {
        for (name, _) in BUILTIN {
            MachineProfile::builtin(name).unwrap();
        }
        let p = MachineProfile::builtin("seed000").unwrap();
        // the GUI's first-run profile is the default: the same machine
        assert_eq!(p, MachineProfile::default());
        assert_eq!(p.stroke_mm, [300.0, 300.0]);
        assert_eq!(p.field_mm, [70.0, 70.0]);
        assert!(!p.gcode.flip_y);
    }

    #[test]
    fn toml_round_trip() {
        let p = MachineProfile::default();
        let q = MachineProfile::from_toml(&p.to_toml().unwrap(), "x").unwrap();
        assert_eq!(p, q);
    }

    #[test]
    fn bad_values_are_named() {
        let e = MachineProfile::from_toml("version = 1\nfield_mm = [0.0, 70.0]\n", "p.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("p.toml") && e.contains("field_mm[0]"), "{e}");
        let e = MachineProfile::from_toml("version = 1\nbogus = 3\n", "p.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bogus"), "{e}");
        let e = MachineProfile::from_toml("version = 99\n", "p.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("Profile version") && e.contains("not 99"), "{e}");
    }
}
