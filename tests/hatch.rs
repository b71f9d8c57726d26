//! Hatch fills checked against an independent reference: the region from the raw contours by
//! ray casting (even-odd) or winding number (non-zero), the offset region as the points of the
//! region at least `d` from every contour segment, distances by brute force over a grid.
//!
//! For every style, on both contest shapes and on random polygons with holes:
//! - every point of the offset region lies within `s/2 · 1.01` of a hatch stroke (sampled on a
//!   grid of `s/4`);
//! - no hatch point lies outside the offset region by more than 1 µm (sampled every `s/4`);
//! - parallel hatch lines are never closer than `0.99 s`; for `contour`, rings of neighbouring
//!   levels are never closer than `0.99 s` and gap strokes never closer than `0.49 s` to a ring.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::bench::hatch::read_contours;
use galvoplan::document::{MachineProfile, SolverSettings};
use galvoplan::geom::{point_segment_dist, star_polygon as star, Pt};
use galvoplan::hatch::{
    hatch_contours, FillRule, HatchSettings, HatchStroke, HatchStyle, OutlineMode, RegionHatch,
    StrokeKind,
};
use galvoplan::import::ImportOptions;
use galvoplan::job::JobCtx;
use galvoplan::pipeline::{load_svg, plan_document};
use proptest::prelude::*;

/// Segments bucketed in a uniform grid, for "is any segment within r of p" queries.
struct SegGrid {
    segs: Vec<(Pt, Pt)>,
    cell: f64,
    origin: Pt,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

impl SegGrid {
    fn new(segs: Vec<(Pt, Pt)>, cell: f64) -> Self {
        let (mut lo, mut hi) = (Pt::new(f64::MAX, f64::MAX), Pt::new(f64::MIN, f64::MIN));
        for (a, b) in &segs {
            for p in [a, b] {
                lo = Pt::new(lo.x.min(p.x), lo.y.min(p.y));
                hi = Pt::new(hi.x.max(p.x), hi.y.max(p.y));
            }
        }
        let origin = Pt::new(lo.x - cell, lo.y - cell);
        let nx = ((hi.x - origin.x) / cell) as usize + 2;
        let ny = ((hi.y - origin.y) / cell) as usize + 2;
        let mut cells = vec![Vec::new(); nx * ny];
        for (i, (a, b)) in segs.iter().enumerate() {
            let (x0, y0) = (
                (a.x.min(b.x) - origin.x) / cell,
                (a.y.min(b.y) - origin.y) / cell,
            );
            let (x1, y1) = (
                (a.x.max(b.x) - origin.x) / cell,
                (a.y.max(b.y) - origin.y) / cell,
            );
            for cy in y0 as usize..=(y1 as usize).min(ny - 1) {
                for cx in x0 as usize..=(x1 as usize).min(nx - 1) {
                    cells[cy * nx + cx].push(i as u32);
                }
            }
        }
        Self {
            segs,
            cell,
            origin,
            nx,
            ny,
            cells,
        }
    }
    /// Distance from p to the nearest segment, or None when none is within r.
    fn within(&self, p: Pt, r: f64) -> Option<f64> {
        let c =
            |v: f64, o: f64, n: usize| (((v - o) / self.cell).floor().max(0.0) as usize).min(n - 1);
        let (x0, x1) = (
            c(p.x - r, self.origin.x, self.nx),
            c(p.x + r, self.origin.x, self.nx),
        );
        let (y0, y1) = (
            c(p.y - r, self.origin.y, self.ny),
            c(p.y + r, self.origin.y, self.ny),
        );
        let mut best: Option<f64> = None;
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                for &i in &self.cells[cy * self.nx + cx] {
                    let (a, b) = self.segs[i as usize];
                    let d = point_segment_dist(p, a, b);
                    if d <= r && best.is_none_or(|x| d < x) {
                        best = Some(d);
                    }
                }
            }
        }
        best
    }
}

fn loop_segs(l: &[Pt], closed: bool) -> impl Iterator<Item = (Pt, Pt)> + '_ {
    let n = l.len();
    let m = if closed { n } else { n.saturating_sub(1) };
    (0..m).map(move |i| (l[i], l[(i + 1) % n]))
}

