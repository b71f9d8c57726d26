//! A 2-D or 1-D code of a part (DataMatrix ECC200, QR, Code 128): what it says (a template
//! with the fields of [`super::production`]), where it sits on the part and how big it is. The
//! symbol and its marks are made by `crate::codes`.

use super::production::{parse_template, ProductionError};
use serde::{Deserialize, Serialize};
use std::fmt;

/// The kinds of code galvoplan marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum CodeKind {
    /// DataMatrix ECC200 (square, or rectangular with the `rect` option; GS1 with `gs1`).
    DataMatrix,
    /// QR code (error correction level with `ecc=L|M|Q|H`, M by default).
    Qr,
    /// Code 128 (1-D).
    Code128,
}

impl fmt::Display for CodeKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CodeKind::DataMatrix => "datamatrix",
            CodeKind::Qr => "qr",
            CodeKind::Code128 => "code128",
        })
    }
}

/// QR error correction level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Ecc {
    /// About 7 % of the codewords can be restored.
    L,
    /// About 15 %.
    #[default]
    M,
    /// About 25 %.
    Q,
    /// About 30 %.
    H,
}

/// How a code is marked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct CodeOptions {
    /// Mark the background and the quiet zone, leave the modules (for dark material that the
    /// laser lightens).
    #[serde(default)]
    pub inverted: bool,
    /// A rectangular DataMatrix.
    #[serde(default)]
    pub rect: bool,
    /// QR error correction.
    #[serde(default)]
    pub ecc: Ecc,
    /// GS1 DataMatrix (FNC1 first, for UDI); `\x1D` or `{gs}`-free content: element strings
    /// are separated by the ASCII group separator.
    #[serde(default)]
    pub gs1: bool,
    /// One spot per module, fired for the pen's dot dwell, instead of filled squares (2-D
    /// codes only).
    #[serde(default)]
    pub dots: bool,
}

/// A code of the part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CodeSpec {
    /// Its kind.
    pub kind: CodeKind,
    /// What it says: a template (`GP{serial:05}`).
    pub content: String,
    /// The symbol's top-left corner relative to the part's top-left, mm.
    pub at_mm: [f64; 2],
    /// The symbol's width without its quiet zone, mm (a rectangular DataMatrix's height and a
    /// Code 128's bar height follow from it).
    pub size_mm: f64,
    /// How it is marked.
    #[serde(default)]
    pub options: CodeOptions,
}

/// The layer codes are marked on (its pen's hatch spacing fills the modules).
pub const CODE_LAYER: &str = "codes";

impl CodeSpec {
    /// Reads `KIND:CONTENT@X,Y:SIZE_MM[:OPTIONS]`; the last `@` ends the content; OPTIONS is a
    /// comma-separated list of `dots`, `inverted`, `rect`, `ecc=L|M|Q|H`, `gs1`.
    pub fn parse(text: &str) -> Result<Self, ProductionError> {
        let bad = |why: String| ProductionError::Code {
            text: text.to_string(),
            why,
        };
        let form =
            "expected KIND:CONTENT@X,Y:SIZE_MM[:OPTIONS], e.g. datamatrix:GP{serial:05}@3,3:6";
        let (kind, rest) = text.split_once(':').ok_or_else(|| bad(form.into()))?;
        let kind = match kind.trim().to_ascii_lowercase().as_str() {
            "datamatrix" | "dm" => CodeKind::DataMatrix,
            "qr" => CodeKind::Qr,
            "code128" => CodeKind::Code128,
            other => {
                return Err(bad(format!(
                    "unknown kind '{other}' (datamatrix, qr or code128)"
                )))
            }
        };
        let (content, place) = rest.rsplit_once('@').ok_or_else(|| bad(form.into()))?;
        if content.is_empty() {
            return Err(bad("the content is empty".into()));
        }
        parse_template(content).map_err(|why| bad(format!("content \"{content}\": {why}")))?;
        let mut parts = place.split(':');
        let xy = parts.next().unwrap_or("");
        let (x, y) = xy.split_once(',').ok_or_else(|| bad(form.into()))?;
        let num = |s: &str, what: &str| -> Result<f64, ProductionError> {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && v.abs() <= crate::geom::MAX_COORD_MM)
                .ok_or_else(|| bad(format!("{what} '{}' is not a number of mm", s.trim())))
        };
        let at_mm = [num(x, "X")?, num(y, "Y")?];
        let size_mm = num(parts.next().unwrap_or(""), "SIZE_MM")?;
        if size_mm <= 0.0 {
            return Err(bad(format!("the size must be positive, not {size_mm}")));
        }
        let mut options = CodeOptions::default();
        for opt in parts.flat_map(|o| o.split(',')).map(str::trim) {
            match opt.to_ascii_lowercase().as_str() {
                "" => {}
                "inverted" => options.inverted = true,
                "rect" if kind == CodeKind::DataMatrix => options.rect = true,
                "gs1" if kind == CodeKind::DataMatrix => options.gs1 = true,
                "ecc=l" if kind == CodeKind::Qr => options.ecc = Ecc::L,
                "ecc=m" if kind == CodeKind::Qr => options.ecc = Ecc::M,
                "ecc=q" if kind == CodeKind::Qr => options.ecc = Ecc::Q,
                "ecc=h" if kind == CodeKind::Qr => options.ecc = Ecc::H,
                "dots" if kind != CodeKind::Code128 => options.dots = true,
                other => {
                    return Err(bad(format!(
                        "unknown option '{other}' for {kind} (options: inverted{})",
                        match kind {
                            CodeKind::DataMatrix => ", dots, rect, gs1",
                            CodeKind::Qr => ", dots, ecc=L|M|Q|H",
                            CodeKind::Code128 => "",
                        }
                    )))
                }
            }
        }
        Ok(CodeSpec {
            kind,
            content: content.to_string(),
            at_mm,
            size_mm,
            options,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_read_with_the_last_at_ending_the_content() {
        let c = CodeSpec::parse("qr:{csv:lot}/{serial}@user@14,2:9:ecc=H,inverted").unwrap();
        assert_eq!(c.kind, CodeKind::Qr);
        assert_eq!(c.content, "{csv:lot}/{serial}@user");
        assert_eq!((c.at_mm, c.size_mm), ([14.0, 2.0], 9.0));
        assert_eq!(c.options.ecc, Ecc::H);
        assert!(c.options.inverted);
        let d = CodeSpec::parse("datamatrix:GP{serial:05}@3,3:6:rect,gs1").unwrap();
        assert!(d.options.rect && d.options.gs1 && !d.options.dots);
        assert!(CodeSpec::parse("qr:x@1,1:5:dots").unwrap().options.dots);
        for (bad, says) in [
            ("aztec:x@1,1:5", "unknown kind 'aztec'"),
            ("qr:x@1,1:5:rect", "unknown option 'rect' for qr"),
            ("qr:x@1:5", "expected KIND"),
            ("qr:x@1,1:-5", "positive"),
            ("qr:{serial@1,1:5", "unbalanced"),
            ("qr:@1,1:5", "empty"),
            ("code128:x@1,1:5:dots", "unknown option 'dots' for code128"),
        ] {
            let e = CodeSpec::parse(bad).unwrap_err().to_string();
            assert!(e.contains(says) && !e.contains('\n'), "{bad}: {e}");
        }
    }
}
