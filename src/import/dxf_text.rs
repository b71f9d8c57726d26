//! DXF TEXT and MTEXT as glyph outlines, laid out by usvg with the fonts of [`super::fonts`]
//! (a small SVG `<text>` per entity), so SVG and DXF text share fonts and fallback warnings.
//!
//! Approximations, all documented in the README: the text height is the cap height of the
//! font (DejaVu Sans' 0.729 em is used for every font); SHX fonts are not available and fall
//! back to DejaVu Sans with a warning; MTEXT formatting codes are stripped (paragraphs kept,
//! no automatic word wrap); Aligned and Fit justification are set as left-justified.

use super::curves::Affine;
use super::fonts::{database, BUNDLED_CAP_HEIGHT_EM, BUNDLED_FAMILY};
use super::svg::{text_outlines, Outline, PX_TO_MM};
use super::{ImportOptions, TextError, Warning};
use crate::document::TextAlign;
use crate::geom::Pt;
use ::dxf::entities::{MText, Text};
use ::dxf::enums::{AttachmentPoint, HorizontalTextJustification, VerticalTextJustification};
use ::dxf::Drawing;
use usvg::fontdb;

/// AutoCAD's line pitch of MTEXT: 5/3 of the text height at line spacing factor 1.
const MTEXT_LINE_PITCH: f64 = 5.0 / 3.0;
/// DejaVu Sans' descent (483 / 2048 em): the bottom of TEXT's "bottom" justification.
const DESCENT_EM: f64 = 483.0 / 2048.0;
/// Longest text laid out per entity (characters): more is not a marking job.
pub(super) const MAX_TEXT_CHARS: usize = 10_000;

/// Horizontal anchor of the lines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HAnchor {
    /// Lines start at the anchor.
    Start,
    /// Lines are centred on it.
    Middle,
    /// Lines end at it.
    End,
}

/// Vertical anchor of the block of lines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VAnchor {
    /// The first line's baseline.
    Baseline,
    /// The last line's descent.
    Bottom,
    /// Half way between the first line's cap height and the last baseline.
    Middle,
    /// The first line's cap height.
    Top,
}

/// One TEXT or MTEXT entity, ready to lay out.
#[derive(Debug, Clone)]
pub struct TextRun {
    /// Lines of plain text.
    pub lines: Vec<String>,
    /// Cap height in drawing units.
    pub height: f64,
    /// Baseline-to-baseline distance in drawing units.
    pub pitch: f64,
    /// Font family.
    pub family: String,
    /// Anchors.
    pub anchor: (HAnchor, VAnchor),
    /// Text frame (x along the baseline, y up, origin at the anchor) → entity coordinates.
    pub frame: Affine,
}

/// The font family of a text style: the family of an installed font file of that name, else
/// the file's stem (the font resolver then falls back to DejaVu Sans with a warning).
fn style_family(drawing: &Drawing, style_name: &str, opts: &ImportOptions) -> String {
    let Some(style) = drawing
        .styles()
        .find(|s| s.name.eq_ignore_ascii_case(style_name))
    else {
        return BUNDLED_FAMILY.to_string();
    };
    let file = style.primary_font_file_name.trim();
    if file.is_empty() {
        return BUNDLED_FAMILY.to_string();
    }
    let wanted = std::path::Path::new(file)
        .file_name()
        .and_then(|f| f.to_str())
        .unwrap_or(file)
        .to_ascii_lowercase();
    let db = database(opts.fonts);
    let installed = db.faces().find(|f| match &f.source {
        fontdb::Source::File(p) => p
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.to_ascii_lowercase() == wanted),
        _ => false,
    });
    match installed.and_then(|f| f.families.first()) {
        Some((family, _)) => family.clone(),
        None => std::path::Path::new(&wanted)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or(&wanted)
            .to_string(),
    }
}

fn skew(oblique_deg: f64) -> Affine {
    let t = oblique_deg.to_radians().tan();
    Affine {
        m: [1.0, 0.0, if t.is_finite() { t } else { 0.0 }, 1.0, 0.0, 0.0],
    }
}

/// A TEXT entity (OCS coordinates).
pub fn text_run(t: &Text, drawing: &Drawing, opts: &ImportOptions) -> TextRun {
    use HorizontalTextJustification as H;
    use VerticalTextJustification as V;
    let h = match t.horizontal_text_justification {
        H::Center | H::Middle => HAnchor::Middle,
        H::Right => HAnchor::End,
        H::Left | H::Aligned | H::Fit => HAnchor::Start,
    };
    let v = match (
        t.horizontal_text_justification,
        t.vertical_text_justification,
    ) {
        (H::Middle, _) | (_, V::Middle) => VAnchor::Middle,
        (_, V::Top) => VAnchor::Top,
        (_, V::Bottom) => VAnchor::Bottom,
        (_, V::Baseline) => VAnchor::Baseline,
    };
    let anchor_at_start = h == HAnchor::Start && v == VAnchor::Baseline;
    let at = if anchor_at_start {
        &t.location
    } else {
        &t.second_alignment_point
    };
    let width = if t.relative_x_scale_factor > 0.0 {
        t.relative_x_scale_factor
    } else {
        1.0
    };
    let frame = Affine::translate(at.x, at.y)
        .then(Affine::rotate(t.rotation.to_radians()))
        .then(skew(t.oblique_angle))
        .then(Affine::scale(width, 1.0));
    TextRun {
        lines: vec![decode_specials(&t.value)],
        height: t.text_height,
        pitch: t.text_height * MTEXT_LINE_PITCH,
        family: style_family(drawing, &t.text_style_name, opts),
        anchor: (h, v),
        frame,
    }
}

