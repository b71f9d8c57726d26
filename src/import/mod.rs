//! Import of artwork (SVG, DXF) into [`Geometry`] polylines in mm.
//!
//! [`import_file`] is the one entry point for files: it chooses the format by extension (and by
//! content when the extension says nothing) and every error names the file and the format.

mod clip;
mod curves;
mod dxf;
mod dxf_scan;
mod dxf_text;
mod fonts;
mod guard;
mod place;
mod svg;
mod svg_bounds;
mod svg_scan;
mod template;

pub use self::dxf::import_dxf;
pub use crate::document::{ArtworkImport, LayerHidden, Place, PlaceError, SkippedLayer};
pub use fonts::{bundled_font, BUNDLED_CAP_HEIGHT_EM, BUNDLED_FAMILY};
pub use place::place_artwork;
pub use svg::{import_svg, import_svg_file};
pub use svg_bounds::USER_MAX;
pub use template::shape_template;

use crate::document::production::TemplateError;
use crate::document::{Geometry, TextTemplate};
use crate::geom::{polyline_length, Pt};

use std::path::Path;
use thiserror::Error;

/// Output budget of one import: more vertices than this is an error, not minutes of flattening
/// and gigabytes of memory (80 MB of points). One curve's share follows from [`MAX_COORD_MM`]
/// and the chord tolerance (`geom::flatten`): a curve within the bound needs at most
/// `2,100 / √tol` chords (21,000 at 0.01 mm), and a curve that would take more than what is
/// left of the budget is refused before it is flattened.
pub const MAX_POINTS: usize = 5_000_000;
pub use crate::geom::MAX_COORD_MM;
/// Most characters of text one file may lay out (each a glyph of tens of curves): beyond, the
/// file is refused before any text is shaped.
pub const MAX_GLYPHS: usize = 100_000;
/// Subpaths shorter than this (mm) are degenerate: below the exported G-code's resolution.
const MIN_LENGTH_MM: f64 = 1e-3;
/// Points closer than this are one point (mm).
const SAME_POINT_MM: f64 = 1e-6;

/// Which fonts text is set in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FontSource {
    /// The bundled DejaVu Sans first, then the system's fonts (fontconfig).
    #[default]
    System,
    /// Only the bundled DejaVu Sans: the same outlines on every machine (tests, fuzzing).
    BundledOnly,
}

/// Import options. Build them with `..ImportOptions::default()`: fields are added over time.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportOptions {
    /// Maximum distance between a curve and its flattened polyline, mm (the same guarantee for
    /// SVG curves, text outlines and DXF arcs, ellipses and splines).
    pub chord_tol_mm: f64,
    /// Fonts for text.
    pub fonts: FontSource,
    /// Width and height of the area the artwork should lie in (the base stroke), mm: what
    /// [`Place`] places the artwork on. `None`: no machine is known, the artwork stays as in
    /// the file (except [`Place::Corner`]).
    pub work_area_mm: Option<[f64; 2]>,
    /// Scan field size, mm: the laser reaches half a field beyond the work area on every side
    /// ([`Place::Auto`] keeps artwork inside that reach where it is). `None`: no margin.
    pub field_mm: Option<[f64; 2]>,
    /// Where the artwork goes on the machine (see [`Place`]; applied right after import).
    pub place: Place,
    /// Offsets (mm) smaller than this are not applied nor reported: below the export's
    /// resolution (a G-code with 4 decimals: 10⁻⁴ mm).
    pub resolution_mm: f64,
    /// Layers the drawing hides (DXF layers off or frozen, SVG layers with `display:none`)
    /// to import anyway.
    pub hidden_layers: HiddenLayers,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            chord_tol_mm: 0.01,
            fonts: FontSource::System,
            work_area_mm: None,
            field_mm: None,
            place: Place::Auto,
            resolution_mm: 1e-4,
            hidden_layers: HiddenLayers::Skip,
        }
    }
}

/// What happens to layers the drawing hides.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum HiddenLayers {
    /// Skipped, each with one summary warning and listed in [`Imported::skipped_layers`].
    #[default]
    Skip,
    /// All imported (`--include-hidden-layers`).
    IncludeAll,
    /// These layers (by name, compared without case) imported, others skipped.
    Include(Vec<String>),
}

impl HiddenLayers {
    /// True when the hidden layer `name` is to be imported.
    pub fn includes(&self, name: &str) -> bool {
        match self {
            HiddenLayers::Skip => false,
            HiddenLayers::IncludeAll => true,
            HiddenLayers::Include(names) => names.iter().any(|n| n.eq_ignore_ascii_case(name)),
        }
    }
}

