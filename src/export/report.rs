//! The JSON report (`--report`): fields, order, metrics, settings, history, warnings.

use crate::document::{
    GenerationRecord, Layer, MachineProfile, Metrics, PartRecord, Plan, Pose, SolverSettings,
    Warning,
};
use serde::Serialize;

/// One field in the report.
#[derive(Debug, Serialize)]
pub struct ReportField {
    /// Its number, 1…n in visiting order (what the G-code comments, the preview and the GUI
    /// call it).
    pub number: usize,
    /// Field id (what `order[].field` refers to).
    pub id: usize,
    /// Centre (base position), mm.
    pub center: [f64; 2],
    /// Size, mm.
    pub size: [f64; 2],
    /// Locked by the operator.
    pub locked: bool,
    /// Geometries allocated to it.
    pub geometries: usize,
    /// Where Z, A and B stand while it is marked (mm, deg), on a machine with such axes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pose: Option<Pose>,
}

/// One stroke in the report.
#[derive(Debug, Serialize)]
pub struct ReportStep {
    /// Geometry index (document order of the import).
    pub geometry: usize,
    /// Field id.
    pub field: usize,
    /// Start vertex.
    pub start_vertex: usize,
    /// Marked backwards.
    pub reversed: bool,
}

/// The report document.
#[derive(Debug, Serialize)]
pub struct Report<'a> {
    /// Source file.
    pub source: &'a str,
    /// galvoplan version.
    pub version: &'static str,
    /// The plan's name.
    pub plan: &'a str,
    /// Algorithm, as the CLI spells it (`hha`, `hga`, `baseline`, `as-is`).
    pub algo: &'static str,
    /// Fields in visiting order.
    pub fields: Vec<ReportField>,
    /// Strokes in marking order.
    pub order: Vec<ReportStep>,
    /// Metrics.
    pub metrics: &'a Metrics,
    /// The solver settings the plan was made with.
    pub settings: &'a SolverSettings,
    /// The machine profile it was made for.
    pub profile: &'a MachineProfile,
    /// The layers and their pens it was made with (speeds, powers, passes, hatch).
    pub pens: &'a [Layer],
    /// GA convergence history.
    pub history: &'a [GenerationRecord],
    /// Seams: where artwork larger than a field was cut.
    pub seams: ReportSeams<'a>,
    /// The tray's parts: number, cell, position, serial and every text as marked (absent when
    /// the job is not a tray).
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    pub parts: &'a [PartRecord],
    /// The cylinder of a cylinder job (absent on a flat one); each field's `pose.a_deg` is its
    /// strip's angle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cylinder: Option<ReportCylinder>,
    /// Import warnings.
    pub warnings: Vec<String>,
}

/// A cylinder job in the report.
#[derive(Debug, Serialize)]
pub struct ReportCylinder {
    /// Diameter, mm.
    pub diameter_mm: f64,
    /// Circumference (the unrolled height), mm.
    pub circumference_mm: f64,
    /// The scanner's depth of focus, mm.
    pub depth_of_focus_mm: Option<f64>,
    /// The strips' height in focus (arc), mm.
    pub strip_height_mm: Option<f64>,
}

/// The seams in the report.
#[derive(Debug, Serialize)]
pub struct ReportSeams<'a> {
    /// Seam lines that cut something.
    pub count: usize,
    /// Their length through marked area, mm.
    pub length_mm: f64,
    /// Cuts made.
    pub cuts: usize,
    /// Strokes cut into pieces.
    pub split_strokes: usize,
    /// Length marked twice on purpose (doubled overlap seams), mm: what a checker allows above
    /// the artwork's length.
    pub extra_marked_mm: f64,
    /// The tiling's cell borders (none: nothing was larger than a field).
    pub tiling: Option<&'a crate::geom::tiling::Tiling>,
    /// Each seam line and its stretches through marked area.
    pub lines: &'a [crate::geom::seam::SeamLine],
}

/// Builds the report as pretty JSON text: everything of the plan's own (its inputs, enough to
/// plan it again, whatever the document's settings are now).
pub fn report_json(source: &str, plan: &Plan, warnings: &[Warning]) -> String {
    let r = Report {
        source,
        version: env!("CARGO_PKG_VERSION"),
        plan: &plan.name,
        algo: plan.algo.label(),
        fields: plan
            .fields
            .iter()
            .enumerate()
            .map(|(k, f)| ReportField {
                number: k + 1,
                id: f.id,
                center: [f.center.x, f.center.y],
                size: f.size,
                locked: f.locked,
                geometries: f.geometries.len(),
                pose: (!plan.profile.extra_axes().is_empty()).then_some(f.pose),
            })
            .collect(),
        order: plan
            .order
            .iter()
            .map(|s| ReportStep {
                geometry: s.geometry,
                field: s.field,
                start_vertex: s.start_vertex,
                reversed: s.reversed,
            })
            .collect(),
        metrics: &plan.metrics,
        settings: &plan.settings,
        profile: &plan.profile,
        pens: &plan.layers,
        history: &plan.history,
        parts: &plan.parts,
        cylinder: plan.settings.cylinder.map(|c| {
            let dof = plan.profile.scanner.depth_of_focus_mm;
            ReportCylinder {
                diameter_mm: c.diameter_mm,
                circumference_mm: c.circumference_mm(),
                depth_of_focus_mm: dof,
                strip_height_mm: dof.map(|d| c.strip_height_mm(d, plan.profile.field_mm[1])),
            }
        }),
        seams: ReportSeams {
            count: plan.seams.seams(),
            length_mm: plan.seams.length_mm(),
            cuts: plan.seams.cuts,
            split_strokes: plan.seams.split_strokes,
            extra_marked_mm: plan.seams.extra_marked_mm,
            tiling: plan.tiling.as_ref(),
            lines: &plan.seams.lines,
        },
        warnings: warnings.iter().map(|w| w.to_string()).collect(),
    };
    serde_json::to_string_pretty(&r).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}
