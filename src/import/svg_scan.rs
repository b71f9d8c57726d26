//! What usvg leaves out without a word, found in the XML before it runs: hidden layers and
//! other `display:none` content, broken or external `<use>` references, Inkscape's flowed text
//! (`<flowRoot>`), images and foreign objects, elements usvg does not know. Each gets a warning
//! naming the element and its line; hidden layers the options include are un-hidden by editing
//! the source text (same lines) before usvg reads it.

use super::{HiddenLayers, LayerHidden, SkippedLayer, Warning};
use rustc_hash::FxHashMap;
use std::ops::Range;
use usvg::roxmltree::{Document, Node};

const SVG_NS: &str = "http://www.w3.org/2000/svg";
const XLINK_NS: &str = "http://www.w3.org/1999/xlink";
const INKSCAPE_NS: &str = "http://www.inkscape.org/namespaces/inkscape";

/// Elements that carry visible content galvoplan cannot mark.
const UNSUPPORTED: &[&str] = &[
    "image",
    "foreignObject",
    "video",
    "audio",
    "canvas",
    "iframe",
];
/// Containers whose children are not drawn directly.
const NOT_RENDERED: &[&str] = &[
    "defs", "symbol", "clipPath", "mask", "marker", "pattern", "metadata",
];
/// Elements that draw something.
const DRAWABLE: &[&str] = &[
    "path", "rect", "circle", "ellipse", "line", "polyline", "polygon", "text", "use", "image",
];
/// SVG elements usvg reads (its element table) or that hold no drawing.
const KNOWN: &[&str] = &[
    "a",
    "circle",
    "clipPath",
    "defs",
    "ellipse",
    "feBlend",
    "feColorMatrix",
    "feComponentTransfer",
    "feComposite",
    "feConvolveMatrix",
    "feDiffuseLighting",
    "feDisplacementMap",
    "feDistantLight",
    "feDropShadow",
    "feFlood",
    "feFuncA",
    "feFuncB",
    "feFuncG",
    "feFuncR",
    "feGaussianBlur",
    "feImage",
    "feMerge",
    "feMergeNode",
    "feMorphology",
    "feOffset",
    "fePointLight",
    "feSpecularLighting",
    "feSpotLight",
    "feTile",
    "feTurbulence",
    "filter",
    "g",
    "image",
    "line",
    "linearGradient",
    "marker",
    "mask",
    "path",
    "pattern",
    "polygon",
    "polyline",
    "radialGradient",
    "rect",
    "stop",
    "style",
    "svg",
    "switch",
    "symbol",
    "text",
    "textPath",
    "tref",
    "tspan",
    "use",
    "title",
    "desc",
    "metadata",
    "script",
];

/// What the scan found.
#[derive(Debug, Default)]
pub(super) struct Scan {
    /// One warning per skipped element (per hidden layer: one summary).
    pub warnings: Vec<Warning>,
    /// Hidden layers skipped.
    pub skipped_layers: Vec<SkippedLayer>,
    /// Edits of the source text that show the hidden layers the options include: byte range
    /// of an attribute value and its new value.
    pub edits: Vec<(Range<usize>, String)>,
}

/// `<tag id="…">`, or `<tag>` without an id.
pub(super) fn describe(node: &Node) -> String {
    match node.attribute("id") {
        Some(id) => format!("<{} id=\"{id}\">", node.tag_name().name()),
        None => format!("<{}>", node.tag_name().name()),
    }
}

fn line_of(xml: &Document, node: &Node) -> u32 {
    xml.text_pos_at(node.range().start).row
}

/// Line numbers by byte offset, for many lookups (`Document::text_pos_at` scans the text from
/// its start on every call).
struct LineIndex(Vec<usize>);

impl LineIndex {
    fn new(text: &str) -> Self {
        LineIndex(
            text.bytes()
                .enumerate()
                .filter(|&(_, b)| b == b'\n')
                .map(|(i, _)| i)
                .collect(),
        )
    }
    /// The 1-based line holding byte `pos`.
    fn line(&self, pos: usize) -> u32 {
        u32::try_from(self.0.partition_point(|&nl| nl < pos) + 1).unwrap_or(u32::MAX)
    }
}

