//! Hatch settings (the document's part of a pen): style, spacing, angle, edge offset, outline handling and fill rule, plus the
//! command-line form `STYLE:SPACING_MM[:ANGLE_DEG]`.

use super::validate::InvalidValue;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// The smallest hatch spacing accepted, mm (finer spacings are not a laser process).
pub const MIN_SPACING_MM: f64 = 1e-4;

/// How a region is filled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum HatchStyle {
    /// Bidirectional parallel lines; consecutive lines are joined along the region's boundary
    /// wherever that is possible, so the laser stays on through a sweepable part.
    #[default]
    Zigzag,
    /// Unidirectional parallel lines, one stroke per line, all in the same direction.
    Lines,
    /// Two zigzag families, at the angle and at the angle + 90°.
    Cross,
    /// Contour-parallel rings: repeated inward offsets until the region is used up.
    Contour,
}

impl HatchStyle {
    /// All styles, in the order the CLI lists them.
    pub const ALL: [HatchStyle; 4] = [
        HatchStyle::Zigzag,
        HatchStyle::Lines,
        HatchStyle::Cross,
        HatchStyle::Contour,
    ];
    /// The lower-case name used on the command line and in settings files.
    pub fn name(self) -> &'static str {
        match self {
            HatchStyle::Zigzag => "zigzag",
            HatchStyle::Lines => "lines",
            HatchStyle::Cross => "cross",
            HatchStyle::Contour => "contour",
        }
    }
}

impl fmt::Display for HatchStyle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What happens to the outline (the original closed contours) of a hatched region.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum OutlineMode {
    /// Keep the outlines, listed before the region's hatch.
    #[default]
    Before,
    /// Keep the outlines, listed after the region's hatch.
    After,
    /// Drop the outlines: only the hatch is marked.
    None,
}

/// Which points lie inside a set of contours (the SVG `fill-rule`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum FillRule {
    /// Inside when a ray crosses the contours an odd number of times.
    #[default]
    EvenOdd,
    /// Inside when the winding number is not zero.
    NonZero,
}

/// Which closed shapes of a layer form one region to fill.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum FillShapes {
    /// All the layer's closed shapes together, by the fill rule (a shape inside another is a
    /// hole with even-odd; overlapping shapes are filled once), as LightBurn does.
    #[default]
    Together,
    /// Each drawing element (SVG element, DXF entity) on its own, as SVG paints them: shapes
    /// that overlap are filled once each.
    Apart,
}

/// Hatch settings for the closed regions of a document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct HatchSettings {
    /// Fill style.
    pub style: HatchStyle,
    /// Distance between neighbouring hatch lines (or rings), mm.
    pub spacing_mm: f64,
    /// Direction of the hatch lines, degrees from the +x axis towards +y (machine coordinates,
    /// y down as in SVG, so positive angles turn clockwise on screen). Ignored by `contour`.
    pub angle_deg: f64,
    /// Edge offset: distance from the outline to the hatch, mm. `None`: one spacing, so that the
    /// outline's mark and the hatch's marks just touch.
    pub edge_offset_mm: Option<f64>,
    /// Whether the outlines are kept, and where.
    pub outline: OutlineMode,
    /// Mark the boundary of the offset region too (on by default). Without it, points near the
    /// offset boundary between two line ends may stay unmarked; `contour` ignores it (its first
    /// ring is that boundary).
    pub border: bool,
    /// Fill rule that turns nested contours into a region.
    pub fill_rule: FillRule,
    /// Whether the layer's shapes are filled together or each on its own.
    pub shapes: FillShapes,
}

impl Default for HatchSettings {
    fn default() -> Self {
        Self {
            style: HatchStyle::default(),
            spacing_mm: 0.1,
            angle_deg: 0.0,
            edge_offset_mm: None,
            outline: OutlineMode::default(),
            border: true,
            fill_rule: FillRule::default(),
            shapes: FillShapes::default(),
        }
    }
}

