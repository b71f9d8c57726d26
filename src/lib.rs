//! # galvoplan
//!
//! CAM for redundant laser-marking machines: a fast galvanometer scanner with a small scan field
//! carried by a slow XY base stage with a large stroke. galvoplan imports SVG artwork, places scan
//! fields, orders the geometries (which field after which, which geometry after which, where each
//! starts) and exports the tool-centre-point path as G-code with a JSON report.
//!
//! Every stage is a pure function on data taking a [`job::JobCtx`] (cancel token, progress sink,
//! optional run recorder); the CLI, the GUI, the tests and the benchmarks call the same functions:
//!
//! ```text
//! import::import_svg → fields::place_fields → order::order_plan → export::{write_gcode, report_json}
//! ```
//! [`pipeline`] strings them together.

pub mod bench;
pub mod codes;
pub mod document;
pub mod export;
pub mod fields;
pub mod geom;
pub mod hatch;
pub mod import;
pub mod job;
pub mod motion;
pub mod order;
pub mod pipeline;
#[cfg(feature = "rerun")]
pub mod record;
pub mod tray;

#[cfg(feature = "gui")]
pub mod app;
