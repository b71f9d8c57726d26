//! One table per editable type: each value's label, unit, file key, rule and text form,
//! written once. Validation ([`check_all`]), the GUI's editors and the stale-plan reasons
//! ([`differences`]) all read these tables.

use super::validate::{InvalidValue, NON_NEGATIVE, POSITIVE};
use super::{
    ControllerKind, CostModel, FieldsMode, GcodeMode, HatchSettings, MachineProfile, Motion,
    MotionMode, Pen, SolverSettings, StageRouteKind, MAX_PASSES,
};
use crate::geom::MAX_COORD_MM;
use thiserror::Error;

pub use super::choices::{
    label_of, Choice, CODE_KINDS, CONTROLLERS, COST_MODELS, FIELD_PLACEMENTS, GCODE_DIALECTS,
    MOTION_MODES, NUMBERINGS, STAGE_ROUTES, START_POINTS,
};

/// What a value must be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rule {
    /// A finite number above 0.
    Positive,
    /// A finite number, 0 or above.
    NonNegative,
    /// A length above 0 and at most [`crate::geom::MAX_COORD_MM`] (a machine's size).
    Length,
    /// A length of 0 or more, at most [`crate::geom::MAX_COORD_MM`] (a machine's travel).
    Travel,
    /// A number within the bounds (inclusive).
    Range(f64, f64),
    /// A number of at least this.
    AtLeast(f64),
    /// Any finite number.
    Finite,
    /// A whole number within the bounds (inclusive).
    Whole(u64, u64),
    /// Text that is not blank.
    Text,
    /// Any text.
    AnyText,
    /// One of a fixed set, chosen from a list (not typed).
    Choice,
}

/// One editable value of a `T`.
pub struct FieldSpec<T> {
    /// The setting in words, without its unit (`Base X max velocity`).
    pub label: &'static str,
    /// Unit (`mm/s`), empty for none.
    pub unit: &'static str,
    /// Key in a profile, settings or pens file (`axis_x.max_velocity_mm_s`).
    pub key: &'static str,
    /// One line of help.
    pub help: &'static str,
    /// What the value must be.
    pub rule: Rule,
    /// An empty text unsets it (optional values).
    pub optional: bool,
    /// The value changes the job a plan makes (its motion, marks or time): a change since a
    /// plan makes the plan stale.
    pub shapes_plan: bool,
    /// The value as text (empty: unset).
    pub show: fn(&T) -> String,
    /// The number the rule checks (none: unset, or not a number).
    pub number: fn(&T) -> Option<f64>,
    /// Sets the value from text (a choice is not set from text).
    pub parse: fn(&mut T, &str) -> Result<(), ValueError>,
}

impl<T> Clone for FieldSpec<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for FieldSpec<T> {}

impl<T> FieldSpec<T> {
    /// The label with its unit, as the editors show it: `Base X max velocity (mm/s)`.
    pub fn words(&self) -> String {
        if self.unit.is_empty() {
            self.label.to_string()
        } else {
            format!("{} ({})", self.label, self.unit)
        }
    }
    /// Checks the value against the rule.
    pub fn check(&self, t: &T) -> Result<(), InvalidValue> {
        let bad = |rule: String| InvalidValue::new(self.words(), self.key, (self.show)(t), rule);
        let v = (self.number)(t);
        let unset_ok = self.optional && (self.show)(t).is_empty();
        match self.rule {
            _ if unset_ok => Ok(()),
            Rule::Positive if !v.is_some_and(|v| v.is_finite() && v > 0.0) => {
                Err(bad(POSITIVE.into()))
            }
            Rule::NonNegative if !v.is_some_and(|v| v.is_finite() && v >= 0.0) => {
                Err(bad(NON_NEGATIVE.into()))
            }
            Rule::Length if !v.is_some_and(|v| v.is_finite() && v > 0.0) => {
                Err(bad(POSITIVE.into()))
            }
            Rule::Travel if !v.is_some_and(|v| v.is_finite() && v >= 0.0) => {
                Err(bad(NON_NEGATIVE.into()))
            }
            Rule::Length | Rule::Travel if v.is_some_and(|v| v > MAX_COORD_MM) => {
                Err(bad(format!("at most {MAX_COORD_MM} mm (1 km)")))
            }
            Rule::Range(lo, hi) if !v.is_some_and(|v| (lo..=hi).contains(&v)) => {
                Err(bad(format!("between {lo} and {hi}")))
            }
            Rule::AtLeast(lo) if !v.is_some_and(|v| v.is_finite() && v >= lo) => {
                Err(bad(format!("a number of at least {lo}")))
            }
            Rule::Finite if !v.is_some_and(f64::is_finite) => Err(bad("a finite number".into())),
            Rule::Whole(lo, hi) if !v.is_some_and(|v| (lo as f64..=hi as f64).contains(&v)) => {
                Err(bad(if hi == u64::MAX {
                    format!("a whole number of at least {lo}")
                } else {
                    format!("a whole number from {lo} to {hi}")
                }))
            }
            Rule::Text if (self.show)(t).trim().is_empty() => Err(bad("a word".into())),
            _ => Ok(()),
        }
    }
    /// Sets the value from the text an operator typed; the message names the setting.
    pub fn set_text(&self, t: &mut T, text: &str) -> Result<(), InvalidText> {
        (self.parse)(t, text).map_err(|error| InvalidText {
            setting: self.words(),
            error,
        })
    }
}

/// Why a typed text is not a value; the message follows the setting's words (`Passes must be
/// a whole number (0 or more), not 'x'`).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ValueError {
    /// Not a number.
    #[error("must be a number, not '{text}'")]
    NotANumber {
        /// The text, trimmed.
        text: String,
    },
    /// A number that is not finite (`inf`, `NaN`).
    #[error("must be a finite number, not '{text}'")]
    NotFinite {
        /// The text, trimmed.
        text: String,
    },
    /// Not a whole number of 0 or more.
    #[error("must be a whole number (0 or more), not '{text}'")]
    NotWhole {
        /// The text, trimmed.
        text: String,
    },
    /// A whole number too large for the value's type.
    #[error("must be smaller, not {value}")]
    TooLarge {
        /// The number typed.
        value: u64,
    },
    /// A seam width that is not a number.
    #[error("'{text}' is not a number")]
    NotAWidth {
        /// The text, trimmed.
        text: String,
    },
    /// A value chosen from a list, which text does not set.
    #[error("chosen from a list")]
    Chosen,
}