/// An MTEXT entity (WCS insertion point, direction from the x axis or the rotation in degrees).
/// `\U+XXXX` escapes of a DXF value as written, decoded (what the `dxf` crate does to values
/// it reads); anything else is kept for [`strip_mtext`].
fn decode_unicode(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find("\\U+") {
        out.push_str(&rest[..i]);
        let hex = rest.get(i + 3..i + 7);
        match hex
            .and_then(|h| u32::from_str_radix(h, 16).ok())
            .and_then(char::from_u32)
        {
            Some(c) => {
                out.push(c);
                rest = &rest[i + 7..];
            }
            None => {
                out.push_str("\\U+");
                rest = &rest[i + 3..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// An MTEXT entity (`raw`: its text as the file writes it, when the scan of the file found it;
/// else the `dxf` crate's reading of it).
pub fn mtext_run(t: &MText, raw: Option<&str>, drawing: &Drawing, opts: &ImportOptions) -> TextRun {
    use AttachmentPoint as A;
    let (h, v) = match t.attachment_point {
        A::TopLeft => (HAnchor::Start, VAnchor::Top),
        A::TopCenter => (HAnchor::Middle, VAnchor::Top),
        A::TopRight => (HAnchor::End, VAnchor::Top),
        A::MiddleLeft => (HAnchor::Start, VAnchor::Middle),
        A::MiddleCenter => (HAnchor::Middle, VAnchor::Middle),
        A::MiddleRight => (HAnchor::End, VAnchor::Middle),
        A::BottomLeft => (HAnchor::Start, VAnchor::Bottom),
        A::BottomCenter => (HAnchor::Middle, VAnchor::Bottom),
        A::BottomRight => (HAnchor::End, VAnchor::Bottom),
    };
    let dir = Pt::new(t.x_axis_direction.x, t.x_axis_direction.y);
    let angle = if dir.norm() > 0.0 {
        dir.y.atan2(dir.x)
    } else {
        t.rotation_angle.to_radians()
    };
    let raw = match raw {
        Some(r) => decode_unicode(r),
        None => {
            let mut r: String = t.extended_text.concat();
            r.push_str(&t.text);
            r
        }
    };
    let spacing = if t.line_spacing_factor > 0.0 {
        t.line_spacing_factor
    } else {
        1.0
    };
    TextRun {
        lines: strip_mtext(&raw).split('\n').map(str::to_string).collect(),
        height: t.initial_text_height,
        pitch: t.initial_text_height * MTEXT_LINE_PITCH * spacing,
        family: style_family(drawing, &t.text_style_name, opts),
        anchor: (h, v),
        frame: Affine::translate(t.insertion_point.x, t.insertion_point.y)
            .then(Affine::rotate(angle)),
    }
}

/// `%%d`, `%%p`, `%%c` and `%%%` of TEXT values.
fn decode_specials(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find("%%") {
        out.push_str(&rest[..i]);
        let after = &rest[i + 2..];
        let mut chars = after.chars();
        match chars.next().map(|c| c.to_ascii_lowercase()) {
            Some('d') => out.push('°'),
            Some('p') => out.push('±'),
            Some('c') => out.push('⌀'),
            Some('%') => out.push('%'),
            // underline/overline toggles draw nothing here
            Some('u' | 'o') => {}
            Some(c) => {
                out.push_str("%%");
                out.push(c);
            }
            None => out.push_str("%%"),
        }
        rest = chars.as_str();
    }
    out.push_str(rest);
    out
}

/// MTEXT's inline formatting removed: `\P` is a new line, `\~` a space, `\\ \{ \}` literal;
/// codes with an argument up to `;` (`\f \H \W \Q \T \A \C \c \p`) and toggles
/// (`\L \l \O \o \K \k`) dropped; `\S a^b;` stacks become `a/b`; braces dropped.
fn strip_mtext(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '{' | '}' => {}
            '\\' => match chars.next() {
                Some('P') => out.push('\n'),
                Some('~') => out.push(' '),
                Some(c @ ('\\' | '{' | '}')) => out.push(c),
                Some('S') => {
                    for c in chars.by_ref().take_while(|&c| c != ';') {
                        out.push(if c == '^' || c == '#' { '/' } else { c });
                    }
                }
                Some('f' | 'F' | 'H' | 'W' | 'Q' | 'T' | 'A' | 'C' | 'c' | 'p') => {
                    for _ in chars.by_ref().take_while(|&c| c != ';') {}
                }
                Some('L' | 'l' | 'O' | 'o' | 'K' | 'k' | 'N') => {}
                Some(c) => out.push(c),
                None => {}
            },
            _ => out.push(c),
        }
    }
    decode_specials(&out)
}

fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\t' => out.push(' '),
            c if c.is_control() => {}
            c => out.push(c),
        }
    }
    out
}

