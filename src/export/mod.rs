//! Export of a plan, all from its lowered toolpath: G-code (tool-centre or stage + scanner),
//! JSON report, SVG preview, sampled trajectory; and the geometry as SVG.

mod gcode;
mod guard;
mod report;
mod svg_preview;
mod trajectory;

pub use gcode::{write_gcode, GcodeError};
pub use guard::{check_outputs, OutputClash};
pub use report::{report_json, Report};
pub use svg_preview::{geometry_svg, preview_svg};
pub use trajectory::{
    trajectory_csv, trajectory_period_s, PeriodError, MAX_PERIOD_S, MIN_PERIOD_S, TRAJECTORY_HEADER,
};
