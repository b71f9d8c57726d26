//! Cutting geometries larger than a field at the seams of one chosen tiling.
//!
//! One tiling ([`crate::geom::tiling`]) is chosen for the whole document over everything that
//! must be cut: fills whose strokes do not fit a field, and geometries larger than a field. The
//! hatch stage's strokes are cut on it when the geometries are made ([`cut_hatch_at_tiling`]);
//! outlines and other oversize geometries are cut on the same tiling when the settings split
//! them ([`split_oversize`]), so every cut lies on one of a few shared straight seams (or within
//! its band, per the pen's [`SeamForm`]) and a field centred on each cell holds all its pieces.
//! Small geometries are not cut; the tiling avoids crossing them.

use super::INSIDE_EPS_MM;
use crate::document::runs::continues_run;
use crate::document::{is_hatch_output, pen_of, Layer, Warning};
use crate::document::{Geometry, Source};
use crate::geom::seam::{cut_at_seams, SeamForm, SeamStats};
use crate::geom::tiling::{choose_tiling, Tiling, TilingInput};
use crate::geom::BBox;

/// Cells are smaller than the field by this much on each side, mm, so pieces fit with slack.
pub const FIT_MARGIN_MM: f64 = 1e-3;

/// The words of a cut's warning ("geometry 3 (… mm) is larger than the scan field: split into
/// 4 pieces at field borders"), by which the cut's warnings are found again.
pub const SPLIT_WORDS: &str = "is larger than the scan field: split into";

/// True when the geometry does not fit a field of `field_mm`.
pub fn is_oversize(g: &Geometry, field_mm: [f64; 2]) -> bool {
    let b = g.bbox();
    b.width() > field_mm[0] + INSIDE_EPS_MM || b.height() > field_mm[1] + INSIDE_EPS_MM
}

/// True when a box fits in a field with [`FIT_MARGIN_MM`] to spare.
fn fits_box(b: &BBox, field_mm: [f64; 2]) -> bool {
    b.width() <= field_mm[0] - FIT_MARGIN_MM && b.height() <= field_mm[1] - FIT_MARGIN_MM
}

/// The seam form of a geometry's layer.
fn seam_of(layers: &[Layer], g: &Geometry) -> SeamForm {
    pen_of(layers, g).map_or(SeamForm::Straight, |p| p.seam)
}

/// The largest cell a tiling may have so that a field centred on it holds every piece (pieces
/// pass a seam by up to the layers' seam reach).
pub fn cell_max_mm(layers: &[Layer], field_mm: [f64; 2]) -> [f64; 2] {
    let reach = layers
        .iter()
        .map(|l| l.pen.seam.reach_mm())
        .fold(0.0, f64::max);
    let cell = |f: f64| (f - 2.0 * FIT_MARGIN_MM - 2.0 * reach).max(f * 0.25);
    [cell(field_mm[0]), cell(field_mm[1])]
}

/// The tiling for `geometries`, or none when nothing needs cutting: its extent is the box of the
/// oversize geometries and of the hatch strokes that do not fit a field; its seams are chosen
/// for the fewest cuts of those, avoiding the small geometries in the extent.
pub fn choose_document_tiling(
    geometries: &[Geometry],
    layers: &[Layer],
    field_mm: [f64; 2],
) -> Option<Tiling> {
    let extent = geometries
        .iter()
        .filter(|g| !fits_box(&g.bbox(), field_mm))
        .fold(BBox::EMPTY, |b, g| b.union(g.bbox()));
    if extent.is_empty() {
        return None;
    }
    let inputs: Vec<TilingInput> = geometries
        .iter()
        .filter(|g| overlaps(&g.bbox(), &extent))
        .map(|g| TilingInput {
            points: &g.points,
            closed: g.closed,
            cut: is_hatch_output(g) || !fits_box(&g.bbox(), field_mm),
        })
        .collect();
    Some(choose_tiling(
        &inputs,
        extent,
        cell_max_mm(layers, field_mm),
    ))
}

fn overlaps(a: &BBox, b: &BBox) -> bool {
    a.min_x <= b.max_x && b.min_x <= a.max_x && a.min_y <= b.max_y && b.min_y <= a.max_y
}

