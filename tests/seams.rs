//! Large artwork on a step-and-scan machine (seed000 profile, 70 mm field): the tiling's field
//! count, straight and shared seams, the seam forms, shifted passes and fills of a layer's
//! shapes together or apart. The minimum cuts of any axis-aligned grid are found here by brute
//! force, apart from the planner's dynamic programme.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::document::{
    is_hatch_output, Document, HatchSettings, Layer, MachineProfile, MotionMode, Pen, Plan,
    SolverSettings,
};
use galvoplan::geom::seam::SeamForm;
use galvoplan::geom::Pt;
use galvoplan::hatch::hatch_geometries;
use galvoplan::import::ImportOptions;
use galvoplan::job::JobCtx;
use galvoplan::pipeline::{apply_pen_library, load_svg, plan_document};

/// The plate: 240 × 120 mm at (30, 40), plus `extra` SVG elements.
fn plate_svg(extra: &str) -> String {
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="300mm" height="200mm" viewBox="0 0 300 200">
<rect x="30" y="40" width="240" height="120" fill="none" stroke="black"/>{extra}
</svg>"#
    )
}

fn load(svg: &str, hatch: &str, seam: SeamForm) -> Document {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plate.svg");
    std::fs::write(&path, svg).unwrap();
    let settings = SolverSettings {
        split_oversize: true,
        motion: MotionMode::Step,
        hatch: Some(HatchSettings::parse_spec(hatch).unwrap()),
        seam,
        ..SolverSettings::default()
    };
    let profile = MachineProfile::builtin("seed000").unwrap();
    let (doc, _) = load_svg(&path, profile, settings, &ImportOptions::default()).unwrap();
    doc
}

fn plan(doc: &mut Document) -> Plan {
    let plan = plan_document(doc, &JobCtx::default()).unwrap();
    common::check_plan(doc, &plan);
    plan
}

/// Piece ends strictly inside the plate (more than 1.5 mm from its outline): the cuts.
fn cut_points(doc: &Document, pass: Option<u32>) -> Vec<Pt> {
    doc.geometries
        .iter()
        .filter(|g| !g.closed && pass.is_none_or(|p| g.pass == p))
        .flat_map(|g| [g.points[0], g.points[g.points.len() - 1]])
        .filter(|p| p.x > 31.5 && p.x < 268.5 && p.y > 41.5 && p.y < 158.5)
        .collect()
}

/// Distinct values, to 1 µm.
fn distinct(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    v
}

#[test]
fn a_hatched_plate_takes_eight_fields_cut_on_three_straight_seams() {
    let mut doc = load(&plate_svg(""), "zigzag:0.5:0", SeamForm::Straight);
    let p = plan(&mut doc);
    assert!(p.fields.len() <= 8, "{} fields", p.fields.len());
    let cuts = cut_points(&doc, None);
    let xs = distinct(cuts.iter().map(|p| p.x).collect());
    assert!(!xs.is_empty() && xs.len() <= 3, "cuts at x = {xs:?}");
    // every hatch line (one y) is cut at most 3 times
    let ys = distinct(cuts.iter().map(|p| p.y).collect());
    for y in ys {
        let on_line = distinct(
            cuts.iter()
                .filter(|p| (p.y - y).abs() < 1e-6)
                .map(|p| p.x)
                .collect(),
        );
        assert!(on_line.len() <= 3, "line y = {y} cut at {on_line:?}");
    }
    assert_eq!(p.seams.extra_marked_mm, 0.0);
    assert!(p.seams.seams() >= 3 && p.seams.length_mm() > 3.0 * 110.0);
    // the outline is cut on the same seams: no field holds a lone piece of it
    assert!(p.fields.iter().all(|f| f.geometries.len() > 1));
}

/// Crossings of `strokes` with a vertical line at `c` inside y ∈ [40, 160] (or a horizontal one
/// at y = c inside x ∈ [30, 270]).
fn crossings(strokes: &[Vec<Pt>], vertical: bool, c: f64) -> usize {
    let mut n = 0;
    for s in strokes {
        for w in s.windows(2) {
            let (a, b, along) = if vertical {
                (w[0].x, w[1].x, (w[0].y + w[1].y) / 2.0)
            } else {
                (w[0].y, w[1].y, (w[0].x + w[1].x) / 2.0)
            };
            let inside = if vertical {
                (40.0..=160.0).contains(&along)
            } else {
                (30.0..=270.0).contains(&along)
            };
            if a.min(b) < c && c <= a.max(b) && inside {
                n += 1;
            }
        }
    }
    n
}

