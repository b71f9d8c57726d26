//! End to end on the bundled examples: import → fields → order → export, checked.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use galvoplan::document::{MachineProfile, SolverSettings};
use galvoplan::export::{preview_svg, report_json, write_gcode};
use galvoplan::import::ImportOptions;
use galvoplan::job::JobCtx;
use galvoplan::pipeline::{load_svg, lower_plan, plan_document};

fn run(
    name: &str,
    settings: SolverSettings,
) -> (galvoplan::document::Document, galvoplan::document::Plan) {
    let path = common::root().join("assets/examples").join(name);
    let (mut doc, _) = load_svg(
        &path,
        MachineProfile::default(),
        settings,
        &ImportOptions::default(),
    )
    .unwrap();
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    (doc, plan)
}

#[test]
fn demo_plans_and_checks() {
    let (doc, plan) = run("demo.svg", SolverSettings::default());
    assert!(doc.geometries.len() > 100);
    common::check_plan(&doc, &plan);
    let m = &plan.metrics;
    assert!(m.fields >= 4, "demo spans several fields");
    let marked: f64 = doc.geometries.iter().map(|g| g.length_mm()).sum();
    assert!((m.marked_mm - marked).abs() < 1e-6);
    assert!(m.idle_mm > 0.0 && m.base_mm > 0.0);
    assert!(m.overlap_pct >= 0.0 && m.overlap_pct < 100.0);
    // idle_mm equals the sum of the G-code's laser-off travel between strokes
    let toolpath = lower_plan(&doc, &plan).unwrap();
    let g = write_gcode(&toolpath, &plan, doc.page_mm[1], "demo").unwrap();
    assert!(g.starts_with("; galvoplan"));
    assert!(g.contains("G21\nG90\n"));
    let report: serde_json::Value =
        serde_json::from_str(&report_json("demo.svg", &plan, &doc.warnings)).unwrap();
    assert_eq!(
        report["order"].as_array().unwrap().len(),
        doc.geometries.len()
    );
    assert!(report["metrics"]["idle_mm"].as_f64().unwrap() > 0.0);
    assert!(report["metrics"]["solve_s"]["total"].is_number());
    let svg = preview_svg(&toolpath, &plan, doc.page_mm);
    assert!(galvoplan::import::import_svg(
        svg.as_bytes(),
        "preview.svg",
        &ImportOptions::default()
    )
    .is_ok());
}

#[test]
fn same_input_same_plan() {
    let (_, a) = run("demo.svg", SolverSettings::default());
    let (_, b) = run("demo.svg", SolverSettings::default());
    assert_eq!(a.order, b.order);
    assert_eq!(a.fields, b.fields);
}

