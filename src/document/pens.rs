//! Layers and pens: every geometry belongs to a layer (by name), and each layer has a pen that
//! says how its geometries are marked: enabled, mark speed, power, pulse frequency, passes,
//! hatch and a display colour.
//!
//! A pen's unset speed and power mean *the profile's* (`scanner.mark_speed_mm_s`,
//! `gcode.feed_mm_min`, `gcode.power`), so a document without pens plans and exports exactly as
//! before. Pens are saved in project files and as a small TOML library ([`PenLibrary`]).

use super::validate::InvalidValue;
use super::HatchSettings;
use super::{Geometry, MachineProfile};
use crate::geom::seam::SeamForm;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The layer of geometries whose import gave none.
pub const DEFAULT_LAYER: &str = "default";

/// Current pen-library format version.
pub const PENS_VERSION: u32 = 1;

/// The most passes a pen may ask for (more is a mistake, not a process).
pub const MAX_PASSES: u32 = 100;

/// Seconds per minute: a pen's feed in mm/min is its mark speed in mm/s times this.
const S_PER_MIN: f64 = 60.0;

/// Display colours of layers whose name is not a colour, in order of appearance.
const PALETTE: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf",
];

/// How a layer's geometries are marked.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Pen {
    /// Marked at all: a disabled layer's geometries are left out of the job.
    pub enabled: bool,
    /// Scanner mark speed, mm/s; unset: the profile's. The G-code feed is this × 60.
    pub mark_speed_mm_s: Option<f64>,
    /// Laser power written with the profile's power word; unset: the profile's power.
    pub power: Option<f64>,
    /// Pulse frequency, kHz (written as a G-code comment; unset: the source's setting).
    pub frequency_khz: Option<f64>,
    /// How many times the layer's strokes are marked (each field marks its strokes of this
    /// layer again after the first pass).
    pub passes: u32,
    /// Hatch fill of the layer's closed shapes; none: outlines only.
    pub hatch: Option<HatchSettings>,
    /// How the layer's strokes are cut where they cross a seam of the tiling (artwork larger
    /// than a field).
    pub seam: SeamForm,
    /// With several passes, each pass after the first is cut on a tiling shifted by
    /// `pass / passes` of a cell, so no two passes cut at the same place (more fields, more
    /// job time; the plan reports both).
    pub shift_passes: bool,
    /// How long the laser fires at a dot (a mark of one spot, as a dotted code's modules),
    /// s; unset: the profile's.
    pub dot_dwell_s: Option<f64>,
    /// Display colour `#rrggbb`; unset: from the layer's name when that is a colour, else from
    /// a palette.
    pub colour: Option<String>,
}

impl Default for Pen {
    fn default() -> Self {
        Self {
            enabled: true,
            mark_speed_mm_s: None,
            power: None,
            frequency_khz: None,
            passes: 1,
            hatch: None,
            seam: SeamForm::Straight,
            shift_passes: false,
            dot_dwell_s: None,
            colour: None,
        }
    }
}

impl Pen {
    /// Checks ranges; the error names the first bad value in the GUI's words.
    pub fn validate(&self) -> Result<(), InvalidValue> {
        super::spec::check_all(&super::spec::pen_specs(), self)?;
        if let Some(c) = &self.colour {
            if parse_colour(c).is_none() {
                return Err(InvalidValue::new(
                    "Colour",
                    "colour",
                    format!("'{c}'"),
                    "a colour written #rrggbb",
                ));
            }
        }
        if let Some(h) = &self.hatch {
            h.check()?;
        }
        Ok(())
    }
    /// True when the pen marks exactly as the profile says (speed, power, frequency unset, one
    /// pass).
    pub fn marks_as_profile(&self) -> bool {
        self.mark_speed_mm_s.is_none()
            && self.power.is_none()
            && self.frequency_khz.is_none()
            && self.dot_dwell_s.is_none()
            && self.passes == 1
    }
    /// Mark speed in mm/s on `profile`.
    pub fn mark_speed_mm_s(&self, profile: &MachineProfile) -> f64 {
        self.mark_speed_mm_s
            .unwrap_or(profile.scanner.mark_speed_mm_s)
    }
    /// How long a dot is fired on `profile`, s.
    pub fn dot_dwell_s(&self, profile: &MachineProfile) -> f64 {
        self.dot_dwell_s.unwrap_or(profile.laser.dot_dwell_s)
    }
    /// Feed on `G1` moves in mm/min on `profile`.
    pub fn feed_mm_min(&self, profile: &MachineProfile) -> f64 {
        self.mark_speed_mm_s
            .map_or(profile.gcode.feed_mm_min, |v| v * S_PER_MIN)
    }
    /// Laser power written on `profile` (none: no power word).
    pub fn power(&self, profile: &MachineProfile) -> Option<f64> {
        self.power.or(profile.gcode.power)
    }
}