fn is_svg(node: &Node) -> bool {
    node.tag_name().namespace().is_none_or(|ns| ns == SVG_NS)
}

/// The `display` of an element as written: its `style` declaration, else its attribute.
fn display_none(node: &Node) -> bool {
    let from_style = node.attribute("style").and_then(|s| {
        s.split(';')
            .filter_map(|d| d.split_once(':'))
            .filter(|(k, _)| k.trim() == "display")
            .map(|(_, v)| v.trim().trim_end_matches("!important").trim() == "none")
            .next_back()
    });
    from_style.unwrap_or_else(|| {
        node.attribute("display")
            .is_some_and(|v| v.trim() == "none")
    })
}

/// Drawable elements in a subtree (the node included).
fn drawables(node: &Node) -> usize {
    node.descendants()
        .filter(|n| n.is_element() && is_svg(n) && DRAWABLE.contains(&n.tag_name().name()))
        .count()
}

/// The layer name of a top-level group: its `inkscape:label`, else its `id`.
fn layer_name(node: &Node) -> Option<String> {
    node.attribute((INKSCAPE_NS, "label"))
        .or_else(|| node.attribute("id"))
        .map(str::to_string)
}

/// The edits that make a `display:none` element displayed.
fn unhide(node: &Node, edits: &mut Vec<(Range<usize>, String)>) {
    for a in node.attributes() {
        if a.namespace().is_some() {
            continue;
        }
        match a.name() {
            "display" if a.value().trim() == "none" => {
                edits.push((a.range_value(), "inline".into()));
            }
            "style" => {
                let decls: Vec<String> = a
                    .value()
                    .split(';')
                    .map(|d| match d.split_once(':') {
                        Some((k, _)) if k.trim() == "display" => format!("{}:inline", k),
                        _ => d.to_string(),
                    })
                    .collect();
                let value = decls.join(";");
                if value != a.value() {
                    // entities in the value are gone from the edit; the value has none that
                    // matter to CSS declarations (quotes are written as &quot; only in strings)
                    edits.push((a.range_value(), xml_escape(&value)));
                }
            }
            _ => {}
        }
    }
}

/// The edit that hides an element: `display:none` as the last declaration of its `style`
/// (which wins over attributes and earlier declarations), or a new `style` attribute.
fn hide(text: &str, node: &Node, edits: &mut Vec<(Range<usize>, String)>) {
    let style = node
        .attributes()
        .find(|a| a.name() == "style" && a.namespace().is_none());
    match style {
        Some(a) => edits.push((
            a.range_value(),
            format!("{};display:none", xml_escape(a.value())),
        )),
        None => {
            // right after the tag name as written (with its prefix, if any)
            let start = node.range().start + 1;
            let name_len = text
                .get(start..)
                .and_then(|t| t.find(|c: char| c.is_whitespace() || c == '/' || c == '>'))
                .unwrap_or(0);
            let at = start + name_len;
            edits.push((at..at, " style=\"display:none\"".into()));
        }
    }
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('"', "&quot;")
}

/// The source text with the edits applied (ranges do not overlap).
pub(super) fn apply_edits(text: &str, edits: &[(Range<usize>, String)]) -> String {
    let mut sorted: Vec<&(Range<usize>, String)> = edits.iter().collect();
    sorted.sort_by_key(|(r, _)| r.start);
    let mut out = String::with_capacity(text.len() + 16 * edits.len());
    let mut at = 0;
    for (r, v) in sorted {
        if r.start < at || r.end > text.len() {
            continue;
        }
        out.push_str(&text[at..r.start]);
        out.push_str(v);
        at = r.end;
    }
    out.push_str(&text[at..]);
    out
}

/// The line of each element with an `id`.
pub(super) fn id_lines(xml: &Document) -> FxHashMap<String, u32> {
    let index = LineIndex::new(xml.input_text());
    xml.descendants()
        .filter(|n| n.is_element())
        .filter_map(|n| Some((n.attribute("id")?.to_string(), index.line(n.range().start))))
        .collect()
}

