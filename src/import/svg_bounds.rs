//! Numbers an SVG may hold, checked in the XML before usvg reads it.
//!
//! usvg works in `f32` and turns arcs and circles into curves with a count that grows with the
//! radius (the sixth root of radius ÷ tolerance): a path starting at x = 4.7·10⁶⁰ made a
//! 30 × 15 arc of radius 2·10⁶⁰ (SVG scales radii up to reach the endpoint), and usvg cut it
//! into ~10¹⁰ curves (65 s and 24 GB before the OOM killer, found by fuzzing). A `<circle
//! r="1e300">` does the same. So every coordinate and size in the file is read here first, as
//! the file writes it (user units, before transforms), and a number beyond [`USER_MAX`] is
//! refused with the element and its line. With every point and radius within that bound,
//! usvg's curve count per arc is at most about 50.
//!
//! The bound after transforms (millimetres on the machine) is
//! [`super::MAX_COORD_MM`], checked as the walk maps each point (`svg.rs`); text is bounded by
//! [`super::MAX_GLYPHS`] characters per file, counted here before any shaping.

use super::svg_scan::describe;
use super::{MAX_COORD_MM, MAX_GLYPHS};
use thiserror::Error;
use usvg::roxmltree::{Document, Node};

/// Largest coordinate, radius or size in user units, as written in the file (10⁹: 264 km in
/// px at 96 dpi, 1,000 km in mm). No drawing holds such numbers; usvg cannot be trusted past
/// them (`f32` overflows at 3.4·10³⁸, and arc flattening grows with the radius).
pub const USER_MAX: f64 = 1e9;

/// Attributes that hold one length (a number and a unit).
const LENGTHS: &[&str] = &[
    "x",
    "y",
    "width",
    "height",
    "r",
    "rx",
    "ry",
    "cx",
    "cy",
    "x1",
    "y1",
    "x2",
    "y2",
    "font-size",
    "stroke-width",
];

/// An SVG refused before usvg reads it; each message is one line naming the element and its
/// line.
#[derive(Debug, Clone, PartialEq, Error)]
pub(super) enum BoundsError {
    /// A coordinate, radius or length beyond [`USER_MAX`] user units.
    #[error(
        "{element}: {what} of {value:.4e} user units is beyond ±{USER_MAX:e} (a drawing lies \
         within ±{MAX_COORD_MM:e} mm)"
    )]
    Number {
        /// The element and its line: `<path id="p"> (line 2)`.
        element: String,
        /// What the number is: `a coordinate`, `an arc radius`, `the width`.
        what: String,
        /// The number, as the file writes it.
        value: f64,
    },
    /// More characters of text than [`MAX_GLYPHS`] in the file, reached at this element.
    #[error(
        "{element}: the file's text reaches {glyphs} characters, beyond the {MAX_GLYPHS} \
         galvoplan lays out in one file; split the text into several files"
    )]
    Text {
        /// The element and its line.
        element: String,
        /// The characters counted up to and with it.
        glyphs: usize,
    },
}

/// Checks every number of every element and the text of the file; `Err` names the element,
/// its line and the number.
pub(super) fn check(xml: &Document) -> Result<(), BoundsError> {
    let mut glyphs = 0usize;
    for node in xml.descendants().filter(|n| n.is_element()) {
        let where_ = || {
            let line = xml.text_pos_at(node.range().start).row;
            format!("{} (line {line})", describe(&node))
        };
        if let Some(d) = node.attribute("d") {
            path_data(d, &where_)?;
        }
        if let Some(points) = node.attribute("points") {
            for (x, y) in svgtypes::PointsParser::from(points) {
                within(x, "a coordinate", &where_)?;
                within(y, "a coordinate", &where_)?;
            }
        }
        for &name in LENGTHS {
            let Some(value) = node.attribute(name) else {
                continue;
            };
            // a list (`x="1 2 3"` on text) or a single length; what does not parse is usvg's
            for length in svgtypes::LengthListParser::from(value).flatten() {
                within(length.number, &format!("the {name}"), &where_)?;
            }
        }
        if node.tag_name().name() == "text" {
            glyphs += text_chars(&node);
            if glyphs > MAX_GLYPHS {
                return Err(BoundsError::Text {
                    element: where_(),
                    glyphs,
                });
            }
        }
    }
    Ok(())
}

/// Characters of a `<text>` element that take a glyph (white space does not).
fn text_chars(node: &Node) -> usize {
    node.descendants()
        .filter(|n| n.is_text())
        .filter_map(|n| n.text())
        .map(|t| t.chars().filter(|c| !c.is_whitespace()).count())
        .sum()
}

/// `v` is finite and within [`USER_MAX`]; `what` names it in the error, `element` (called only
/// on an error) the element and its line.
fn within(v: f64, what: &str, element: &dyn Fn() -> String) -> Result<(), BoundsError> {
    if v.is_finite() && v.abs() <= USER_MAX {
        Ok(())
    } else {
        Err(BoundsError::Number {
            element: element(),
            what: what.to_string(),
            value: v,
        })
    }
}