/// A typed text that is not a value of the setting: the setting's words and why.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{setting} {error}")]
pub struct InvalidText {
    /// The setting in words with its unit, as the editors show it (`Passes`).
    pub setting: String,
    /// What is wrong with the text.
    pub error: ValueError,
}

/// Checks every value of `t` against its table.
pub fn check_all<T>(specs: &[FieldSpec<T>], t: &T) -> Result<(), InvalidValue> {
    specs.iter().try_for_each(|s| s.check(t))
}

/// What changed from `old` to `new` among the values that shape a plan, in words:
/// `Base X max velocity: 500 → 100 mm/s`.
pub fn differences<T>(specs: &[FieldSpec<T>], old: &T, new: &T) -> Vec<String> {
    specs
        .iter()
        .filter(|s| s.shapes_plan)
        .filter_map(|s| {
            let (a, b) = ((s.show)(old), (s.show)(new));
            (a != b).then(|| {
                // an empty value reads as the editors show it
                let a = if a.is_empty() { "none".into() } else { a };
                let b = if b.is_empty() { "none".into() } else { b };
                let unit = if s.unit.is_empty() || s.rule == Rule::Choice {
                    String::new()
                } else {
                    format!(" {}", s.unit)
                };
                // the unit goes with a number: after the new value, or the old one when the
                // new one is none
                let (a, b) = if b == "none" {
                    (format!("{a}{unit}"), b)
                } else {
                    (a, format!("{b}{unit}"))
                };
                format!("{} {a} → {b}", lower_first(s.label))
            })
        })
        .collect()
}

/// A label in the middle of a sentence: its first word in lower case, an axis letter kept
/// (`Base X max velocity` → `base X max velocity`).
fn lower_first(label: &str) -> String {
    let mut chars = label.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().chain(chars).collect(),
        None => String::new(),
    }
}

/// A number typed by the operator.
pub fn parse_number(s: &str) -> Result<f64, ValueError> {
    let text = s.trim();
    let v: f64 = text.parse().map_err(|_| ValueError::NotANumber {
        text: text.to_string(),
    })?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ValueError::NotFinite {
            text: text.to_string(),
        })
    }
}

/// An optional number: empty text is none.
pub fn parse_optional(s: &str) -> Result<Option<f64>, ValueError> {
    if s.trim().is_empty() {
        Ok(None)
    } else {
        parse_number(s).map(Some)
    }
}

/// A whole number typed by the operator.
pub fn parse_whole(s: &str) -> Result<u64, ValueError> {
    let text = s.trim();
    text.parse().map_err(|_| ValueError::NotWhole {
        text: text.to_string(),
    })
}

fn show(v: f64) -> String {
    format!("{v}")
}

fn show_opt(v: Option<f64>) -> String {
    v.map(show).unwrap_or_default()
}

fn no_text<T>(_: &mut T, _: &str) -> Result<(), ValueError> {
    Err(ValueError::Chosen)
}

fn no_number<T>(_: &T) -> Option<f64> {
    None
}

/// A number spec: `$label`, `$unit`, `$key`, `$help`, `$rule`, a place `|x| x.field`.
macro_rules! number {
    ($label:expr, $unit:expr, $key:expr, $help:expr, $rule:expr, |$t:ident| $place:expr) => {
        FieldSpec {
            label: $label,
            unit: $unit,
            key: $key,
            help: $help,
            rule: $rule,
            optional: false,
            shapes_plan: true,
            show: |$t| show($place),
            number: |$t| Some($place),
            parse: |$t, s| {
                $place = parse_number(s)?;
                Ok(())
            },
        }
    };
}

/// An optional number spec (empty text unsets it).
macro_rules! optional {
    ($label:expr, $unit:expr, $key:expr, $help:expr, $rule:expr, |$t:ident| $place:expr) => {
        FieldSpec {
            label: $label,
            unit: $unit,
            key: $key,
            help: $help,
            rule: $rule,
            optional: true,
            shapes_plan: true,
            show: |$t| show_opt($place),
            number: |$t| $place,
            parse: |$t, s| {
                $place = parse_optional(s)?;
                Ok(())
            },
        }
    };
}

/// A whole-number spec from `$lo` to `$hi`, stored as `$ty`.
macro_rules! whole {
    ($label:expr, $key:expr, $help:expr, $lo:expr, $hi:expr, $ty:ty, |$t:ident| $place:expr) => {
        FieldSpec {
            label: $label,
            unit: "",
            key: $key,
            help: $help,
            rule: Rule::Whole($lo as u64, $hi as u64),
            optional: false,
            shapes_plan: true,
            show: |$t| $place.to_string(),
            number: |$t| Some($place as f64),
            parse: |$t, s| {
                let v = parse_whole(s)?;
                $place = <$ty>::try_from(v).map_err(|_| ValueError::TooLarge { value: v })?;
                Ok(())
            },
        }
    };
}

/// A text spec (`Rule::Text`: not blank).
macro_rules! text {
    ($label:expr, $key:expr, $help:expr, $rule:expr, |$t:ident| $place:expr) => {
        FieldSpec {
            label: $label,
            unit: "",
            key: $key,
            help: $help,
            rule: $rule,
            optional: false,
            shapes_plan: true,
            show: |$t| $place.clone(),
            number: no_number,
            parse: |$t, s| {
                $place = s.trim().to_string();
                Ok(())
            },
        }
    };
}

/// A value chosen from a list, shown in words.
macro_rules! choice {
    ($label:expr, $key:expr, |$t:ident| $words:expr) => {
        FieldSpec {
            label: $label,
            unit: "",
            key: $key,
            help: "",
            rule: Rule::Choice,
            optional: false,
            shapes_plan: true,
            show: |$t| $words,
            number: no_number,
            parse: no_text,
        }
    };
}

mod axis_rows;

/// The most decimal places a G-code number may have (below a nanometre is noise).
pub const MAX_DECIMALS: usize = 9;

