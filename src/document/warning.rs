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