/// The region of raw contours under a fill rule, and distances to its boundary.
struct Reference {
    contours: Vec<Vec<Pt>>,
    rule: FillRule,
    boundary: SegGrid,
}

impl Reference {
    fn new(contours: &[Vec<Pt>], rule: FillRule, cell: f64) -> Self {
        let segs = contours.iter().flat_map(|c| loop_segs(c, true)).collect();
        Self {
            contours: contours.to_vec(),
            rule,
            boundary: SegGrid::new(segs, cell),
        }
    }
    fn inside(&self, p: Pt) -> bool {
        let mut crossings = 0;
        let mut winding = 0;
        for c in &self.contours {
            for (a, b) in loop_segs(c, true) {
                if (a.y <= p.y) != (b.y <= p.y) {
                    let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                    if x > p.x {
                        crossings += 1;
                        winding += if b.y > a.y { 1 } else { -1 };
                    }
                }
            }
        }
        match self.rule {
            FillRule::EvenOdd => crossings % 2 == 1,
            FillRule::NonZero => winding != 0,
        }
    }
    /// Inside the region and at least `d` from its boundary.
    fn in_offset(&self, p: Pt, d: f64) -> bool {
        self.inside(p) && self.boundary.within(p, d).is_none()
    }
}

fn strokes_grid(strokes: &[&HatchStroke], cell: f64) -> SegGrid {
    let segs = strokes
        .iter()
        .flat_map(|s| loop_segs(&s.points, s.closed).collect::<Vec<_>>())
        .collect();
    SegGrid::new(segs, cell)
}

/// Points along a polyline, at most `step` apart.
fn samples(points: &[Pt], closed: bool, step: f64) -> Vec<Pt> {
    let mut out = Vec::new();
    for (a, b) in loop_segs(points, closed) {
        let n = (a.dist(b) / step).ceil().max(1.0) as usize;
        for k in 0..n {
            out.push(a.plus(b.minus(a).scale(k as f64 / n as f64)));
        }
    }
    if let Some(&p) = points.last() {
        out.push(p);
    }
    out
}

/// Checks a hatch against the reference; panics with the first violation of each kind.
fn check(contours: &[Vec<Pt>], settings: &HatchSettings, h: &RegionHatch) {
    let s = settings.spacing_mm;
    let d = settings.edge_offset();
    let reference = Reference::new(contours, settings.fill_rule, s.max(0.05));
    let strokes: Vec<&HatchStroke> = h.strokes.iter().collect();
    assert!(!strokes.is_empty(), "no strokes");
    // 0. no micro-strokes (a jump and a laser switch for nothing)
    for st in &strokes {
        let l = galvoplan::geom::polyline_length(&st.points, st.closed);
        assert!(l >= 0.002 * s, "{:?} stroke of {l} mm", st.kind);
    }
    // 1. nothing outside the offset region (1 µm)
    for st in &strokes {
        for p in samples(&st.points, st.closed, s / 4.0) {
            assert!(
                reference.inside(p),
                "{:?} point {p:?} outside the region",
                st.kind
            );
            if let Some(x) = reference.boundary.within(p, d - 1e-3) {
                panic!(
                    "{:?} point {p:?} only {x} mm from the outline (edge offset {d})",
                    st.kind
                );
            }
        }
    }
    // 2. coverage: every offset-region point within s/2 · 1.01 of a stroke
    let marks = strokes_grid(&strokes, s);
    let b = galvoplan::geom::BBox::of(&contours.iter().flatten().copied().collect::<Vec<_>>());
    let step = s / 4.0;
    let phase = 0.37 * step;
    let r = s / 2.0 * 1.01;
    let (mut tested, mut missed, mut worst) = (0usize, Vec::new(), 0.0f64);
    let mut y = b.min_y + phase;
    while y < b.max_y {
        let mut x = b.min_x + phase;
        while x < b.max_x {
            let p = Pt::new(x, y);
            if reference.in_offset(p, d) {
                tested += 1;
                if marks.within(p, r).is_none() {
                    let dist = marks.within(p, 10.0 * s).unwrap_or(f64::INFINITY);
                    worst = worst.max(dist);
                    missed.push(p);
                }
            }
            x += step;
        }
        y += step;
    }
    assert!(tested > 0, "no sample inside the offset region");
    assert!(
        missed.is_empty(),
        "{} of {tested} offset-region points farther than s/2·1.01 = {r} from every mark (worst {worst}), e.g. {:?}",
        missed.len(),
        &missed[..missed.len().min(5)]
    );
    // 3. spacing
    if settings.style == HatchStyle::Contour {
        check_rings(&strokes, s);
    } else {
        let families = if settings.style == HatchStyle::Cross {
            2
        } else {
            1
        };
        let offset_boundary = SegGrid::new(
            h.offset_loops
                .iter()
                .flat_map(|l| loop_segs(l, true))
                .collect(),
            s,
        );
        for f in 0..families {
            let a = settings.angle_deg.to_radians() + f as f64 * std::f64::consts::FRAC_PI_2;
            check_lines(
                &strokes,
                f as u8,
                Pt::new(a.cos(), a.sin()),
                s,
                &offset_boundary,
            );
        }
    }
}