/// The machine profile's values (the profile editor's rows, in order, then the ones only a
/// profile file sets).
pub fn profile_specs() -> Vec<FieldSpec<MachineProfile>> {
    use Rule::{NonNegative, Positive};
    let mut name: FieldSpec<MachineProfile> =
        text!("Name", "name", "display name", Rule::AnyText, |p| p.name);
    name.shapes_plan = false;
    vec![
        name,
        number!(
            "Stroke X",
            "mm",
            "stroke_mm[0]",
            "base-stage travel in x: field centres range over [0, stroke]",
            Rule::Travel,
            |p| p.stroke_mm[0]
        ),
        number!(
            "Stroke Y",
            "mm",
            "stroke_mm[1]",
            "base-stage travel in y",
            Rule::Travel,
            |p| p.stroke_mm[1]
        ),
        number!(
            "Field width",
            "mm",
            "field_mm[0]",
            "scan-field size in x",
            Rule::Length,
            |p| p.field_mm[0]
        ),
        number!(
            "Field height",
            "mm",
            "field_mm[1]",
            "scan-field size in y",
            Rule::Length,
            |p| p.field_mm[1]
        ),
        number!(
            "Base X max velocity",
            "mm/s",
            "axis_x.max_velocity_mm_s",
            "",
            Positive,
            |p| p.axis_x.max_velocity_mm_s
        ),
        number!(
            "Base X max accel",
            "mm/s²",
            "axis_x.max_accel_mm_s2",
            "",
            Positive,
            |p| p.axis_x.max_accel_mm_s2
        ),
        number!(
            "Base X settling time",
            "s",
            "axis_x.settle_s",
            "after every move",
            NonNegative,
            |p| p.axis_x.settle_s
        ),
        number!(
            "Base Y max velocity",
            "mm/s",
            "axis_y.max_velocity_mm_s",
            "",
            Positive,
            |p| p.axis_y.max_velocity_mm_s
        ),
        number!(
            "Base Y max accel",
            "mm/s²",
            "axis_y.max_accel_mm_s2",
            "",
            Positive,
            |p| p.axis_y.max_accel_mm_s2
        ),
        number!(
            "Base Y settling time",
            "s",
            "axis_y.settle_s",
            "after every move",
            NonNegative,
            |p| p.axis_y.settle_s
        ),
    ]
    .into_iter()
    .chain(axis_rows::axis_specs())
    .chain(scanner_to_gcode_specs())
    .chain(controller_specs())
    .collect()
}

/// The profile's scanner, laser and G-code rows.
fn scanner_to_gcode_specs() -> Vec<FieldSpec<MachineProfile>> {
    use Rule::{NonNegative, Positive};
    vec![
        number!(
            "Scanner jump speed",
            "mm/s",
            "scanner.jump_speed_mm_s",
            "laser off",
            Positive,
            |p| p.scanner.jump_speed_mm_s
        ),
        number!(
            "Scanner mark speed",
            "mm/s",
            "scanner.mark_speed_mm_s",
            "laser on",
            Positive,
            |p| p.scanner.mark_speed_mm_s
        ),
        optional!(
            "Depth of focus",
            "mm",
            "scanner.depth_of_focus_mm",
            "how far below the focus the surface still marks: a cylinder's strips follow from it",
            Positive,
            |p| p.scanner.depth_of_focus_mm
        ),
        number!(
            "Laser on delay",
            "s",
            "laser.on_delay_s",
            "",
            NonNegative,
            |p| p.laser.on_delay_s
        ),
        number!(
            "Laser off delay",
            "s",
            "laser.off_delay_s",
            "",
            NonNegative,
            |p| p.laser.off_delay_s
        ),
        number!(
            "Jump delay",
            "s",
            "laser.jump_delay_s",
            "scanner settling after a jump",
            NonNegative,
            |p| p.laser.jump_delay_s
        ),
        number!(
            "Laser spot",
            "mm",
            "laser.spot_mm",
            "the spot's diameter: codes without a pen of their own are filled at this spacing",
            Rule::Length,
            |p| p.laser.spot_mm
        ),
        number!(
            "Dot dwell",
            "s",
            "laser.dot_dwell_s",
            "how long the laser fires at a dot (a dotted code's module); pens may set their own",
            Positive,
            |p| p.laser.dot_dwell_s
        ),
        number!(
            "On-the-fly margin",
            "mm",
            "otf_margin_mm",
            "kept free at the field's edge while the stage moves",
            NonNegative,
            |p| p.otf_margin_mm
        ),
        text!(
            "Laser on word",
            "gcode.laser_on",
            "M3 or M4 (LinuxCNC: M62 on the laser output)",
            Rule::Text,
            |p| p.gcode.laser_on
        ),
        text!(
            "Laser off word",
            "gcode.laser_off",
            "usually M5 (LinuxCNC: M63 on the laser output)",
            Rule::Text,
            |p| p.gcode.laser_off
        ),
        text!(
            "Power word",
            "gcode.power_word",
            "written before the power, usually S",
            Rule::Text,
            |p| p.gcode.power_word
        ),
        optional!(
            "Power",
            "",
            "gcode.power",
            "written after the laser-on word; empty: none",
            NonNegative,
            |p| p.gcode.power
        ),
        number!(
            "Feed",
            "mm/min",
            "gcode.feed_mm_min",
            "on G1 moves (LinuxCNC: the mark speed × 60, as the job is timed)",
            Positive,
            |p| p.gcode.feed_mm_min
        ),
        whole!(
            "Decimals",
            "gcode.decimals",
            "digits after the point in G-code",
            0,
            MAX_DECIMALS,
            usize,
            |p| p.gcode.decimals
        ),
        text!(
            "Scanner X axis word",
            "gcode.scanner_axes[0]",
            "stage-and-scanner G-code",
            Rule::Text,
            |p| p.gcode.scanner_axes[0]
        ),
        text!(
            "Scanner Y axis word",
            "gcode.scanner_axes[1]",
            "stage-and-scanner G-code",
            Rule::Text,
            |p| p.gcode.scanner_axes[1]
        ),
        whole!(
            "Laser output",
            "gcode.laser_output",
            "LinuxCNC digital output that gates the laser (M62/M63 P)",
            0,
            MAX_LINUXCNC_IO,
            u32,
            |p| p.gcode.laser_output
        ),
        FieldSpec {
            label: "Power output",
            unit: "",
            key: "gcode.power_output",
            help: "LinuxCNC analog output for the power (M67 E); empty: the power word",
            rule: Rule::Whole(0, MAX_LINUXCNC_IO as u64),
            optional: true,
            shapes_plan: false,
            show: |p| {
                p.gcode
                    .power_output
                    .map(|e| e.to_string())
                    .unwrap_or_default()
            },
            number: |p| p.gcode.power_output.map(f64::from),
            parse: |p, s| {
                p.gcode.power_output = if s.trim().is_empty() {
                    None
                } else {
                    let v = parse_whole(s)?;
                    Some(u32::try_from(v).map_err(|_| ValueError::TooLarge { value: v })?)
                };
                Ok(())
            },
        },
        number!(
            "Path tolerance",
            "mm",
            "gcode.path_tol_mm",
            "LinuxCNC blending (G64 P) and on-the-fly sample merging",
            Positive,
            |p| p.gcode.path_tol_mm
        ),
    ]
}

