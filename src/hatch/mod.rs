//! Hatch fills (seed 003): closed regions filled with laser hatch lines after an inward edge
//! offset.
//!
//! A region is a set of contours resolved by a fill rule (even-odd or non-zero, like SVG's
//! `fill-rule`; i_overlay does the resolution). Its boundary is offset inward by the edge offset
//! `d` (cavalier_contours: exact lines and arcs), giving the *offset region* `O`. Then:
//! - `lines`: chords of parallel lines `s` apart, one stroke each, all in the same direction;
//! - `zigzag`: the same chords, consecutive ones joined along the boundary of `O` wherever the
//!   boundary between them stays between the two lines, so each sweepable part is one polyline;
//! - `cross`: zigzag at the angle and at the angle + 90°;
//! - `contour`: the boundaries of `O`, `O ⊖ s`, `O ⊖ 2s`, … (rings), plus gap strokes where the
//!   rings alone would leave points farther than `s/2` from every mark.
//!
//! Line styles also mark the boundary of `O` (the *border*, on by default), each piece once: the
//! pieces zigzag joins already follow are not repeated. With the border every point of `O` is
//! within `s/2` of a mark: a point farther than `s/2` from the boundary has the nearest line
//! within `s/2` inside `O`. Parallel lines are exactly `s` apart, rings exactly `s` apart.
//!
//! [`hatch_contours`] fills one region; [`hatch_geometries`] fills the closed geometries of a
//! layer (together, or one region per drawing element); strokes larger than a scan field are cut
//! afterwards on the document's tiling (`fields::cut_hatch_at_tiling`). `bench::hatch`
//! reproduces seed 003's experiment.

mod boundary;
mod clip;
mod contour;
mod document;
mod elems;
mod gaps;
mod region;
mod scan;
mod spots;
mod zigzag;

pub use crate::document::{
    FillRule, HatchSettings, HatchSpecError, HatchStyle, OutlineMode, MIN_SPACING_MM,
};
use crate::document::{Run, RunOrder};
pub use document::{
    hatch_geometries, is_hatch_output, layer_geometries, HatchedGeometries, HATCH_LAYER_PREFIX,
};

use crate::geom::{polyline_length, BBox, Pt};
use crate::job::{Cancelled, JobCtx};
use boundary::Boundary;
use region::{Frame, Region};
use serde::Serialize;
use thiserror::Error;

/// Arcs are flattened within this fraction of the spacing.
const FLATTEN_TOL_SPACING: f64 = 1e-3;
/// Strokes shorter than this many spacings are dropped: nothing is left unmarked by more than
/// half of that, far inside the coverage tolerance, and the machine is spared a jump and a
/// laser switch for a mark below any spot size (and below the G-code's resolution).
const MIN_STROKE_SPACING: f64 = 2e-3;
/// At most this many lines per family (or rings) per region.
pub const MAX_LINES: usize = 1_000_000;
/// At most about this many hatch lines in one job, all layers together (an upper estimate made
/// before hatching: each region's diagonal over the spacing, twice for two families): ten times
/// the largest job benchmarked (a million strokes, 1 GB), so no file can take the machine's
/// memory through its hatch.
pub const MAX_JOB_LINES: f64 = 1e7;