/// A geometry's pieces: points and whether closed.
type Pieces = Vec<(Vec<crate::geom::Pt>, bool)>;

/// Geometries cut at a tiling's seams.
#[derive(Debug, Clone, Default)]
pub struct Cut {
    /// The geometries, each cut one replaced by its pieces where it was.
    pub geometries: Vec<Geometry>,
    /// What the cut did.
    pub stats: SeamStats,
    /// Which input geometries were cut, with their piece counts.
    pub split: Vec<(usize, usize)>,
}

/// Cuts the geometries `which` selects where they cross the seams of `tiling` inside its extent,
/// each with its layer's seam form. Pieces keep their geometry's layer; a non-hatch piece's
/// element is named "… (piece k)".
///
/// A layer whose pen shifts its passes (`shift_passes`, passes n > 1) gets each cut geometry
/// once per pass: pass 1 cut on `tiling`, pass k on `tiling` shifted by (k − 1)/n of its mean
/// cell in both axes ([`Tiling::shifted`]), each piece marked once ([`Geometry::pass`]); so no
/// two passes cut at the same place.
pub fn cut_at_tiling(
    geometries: Vec<Geometry>,
    tiling: &Tiling,
    layers: &[Layer],
    field_mm: [f64; 2],
    which: impl Fn(&Geometry) -> bool,
) -> Cut {
    let extent = tiling.extent();
    let selected: Vec<bool> = geometries
        .iter()
        .map(|g| g.pass == 0 && which(g) && overlaps(&g.bbox(), &extent))
        .collect();
    let shifted_passes = |g: &Geometry| {
        pen_of(layers, g)
            .filter(|p| p.shift_passes && p.passes > 1)
            .map_or(1, |p| p.passes)
    };
    let most = geometries
        .iter()
        .zip(&selected)
        .filter(|(_, s)| **s)
        .map(|(g, _)| shifted_passes(g))
        .max()
        .unwrap_or(1);
    let cells = tiling.cells();
    let pitch = [
        extent.width() / cells[0] as f64,
        extent.height() / cells[1] as f64,
    ];
    let cell_max = cell_max_mm(layers, field_mm);
    // pieces per geometry per pass (pass 0: the one tiling of geometries without shifted passes)
    let mut pieces_of: Vec<Vec<Pieces>> = vec![Vec::new(); geometries.len()];
    let mut stats = SeamStats::default();
    for pass in 0..most {
        let pass_tiling;
        let on = if pass == 0 {
            tiling
        } else {
            let k = pass as f64;
            let n = most as f64;
            pass_tiling = tiling.shifted([pitch[0] * k / n, pitch[1] * k / n], cell_max);
            &pass_tiling
        };
        let take = |i: usize| selected[i] && (pass == 0 || shifted_passes(&geometries[i]) > pass);
        let cut = cut_forms(&geometries, on, layers, field_mm, &take);
        stats.merge(cut.1);
        for (i, pieces) in cut.0 {
            let slot = &mut pieces_of[i];
            slot.resize(pass as usize + 1, Vec::new());
            slot[pass as usize] = pieces;
        }
    }
    let mut out = Cut {
        stats,
        ..Cut::default()
    };
    out.geometries.reserve(geometries.len());
    for (i, (g, passes)) in geometries.into_iter().zip(pieces_of).enumerate() {
        let shifted = passes.len() > 1;
        let whole = passes.len() == 1
            && passes[0].len() == 1
            && passes[0][0].0 == g.points
            && passes[0][0].1 == g.closed;
        if passes.is_empty() || whole {
            out.geometries.push(g);
            continue;
        }
        out.split.push((i, passes.iter().map(Vec::len).sum()));
        let hatch = is_hatch_output(&g);
        let mut k = 0;
        for (pass, pieces) in passes.into_iter().enumerate() {
            for (points, closed) in pieces {
                k += 1;
                let source = if hatch {
                    g.source.clone()
                } else {
                    Source {
                        element: format!("{} (piece {k})", g.source.element),
                        subpath: g.source.subpath,
                        layer: g.source.layer.clone(),
                        part: g.source.part,
                    }
                };
                let piece = Geometry::new(points, closed, source).with_layer(&g.layer);
                out.geometries.push(if shifted {
                    piece.with_pass(pass as u32 + 1)
                } else {
                    piece
                });
            }
        }
    }
    split_runs_at_cells(&mut out.geometries, tiling);
    out
}

