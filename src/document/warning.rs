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
        match self.line {
            Some(l) => write!(f, "{} (line {l}): {}", self.element, self.message),
            None => write!(f, "{}: {}", self.element, self.message),
        }
    }
}
