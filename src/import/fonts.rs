//! Fonts for `<text>` (SVG) and TEXT/MTEXT (DXF): the bundled DejaVu Sans plus, unless the
//! options say otherwise, the system's fonts; every substitution is reported.
//!
//! The bundled face is loaded first, so it wins ties against an installed copy of the same
//! family, weight and style: "DejaVu Sans" and `sans-serif` give the same outlines on a fresh
//! machine as on one with more fonts installed.

use super::{FontSource, Warning};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};
use usvg::fontdb::{self, Database, Family, Query, Source};
use usvg::{FontResolver, FontStretch, FontStyle};

/// The bundled fallback face (Bitstream Vera licence, `assets/fonts/DejaVuSans-LICENSE.txt`).
static BUNDLED_FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The bundled DejaVu Sans (TrueType), for the GUI's fallback font too.
pub fn bundled_font() -> &'static [u8] {
    BUNDLED_FONT
}
/// Family name of the bundled face.
pub const BUNDLED_FAMILY: &str = "DejaVu Sans";
/// Cap height of DejaVu Sans in em (1493 / 2048 font units): DXF text heights are cap heights.
pub const BUNDLED_CAP_HEIGHT_EM: f64 = 1493.0 / 2048.0;

static BUNDLED_ONLY: OnceLock<Arc<Database>> = OnceLock::new();
static WITH_SYSTEM: OnceLock<Arc<Database>> = OnceLock::new();

fn build_database(system: bool) -> Arc<Database> {
    let mut db = Database::new();
    db.load_font_source(Source::Binary(Arc::new(BUNDLED_FONT)));
    if system {
        db.load_system_fonts();
    }
    // generic families resolve to DejaVu faces (installed with the bundled one on Debian);
    // cursive and fantasy have none and fall back with a warning
    db.set_sans_serif_family(BUNDLED_FAMILY);
    db.set_serif_family("DejaVu Serif");
    db.set_monospace_family("DejaVu Sans Mono");
    Arc::new(db)
}

/// The font database for `source`, built once per process.
pub fn database(source: FontSource) -> Arc<Database> {
    let cell = match source {
        FontSource::System => &WITH_SYSTEM,
        FontSource::BundledOnly => &BUNDLED_ONLY,
    };
    Arc::clone(cell.get_or_init(|| build_database(source == FontSource::System)))
}

/// A font request that was not met as asked.
#[derive(Debug, Clone, PartialEq)]
pub enum FontMiss {
    /// None of the families exists: the bundled face was used.
    Family {
        /// The requested family list, as written.
        requested: String,
    },
    /// The family exists but not in the requested weight or style.
    Face {
        /// The requested family list.
        requested: String,
        /// What was asked, e.g. `weight 700 italic`.
        asked: String,
        /// What was used.
        used: String,
    },
    /// A common CAD font that is not installed, drawn with its closest face (a note: the
    /// operator expects it, the report records it).
    Mapped {
        /// The requested family list.
        requested: String,
        /// The face used.
        used: String,
    },
    /// A character is in no font at all: the font's missing-glyph box is drawn.
    Char {
        /// The character.
        c: char,
    },
}

impl FontMiss {
    /// The requested family list this miss belongs to (empty for a missing character).
    pub fn requested(&self) -> &str {
        match self {
            FontMiss::Family { requested }
            | FontMiss::Face { requested, .. }
            | FontMiss::Mapped { requested, .. } => requested,
            FontMiss::Char { .. } => "",
        }
    }
    /// The warning text.
    pub fn message(&self) -> String {
        match self {
            FontMiss::Family { requested } => format!(
                "font family '{requested}' not found; using the bundled {BUNDLED_FAMILY}"
            ),
            FontMiss::Face {
                requested,
                asked,
                used,
            } => format!("font '{requested}' has no {asked} face; using {used}"),
            FontMiss::Mapped { requested, used } => {
                format!("font '{requested}' is not installed; drawn with its closest, {used}")
            }
            FontMiss::Char { c } => format!(
                "character '{c}' (U+{:04X}) is in no available font; its missing-glyph box is outlined",
                u32::from(*c)
            ),
        }
    }
}