/// The controller's values (a profile's `[controller]` table), and the two choices of
/// dialect and controller.
fn controller_specs() -> Vec<FieldSpec<MachineProfile>> {
    use Rule::{Positive, Range};
    vec![
        number!(
            "Servo period",
            "s",
            "controller.servo_period_s",
            "LinuxCNC controller: its servo period (the clock its moves are timed on)",
            Range(1e-5, 0.01),
            |p| p.controller.servo_period_s
        ),
        optional!(
            "Stream period",
            "s",
            "controller.stream_period_s",
            "LinuxCNC: on-the-fly plans streamed to the joints, one sample a period (its base \
             thread); empty: an inverse-time (G93) program",
            Range(1e-5, 0.01),
            |p| p.controller.stream_period_s
        ),
        optional!(
            "Scan-head clock",
            "s",
            "controller.clock_period_s",
            "the scan head's clock period: every mark starts and ends on a tick; empty: continuous",
            Range(1e-6, 0.1),
            |p| p.controller.clock_period_s
        ),
        number!(
            "Scanner accel",
            "mm/s²",
            "controller.scanner_accel_mm_s2",
            "LinuxCNC: the scanner axes' acceleration (its configuration and time law)",
            Positive,
            |p| p.controller.scanner_accel_mm_s2
        ),
        // a choice's short words (plan names, stale reasons); the editors' labels and help are
        // the tables of `super::choices`
        choice!("G-code dialect", "gcode.mode", |p| match p.gcode.mode {
            GcodeMode::Tcp => "tool-centre point".into(),
            GcodeMode::StageScanner => "stage and scanner axes".into(),
            GcodeMode::Linuxcnc => "LinuxCNC".into(),
        }),
        choice!(
            "Controller",
            "controller.kind",
            |p| match p.controller.kind {
                ControllerKind::Ideal => "scan-head controller".into(),
                ControllerKind::Linuxcnc => "LinuxCNC".into(),
            }
        ),
    ]
}

/// The highest digital or analog output number a LinuxCNC program may name (motmod allows 64).
pub const MAX_LINUXCNC_IO: u32 = 63;

/// The solver settings' values: the typed ones (the settings editor's rows), then the ones
/// chosen from lists.
pub fn settings_specs() -> Vec<FieldSpec<SolverSettings>> {
    use Rule::{NonNegative, Positive, Range};
    let mut search: Vec<FieldSpec<SolverSettings>> = vec![
        whole!(
            "Seed",
            "seed",
            "all randomised stages are deterministic for a seed",
            0,
            u64::MAX,
            u64,
            |t| t.seed
        ),
        optional!(
            "Time limit",
            "s",
            "time_limit_s",
            "for the ordering stage; empty: none",
            Positive,
            |t| t.time_limit_s
        ),
        number!(
            "Direction weight",
            "",
            "direction_weight",
            "how strongly HHA keeps each field's marks running one way (fewer turns back): 0 \
             ignores direction, higher favours sweeping over shorter travel",
            NonNegative,
            |t| t.direction_weight
        ),
        whole!(
            "GA population",
            "ga.population",
            "initial population size",
            super::settings::MIN_POPULATION,
            u64::MAX,
            usize,
            |t| t.ga.population
        ),
        whole!(
            "GA population min",
            "ga.population_min",
            "",
            super::settings::MIN_POPULATION,
            u64::MAX,
            usize,
            |t| t.ga.population_min
        ),
        whole!(
            "GA population max",
            "ga.population_max",
            "",
            super::settings::MIN_POPULATION,
            u64::MAX,
            usize,
            |t| t.ga.population_max
        ),
        number!(
            "GA elite fraction",
            "",
            "ga.elite_fraction",
            "share of the best plans carried unchanged into each next generation (0 … 1)",
            Range(0.0, 1.0),
            |t| t.ga.elite_fraction
        ),
        number!(
            "GA mutation rate",
            "",
            "ga.mutation_rate",
            "chance that a new plan is changed at random, to keep the search from settling \
             early (0 … 1)",
            Range(0.0, 1.0),
            |t| t.ga.mutation_rate
        ),
        whole!(
            "GA stall generations",
            "ga.stall_generations",
            "without a time limit, stop after this many generations without improvement",
            1,
            u64::MAX,
            usize,
            |t| t.ga.stall_generations
        ),
        FieldSpec {
            label: "GA generations at most",
            unit: "",
            key: "ga.max_generations",
            help: "stop after this many generations; empty: no cap (the stall or the time limit \
                   ends the run)",
            rule: Rule::Whole(1, u64::MAX),
            optional: true,
            shapes_plan: true,
            show: |t| {
                t.ga.max_generations
                    .map_or_else(String::new, |v| v.to_string())
            },
            number: |t| t.ga.max_generations.map(|v| v as f64),
            parse: |t, s| {
                t.ga.max_generations = if s.trim().is_empty() {
                    None
                } else {
                    let v = parse_whole(s)?;
                    Some(usize::try_from(v).map_err(|_| ValueError::TooLarge { value: v })?)
                };
                Ok(())
            },
        },
    ];
    // how hard a solve searches, not what job it makes: a plan is not stale for them
    for s in &mut search {
        s.shapes_plan = matches!(s.key, "direction_weight");
    }
    let choices: [FieldSpec<SolverSettings>; 7] = [
        choice!("Cost", "cost_model", |t| match t.cost_model {
            CostModel::Time => "job time".into(),
            CostModel::Distance => "idle distance".into(),
        }),
        choice!("Motion", "motion", |t| match t.motion {
            MotionMode::Auto => "automatic (the faster)".into(),
            MotionMode::Step => Motion::Step.words().into(),
            MotionMode::OnTheFly => Motion::OnTheFly.words().into(),
        }),
        choice!(
            "Stage route",
            "stage_route",
            |t| match (t.motion, t.stage_route) {
                (MotionMode::Step, _) => "none (step-and-scan)".into(),
                (_, StageRouteKind::Taut) => "tracked (galvoplan's own)".into(),
                (_, StageRouteKind::Lsa) => "simplified pattern (lsa)".into(),
                (_, StageRouteKind::CetspGa) => "genetic algorithm (cetsp-ga)".into(),
            }
        ),
        choice!(
            "Route GA",
            "route_ga",
            |t| match (t.motion, t.stage_route) {
                (
                    MotionMode::OnTheFly | MotionMode::Auto,
                    StageRouteKind::Lsa | StageRouteKind::CetspGa,
                ) => {
                    let g = &t.route_ga;
                    format!(
                        "population {}, generations {}, crossover {}, mutation {}, padding {}",
                        g.population,
                        g.generations,
                        g.crossover_rate,
                        g.mutation_rate,
                        g.padding_radius_mm
                            .map_or("half the field".into(), |r| format!("{r} mm"))
                    )
                }
                _ => String::new(),
            }
        ),
        choice!("Scan fields", "fields", |t| match t.fields {
            FieldsMode::Auto => "automatic".into(),
            FieldsMode::Paper => "the scan-field paper's placement".into(),
            FieldsMode::Greedy => "greedy".into(),
        }),
        choice!("Split oversize geometries", "split_oversize", |t| yes_no(
            t.split_oversize
        )),
        choice!("Default hatch", "hatch", |t| hatch_words(t.hatch.as_ref())),
    ];
    search.extend(choices);
    search
}

