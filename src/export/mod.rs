//! Export of a plan, all from its lowered toolpath: G-code (tool-centre or stage + scanner),
//! JSON report, SVG preview, sampled trajectory; and the geometry as SVG.

mod gcode;
mod guard;
mod linuxcnc;
mod linuxcnc_config;
mod parts_log;
mod report;
mod stream;
mod svg_preview;
mod trajectory;

pub use gcode::{write_gcode, write_gcode_to, GcodeError};
pub use guard::{check_outputs, OutputClash};
pub use linuxcnc_config::{linuxcnc_config, ConfigFile, LIMIT_MARGIN_MM};
pub use parts_log::{append_parts_log, parts_log_rows, PARTS_LOG_HEADER};
pub use report::{report_json, Report};
pub use stream::{stream_text, StreamError, StreamFigures, DEVIATION_SUBSAMPLES};
pub use svg_preview::{geometry_svg, preview_svg};
pub use trajectory::{
    trajectory_csv, trajectory_period_s, waypoints_csv, PeriodError, MAX_PERIOD_S, MIN_PERIOD_S,
    TRAJECTORY_HEADER,
};
