//! Codes that scan: a part's DataMatrix, QR or Code 128 as marks.
//!
//! [`symbol`] encodes a content with a well-kept crate (`datamatrix`, `qrcode`, `barcoders`)
//! into a grid of modules with its quiet zone; [`marks`] turns the dark modules (or, inverted,
//! the light ones and the quiet zone) into fill strokes:
//!
//! * a module is `size / columns` wide (a Code 128 bar is as tall as [`BAR_HEIGHT_OF_WIDTH`] of
//!   the symbol's width);
//! * the dark modules of a row are merged into runs, and each run's rectangle is filled by one
//!   serpentine stroke along its long side at the pen's spacing `s`;
//! * the fill is inset by half the spot `d`: the lines run from `d/2` inside one edge to `d/2`
//!   inside the other, so that a spot of diameter `d` marks exactly the run's rectangle (its
//!   edges) and no more: a marked module has the module's size;
//! * a module smaller than `max(2·s, d)` cannot be filled that way and is refused with the
//!   smallest symbol width that works;
//! * `dots`: one spot (a mark of one point, fired for the pen's dot dwell) at the centre of each
//!   marked module instead, in the same order; a module smaller than the spot is refused (the
//!   dots would run together).

use crate::document::{CodeKind, CodeSpec, Ecc, Geometry, Run, RunOrder, Source, CODE_LAYER};
use crate::geom::Pt;
use thiserror::Error;

/// A Code 128's bar height as a share of the symbol's width (without quiet zones).
pub const BAR_HEIGHT_OF_WIDTH: f64 = 0.3;
/// Quiet zones in modules: DataMatrix (ISO/IEC 16022 asks 1; 2 reads better on marked parts),
/// QR (ISO/IEC 18004: 4), Code 128 (ISO/IEC 15417: 10).
const QUIET_DATAMATRIX: usize = 2;
const QUIET_QR: usize = 4;
const QUIET_CODE128: usize = 10;

/// A code as modules: `rows × cols`, row-major, `true` for dark.
#[derive(Debug, Clone, PartialEq)]
pub struct Symbol {
    /// Columns of modules (without the quiet zone).
    pub cols: usize,
    /// Rows of modules (1 for a 1-D code).
    pub rows: usize,
    /// Dark modules, row-major.
    pub dark: Vec<bool>,
    /// The quiet zone, in modules, on each side (left and right only for a 1-D code).
    pub quiet: usize,
    /// A 1-D code: its one row is a row of bars.
    pub bars: bool,
}

impl Symbol {
    /// Module `(row, col)` is dark.
    pub fn is_dark(&self, row: usize, col: usize) -> bool {
        self.dark
            .get(row * self.cols + col)
            .copied()
            .unwrap_or(false)
    }
}

/// Why a code cannot be made: its content does not encode, or its modules are too small to mark.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CodeError {
    /// The content is too long for the kind at any size.
    #[error("\"{content}\" does not fit a{shape} at any size")]
    DoesNotFit {
        /// The content.
        content: String,
        /// The symbol it does not fit, with its article's tail: ` square DataMatrix`,
        /// ` rectangular DataMatrix`.
        shape: String,
    },
    /// The content is too long for a QR code at any size with this error correction.
    #[error("\"{content}\" does not fit a QR code at any size with error correction {ecc:?}")]
    QrDoesNotFit {
        /// The content.
        content: String,
        /// The error correction asked for.
        ecc: Ecc,
    },
    /// A character Code 128 (set B) cannot encode: printable ASCII only.
    #[error(
        "Code 128 (set B) cannot encode '{character}' in \"{content}\" (printable ASCII only)"
    )]
    CannotEncode {
        /// The character, escaped when it is a control character.
        character: String,
        /// The content.
        content: String,
    },
    /// The Code 128 encoder refused the content.
    #[error("Code 128 cannot encode \"{content}\": {why}")]
    Encoder {
        /// The content.
        content: String,
        /// The encoder's reason.
        why: String,
    },
    /// Modules too small to fill at the pen's spacing with the spot.
    #[error(
        "modules of {module_mm:.3} mm are smaller than twice the fill spacing ({spacing_mm} mm) \
         or the spot ({spot_mm} mm): make it at least {least_width_mm:.2} mm wide"
    )]
    ModulesTooSmall {
        /// The module's width, mm.
        module_mm: f64,
        /// The fill's line spacing, mm.
        spacing_mm: f64,
        /// The spot's diameter, mm.
        spot_mm: f64,
        /// The smallest symbol width that can be filled, mm.
        least_width_mm: f64,
    },
    /// Dots (one spot per module) on modules smaller than the spot: they would run together.
    #[error(
        "modules of {module_mm:.3} mm are smaller than the spot ({spot_mm} mm), so the dots \
         would run together: make it at least {least_width_mm:.2} mm wide"
    )]
    DotsTooSmall {
        /// The module's width, mm.
        module_mm: f64,
        /// The spot's diameter, mm.
        spot_mm: f64,
        /// The smallest symbol width whose dots stay apart, mm.
        least_width_mm: f64,
    },
}