/// Why a hatch could not be made.
#[derive(Debug, Error)]
pub enum HatchError {
    /// The settings are out of range.
    #[error("hatch settings: {0}")]
    Settings(#[from] crate::document::validate::InvalidValue),
    /// The layers' hatches together would make more lines than one job may have.
    #[error(
        "layer '{layer}': hatching its shapes at {spacing_mm} mm would make about {lines:.0} lines \
         with the layers before it, beyond the {MAX_JOB_LINES:e} of one job; raise the hatch spacing"
    )]
    TooManyLines {
        /// The layer that passes the budget.
        layer: String,
        /// Its spacing, mm.
        spacing_mm: f64,
        /// Estimated lines so far.
        lines: f64,
    },
    /// The spacing is too fine for the region's size.
    #[error(
        "{element}: hatch spacing {spacing_mm} mm would need {lines} lines (at most {MAX_LINES})"
    )]
    TooFine {
        /// The region's element.
        element: String,
        /// Spacing, mm.
        spacing_mm: f64,
        /// Lines needed.
        lines: usize,
    },
    /// Hatching left nothing to mark (every region vanished inside the edge offset and the
    /// outlines are dropped).
    #[error("nothing left to mark: every hatched region vanished inside the {edge_offset_mm} mm edge offset and the outlines are dropped")]
    NothingLeft {
        /// Edge offset, mm.
        edge_offset_mm: f64,
    },
    /// The operator cancelled.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// What a hatch stroke is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StrokeKind {
    /// One chord of a `lines` hatch.
    Line,
    /// A zigzag polyline: chords of consecutive lines and the boundary joins between them.
    Zigzag,
    /// A piece of the offset region's boundary.
    Border,
    /// A contour-parallel ring (closed).
    Ring,
    /// A gap stroke of a contour-parallel fill.
    Gap,
}

/// Runs of one stroke made loose (a run is a group of strokes).
fn lone_runs_loose(strokes: &mut [HatchStroke]) {
    for group in strokes.chunk_by_mut(|a, b| a.run.map(|r| r.id) == b.run.map(|r| r.id)) {
        if let [lone] = group {
            lone.run = None;
        }
    }
}

/// One stroke of a hatch.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HatchStroke {
    /// What it is.
    pub kind: StrokeKind,
    /// Line family: 0, or 1 for the second direction of `cross`.
    pub family: u8,
    /// Ring level `k` (ring at `k` spacings inside the offset boundary; gaps lie between level
    /// `k` and `k + 1`); 0 for line styles.
    pub level: u32,
    /// Points in mm, in marking order.
    pub points: Vec<Pt>,
    /// Closed (marked back to the first point).
    pub closed: bool,
    /// The run it belongs to, where the fill fixes the order of its strokes: the border pieces
    /// of one boundary loop (round the loop), the zigzag parts of one sweep (line by line).
    pub run: Option<Run>,
}

impl HatchStroke {
    /// Marked length, mm.
    pub fn length_mm(&self) -> f64 {
        polyline_length(&self.points, self.closed)
    }
}

/// Counts and lengths of a region's hatch.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct HatchStats {
    /// Chords (hatch line segments) of the line styles.
    pub lines: usize,
    /// Zigzag polylines.
    pub parts: usize,
    /// Rings of `contour`.
    pub rings: usize,
    /// Ring levels of `contour`.
    pub levels: usize,
    /// Gap strokes of `contour`.
    pub gaps: usize,
    /// Border strokes.
    pub borders: usize,
    /// Length of lines / zigzag polylines (chords and joins) / rings, mm.
    pub fill_mm: f64,
    /// Length of the border strokes, mm.
    pub border_mm: f64,
    /// Length of the gap strokes, mm.
    pub gap_mm: f64,
    /// Everything marked, mm.
    pub total_mm: f64,
}

/// The hatch of one region.
#[derive(Debug, Clone, Default)]
pub struct RegionHatch {
    /// Strokes in a sensible marking order (line by line, ring by ring).
    pub strokes: Vec<HatchStroke>,
    /// The offset region's boundary loops as flattened (inside the exact offset region).
    pub offset_loops: Vec<Vec<Pt>>,
    /// Counts and lengths.
    pub stats: HatchStats,
}