/// Chords (segments along the hatch direction longer than s/100) sit on lines exactly one
/// spacing apart; a parallel segment off that lattice must be a piece of the offset boundary
/// (a zigzag join along a flat step of the boundary).
fn check_lines(strokes: &[&HatchStroke], family: u8, dir: Pt, s: f64, offset_boundary: &SegGrid) {
    let n = Pt::new(-dir.y, dir.x);
    let mut segs: Vec<(f64, Pt)> = Vec::new();
    for st in strokes.iter().filter(|st| {
        matches!(st.kind, StrokeKind::Line | StrokeKind::Zigzag) && st.family == family
    }) {
        for (a, b) in loop_segs(&st.points, st.closed) {
            let v = b.minus(a);
            let len = v.norm();
            if len > s / 100.0 && (v.x * dir.y - v.y * dir.x).abs() < 1e-9 * len.max(1.0) {
                segs.push((a.dot(n), a.plus(b).scale(0.5)));
            }
        }
    }
    // the line lattice: anchored at the most common position
    let mut vs: Vec<f64> = segs.iter().map(|x| x.0).collect();
    vs.sort_by(f64::total_cmp);
    let Some(&v0) = vs.get(vs.len() / 2) else {
        return;
    };
    let on_lattice = |v: f64| {
        let k = ((v - v0) / s).round();
        (v - v0 - k * s).abs() < 1e-6
    };
    let mut lines: Vec<f64> = vs.iter().copied().filter(|&v| on_lattice(v)).collect();
    lines.dedup_by(|a, b| (*a - *b).abs() < 1e-7);
    for w in lines.windows(2) {
        assert!(
            w[1] - w[0] >= 0.99 * s,
            "parallel lines {} apart (spacing {s})",
            w[1] - w[0]
        );
    }
    for (v, mid) in segs.iter().filter(|x| !on_lattice(x.0)) {
        assert!(
            offset_boundary.within(*mid, 1e-6).is_some(),
            "parallel segment at v = {v} (lattice {v0} + k·{s}) off the lines and off the boundary, at {mid:?}"
        );
    }
}