/// Encodes `content` as `spec` says; `Err` says why it cannot be (too long for the kind at
/// any size, a character the kind cannot encode).
pub fn symbol(spec: &CodeSpec, content: &str) -> Result<Symbol, CodeError> {
    match spec.kind {
        CodeKind::DataMatrix => {
            use datamatrix::{DataMatrix, SymbolList};
            let list = if spec.options.rect {
                SymbolList::with_extended_rectangles().enforce_rectangular()
            } else {
                SymbolList::default().enforce_square()
            };
            let made = if spec.options.gs1 {
                DataMatrix::encode_gs1(content.as_bytes(), list)
            } else {
                DataMatrix::encode_str(content, list)
            };
            let dm = made.map_err(|_| CodeError::DoesNotFit {
                content: content.into(),
                shape: if spec.options.rect {
                    " rectangular DataMatrix"
                } else {
                    " square DataMatrix"
                }
                .into(),
            })?;
            let bitmap = dm.bitmap();
            Ok(Symbol {
                cols: bitmap.width(),
                rows: bitmap.height(),
                dark: bitmap.bits().to_vec(),
                quiet: QUIET_DATAMATRIX,
                bars: false,
            })
        }
        CodeKind::Qr => {
            use qrcode::{Color, EcLevel, QrCode};
            let ecc = match spec.options.ecc {
                Ecc::L => EcLevel::L,
                Ecc::M => EcLevel::M,
                Ecc::Q => EcLevel::Q,
                Ecc::H => EcLevel::H,
            };
            let qr =
                QrCode::with_error_correction_level(content.as_bytes(), ecc).map_err(|_| {
                    CodeError::QrDoesNotFit {
                        content: content.into(),
                        ecc: spec.options.ecc,
                    }
                })?;
            let n = qr.width();
            Ok(Symbol {
                cols: n,
                rows: n,
                dark: qr.to_colors().iter().map(|c| *c == Color::Dark).collect(),
                quiet: QUIET_QR,
                bars: false,
            })
        }
        CodeKind::Code128 => {
            if let Some(c) = content.chars().find(|c| !(' '..='~').contains(c)) {
                let shown = if c.is_control() {
                    c.escape_default().to_string()
                } else {
                    c.to_string()
                };
                return Err(CodeError::CannotEncode {
                    character: shown,
                    content: content.into(),
                });
            }
            // set B: every printable ASCII character
            let code =
                barcoders::sym::code128::Code128::new(format!("Ɓ{content}")).map_err(|e| {
                    CodeError::Encoder {
                        content: content.into(),
                        why: e.to_string(),
                    }
                })?;
            let dark: Vec<bool> = code.encode().into_iter().map(|b| b == 1).collect();
            Ok(Symbol {
                cols: dark.len(),
                rows: 1,
                dark,
                quiet: QUIET_CODE128,
                bars: true,
            })
        }
    }
}