/// Collects [`FontMiss`]es while usvg lays text out.
#[derive(Debug, Default)]
pub struct Misses(Mutex<Vec<FontMiss>>);

impl Misses {
    fn push(&self, m: FontMiss) {
        // a lock is poisoned only by a panic while it was held; the list is whole (a push)
        let mut v = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        if !v.contains(&m) {
            v.push(m);
        }
    }
    /// The misses recorded so far.
    pub fn take(&self) -> Vec<FontMiss> {
        let mut v = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        std::mem::take(&mut *v)
    }
}

/// A family list as written, without CSS quotes: `No Such Font, sans-serif`.
pub fn family_list(families: &[usvg::FontFamily]) -> String {
    let names: Vec<String> = families
        .iter()
        .map(|f| match f {
            usvg::FontFamily::Named(name) => name.clone(),
            generic => generic.to_string(),
        })
        .collect();
    names.join(", ")
}

fn style_words(weight: u16, style: fontdb::Style) -> String {
    match style {
        fontdb::Style::Normal => format!("weight {weight}"),
        fontdb::Style::Italic => format!("weight {weight} italic"),
        fontdb::Style::Oblique => format!("weight {weight} oblique"),
    }
}

fn query_for<'a>(font: &usvg::Font, families: &'a [Family<'a>]) -> Query<'a> {
    let stretch = match font.stretch() {
        FontStretch::UltraCondensed => fontdb::Stretch::UltraCondensed,
        FontStretch::ExtraCondensed => fontdb::Stretch::ExtraCondensed,
        FontStretch::Condensed => fontdb::Stretch::Condensed,
        FontStretch::SemiCondensed => fontdb::Stretch::SemiCondensed,
        FontStretch::Normal => fontdb::Stretch::Normal,
        FontStretch::SemiExpanded => fontdb::Stretch::SemiExpanded,
        FontStretch::Expanded => fontdb::Stretch::Expanded,
        FontStretch::ExtraExpanded => fontdb::Stretch::ExtraExpanded,
        FontStretch::UltraExpanded => fontdb::Stretch::UltraExpanded,
    };
    let style = match font.style() {
        FontStyle::Normal => fontdb::Style::Normal,
        FontStyle::Italic => fontdb::Style::Italic,
        FontStyle::Oblique => fontdb::Style::Oblique,
    };
    Query {
        families,
        weight: fontdb::Weight(font.weight()),
        stretch,
        style,
    }
}

/// Fonts CAD drawings name that are rarely installed on a Linux machine, by the generic family
/// closest to them (lower case, without a file extension): the Windows core fonts and
/// AutoCAD's shape fonts (SHX; their single-stroke letters are closest to a sans face).
const CAD_SANS: &[&str] = &[
    "arial",
    "arial narrow",
    "helvetica",
    "verdana",
    "tahoma",
    "calibri",
    "segoe ui",
    "txt",
    "simplex",
    "romans",
    "isocp",
    "isoct",
    "monotxt8",
    "gdt",
    "osifont",
];
const CAD_SERIF: &[&str] = &[
    "times",
    "times new roman",
    "romanc",
    "romant",
    "cambria",
    "georgia",
];
const CAD_MONO: &[&str] = &["courier", "courier new", "cour", "monotxt", "consolas"];

/// The generic family closest to the first named family of `families` when that is a common
/// CAD font (see [`CAD_SANS`]).
fn cad_alias(families: &[usvg::FontFamily]) -> Option<Family<'static>> {
    let name = families.iter().find_map(|f| match f {
        usvg::FontFamily::Named(n) => Some(n.trim().to_ascii_lowercase()),
        _ => None,
    })?;
    let stem = name
        .strip_suffix(".shx")
        .or_else(|| name.strip_suffix(".ttf"))
        .unwrap_or(&name);
    if CAD_SANS.contains(&stem) {
        Some(Family::SansSerif)
    } else if CAD_SERIF.contains(&stem) {
        Some(Family::Serif)
    } else if CAD_MONO.contains(&stem) {
        Some(Family::Monospace)
    } else {
        None
    }
}