/// Rings of neighbouring levels at least 0.99 s apart; gaps at least 0.49 s from rings.
fn check_rings(strokes: &[&HatchStroke], s: f64) {
    let max_level = strokes.iter().map(|st| st.level).max().unwrap_or(0);
    let rings_at = |k: u32| -> Vec<&HatchStroke> {
        strokes
            .iter()
            .copied()
            .filter(|st| st.kind == StrokeKind::Ring && st.level == k)
            .collect()
    };
    for k in 0..max_level {
        let (a, b) = (rings_at(k), rings_at(k + 1));
        if a.is_empty() || b.is_empty() {
            continue;
        }
        let grid_a = strokes_grid(&a, s);
        for st in &b {
            for p in samples(&st.points, true, s / 4.0) {
                if let Some(x) = grid_a.within(p, 0.99 * s) {
                    panic!(
                        "ring of level {} only {x} from level {k} (spacing {s})",
                        k + 1
                    );
                }
            }
        }
    }
    let rings: Vec<&HatchStroke> = strokes
        .iter()
        .copied()
        .filter(|st| st.kind == StrokeKind::Ring)
        .collect();
    let grid = strokes_grid(&rings, s);
    for st in strokes.iter().filter(|st| st.kind == StrokeKind::Gap) {
        for p in samples(&st.points, st.closed, s / 4.0) {
            if let Some(x) = grid.within(p, 0.49 * s) {
                panic!("gap stroke point {p:?} only {x} from a ring (spacing {s})");
            }
        }
    }
}

fn contest(name: &str) -> Vec<Vec<Pt>> {
    read_contours(&common::root().join("tests/data/hatch").join(name)).unwrap()
}

fn settings(style: HatchStyle, s: f64, angle: f64) -> HatchSettings {
    HatchSettings {
        style,
        spacing_mm: s,
        angle_deg: angle,
        edge_offset_mm: Some(s),
        ..HatchSettings::default()
    }
}

fn run_and_check(contours: &[Vec<Pt>], st: &HatchSettings) -> RegionHatch {
    let h = hatch_contours(contours, st, &JobCtx::default()).unwrap();
    check(contours, st, &h);
    h
}

#[test]
fn contest_single_layer_all_styles() {
    let c = contest("attachment1_graph1.csv");
    assert_eq!(c.iter().map(Vec::len).sum::<usize>(), 1195);
    for style in HatchStyle::ALL {
        let h = run_and_check(&c, &settings(style, 1.0, 0.0));
        let st = &h.stats;
        match style {
            HatchStyle::Contour => {
                // seed 003: 895.954 mm of rings at d = s = 1 mm
                assert!((st.fill_mm - 896.0).abs() < 5.0, "{st:?}");
                assert!(st.rings >= 8);
            }
            HatchStyle::Zigzag => {
                // offset region 793 mm² / 1 mm + half its 213 mm perimeter in joins
                assert!((st.fill_mm - 900.0).abs() < 15.0, "{st:?}");
                assert!((st.total_mm - 1006.6).abs() < 3.0, "{st:?}");
            }
            _ => {}
        }
    }
    run_and_check(&c, &settings(HatchStyle::Zigzag, 1.0, 30.0));
    run_and_check(&c, &settings(HatchStyle::Cross, 1.0, 60.0));
}

#[test]
fn contest_multi_layer_all_styles() {
    let c = contest("attachment2_graph2.csv");
    assert_eq!(c.len(), 4);
    assert_eq!(c.iter().map(Vec::len).sum::<usize>(), 1681);
    for style in HatchStyle::ALL {
        let h = run_and_check(&c, &settings(style, 1.0, 0.0));
        // nothing inside the hole or the small hole, but the island is hatched
        assert!(h.stats.total_mm > 500.0);
    }
    run_and_check(&c, &settings(HatchStyle::Contour, 0.5, 0.0));
    run_and_check(&c, &settings(HatchStyle::Lines, 0.5, 135.0));
}

#[test]
fn finer_spacing_on_a_window_of_the_contest_shape() {
    // 0.2 mm on the whole single-layer shape (about 20 000 coverage samples per style)
    let c = contest("attachment1_graph1.csv");
    for style in [HatchStyle::Zigzag, HatchStyle::Contour] {
        run_and_check(&c, &settings(style, 0.2, 0.0));
    }
}

#[test]
fn without_border_lines_leave_the_boundary_alone() {
    let sq = vec![vec![
        Pt::new(0.0, 0.0),
        Pt::new(20.0, 0.0),
        Pt::new(20.0, 20.0),
        Pt::new(0.0, 20.0),
    ]];
    let mut st = settings(HatchStyle::Zigzag, 1.0, 0.0);
    st.border = false;
    let h = hatch_contours(&sq, &st, &JobCtx::default()).unwrap();
    assert!(h.strokes.iter().all(|s| s.kind == StrokeKind::Zigzag));
    assert_eq!(h.stats.lines, 18);
    assert_eq!(h.stats.parts, 1);
}

