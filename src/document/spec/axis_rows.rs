//! The rows of the axes beyond X/Y (Z, A, B): each exists in a profile only when the machine has
//! the axis ([`super::PROFILE_APPLIES`] shows them then), in the axis's own unit.

use super::{parse_number, show_opt, FieldSpec, Rule};
use crate::document::{ExtraAxis, MachineProfile};

/// A number of an axis beyond X/Y: unset when the profile has no such axis (nothing to check),
/// set only on an axis the profile has.
macro_rules! axis_number {
    ($label:expr, $unit:expr, $key:expr, $help:expr, $rule:expr, $get:expr, $field:ident) => {
        FieldSpec {
            label: $label,
            unit: $unit,
            key: $key,
            help: $help,
            rule: $rule,
            optional: true,
            shapes_plan: true,
            show: |p| show_opt($get(p).map(|a: &ExtraAxis| a.$field)),
            number: |p| $get(p).map(|a: &ExtraAxis| a.$field),
            parse: |p, s| {
                let v = parse_number(s)?;
                set(p, $key, |a| a.$field = v);
                Ok(())
            },
        }
    };
}

/// One end of an axis's travel: empty text makes it endless.
macro_rules! travel_end {
    ($label:expr, $unit:expr, $key:expr, $help:expr, $get:expr, $end:expr) => {
        FieldSpec {
            label: $label,
            unit: $unit,
            key: $key,
            help: $help,
            rule: Rule::Finite,
            optional: true,
            shapes_plan: true,
            show: |p| show_opt($get(p).and_then(|a: &ExtraAxis| a.travel).map(|t| t[$end])),
            number: |p| $get(p).and_then(|a: &ExtraAxis| a.travel).map(|t| t[$end]),
            parse: |p, s| {
                let v = if s.trim().is_empty() {
                    None
                } else {
                    Some(parse_number(s)?)
                };
                set(p, $key, |a| a.travel = travel_with(a.travel, $end, v));
                Ok(())
            },
        }
    };
}

/// `travel` with end `end` (0: from, 1: to) set to `v`: a travel set from nothing is symmetric
/// about zero; no value makes the axis endless.
fn travel_with(travel: Option<[f64; 2]>, end: usize, v: Option<f64>) -> Option<[f64; 2]> {
    let v = v?;
    let mut t = travel.unwrap_or([-v.abs(), v.abs()]);
    t[end] = v;
    Some(t)
}

/// Changes the axis that `key` names (`axis_a.…`), when the profile has it.
fn set(p: &mut MachineProfile, key: &str, f: impl FnOnce(&mut ExtraAxis)) {
    let axis = match key.as_bytes().get(5) {
        Some(b'z') => p.axis_z.as_mut().map(|a| &mut a.0),
        Some(b'a') => p.axis_a.as_mut().map(|a| &mut a.0),
        Some(b'b') => p.axis_b.as_mut().map(|a| &mut a.0),
        _ => None,
    };
    if let Some(a) = axis {
        f(a);
    }
}

fn z(p: &MachineProfile) -> Option<&ExtraAxis> {
    p.axis_z.as_ref().map(|a| &a.0)
}
fn a(p: &MachineProfile) -> Option<&ExtraAxis> {
    p.axis_a.as_ref().map(|a| &a.0)
}
fn b(p: &MachineProfile) -> Option<&ExtraAxis> {
    p.axis_b.as_ref().map(|a| &a.0)
}

/// Help of Z's travel.
const Z_TRAVEL: &str = "empty: no limit";
/// Help of a rotary's travel.
const ROTARY_TRAVEL: &str = "empty: endless (the axis turns freely)";

/// The Z, A and B rows, in that order.
pub(super) fn axis_specs() -> Vec<FieldSpec<MachineProfile>> {
    use Rule::{NonNegative, Positive};
    vec![
        axis_number!(
            "Axis Z max velocity",
            "mm/s",
            "axis_z.max_velocity_mm_s",
            "",
            Positive,
            z,
            max_velocity
        ),
        axis_number!(
            "Axis Z max accel",
            "mm/s²",
            "axis_z.max_accel_mm_s2",
            "",
            Positive,
            z,
            max_accel
        ),
        axis_number!(
            "Axis Z settling time",
            "s",
            "axis_z.settle_s",
            "after every move",
            NonNegative,
            z,
            settle_s
        ),
        travel_end!(
            "Axis Z travel from",
            "mm",
            "axis_z.travel_mm[0]",
            Z_TRAVEL,
            z,
            0
        ),
        travel_end!(
            "Axis Z travel to",
            "mm",
            "axis_z.travel_mm[1]",
            Z_TRAVEL,
            z,
            1
        ),
        axis_number!(
            "Axis A max velocity",
            "deg/s",
            "axis_a.max_velocity_deg_s",
            "rotation about X",
            Positive,
            a,
            max_velocity
        ),
        axis_number!(
            "Axis A max accel",
            "deg/s²",
            "axis_a.max_accel_deg_s2",
            "",
            Positive,
            a,
            max_accel
        ),
        axis_number!(
            "Axis A settling time",
            "s",
            "axis_a.settle_s",
            "after every move",
            NonNegative,
            a,
            settle_s
        ),
        travel_end!(
            "Axis A travel from",
            "deg",
            "axis_a.travel_deg[0]",
            ROTARY_TRAVEL,
            a,
            0
        ),
        travel_end!(
            "Axis A travel to",
            "deg",
            "axis_a.travel_deg[1]",
            ROTARY_TRAVEL,
            a,
            1
        ),
        axis_number!(
            "Axis B max velocity",
            "deg/s",
            "axis_b.max_velocity_deg_s",
            "rotation about Y",
            Positive,
            b,
            max_velocity
        ),
        axis_number!(
            "Axis B max accel",
            "deg/s²",
            "axis_b.max_accel_deg_s2",
            "",
            Positive,
            b,
            max_accel
        ),
        axis_number!(
            "Axis B settling time",
            "s",
            "axis_b.settle_s",
            "after every move",
            NonNegative,
            b,
            settle_s
        ),
        travel_end!(
            "Axis B travel from",
            "deg",
            "axis_b.travel_deg[0]",
            ROTARY_TRAVEL,
            b,
            0
        ),
        travel_end!(
            "Axis B travel to",
            "deg",
            "axis_b.travel_deg[1]",
            ROTARY_TRAVEL,
            b,
            1
        ),
    ]
}
