//! How the artwork was brought in: where it was placed on the machine, and which layers the
//! drawing hides (skipped, or imported at the operator's request). Plain data; the import
//! (`crate::import`) makes it, the project keeps it, the GUI offers the choices again.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// Where the artwork goes on the machine (machine coordinates: mm, x right, y down, the base
/// stroke's corner at the origin).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum Place {
    /// As in the file where the laser reaches all of the artwork; otherwise, when the artwork
    /// is no larger than the reach, centred on the base stroke (with a warning); otherwise as
    /// in the file (the field stage then says how large it is).
    #[default]
    Auto,
    /// As in the file (SVG page coordinates; DXF coordinates, y flipped about the page top).
    AsIs,
    /// The artwork's bounding box centred on the base stroke.
    Centre,
    /// The artwork's bounding box with its top-left corner (least x, least y) at this machine
    /// position, mm.
    Corner([f64; 2]),
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Place::Auto => f.write_str("auto"),
            Place::AsIs => f.write_str("as-is"),
            Place::Centre => f.write_str("centre"),
            Place::Corner([x, y]) => write!(f, "corner:{x},{y}"),
        }
    }
}

/// Why a placement could not be read or made.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PlaceError {
    /// The text is not a placement.
    #[error("'{0}' is not a placement: use auto, as-is, centre or corner:X,Y (mm)")]
    Syntax(String),
    /// Centring needs the machine's base stroke.
    #[error("centring needs the machine's base stroke, and none is known")]
    NoWorkArea,
}

impl FromStr for Place {
    type Err = PlaceError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || PlaceError::Syntax(s.to_string());
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Place::Auto),
            "as-is" | "asis" | "as_is" => Ok(Place::AsIs),
            "centre" | "center" => Ok(Place::Centre),
            other => {
                let xy = other.strip_prefix("corner:").ok_or_else(bad)?;
                let (x, y) = xy.split_once(',').ok_or_else(bad)?;
                let x: f64 = x.trim().parse().map_err(|_| bad())?;
                let y: f64 = y.trim().parse().map_err(|_| bad())?;
                if x.is_finite() && y.is_finite() {
                    Ok(Place::Corner([x, y]))
                } else {
                    Err(bad())
                }
            }
        }
    }
}

/// Why a layer was not imported.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum LayerHidden {
    /// A DXF layer that is off (negative colour number).
    Off,
    /// A DXF layer that is frozen (flag 1).
    Frozen,
    /// A DXF layer that is off and frozen.
    OffAndFrozen,
    /// An SVG layer (top-level group) with `display:none`.
    Hidden,
}

impl std::fmt::Display for LayerHidden {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LayerHidden::Off => "off",
            LayerHidden::Frozen => "frozen",
            LayerHidden::OffAndFrozen => "off and frozen",
            LayerHidden::Hidden => "hidden",
        })
    }
}

/// A layer the import skipped because the drawing hides it; imported when
/// the import's hidden-layer option names it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedLayer {
    /// The layer's name, as geometries on it would carry it (`Geometry::layer`).
    pub name: String,
    /// How the drawing hides it.
    pub why: LayerHidden,
    /// Entities (DXF, each block instance counted) or elements (SVG) skipped with it.
    pub skipped: usize,
}

/// The import choices a document's artwork was made with, kept so that it can be imported again
/// the same way or with a different choice (the GUI's placement and hidden layers).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ArtworkImport {
    /// Where the artwork was placed.
    #[serde(default)]
    pub place: Place,
    /// Every layer the drawing hides, imported or not (skipped unless in `included`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub hidden_layers: Vec<SkippedLayer>,
    /// Hidden layers imported at the operator's request (names as in `hidden_layers`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub included: Vec<String>,
}

impl ArtworkImport {
    /// The hidden layers that were left out.
    pub fn skipped(&self) -> impl Iterator<Item = &SkippedLayer> {
        self.hidden_layers.iter().filter(|l| {
            !self
                .included
                .iter()
                .any(|n| n.eq_ignore_ascii_case(&l.name))
        })
    }
}
