//! Export of a plan: G-code (TCP path), JSON report, SVG preview, and the geometry as SVG.

mod gcode;
mod report;
mod svg_preview;

pub use gcode::write_gcode;
pub use report::{report_json, Report};
pub use svg_preview::{geometry_svg, preview_svg};