/// Runs (`document::Run`) are cut where consecutive members lie in different cells of
/// `tiling` (a seam through the gap between two members cuts no stroke): each stretch gets an
/// id of its own, so that no run chunk the field stage places as one node straddles a seam
/// (it would need a field of its own across two cells). Pieces of cut strokes are loose
/// already.
fn split_runs_at_cells(geometries: &mut [Geometry], tiling: &Tiling) {
    let cell = |g: &Geometry| {
        let c = g.bbox().center();
        let at = |borders: &[f64], v: f64| borders.partition_point(|&b| b <= v);
        (at(&tiling.xs, c.x), at(&tiling.ys, c.y))
    };
    // fresh ids above any a fill gives (a fill numbers its runs from 1 per region); the new
    // ids are found on the fill's own first, then set
    let mut next_id = u32::MAX / 2;
    let mut ids: Vec<Option<u32>> = vec![None; geometries.len()];
    let mut last_cell = (usize::MAX, usize::MAX);
    for k in 0..geometries.len() {
        let Some(run) = geometries[k].run else {
            continue;
        };
        let here = cell(&geometries[k]);
        let id = match ids.get(k.wrapping_sub(1)).copied().flatten() {
            Some(id) if continues_run(&geometries[k - 1], &geometries[k]) && here == last_cell => {
                id
            }
            Some(_) if continues_run(&geometries[k - 1], &geometries[k]) => {
                next_id = next_id.wrapping_add(1);
                next_id
            }
            _ => run.id,
        };
        ids[k] = Some(id);
        last_cell = here;
    }
    for (g, id) in geometries.iter_mut().zip(ids) {
        if let (Some(run), Some(id)) = (&mut g.run, id) {
            run.id = id;
        }
    }
}

/// Cuts the geometries `take` selects on `tiling`, one cut per seam form (crossings are ranked
/// along each seam within a form); returns each cut geometry's pieces and the figures.
fn cut_forms(
    geometries: &[Geometry],
    tiling: &Tiling,
    layers: &[Layer],
    field_mm: [f64; 2],
    take: &impl Fn(usize) -> bool,
) -> (Vec<(usize, Pieces)>, SeamStats) {
    let mut forms: Vec<SeamForm> = Vec::new();
    for (i, g) in geometries.iter().enumerate() {
        let f = seam_of(layers, g);
        if take(i) && !forms.contains(&f) {
            forms.push(f);
        }
    }
    let mut out: Vec<(usize, Pieces)> = Vec::new();
    let mut stats = SeamStats::default();
    for form in forms {
        let members: Vec<usize> = (0..geometries.len())
            .filter(|&i| take(i) && seam_of(layers, &geometries[i]) == form)
            .collect();
        let strokes: Vec<(&[crate::geom::Pt], bool)> = members
            .iter()
            .map(|&i| (geometries[i].points.as_slice(), geometries[i].closed))
            .collect();
        let cut = cut_at_seams(&strokes, tiling, form, |p| fits_box(&BBox::of(p), field_mm));
        stats.merge(cut.stats);
        let mut pieces: Vec<Pieces> = vec![Vec::new(); members.len()];
        for (k, points, closed) in cut.pieces {
            pieces[k].push((points, closed));
        }
        out.extend(members.into_iter().zip(pieces));
    }
    (out, stats)
}

/// The hatch stage's cut: hatch strokes crossing a seam of the document's tiling are cut on it,
/// so a fill larger than a field is cut along a few straight seams. The tiling is `set` (the
/// operator's, after moving seams) when that still covers what needs cutting with cells that
/// fit, else chosen ([`choose_document_tiling`]). Returns the tiling (none: nothing to cut) and
/// the cut.
pub fn cut_hatch_at_tiling(
    geometries: Vec<Geometry>,
    layers: &[Layer],
    field_mm: [f64; 2],
    set: Option<&Tiling>,
) -> (Option<Tiling>, Cut) {
    let chosen = choose_document_tiling(&geometries, layers, field_mm);
    let tiling = match (set, chosen) {
        (Some(s), Some(c)) if fits_tiling(s, &c.extent(), cell_max_mm(layers, field_mm)) => {
            Some(s.clone())
        }
        (_, c) => c,
    };
    let Some(tiling) = tiling else {
        return (
            None,
            Cut {
                geometries,
                ..Cut::default()
            },
        );
    };
    let cut = cut_at_tiling(geometries, &tiling, layers, field_mm, is_hatch_output);
    (Some(tiling), cut)
}