/// The run's glyph outlines in its text frame (x along the baseline, y up, origin at the
/// anchor), flattened within `tol` drawing units into at most `budget` vertices, with the font
/// warnings.
pub fn outlines(
    run: &TextRun,
    opts: &ImportOptions,
    tol: f64,
    budget: usize,
) -> Result<(Vec<Outline>, Vec<Warning>), TextError> {
    if !(run.height.is_finite() && run.height > 0.0) {
        return Err(TextError::Height { height: run.height });
    }
    let chars: usize = run.lines.iter().map(|l| l.chars().count()).sum();
    if chars > MAX_TEXT_CHARS {
        return Err(TextError::TooLong { chars });
    }
    let (h, v) = run.anchor;
    let align = match h {
        HAnchor::Start => TextAlign::Start,
        HAnchor::Middle => TextAlign::Middle,
        HAnchor::End => TextAlign::End,
    };
    let em = run.height / BUNDLED_CAP_HEIGHT_EM;
    let layout = Layout {
        family: &run.family,
        em,
        pitch: run.pitch,
        first_baseline: first_baseline(run.lines.len(), run.height, run.pitch, v),
        align,
    };
    glyph_outlines(&run.lines, &layout, opts, tol, budget)
}

/// The first baseline above the anchor (y up) of `lines` lines of cap height `height`, `pitch`
/// apart, for a vertical anchor.
pub fn first_baseline(lines: usize, height: f64, pitch: f64, v: VAnchor) -> f64 {
    let n = lines.max(1) as f64;
    match v {
        VAnchor::Baseline => 0.0,
        VAnchor::Top => -height,
        VAnchor::Middle => (-height + (n - 1.0) * pitch) / 2.0,
        VAnchor::Bottom => (n - 1.0) * pitch + DESCENT_EM / BUNDLED_CAP_HEIGHT_EM * height,
    }
}

/// How lines of text sit in their frame (x along the baseline, y up, origin at the anchor), in
/// the frame's units.
pub struct Layout<'a> {
    /// Font family list, as CSS writes it.
    pub family: &'a str,
    /// Font size (em).
    pub em: f64,
    /// Baseline-to-baseline distance.
    pub pitch: f64,
    /// The first baseline's height above the anchor.
    pub first_baseline: f64,
    /// Alignment along the baseline.
    pub align: TextAlign,
}

/// The glyph outlines of `lines` laid out as `layout` says, in its frame (y up), flattened
/// within `tol` frame units into at most `budget` vertices, with the font warnings. The one
/// text path of DXF text and of text templates: a small SVG laid out by usvg with the import's
/// fonts.
pub fn glyph_outlines(
    lines: &[String],
    layout: &Layout,
    opts: &ImportOptions,
    tol: f64,
    budget: usize,
) -> Result<(Vec<Outline>, Vec<Warning>), TextError> {
    // the SVG is in px: 1 frame unit = 1 mm of the SVG importer's output
    let px = 1.0 / PX_TO_MM;
    let anchor = match layout.align {
        TextAlign::Start => "start",
        TextAlign::Middle => "middle",
        TextAlign::End => "end",
    };
    let mut svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="1" height="1"><text font-family="{}" font-size="{}" text-anchor="{anchor}" xml:space="preserve">"#,
        xml_escape(layout.family),
        layout.em * px
    );
    for (i, line) in lines.iter().enumerate() {
        let y = -(layout.first_baseline - i as f64 * layout.pitch) * px;
        svg.push_str(&format!(
            r#"<tspan x="0" y="{y}">{}</tspan>"#,
            xml_escape(line)
        ));
    }
    svg.push_str("</text></svg>");
    let (outlines, warnings) = text_outlines(&svg, opts, tol, budget)?;
    let flipped = outlines
        .into_iter()
        .map(|(p, closed)| (p.into_iter().map(|q| Pt::new(q.x, -q.y)).collect(), closed))
        .collect();
    Ok((flipped, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mtext_codes_are_stripped() {
        assert_eq!(
            strip_mtext(r"{\fArial|b1;SN} 0042\P\H2.5;ACME \S1^2; 10%%d"),
            "SN 0042\nACME 1/2 10°"
        );
        assert_eq!(strip_mtext(r"a\\b\{c\}"), r"a\b{c}");
        assert_eq!(decode_unicode(r"a\U+00B0b\U+zz"), "a°b\\U+zz");
        // a field in a formatted MTEXT: the braces of the format go, the escaped ones stay
        assert_eq!(
            strip_mtext(r"{\fArial|b1;SN} \{serial:04\}"),
            "SN {serial:04}"
        );
    }
}