/// The result of an import.
#[derive(Debug, Clone, Default)]
pub struct Imported {
    /// Geometries in document order.
    pub geometries: Vec<Geometry>,
    /// Skipped elements and degenerate paths.
    pub warnings: Vec<Warning>,
    /// Page size in mm (width, height).
    pub page_mm: [f64; 2],
    /// Layers left out because the drawing hides them (each also has a warning).
    pub skipped_layers: Vec<SkippedLayer>,
    /// How far the placement moved the artwork (mm; zero when it stays as in the file).
    pub moved_mm: [f64; 2],
    /// Texts holding fields (`SN {serial:05}`), kept to be shaped per part; in the file's
    /// coordinates (the placement does not move them: `moved_mm` says where it moved the rest).
    pub templates: Vec<TextTemplate>,
}

/// A file format [`import_file`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// SVG or gzip-compressed SVGZ.
    Svg,
    /// DXF, ASCII or binary.
    Dxf,
}

/// The format of a file: by extension (`.svg`, `.svgz`, `.dxf`, any case), else by content
/// (XML or gzip → SVG; the binary DXF sentinel or a leading `0`/`SECTION` pair → DXF).
pub fn detect_format(path: &Path, bytes: &[u8]) -> Option<Format> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("svg" | "svgz") => return Some(Format::Svg),
        Some("dxf") => return Some(Format::Dxf),
        _ => {}
    }
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let start = text
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(0);
    let text = &text[start..];
    if text.starts_with(b"AutoCAD Binary DXF") {
        return Some(Format::Dxf);
    }
    if text.starts_with(b"<") || text.starts_with(&[0x1f, 0x8b]) {
        return Some(Format::Svg);
    }
    let head: Vec<&[u8]> = text
        .split(|&b| b == b'\n')
        .take(2)
        .map(|l| l.trim_ascii())
        .collect();
    (head.len() == 2 && head[0] == b"0" && head[1] == b"SECTION").then_some(Format::Dxf)
}

/// Reads and imports an SVG or DXF file, choosing the format with [`detect_format`].
pub fn import_file(path: &Path, opts: &ImportOptions) -> Result<Imported, ImportError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        file: file.clone(),
        source,
    })?;
    match detect_format(path, &bytes) {
        Some(Format::Svg) => import_svg(&bytes, &file, opts),
        Some(Format::Dxf) => import_dxf(&bytes, &file, opts),
        None => Err(ImportError::UnknownFormat { file }),
    }
}

pub use crate::document::{short_list, Warning, LIST_MAX};

/// The geometries of an import placed as `opts.place` says ([`place_artwork`]); a placement
/// that cannot be made is an error naming the file.
fn placed(mut im: Imported, file: &str, opts: &ImportOptions) -> Result<Imported, ImportError> {
    place_artwork(&mut im, opts).map_err(|source| ImportError::Place {
        file: file.into(),
        source,
    })?;
    Ok(im)
}

/// Why a file could not be imported. Every variant names the file.
#[derive(Debug, Error)]
pub enum ImportError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is empty.
    #[error("{file}: empty file")]
    Empty {
        /// The file.
        file: String,
    },
    /// The file is not well-formed XML / SVG.
    #[error("{file}: not a valid SVG: {cause}")]
    Malformed {
        /// The file.
        file: String,
        /// Parser message, with line and column where known.
        cause: String,
    },
    /// The file is not a valid DXF.
    #[error("{file}: not a valid DXF: {cause}")]
    MalformedDxf {
        /// The file.
        file: String,
        /// Parser message, with the line (ASCII) or byte offset (binary) where known.
        cause: String,
    },
    /// Neither the extension nor the content says SVG or DXF.
    #[error("{file}: unknown format (galvoplan reads SVG, SVGZ and DXF files)")]
    UnknownFormat {
        /// The file.
        file: String,
    },
    /// The drawing expands to more than the import's budget (e.g. nested block arrays).
    #[error("{file}: {detail}")]
    TooLarge {
        /// The file.
        file: String,
        /// What overflowed.
        detail: String,
    },
    /// A coordinate, size or count in the file beyond what galvoplan reads ([`MAX_COORD_MM`],
    /// [`USER_MAX`], [`MAX_GLYPHS`]); `detail` names the element and where it is.
    #[error("{file}: {detail}")]
    Bounds {
        /// The file.
        file: String,
        /// The element, its line and the number.
        detail: String,
    },
    /// A text's fields cannot be read (an unknown field, an unbalanced brace); `detail` names
    /// the text and where it is.
    #[error("{file}: {detail}")]
    Field {
        /// The file.
        file: String,
        /// The element, its line, the text and what is wrong.
        detail: String,
    },
    /// The file holds nothing that can be marked.
    #[error("{file}: no markable geometry ({detail})")]
    NothingToMark {
        /// The file.
        file: String,
        /// What was found instead.
        detail: String,
    },
    /// The artwork cannot be placed as asked.
    #[error("{file}: {source}")]
    Place {
        /// The file.
        file: String,
        /// Why.
        source: PlaceError,
    },
}