fn select_font(font: &usvg::Font, db: &Database, misses: &Misses) -> Option<fontdb::ID> {
    let families: Vec<Family> = font
        .families()
        .iter()
        .map(|f| match f {
            usvg::FontFamily::Serif => Family::Serif,
            usvg::FontFamily::SansSerif => Family::SansSerif,
            usvg::FontFamily::Cursive => Family::Cursive,
            usvg::FontFamily::Fantasy => Family::Fantasy,
            usvg::FontFamily::Monospace => Family::Monospace,
            usvg::FontFamily::Named(s) => Family::Name(s),
        })
        .collect();
    let query = query_for(font, &families);
    let requested = family_list(font.families());
    if let Some(id) = db.query(&query) {
        if let Some(face) = db.face(id) {
            if face.weight != query.weight || face.style != query.style {
                misses.push(FontMiss::Face {
                    requested,
                    asked: style_words(query.weight.0, query.style),
                    used: format!(
                        "{} {}",
                        face.families.first().map_or("?", |f| f.0.as_str()),
                        style_words(face.weight.0, face.style)
                    ),
                });
            }
        }
        return Some(id);
    }
    if let Some(generic) = cad_alias(font.families()) {
        // the closest generic family, else the bundled sans (always there)
        let closest = [generic];
        let sans = [Family::SansSerif];
        let found = db
            .query(&query_for(font, &closest))
            .or_else(|| db.query(&query_for(font, &sans)));
        if let Some(id) = found {
            let used = db
                .face(id)
                .and_then(|f| f.families.first().map(|f| f.0.clone()))
                .unwrap_or_else(|| BUNDLED_FAMILY.to_string());
            misses.push(FontMiss::Mapped { requested, used });
            return Some(id);
        }
    }
    misses.push(FontMiss::Family { requested });
    let bundled = [Family::Name(BUNDLED_FAMILY)];
    db.query(&query_for(font, &bundled))
}

/// usvg options using the font database of `source`; misses are recorded in `misses`.
pub fn usvg_options(source: FontSource, misses: &Misses) -> usvg::Options<'_> {
    let fallback = FontResolver::default_fallback_selector();
    usvg::Options {
        fontdb: database(source),
        font_family: BUNDLED_FAMILY.to_string(),
        font_resolver: FontResolver {
            select_font: Box::new(move |font, db| select_font(font, db, misses)),
            select_fallback: Box::new(move |c, used, db| {
                let id = fallback(c, used, db);
                if id.is_none() {
                    misses.push(FontMiss::Char { c });
                }
                id
            }),
        },
        ..usvg::Options::default()
    }
}

/// Turns misses into warnings; `element_of` names the first text element that asked for a
/// family list (or `<text>` when none is known).
pub fn miss_warnings(misses: Vec<FontMiss>, element_of: impl Fn(&str) -> String) -> Vec<Warning> {
    misses
        .into_iter()
        .map(|m| Warning {
            element: element_of(m.requested()),
            line: None,
            message: m.message(),
            note: matches!(m, FontMiss::Mapped { .. }),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_face_is_found_by_name_and_generic_family() {
        let db = database(FontSource::BundledOnly);
        let q = |f: &[Family]| {
            db.query(&Query {
                families: f,
                ..Query::default()
            })
        };
        let named = q(&[Family::Name(BUNDLED_FAMILY)]);
        assert!(named.is_some());
        assert_eq!(q(&[Family::SansSerif]), named);
        assert_eq!(q(&[Family::Name("No Such Font")]), None);
    }
}
