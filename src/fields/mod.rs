//! Scan-field placement and allocation of geometries to fields.

mod greedy;
mod reach;

pub use greedy::greedy_fields;
pub use reach::{center_range, check_reach, Span};

use crate::document::{FieldsMode, Geometry, MachineProfile, ScanField, SolverSettings};
use crate::job::{Cancelled, JobCtx};
use thiserror::Error;

/// Slack when testing whether a geometry lies inside a field, mm.
pub const INSIDE_EPS_MM: f64 = 1e-7;

/// Why fields could not be placed.
#[derive(Debug, Error)]
pub enum FieldError {
    /// Geometries larger than one scan field.
    #[error("{} {} larger than the {:.1} × {:.1} mm scan field: {}", .list.len(), if .list.len() == 1 { "geometry is" } else { "geometries are" }, .field_mm[0], .field_mm[1], .list.join("; "))]
    Oversize {
        /// Each offending geometry, described with its size.
        list: Vec<String>,
        /// Field size.
        field_mm: [f64; 2],
    },
    /// Geometries the laser cannot reach from any base position.
    #[error("{} {} out of reach (base stroke {:.1} × {:.1} mm, laser reaches x and y in [{:.1}, {:.1}] mm): {}", .list.len(), if .list.len() == 1 { "geometry is" } else { "geometries are" }, .stroke_mm[0], .stroke_mm[1], -.field_mm[0] / 2.0, .stroke_mm[0] + .field_mm[0] / 2.0, .list.join("; "))]
    OutOfReach {
        /// Each offending geometry, described with its position.
        list: Vec<String>,
        /// Base stroke.
        stroke_mm: [f64; 2],
        /// Field size.
        field_mm: [f64; 2],
    },
    /// The operator cancelled.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// Places scan fields for `geometries` with the mode in `settings` and allocates every geometry
/// to exactly one field (`ScanField::geometries`).
pub fn place_fields(
    geometries: &[Geometry],
    profile: &MachineProfile,
    settings: &SolverSettings,
    ctx: &JobCtx,
) -> Result<Vec<ScanField>, FieldError> {
    check_reach(geometries, profile)?;
    match settings.fields {
        FieldsMode::Greedy => greedy_fields(geometries, profile, ctx),
    }
}

#[cfg(test)]
mod tests;
#[cfg(test)]
pub(crate) mod tests_support;