/// How a pen marks in time: along a line at its mark speed, or a dot (a mark of one point,
/// [`crate::geom::is_dot`]) fired in place for its dwell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarkTiming {
    /// Mark speed, mm/s.
    pub speed_mm_s: f64,
    /// A dot's laser-on time, s.
    pub dot_dwell_s: f64,
}

impl MarkTiming {
    /// The timing of `pen` (none: the profile's settings) on `profile`.
    pub fn of(pen: Option<&Pen>, profile: &MachineProfile) -> Self {
        match pen {
            Some(p) => Self {
                speed_mm_s: p.mark_speed_mm_s(profile),
                dot_dwell_s: p.dot_dwell_s(profile),
            },
            None => Self {
                speed_mm_s: profile.scanner.mark_speed_mm_s,
                dot_dwell_s: profile.laser.dot_dwell_s,
            },
        }
    }
    /// How long the laser is on for the mark through `points` (`length_mm` long), s, between
    /// its on and off delays.
    pub fn mark_s(&self, points: &[crate::geom::Pt], length_mm: f64) -> f64 {
        if crate::geom::is_dot(points) {
            self.dot_dwell_s
        } else {
            length_mm / self.speed_mm_s
        }
    }
}

/// A layer: a name the geometries refer to, and its pen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "LayerFile")]
pub struct Layer {
    /// Name (SVG group id or label, or stroke colour; DXF layer; [`DEFAULT_LAYER`]).
    pub name: String,
    /// How it is marked.
    #[serde(flatten)]
    pub pen: Pen,
}

/// A layer as written in a file: the name and the pen's keys side by side, unknown keys
/// rejected (serde's `flatten` cannot reject them).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LayerFile {
    name: String,
    #[serde(default = "yes")]
    enabled: bool,
    #[serde(default)]
    mark_speed_mm_s: Option<f64>,
    #[serde(default)]
    power: Option<f64>,
    #[serde(default)]
    frequency_khz: Option<f64>,
    #[serde(default = "one")]
    passes: u32,
    #[serde(default)]
    hatch: Option<HatchSettings>,
    #[serde(default)]
    seam: SeamForm,
    #[serde(default)]
    shift_passes: bool,
    #[serde(default)]
    dot_dwell_s: Option<f64>,
    #[serde(default)]
    colour: Option<String>,
}

fn yes() -> bool {
    true
}

fn one() -> u32 {
    1
}

impl From<LayerFile> for Layer {
    fn from(f: LayerFile) -> Self {
        Layer {
            name: f.name,
            pen: Pen {
                enabled: f.enabled,
                mark_speed_mm_s: f.mark_speed_mm_s,
                power: f.power,
                frequency_khz: f.frequency_khz,
                passes: f.passes,
                hatch: f.hatch,
                seam: f.seam,
                shift_passes: f.shift_passes,
                dot_dwell_s: f.dot_dwell_s,
                colour: f.colour,
            },
        }
    }
}

impl Layer {
    /// A layer with the default pen.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            pen: Pen::default(),
        }
    }
    /// Checks the pen; the error names the layer.
    pub fn validate(&self) -> Result<(), InvalidValue> {
        if self.name.trim().is_empty() {
            return Err(InvalidValue::new(
                "Layer name",
                "name",
                "an empty name",
                "a name",
            ));
        }
        self.pen.validate().map_err(|e| {
            e.within(
                &format!("Layer '{}'", self.name),
                &format!("layer.{}", self.name),
            )
        })
    }
    /// Display colour as RGB.
    pub fn rgb(&self) -> [u8; 3] {
        self.pen
            .colour
            .as_deref()
            .and_then(parse_colour)
            .unwrap_or([0, 0, 0])
    }
}

