//! SVG renderings: the planned path over the fields, and the bare geometry to be marked.

use crate::document::{Geometry, Plan};
use crate::motion::Toolpath;
use std::fmt::Write;

fn pts_attr(points: &[crate::geom::Pt]) -> String {
    let mut s = String::with_capacity(points.len() * 16);
    for p in points {
        let _ = write!(s, "{:.4},{:.4} ", p.x, p.y);
    }
    s.trim_end().to_string()
}

fn header(out: &mut String, w: f64, h: f64, min_x: f64, min_y: f64) {
    let _ = writeln!(
        out,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.3}mm\" height=\"{h:.3}mm\" viewBox=\"{min_x:.3} {min_y:.3} {w:.3} {h:.3}\">"
    );
}

/// The plan as an SVG in mm: scan fields as translucent numbered squares (visiting order), the
/// toolpath's marks in black, its idle moves as dashed red lines, on the fly the stage's route
/// in blue, start (green) and end (red) markers.
pub fn preview_svg(toolpath: &Toolpath, plan: &Plan, page_mm: [f64; 2]) -> String {
    let mut b = crate::geom::BBox {
        min_x: 0.0,
        min_y: 0.0,
        max_x: page_mm[0],
        max_y: page_mm[1],
    };
    for f in &plan.fields {
        b = b.union(f.bbox());
    }
    let mut out = String::new();
    header(&mut out, b.width(), b.height(), b.min_x, b.min_y);
    out.push_str("<g id=\"fields\" fill=\"#3b82f6\" fill-opacity=\"0.08\" stroke=\"#3b82f6\" stroke-width=\"0.3\">\n");
    for (k, f) in plan.fields.iter().enumerate() {
        let fb = f.bbox();
        let _ = writeln!(
            out,
            "<rect x=\"{:.3}\" y=\"{:.3}\" width=\"{:.3}\" height=\"{:.3}\"/><text x=\"{:.3}\" y=\"{:.3}\" font-size=\"6\" fill=\"#1d4ed8\" fill-opacity=\"1\" stroke=\"none\">{} (#{})</text>",
            fb.min_x, fb.min_y, fb.width(), fb.height(), fb.min_x + 1.5, fb.min_y + 6.5, k + 1, f.id
        );
    }
    out.push_str("</g>\n<g id=\"marks\" fill=\"none\" stroke=\"black\" stroke-width=\"0.25\">\n");
    let mut ends = Vec::with_capacity(toolpath.strokes.len());
    for k in 0..toolpath.strokes.len() {
        let path = toolpath.stroke_points(k);
        let _ = writeln!(out, "<polyline points=\"{}\"/>", pts_attr(path));
        if let (Some(&a), Some(&z)) = (path.first(), path.last()) {
            ends.push((a, z));
        }
    }
    out.push_str("</g>\n<g id=\"idle\" fill=\"none\" stroke=\"#dc2626\" stroke-width=\"0.2\" stroke-dasharray=\"1 0.7\">\n");
    for w in ends.windows(2) {
        let (a, b) = (w[0].1, w[1].0);
        let _ = writeln!(
            out,
            "<line x1=\"{:.4}\" y1=\"{:.4}\" x2=\"{:.4}\" y2=\"{:.4}\"/>",
            a.x, a.y, b.x, b.y
        );
    }
    out.push_str("</g>\n");
    stage_route(&mut out, toolpath);
    if let (Some(first), Some(last)) = (ends.first(), ends.last()) {
        let _ = writeln!(
            out,
            "<circle id=\"start\" cx=\"{:.3}\" cy=\"{:.3}\" r=\"1.2\" fill=\"#16a34a\"/>\n<circle id=\"end\" cx=\"{:.3}\" cy=\"{:.3}\" r=\"1.2\" fill=\"#dc2626\"/>",
            first.0.x, first.0.y, last.1.x, last.1.y
        );
    }
    out.push_str("</svg>\n");
    out
}

/// Sampling step of the stage route in the preview, s (5 ms: under 2.5 mm at 500 mm/s).
const ROUTE_PREVIEW_STEP_S: f64 = 5e-3;

/// On the fly: the stage's route as a blue polyline (nothing for step-and-scan).
fn stage_route(out: &mut String, toolpath: &Toolpath) {
    let Some(route) = &toolpath.route else {
        return;
    };
    let samples = (toolpath.duration_s() / ROUTE_PREVIEW_STEP_S).ceil() as usize;
    let points: Vec<crate::geom::Pt> = (0..=samples)
        .map(|k| route.position((k as f64 * ROUTE_PREVIEW_STEP_S).min(toolpath.duration_s())))
        .collect();
    let _ = writeln!(
        out,
        "<polyline id=\"stage-route\" fill=\"none\" stroke=\"#2563eb\" stroke-width=\"0.4\" points=\"{}\"/>",
        pts_attr(&points)
    );
}

/// Exactly the geometry to be marked, as an SVG in mm (user unit = 1 mm, page as given): one
/// `<path>` per geometry, closed ones with `Z`.
pub fn geometry_svg(geometries: &[Geometry], page_mm: [f64; 2]) -> String {
    let mut out = String::new();
    header(&mut out, page_mm[0], page_mm[1], 0.0, 0.0);
    out.push_str("<g fill=\"none\" stroke=\"black\" stroke-width=\"0.1\">\n");
    for g in geometries {
        let mut d = String::new();
        for (k, p) in g.points.iter().enumerate() {
            let _ = write!(
                d,
                "{}{:.5} {:.5} ",
                if k == 0 { "M" } else { "L" },
                p.x,
                p.y
            );
        }
        if g.closed {
            d.push('Z');
        }
        let _ = writeln!(out, "<path d=\"{}\"/>", d.trim_end());
    }
    out.push_str("</g>\n</svg>\n");
    out
}