prop_compose! {
    /// An outer star polygon (radius 6–12 mm) and up to three star holes (radius 1–3 mm)
    /// inside it; holes may overlap (even-odd then fills their overlap).
    fn polygon_with_holes()(
        outer in prop::collection::vec(6.0f64..12.0, 5..40),
        holes in prop::collection::vec(
            ((-4.0f64..4.0, -4.0f64..4.0), prop::collection::vec(1.0f64..3.0, 3..12), 0.0f64..6.3),
            0..4,
        ),
        rot in 0.0f64..6.3,
    ) -> Vec<Vec<Pt>> {
        let mut v = vec![star(Pt::new(20.0, 20.0), &outer, rot)];
        for ((x, y), r, a) in holes {
            v.push(star(Pt::new(20.0 + x, 20.0 + y), &r, a));
        }
        v
    }
}

fn style_strategy() -> impl Strategy<Value = HatchStyle> {
    prop::sample::select(HatchStyle::ALL.to_vec())
}

/// Cases per property test: 128, or `HATCH_PROPTEST_CASES` for a longer stress run.
fn proptest_cases() -> u32 {
    std::env::var("HATCH_PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(128)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: proptest_cases(), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_polygons_with_holes_even_odd(
        contours in polygon_with_holes(),
        style in style_strategy(),
        s in 0.4f64..1.2,
        d_factor in 0.3f64..1.5,
        angle in 0.0f64..180.0,
    ) {
        let st = HatchSettings {
            style,
            spacing_mm: s,
            angle_deg: angle,
            edge_offset_mm: Some(d_factor * s),
            ..HatchSettings::default()
        };
        let h = hatch_contours(&contours, &st, &JobCtx::default()).unwrap();
        // a random polygon may leave nothing after the offset; then nothing is drawn
        let reference = Reference::new(&contours, FillRule::EvenOdd, s);
        let b = galvoplan::geom::BBox::of(&contours.iter().flatten().copied().collect::<Vec<_>>());
        let any_inside = (0..200).any(|i| {
            let p = Pt::new(
                b.min_x + (i % 20) as f64 / 20.0 * b.width(),
                b.min_y + (i / 20) as f64 / 10.0 * b.height(),
            );
            reference.in_offset(p, st.edge_offset() + 0.05 * s)
        });
        if h.strokes.is_empty() {
            prop_assert!(!any_inside, "no hatch although the offset region is not empty");
        } else {
            check(&contours, &st, &h);
        }
    }

    #[test]
    fn random_polygons_with_holes_non_zero(
        outer in prop::collection::vec(6.0f64..12.0, 5..30),
        hole in prop::collection::vec(1.0f64..3.0, 3..12),
        // the hole's inscribed circle has radius ≥ 1 · cos 60° = 0.5: the island stays inside it
        island in prop::collection::vec(0.2f64..0.48, 3..8),
        style in style_strategy(),
        s in 0.4f64..1.0,
    ) {
        // outer counter-clockwise, hole clockwise (a hole under non-zero), island inside the
        // hole counter-clockwise again
        let c = Pt::new(20.0, 20.0);
        let mut h_pts = star(c, &hole, 0.1);
        h_pts.reverse();
        let contours = vec![star(c, &outer, 0.0), h_pts, star(c, &island, 0.2)];
        let st = HatchSettings {
            style,
            spacing_mm: s,
            edge_offset_mm: Some(0.5 * s),
            fill_rule: FillRule::NonZero,
            ..HatchSettings::default()
        };
        let h = hatch_contours(&contours, &st, &JobCtx::default()).unwrap();
        check(&contours, &st, &h);
    }
}

