//! Hatching a document's geometries: closed geometries grouped into regions (a layer's shapes
//! together, or each drawing element on its own), hatched, and put back in document order with
//! their outlines. Strokes larger than a field are cut later, on the document's tiling
//! (`fields::cut_hatch_at_tiling`).

use super::{hatch_contours, HatchError, HatchSettings, OutlineMode, MAX_JOB_LINES};
use crate::document::{FillShapes, Geometry, Layer, Source, Warning};
use crate::geom::Pt;
use crate::job::JobCtx;
use rayon::prelude::*;
use std::collections::HashMap;

pub use crate::document::{is_hatch_output, HATCH_LAYER_PREFIX};

/// The geometries after hatching.
#[derive(Debug, Clone, Default)]
pub struct HatchedGeometries {
    /// Open geometries as they were, each region's outlines (unless dropped) and its hatch, in
    /// document order (a region sits where its first contour was).
    pub geometries: Vec<Geometry>,
    /// Regions with nothing left to hatch after the edge offset.
    pub warnings: Vec<Warning>,
    /// Regions hatched.
    pub regions: usize,
    /// Hatch geometries made.
    pub hatch_geometries: usize,
}

/// Hatches the closed geometries: with `settings.shapes` together, all of them form one region;
/// apart, the closed geometries of one drawing element (same `source.element`) do. A region is
/// resolved with `settings.fill_rule`. Hatch geometries are open polylines or closed rings, as
/// long as the fill makes them (cut to fit fields later, on the document's tiling).
pub fn hatch_geometries(
    geometries: &[Geometry],
    settings: &HatchSettings,
    ctx: &JobCtx,
) -> Result<HatchedGeometries, HatchError> {
    settings.check()?;
    let regions = fill_regions(geometries, settings.shapes);
    let hatched: Vec<Result<Vec<Geometry>, HatchError>> = regions
        .par_iter()
        .map(|members| {
            ctx.check()?;
            hatch_region(geometries, members, settings, ctx)
        })
        .collect();
    let mut out = HatchedGeometries {
        regions: regions.len(),
        ..HatchedGeometries::default()
    };
    let mut hatch_of: Vec<Vec<Geometry>> = Vec::with_capacity(regions.len());
    for (members, h) in regions.iter().zip(hatched) {
        let h = h?;
        if h.is_empty() {
            let g = &geometries[members[0]];
            out.warnings.push(Warning {
                element: g.source.element.clone(),
                line: None,
                message: format!(
                    "nothing left to hatch inside the {} mm edge offset",
                    settings.edge_offset()
                ),
                note: false,
            });
        }
        out.hatch_geometries += h.len();
        hatch_of.push(h);
    }
    let first_of: HashMap<usize, usize> =
        regions.iter().enumerate().map(|(r, m)| (m[0], r)).collect();
    let in_region: std::collections::HashSet<usize> = regions.iter().flatten().copied().collect();
    for (i, g) in geometries.iter().enumerate() {
        if !in_region.contains(&i) {
            out.geometries.push(g.clone());
            continue;
        }
        let Some(&r) = first_of.get(&i) else {
            continue;
        };
        let outlines = regions[r].iter().map(|&k| geometries[k].clone());
        // each region is emitted once, at its first member
        let hatch = std::mem::take(&mut hatch_of[r]);
        match settings.outline {
            OutlineMode::Before => {
                out.geometries.extend(outlines);
                out.geometries.extend(hatch);
            }
            OutlineMode::After => {
                out.geometries.extend(hatch);
                out.geometries.extend(outlines);
            }
            OutlineMode::None => out.geometries.extend(hatch),
        }
    }
    if out.geometries.is_empty() && !geometries.is_empty() {
        return Err(HatchError::NothingLeft {
            edge_offset_mm: settings.edge_offset(),
        });
    }
    Ok(out)
}