/// Checks path data: every point, made absolute as the path is followed, and every arc radius.
/// Path data that does not parse is left to usvg (which keeps the part before the error, as the
/// SVG specification asks). `element` names the element in the error.
fn path_data(d: &str, element: &dyn Fn() -> String) -> Result<(), BoundsError> {
    use svgtypes::PathSegment as S;
    let (mut cur, mut start) = ((0.0f64, 0.0f64), (0.0f64, 0.0f64));
    let at = |abs: bool, cur: (f64, f64), x: f64, y: f64| {
        if abs {
            (x, y)
        } else {
            (cur.0 + x, cur.1 + y)
        }
    };
    let point = |p: (f64, f64)| {
        within(p.0, "a coordinate", element)?;
        within(p.1, "a coordinate", element)
    };
    for segment in svgtypes::PathParser::from(d) {
        let Ok(segment) = segment else {
            break;
        };
        let (end, controls): ((f64, f64), Vec<(f64, f64)>) = match segment {
            S::MoveTo { abs, x, y } => {
                let p = at(abs, cur, x, y);
                start = p;
                (p, Vec::new())
            }
            S::LineTo { abs, x, y } | S::SmoothQuadratic { abs, x, y } => {
                (at(abs, cur, x, y), Vec::new())
            }
            S::HorizontalLineTo { abs, x } => {
                ((if abs { x } else { cur.0 + x }, cur.1), Vec::new())
            }
            S::VerticalLineTo { abs, y } => ((cur.0, if abs { y } else { cur.1 + y }), Vec::new()),
            S::CurveTo {
                abs,
                x1,
                y1,
                x2,
                y2,
                x,
                y,
            } => (
                at(abs, cur, x, y),
                vec![at(abs, cur, x1, y1), at(abs, cur, x2, y2)],
            ),
            S::SmoothCurveTo { abs, x2, y2, x, y } => {
                (at(abs, cur, x, y), vec![at(abs, cur, x2, y2)])
            }
            S::Quadratic { abs, x1, y1, x, y } => (at(abs, cur, x, y), vec![at(abs, cur, x1, y1)]),
            S::EllipticalArc {
                abs, rx, ry, x, y, ..
            } => {
                within(rx, "an arc radius", element)?;
                within(ry, "an arc radius", element)?;
                (at(abs, cur, x, y), Vec::new())
            }
            S::ClosePath { .. } => (start, Vec::new()),
        };
        for c in controls {
            point(c)?;
        }
        point(end)?;
        cur = end;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc(body: &str) -> String {
        format!("<svg xmlns=\"http://www.w3.org/2000/svg\">\n{body}\n</svg>")
    }

    fn checked(body: &str) -> Result<(), BoundsError> {
        let text = doc(body);
        let xml = Document::parse(&text).unwrap();
        check(&xml)
    }

    #[test]
    fn ordinary_drawings_pass() {
        assert!(checked(
            "<path d=\"M 10 10 l 20 0 a 5 5 0 0 1 10 0 c 1 2 3 4 5 6 h 3 v 4 z m 1 1 q 2 2 4 0 t 4 0 s 1 1 2 2\"/>\
             <circle cx=\"5\" cy=\"5\" r=\"1e6\"/><polyline points=\"0,0 1e8,2\"/>\
             <text x=\"1 2 3\" font-size=\"12pt\">abc</text>"
        )
        .is_ok());
    }

    #[test]
    fn each_kind_of_number_is_bounded_with_element_and_line() {
        for (body, what) in [
            (
                "<path id=\"p\" d=\"M 4666666666666666666666666666660 240 A 15 10 0 0 1 70 240\"/>",
                "a coordinate",
            ),
            (
                "<path id=\"p\" d=\"M 0 0 A 1e40 1 0 0 1 70 240\"/>",
                "an arc radius",
            ),
            (
                "<path id=\"p\" d=\"M 0 0 l 6e8 0 l 6e8 0\"/>",
                "a coordinate",
            ),
            (
                "<path id=\"p\" d=\"M 0 0 C 0 0 0 -2e9 5 5\"/>",
                "a coordinate",
            ),
            ("<circle id=\"p\" r=\"1e300\"/>", "the r of 1.0000e300"),
            (
                "<rect id=\"p\" width=\"1e12mm\" height=\"3\"/>",
                "the width",
            ),
            (
                "<polygon id=\"p\" points=\"0,0 1e10,0 3,3\"/>",
                "a coordinate",
            ),
            ("<text id=\"p\" font-size=\"1e99\">a</text>", "font-size"),
        ] {
            let e = checked(body).unwrap_err().to_string();
            assert!(
                e.starts_with("<") && e.contains("id=\"p\"> (line 2)"),
                "{e}"
            );
            assert!(e.contains(what), "{body}: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn a_number_beyond_says_the_bound_in_one_line() {
        assert_eq!(
            checked("<circle id=\"c\" r=\"1e300\"/>")
                .unwrap_err()
                .to_string(),
            "<circle id=\"c\"> (line 2): the r of 1.0000e300 user units is beyond ±1e9 (a \
             drawing lies within ±1e6 mm)"
        );
    }

    #[test]
    fn text_is_bounded_per_file() {
        let a = "x".repeat(MAX_GLYPHS / 2 + 1);
        assert!(checked(&format!("<text>{a}</text>")).is_ok());
        let e = checked(&format!(
            "<text>{a}</text><text id=\"t2\"><tspan>{a}</tspan></text>"
        ))
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("<text id=\"t2\"> (line 2)") && e.contains("characters"),
            "{e}"
        );
        // white space takes no glyph
        let spaces = " ".repeat(MAX_GLYPHS + 1);
        assert!(checked(&format!("<text>{spaces}</text>")).is_ok());
    }
}