#[test]
fn non_zero_fills_a_same_direction_inner_contour() {
    let outer = star(Pt::new(0.0, 0.0), &[10.0; 24], 0.0);
    let inner = star(Pt::new(0.0, 0.0), &[4.0; 24], 0.0);
    let c = vec![outer, inner];
    let mut st = settings(HatchStyle::Lines, 1.0, 0.0);
    st.border = false;
    st.fill_rule = FillRule::NonZero;
    let nz = hatch_contours(&c, &st, &JobCtx::default()).unwrap();
    st.fill_rule = FillRule::EvenOdd;
    let eo = hatch_contours(&c, &st, &JobCtx::default()).unwrap();
    // non-zero: one chord per line through the middle; even-odd: two
    let through_middle = |h: &RegionHatch| {
        h.strokes
            .iter()
            .filter(|s| s.points[0].y.abs() < 0.6)
            .count()
    };
    assert_eq!(through_middle(&nz), 1);
    assert_eq!(through_middle(&eo), 2);
}

#[test]
fn pipeline_hatches_the_contest_svg_into_fields() {
    let path = common::root().join("tests/data/hatch/apmcm-multi.svg");
    // a small field so that the hatch has to be cut (the outlines are split by the field stage)
    let settings = SolverSettings {
        hatch: Some(HatchSettings {
            outline: OutlineMode::Before,
            ..HatchSettings::new(HatchStyle::Zigzag, 0.5)
        }),
        split_oversize: true,
        ..SolverSettings::default()
    };
    let profile = MachineProfile {
        field_mm: [20.0, 20.0],
        ..MachineProfile::default()
    };
    let (mut doc, _) = load_svg(&path, profile, settings, &ImportOptions::default()).unwrap();
    let outlines = doc.geometries.len();
    assert_eq!(outlines, 4);
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    common::check_plan(&doc, &plan);
    assert!(plan.metrics.solve_s.hatch > 0.0);
    let outlines = doc
        .geometries
        .iter()
        .filter(|g| !galvoplan::hatch::is_hatch_output(g))
        .count();
    let hatch: Vec<_> = doc
        .geometries
        .iter()
        .filter(|g| galvoplan::hatch::is_hatch_output(g))
        .collect();
    assert_eq!(doc.geometries.len(), outlines + hatch.len());
    for g in &hatch {
        let b = g.bbox();
        assert!(b.width() < 20.0 && b.height() < 20.0);
    }
    // planning again does not hatch twice
    let n = doc.geometries.len();
    let plan2 = plan_document(&mut doc, &JobCtx::default()).unwrap();
    assert_eq!(doc.geometries.len(), n);
    assert_eq!(plan2.metrics.solve_s.hatch, 0.0);
}

fn pts(v: &[(f64, f64)]) -> Vec<Pt> {
    v.iter().map(|&(x, y)| Pt::new(x, y)).collect()
}

/// Zigzag at 0° with spacing `s` and edge offset `d`, checked like the property tests.
fn zigzag_checked(contours: &[Vec<Pt>], s: f64, d: f64, fill_rule: FillRule) {
    let st = HatchSettings {
        style: HatchStyle::Zigzag,
        spacing_mm: s,
        angle_deg: 0.0,
        edge_offset_mm: Some(d),
        fill_rule,
        ..HatchSettings::default()
    };
    let h = hatch_contours(contours, &st, &JobCtx::default()).unwrap();
    check(contours, &st, &h);
}

/// Found by the property test: the triangle's tip pokes 1.4 µm across an edge of the ten-gon,
/// which leaves a hole of 8·10⁻⁷ mm² in the even-odd region; its outline must keep the offset
/// region `d` away like any other.
#[test]
fn tiny_hole_where_contours_almost_touch_keeps_the_edge_offset() {
    let contours = vec![
        pts(&[
            (26.0, 20.0),
            (21.854101966249686, 25.706339097770922),
            (15.145898033750317, 23.52671151375484),
            (15.145898033750314, 16.47328848624516),
            (21.854101966249683, 14.293660902229078),
        ]),
        pts(&[
            (18.473218585085007, 19.715145660607785),
            (18.21326422543313, 17.69582318173844),
            (19.712352230930534, 18.445269141350373),
            (20.082044403894173, 19.542769695105314),
            (20.3345597673638, 20.106863661091396),
            (20.207282873637702, 20.711650072623218),
            (19.748829170136744, 21.12612107642971),
            (19.134312389330024, 21.191962836408074),
            (18.598457054828536, 20.88402603812569),
            (18.34594169135891, 20.319932072139608),
        ]),
        pts(&[
            (18.376237222371675, 17.775700320554346),
            (18.136688487015466, 20.06144175256869),
            (16.60907837936767, 19.24510397994495),
        ]),
    ];
    let s = 1.1410004342545863;
    zigzag_checked(&contours, s, 0.3 * s, FillRule::EvenOdd);
}