/// The cylinder of a cylinder job (the GUI's Cylinder section; a plan is stale when it
/// changes).
pub fn cylinder_specs() -> Vec<FieldSpec<SolverSettings>> {
    vec![FieldSpec {
        label: "Cylinder diameter",
        unit: "mm",
        key: "cylinder.diameter_mm",
        help: "mark around a cylinder of this diameter on the rotary A axis: the artwork is its \
               unrolled surface, x along the axis, y around it; empty: a flat job",
        rule: Rule::Positive,
        optional: true,
        shapes_plan: true,
        show: |t| show_opt(t.cylinder.map(|c| c.diameter_mm)),
        number: |t| t.cylinder.map(|c| c.diameter_mm),
        parse: |t, s| {
            t.cylinder = parse_optional(s)?.map(|diameter_mm| super::Cylinder { diameter_mm });
            Ok(())
        },
    }]
}

/// A pen's values (the layers panel's rows).
pub fn pen_specs() -> Vec<FieldSpec<Pen>> {
    use Rule::Positive;
    let colour = FieldSpec {
        label: "Colour",
        unit: "",
        key: "colour",
        help: "display colour #rrggbb; empty: from the layer's name",
        rule: Rule::AnyText,
        optional: true,
        shapes_plan: false,
        show: |p: &Pen| p.colour.clone().unwrap_or_default(),
        number: no_number,
        parse: |p: &mut Pen, s: &str| {
            let s = s.trim();
            p.colour = (!s.is_empty()).then(|| s.to_string());
            Ok(())
        },
    };
    vec![
        choice!("Marked", "enabled", |p| yes_no(p.enabled)),
        optional!(
            "Mark speed",
            "mm/s",
            "mark_speed_mm_s",
            "scanner mark speed; empty: the profile's",
            Positive,
            |p| p.mark_speed_mm_s
        ),
        optional!(
            "Power",
            "",
            "power",
            "written with the profile's power word; empty: the profile's",
            Rule::NonNegative,
            |p| p.power
        ),
        optional!(
            "Pulse frequency",
            "kHz",
            "frequency_khz",
            "written as a comment; empty: unset",
            Positive,
            |p| p.frequency_khz
        ),
        whole!(
            "Passes",
            "passes",
            "how many times the layer is marked",
            1,
            MAX_PASSES,
            u32,
            |p| p.passes
        ),
        choice!("Shifted passes", "shift_passes", |p| yes_no(p.shift_passes)),
        optional!(
            "Dot dwell",
            "s",
            "dot_dwell_s",
            "how long the laser fires at a dot (a dotted code's module); empty: the profile's",
            Positive,
            |p| p.dot_dwell_s
        ),
        choice!("Hatch", "hatch", |p| hatch_words(p.hatch.as_ref())),
        choice!("Seam", "seam", |p| p.seam.describe()),
        seam_width_spec(),
        colour,
    ]
}

/// The seam form's width (band or overlap), typed; its form is chosen from a list.
fn seam_width_spec() -> FieldSpec<Pen> {
    FieldSpec {
        label: "Seam width",
        unit: "mm",
        key: "seam_mm",
        help: "interlocked and staggered: the band the cuts spread over; overlap: how far each side marks past the cut",
        rule: Rule::Range(1e-3, crate::geom::seam::MAX_SEAM_BAND_MM),
        optional: true,
        shapes_plan: true,
        show: |p: &Pen| seam_width(&p.seam).map_or_else(String::new, |w| w.to_string()),
        number: |p: &Pen| seam_width(&p.seam),
        parse: |p: &mut Pen, s: &str| {
            use crate::geom::seam::SeamForm;
            let s = s.trim();
            if s.is_empty() {
                return Ok(());
            }
            let w: f64 = s.parse().map_err(|_| ValueError::NotAWidth {
                text: s.to_string(),
            })?;
            p.seam = match p.seam {
                SeamForm::Straight => SeamForm::Straight,
                SeamForm::Overlap { doubled, .. } => SeamForm::Overlap {
                    overlap_mm: w,
                    doubled,
                },
                SeamForm::Interlocked { .. } => SeamForm::Interlocked { band_mm: w },
                SeamForm::Staggered { seed, .. } => SeamForm::Staggered { band_mm: w, seed },
            };
            Ok(())
        },
    }
}

