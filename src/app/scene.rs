//! What a canvas shows: the artwork, the machine, the fields, the planned paths and which
//! layers are drawn ([`Canvas`]). Its interaction is `super::canvas`, its drawing
//! `super::paint`; both read this, neither is read here.

use super::toolpaths::Lowered;
use crate::document::{Geometry, MachineProfile, Plan, ScanField};
use egui::Color32;
use serde::{Deserialize, Serialize};

/// Which layers a canvas draws (kept between runs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Layers {
    /// Scan fields.
    pub fields: bool,
    /// The planned path: idle moves and start/end markers.
    pub path: bool,
    /// Direction arrows on idle moves long enough to carry one.
    pub arrows: bool,
    /// The base path through the field centres in visiting order.
    pub base_path: bool,
    /// Marks coloured by their position in the order (else: by open/closed).
    pub order_colours: bool,
}

impl Default for Layers {
    fn default() -> Self {
        Self {
            fields: true,
            path: true,
            arrows: true,
            base_path: true,
            order_colours: true,
        }
    }
}

/// One planned path to draw.
#[derive(Debug, Clone, Copy)]
pub struct PathLayer<'a> {
    /// The plan.
    pub plan: &'a Plan,
    /// Its lowered toolpath (what is drawn), or why it could not be lowered.
    pub lowered: Result<&'a Lowered, &'a str>,
    /// Colour of its idle moves and markers.
    pub colour: Color32,
}

/// A canvas over the machine's work area.
pub struct Canvas<'a> {
    /// Accessible name and caption.
    pub label: &'a str,
    /// The artwork.
    pub geometries: &'a [Geometry],
    /// The machine (stroke and field size).
    pub profile: std::borrow::Cow<'a, MachineProfile>,
    /// A cylinder job's cylinder: the work area is its unrolled surface.
    pub cylinder: Option<crate::document::Cylinder>,
    /// Fields to draw.
    pub fields: &'a [ScanField],
    /// Seams: where artwork larger than a field is cut (drawn with the fields).
    pub seams: &'a [crate::geom::seam::SeamLine],
    /// The tiling the seams belong to (its extent: how far a seam line runs).
    pub tiling: Option<&'a crate::geom::tiling::Tiling>,
    /// The widest cell the tiling may have (how far a seam can be dragged), mm.
    pub cell_max_mm: [f64; 2],
    /// The shown plan's fields in visiting order: fields are numbered 1…n in that order (the
    /// others after them), else in the order of `fields` (placement order).
    pub visiting: Option<&'a [ScanField]>,
    /// Each geometry's layer colour (none: closed dark, open green).
    pub colours: Option<&'a [Color32]>,
    /// Uncovered geometries no scan field can hold (drawn apart from merely uncovered ones).
    pub out_of_reach: &'a [usize],
    /// Planned paths to draw (one, or two overlaid).
    pub paths: Vec<PathLayer<'a>>,
    /// Geometries no field holds (drawn in red).
    pub uncovered: &'a [usize],
    /// The selected field id.
    pub selected: Option<usize>,
    /// Fields can be selected, dragged and added.
    pub editable: bool,
    /// The add tool is active: a click adds a field.
    pub add_tool: bool,
    /// Layers.
    pub layers: Layers,
    /// What changed since the path was planned (empty: it is current).
    pub stale: &'a [String],
    /// Playback time: the machine is drawn at this job time (`None`: the planned path only).
    pub playback_t_s: Option<f64>,
    /// The tray's cells: numbered, skipped ones greyed, each part's serial on hover.
    pub parts: &'a [super::tray_panel::PartBox],
    /// The parts' codes (dragged on an editable canvas).
    pub codes: &'a [super::tray_panel::CodeBox],
    /// Changes whenever the artwork, its colours or coverage change: the canvas keeps a raster
    /// of what it draws while this (and what it compares by value) stays the same.
    pub revision: u64,
}