/// Fills one region: `contours` (closed, mm, any orientation) resolved with the settings' fill
/// rule, offset inward by the edge offset, then hatched in the settings' style.
pub fn hatch_contours(
    contours: &[Vec<Pt>],
    settings: &HatchSettings,
    ctx: &JobCtx,
) -> Result<RegionHatch, HatchError> {
    settings.check()?;
    let s = settings.spacing_mm;
    let loops = region::resolve(contours, settings.fill_rule);
    let mut out = RegionHatch::default();
    if loops.is_empty() {
        return Ok(out);
    }
    let b = BBox::of(&loops.iter().flatten().copied().collect::<Vec<_>>());
    let lines_needed = (b.width().hypot(b.height()) / s).ceil();
    if lines_needed > MAX_LINES as f64 {
        return Err(HatchError::TooFine {
            element: "region".into(),
            spacing_mm: s,
            lines: lines_needed as usize,
        });
    }
    let region = Region::new(&loops, Frame::new(&loops, s));
    let tol = s * FLATTEN_TOL_SPACING;
    if settings.style == HatchStyle::Contour {
        contour_fill(&region, settings, tol, ctx, &mut out)?;
    } else if !scan_fill(&region, settings, tol, ctx, &mut out)? {
        return Ok(out);
    }
    // (a few µm or less: where a line ends next to a corner, a border piece of 0.01 µm is left)
    out.strokes.retain(|st| {
        let len_mm = st.length_mm();
        st.points.len() >= 2 && len_mm > 0.0 && len_mm >= s * MIN_STROKE_SPACING
    });
    count_strokes(&out.strokes, &mut out.stats);
    Ok(out)
}

/// A hatch stroke outside any run.
fn loose(kind: StrokeKind, family: u8, level: u32, points: Vec<Pt>, closed: bool) -> HatchStroke {
    HatchStroke {
        kind,
        family,
        level,
        points,
        closed,
        run: None,
    }
}

/// The runs of one region, numbered from 1.
#[derive(Default)]
struct Runs(u32);

impl Runs {
    fn next(&mut self, order: RunOrder) -> Run {
        self.0 += 1;
        Run { id: self.0, order }
    }
}

/// The contour-parallel fill: rings inward from the edge offset, each level's gaps filled.
fn contour_fill(
    region: &Region,
    settings: &HatchSettings,
    tol: f64,
    ctx: &JobCtx,
    out: &mut RegionHatch,
) -> Result<(), HatchError> {
    ctx.check()?;
    let s = settings.spacing_mm;
    let levels = contour::contour_levels(region, settings.edge_offset(), s, tol, MAX_LINES, ctx)?;
    out.offset_loops = levels.first().map(|l| l.rings.clone()).unwrap_or_default();
    out.stats.levels = levels.len();
    for (k, level) in levels.into_iter().enumerate() {
        for r in level.rings {
            out.strokes
                .push(loose(StrokeKind::Ring, 0, k as u32, r, true));
        }
        for (g, closed) in level.gaps {
            out.strokes
                .push(loose(StrokeKind::Gap, 0, k as u32, g, closed));
        }
    }
    Ok(())
}

/// The scan-line fills (lines, zigzag, cross) of the region offset by the edge offset, with
/// their border; `false` when the offset leaves nothing to fill.
fn scan_fill(
    region: &Region,
    settings: &HatchSettings,
    tol: f64,
    ctx: &JobCtx,
    out: &mut RegionHatch,
) -> Result<bool, HatchError> {
    let s = settings.spacing_mm;
    let o = region.offset(settings.edge_offset());
    if o.is_empty() {
        return Ok(false);
    }
    ctx.check()?;
    let flat = o.flatten(tol);
    let a = settings.angle_deg.to_radians();
    let angles = if settings.style == HatchStyle::Cross {
        vec![a, a + std::f64::consts::FRAC_PI_2]
    } else {
        vec![a]
    };
    let scans = angles
        .iter()
        .map(|&a| scan::scan(&flat, a, s, MAX_LINES))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| HatchError::TooFine {
            element: "region".into(),
            spacing_mm: s,
            lines: e.0,
        })?;
    ctx.check()?;
    let mut runs = Runs::default();
    if settings.style == HatchStyle::Lines {
        line_strokes(&scans[0], a, &mut runs, &mut out.strokes);
        if settings.border {
            for l in &flat {
                out.strokes
                    .push(loose(StrokeKind::Border, 0, 0, l.clone(), true));
            }
        }
    } else {
        zigzag_strokes(&scans, &flat, settings.border, &mut runs, &mut out.strokes);
    }
    out.stats.lines = scans
        .iter()
        .flat_map(|sc| sc.lines.iter().flatten().map(move |c| sc.ends(*c)))
        .map(|(p, q)| p.dist(q))
        .filter(|&len_mm| len_mm > 0.0 && len_mm >= s * MIN_STROKE_SPACING)
        .count();
    out.offset_loops = flat;
    Ok(true)
}