/// The width of a seam form (none for straight), mm.
pub fn seam_width(f: &crate::geom::seam::SeamForm) -> Option<f64> {
    use crate::geom::seam::SeamForm;
    match *f {
        SeamForm::Straight => None,
        SeamForm::Overlap { overlap_mm, .. } => Some(overlap_mm),
        SeamForm::Interlocked { band_mm } | SeamForm::Staggered { band_mm, .. } => Some(band_mm),
    }
}

/// A hatch's typed values (the layers panel's hatch rows).
pub fn hatch_specs() -> Vec<FieldSpec<HatchSettings>> {
    vec![
        number!(
            "Hatch spacing",
            "mm",
            "spacing_mm",
            "distance between hatch lines",
            Rule::AtLeast(super::MIN_SPACING_MM),
            |h| h.spacing_mm
        ),
        number!(
            "Hatch angle",
            "°",
            "angle_deg",
            "direction of the hatch lines",
            Rule::Finite,
            |h| h.angle_deg
        ),
        optional!(
            "Hatch edge offset",
            "mm",
            "edge_offset_mm",
            "kept free inside the outline; empty: the spacing",
            Rule::NonNegative,
            |h| h.edge_offset_mm
        ),
    ]
}

fn yes_no(b: bool) -> String {
    if b { "yes" } else { "no" }.into()
}

/// A hatch in words: `zigzag every 0.1 mm at 45°, edge 0.1 mm, outlines after`.
pub fn hatch_words(h: Option<&HatchSettings>) -> String {
    match h {
        None => "none".into(),
        Some(h) => format!(
            "{} every {} mm at {}°, edge {} mm, outlines {:?}",
            h.style,
            h.spacing_mm,
            h.angle_deg,
            h.edge_offset(),
            h.outline
        )
        .to_lowercase(),
    }
}

/// The tray of a production job (the Tray section's rows): counts, pitch, serials. The
/// numbering is a choice the section offers beside them.
pub fn tray_specs() -> Vec<FieldSpec<super::TraySetup>> {
    use super::production::MAX_CELLS;
    vec![
        whole!(
            "Columns",
            "tray.cols",
            "parts across (x)",
            1,
            MAX_CELLS,
            u32,
            |p| p.tray.cols
        ),
        whole!(
            "Rows",
            "tray.rows",
            "parts down (y)",
            1,
            MAX_CELLS,
            u32,
            |p| p.tray.rows
        ),
        number!(
            "Pitch X",
            "mm",
            "tray.pitch_mm[0]",
            "from one part to the next across",
            Rule::Travel,
            |p| p.tray.pitch_mm[0]
        ),
        number!(
            "Pitch Y",
            "mm",
            "tray.pitch_mm[1]",
            "from one part to the next down",
            Rule::Travel,
            |p| p.tray.pitch_mm[1]
        ),
        whole!(
            "First serial",
            "serial.start",
            "the serial number of part 1",
            0,
            i64::MAX,
            i64,
            |p| p.serial.start
        ),
        whole!(
            "Serial step",
            "serial.step",
            "from one part's serial to the next",
            1,
            1_000_000_000u64,
            i64,
            |p| p.serial.step
        ),
    ]
}

/// A typed handle on one row of a spec table over `T`: the row's key and its table. Editors
/// name the rows they show by handle, never by a key typed where it is used; every handle
/// resolves ([`unresolved`] is empty for [`editor_rows`], which a test checks).
pub struct Row<T: 'static> {
    /// The row's file key.
    pub key: &'static str,
    table: fn() -> Vec<FieldSpec<T>>,
}

impl<T> Clone for Row<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Row<T> {}

impl<T> std::fmt::Debug for Row<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Row({})", self.key)
    }
}

impl<T> Row<T> {
    /// The handle on the row `key` of `table`.
    pub const fn new(key: &'static str, table: fn() -> Vec<FieldSpec<T>>) -> Self {
        Self { key, table }
    }
    /// The row (none only for a handle whose key its table lacks: see [`unresolved`]).
    pub fn spec(&self) -> Option<FieldSpec<T>> {
        (self.table)().into_iter().find(|s| s.key == self.key)
    }
    /// True when `spec` is this row.
    pub fn is(&self, spec: &FieldSpec<T>) -> bool {
        spec.key == self.key
    }
}

/// The rows the editors name.
pub mod rows {
    use super::{hatch_specs, pen_specs, profile_specs, Row};
    use crate::document::{HatchSettings, MachineProfile, Pen};

    /// The profile's name (a free-text row: the panel's width).
    pub const PROFILE_NAME: Row<MachineProfile> = Row::new("name", profile_specs);
    /// The laser-on word (dialects that are not LinuxCNC).
    pub const LASER_ON: Row<MachineProfile> = Row::new("gcode.laser_on", profile_specs);
    /// The laser-off word.
    pub const LASER_OFF: Row<MachineProfile> = Row::new("gcode.laser_off", profile_specs);
    /// The feed word's value.
    pub const FEED: Row<MachineProfile> = Row::new("gcode.feed_mm_min", profile_specs);
    /// The scanner's first axis word.
    pub const SCANNER_AXIS_0: Row<MachineProfile> =
        Row::new("gcode.scanner_axes[0]", profile_specs);
    /// The scanner's second axis word.
    pub const SCANNER_AXIS_1: Row<MachineProfile> =
        Row::new("gcode.scanner_axes[1]", profile_specs);
    /// LinuxCNC's laser output.
    pub const LASER_OUTPUT: Row<MachineProfile> = Row::new("gcode.laser_output", profile_specs);
    /// LinuxCNC's power output.
    pub const POWER_OUTPUT: Row<MachineProfile> = Row::new("gcode.power_output", profile_specs);
    /// LinuxCNC's path tolerance.
    pub const PATH_TOL: Row<MachineProfile> = Row::new("gcode.path_tol_mm", profile_specs);
    /// The power word.
    pub const POWER_WORD: Row<MachineProfile> = Row::new("gcode.power_word", profile_specs);
    /// LinuxCNC's servo period.
    pub const SERVO_PERIOD: Row<MachineProfile> =
        Row::new("controller.servo_period_s", profile_specs);
    /// A LinuxCNC stream's period.
    pub const STREAM: Row<MachineProfile> = Row::new("controller.stream_period_s", profile_specs);
    /// A scan head's clock.
    pub const CLOCK: Row<MachineProfile> = Row::new("controller.clock_period_s", profile_specs);
    /// LinuxCNC's scanner acceleration.
    pub const SCANNER_ACCEL: Row<MachineProfile> =
        Row::new("controller.scanner_accel_mm_s2", profile_specs);