/// `#rrggbb` as RGB.
pub fn parse_colour(text: &str) -> Option<[u8; 3]> {
    let hex = text.strip_prefix('#')?;
    if hex.len() != 6 || !hex.is_ascii() {
        return None;
    }
    let byte = |k: usize| u8::from_str_radix(&hex[k..k + 2], 16).ok();
    Some([byte(0)?, byte(2)?, byte(4)?])
}

/// The pen of `g`'s layer, if the table has it.
pub fn pen_of<'a>(layers: &'a [Layer], g: &Geometry) -> Option<&'a Pen> {
    layers.iter().find(|l| l.name == g.layer).map(|l| &l.pen)
}

/// How many times geometry `g` is marked: its pen's passes, or once for one pass of a pen with
/// shifted passes (each pass is a geometry of its own, [`Geometry::pass`]).
pub fn passes_of(layers: &[Layer], g: &Geometry) -> u32 {
    if g.pass > 0 {
        return 1;
    }
    pen_of(layers, g).map_or(1, |p| p.passes.max(1))
}

/// Checks every layer and that names are unique.
pub fn validate_layers(layers: &[Layer]) -> Result<(), InvalidValue> {
    for (k, l) in layers.iter().enumerate() {
        l.validate()?;
        if layers[..k].iter().any(|m| m.name == l.name) {
            return Err(InvalidValue::new(
                "Layer name",
                "name",
                format!("'{}' twice", l.name),
                "unique",
            ));
        }
    }
    Ok(())
}

/// Adds a layer with `default_pen` for every layer name of `geometries` the table lacks, in
/// order of first appearance, and gives every layer without a colour one (the name's, when it
/// is a colour, else the next palette colour).
pub fn sync_layers(layers: &mut Vec<Layer>, geometries: &[Geometry], default_pen: &Pen) {
    for g in geometries {
        if !layers.iter().any(|l| l.name == g.layer) {
            layers.push(Layer {
                name: g.layer.clone(),
                pen: default_pen.clone(),
            });
        }
    }
    let mut next = 0;
    for l in layers.iter_mut() {
        if l.pen.colour.is_none() {
            let colour = if parse_colour(&l.name).is_some() {
                l.name.clone()
            } else {
                next += 1;
                PALETTE[(next - 1) % PALETTE.len()].to_string()
            };
            l.pen.colour = Some(colour);
        }
    }
}

/// A pen library: pens by layer name plus an optional default for layers it does not name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PenLibrary {
    /// Format version ([`PENS_VERSION`]).
    pub version: u32,
    /// The pen of layers the library does not name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default: Option<Pen>,
    /// Layers and their pens.
    #[serde(default, rename = "layer")]
    pub layers: Vec<Layer>,
}

/// Errors reading or writing a pen library. Every variant names the file.
#[derive(Debug, Error)]
pub enum PensError {
    /// The file could not be read or written.
    #[error("{file}: {what}: {source}")]
    Io {
        /// The file.
        file: String,
        /// What was attempted.
        what: &'static str,
        /// The cause.
        source: std::io::Error,
    },
    /// Not a valid pen library.
    #[error("{file}: invalid pens file: {msg}")]
    Parse {
        /// The file.
        file: String,
        /// Parser message, with line and column.
        msg: String,
    },
    /// A value is out of range.
    #[error("{file}: invalid pens file: {}", .error.with_key())]
    Invalid {
        /// The file.
        file: String,
        /// The value.
        error: InvalidValue,
    },
}