/// Why a text cannot be laid out as glyph outlines, or why a text with fields does not read. A
/// DXF import skips a text with its reason; a tray refuses the part with it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TextError {
    /// The text's height is not a positive number.
    #[error("text height {height} is not a positive number")]
    Height {
        /// The height, in drawing units.
        height: f64,
    },
    /// More characters than one text may have.
    #[error("{chars} characters (more than {})", dxf_text::MAX_TEXT_CHARS)]
    TooLong {
        /// The text's characters.
        chars: usize,
    },
    /// The template's frame maps the text to nothing (a zero or infinite scale).
    #[error("{element}: the text's frame is degenerate")]
    DegenerateFrame {
        /// The template's element.
        element: String,
    },
    /// A glyph point beyond [`MAX_COORD_MM`] on the machine.
    #[error("{element}: a glyph point at ({x:e}, {y:e}) mm is beyond ±{MAX_COORD_MM:e} mm")]
    GlyphBeyond {
        /// The template's element.
        element: String,
        /// The point's x, mm.
        x: f64,
        /// The point's y, mm.
        y: f64,
    },
    /// The glyphs take more vertices than the import has left.
    #[error("more than {budget} vertices")]
    TooManyPoints {
        /// The vertices that were left.
        budget: usize,
    },
    /// The SVG the text is laid out in does not read (the XML parser's reason).
    #[error("{why}")]
    Markup {
        /// The parser's message.
        why: String,
    },
    /// The text cannot be laid out (usvg's reason).
    #[error("{why}")]
    Layout {
        /// usvg's message.
        why: String,
    },
    /// A laid-out point beyond [`MAX_COORD_MM`]: the element and the point.
    #[error("{detail}")]
    Beyond {
        /// The element, the point and the bound.
        detail: String,
    },
    /// An SVG `<text>` whose fields do not read: an unknown field, an unbalanced brace.
    #[error("{element} (line {line}) text \"{text}\": {why}")]
    Field {
        /// The element, as the file writes its start tag.
        element: String,
        /// Its line in the file.
        line: u32,
        /// The text, trimmed.
        text: String,
        /// What is wrong with its fields.
        why: TemplateError,
    },
}

/// Drops repeated points, detects implicit closing, rejects degenerate subpaths.
fn normalise(pts: Vec<Pt>, closed: bool) -> Result<(Vec<Pt>, bool), &'static str> {
    if pts.iter().any(|p| !p.is_finite()) {
        return Err("non-finite coordinates (NaN or infinity)");
    }
    let mut out: Vec<Pt> = Vec::with_capacity(pts.len());
    for p in pts {
        if out.last().is_none_or(|q| q.dist(p) > SAME_POINT_MM) {
            out.push(p);
        }
    }
    let mut closed = closed;
    if out.len() > 2 {
        if let (Some(a), Some(b)) = (out.first(), out.last()) {
            if a.dist(*b) <= SAME_POINT_MM {
                out.pop();
                closed = true;
            }
        }
    }
    if out.len() < 2 || polyline_length(&out, closed) < MIN_LENGTH_MM {
        return Err("zero length (shorter than 1 µm)");
    }
    Ok((out, closed))
}

/// The error for a file with nothing to mark: what was skipped (the first [`LIST_MAX`]
/// warnings), or `empty` when nothing was.
fn nothing_to_mark(file: &str, warnings: &[Warning], empty: &str) -> ImportError {
    let detail = if warnings.is_empty() {
        empty.to_string()
    } else {
        format!("only skipped content: {}", short_list(warnings, "; "))
    };
    ImportError::NothingToMark {
        file: file.into(),
        detail,
    }
}