/// How a code is filled: the pen's line spacing and the laser's spot, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fill {
    /// Distance between fill lines, mm.
    pub spacing_mm: f64,
    /// Spot diameter, mm.
    pub spot_mm: f64,
}

/// The symbol's module size for `spec`, mm: (across, down).
pub fn module_mm(spec: &CodeSpec, sym: &Symbol) -> (f64, f64) {
    let m = spec.size_mm / sym.cols.max(1) as f64;
    if sym.bars {
        (m, spec.size_mm * BAR_HEIGHT_OF_WIDTH)
    } else {
        (m, m)
    }
}

/// The box the code takes with its quiet zone (top-left, bottom-right), mm, for a symbol whose
/// top-left is `at`.
pub fn quiet_box(spec: &CodeSpec, sym: &Symbol, at: Pt) -> (Pt, Pt) {
    let (mx, my) = module_mm(spec, sym);
    let q = sym.quiet as f64;
    let (qx, qy) = (q * mx, if sym.bars { 0.0 } else { q * my });
    (
        Pt::new(at.x - qx, at.y - qy),
        Pt::new(
            at.x + sym.cols as f64 * mx + qx,
            at.y + sym.rows as f64 * my + qy,
        ),
    )
}

/// The fill strokes of `sym` with its top-left at `at` (machine mm), as geometries of part
/// `part` on the codes' layer named `element`; `Err` when its modules are too small for the
/// fill, with the smallest width that works.
///
/// The strokes form one run (`run_id`, swept: every other one marked reversed) in the order of
/// the rows, so that ordering treats a code as one node: a 9 mm QR code is some 80 strokes,
/// and a tray of 96 codes would otherwise be 8,000 nodes to order for no gain.
pub fn marks(
    spec: &CodeSpec,
    sym: &Symbol,
    at: Pt,
    fill: Fill,
    part: u32,
    element: &str,
    run_id: u32,
) -> Result<Vec<Geometry>, CodeError> {
    let (mx, my) = module_mm(spec, sym);
    if spec.options.dots && mx < fill.spot_mm - 1e-9 {
        return Err(CodeError::DotsTooSmall {
            module_mm: mx,
            spot_mm: fill.spot_mm,
            least_width_mm: fill.spot_mm * sym.cols as f64,
        });
    }
    let least = (2.0 * fill.spacing_mm).max(fill.spot_mm);
    if !spec.options.dots && mx < least - 1e-9 {
        return Err(CodeError::ModulesTooSmall {
            module_mm: mx,
            spacing_mm: fill.spacing_mm,
            spot_mm: fill.spot_mm,
            least_width_mm: least * sym.cols as f64,
        });
    }
    // the grid that is marked: the symbol, or (inverted) the symbol in its quiet zone
    let q = if spec.options.inverted { sym.quiet } else { 0 };
    let (qr, cols, rows) = if sym.bars {
        (0, sym.cols + 2 * q, 1)
    } else {
        (q, sym.cols + 2 * q, sym.rows + 2 * q)
    };
    let marked = |r: usize, c: usize| -> bool {
        let inside = r >= qr && r < qr + sym.rows && c >= q && c < q + sym.cols;
        let dark = inside && sym.is_dark(r - qr, c - q);
        dark != spec.options.inverted
    };
    let origin = Pt::new(at.x - q as f64 * mx, at.y - qr as f64 * my);
    // the runs of each row, rows taken back and forth (boustrophedon)
    let mut rects: Vec<(f64, f64, f64, f64, bool)> = Vec::new();
    for r in 0..rows {
        let mut row = Vec::new();
        let mut c = 0;
        while c < cols {
            if !marked(r, c) {
                c += 1;
                continue;
            }
            let start = c;
            while c < cols && marked(r, c) {
                c += 1;
            }
            let (x0, x1) = (origin.x + start as f64 * mx, origin.x + c as f64 * mx);
            let (y0, y1) = (origin.y + r as f64 * my, origin.y + (r + 1) as f64 * my);
            row.push((x0, y0, x1, y1, r % 2 == 1));
        }
        if r % 2 == 1 {
            row.reverse();
        }
        rects.extend(row);
    }
    let pieces: Vec<Vec<Pt>> = if spec.options.dots {
        // one spot at the centre of each marked module, in the runs' order
        rects
            .into_iter()
            .flat_map(|(x0, y0, x1, y1, leftwards)| {
                let n = ((x1 - x0) / mx).round().max(1.0) as usize;
                let y = (y0 + y1) / 2.0;
                let centre = move |j: usize| {
                    let j = if leftwards { n - 1 - j } else { j };
                    vec![Pt::new(x0 + (j as f64 + 0.5) * mx, y)]
                };
                (0..n).map(centre)
            })
            .collect()
    } else {
        rects
            .into_iter()
            .enumerate()
            .map(|(k, (x0, y0, x1, y1, leftwards))| {
                let mut points = serpentine(x0, y0, x1, y1, fill);
                if leftwards {
                    points.reverse();
                }
                // a swept run marks every other member reversed: stored so that it comes out
                // as meant
                if k % 2 == 1 {
                    points.reverse();
                }
                points
            })
            .collect()
    };
    let mut out = Vec::with_capacity(pieces.len());
    for (k, points) in pieces.into_iter().enumerate() {
        let source = Source {
            element: element.to_string(),
            subpath: k,
            layer: CODE_LAYER.into(),
            part,
        };
        let run = Run {
            id: run_id,
            order: RunOrder::Sweep,
        };
        out.push(
            Geometry::new(points, false, source)
                .with_layer(CODE_LAYER)
                .with_run(Some(run)),
        );
    }
    Ok(out)
}

