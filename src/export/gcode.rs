//! G-code for the tool-centre-point path, per the contract in DESIGN.md.

use crate::document::{Geometry, MachineProfile, Plan};
use crate::geom::Pt;
use std::fmt::Write;

/// Writes the plan as G-code: `G21`, `G90`; per stroke a `G0` to its start, the laser-on word
/// (with `S` power when the profile sets one), `G1` moves (feed on the first), the laser-off word.
/// A comment marks every field change. Y is mirrored about `page_height_mm` when the profile's
/// dialect says `flip_y`.
pub fn write_gcode(
    geometries: &[Geometry],
    plan: &Plan,
    profile: &MachineProfile,
    page_height_mm: f64,
    title: &str,
) -> String {
    let d = &profile.gcode;
    let prec = d.decimals;
    let map = |p: Pt| -> (f64, f64) {
        if d.flip_y {
            (p.x, page_height_mm - p.y)
        } else {
            (p.x, p.y)
        }
    };
    let num = |v: f64| -> String {
        let s = format!("{:.*}", prec, v);
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        if s == "-0" {
            "0".into()
        } else {
            s
        }
    };
    let on = match d.power {
        Some(s) => format!("{} S{}", d.laser_on, num(s)),
        None => d.laser_on.clone(),
    };
    let mut out = String::with_capacity(plan.order.len() * 64);
    let _ = writeln!(
        out,
        "; galvoplan {} — {}",
        env!("CARGO_PKG_VERSION"),
        title.replace('\n', " ")
    );
    let _ = writeln!(
        out,
        "; {} strokes in {} fields, marked {:.3} mm, idle {:.3} mm, base {:.3} mm",
        plan.order.len(),
        plan.fields.len(),
        plan.metrics.marked_mm,
        plan.metrics.idle_mm,
        plan.metrics.base_mm
    );
    out.push_str("G21\nG90\n");
    let _ = writeln!(out, "{}", d.laser_off);
    let mut current_field = None;
    for step in &plan.order {
        if current_field != Some(step.field) {
            current_field = Some(step.field);
            if let Some(f) = plan.fields.iter().find(|f| f.id == step.field) {
                let (x, y) = map(f.center);
                let _ = writeln!(out, "; field {} centre {} {}", f.id, num(x), num(y));
            }
        }
        let Some(g) = geometries.get(step.geometry) else {
            continue;
        };
        let path = g.marking_path(step.start_vertex, step.reversed);
        let Some((&first, rest)) = path.split_first() else {
            continue;
        };
        let (x, y) = map(first);
        let _ = writeln!(out, "G0 X{} Y{}", num(x), num(y));
        let _ = writeln!(out, "{on}");
        for (k, &p) in rest.iter().enumerate() {
            let (x, y) = map(p);
            if k == 0 {
                let _ = writeln!(out, "G1 X{} Y{} F{}", num(x), num(y), num(d.feed_mm_min));
            } else {
                let _ = writeln!(out, "G1 X{} Y{}", num(x), num(y));
            }
        }
        let _ = writeln!(out, "{}", d.laser_off);
    }
    out.push_str("; end\n");
    out
}