/// Why a `<use>` draws nothing, if it does not.
fn broken_use(node: &Node, ids: &FxHashMap<&str, Node>) -> Option<String> {
    let href = node
        .attributes()
        .find(|a| a.name() == "href" && a.namespace().is_none())
        .or_else(|| {
            node.attributes()
                .find(|a| a.name() == "href" && a.namespace() == Some(XLINK_NS))
        })
        .map(|a| a.value().trim().to_string());
    let Some(href) = href else {
        return Some("has no href: nothing to draw; skipped".into());
    };
    let Some(id) = href.strip_prefix('#') else {
        return Some(format!(
            "refers to '{href}' in another file, which is not read; skipped (put the element in this file)"
        ));
    };
    let Some(target) = ids.get(id) else {
        return Some(format!(
            "refers to #{id}, which is not in the file; skipped"
        ));
    };
    if target == node
        || target.ancestors().any(|a| a == *node)
        || node.ancestors().any(|a| a == *target)
    {
        return Some(format!("refers to #{id}, which holds it (a loop); skipped"));
    }
    if !is_svg(target) || !KNOWN.contains(&target.tag_name().name()) {
        return Some(format!(
            "refers to #{id}, a <{}> that is not drawn; skipped",
            target.tag_name().name()
        ));
    }
    None
}

/// The value of a presentation property: its `style` declaration, else its attribute.
fn property<'a>(node: &Node<'a, '_>, name: &str) -> Option<&'a str> {
    let from_style = node.attribute("style").and_then(|s| {
        s.split(';')
            .filter_map(|d| d.split_once(':'))
            .filter(|(k, _)| k.trim() == name)
            .map(|(_, v)| v.trim())
            .next_back()
    });
    from_style.or_else(|| node.attribute(name).map(str::trim))
}

/// Why an element with a `clip-path` or `mask` usvg cannot use draws nothing (usvg drops such
/// an element without a word; browsers differ), if it does not.
fn broken_link(node: &Node, ids: &FxHashMap<&str, Node>) -> Option<String> {
    for (property_name, tag) in [("clip-path", "clipPath"), ("mask", "mask")] {
        let Some(value) = property(node, property_name) else {
            continue;
        };
        if value == "none" || value.is_empty() {
            continue;
        }
        let id = value
            .strip_prefix("url(")
            .and_then(|v| v.strip_suffix(')'))
            .map(|v| v.trim().trim_matches(['"', '\'']))
            .and_then(|v| v.strip_prefix('#'));
        let Some(id) = id else {
            return Some(format!(
                "{property_name} '{value}' is not a reference to a <{tag}> in this file; the element was skipped"
            ));
        };
        match ids.get(id) {
            None => {
                return Some(format!(
                    "{property_name} refers to #{id}, which is not in the file; the element was skipped"
                ))
            }
            Some(t) if t.tag_name().name() != tag => {
                return Some(format!(
                    "{property_name} refers to #{id}, a <{}> and not a <{tag}>; the element was skipped",
                    t.tag_name().name()
                ))
            }
            Some(_) => {}
        }
    }
    None
}

/// A short quote of an element's text, for naming it.
fn text_quote(node: &Node) -> String {
    let text: String = node
        .descendants()
        .filter(|n| n.is_text())
        .filter_map(|n| n.text())
        .collect::<Vec<_>>()
        .join(" ");
    let words: Vec<&str> = text.split_whitespace().collect();
    let joined = words.join(" ");
    let mut quote: String = joined.chars().take(40).collect();
    if joined.chars().count() > 40 {
        quote.push('…');
    }
    quote
}

