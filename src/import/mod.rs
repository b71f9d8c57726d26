//! Import of artwork into [`Geometry`](crate::document::Geometry) polylines in mm.

mod svg;

pub use svg::{import_svg, import_svg_file, ImportOptions, Imported};

use serde::{Deserialize, Serialize};
use thiserror::Error;

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
    /// The SVG holds nothing that can be marked.
    #[error("{file}: no markable geometry ({detail})")]
    NothingToMark {
        /// The file.
        file: String,
        /// What was found instead.
        detail: String,
    },
}