/// Parallel lines at angle `a` (rad): consecutive lines of one chord each, overlapping along the
/// lines, are one sweep: one run, marked in line order, each chord entered at the end next to
/// the last (the planner flips open strokes anyway); lines of several chords stay loose.
fn line_strokes(sc: &scan::Scan, a: f64, runs: &mut Runs, strokes: &mut Vec<HatchStroke>) {
    let along = Pt::new(a.cos(), a.sin());
    let first = strokes.len();
    let mut run: Option<Run> = None;
    let mut last: Option<(f64, f64)> = None;
    for line in &sc.lines {
        let span = match line.as_slice() {
            [c] => {
                let (p, q) = sc.ends(*c);
                let (u, v) = (p.dot(along), q.dot(along));
                Some((u.min(v), u.max(v)))
            }
            _ => None,
        };
        let continues =
            matches!((last, span), (Some((a0, a1)), Some((b0, b1))) if b0 <= a1 && a0 <= b1);
        if !continues {
            run = span.map(|_| runs.next(RunOrder::Sweep));
        }
        for c in line {
            let (p, q) = sc.ends(*c);
            strokes.push(HatchStroke {
                run: span.and(run),
                ..loose(StrokeKind::Line, 0, 0, vec![p, q], false)
            });
        }
        last = span;
    }
    lone_runs_loose(&mut strokes[first..]);
}

/// Zigzag (and cross) fills: each family's chords linked along the boundary `flat`, a sweep of
/// two parts or more one run; with `border`, the boundary the links left unused, one run per
/// loop.
fn zigzag_strokes(
    scans: &[scan::Scan],
    flat: &[Vec<Pt>],
    border: bool,
    runs: &mut Runs,
    strokes: &mut Vec<HatchStroke>,
) {
    let refs: Vec<&scan::Scan> = scans.iter().collect();
    let mut boundary = Boundary::new(flat, &refs);
    for (f, sc) in scans.iter().enumerate() {
        let mut parts = zigzag::link(sc, f, &mut boundary);
        // each sweep's parts together, line by line
        parts.sort_by_key(|p| p.sweep);
        for sweep in parts.chunk_by_mut(|a, b| a.sweep == b.sweep) {
            let run = (sweep.len() > 1).then(|| runs.next(RunOrder::Sweep));
            for part in sweep {
                let points = std::mem::take(&mut part.points);
                strokes.push(HatchStroke {
                    run,
                    ..loose(StrokeKind::Zigzag, f as u8, 0, points, false)
                });
            }
        }
    }
    if border {
        let mut loop_run = (u32::MAX, None);
        for (loop_id, pts, closed) in boundary.unused_by_loop() {
            if loop_run.0 != loop_id {
                loop_run = (loop_id, Some(runs.next(RunOrder::Loop)));
            }
            strokes.push(HatchStroke {
                run: if closed { None } else { loop_run.1 },
                ..loose(StrokeKind::Border, 0, 0, pts, closed)
            });
        }
    }
}

/// Counts and lengths of `strokes` by kind into `st`.
fn count_strokes(strokes: &[HatchStroke], st: &mut HatchStats) {
    for k in strokes {
        let len = k.length_mm();
        match k.kind {
            StrokeKind::Line => st.fill_mm += len,
            StrokeKind::Zigzag => {
                st.parts += 1;
                st.fill_mm += len;
            }
            StrokeKind::Ring => {
                st.rings += 1;
                st.fill_mm += len;
            }
            StrokeKind::Border => {
                st.borders += 1;
                st.border_mm += len;
            }
            StrokeKind::Gap => {
                st.gaps += 1;
                st.gap_mm += len;
            }
        }
    }
    st.total_mm = st.fill_mm + st.border_mm + st.gap_mm;
}