/// Scans the document: see the module docs.
pub(super) fn scan(xml: &Document, hidden: &HiddenLayers) -> Scan {
    let ids: FxHashMap<&str, Node> = xml
        .descendants()
        .filter(|n| n.is_element())
        .filter_map(|n| Some((n.attribute("id")?, n)))
        .collect();
    let root = xml.root_element();
    let mut out = Scan::default();
    let mut stack = vec![root];
    while let Some(node) = stack.pop() {
        let name = node.tag_name().name();
        let svg = is_svg(&node);
        let warn = |out: &mut Scan, message: String| {
            out.warnings.push(Warning {
                element: describe(&node),
                line: Some(line_of(xml, &node)),
                message,
                note: false,
            });
        };
        if name == "flowRoot" {
            let quote = text_quote(&node);
            warn(
                &mut out,
                format!(
                    "Inkscape flowed text{} is not supported; skipped (in Inkscape: Text ▸ Convert to Text)",
                    if quote.is_empty() { String::new() } else { format!(" \"{quote}\"") }
                ),
            );
            continue;
        }
        if !svg {
            // Inkscape's and other editors' own elements: not drawn, unless they hold drawing
            let n = drawables(&node);
            if n > 0 {
                warn(
                    &mut out,
                    format!("an element outside SVG holding {n} drawn elements; skipped"),
                );
            }
            continue;
        }
        if node != root && display_none(&node) {
            let top_layer = node.parent() == Some(root) && name == "g";
            let layer = if top_layer { layer_name(&node) } else { None };
            match layer {
                Some(layer) if hidden.includes(&layer) => unhide(&node, &mut out.edits),
                Some(layer) => {
                    let n = drawables(&node);
                    if n > 0 {
                        out.warnings.push(Warning {
                            element: format!("layer {layer} hidden"),
                            line: Some(line_of(xml, &node)),
                            message: format!(
                                "{n} {} skipped (hidden in the drawing)",
                                if n == 1 { "element" } else { "elements" }
                            ),
                            note: false,
                        });
                        out.skipped_layers.push(SkippedLayer {
                            name: layer,
                            why: LayerHidden::Hidden,
                            skipped: n,
                        });
                    }
                    continue;
                }
                None => {
                    let n = drawables(&node);
                    if n > 0 {
                        let what = if n == 1 && DRAWABLE.contains(&name) {
                            String::new()
                        } else {
                            format!(" ({n} drawn elements)")
                        };
                        warn(&mut out, format!("display:none{what}; skipped"));
                    }
                    continue;
                }
            }
        }
        if UNSUPPORTED.contains(&name) {
            warn(
                &mut out,
                format!("<{name}> is not supported and was skipped (convert it to paths)"),
            );
            continue;
        }
        if NOT_RENDERED.contains(&name) {
            continue;
        }
        if let Some(why) = broken_link(&node, &ids) {
            // usvg would draw it unclipped (or unmasked): hidden instead
            hide(xml.input_text(), &node, &mut out.edits);
            warn(&mut out, why);
            continue;
        }
        if name == "use" {
            if let Some(why) = broken_use(&node, &ids) {
                warn(&mut out, why);
            }
            continue;
        }
        if !KNOWN.contains(&name) {
            let n = drawables(&node);
            if n > 0 {
                warn(
                    &mut out,
                    format!("<{name}> is not an SVG element galvoplan reads; it and the {n} drawn elements in it were skipped"),
                );
            }
            continue;
        }
        // reverse so that the stack pops in document order
        let children: Vec<_> = node.children().filter(|c| c.is_element()).collect();
        stack.extend(children.into_iter().rev());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc(body: &str) -> String {
        format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
 xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" width="10mm" height="10mm">
{body}
</svg>"#
        )
    }

    #[test]
    fn line_index_agrees_with_roxmltree() {
        let text = doc("<rect id=\"a\"/>\n\n<g>\n<circle id=\"b\" r=\"1\"/></g>");
        let xml = Document::parse(&text).unwrap();
        let lines = id_lines(&xml);
        for n in xml.descendants().filter(|n| n.is_element()) {
            if let Some(id) = n.attribute("id") {
                assert_eq!(lines[id], line_of(&xml, &n), "{id}");
            }
        }
        assert_eq!((lines["a"], lines["b"]), (3, 6));
    }

    #[test]
    fn hidden_layers_are_summarised_and_can_be_included() {
        let text = doc(
            r#"<g id="l1" inkscape:label="Cut" style="display:none"><rect width="1" height="1"/><path d="M0 0 L1 1"/></g>
<g id="l2" display="none"><circle r="1"/></g>
<g id="l3"><rect width="1" height="1" style="fill:red; display : none"/></g>"#,
        );
        let xml = Document::parse(&text).unwrap();
        let s = scan(&xml, &HiddenLayers::Skip);
        let names: Vec<&str> = s.skipped_layers.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(names, ["Cut", "l2"]);
        assert_eq!(s.skipped_layers[0].skipped, 2);
        let w: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
        assert_eq!(w.len(), 3, "{w:?}");
        assert!(
            w[0].starts_with("layer Cut hidden (line 3): 2 elements skipped"),
            "{w:?}"
        );
        assert!(
            w[2].starts_with("<rect> (line 5): display:none; skipped"),
            "{w:?}"
        );
        assert!(s.edits.is_empty());
        // included by name: the edits show the layer, the other stays hidden
        let s = scan(&xml, &HiddenLayers::Include(vec!["cut".into()]));
        assert_eq!(s.skipped_layers.len(), 1);
        let shown = apply_edits(&text, &s.edits);
        assert!(shown.contains(r#"style="display:inline""#), "{shown}");
        assert_eq!(shown.lines().count(), text.lines().count());
        let again = Document::parse(&shown).unwrap();
        assert_eq!(scan(&again, &HiddenLayers::Skip).skipped_layers.len(), 1);
        let all = scan(&xml, &HiddenLayers::IncludeAll);
        let shown = apply_edits(&text, &all.edits);
        assert!(shown.contains(r#"display="inline""#), "{shown}");
        assert!(all.skipped_layers.is_empty());
    }

    #[test]
    fn elements_with_broken_clip_or_mask_references_are_hidden_and_named() {
        let text = doc(r##"<clipPath id="c"><rect width="1" height="1"/></clipPath>
<rect id="ok" width="1" height="1" clip-path="url(#c)"/>
<svg:rect xmlns:svg="http://www.w3.org/2000/svg" id="lost" width="1" height="1" clip-path="url(#nothere)"/>
<circle id="m" r="1" style="fill:red" mask="url('#c')"/>"##);
        let xml = Document::parse(&text).unwrap();
        let s = scan(&xml, &HiddenLayers::Skip);
        let w: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
        assert_eq!(
            w,
            [
                "<rect id=\"lost\"> (line 5): clip-path refers to #nothere, which is not in the file; the element was skipped",
                "<circle id=\"m\"> (line 6): mask refers to #c, a <clipPath> and not a <mask>; the element was skipped",
            ]
        );
        let edited = apply_edits(&text, &s.edits);
        assert!(
            edited.contains(r#"<svg:rect style="display:none" xmlns:svg"#),
            "{edited}"
        );
        assert!(
            edited.contains(r#"style="fill:red;display:none""#),
            "{edited}"
        );
        let again = Document::parse(&edited).unwrap();
        let hidden: Vec<&str> = again
            .descendants()
            .filter(|n| n.is_element() && display_none(n))
            .filter_map(|n| n.attribute("id"))
            .collect();
        assert_eq!(hidden, ["lost", "m"]);
    }

    #[test]
    fn broken_use_flowroot_and_unknown_elements_are_named() {
        let text = doc(
            r##"<defs><rect id="r" width="1" height="1"/><use id="indefs" href="#none"/></defs>
<use id="ok" href="#r"/>
<use id="missing" xlink:href="#nothere"/>
<use id="external" xlink:href="other.svg#r"/>
<g id="g"><use id="loop" href="#g"/></g>
<flowRoot id="fr"><flowRegion><rect width="5" height="5"/></flowRegion><flowPara>Hello   flowed world</flowPara></flowRoot>
<blink id="b"><rect width="1" height="1"/></blink>
<title>not drawn</title>"##,
        );
        let xml = Document::parse(&text).unwrap();
        let w: Vec<String> = scan(&xml, &HiddenLayers::Skip)
            .warnings
            .iter()
            .map(|w| w.to_string())
            .collect();
        assert_eq!(w.len(), 5, "{w:?}");
        assert!(
            w[0].starts_with(r#"<use id="missing"> (line 5): refers to #nothere"#),
            "{w:?}"
        );
        assert!(w[1].contains("'other.svg#r' in another file"), "{w:?}");
        assert!(
            w[2].contains(r#"<use id="loop">"#) && w[2].contains("loop"),
            "{w:?}"
        );
        assert!(
            w[3].starts_with(
                r#"<flowRoot id="fr"> (line 8): Inkscape flowed text "Hello flowed world""#
            ),
            "{w:?}"
        );
        assert!(w[4].starts_with(r#"<blink id="b"> (line 9)"#), "{w:?}");
    }
}
