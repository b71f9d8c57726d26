//! Warnings: what the import, hatching or splitting skipped or changed, naming the element.

use serde::{Deserialize, Serialize};

/// Something the import skipped or changed, naming the element.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Warning {
    /// The element, e.g. `<text id="t1">` or `path #12`.
    pub element: String,
    /// Source line, when known.
    pub line: Option<u32>,
    /// What happened.
    pub message: String,
    /// A substitution made as an operator expects it (a common CAD font drawn with its closest
    /// face): kept in the document and the report, not listed among the warnings.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub note: bool,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.line, self.element.is_empty()) {
            (Some(l), _) => write!(f, "{} (line {l}): {}", self.element, self.message),
            // a note about the whole job names no element
            (None, true) => write!(f, "{}", self.message),
            (None, false) => write!(f, "{}: {}", self.element, self.message),
        }
    }
}

/// Most items an error or warning lists before "… and N more".
pub const LIST_MAX: usize = 5;

/// Up to [`LIST_MAX`] items joined by `sep`, then "… and N more" for the rest.
pub fn short_list<T: std::fmt::Display>(items: &[T], sep: &str) -> String {
    let mut out: Vec<String> = items.iter().take(LIST_MAX).map(|i| i.to_string()).collect();
    if items.len() > LIST_MAX {
        out.push(format!("… and {} more", items.len() - LIST_MAX));
    }
    out.join(sep)
}

/// The warnings as an operator reads them: notes left out, and the same message for several
/// elements said once, with their count and at most [`LIST_MAX`] of them
/// (`font family 'isocpeur' not found; … (30 elements: TEXT 1A, TEXT 1B, … and 25 more)`),
/// in the order the messages first came.
pub fn grouped(warnings: &[Warning]) -> Vec<String> {
    let mut order: Vec<&str> = Vec::new();
    let mut by_message: std::collections::HashMap<&str, Vec<&Warning>> = Default::default();
    for w in warnings.iter().filter(|w| !w.note) {
        let list = by_message.entry(w.message.as_str()).or_default();
        if list.is_empty() {
            order.push(&w.message);
        }
        list.push(w);
    }
    order
        .into_iter()
        .map(
            |m| match by_message.get(m).map(Vec::as_slice).unwrap_or_default() {
                [one] => one.to_string(),
                many => {
                    let names: Vec<String> = many
                        .iter()
                        .map(|w| match w.line {
                            Some(l) => format!("{} (line {l})", w.element),
                            None => w.element.clone(),
                        })
                        .collect();
                    format!(
                        "{m} ({} elements: {})",
                        many.len(),
                        short_list(&names, ", ")
                    )
                }
            },
        )
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w(element: &str, message: &str, note: bool) -> Warning {
        Warning {
            element: element.into(),
            line: None,
            message: message.into(),
            note,
        }
    }

    #[test]
    fn one_line_per_message_with_a_count_and_five_examples() {
        let mut ws: Vec<Warning> = (1..=30)
            .map(|k| {
                w(
                    &format!("TEXT {k:X}"),
                    "font family 'isocpeur' not found",
                    false,
                )
            })
            .collect();
        ws.insert(3, w("path #2", "skipped", false));
        ws.push(w("TEXT 1F", "font 'arial' drawn with DejaVu Sans", true));
        let lines = grouped(&ws);
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert_eq!(
            lines[0],
            "font family 'isocpeur' not found (30 elements: TEXT 1, TEXT 2, TEXT 3, TEXT 4, \
             TEXT 5, … and 25 more)"
        );
        assert_eq!(lines[1], "path #2: skipped");
    }
}
