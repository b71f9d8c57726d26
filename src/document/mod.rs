//! The document model: geometries, machine profile, solver settings, scan fields and plans.

mod artwork_import;
mod axes;
mod choices;
mod code;
mod cylinder;
mod geometry;
mod hatch;
mod inputs;
mod pens;
mod plan;
pub mod production;
mod profile;
mod project;
mod route;
pub mod runs;
mod settings;
pub mod spec;
pub mod validate;
mod warning;

pub use artwork_import::{ArtworkImport, LayerHidden, Place, PlaceError, SkippedLayer};
pub use axes::{AxisFileError, ExtraAxis, ExtraAxisId, LinearAxis, Pose, PoseError, RotaryAxis};
pub use code::{CodeKind, CodeOptions, CodeSpec, Ecc, CODE_LAYER};
pub use cylinder::{Cylinder, CylinderError, Predistorted, LANDING_TOL_MM};
pub use geometry::{is_hatch_output, Geometry, Run, RunOrder, Source, HATCH_LAYER_PREFIX};
pub use hatch::{
    FillRule, FillShapes, HatchSettings, HatchSpecError, HatchStyle, OutlineMode, MIN_SPACING_MM,
};
pub use inputs::{staleness, GeometryRevision, PlanInputs};
pub use pens::{
    colour_word, layer_label, parse_colour, passes_of, pen_of, sync_layers, validate_layers, Layer,
    MarkTiming, Pen, PenLibrary, PensError, DEFAULT_LAYER, MAX_PASSES, PENS_VERSION,
};
pub use plan::{
    GenerationRecord, Metrics, MotionFigures, MotionRegion, ObjectiveKind, Plan, ScanField,
    StageTimes, Step, TimeBreakdown,
};
pub use production::{
    DataTable, Numbering, PartRecord, PartSlot, Production, ProductionError, Serial, Stamp,
    TextAlign, TextTemplate, Tray, TraySettings, TraySetup,
};
pub use profile::{
    AxisLimits, Controller, ControllerKind, GcodeDialect, GcodeMode, LaserTiming, MachineProfile,
    ProfileError, ScannerSpeeds, BUILTIN, PROFILE_VERSION,
};
pub use project::{
    load_project, parse_project, save_project, write_atomic, write_atomic_with, ProjectError,
    PROJECT_VERSION,
};
pub use route::TimedRoute;
pub use settings::{
    Algo, CostModel, FieldsMode, GaParams, Motion, MotionMode, RouteGaSettings, SolverSettings,
    StageRouteKind, VertexMode,
};

use crate::geom::seam::{SeamForm, SeamStats};
use crate::geom::tiling::Tiling;
use serde::{Deserialize, Serialize};
pub use warning::{grouped, short_list, Warning, LIST_MAX};

/// The parts of the layer table and profile that decide the marked geometries: per layer its
/// name, whether it is enabled, its hatch and seam form; the field size (hatch is cut at the
/// seams of a tiling of field-sized cells).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DerivedKey {
    /// (name, enabled, hatch) per layer.
    pub layers: Vec<(String, bool, Option<HatchSettings>)>,
    /// Per layer: seam form, whether its passes are shifted, and then how many (1 otherwise).
    #[serde(default)]
    pub seams: Vec<(SeamForm, bool, u32)>,
    /// The tiling the operator set by moving seams (none: the planner's).
    #[serde(default)]
    pub tiling_set: Option<Tiling>,
    /// Scan-field size, mm.
    pub field_mm: [f64; 2],
}

impl DerivedKey {
    /// The key of a layer table on a field size, with the tiling the operator set.
    pub fn of(layers: &[Layer], field_mm: [f64; 2], tiling_set: Option<&Tiling>) -> Self {
        Self {
            layers: layers
                .iter()
                .map(|l| (l.name.clone(), l.pen.enabled, l.pen.hatch.clone()))
                .collect(),
            seams: layers
                .iter()
                // passes cut geometries of their own only when shifted: else a change of
                // passes needs no new geometries
                .map(|l| {
                    let shifted = l.pen.shift_passes && l.pen.passes > 1;
                    (l.pen.seam, shifted, if shifted { l.pen.passes } else { 1 })
                })
                .collect(),
            tiling_set: tiling_set.cloned(),
            field_mm,
        }
    }
}