/// The fewest cuts of any axis-aligned grid of cells at most `cell` wide over the plate, by
/// brute force over seam positions 0.5 mm apart.
fn fewest_grid_cuts(strokes: &[Vec<Pt>], cell: f64) -> usize {
    let step = 0.5;
    let best_axis = |vertical: bool, lo: f64, hi: f64| -> usize {
        let n = ((hi - lo) / cell).ceil() as usize;
        let positions: Vec<f64> = (1..((hi - lo) / step) as usize)
            .map(|k| lo + k as f64 * step)
            .collect();
        let cost: Vec<usize> = positions
            .iter()
            .map(|&c| crossings(strokes, vertical, c))
            .collect();
        // best[k][i]: least cuts of seams 1..=k with seam k at position i
        let mut best: Vec<Option<usize>> = positions
            .iter()
            .zip(&cost)
            .map(|(&p, &c)| (p - lo <= cell).then_some(c))
            .collect();
        for _ in 2..n {
            let next: Vec<Option<usize>> = (0..positions.len())
                .map(|i| {
                    (0..i)
                        .filter(|&j| positions[i] - positions[j] <= cell)
                        .filter_map(|j| best[j])
                        .min()
                        .map(|b| b + cost[i])
                })
                .collect();
            best = next;
        }
        (0..positions.len())
            .filter(|&i| hi - positions[i] <= cell)
            .filter_map(|i| best[i])
            .min()
            .unwrap()
    };
    best_axis(true, 30.0, 270.0) + best_axis(false, 40.0, 160.0)
}

#[test]
fn at_45_degrees_fields_and_cuts_are_near_the_fewest() {
    let mut doc = load(&plate_svg(""), "zigzag:0.5:45", SeamForm::Straight);
    // the fill and outline before any cut
    let uncut = hatch_geometries(
        &doc.artwork,
        &doc.settings.hatch.clone().unwrap(),
        &JobCtx::default(),
    )
    .unwrap();
    let strokes: Vec<Vec<Pt>> = uncut
        .geometries
        .iter()
        .map(|g| {
            let mut p = g.points.clone();
            if g.closed {
                p.push(p[0]);
            }
            p
        })
        .collect();
    let p = plan(&mut doc);
    assert!(p.fields.len() <= 9, "{} fields", p.fields.len());
    let fewest = fewest_grid_cuts(&strokes, 70.0 - 0.002);
    assert!(
        p.seams.cuts as f64 <= 1.10 * fewest as f64,
        "{} cuts, the fewest of any grid {fewest}",
        p.seams.cuts
    );
}

#[test]
fn interlocked_seams_are_a_comb_and_overlap_is_declared() {
    let mut doc = load(
        &plate_svg(""),
        "zigzag:0.5:0",
        SeamForm::Interlocked { band_mm: 0.6 },
    );
    let p = plan(&mut doc);
    let seams = p.tiling.as_ref().unwrap().seams(0).to_vec();
    assert_eq!(seams.len(), 3);
    for s in seams {
        // the cuts near this seam, line by line (by y): +0.3 and −0.3 alternate
        let mut near: Vec<Pt> = cut_points(&doc, None)
            .into_iter()
            .filter(|p| (p.x - s).abs() < 0.5)
            .collect();
        near.sort_by(|a, b| a.y.total_cmp(&b.y).then(a.x.total_cmp(&b.x)));
        near.dedup_by(|a, b| a.dist(*b) < 1e-9);
        assert!(near.len() > 100);
        for w in near.windows(2) {
            assert!(((w[0].x - s).abs() - 0.3).abs() < 1e-6);
            assert!(
                (w[0].x - s).signum() != (w[1].x - s).signum(),
                "not alternating at y = {}",
                w[0].y
            );
        }
    }
    // doubled overlap: the pieces mark exactly the artwork plus what the plan declares
    let mut doc = load(
        &plate_svg(""),
        "zigzag:0.5:0",
        SeamForm::Overlap {
            overlap_mm: 0.4,
            doubled: true,
        },
    );
    let whole: f64 = hatch_geometries(
        &doc.artwork,
        &doc.settings.hatch.clone().unwrap(),
        &JobCtx::default(),
    )
    .unwrap()
    .geometries
    .iter()
    .map(|g| g.length_mm())
    .sum();
    let p = plan(&mut doc);
    let marked: f64 = doc.geometries.iter().map(|g| g.length_mm()).sum();
    assert!(p.seams.extra_marked_mm > 100.0);
    assert!((marked - whole - p.seams.extra_marked_mm).abs() < 1e-6 * whole);
}

