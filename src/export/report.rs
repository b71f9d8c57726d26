//! The JSON report (`--report`): fields, order, metrics, settings, history, warnings.

use crate::document::{GenerationRecord, Metrics, Plan, SolverSettings};
use crate::import::Warning;
use serde::Serialize;

/// One field in the report.
#[derive(Debug, Serialize)]
pub struct ReportField {
    /// Field id.
    pub id: usize,
    /// Centre (base position), mm.
    pub center: [f64; 2],
    /// Size, mm.
    pub size: [f64; 2],
    /// Locked by the operator.
    pub locked: bool,
    /// Geometries allocated to it.
    pub geometries: usize,
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
    /// Algorithm.
    pub algo: String,
    /// Fields in visiting order.
    pub fields: Vec<ReportField>,
    /// Strokes in marking order.
    pub order: Vec<ReportStep>,
    /// Metrics.
    pub metrics: &'a Metrics,
    /// Settings used.
    pub settings: &'a SolverSettings,
    /// GA convergence history.
    pub history: &'a [GenerationRecord],
    /// Import warnings.
    pub warnings: Vec<String>,
}

/// Builds the report as pretty JSON text.
pub fn report_json(
    source: &str,
    plan: &Plan,
    settings: &SolverSettings,
    warnings: &[Warning],
) -> String {
    let r = Report {
        source,
        version: env!("CARGO_PKG_VERSION"),
        algo: format!("{:?}", plan.algo).to_lowercase(),
        fields: plan
            .fields
            .iter()
            .map(|f| ReportField {
                id: f.id,
                center: [f.center.x, f.center.y],
                size: f.size,
                locked: f.locked,
                geometries: f.geometries.len(),
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
        settings,
        history: &plan.history,
        warnings: warnings.iter().map(|w| w.to_string()).collect(),
    };
    serde_json::to_string_pretty(&r).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}