/// One stroke filling the rectangle `[x0, x1] × [y0, y1]` with lines along its long side,
/// `spacing` apart, inset by half the spot (a single centre line when only one fits).
fn serpentine(x0: f64, y0: f64, x1: f64, y1: f64, fill: Fill) -> Vec<Pt> {
    let h = fill.spot_mm / 2.0;
    let along_x = x1 - x0 >= y1 - y0;
    // (from, to) along the lines, (lo, hi) across them
    let (a0, a1, lo, hi) = if along_x {
        (x0 + h, x1 - h, y0 + h, y1 - h)
    } else {
        (y0 + h, y1 - h, x0 + h, x1 - h)
    };
    let (a0, a1) = if a1 > a0 {
        (a0, a1)
    } else {
        let m = (a0 + a1) / 2.0;
        (m - 1e-3, m + 1e-3)
    };
    let span = (hi - lo).max(0.0);
    let n = (span / fill.spacing_mm).ceil().max(1.0) as usize;
    let step = span / n as f64;
    let levels: Vec<f64> = if span <= 0.0 {
        vec![(lo + hi) / 2.0]
    } else {
        (0..=n).map(|k| lo + k as f64 * step).collect()
    };
    let mut pts = Vec::with_capacity(2 * levels.len());
    for (k, v) in levels.into_iter().enumerate() {
        let (p, q) = if k % 2 == 0 { (a0, a1) } else { (a1, a0) };
        let (p, q) = if along_x {
            (Pt::new(p, v), Pt::new(q, v))
        } else {
            (Pt::new(v, p), Pt::new(v, q))
        };
        pts.push(p);
        pts.push(q);
    }
    pts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::CodeOptions;

    fn spec(kind: CodeKind, size: f64) -> CodeSpec {
        CodeSpec {
            kind,
            content: "x".into(),
            at_mm: [0.0, 0.0],
            size_mm: size,
            options: CodeOptions::default(),
        }
    }

    #[test]
    fn symbols_of_each_kind() {
        let dm = symbol(&spec(CodeKind::DataMatrix, 6.0), "GP01001").unwrap();
        assert_eq!((dm.cols, dm.rows), (12, 12));
        let mut rect = spec(CodeKind::DataMatrix, 6.0);
        rect.options.rect = true;
        let r = symbol(&rect, "GP01001").unwrap();
        assert!(r.cols > r.rows, "{} × {}", r.cols, r.rows);
        let qr = symbol(&spec(CodeKind::Qr, 9.0), "L26-001/1001").unwrap();
        assert_eq!((qr.cols, qr.rows), (21, 21));
        let c = symbol(&spec(CodeKind::Code128, 30.0), "SN1001").unwrap();
        assert!(c.bars && c.rows == 1 && c.cols > 60);
        let e = symbol(&spec(CodeKind::Code128, 30.0), "Grüße").unwrap_err();
        assert_eq!(
            e.to_string(),
            "Code 128 (set B) cannot encode 'ü' in \"Grüße\" (printable ASCII only)"
        );
        let e = symbol(&spec(CodeKind::Qr, 9.0), &"x".repeat(5000)).unwrap_err();
        assert!(
            e.to_string()
                .contains("does not fit a QR code at any size with error correction"),
            "{e}"
        );
        let mut square = spec(CodeKind::DataMatrix, 9.0);
        let e = symbol(&square, &"x".repeat(5000)).unwrap_err().to_string();
        assert!(
            e.ends_with("\" does not fit a square DataMatrix at any size"),
            "{e}"
        );
        square.options.rect = true;
        let e = symbol(&square, &"x".repeat(5000)).unwrap_err().to_string();
        assert!(
            e.ends_with("\" does not fit a rectangular DataMatrix at any size"),
            "{e}"
        );
    }

    #[test]
    fn runs_are_filled_inset_by_half_the_spot() {
        let s = spec(CodeKind::DataMatrix, 3.5);
        let sym = symbol(&s, "GP01001").unwrap();
        let fill = Fill {
            spacing_mm: 0.05,
            spot_mm: 0.05,
        };
        let g = marks(&s, &sym, Pt::new(10.0, 20.0), fill, 1, "code", 1).unwrap();
        // one stroke per run, far fewer than dark modules
        let dark = sym.dark.iter().filter(|d| **d).count();
        assert!(
            g.len() < dark && !g.is_empty(),
            "{} strokes, {dark} modules",
            g.len()
        );
        // every point stays half a spot inside the symbol
        let m = 3.5 / sym.cols as f64;
        for p in g.iter().flat_map(|g| &g.points) {
            assert!(p.x >= 10.0 + 0.025 - 1e-9 && p.x <= 10.0 + 3.5 - 0.025 + 1e-9);
            assert!(p.y >= 20.0 + 0.025 - 1e-9 && p.y <= 20.0 + 3.5 - 0.025 + 1e-9);
        }
        assert!(m > 0.2);
        // too small for the fill: the smallest width that works
        let tiny = spec(CodeKind::DataMatrix, 1.0);
        let e = marks(&tiny, &sym, Pt::new(0.0, 0.0), fill, 1, "code", 1).unwrap_err();
        // 12 modules of at least 2 × 0.05 mm
        assert_eq!(sym.cols, 12);
        assert_eq!(
            e.to_string(),
            "modules of 0.083 mm are smaller than twice the fill spacing (0.05 mm) or the spot \
             (0.05 mm): make it at least 1.20 mm wide"
        );
    }

    #[test]
    fn inverted_marks_the_quiet_zone_and_leaves_the_modules() {
        let mut s = spec(CodeKind::Qr, 9.0);
        s.options.inverted = true;
        let sym = symbol(&s, "A").unwrap();
        let fill = Fill {
            spacing_mm: 0.05,
            spot_mm: 0.05,
        };
        let g = marks(&s, &sym, Pt::new(0.0, 0.0), fill, 1, "code", 1).unwrap();
        let (lo, hi) = quiet_box(&s, &sym, Pt::new(0.0, 0.0));
        let xs = g.iter().flat_map(|g| &g.points).map(|p| p.x);
        let min_x = xs.fold(f64::INFINITY, f64::min);
        assert!(
            (min_x - (lo.x + 0.025)).abs() < 1e-9,
            "{min_x} {lo:?} {hi:?}"
        );
    }
}