#[test]
fn shifted_passes_never_cut_a_line_twice_at_one_place() {
    let mut doc = load(&plate_svg(""), "zigzag:0.5:0", SeamForm::Straight);
    let pen = Pen {
        passes: 2,
        shift_passes: true,
        hatch: doc.settings.hatch.clone(),
        ..Pen::default()
    };
    let library = galvoplan::document::PenLibrary {
        version: galvoplan::document::PENS_VERSION,
        default: Some(pen),
        layers: Vec::new(),
    };
    apply_pen_library(&mut doc, &library);
    let _ = plan(&mut doc);
    let (one, two) = (cut_points(&doc, Some(1)), cut_points(&doc, Some(2)));
    assert!(!one.is_empty() && !two.is_empty());
    for a in &one {
        for b in two.iter().filter(|b| (b.y - a.y).abs() < 1e-6) {
            assert!(a.dist(*b) >= 1.0, "pass 1 cut {a:?} near pass 2 cut {b:?}");
        }
    }
    // each pass marks the whole plate once
    let length = |pass: u32| -> f64 {
        doc.geometries
            .iter()
            .filter(|g| g.pass == pass)
            .map(|g| g.length_mm())
            .sum()
    };
    assert!((length(1) - length(2)).abs() < 1e-6 * length(1));
    assert!(doc.geometries.iter().all(|g| g.pass > 0));
    // the job time of both choices is said
    let note = doc
        .warnings
        .iter()
        .find(|w| w.message.starts_with("shifted passes:"))
        .expect("a note comparing shifted and unshifted passes");
    assert!(note.message.contains("against"), "{}", note.message);
}

#[test]
fn a_circle_on_the_plate_is_a_hole_when_filled_together() {
    let svg = plate_svg(r#"<circle cx="150" cy="100" r="30" fill="none" stroke="black"/>"#);
    let inside = |doc: &Document| {
        doc.geometries
            .iter()
            .filter(|g| is_hatch_output(g))
            .flat_map(|g| {
                g.points
                    .windows(2)
                    .map(|w| (w[0], w[1]))
                    .collect::<Vec<_>>()
            })
            .filter(|(a, b)| {
                let m = a.plus(*b).scale(0.5);
                m.dist(Pt::new(150.0, 100.0)) < 28.0
            })
            .count()
    };
    let mut together = load(&svg, "lines:1:0", SeamForm::Straight);
    plan(&mut together);
    assert_eq!(inside(&together), 0);
    let mut apart = load(&svg, "lines:1:0", SeamForm::Straight);
    apart.settings.hatch.as_mut().unwrap().shapes = galvoplan::document::FillShapes::Apart;
    for l in &mut apart.layers {
        l.pen.hatch = apart.settings.hatch.clone();
    }
    if apart.layers.is_empty() {
        apart.layers.push(Layer {
            name: apart.artwork[0].layer.clone(),
            pen: Pen {
                hatch: apart.settings.hatch.clone(),
                ..Pen::default()
            },
        });
    }
    plan(&mut apart);
    assert!(inside(&apart) > 50);
}

#[test]
fn a_seam_moved_by_hand_moves_the_cuts() {
    let mut doc = load(&plate_svg(""), "zigzag:0.5:0", SeamForm::Straight);
    plan(&mut doc);
    let first = doc.tiling.as_ref().unwrap().seams(0)[0];
    let at = galvoplan::pipeline::move_seam(&mut doc, 0, first + 0.2, first - 5.0).unwrap();
    assert!((at - (first - 5.0)).abs() < 1e-9);
    let p = plan(&mut doc);
    assert!(p.fields.len() <= 8, "{} fields", p.fields.len());
    let xs = distinct(cut_points(&doc, None).iter().map(|p| p.x).collect());
    assert!(xs.iter().any(|x| (x - at).abs() < 1e-6), "{xs:?}");
    assert!(!xs.iter().any(|x| (x - first).abs() < 1e-6), "{xs:?}");
    // as far as the neighbours allow: no cell wider than the field leaves room for
    let second = doc.tiling.as_ref().unwrap().seams(0)[1];
    let at = galvoplan::pipeline::move_seam(&mut doc, 0, at, 0.0).unwrap();
    assert!((second - at - 70.0).abs() < 0.01, "{at} vs {second}");
    // on a project save and load, the moved tiling stays
    let text = serde_json::to_string(&doc).unwrap();
    let back: Document = serde_json::from_str(&text).unwrap();
    assert_eq!(back.tiling_set, doc.tiling_set);
}

#[test]
fn a_plan_keeps_its_geometries_when_a_hatch_change_makes_fewer() {
    let mut doc = load(&plate_svg(""), "zigzag:0.5:0", SeamForm::Straight);
    let p = plan(&mut doc);
    doc.plans.push(p);
    let before = doc.geometries.len();
    for l in &mut doc.layers {
        if let Some(h) = &mut l.pen.hatch {
            h.spacing_mm = 0.8;
        }
    }
    galvoplan::pipeline::derive_geometries(&mut doc, &JobCtx::default()).unwrap();
    galvoplan::pipeline::place_document_fields(&mut doc, &JobCtx::default()).unwrap();
    assert!(doc.geometries.len() < before);
    // the plan names the geometries it was planned on, which the document keeps
    doc.validate().unwrap();
    assert_eq!(
        doc.plan_geometries(&doc.plans[0]).map(<[_]>::len),
        Some(before)
    );
}
