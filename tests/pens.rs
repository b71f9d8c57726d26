//! Layers and pens end to end: the two-layer example with its pens file plans with per-layer
//! speeds, powers and passes; pens change the job time, the G-code and what is marked.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::document::{Document, MachineProfile, PenLibrary, Plan, SolverSettings};
use galvoplan::export::write_gcode;
use galvoplan::import::ImportOptions;
use galvoplan::job::JobCtx;
use galvoplan::pipeline::{apply_pen_library, load_svg, lower_plan, plan_document};

fn example(name: &str) -> std::path::PathBuf {
    common::root().join("assets/examples").join(name)
}

fn plan_with(library: Option<&PenLibrary>) -> (Document, Plan) {
    let settings = SolverSettings {
        seed: 3,
        ..SolverSettings::default()
    };
    let (mut doc, _) = load_svg(
        &example("two-layers.svg"),
        MachineProfile::default(),
        settings,
        &ImportOptions::default(),
    )
    .unwrap();
    if let Some(lib) = library {
        assert!(apply_pen_library(&mut doc, lib).is_empty());
    }
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    (doc, plan)
}

fn pens() -> PenLibrary {
    PenLibrary::load(&example("two-layers.pens.toml")).unwrap()
}

#[test]
fn two_layers_plan_with_their_pens() {
    let lib = pens();
    let (doc, plan) = plan_with(Some(&lib));
    let names: Vec<&str> = doc.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["outline", "fill"]);
    assert_eq!(plan.layers, doc.layers);
    // the fill layer is hatched and marked twice, the outline once
    let fill = |k: usize| doc.geometries[k].layer == "fill";
    let hatched = doc.geometries.iter().filter(|g| g.layer == "fill").count();
    assert!(hatched > 4, "the fill layer is hatched: {hatched}");
    let fill_steps = plan.order.iter().filter(|s| fill(s.geometry)).count();
    assert_eq!(fill_steps, 2 * hatched);
    assert_eq!(
        plan.order.len() - fill_steps,
        doc.geometries.len() - hatched
    );
    // the job time's marking is each stroke at its pen's speed, once per pass
    let mark_s: f64 = plan
        .order
        .iter()
        .map(|s| {
            let g = &doc.geometries[s.geometry];
            let v = if g.layer == "fill" { 600.0 } else { 1500.0 };
            g.length_mm() / v
        })
        .sum();
    let b = plan.metrics.job_time_breakdown_s.unwrap();
    assert!(
        (b.mark - mark_s).abs() < 1e-9 * mark_s.max(1.0),
        "{} vs {mark_s}",
        b.mark
    );
    let marked: f64 = plan
        .order
        .iter()
        .map(|s| doc.geometries[s.geometry].length_mm())
        .sum();
    assert!((plan.metrics.marked_mm - marked).abs() < 1e-6);
    // the G-code carries both powers and both feeds
    let toolpath = lower_plan(&doc, &plan).unwrap();
    let g = write_gcode(&toolpath, &plan, doc.page_mm[1], "t").unwrap();
    assert!(g.contains("\nM3 S40\n") && g.contains("\nM3 S85\n"));
    assert!(g.contains(" F90000\n") && g.contains(" F36000\n"));
    assert!(g.contains("; layer fill: mark speed 600 mm/s, passes 2, pulse frequency 60 kHz"));
    assert_eq!(
        g.matches("\nM3 ").count(),
        plan.order.len(),
        "one laser-on per stroke"
    );
}

#[test]
fn speeds_and_passes_change_the_job_time() {
    let (_, plain) = plan_with(None);
    let mut lib = pens();
    let (_, with_pens) = plan_with(Some(&lib));
    let t = |p: &Plan| p.metrics.job_time_breakdown_s.unwrap().mark;
    // one pass at the same speeds: less marking than two passes
    lib.layers[1].pen.passes = 1;
    let (_, one_pass) = plan_with(Some(&lib));
    assert!(
        t(&with_pens) > t(&one_pass) * 1.5,
        "{} vs {}",
        t(&with_pens),
        t(&one_pass)
    );
    // a faster pen marks faster
    lib.layers[1].pen.mark_speed_mm_s = Some(1200.0);
    let (_, faster) = plan_with(Some(&lib));
    assert!(
        (t(&one_pass) / t(&faster) - 1.0) > 0.2,
        "{} vs {}",
        t(&one_pass),
        t(&faster)
    );
    assert!(plain.metrics.job_time_s.unwrap() < with_pens.metrics.job_time_s.unwrap());
    // a disabled layer is not marked
    lib.layers[1].pen.enabled = false;
    let (doc, off) = plan_with(Some(&lib));
    assert!(doc.geometries.iter().all(|g| g.layer == "outline"));
    assert_eq!(off.order.len(), doc.geometries.len());
}

#[test]
fn version_1_projects_upgrade_with_their_hatch_on_the_default_layer() {
    let path = common::root().join("tests/data/projects/v1.galvoplan");
    let doc = galvoplan::document::load_project(&path).unwrap();
    assert_eq!(doc.layers.len(), 1);
    assert_eq!(doc.layers[0].name, "default");
    assert_eq!(
        doc.layers[0].pen.hatch.as_ref().map(|h| h.spacing_mm),
        Some(0.5)
    );
    assert_eq!(doc.artwork.len(), 2);
    assert_eq!(doc.geometries.len(), 3);
    assert_eq!(doc.fields.len(), 1);
    assert_eq!(doc.plans.len(), 1);
    assert!(doc.plans[0].layers.is_empty());
    // saved again it is a version-2 project that loads the same
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("v2.galvoplan");
    galvoplan::document::save_project(&doc, &p).unwrap();
    assert!(std::fs::read_to_string(&p)
        .unwrap()
        .contains("\"version\": 2"));
    assert_eq!(galvoplan::document::load_project(&p).unwrap(), doc);
}

#[test]
fn invalid_projects_name_the_value_in_words() {
    let path = common::root().join("tests/data/projects/v1.galvoplan");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("\"direction_weight\": 0.5", "\"direction_weight\": -2.0");
    let e = galvoplan::document::parse_project(&text, "p.galvoplan")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("p.galvoplan")
            && e.contains("Direction weight must be zero or a positive number, not -2"),
        "{e}"
    );
}