#[test]
fn project_round_trip_with_plan() {
    let (mut doc, plan) = run("demo.svg", SolverSettings::default());
    doc.plans.push(plan);
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("demo.galvoplan.json");
    galvoplan::document::save_project(&doc, &p).unwrap();
    let back = galvoplan::document::load_project(&p).unwrap();
    assert!(back == doc, "project round trip changed the document");
    // a corrupt file is reported, the good one is untouched by a failed save elsewhere
    std::fs::write(
        dir.path().join("bad.json"),
        "{\"format\":\"galvoplan-project\",\"version\":1,",
    )
    .unwrap();
    let e = galvoplan::document::load_project(&dir.path().join("bad.json"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bad.json") && e.contains("not a valid galvoplan project"),
        "{e}"
    );
}

/// `order_document_lowered` hands out the toolpath the plan's metrics were computed on, which
/// the GUI shows without lowering again: it must be what `lower_plan` makes of the plan, in
/// step-and-scan, on the fly (taut and seed 001's lsa route) and with pens that change the time
/// law (speeds, passes).
#[test]
fn the_ordering_toolpath_is_the_plans_lowering() {
    use galvoplan::document::{MotionMode, PenLibrary, StageRouteKind};
    use galvoplan::pipeline::{apply_pen_library, order_document_lowered, place_document_fields};
    let examples = common::root().join("assets/examples");
    let cases = [
        ("demo.svg", MotionMode::Step, StageRouteKind::Taut, false),
        (
            "demo.svg",
            MotionMode::OnTheFly,
            StageRouteKind::Taut,
            false,
        ),
        (
            "oversize.svg",
            MotionMode::OnTheFly,
            StageRouteKind::Lsa,
            false,
        ),
        (
            "two-layers.svg",
            MotionMode::Step,
            StageRouteKind::Taut,
            true,
        ),
        (
            "two-layers.svg",
            MotionMode::OnTheFly,
            StageRouteKind::Lsa,
            true,
        ),
    ];
    for (name, motion, stage_route, pens) in cases {
        let settings = SolverSettings {
            motion,
            stage_route,
            ..SolverSettings::default()
        };
        let (mut doc, _) = load_svg(
            &examples.join(name),
            MachineProfile::default(),
            settings,
            &ImportOptions::default(),
        )
        .unwrap();
        if pens {
            let lib = PenLibrary::load(&examples.join("two-layers.pens.toml")).unwrap();
            assert!(apply_pen_library(&mut doc, &lib).is_empty());
        }
        place_document_fields(&mut doc, &JobCtx::default()).unwrap();
        let (plan, toolpath) = order_document_lowered(&doc, &JobCtx::default()).unwrap();
        let case = format!("{name} {motion:?} {stage_route:?} pens {pens}");
        assert_eq!(MotionMode::from(plan.motion), motion, "{case}");
        assert_eq!(
            plan.stage_route.is_some(),
            stage_route != StageRouteKind::Taut && motion == MotionMode::OnTheFly,
            "{case}"
        );
        assert_eq!(
            plan.metrics.job_time_s,
            Some(toolpath.duration_s()),
            "{case}"
        );
        assert!(toolpath == lower_plan(&doc, &plan).unwrap(), "{case}");
    }
}

/// A project saved with a plan and reopened where the profile, pens and hatch are different
/// exports the plan byte for byte as it was planned (its own inputs), and says it is stale.
#[test]
fn a_saved_plan_exports_the_same_gcode_after_reopening_and_edits() {
    use galvoplan::document::{load_project, save_project, staleness, HatchSettings, PenLibrary};
    use galvoplan::pipeline::{apply_pen_library, derive_geometries, plan_document_lowered};
    let root = common::root().join("assets/examples");
    let (mut doc, _) = load_svg(
        &root.join("two-layers.svg"),
        MachineProfile::default(),
        SolverSettings::default(),
        &ImportOptions::default(),
    )
    .unwrap();
    let pens = PenLibrary::load(&root.join("two-layers.pens.toml")).unwrap();
    apply_pen_library(&mut doc, &pens);
    let (plan, toolpath) = plan_document_lowered(&mut doc, &JobCtx::default()).unwrap();
    let gcode = write_gcode(&toolpath, &plan, doc.page_mm[1], "two-layers.svg").unwrap();
    doc.plans.push(plan);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("job.galvoplan");
    save_project(&doc, &file).unwrap();
    let mut back = load_project(&file).unwrap();
    // another machine, other pens, another hatch: the plan keeps its own
    back.profile.axis_x.max_velocity_mm_s /= 3.0;
    back.profile.gcode.feed_mm_min = 1234.0;
    back.layers[0].pen.power = Some(5.0);
    back.layers[1].pen.hatch = Some(HatchSettings::parse_spec("lines:1:0").unwrap());
    derive_geometries(&mut back, &JobCtx::default()).unwrap();
    let plan = &back.plans[0];
    let again = write_gcode(
        &lower_plan(&back, plan).unwrap(),
        plan,
        back.page_mm[1],
        "two-layers.svg",
    )
    .unwrap();
    assert_eq!(again, gcode);
    let why = staleness(plan, &back);
    assert!(why.len() >= 4, "{why:?}");
    assert!(
        why.iter().any(|w| w.starts_with("outline: power 40 → 5")),
        "{why:?}"
    );
}

/// Version-2 projects (plans without their inputs) load with the document's profile and
/// settings as the plans' own.
#[test]
fn a_version_2_project_gives_its_plans_the_documents_inputs() {
    let (mut doc, plan) = run("demo.svg", SolverSettings::default());
    doc.plans.push(plan);
    let mut v: serde_json::Value = serde_json::json!({
        "format": "galvoplan-project",
        "version": 2,
        "document": serde_json::to_value(&doc).unwrap(),
    });
    for p in v["document"]["plans"].as_array_mut().unwrap() {
        let p = p.as_object_mut().unwrap();
        p.remove("profile");
        p.remove("settings");
        p.remove("geometry_rev");
    }
    v["document"]["profile"]["axis_x"]["max_velocity_mm_s"] = serde_json::json!(123.0);
    let back = galvoplan::document::parse_project(&v.to_string(), "v2.json").unwrap();
    assert_eq!(back.plans[0].profile.axis_x.max_velocity_mm_s, 123.0);
    assert_eq!(back.plans[0].profile, back.profile);
    assert!(galvoplan::document::staleness(&back.plans[0], &back).is_empty());
}

/// An example opened with the motion on automatic.
fn load_auto(name: &str) -> galvoplan::document::Document {
    let path = common::root().join("assets/examples").join(name);
    let settings = SolverSettings {
        motion: galvoplan::document::MotionMode::Auto,
        ..SolverSettings::default()
    };
    let options = ImportOptions::default();
    let (doc, _) = load_svg(&path, MachineProfile::default(), settings, &options).unwrap();
    doc
}

/// Cancels the job when the second ordering (the second motion, under auto) starts.
struct CancelOnSecondOrdering {
    token: galvoplan::job::CancelToken,
    starts: std::sync::atomic::AtomicUsize,
}

impl galvoplan::job::ProgressSink for CancelOnSecondOrdering {
    fn report(&self, p: &galvoplan::job::Progress) {
        if p.message == "HHA: field order"
            && self
                .starts
                .fetch_add(1, std::sync::atomic::Ordering::SeqCst)
                == 1
        {
            self.token.cancel();
        }
    }
}

#[test]
fn a_cancel_under_auto_keeps_the_motion_planned_so_far() {
    let mut doc = load_auto("demo.svg");
    let token = galvoplan::job::CancelToken::new();
    let sink = std::sync::Arc::new(CancelOnSecondOrdering {
        token: token.clone(),
        starts: Default::default(),
    });
    let ctx = JobCtx::new(token, sink.clone());
    let plan = plan_document(&mut doc, &ctx).unwrap();
    assert!(ctx.is_cancelled(), "the second motion was never started");
    assert_eq!(plan.motion, galvoplan::document::Motion::Step);
    common::check_plan(&doc, &plan);
}

#[test]
fn a_cut_is_the_placements_choice_and_a_step_placement_starts_again_from_whole_geometries() {
    let mut doc = load_auto("oversize.svg");
    let whole = doc.geometries.len();
    let ctx = JobCtx::default();
    let choices = |doc: &galvoplan::document::Document| {
        doc.warnings
            .iter()
            .filter(|w| w.message.contains("cut at field borders"))
            .count()
    };
    galvoplan::pipeline::place_document_fields(&mut doc, &ctx).unwrap();
    assert!(doc.geometries.len() > whole, "auto cuts oversize.svg");
    galvoplan::pipeline::place_document_fields(&mut doc, &ctx).unwrap();
    assert_eq!(choices(&doc), 1, "{:?}", doc.warnings);
    // step-and-scan without the split setting: the whole geometries again, which it cannot mark
    doc.settings.motion = galvoplan::document::MotionMode::Step;
    let err = galvoplan::pipeline::place_document_fields(&mut doc, &ctx).unwrap_err();
    assert!(err.to_string().contains("larger than"), "{err}");
    assert_eq!(doc.geometries.len(), whole);
    assert_eq!(choices(&doc), 0);
}

/// A layer named after its stroke colour (an SVG without layer groups) is said by a colour
/// word in stale reasons, and a value its pen leaves to the profile by the profile's value.
#[test]
fn stale_reasons_name_a_colour_layer_in_words() {
    use galvoplan::document::staleness;
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("grey.svg");
    std::fs::write(
        &svg,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="40mm" height="40mm" viewBox="0 0 40 40">
<path d="M5 5 L30 5 L30 30" fill="none" stroke="#1f2937"/></svg>"##,
    )
    .unwrap();
    let (mut doc, _) = load_svg(
        &svg,
        MachineProfile::default(),
        SolverSettings::default(),
        &ImportOptions::default(),
    )
    .unwrap();
    let plan = plan_document(&mut doc, &JobCtx::default()).unwrap();
    doc.plans.push(plan);
    assert_eq!(doc.layers[0].name, "#1f2937");
    doc.layers[0].pen.mark_speed_mm_s = Some(500.0);
    let why = staleness(&doc.plans[0], &doc);
    assert_eq!(why, ["dark grey (#1f2937): mark speed 1000 → 500 mm/s"]);
}