/// True when `t` covers `extent` and none of its cells is wider than `cell_max`.
fn fits_tiling(t: &Tiling, extent: &BBox, cell_max: [f64; 2]) -> bool {
    let cells_fit = |v: &[f64], max: f64| v.windows(2).all(|w| w[1] - w[0] <= max + 1e-9);
    t.extent().contains_box(extent, 1e-9)
        && cells_fit(&t.xs, cell_max[0])
        && cells_fit(&t.ys, cell_max[1])
}

/// Narrowest cell a moved seam leaves, mm.
const MIN_CELL_MM: f64 = 1.0;

/// Where the seam of `axis` nearest to `from_mm` may go: its index among the borders, its
/// neighbours and the range `[lo, hi]` (no cell wider than `max`, none narrower than 1 mm).
struct SeamRange {
    k: usize,
    prev: f64,
    next: f64,
    lo: f64,
    hi: f64,
    max: f64,
}

impl SeamRange {
    fn of(tiling: &Tiling, axis: usize, from_mm: f64, cell_max_mm: [f64; 2]) -> Option<Self> {
        let borders = tiling.borders(axis);
        let k = (1..borders.len().saturating_sub(1)).min_by(|&a, &b| {
            (borders[a] - from_mm)
                .abs()
                .total_cmp(&(borders[b] - from_mm).abs())
        })?;
        let (prev, next) = (borders[k - 1], borders[k + 1]);
        let max = cell_max_mm[axis.min(1)];
        let lo = (prev + MIN_CELL_MM).max(next - max);
        let hi = (next - MIN_CELL_MM).min(prev + max);
        (lo <= hi).then_some(Self {
            k,
            prev,
            next,
            lo,
            hi,
            max,
        })
    }
}

/// `tiling` with the seam of `axis` (0: vertical, x; 1: horizontal, y) nearest to `from_mm`
/// moved towards `to_mm`, as far as its neighbours allow (no cell wider than `cell_max_mm`, no
/// cell narrower than 1 mm), and where the seam went, mm. None when the axis has no seam.
pub fn move_seam(
    tiling: &Tiling,
    axis: usize,
    from_mm: f64,
    to_mm: f64,
    cell_max_mm: [f64; 2],
) -> Option<(Tiling, f64)> {
    let r = SeamRange::of(tiling, axis, from_mm, cell_max_mm)?;
    let mut moved = tiling.clone();
    let v = if axis == 0 {
        &mut moved.xs
    } else {
        &mut moved.ys
    };
    let at = to_mm.clamp(r.lo, r.hi);
    v[r.k] = at;
    Some((moved, at))
}

/// Why the seam [`move_seam`] moves towards `to_mm` stops short of it, in words ("the cell
/// from 39.99 mm would be wider than 69.99 mm, the widest a scan field holds"); None when it
/// gets there (or there is no seam).
pub fn seam_stop_reason(
    tiling: &Tiling,
    axis: usize,
    from_mm: f64,
    to_mm: f64,
    cell_max_mm: [f64; 2],
) -> Option<String> {
    let r = SeamRange::of(tiling, axis, from_mm, cell_max_mm)?;
    let too_wide = |from: f64| {
        format!(
            "the cell from {from:.1} mm would be wider than {:.1} mm, the widest a scan field holds",
            r.max
        )
    };
    if to_mm > r.hi + 1e-9 {
        Some(if r.hi >= r.next - MIN_CELL_MM - 1e-9 {
            format!("the next seam is at {:.1} mm", r.next)
        } else {
            too_wide(r.prev)
        })
    } else if to_mm < r.lo - 1e-9 {
        Some(if r.lo <= r.prev + MIN_CELL_MM + 1e-9 {
            format!("the previous seam is at {:.1} mm", r.prev)
        } else {
            format!(
                "the cell up to {:.1} mm would be wider than {:.1} mm, the widest a scan field holds",
                r.next, r.max
            )
        })
    } else {
        None
    }
}