impl PenLibrary {
    /// The library of a document's layers.
    pub fn of(layers: &[Layer]) -> Self {
        Self {
            version: PENS_VERSION,
            default: None,
            layers: layers.to_vec(),
        }
    }
    /// Parses and validates TOML text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Self, PensError> {
        let lib: PenLibrary = toml::from_str(text).map_err(|e| PensError::Parse {
            file: file.into(),
            msg: e.to_string().replace('\n', " "),
        })?;
        lib.validate().map_err(|error| PensError::Invalid {
            file: file.into(),
            error,
        })?;
        Ok(lib)
    }
    /// Reads a pens file.
    pub fn load(path: &std::path::Path) -> Result<Self, PensError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| PensError::Io {
            file: file.clone(),
            what: "cannot read pens",
            source,
        })?;
        Self::from_toml(&text, &file)
    }
    /// Writes the library as TOML, atomically.
    pub fn save(&self, path: &std::path::Path) -> Result<(), PensError> {
        let file = path.display().to_string();
        let text = toml::to_string_pretty(self).map_err(|e| PensError::Parse {
            file: file.clone(),
            msg: format!("cannot be written as TOML: {e}"),
        })?;
        super::write_atomic(path, text.as_bytes()).map_err(|source| PensError::Io {
            file,
            what: "cannot write pens",
            source,
        })
    }
    /// Checks version, every pen and unique names.
    pub fn validate(&self) -> Result<(), InvalidValue> {
        if self.version == 0 || self.version > PENS_VERSION {
            return Err(InvalidValue::new(
                "Pens file version",
                "version",
                self.version,
                format!("between 1 and {PENS_VERSION} (this build)"),
            ));
        }
        if let Some(p) = &self.default {
            p.validate()
                .map_err(|e| e.within("Default pen", "default"))?;
        }
        validate_layers(&self.layers)
    }
    /// Gives each of `layers` the library's pen of that name (or its default pen); returns
    /// the names the library has but `layers` lacks.
    pub fn apply(&self, layers: &mut [Layer]) -> Vec<String> {
        for l in layers.iter_mut() {
            match self.layers.iter().find(|m| m.name == l.name) {
                Some(m) => l.pen = m.pen.clone(),
                None => {
                    if let Some(d) = &self.default {
                        l.pen = d.clone();
                    }
                }
            }
        }
        self.layers
            .iter()
            .filter(|m| !layers.iter().any(|l| l.name == m.name))
            .map(|m| m.name.clone())
            .collect()
    }
}

/// How the window names a layer: its own name, or for a layer named after its stroke colour
/// (`#rrggbb`, what an SVG without layer groups gives) a colour word and the hex, e.g.
/// `dark grey (#1f2937)`. Display only (the window, stale reasons): the document and pens files
/// keep the name.
pub fn layer_label(name: &str) -> String {
    match crate::document::parse_colour(name) {
        Some(rgb) => format!("{} ({name})", colour_word(rgb)),
        None => name.to_string(),
    }
}