    /// Axis Z's rows.
    pub const AXIS_Z: &[Row<MachineProfile>] = &[
        Row::new("axis_z.max_velocity_mm_s", profile_specs),
        Row::new("axis_z.max_accel_mm_s2", profile_specs),
        Row::new("axis_z.settle_s", profile_specs),
        Row::new("axis_z.travel_mm[0]", profile_specs),
        Row::new("axis_z.travel_mm[1]", profile_specs),
    ];
    /// Axis A's rows.
    pub const AXIS_A: &[Row<MachineProfile>] = &[
        Row::new("axis_a.max_velocity_deg_s", profile_specs),
        Row::new("axis_a.max_accel_deg_s2", profile_specs),
        Row::new("axis_a.settle_s", profile_specs),
        Row::new("axis_a.travel_deg[0]", profile_specs),
        Row::new("axis_a.travel_deg[1]", profile_specs),
    ];
    /// Axis B's rows.
    pub const AXIS_B: &[Row<MachineProfile>] = &[
        Row::new("axis_b.max_velocity_deg_s", profile_specs),
        Row::new("axis_b.max_accel_deg_s2", profile_specs),
        Row::new("axis_b.settle_s", profile_specs),
        Row::new("axis_b.travel_deg[0]", profile_specs),
        Row::new("axis_b.travel_deg[1]", profile_specs),
    ];
    /// The Y axis's dynamics (a rotary machine without Y has none).
    pub const AXIS_Y: &[Row<MachineProfile>] = &[
        Row::new("axis_y.max_velocity_mm_s", profile_specs),
        Row::new("axis_y.max_accel_mm_s2", profile_specs),
        Row::new("axis_y.settle_s", profile_specs),
    ];

    /// A pen's mark speed.
    pub const PEN_SPEED: Row<Pen> = Row::new("mark_speed_mm_s", pen_specs);
    /// A pen's power.
    pub const PEN_POWER: Row<Pen> = Row::new("power", pen_specs);
    /// A pen's pulse frequency.
    pub const PEN_FREQUENCY: Row<Pen> = Row::new("frequency_khz", pen_specs);
    /// A pen's passes.
    pub const PEN_PASSES: Row<Pen> = Row::new("passes", pen_specs);
    /// A pen's seam width.
    pub const PEN_SEAM_WIDTH: Row<Pen> = Row::new("seam_mm", pen_specs);
    /// A hatch's line spacing.
    pub const HATCH_SPACING: Row<HatchSettings> = Row::new("spacing_mm", hatch_specs);
    /// A hatch's angle.
    pub const HATCH_ANGLE: Row<HatchSettings> = Row::new("angle_deg", hatch_specs);
    /// A hatch's edge offset.
    pub const HATCH_EDGE: Row<HatchSettings> = Row::new("edge_offset_mm", hatch_specs);
}