/// The geometries to mark from the artwork and its layers: the geometries of disabled layers
/// are left out; each hatched layer's closed geometries are hatched with its pen's settings
/// ([`hatch_geometries`] on that layer alone), its output placed where the layer's first
/// geometry was; everything else stays in artwork order. Layers not in the table are marked
/// as they are.
pub fn layer_geometries(
    artwork: &[Geometry],
    layers: &[Layer],
    ctx: &JobCtx,
) -> Result<HatchedGeometries, HatchError> {
    let mut out = HatchedGeometries::default();
    let mut hatched: HashMap<&str, Vec<Geometry>> = HashMap::new();
    let mut lines = 0.0;
    for l in layers.iter().filter(|l| l.pen.enabled) {
        let Some(settings) = &l.pen.hatch else {
            continue;
        };
        let members: Vec<Geometry> = artwork
            .iter()
            .filter(|g| g.layer == l.name)
            .cloned()
            .collect();
        if members.is_empty() {
            continue;
        }
        lines += estimated_lines(&members, settings);
        if lines > MAX_JOB_LINES {
            return Err(HatchError::TooManyLines {
                layer: l.name.clone(),
                spacing_mm: settings.spacing_mm,
                lines,
            });
        }
        let h = hatch_geometries(&members, settings, ctx)?;
        out.warnings.extend(h.warnings);
        out.regions += h.regions;
        out.hatch_geometries += h.hatch_geometries;
        hatched.insert(l.name.as_str(), h.geometries);
    }
    for g in artwork {
        let layer = layers.iter().find(|l| l.name == g.layer);
        if layer.is_some_and(|l| !l.pen.enabled) {
            continue;
        }
        match hatched.get_mut(g.layer.as_str()) {
            // the layer's whole output goes where its first geometry was; later ones find it empty
            Some(h) => out.geometries.append(h),
            None => out.geometries.push(g.clone()),
        }
    }
    Ok(out)
}

/// An upper estimate of the lines a hatch makes of `geometries`: per region its bounding box's
/// diagonal over the spacing, twice (a second family, or rings and gap strokes).
pub fn estimated_lines(geometries: &[Geometry], settings: &HatchSettings) -> f64 {
    let spacing = settings.spacing_mm.max(super::MIN_SPACING_MM);
    fill_regions(geometries, settings.shapes)
        .iter()
        .map(|members| {
            let b = members.iter().fold(crate::geom::BBox::EMPTY, |b, &k| {
                b.union(crate::geom::BBox::of(&geometries[k].points))
            });
            2.0 * (b.width().hypot(b.height()) / spacing).ceil()
        })
        .sum()
}

/// The regions to fill, each a list of closed geometries (indices), in order of first
/// appearance. Apart: the closed geometries of one drawing element form a region. Together:
/// also shapes whose boxes overlap join one region (a shape inside another is then a hole by
/// the fill rule, overlapping shapes are filled once); shapes apart from every other stay
/// regions of their own, so a layer of separate shapes is filled exactly as apart (its hatch
/// lines keep each shape's own phase).
fn fill_regions(geometries: &[Geometry], shapes: FillShapes) -> Vec<Vec<usize>> {
    let closed: Vec<usize> = (0..geometries.len())
        .filter(|&i| {
            let g = &geometries[i];
            g.closed && g.points.len() >= 3 && !is_hatch_output(g)
        })
        .collect();
    // union-find over the closed geometries (by position in `closed`)
    let mut parent: Vec<usize> = (0..closed.len()).collect();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    let join = |parent: &mut Vec<usize>, a: usize, b: usize| {
        let (ra, rb) = (root(parent, a), root(parent, b));
        if ra != rb {
            // the earlier one stays the root: regions keep their first member's place
            parent[ra.max(rb)] = ra.min(rb);
        }
    };
    let mut first_of: HashMap<&str, usize> = HashMap::new();
    for (k, &i) in closed.iter().enumerate() {
        let first = *first_of
            .entry(geometries[i].source.element.as_str())
            .or_insert(k);
        join(&mut parent, first, k);
    }
    if shapes == FillShapes::Together {
        // sweep over boxes sorted by their left edge: overlapping boxes join
        let boxes: Vec<crate::geom::BBox> = closed.iter().map(|&i| geometries[i].bbox()).collect();
        let mut by_x: Vec<usize> = (0..closed.len()).collect();
        by_x.sort_by(|&a, &b| boxes[a].min_x.total_cmp(&boxes[b].min_x));
        let mut open: Vec<usize> = Vec::new();
        for &k in &by_x {
            let b = boxes[k];
            open.retain(|&o| boxes[o].max_x >= b.min_x);
            for &o in &open {
                if boxes[o].min_y <= b.max_y && b.min_y <= boxes[o].max_y {
                    join(&mut parent, o, k);
                }
            }
            open.push(k);
        }
    }
    let mut region_of: HashMap<usize, usize> = HashMap::new();
    let mut regions: Vec<Vec<usize>> = Vec::new();
    for (k, &i) in closed.iter().enumerate() {
        let r = root(&mut parent, k);
        let slot = *region_of.entry(r).or_insert_with(|| {
            regions.push(Vec::new());
            regions.len() - 1
        });
        regions[slot].push(i);
    }
    regions
}