/// A plain word for a colour: black, white, (dark/light) grey, or a hue (red, orange, brown,
/// yellow, olive, green, teal, cyan, blue, purple, magenta, pink) with "dark" or "light" when
/// it is far from mid lightness.
pub fn colour_word([r, g, b]: [u8; 3]) -> String {
    let (r, g, b) = (
        f32::from(r) / 255.0,
        f32::from(g) / 255.0,
        f32::from(b) / 255.0,
    );
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    let chroma = max - min;
    let light = (max + min) / 2.0;
    if chroma < 0.12 {
        return match light {
            l if l < 0.1 => "black",
            l if l < 0.33 => "dark grey",
            l if l < 0.7 => "grey",
            l if l < 0.93 => "light grey",
            _ => "white",
        }
        .to_string();
    }
    let hue = if max == r {
        60.0 * ((g - b) / chroma).rem_euclid(6.0)
    } else if max == g {
        60.0 * ((b - r) / chroma + 2.0)
    } else {
        60.0 * ((r - g) / chroma + 4.0)
    };
    let saturation = chroma / (1.0 - (2.0 * light - 1.0).abs()).max(1e-6);
    let base = match hue {
        h if !(12.0..345.0).contains(&h) => {
            if light < 0.45 && saturation < 0.5 {
                "brown"
            } else {
                "red"
            }
        }
        h if h < 45.0 => {
            if light < 0.45 {
                "brown"
            } else {
                "orange"
            }
        }
        h if h < 70.0 => {
            if light < 0.35 {
                "olive"
            } else {
                "yellow"
            }
        }
        h if h < 165.0 => "green",
        h if h < 175.0 => "teal",
        h if h < 192.0 => "cyan",
        h if h < 255.0 => "blue",
        h if h < 290.0 => "purple",
        _ if light > 0.6 => "pink",
        _ => "magenta",
    };
    let shade = match light {
        l if l < 0.28 && base != "brown" && base != "olive" => "dark ",
        l if l > 0.78 && base != "pink" => "light ",
        _ => "",
    };
    format!("{shade}{base}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::Source;
    use crate::geom::Pt;

    const LIB: &str = r##"
version = 1
[default]
passes = 1
[[layer]]
name = "outline"
mark_speed_mm_s = 800
power = 40
[[layer]]
name = "fill"
mark_speed_mm_s = 2000.0
power = 80
passes = 2
colour = "#ff0000"
[layer.hatch]
style = "lines"
spacing_mm = 0.5
"##;

    fn geom(layer: &str) -> Geometry {
        let mut g = Geometry::new(vec![Pt::new(0.0, 0.0)], false, Source::default());
        g.layer = layer.into();
        g
    }

    #[test]
    fn library_round_trip_and_apply() {
        let lib = PenLibrary::from_toml(LIB, "p.toml").unwrap();
        assert_eq!(lib.layers.len(), 2);
        assert_eq!(lib.layers[1].pen.passes, 2);
        assert_eq!(lib.layers[1].pen.hatch.as_ref().unwrap().spacing_mm, 0.5);
        let text = toml::to_string_pretty(&lib).unwrap();
        assert_eq!(PenLibrary::from_toml(&text, "q").unwrap(), lib);
        let mut layers = Vec::new();
        let gs = [geom("fill"), geom("#00ff00"), geom("fill"), geom("other")];
        sync_layers(&mut layers, &gs, &Pen::default());
        let names: Vec<&str> = layers.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(names, ["fill", "#00ff00", "other"]);
        assert_eq!(layers[1].pen.colour.as_deref(), Some("#00ff00"));
        assert_eq!(layers[0].pen.colour.as_deref(), Some(PALETTE[0]));
        assert_eq!(layers[2].pen.colour.as_deref(), Some(PALETTE[1]));
        let missing = lib.apply(&mut layers);
        assert_eq!(missing, ["outline"]);
        assert_eq!(layers[0].pen.mark_speed_mm_s, Some(2000.0));
        let p = MachineProfile::default();
        assert_eq!(layers[0].pen.feed_mm_min(&p), 120_000.0);
        assert_eq!(layers[1].pen.feed_mm_min(&p), p.gcode.feed_mm_min);
        assert_eq!(layers[1].pen.mark_speed_mm_s(&p), p.scanner.mark_speed_mm_s);
        assert_eq!(pen_of(&layers, &gs[0]).map(|p| p.passes), Some(2));
    }

    #[test]
    fn bad_pens_are_named_in_words() {
        let e = PenLibrary::from_toml(
            "version = 1\n[[layer]]\nname = \"fill\"\npasses = 0\n",
            "p.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("p.toml")
                && e.contains("Layer 'fill': Passes must be")
                && e.contains("layer.fill.passes"),
            "{e}"
        );
        let e = PenLibrary::from_toml(
            "version = 1\n[[layer]]\nname = \"a\"\nspeed = 3\n",
            "p.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("speed"), "{e}");
        let e = PenLibrary::from_toml("version = 9\n", "p.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not 9"), "{e}");
        let mut l = Layer::new("x");
        l.pen.colour = Some("red".into());
        assert!(l.validate().unwrap_err().to_string().contains("#rrggbb"));
        l.pen.colour = None;
        l.pen.mark_speed_mm_s = Some(0.0);
        assert_eq!(
            l.validate().unwrap_err().what,
            "Layer 'x': Mark speed (mm/s)"
        );
        let dup = [Layer::new("a"), Layer::new("a")];
        assert!(validate_layers(&dup).is_err());
    }
}