/// Replaces every oversize geometry by its pieces, cut at the seams of `tiling` (the document's,
/// see [`choose_document_tiling`]; chosen here when none or when it does not cover them), in
/// place, keeping document order. Returns a warning per split geometry and the cut's figures.
pub fn split_oversize(
    geometries: &mut Vec<Geometry>,
    tiling: Option<&Tiling>,
    layers: &[Layer],
    field_mm: [f64; 2],
) -> (Vec<Warning>, SeamStats, Option<Tiling>) {
    let oversize: BBox = geometries
        .iter()
        .filter(|g| is_oversize(g, field_mm))
        .fold(BBox::EMPTY, |b, g| b.union(g.bbox()));
    if oversize.is_empty() {
        return (Vec::new(), SeamStats::default(), tiling.cloned());
    }
    let tiling = match tiling {
        Some(t) if t.extent().contains_box(&oversize, 1e-9) => t.clone(),
        _ => match choose_document_tiling(geometries, layers, field_mm) {
            Some(t) => t,
            None => return (Vec::new(), SeamStats::default(), tiling.cloned()),
        },
    };
    let sizes: Vec<(String, f64, f64)> = geometries
        .iter()
        .map(|g| {
            (
                g.source.element.clone(),
                g.bbox().width(),
                g.bbox().height(),
            )
        })
        .collect();
    let cut = cut_at_tiling(std::mem::take(geometries), &tiling, layers, field_mm, |g| {
        is_oversize(g, field_mm)
    });
    let mut warnings = Vec::new();
    *geometries = cut.geometries;
    // warnings name the geometries by their number before the cut
    for &(i, pieces) in &cut.split {
        let (element, w, h) = &sizes[i];
        warnings.push(Warning {
            element: element.clone(),
            line: None,
            message: format!(
                "geometry {} ({w:.2} × {h:.2} mm) {SPLIT_WORDS} {pieces} pieces at field borders",
                i + 1
            ),
            note: false,
        });
    }
    (warnings, cut.stats, Some(tiling))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::tests_support::rect;
    use crate::geom::Pt;
    use proptest::prelude::*;

    #[test]
    fn big_rectangle_becomes_open_pieces_of_the_same_length() {
        let mut gs = vec![rect(0.0, 0.0, 150.0, 20.0)];
        let whole = gs[0].length_mm();
        let (warnings, stats, tiling) = split_oversize(&mut gs, None, &[], [70.0, 70.0]);
        // three columns of 50 mm: top and bottom edges cut twice each, joined around the ends
        assert_eq!(tiling.map(|t| t.cells()), Some([3, 1]));
        assert_eq!(gs.len(), 4, "{gs:?}");
        assert_eq!(warnings.len(), 1);
        assert_eq!(stats.cuts, 4);
        let total: f64 = gs.iter().map(Geometry::length_mm).sum();
        assert!((total - whole).abs() < 1e-9);
        for p in &gs {
            assert!(!p.closed);
            assert!(!is_oversize(p, [70.0, 70.0]));
        }
    }

    proptest! {
        #[test]
        fn pieces_fit_and_keep_length(
            pts in proptest::collection::vec((0.0f64..400.0, 0.0f64..400.0), 2..30),
            closed in any::<bool>(),
        ) {
            let pts: Vec<Pt> = pts.into_iter().map(|(x, y)| Pt::new(x, y)).collect();
            let g = Geometry::new(pts, closed, Source::default());
            let length = g.length_mm();
            let mut gs = vec![g];
            split_oversize(&mut gs, None, &[], [70.0, 70.0]);
            let total: f64 = gs.iter().map(Geometry::length_mm).sum();
            prop_assert!((total - length).abs() < 1e-6 * length.max(1.0) + crate::geom::seam::MIN_PIECE_MM * 4.0 * gs.len() as f64);
            for p in &gs {
                prop_assert!(!is_oversize(p, [70.0, 70.0]));
            }
        }
    }
}
