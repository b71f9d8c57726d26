//! Texts with fields (`SN {serial:05}`, the language of [`crate::document::production`]): the
//! import keeps them as [`TextTemplate`]s instead of glyph outlines, and [`shape_template`] lays
//! one out for a part with the same font path as any text ([`super::dxf_text::glyph_outlines`]).
//!
//! A template is checked when it is read: an unknown field or an unbalanced brace refuses the
//! file, naming the text and its line.

use super::dxf_text::{glyph_outlines, Layout};
use super::svg_scan::describe;
use super::{normalise, ImportOptions, TextError, Warning};
use crate::document::production::{is_template, parse_template};
use crate::document::{Geometry, Source, TextAlign, TextTemplate};
use crate::geom::{within_reach_bound, Pt};
use usvg::roxmltree::Document;

/// Checks the fields of every SVG `<text>` that holds a brace; `Err` is one line naming the
/// element, its line and the text.
pub(super) fn check_svg_texts(xml: &Document) -> Result<(), TextError> {
    for node in xml
        .descendants()
        .filter(|n| n.is_element() && n.tag_name().name() == "text")
    {
        let text: String = node
            .descendants()
            .filter(|n| n.is_text())
            .filter_map(|n| n.text())
            .collect();
        if !is_template(&text) {
            continue;
        }
        if let Err(why) = parse_template(&text) {
            let line = xml.text_pos_at(node.range().start).row;
            return Err(TextError::Field {
                element: describe(&node),
                line,
                text: text.trim().to_string(),
                why,
            });
        }
    }
    Ok(())
}

/// The frame scale of a template (how many mm one frame unit is, on average over both axes).
fn frame_scale(m: &[f64; 6]) -> f64 {
    let det = (m[0] * m[3] - m[1] * m[2]).abs();
    det.sqrt()
}

/// The glyphs of `text` set as template `t` says, in machine mm, as geometries of part `part`
/// (named after the template's element, on its layer), flattened within the options' chord
/// tolerance into at most `budget` vertices; with the font warnings.
pub fn shape_template(
    t: &TextTemplate,
    text: &str,
    part: u32,
    opts: &ImportOptions,
    budget: usize,
) -> Result<(Vec<Geometry>, Vec<Warning>), TextError> {
    let scale = frame_scale(&t.frame);
    if !(scale.is_finite() && scale > 0.0) {
        return Err(TextError::DegenerateFrame {
            element: t.element.clone(),
        });
    }
    let lines: Vec<String> = text.split('\n').map(str::to_string).collect();
    let layout = Layout {
        family: &t.family,
        em: t.em,
        pitch: t.pitch,
        first_baseline: t.first_baseline,
        align: t.align,
    };
    let tol = opts.chord_tol_mm.max(1e-6) / scale;
    let (outlines, warnings) = glyph_outlines(&lines, &layout, opts, tol, budget)?;
    let [a, b, c, d, e, f] = t.frame;
    let mut out = Vec::with_capacity(outlines.len());
    for (k, (pts, closed)) in outlines.into_iter().enumerate() {
        let pts: Vec<Pt> = pts
            .into_iter()
            .map(|q| Pt::new(a * q.x + c * q.y + e, b * q.x + d * q.y + f))
            .collect();
        if let Some(p) = pts.iter().find(|p| !within_reach_bound(**p)) {
            return Err(TextError::GlyphBeyond {
                element: t.element.clone(),
                x: p.x,
                y: p.y,
            });
        }
        // a glyph with an empty contour (DejaVu Sans' "u") is no loss
        let Ok((pts, closed)) = normalise(pts, closed) else {
            continue;
        };
        let source = Source {
            element: t.element.clone(),
            subpath: k,
            layer: t.layer.clone(),
            part,
        };
        out.push(Geometry::new(pts, closed, source));
    }
    Ok((out, warnings))
}

/// What an SVG `<text>` chunk gives a template: its text, position in the text's user space,
/// anchor, font family list and size (px), and the text's transform to px.
pub(super) struct SvgChunk<'a> {
    /// The chunk's text.
    pub text: &'a str,
    /// Its anchor point in the text's user space.
    pub at: (f64, f64),
    /// Alignment on the anchor.
    pub align: TextAlign,
    /// Font family list.
    pub family: String,
    /// Font size, px.
    pub em_px: f64,
    /// The text element's transform to the document's px: `[sx, ky, kx, sy, tx, ty]`.
    pub transform: [f64; 6],
}

/// A template of one SVG text chunk: frame units are px, the frame maps (x along the baseline,
/// y up, origin at the chunk's anchor) through the text's transform to mm.
pub(super) fn svg_template(
    chunk: &SvgChunk,
    element: String,
    line: Option<u32>,
    layer: String,
    px_to_mm: f64,
) -> TextTemplate {
    let [sx, ky, kx, sy, tx, ty] = chunk.transform;
    let (x, y) = chunk.at;
    let k = px_to_mm;
    TextTemplate {
        text: chunk.text.to_string(),
        element,
        line,
        layer,
        family: chunk.family.clone(),
        em: chunk.em_px,
        pitch: chunk.em_px * 1.2,
        align: chunk.align,
        first_baseline: 0.0,
        frame: [
            k * sx,
            k * ky,
            -k * kx,
            -k * sy,
            k * (sx * x + kx * y + tx),
            k * (ky * x + sy * y + ty),
        ],
    }
}
