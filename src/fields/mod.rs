//! Scan-field placement, allocation of geometries to fields, and operator edits.
//!
//! Modes (`SolverSettings::fields`): `greedy` (baseline serpentine cover), `auto` (set cover with
//! least overlap and best centring, [`auto`]), `paper` (seed 000 §3.1, [`paper`]). Locked fields
//! are kept as they are; a mode only adds fields for what they leave uncovered.

mod allocate;
pub mod auto;
pub mod cover;
mod edit;
mod greedy;
pub mod paper;
pub mod position;
mod reach;
mod split;

pub use allocate::{allocate, holders, Allocation};
pub use edit::{
    add_field, delete_field, move_field, reallocate, replace_automatically, set_locked, EditError,
};
pub use greedy::greedy_fields;
pub use reach::{center_range, check_artwork, check_reach, Span};
pub use split::{
    cell_max_mm, choose_document_tiling, cut_at_tiling, cut_hatch_at_tiling, is_oversize,
    move_seam, seam_stop_reason, split_oversize, Cut, FIT_MARGIN_MM, SPLIT_WORDS,
};

use crate::document::runs::Contraction;
use crate::document::{FieldsMode, Geometry, MachineProfile, ScanField, SolverSettings};
use crate::job::{Cancelled, JobCtx};
use thiserror::Error;

/// Slack when testing whether a geometry lies inside a field, mm.
pub const INSIDE_EPS_MM: f64 = 1e-7;

/// Why fields could not be placed.
#[derive(Debug, Error)]
pub enum FieldError {
    /// The artwork as a whole lies beyond the laser's reach, or is larger than it.
    #[error("{}", reach::artwork_message(.extent_mm, .stroke_mm, .field_mm))]
    Artwork {
        /// The artwork's bounding box: least x, least y, greatest x, greatest y (mm).
        extent_mm: [f64; 4],
        /// Base stroke.
        stroke_mm: [f64; 2],
        /// Field size.
        field_mm: [f64; 2],
    },
    /// Geometries larger than one scan field.
    #[error("{} {} larger than the {:.1} × {:.1} mm scan field: {}", .list.len(), if .list.len() == 1 { "geometry is" } else { "geometries are" }, .field_mm[0], .field_mm[1], crate::document::short_list(.list, "; "))]
    Oversize {
        /// Each offending geometry, described with its size.
        list: Vec<String>,
        /// Field size.
        field_mm: [f64; 2],
    },
    /// Geometries the laser cannot reach from any base position.
    #[error("{} {} out of reach (base stroke {:.1} × {:.1} mm, laser reaches x and y in [{:.1}, {:.1}] mm): {}", .list.len(), if .list.len() == 1 { "geometry is" } else { "geometries are" }, .stroke_mm[0], .stroke_mm[1], -.field_mm[0] / 2.0, .stroke_mm[0] + .field_mm[0] / 2.0, crate::document::short_list(.list, "; "))]
    OutOfReach {
        /// Each offending geometry, described with its position.
        list: Vec<String>,
        /// Base stroke.
        stroke_mm: [f64; 2],
        /// Field size.
        field_mm: [f64; 2],
    },
    /// Internal consistency failure: a placement left geometries uncovered.
    #[error("{0} geometries left uncovered by the field placement (first: geometry {1})")]
    Uncovered(usize, usize),
    /// The operator cancelled.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// The result of a placement.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// Locked fields first (unchanged), then the new ones; geometries allocated.
    pub fields: Vec<ScanField>,
    /// A lower bound on the number of fields any placement needs.
    pub lower_bound: usize,
}

/// Run chunks the field stage places as one node are at most this share of a field wide and
/// tall: they fit a field with room for the cover to move it (a chunk nearly a field wide
/// would pin its field).
const RUN_CHUNK_FIELD_SHARE: f64 = 0.5;

/// Places scan fields for `geometries` with the mode in `settings`, keeping `locked` fields, and
/// allocates every geometry to exactly one field (`ScanField::geometries`). Runs of strokes a
/// fill orders (`document::Run`) are placed as one node per chunk of at most half a field
/// ([`Contraction::within`]), so a chunk's members share a field.
pub fn place_fields(
    geometries: &[Geometry],
    profile: &MachineProfile,
    settings: &SolverSettings,
    locked: &[ScanField],
    ctx: &JobCtx,
) -> Result<Placement, FieldError> {
    check_reach(geometries, profile)?;
    let max_mm = profile.field_mm.map(|f| f * RUN_CHUNK_FIELD_SHARE);
    let Some(runs) = Contraction::within(geometries, max_mm) else {
        let fields = place_nodes(geometries, profile, settings, locked, ctx)?;
        let lower_bound = cover::lower_bound(&auto::feasible_rects(geometries, profile));
        return Ok(Placement {
            fields,
            lower_bound,
        });
    };
    let fields = place_nodes(runs.nodes(), profile, settings, locked, ctx)?;
    let representatives = runs.representatives().into_iter().map(|g| &geometries[g]);
    Ok(Placement {
        fields: runs.fields_to_geometries(fields),
        lower_bound: cover::lower_bound(&auto::feasible_rects(representatives, profile)),
    })
}

/// [`place_fields`] on nodes (geometries, or the proxies of run chunks): the placed fields.
fn place_nodes(
    geometries: &[Geometry],
    profile: &MachineProfile,
    settings: &SolverSettings,
    locked: &[ScanField],
    ctx: &JobCtx,
) -> Result<Vec<ScanField>, FieldError> {
    let locked: Vec<ScanField> = locked
        .iter()
        .map(|f| ScanField {
            locked: true,
            geometries: Vec::new(),
            ..f.clone()
        })
        .collect();
    let held = holders(geometries, &locked);
    let rest: Vec<usize> = (0..geometries.len())
        .filter(|&g| held[g].is_empty())
        .collect();
    let first_id = locked.iter().map(|f| f.id + 1).max().unwrap_or(0);
    let mut fields = locked.clone();
    match settings.fields {
        FieldsMode::Greedy => {
            // locked fields take what they hold; the baseline sweep keeps its own allocation
            allocate(geometries, &mut fields);
            let mut new = greedy_fields(geometries, &rest, profile, ctx)?;
            for f in &mut new {
                f.id += first_id;
            }
            fields.extend(new);
        }
        FieldsMode::Auto => {
            fields.extend(auto::auto_fields(
                geometries, &rest, profile, &locked, first_id, ctx,
            )?);
            allocate(geometries, &mut fields);
        }
        FieldsMode::Paper => {
            fields.extend(paper::paper_fields(
                geometries,
                &rest,
                profile,
                settings.seed,
                first_id,
                ctx,
            )?);
            allocate(geometries, &mut fields);
        }
    }
    fields.retain(|f| f.locked || !f.geometries.is_empty());
    let covered: usize = fields.iter().map(|f| f.geometries.len()).sum();
    if covered != geometries.len() {
        let alloc = holders(geometries, &fields);
        let missing: Vec<usize> = (0..geometries.len())
            .filter(|&g| alloc[g].is_empty())
            .collect();
        return Err(FieldError::Uncovered(
            missing.len(),
            missing.first().copied().unwrap_or(0),
        ));
    }
    Ok(fields)
}

#[cfg(test)]
mod tests;
#[cfg(test)]
pub(crate) mod tests_support;
