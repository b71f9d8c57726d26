//! The document model: geometries, machine profile, solver settings, scan fields and plans.

mod geometry;
mod plan;
mod profile;
mod project;
mod settings;

pub use geometry::{Geometry, Source};
pub use plan::{
    GenerationRecord, Metrics, MotionFigures, Plan, ScanField, StageTimes, Step, TimeBreakdown,
};
pub use profile::{
    AxisLimits, GcodeDialect, GcodeMode, LaserTiming, MachineProfile, ProfileError, ScannerSpeeds,
    BUILTIN, PROFILE_VERSION,
};
pub use project::{load_project, save_project, write_atomic, ProjectError, PROJECT_VERSION};
pub use settings::{
    Algo, CostModel, FieldsMode, GaParams, MotionMode, RouteGaSettings, SolverSettings,
    StageRouteKind, VertexMode,
};

use crate::import::Warning;
use serde::{Deserialize, Serialize};

/// Everything an operator works on: imported artwork, machine, settings, fields and plans.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct Document {
    /// Where the artwork came from (SVG path), if known.
    pub source: Option<String>,
    /// Page size of the imported artwork in mm (width, height), used for the Y flip.
    pub page_mm: [f64; 2],
    /// Imported geometries; a geometry's index is its id.
    pub geometries: Vec<Geometry>,
    /// Warnings from the import (skipped elements, degenerate paths).
    pub warnings: Vec<Warning>,
    /// The machine the job is planned for.
    pub profile: MachineProfile,
    /// Solver settings.
    pub settings: SolverSettings,
    /// Current scan fields (automatic placement plus operator edits).
    pub fields: Vec<ScanField>,
    /// Results kept for comparison, newest last.
    pub plans: Vec<Plan>,
}