/// Everything an operator works on: imported artwork, machine, settings, fields and plans.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct Document {
    /// Where the artwork came from (SVG path), if known.
    pub source: Option<String>,
    /// Page size of the imported artwork in mm (width, height), used for the Y flip.
    pub page_mm: [f64; 2],
    /// The artwork as imported (outlines only, every layer), from which `geometries` are
    /// made by the layers' pens (see `solve::derive_geometries`).
    #[serde(default)]
    pub artwork: Vec<Geometry>,
    /// How the artwork was imported (placement, hidden layers).
    #[serde(default)]
    pub import: ArtworkImport,
    /// The layers of the artwork and their pens, in order of first appearance.
    #[serde(default)]
    pub layers: Vec<Layer>,
    /// What `geometries` were last made from (none: not made yet, they are the artwork).
    #[serde(default)]
    pub derived_with: Option<DerivedKey>,
    /// The geometries to mark: the enabled layers' artwork with their hatch; a geometry's
    /// index is its id (fields and plans refer to it).
    pub geometries: Vec<Geometry>,
    /// The geometries before a placement cut them at field borders (the split setting, or the
    /// whole-or-cut choice on the fly): a placement that may not cut (step-and-scan without
    /// the split setting) starts again from these. Not saved: a project reopens as it was cut.
    #[serde(skip)]
    pub uncut_geometries: Option<Vec<Geometry>>,
    /// The seams of `uncut_geometries` (the hatch's cut alone).
    #[serde(skip)]
    pub uncut_seams: SeamStats,
    /// The tiling that cuts what is larger than a field (none: nothing is).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tiling: Option<Tiling>,
    /// What the cuts of `geometries` at the tiling's seams did.
    #[serde(default)]
    pub seams: SeamStats,
    /// The tiling as the operator set it by moving seams (none: the planner chooses; see
    /// `pipeline::move_seam`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tiling_set: Option<Tiling>,
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
    /// Revision of `geometries`, raised whenever they change ([`Document::set_geometries`]);
    /// each plan names the revision it was planned on.
    #[serde(default)]
    pub geometry_rev: u64,
    /// Earlier geometry lists that plans were planned on and still refer to.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub kept_geometries: Vec<GeometryRevision>,
    /// A production job: the part, its texts with fields and the tray it is repeated over
    /// (none: the artwork is marked once, as imported). `artwork` is then the whole tray, made
    /// from it by `crate::tray::expand`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub production: Option<Production>,
    /// The parts of the tray as `artwork` marks them (number, cell, serial, texts).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub parts: Vec<PartRecord>,
}

impl Document {
    /// The profile the document's fields are placed and edited with: on a cylinder job the
    /// strips on its unrolled surface ([`Cylinder::reach_profile`]), else the machine's.
    pub fn reach_profile(&self) -> std::borrow::Cow<'_, MachineProfile> {
        Cylinder::reach_profile(&self.profile, self.settings.cylinder)
    }
    /// Checks profile, settings and layers, that every geometry's layer is in the table and
    /// that fields and plans name geometries the document has. The CLI, the GUI and the project
    /// loader all call it.
    pub fn validate(&self) -> Result<(), validate::InvalidValue> {
        use crate::geom::{within_reach_bound, MAX_COORD_MM};
        use validate::InvalidValue;
        self.profile.validate()?;
        self.settings.validate()?;
        validate_layers(&self.layers)?;
        for (k, g) in self.artwork.iter().chain(&self.geometries).enumerate() {
            if let Some(p) = g.points.iter().find(|&&p| !within_reach_bound(p)) {
                return Err(InvalidValue::new(
                    format!("A point of geometry {} ({})", k + 1, g.source.element),
                    "points",
                    format!("({:e}, {:e}) mm", p.x, p.y),
                    format!("within ±{MAX_COORD_MM:e} mm"),
                ));
            }
            if !self.layers.is_empty() && !self.layers.iter().any(|l| l.name == g.layer) {
                return Err(InvalidValue::new(
                    format!("The layer of geometry {}", k + 1),
                    "layer",
                    format!("'{}'", g.layer),
                    "a layer of the layer table",
                ));
            }
        }
        if let Some(f) = self.fields.iter().find(|f| !within_reach_bound(f.center)) {
            return Err(InvalidValue::new(
                format!("The centre of scan field {}", f.id),
                "center",
                format!("({:e}, {:e}) mm", f.center.x, f.center.y),
                format!("within ±{MAX_COORD_MM:e} mm"),
            ));
        }
        let n = self.geometries.len();
        let held = self
            .fields
            .iter()
            .flat_map(|f| f.geometries.iter().map(move |&g| (f.id, g, n)));
        // a plan names the geometries of its own revision (kept when they changed since)
        let planned = self.plans.iter().flat_map(|p| {
            let n = self.plan_geometries(p).map_or(0, <[Geometry]>::len);
            p.order.iter().map(move |s| (s.field, s.geometry, n))
        });
        if let Some((field, g, n)) = held.chain(planned).find(|&(_, g, n)| g >= n) {
            return Err(InvalidValue::new(
                format!("A geometry of scan field {field}"),
                "geometries",
                g,
                format!("one of the document's {n} geometries"),
            ));
        }
        Ok(())
    }
}