/// Found by the property test: offsetting this region trips a debug assertion inside
/// cavalier_contours (its release behaviour, checked here, is right).
#[test]
fn offset_that_trips_a_cavalier_debug_assertion() {
    let contours = vec![
        pts(&[
            (26.0, 20.0),
            (23.154862463615082, 29.7096682663203),
            (15.145898033750317, 23.52671151375484),
            (15.145898033750314, 16.47328848624516),
            (22.0768662234994, 13.608063015020548),
        ]),
        pts(&[
            (16.90093195722244, 22.48608803004446),
            (17.4065208423117, 21.780821927387642),
            (18.885265768195378, 20.27869869496166),
            (18.848229096760434, 22.386230200346485),
            (18.698712745031127, 23.241019798345953),
            (17.937189405914605, 23.657075804507812),
            (17.13710168601079, 23.32109956019633),
        ]),
        pts(&[
            (17.284531629385793, 19.972706729710684),
            (18.47970846924733, 18.26778463770463),
            (19.818990574781193, 18.722013040379736),
            (19.533240252317587, 20.402706301288895),
        ]),
    ];
    zigzag_checked(&contours, 0.4, 0.3 * 0.4, FillRule::EvenOdd);
}

/// Found by the property test: an offset leaves a degenerate loop on which
/// cavalier_contours' `remove_redundant` indexed past the end (a panic, also in release).
#[test]
fn degenerate_offset_loop_does_not_panic() {
    let outer = [6.0, 6.0, 6.0, 6.0, 6.0];
    let hole = [1.0, 1.0, 1.0];
    let island = [
        0.39165319098710055,
        0.20137599284156465,
        0.2,
        0.2,
        0.25050627362282246,
        0.3876117060660731,
        0.38686100316651706,
    ];
    let s = 0.5033860183032421;
    let c = Pt::new(20.0, 20.0);
    let mut hole_pts = star(c, &hole, 0.1);
    hole_pts.reverse();
    let contours = vec![star(c, &outer, 0.0), hole_pts, star(c, &island, 0.2)];
    zigzag_checked(&contours, s, 0.5 * s, FillRule::NonZero);
}

/// A circle imported as a coarse polygon (bench instance rnd-82: r = 1.44 mm, 0.01 mm chord
/// tolerance) under a 0.3 mm contour fill: its corners leave slivers a fraction of a percent
/// beyond s/2, which once became hundreds of gap strokes of about 3 µm. Gap strokes are at
/// least 0.02 s long, and the coverage still holds.
#[test]
fn coarse_polygon_circle_gets_no_micro_gap_strokes() {
    for n in [24usize, 27, 30, 36, 48] {
        let c: Vec<Pt> = (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                Pt::new(206.218 + 1.44 * a.cos(), 75.898 + 1.44 * a.sin())
            })
            .collect();
        let st = HatchSettings::new(HatchStyle::Contour, 0.3);
        let h = hatch_contours(std::slice::from_ref(&c), &st, &JobCtx::default()).unwrap();
        for g in h.strokes.iter().filter(|g| g.kind == StrokeKind::Gap) {
            let l = galvoplan::geom::polyline_length(&g.points, g.closed);
            assert!(l >= 0.02 * 0.3, "{n} corners: gap stroke of {l} mm");
        }
        check(&[c], &st, &h);
    }
}