/// Profile rows and the test of the profiles they are used with.
pub type AppliesWhen = (&'static [Row<MachineProfile>], fn(&MachineProfile) -> bool);

/// Every row handle an editor uses, by table: profile, pen and hatch rows.
pub type EditorRows = (
    Vec<Row<MachineProfile>>,
    Vec<Row<Pen>>,
    Vec<Row<HatchSettings>>,
);

/// When profile rows apply: the rows, and the profiles they are used with (the G-code dialect
/// and the controller decide). A row named by no rule always applies.
pub const PROFILE_APPLIES: &[AppliesWhen] = &[
    (&[rows::LASER_ON, rows::LASER_OFF, rows::FEED], |p| {
        p.gcode.mode != GcodeMode::Linuxcnc
    }),
    (&[rows::SCANNER_AXIS_0, rows::SCANNER_AXIS_1], |p| {
        p.gcode.mode != GcodeMode::Tcp
    }),
    (
        &[rows::LASER_OUTPUT, rows::POWER_OUTPUT, rows::PATH_TOL],
        |p| p.gcode.mode == GcodeMode::Linuxcnc,
    ),
    (&[rows::POWER_WORD], |p| {
        !(p.gcode.mode == GcodeMode::Linuxcnc && p.gcode.power_output.is_some())
    }),
    (&[rows::SERVO_PERIOD, rows::STREAM], |p| {
        p.controller.kind == ControllerKind::Linuxcnc
    }),
    (&[rows::CLOCK], |p| {
        p.controller.kind == ControllerKind::Ideal
    }),
    // also the scanner's acceleration in linuxcnc-config's machine
    (&[rows::SCANNER_ACCEL], |p| {
        p.gcode.mode == GcodeMode::Linuxcnc || p.controller.kind == ControllerKind::Linuxcnc
    }),
];

/// Profile rows of axes a machine may not have, and the test of the machines that have them: an
/// editor leaves them out where the machine lacks the axis.
pub const PROFILE_AXES: &[AppliesWhen] = &[
    (rows::AXIS_Y, MachineProfile::has_y),
    (rows::AXIS_Z, |p| p.axis_z.is_some()),
    (rows::AXIS_A, |p| p.axis_a.is_some()),
    (rows::AXIS_B, |p| p.axis_b.is_some()),
];

/// Whether profile row `spec` belongs to `p`'s machine (not the row of an axis it lacks).
pub fn profile_row_present(spec: &FieldSpec<MachineProfile>, p: &MachineProfile) -> bool {
    PROFILE_AXES
        .iter()
        .filter(|(rows, _)| rows.iter().any(|r| r.is(spec)))
        .all(|(_, has)| has(p))
}

/// Whether profile row `spec` is used with `p`'s G-code dialect and controller.
pub fn profile_row_applies(spec: &FieldSpec<MachineProfile>, p: &MachineProfile) -> bool {
    PROFILE_APPLIES
        .iter()
        .filter(|(rows, _)| rows.iter().any(|r| r.is(spec)))
        .all(|(_, when)| when(p))
}

/// Every row handle an editor uses, by table: (profile rows, pen rows, hatch rows).
pub fn editor_rows() -> EditorRows {
    use rows::*;
    let mut profile = vec![PROFILE_NAME];
    profile.extend(PROFILE_APPLIES.iter().flat_map(|(r, _)| r.iter().copied()));
    profile.extend(PROFILE_AXES.iter().flat_map(|(r, _)| r.iter().copied()));
    let pen = vec![
        PEN_SPEED,
        PEN_POWER,
        PEN_FREQUENCY,
        PEN_PASSES,
        PEN_SEAM_WIDTH,
    ];
    let hatch = vec![HATCH_SPACING, HATCH_ANGLE, HATCH_EDGE];
    (profile, pen, hatch)
}

/// The keys of `rows` whose table has no such row.
pub fn unresolved<T>(rows: &[Row<T>]) -> Vec<&'static str> {
    rows.iter()
        .filter(|r| r.spec().is_none())
        .map(|r| r.key)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_unique_and_words_carry_units() {
        let keys: Vec<&str> = profile_specs().iter().map(|s| s.key).collect();
        let mut sorted = keys.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), keys.len());
        let v = profile_specs()
            .into_iter()
            .find(|s| s.key == "axis_x.max_velocity_mm_s")
            .unwrap();
        assert_eq!(v.words(), "Base X max velocity (mm/s)");
    }

    #[test]
    fn rules_and_differences() {
        let specs = profile_specs();
        let mut p = MachineProfile::default();
        assert!(check_all(&specs, &p).is_ok());
        let old = p.clone();
        p.axis_x.max_velocity_mm_s = 100.0;
        p.name = "other".into();
        let d = differences(&specs, &old, &p);
        assert_eq!(d.len(), 1, "{d:?}");
        assert!(d[0].starts_with("base X max velocity ") && d[0].ends_with(" → 100 mm/s"));
        p.field_mm[0] = -1.0;
        let e = check_all(&specs, &p).unwrap_err();
        assert_eq!(
            e.to_string(),
            "Field width (mm) must be a positive number, not -1"
        );
        assert_eq!(e.key, "field_mm[0]");
        // a size beyond any machine is refused too (artwork is bounded the same way)
        p.field_mm[0] = 2e6;
        let e = check_all(&specs, &p).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("must be at most 1000000 mm (1 km), not 2000000"),
            "{e}"
        );
        let pen = pen_specs();
        let mut a = Pen::default();
        let b = a.clone();
        a.mark_speed_mm_s = Some(300.0);
        assert_eq!(
            differences(&pen, &b, &a),
            vec!["mark speed none → 300 mm/s"]
        );
        let passes = pen.iter().find(|s| s.key == "passes").unwrap();
        let mut bad = Pen::default();
        assert_eq!(
            passes.set_text(&mut bad, " x ").unwrap_err().to_string(),
            "Passes must be a whole number (0 or more), not 'x'"
        );
        assert_eq!(
            passes
                .set_text(&mut bad, "5000000000")
                .unwrap_err()
                .to_string(),
            "Passes must be smaller, not 5000000000"
        );
        let speed = pen.iter().find(|s| s.key == "mark_speed_mm_s").unwrap();
        assert_eq!(
            speed.set_text(&mut bad, "fast").unwrap_err().to_string(),
            "Mark speed (mm/s) must be a number, not 'fast'"
        );
        assert_eq!(
            speed.set_text(&mut bad, "inf").unwrap_err().to_string(),
            "Mark speed (mm/s) must be a finite number, not 'inf'"
        );
        let marked = pen.iter().find(|s| s.key == "enabled").unwrap();
        assert_eq!(
            marked.set_text(&mut bad, "yes").unwrap_err().to_string(),
            "Marked chosen from a list"
        );
        let mut seamed = Pen {
            seam: crate::geom::seam::SeamForm::Interlocked { band_mm: 0.5 },
            ..Pen::default()
        };
        let width = pen.iter().find(|s| s.key == "seam_mm").unwrap();
        assert_eq!(
            width.set_text(&mut seamed, "wide").unwrap_err().to_string(),
            "Seam width (mm) 'wide' is not a number"
        );
        bad.passes = 0;
        assert!(passes.check(&bad).is_err());
    }

    /// Every row an editor names resolves in its table, and the check finds a planted handle
    /// whose key the table lacks.
    #[test]
    fn every_editor_row_resolves_and_a_planted_key_is_found() {
        let (profile, pen, hatch) = editor_rows();
        assert!(profile.len() > 10 && pen.len() == 5 && hatch.len() == 3);
        assert!(
            unresolved(&profile).is_empty(),
            "{:?}",
            unresolved(&profile)
        );
        assert!(unresolved(&pen).is_empty(), "{:?}", unresolved(&pen));
        assert!(unresolved(&hatch).is_empty(), "{:?}", unresolved(&hatch));
        let mut planted = pen.clone();
        planted.push(Row::new("mark_sped_mm_s", pen_specs));
        assert_eq!(unresolved(&planted), ["mark_sped_mm_s"]);
        // every choice's value has its words
        for m in [GcodeMode::Tcp, GcodeMode::StageScanner, GcodeMode::Linuxcnc] {
            assert_ne!(label_of(GCODE_DIALECTS, &m), "?");
        }
        for c in [ControllerKind::Ideal, ControllerKind::Linuxcnc] {
            assert_ne!(label_of(CONTROLLERS, &c), "?");
        }
        for m in [MotionMode::Auto, MotionMode::Step, MotionMode::OnTheFly] {
            assert_ne!(label_of(MOTION_MODES, &m), "?");
        }
    }
}