impl HatchSettings {
    /// Settings for a style and spacing, everything else default.
    pub fn new(style: HatchStyle, spacing_mm: f64) -> Self {
        Self {
            style,
            spacing_mm,
            ..Self::default()
        }
    }
    /// The edge offset in mm (the spacing unless set).
    pub fn edge_offset(&self) -> f64 {
        self.edge_offset_mm.unwrap_or(self.spacing_mm)
    }
    /// Checks that the numbers make sense; the error names the setting in the GUI's words.
    pub fn check(&self) -> Result<(), InvalidValue> {
        super::spec::check_all(&super::spec::hatch_specs(), self)
    }
    /// Parses the command-line form `STYLE:SPACING_MM[:ANGLE_DEG]`, e.g. `zigzag:0.1:45`.
    pub fn parse_spec(spec: &str) -> Result<Self, HatchSpecError> {
        let err = |reason: String| HatchSpecError {
            spec: spec.to_string(),
            reason,
        };
        let parts: Vec<&str> = spec.split(':').map(str::trim).collect();
        if !(2..=3).contains(&parts.len()) {
            return Err(err(format!("{} field(s), need 2 or 3", parts.len())));
        }
        let style = HatchStyle::ALL
            .into_iter()
            .find(|s| s.name().eq_ignore_ascii_case(parts[0]))
            .ok_or_else(|| err(format!("unknown style {:?}", parts[0])))?;
        let spacing_mm: f64 = parts[1]
            .parse()
            .map_err(|_| err(format!("spacing {:?} is not a number", parts[1])))?;
        let angle_deg: f64 = match parts.get(2) {
            Some(a) => a
                .parse()
                .map_err(|_| err(format!("angle {a:?} is not a number")))?,
            None => 0.0,
        };
        let s = Self {
            style,
            spacing_mm,
            angle_deg,
            ..Self::default()
        };
        s.check().map_err(|e| err(e.to_string()))?;
        Ok(s)
    }
}

/// A malformed hatch description `STYLE:SPACING_MM[:ANGLE_DEG]` (the CLI's `--hatch`).
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{spec:?}: {reason} (expected STYLE:SPACING_MM[:ANGLE_DEG] with STYLE = zigzag | lines | cross | contour)")]
pub struct HatchSpecError {
    /// The description as given.
    pub spec: String,
    /// What is wrong.
    pub reason: String,
}

impl FromStr for HatchSettings {
    type Err = HatchSpecError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::parse_spec(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_specs() {
        let s = HatchSettings::parse_spec("zigzag:0.1").unwrap();
        assert_eq!(
            (s.style, s.spacing_mm, s.angle_deg),
            (HatchStyle::Zigzag, 0.1, 0.0)
        );
        let s: HatchSettings = "Contour:1:45".parse().unwrap();
        assert_eq!(
            (s.style, s.spacing_mm, s.angle_deg),
            (HatchStyle::Contour, 1.0, 45.0)
        );
        assert_eq!(s.edge_offset(), 1.0);
        for bad in [
            "zigzag",
            "dots:1",
            "lines:x",
            "lines:1:y",
            "lines:0",
            "lines:-1",
            "a:1:2:3",
        ] {
            let e = HatchSettings::parse_spec(bad).unwrap_err().to_string();
            assert!(e.contains("STYLE:SPACING_MM"), "{bad}: {e}");
        }
    }

    #[test]
    fn serde_names() {
        let s = HatchSettings {
            fill_rule: FillRule::NonZero,
            outline: OutlineMode::None,
            ..HatchSettings::default()
        };
        let j = serde_json::to_string(&s).unwrap();
        assert!(j.contains("\"nonzero\"") && j.contains("\"none\"") && j.contains("\"zigzag\""));
        let back: HatchSettings = serde_json::from_str(&j).unwrap();
        assert_eq!(back, s);
        let partial: HatchSettings = serde_json::from_str("{\"spacing_mm\": 0.5}").unwrap();
        assert_eq!(partial.spacing_mm, 0.5);
        assert!(partial.border);
    }
}