/// One region's hatch as geometries.
fn hatch_region(
    geometries: &[Geometry],
    members: &[usize],
    settings: &HatchSettings,
    ctx: &JobCtx,
) -> Result<Vec<Geometry>, HatchError> {
    let first = &geometries[members[0]];
    let contours: Vec<Vec<Pt>> = members
        .iter()
        .map(|&k| geometries[k].points.clone())
        .collect();
    let h = hatch_contours(&contours, settings, ctx).map_err(|e| match e {
        HatchError::TooFine {
            spacing_mm, lines, ..
        } => HatchError::TooFine {
            element: first.source.element.clone(),
            spacing_mm,
            lines,
        },
        e => e,
    })?;
    let layer = format!("{HATCH_LAYER_PREFIX}{}", first.source.layer);
    Ok(h.strokes
        .into_iter()
        .enumerate()
        .map(|(k, s)| {
            let source = Source {
                element: first.source.element.clone(),
                subpath: k,
                layer: layer.clone(),
                part: first.source.part,
            };
            Geometry::new(s.points, s.closed, source)
                .with_layer(&first.layer)
                .with_run(s.run)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::super::HatchStyle;
    use super::*;

    fn geom(points: Vec<Pt>, closed: bool, element: &str) -> Geometry {
        Geometry::new(
            points,
            closed,
            Source {
                element: element.into(),
                subpath: 0,
                layer: "#000000".into(),
                part: 0,
            },
        )
    }

    fn square(x0: f64, y0: f64, w: f64) -> Vec<Pt> {
        vec![
            Pt::new(x0, y0),
            Pt::new(x0 + w, y0),
            Pt::new(x0 + w, y0 + w),
            Pt::new(x0, y0 + w),
        ]
    }

    #[test]
    fn regions_by_element_with_outline_modes() {
        let gs = vec![
            geom(vec![Pt::new(0.0, 0.0), Pt::new(5.0, 5.0)], false, "#line"),
            geom(square(0.0, 0.0, 10.0), true, "#a"),
            geom(square(20.0, 0.0, 10.0), true, "#b"),
            geom(square(3.0, 3.0, 4.0), true, "#a"),
        ];
        let mut s = HatchSettings::new(HatchStyle::Lines, 1.0);
        s.shapes = FillShapes::Apart;
        let h = hatch_geometries(&gs, &s, &JobCtx::default()).unwrap();
        assert_eq!(h.regions, 2);
        assert_eq!(h.geometries[0].source.element, "#line");
        // outlines of #a first (both contours), then its hatch
        assert_eq!(h.geometries[1], gs[1]);
        assert_eq!(h.geometries[2], gs[3]);
        assert!(is_hatch_output(&h.geometries[3]));
        assert_eq!(h.geometries.len(), 4 + h.hatch_geometries);
        // #a has a hole: nothing within 1 mm of it or of the outer square
        for g in h
            .geometries
            .iter()
            .filter(|g| is_hatch_output(g) && g.source.element == "#a")
        {
            for p in &g.points {
                let dx = (3.0 - p.x).max(p.x - 7.0).max(0.0);
                let dy = (3.0 - p.y).max(p.y - 7.0).max(0.0);
                let outer = p.x.min(p.y).min(10.0 - p.x).min(10.0 - p.y);
                assert!(dx.hypot(dy) > 1.0 - 1e-6 && outer > 1.0 - 1e-6, "{p:?}");
            }
        }
        s.outline = OutlineMode::None;
        let h2 = hatch_geometries(&gs, &s, &JobCtx::default()).unwrap();
        assert_eq!(h2.geometries.len(), 1 + h2.hatch_geometries);
        s.outline = OutlineMode::After;
        let h3 = hatch_geometries(&gs, &s, &JobCtx::default()).unwrap();
        let last_a = h3
            .geometries
            .iter()
            .rposition(|g| g.source.element == "#a")
            .unwrap();
        assert_eq!(h3.geometries[last_a], gs[3]);
        // hatch output is never taken for a region again
        let again = hatch_geometries(&h3.geometries, &s, &JobCtx::default()).unwrap();
        assert_eq!(again.regions, 2);
    }

    /// Hatch samples (every 0.5 mm along the strokes) strictly inside the square `(x0, y0, w)`
    /// shrunk by `inset`.
    fn inside(h: &HatchedGeometries, x0: f64, y0: f64, w: f64, inset: f64) -> usize {
        let mut n = 0;
        for g in h.geometries.iter().filter(|g| is_hatch_output(g)) {
            for s in g.points.windows(2) {
                let steps = (s[0].dist(s[1]) / 0.5).ceil() as usize;
                for k in 0..=steps {
                    let p = s[0].plus(s[1].minus(s[0]).scale(k as f64 / steps.max(1) as f64));
                    if p.x > x0 + inset
                        && p.x < x0 + w - inset
                        && p.y > y0 + inset
                        && p.y < y0 + w - inset
                    {
                        n += 1;
                    }
                }
            }
        }
        n
    }

    #[test]
    fn a_layer_is_filled_together_or_apart() {
        // a plate and a shape inside it, two elements of one layer
        let gs = vec![
            geom(square(0.0, 0.0, 100.0), true, "#plate"),
            geom(square(30.0, 30.0, 40.0), true, "#inner"),
        ];
        let mut s = HatchSettings::new(HatchStyle::Lines, 1.0);
        s.outline = OutlineMode::None;
        let together = hatch_geometries(&gs, &s, &JobCtx::default()).unwrap();
        assert_eq!(together.regions, 1);
        // the inner shape is a hole: nothing hatched inside it (1.5 mm inset: edge offset)
        assert_eq!(inside(&together, 30.0, 30.0, 40.0, 1.5), 0);
        assert!(inside(&together, 0.0, 0.0, 25.0, 1.5) > 0);
        s.shapes = FillShapes::Apart;
        let apart = hatch_geometries(&gs, &s, &JobCtx::default()).unwrap();
        assert_eq!(apart.regions, 2);
        // each filled on its own: the inner square is hatched (by both fills)
        assert!(inside(&apart, 30.0, 30.0, 40.0, 1.5) > 0);
        let len = |h: &HatchedGeometries| h.geometries.iter().map(Geometry::length_mm).sum::<f64>();
        assert!(len(&apart) > len(&together) + 1500.0);
    }

    #[test]
    fn separate_shapes_are_filled_together_exactly_as_apart() {
        let gs = vec![
            geom(square(0.0, 0.0, 20.0), true, "#a"),
            geom(square(30.0, 0.0, 20.0), true, "#b"),
            geom(square(30.0, 30.0, 20.0), true, "#c"),
        ];
        let mut s = HatchSettings::new(HatchStyle::Zigzag, 0.7);
        let together = hatch_geometries(&gs, &s, &JobCtx::default()).unwrap();
        s.shapes = FillShapes::Apart;
        let apart = hatch_geometries(&gs, &s, &JobCtx::default()).unwrap();
        assert_eq!(together.regions, 3);
        assert_eq!(together.geometries, apart.geometries);
    }

    #[test]
    fn nothing_left_inside_the_edge_offset() {
        let mut s = HatchSettings::new(HatchStyle::Zigzag, 2.0);
        s.outline = OutlineMode::None;
        // tiny region: warning, no hatch; without outlines nothing is left, which is an error
        let tiny = vec![geom(square(0.0, 0.0, 1.0), true, "#tiny")];
        let e = hatch_geometries(&tiny, &s, &JobCtx::default()).unwrap_err();
        assert!(e.to_string().contains("nothing left to mark"), "{e}");
        s.outline = OutlineMode::After;
        let h = hatch_geometries(&tiny, &s, &JobCtx::default()).unwrap();
        assert_eq!(h.warnings.len(), 1);
        assert_eq!(h.geometries, tiny);
    }
}
