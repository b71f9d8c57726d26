//! Headless GUI tests (egui_kittest): the real `App::ui` driven through the accessibility tree
//! and synthetic pointer/keyboard events, no display or GPU needed.
#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use egui::{Event, Key, Modifiers, PointerButton, Vec2};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use galvoplan::app::commands::Command;
use galvoplan::app::playback::{state_text, time_text};
use galvoplan::app::App;
use galvoplan::document::{Algo, CostModel, MotionMode, SolverSettings};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn demo() -> PathBuf {
    common::root().join("assets/examples/demo.svg")
}

/// `assets/examples/oversize.svg` opened in step-and-scan (fields for what fits; the strokes
/// larger than a field uncovered) and its geometry count.
fn opened_oversize() -> (Harness<'static, App>, usize) {
    let h = opened(&common::root().join("assets/examples/oversize.svg"));
    let n = h.state().session.doc().geometries.len();
    (h, n)
}

/// Steps `Harness::run` may take before the UI must have settled.
const MAX_STEPS: u64 = 16;

fn harness(app: App) -> Harness<'static, App> {
    Harness::builder()
        // a canvas raster drawn in the background asks for a frame when it is done (to show
        // it): a few steps more than egui's default of 4 before the UI settles
        .with_max_steps(MAX_STEPS)
        .with_size(Vec2::new(1500.0, 950.0))
        .build_ui_state(|ui, app: &mut App| app.ui(ui), app)
}

/// A harness with `path` opened through the public API (as the CLI argument does).
fn opened(path: &Path) -> Harness<'static, App> {
    let mut app = App::default();
    assert!(app.open(path), "{}", app.status());
    let mut h = harness(app);
    settle(&mut h);
    h
}

/// Runs the UI until it settles, however long background work (an import, a solve, a canvas
/// raster) keeps it repainting: steps with small sleeps while a job runs, then `try_run`, and
/// again after a sleep if a frame is still asked for. Panics only if the UI has not settled
/// after 60 s. (`Harness::run` alone gives up after `MAX_STEPS` frames, which a loaded CI
/// machine can exceed while a quick job finishes.)
fn settle(h: &mut Harness<'_, App>) {
    let t0 = Instant::now();
    loop {
        while h.state().is_busy() {
            assert!(
                t0.elapsed() < Duration::from_secs(60),
                "a job still runs after 60 s"
            );
            std::thread::sleep(Duration::from_millis(20));
            h.step();
        }
        match h.try_run() {
            Ok(_) => return,
            Err(e) => assert!(t0.elapsed() < Duration::from_secs(60), "{e}"),
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Steps the UI (with small sleeps) until no solve runs; panics after `limit`.
fn wait_idle(h: &mut Harness<'_, App>, limit: Duration) {
    let t0 = Instant::now();
    while h.state().is_busy() {
        assert!(t0.elapsed() < limit, "solve still running after {limit:?}");
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    settle(h);
}

/// Shows a section of the left panel ("Layers (n)", "Solver settings", "Machine profile").
fn section(h: &mut Harness<'_, App>, name: &str) {
    h.get_by_label(name).click();
    settle(h);
}

/// A file dropped on the window.
#[derive(Debug)]
struct Dropped(PathBuf);
impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

fn ctrl() -> Modifiers {
    Modifiers::COMMAND | Modifiers::CTRL
}

#[test]
fn open_demo_run_hha_shows_metrics() {
    let mut h = opened(&demo());
    assert_eq!(h.state().session.doc().geometries.len(), 122);
    assert!(!h.state().session.doc().fields.is_empty());
    assert!(h.state().uncovered().is_empty());
    assert!(h.query_by_label("Idle travel (mm)").is_none());
    h.get_by_label("Run HHA").click();
    h.step();
    assert!(h.state().is_busy(), "the solve runs in the background");
    wait_idle(&mut h, Duration::from_secs(120));
    let plan = h.state().active_plan().expect("a plan").clone();
    assert_eq!(plan.algo, Algo::Hha);
    assert_eq!(plan.name, "HHA · job time · step-and-scan");
    common::check_plan(h.state().session.doc(), &plan);
    // the metrics table: worded rows with units, the job time first with the plan's value
    h.get_by_label("Idle travel (mm)");
    h.get_by_label(&format!("{:.1}", plan.metrics.idle_mm));
    h.get_by_label("Stage travel (mm)");
    h.get_by_label(&format!("{:.1}", plan.metrics.base_mm));
    let job_s = plan.metrics.job_time_s.expect("a job time");
    h.get_by_label(&format!("{job_s:.3}"));
    let breakdown = plan.metrics.job_time_breakdown_s.expect("a breakdown");
    h.get_by_label("Marking (s)");
    h.get_by_label(&format!("{:.2}", breakdown.mark));
    let job_row = h.get_by_label("Job time (s)").rect();
    let idle_row = h.get_by_label("Idle travel (mm)").rect();
    let solve_row = h.get_by_label("Solve time (s)").rect();
    assert!(job_row.top() < idle_row.top() && idle_row.top() < solve_row.top());
    assert!(h.query_by_label("idle_mm").is_none(), "no internal keys");
}

#[test]
fn dragging_a_field_reallocates_and_undoes() {
    let mut h = opened(&demo());
    h.get_by_label("Run HHA").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(120));
    assert!(h.query_by_label("stale").is_none());
    let field = h.state().session.doc().fields[0].clone();
    assert!(!field.geometries.is_empty());
    let p0 = h.state().field_screen_pos(field.id).unwrap();
    let d = Vec2::new(-120.0, 90.0);
    h.hover_at(p0);
    h.step();
    h.drag_at(p0);
    h.step();
    for i in 1..=6 {
        h.hover_at(p0 + d * (i as f32 / 6.0));
        h.step();
    }
    h.drop_at(p0 + d);
    settle(&mut h);
    let moved = h
        .state()
        .session
        .doc()
        .fields
        .iter()
        .find(|f| f.id == field.id)
        .unwrap()
        .clone();
    assert!(moved.center.x < field.center.x - 5.0, "{moved:?}");
    assert!(moved.center.y > field.center.y + 5.0, "{moved:?}");
    // the allocation followed the move: the field lost geometries (now uncovered or moved)
    assert_ne!(moved.geometries, field.geometries);
    assert!(!h.state().uncovered().is_empty());
    assert!(
        h.state().status().contains("uncovered"),
        "{}",
        h.state().status()
    );
    // the plan is marked stale, and Run is blocked while geometries are uncovered
    h.get_by_label("stale");
    assert!(h.state().solve_blocker().is_some());
    // the whole drag is one undo step
    h.key_press_modifiers(ctrl(), Key::Z);
    settle(&mut h);
    let back = h
        .state()
        .session
        .doc()
        .fields
        .iter()
        .find(|f| f.id == field.id)
        .unwrap();
    assert_eq!(back.center, field.center);
    assert_eq!(back.geometries, field.geometries);
    assert!(h.state().uncovered().is_empty());
    assert!(h.query_by_label("stale").is_none());
    h.key_press_modifiers(ctrl() | Modifiers::SHIFT, Key::Z);
    settle(&mut h);
    let again = h
        .state()
        .session
        .doc()
        .fields
        .iter()
        .find(|f| f.id == field.id)
        .unwrap();
    assert_eq!(again.center, moved.center);
}

#[test]
fn add_lock_delete_and_replace_fields() {
    let mut h = opened(&demo());
    let n = h.state().session.doc().fields.len();
    h.get_by_label("Add field").click();
    settle(&mut h);
    let canvas = h.get_by_label("Work area").rect();
    let at = canvas.center() + Vec2::new(10.0, 10.0);
    h.hover_at(at);
    h.step();
    for pressed in [true, false] {
        h.event(Event::PointerButton {
            pos: at,
            button: PointerButton::Primary,
            pressed,
            modifiers: Modifiers::NONE,
        });
    }
    settle(&mut h);
    assert_eq!(h.state().session.doc().fields.len(), n + 1);
    let id = h
        .state()
        .selected_field()
        .expect("the new field is selected");
    h.get_by_label("Lock").click();
    settle(&mut h);
    assert!(h
        .state()
        .session
        .doc()
        .fields
        .iter()
        .any(|f| f.id == id && f.locked));
    // re-placing keeps the locked field (a background job)
    h.get_by_label("Re-place automatically").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    assert!(h
        .state()
        .session
        .doc()
        .fields
        .iter()
        .any(|f| f.id == id && f.locked));
    assert!(h.state().uncovered().is_empty());
    h.get_by_label("Delete field").click();
    settle(&mut h);
    assert!(!h.state().session.doc().fields.iter().any(|f| f.id == id));
    // undo the delete, the re-placement, the lock and the add
    for _ in 0..4 {
        h.get_by_label("Undo").click();
        settle(&mut h);
    }
    assert_eq!(h.state().session.doc().fields.len(), n);
}

/// Types `text` into the `n`-th field labelled `label` and presses Enter; steps once (a
/// background job may start).
fn enter_nth(h: &mut Harness<'_, App>, label: &str, n: usize, text: &str) {
    nth_by_label(h, label, n).focus();
    settle(h);
    h.key_press_modifiers(ctrl(), Key::A);
    nth_by_label(h, label, n).type_text(text);
    settle(h);
    h.key_press(Key::Enter);
    h.step();
}

fn set_text(h: &mut Harness<'_, App>, label: &str, text: &str) {
    h.get_by_label(label).focus();
    settle(h);
    h.key_press_modifiers(ctrl(), Key::A);
    h.get_by_label(label).type_text(text);
    settle(h);
    h.key_press(Key::Enter);
    settle(h);
}

#[test]
fn invalid_profile_and_settings_input_is_rejected() {
    let mut h = opened(&demo());
    section(&mut h, "Machine profile");
    set_text(&mut h, "Field width (mm)", "-5");
    // worded, without file keys
    h.get_by_label("Field width (mm) must be a positive number, not -5");
    assert!(h.query_by_label_contains("field_mm").is_none());
    assert_eq!(h.state().session.doc().profile.field_mm, [70.0, 70.0]);
    set_text(&mut h, "Field width (mm)", "abc");
    h.get_by_label_contains("Field width (mm) must be a number, not 'abc'");
    assert_eq!(h.state().session.doc().profile.field_mm, [70.0, 70.0]);
    section(&mut h, "Solver settings");
    set_text(&mut h, "GA mutation rate", "1.5");
    h.get_by_label("GA mutation rate must be between 0 and 1, not 1.5");
    assert_eq!(
        h.state().session.doc().settings.ga.mutation_rate,
        SolverSettings::default().ga.mutation_rate
    );
    // a valid value is applied, resizes the fields and can be undone
    section(&mut h, "Machine profile");
    set_text(&mut h, "Field width (mm)", "60");
    assert!(h
        .query_by_label_contains("must be a positive number")
        .is_none());
    assert_eq!(h.state().session.doc().profile.field_mm, [60.0, 70.0]);
    assert!(h
        .state()
        .session
        .doc()
        .fields
        .iter()
        .all(|f| f.size == [60.0, 70.0]));
    h.get_by_label("Undo").click();
    settle(&mut h);
    assert_eq!(h.state().session.doc().profile.field_mm, [70.0, 70.0]);
    // a built-in profile is selectable
    h.get_by_label("Machine").click();
    settle(&mut h);
    h.get_by_label("Small machine: 200 mm stage, 40 mm field (Y up)")
        .click();
    settle(&mut h);
    assert_ne!(h.state().session.doc().profile.field_mm, [70.0, 70.0]);
    assert!(h
        .state()
        .session
        .doc()
        .fields
        .iter()
        .all(|f| f.size == h.state().session.doc().profile.field_mm));
}

/// Runs the CLI on the demo with `algo` and seed 7, the GUI likewise; the plans must agree.
fn same_plan_as_cli(algo: &str, button: &str) {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("r.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_galvoplan"))
        .args(["plan", &demo().display().to_string(), "-o"])
        .arg(dir.path().join("x.gcode"))
        .arg("--report")
        .arg(&report)
        .args(["--seed", "7", "--algo", algo, "--motion", "step"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cli: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();

    let mut h = opened(&demo());
    section(&mut h, "Solver settings");
    set_text(&mut h, "Seed", "7");
    assert_eq!(h.state().session.doc().settings.seed, 7);
    h.get_by_label(button).click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(300));
    let plan = h.state().active_plan().unwrap();
    assert_eq!(format!("{:?}", plan.algo).to_lowercase(), algo);
    let gui: Vec<serde_json::Value> = plan
        .order
        .iter()
        .map(|s| {
            serde_json::json!({"geometry": s.geometry, "field": s.field,
                "start_vertex": s.start_vertex, "reversed": s.reversed})
        })
        .collect();
    assert_eq!(cli["order"].as_array().unwrap(), &gui);
    let idle = cli["metrics"]["idle_mm"].as_f64().unwrap();
    assert!((idle - plan.metrics.idle_mm).abs() < 1e-9);
    let fields: Vec<_> = plan
        .fields
        .iter()
        .map(|f| serde_json::json!({"id": f.id, "center": [f.center.x, f.center.y]}))
        .collect();
    let cli_fields: Vec<_> = cli["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| serde_json::json!({"id": f["id"], "center": f["center"]}))
        .collect();
    assert_eq!(cli_fields, fields);
}

#[test]
fn gui_and_cli_make_the_same_hha_plan() {
    same_plan_as_cli("hha", "Run HHA");
}

#[test]
fn gui_and_cli_make_the_same_hga_plan() {
    same_plan_as_cli("hga", "Run HGA");
}

#[test]
fn cancel_an_hga_run() {
    let mut h = opened(&demo());
    // settings under which HGA would run for minutes
    let mut s = h.state().session.doc().settings.clone();
    s.ga.stall_generations = 1_000_000;
    s.time_limit_s = Some(600.0);
    h.state_mut()
        .execute(Command::SetSettings(Box::new(s)))
        .unwrap();
    h.get_by_label("Run HGA").click();
    h.step();
    assert!(h.state().is_busy());
    // let it get into the generations, with the GUI stepping all the while
    let t0 = Instant::now();
    while !h
        .state()
        .job_message()
        .is_some_and(|m| m.contains("generation"))
    {
        assert!(
            t0.elapsed() < Duration::from_secs(120),
            "no generation reported"
        );
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    h.get_by_label("Cancel").click();
    h.step();
    let t1 = Instant::now();
    wait_idle(&mut h, Duration::from_secs(60));
    assert!(t1.elapsed() < Duration::from_secs(30));
    // a cancelled HGA keeps its best plan so far, with its convergence history
    let plan = h.state().active_plan().expect("best plan so far").clone();
    assert_eq!(plan.algo, Algo::Hga);
    assert!(plan.name.contains("stopped"), "{}", plan.name);
    assert!(!plan.history.is_empty());
    common::check_plan(h.state().session.doc(), &plan);
    // … never slower than its seed, the HHA plan of the same settings
    h.get_by_label("Run HHA").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(120));
    let hha = h.state().active_plan().unwrap().clone();
    assert_eq!(hha.algo, Algo::Hha);
    let (ta, th) = (
        plan.metrics.job_time_s.unwrap(),
        hha.metrics.job_time_s.unwrap(),
    );
    assert!(ta <= th + 1e-12, "cancelled HGA {ta} s vs HHA {th} s");
}

#[test]
fn compare_view_shows_both_plans_and_the_difference() {
    let mut h = opened(&demo());
    for label in ["Run HHA", "Run baseline"] {
        h.get_by_label(label).click();
        h.step();
        wait_idle(&mut h, Duration::from_secs(120));
    }
    h.get_by_label("Compare").click();
    settle(&mut h);
    h.get_by_label("B vs A");
    // the compare table and the active plan's table in the side panel
    assert_eq!(h.get_all_by_label("Direction changes").count(), 2);
    let plans = &h.state().session.doc().plans;
    let (a, b) = (&plans[0].metrics, &plans[1].metrics);
    let pct = (b.idle_mm - a.idle_mm) / a.idle_mm * 100.0;
    h.get_by_label(&format!("{pct:+.1} %"));
    // the faster plan's job time is marked, once (the side panel shows one plan)
    let faster = h.get_by_label("faster").rect();
    let best_s = a.job_time_s.unwrap().min(b.job_time_s.unwrap());
    assert!(h
        .get_all_by_label(&format!("{best_s:.3}"))
        .any(|n| (n.rect().center().y - faster.center().y).abs() < 4.0
            && n.rect().right() <= faster.left()));
    // one playback clock for both canvases, as long as the longer job
    let longer_s = a.job_time_s.unwrap().max(b.job_time_s.unwrap());
    h.get_by_label("Time").set_value_accesskit(1.5);
    settle(&mut h);
    assert_eq!(h.state().compare_state().playback.t_s, 1.5);
    h.get_by_label(&time_text(1.5, longer_s));
    assert_eq!(h.state().playback().t_s, 0.0, "the workbench keeps its own");
    h.get_by_label("Overlay").click();
    settle(&mut h);
    h.get_by_label("Compare (overlay)");
}

#[test]
fn project_round_trip_and_drag_and_drop() {
    let dir = tempfile::tempdir().unwrap();
    let project = dir.path().join("job.galvoplan");
    let mut h = opened(&demo());
    h.get_by_label("Run baseline").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    h.state_mut().save_project(&project).unwrap();
    let gcode = dir.path().join("job.gcode");
    h.state_mut()
        .export(galvoplan::app::files::ExportKind::Gcode, &gcode)
        .unwrap();
    assert!(std::fs::read_to_string(&gcode).unwrap().contains("G21"));

    // a fresh window; the project is dropped on it
    let mut h2 = harness(App::default());
    settle(&mut h2);
    h2.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(project.clone())));
    h2.step();
    wait_idle(&mut h2, Duration::from_secs(60));
    let (a, b) = (h.state().session.doc(), &h2.state().session.doc());
    assert_eq!(a.fields, b.fields);
    assert_eq!(a.plans, b.plans);
    assert_eq!(
        h2.state().active_plan().unwrap().name,
        "Baseline · job time · step-and-scan"
    );
    // a bad file is reported, not fatal
    let mut app = App::default();
    assert!(!app.open(&dir.path().join("missing.svg")));
    assert!(app.status().contains("missing.svg"), "{}", app.status());
}

#[test]
fn oversize_artwork_opens_with_fields_for_what_fits_and_the_remedies_as_buttons() {
    let (mut h, n) = opened_oversize();
    // fields for everything that fits (the small circle and square); only the strokes larger
    // than a field are left uncovered, told apart from what is merely uncovered
    let far = h.state().out_of_reach().len();
    assert!(far > 0 && far < n, "{far} of {n}");
    assert_eq!(h.state().uncovered().len(), far);
    assert!(!h.state().session.doc().fields.is_empty());
    assert!(h.state().solve_blocker().is_some());
    // said once, which they are, with the two remedies as buttons
    let said = h.query_all_by_label_contains("larger than the 70 × 70 mm scan field");
    assert_eq!(said.count(), 1);
    h.get_by_label_contains("(closed outline 280.00");
    assert!(!h.state().status().contains("--split-oversize"));
    assert!(h.query_by_label_contains("subpath").is_none());
    h.get_by_label("Mark on the fly");
    h.get_by_label("Split at field borders").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    assert!(h.state().session.doc().settings.split_oversize);
    assert!(h.state().session.doc().geometries.len() > n);
    assert!(h.state().uncovered().is_empty());
    // the split pieces are reported as warnings in the panel
    let w = h.state().session.doc().warnings.len();
    assert!(w > 0);
    h.get_by_label(&format!("Warnings ({w})"));
    // undo restores the unsplit geometries, with their fields for what fits
    h.get_by_label("Undo").click();
    settle(&mut h);
    assert_eq!(h.state().session.doc().geometries.len(), n);
    assert_eq!(h.state().uncovered().len(), far);
}

#[test]
fn switching_to_on_the_fly_places_fields_for_what_was_uncovered() {
    let (mut h, n) = opened_oversize();
    let far = h.state().out_of_reach().len();
    assert_eq!(h.state().uncovered().len(), far);
    section(&mut h, "Solver settings");
    h.get_by_label("Motion").click();
    settle(&mut h);
    // the switch starts a background placement: step, not run (the progress bar repaints)
    h.get_by_label("On the fly (stage moves while marking)")
        .click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    // no "Re-place automatically" press needed: only what is beyond the stage's reach stays
    let left = h.state().uncovered().len();
    assert!(left < n, "{left} of {n} still uncovered");
    assert!(
        h.state()
            .uncovered()
            .iter()
            .all(|g| h.state().out_of_reach().contains(g)),
        "{}",
        h.state().status()
    );
    assert!(!h.state().session.doc().fields.is_empty());
    // counts read as words: "1 geometry", not "1 geometries"
    assert!(h.query_by_label_contains("1 geometries").is_none());
}

#[test]
fn import_warnings_are_listed() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("w.svg");
    std::fs::write(
        &svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
<rect x="10" y="10" width="5" height="5" fill="none" stroke="black"/>
<image id="photo" x="20" y="20" width="10" height="10" href="p.png"/></svg>"#,
    )
    .unwrap();
    let h = opened(&svg);
    assert_eq!(h.state().session.doc().warnings.len(), 1);
    h.get_by_label("Warnings (1)");
    h.get_by_label_contains("photo");
}

/// Frame time of `App::ui` while a solve runs on a large instance (not run by default):
/// `GALVOPLAN_FRAME_SVG=path GALVOPLAN_FRAME_ALGO=hga cargo test --release --test gui -- --ignored --nocapture`.
#[test]
#[ignore]
fn frame_time_while_solving() {
    let path = std::env::var("GALVOPLAN_FRAME_SVG")
        .map(PathBuf::from)
        .unwrap_or_else(|_| common::root().join("../shared/bench/instances/ISW-1017.svg"));
    let algo = std::env::var("GALVOPLAN_FRAME_ALGO").unwrap_or_else(|_| "hga".into());
    let mut app = App::default();
    assert!(app.open(&path), "{}", app.status());
    let times = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
    let t = times.clone();
    let mut h = Harness::builder()
        // a canvas raster drawn in the background asks for a frame when it is done (to show
        // it): a few steps more than egui's default of 4 before the UI settles
        .with_max_steps(MAX_STEPS)
        .with_size(Vec2::new(1500.0, 950.0))
        .build_ui_state(
            move |ui, app: &mut App| {
                let t0 = Instant::now();
                app.ui(ui);
                if app.is_busy() {
                    t.borrow_mut().push(t0.elapsed().as_secs_f64() * 1e3);
                }
            },
            app,
        );
    settle(&mut h);
    let label = format!("Run {}", algo.to_uppercase());
    h.get_by_label(&label).click();
    h.step();
    assert!(h.state().is_busy(), "{}", h.state().status());
    // hover the canvas so that hover hit-testing is part of every frame
    let centre = h.get_by_label("Work area").rect().center();
    let t0 = Instant::now();
    while h.state().is_busy() {
        h.hover_at(centre + Vec2::new((t0.elapsed().as_secs_f32() * 3.0).sin() * 50.0, 0.0));
        h.step();
        std::thread::sleep(Duration::from_millis(16));
    }
    let mut v = times.borrow().clone();
    v.sort_by(f64::total_cmp);
    let median = v[v.len() / 2];
    let p95 = v[(v.len() * 95 / 100).min(v.len() - 1)];
    let max = v[v.len() - 1];
    println!(
        "{} on {}: solve {:.1} s, {} frames while solving, App::ui median {median:.2} ms, p95 {p95:.2} ms, max {max:.2} ms; plan: {}",
        label,
        path.display(),
        t0.elapsed().as_secs_f64(),
        v.len(),
        h.state().status()
    );
}

/// Runs `button`'s solver to the end; returns the new plan.
fn solve(h: &mut Harness<'_, App>, button: &str) -> galvoplan::document::Plan {
    let n = h.state().session.doc().plans.len();
    h.get_by_label(button).click();
    h.step();
    wait_idle(h, Duration::from_secs(120));
    assert_eq!(
        h.state().session.doc().plans.len(),
        n + 1,
        "{}",
        h.state().status()
    );
    h.state().active_plan().unwrap().clone()
}

#[test]
fn the_cost_switch_decides_what_the_solve_minimises() {
    let mut h = opened(&demo());
    assert_eq!(h.state().session.doc().settings.cost_model, CostModel::Time);
    section(&mut h, "Solver settings");
    h.get_by_label("Cost model").hover();
    settle(&mut h);
    h.get_by_label_contains("What the ordering minimises");
    let by_time = solve(&mut h, "Run HHA");
    h.get_by_label("Cost model").click();
    settle(&mut h);
    h.get_by_label("Idle travel distance").click();
    settle(&mut h);
    assert_eq!(
        h.state().session.doc().settings.cost_model,
        CostModel::Distance
    );
    let by_distance = solve(&mut h, "Run HHA");
    assert_eq!(by_distance.name, "HHA · idle distance · step-and-scan");
    assert_ne!(by_time.order, by_distance.order);
    // each plan is best at what it minimised (demo: 9.116 s / 1848 mm against 9.142 s / 1704 mm)
    let (t_time, t_dist) = (
        by_time.metrics.job_time_s.unwrap(),
        by_distance.metrics.job_time_s.unwrap(),
    );
    assert!(t_time < t_dist, "{t_time} s !< {t_dist} s");
    assert!(by_distance.metrics.idle_mm < by_time.metrics.idle_mm);
    // the change is one undoable settings step
    h.get_by_label("Undo").click();
    settle(&mut h);
    assert_eq!(h.state().session.doc().settings.cost_model, CostModel::Time);
}

#[test]
fn run_as_is_keeps_the_document_order() {
    let mut h = opened(&demo());
    let plan = solve(&mut h, "Run as-is");
    assert_eq!(plan.algo, Algo::AsIs);
    assert_eq!(plan.name, "As-is · job time · step-and-scan");
    common::check_plan(h.state().session.doc(), &plan);
    let hha = solve(&mut h, "Run HHA");
    assert!(hha.metrics.job_time_s.unwrap() < plan.metrics.job_time_s.unwrap());
}

#[test]
fn playback_scrubs_plays_pauses_and_rewinds() {
    let mut h = opened(&demo());
    h.get_by_label("No plan yet: run a solver to play the job back.");
    let plan = solve(&mut h, "Run HHA");
    let l = h.state().toolpath(0).unwrap().unwrap().clone();
    let end_s = l.duration_s();
    assert!((end_s - plan.metrics.job_time_s.unwrap()).abs() < 1e-9);
    h.get_by_label(&time_text(0.0, end_s));
    assert_eq!(h.state().playback().shown_t_s(), None);
    // scrub to the middle of the middle stroke: the machine is marking it
    let n = l.toolpath.strokes.len();
    let (s0, s1) = l.mark_s[n / 2];
    let t_s = (s0 + s1) / 2.0;
    h.get_by_label("Time").set_value_accesskit(t_s);
    settle(&mut h);
    assert!((h.state().playback().t_s - t_s).abs() < 1e-9);
    assert_eq!(
        h.state().playback().shown_t_s(),
        Some(h.state().playback().t_s)
    );
    h.get_by_label(&time_text(t_s, end_s));
    let words = state_text(&l, t_s);
    assert!(
        words.starts_with(&format!("marking stroke {} of {n};", n / 2 + 1))
            && words.ends_with("laser on"),
        "{words}"
    );
    h.get_by_label(&words);
    // the strip and the canvas fit the window
    let canvas = h.get_by_label("Work area").rect();
    assert!(
        canvas.right() <= 1500.0 && canvas.width() > 500.0,
        "{canvas:?}"
    );
    let (play, slider) = (h.get_by_label("Play").rect(), h.get_by_label("Time").rect());
    // play: each frame (0.25 s, counted as at most 0.1 s) advances 0.1 s at 1× (auto, short job)
    h.get_by_label("Play").click();
    h.step();
    assert!(h.state().playback().playing);
    h.step();
    // nothing moved under the pointer: Pause where Play was, the slider in place
    assert_eq!(h.get_by_label("Pause").rect().min, play.min);
    assert_eq!(h.get_by_label("Time").rect(), slider);
    let t0_s = h.state().playback().t_s;
    for _ in 0..5 {
        h.step();
    }
    let t1_s = h.state().playback().t_s;
    assert!((t1_s - t0_s - 0.5).abs() < 1e-9, "{t0_s} -> {t1_s}");
    h.get_by_label(&time_text(t1_s, end_s));
    assert!(
        h.query_by_label(&words).is_none(),
        "the state shown moved on"
    );
    // pause: time stands
    h.get_by_label("Pause").click();
    settle(&mut h);
    let t2_s = h.state().playback().t_s;
    h.step();
    h.step();
    assert_eq!(h.state().playback().t_s, t2_s);
    // 100×: plays to the end of the job and stops there
    h.get_by_label("Speed").click();
    settle(&mut h);
    h.get_by_label("100×").click();
    settle(&mut h);
    h.get_by_label("Play").click();
    for _ in 0..20 {
        h.step();
    }
    assert!(!h.state().playback().playing);
    assert_eq!(h.state().playback().t_s, end_s);
    h.get_by_label_contains(&format!("job done: {n} strokes marked"));
    // rewind: back to the planned path
    h.get_by_label("Rewind").click();
    settle(&mut h);
    assert_eq!(h.state().playback().t_s, 0.0);
    assert_eq!(h.state().playback().shown_t_s(), None);
    assert_eq!(h.state().playback().speed_x, Some(100.0), "the speed stays");
}

/// Switches the motion mode through the settings panel's combo box.
fn set_motion(h: &mut Harness<'_, App>, option: &str) {
    section(h, "Solver settings");
    h.get_by_label("Motion").click();
    settle(h);
    h.get_by_label(option).click();
    settle(h);
}

#[test]
fn the_motion_switch_plans_on_the_fly() {
    let mut h = opened(&demo());
    assert_eq!(h.state().session.doc().settings.motion, MotionMode::Step);
    section(&mut h, "Solver settings");
    h.get_by_label("Motion").hover();
    settle(&mut h);
    h.get_by_label_contains("How the machine moves while it marks");
    let step = solve(&mut h, "Run HHA");
    assert!(!h.state().toolpath(0).unwrap().unwrap().on_the_fly());
    set_motion(&mut h, "On the fly (stage moves while marking)");
    assert_eq!(
        h.state().session.doc().settings.motion,
        MotionMode::OnTheFly
    );
    // the step plan keeps the motion it was planned for
    let kept = h.state().toolpath(0).unwrap().unwrap().clone();
    assert!(!kept.on_the_fly());
    assert_eq!(Some(kept.duration_s()), step.metrics.job_time_s);
    // ... and says that the motion setting changed since
    h.get_by_label_contains("is stale: motion step-and-scan → on the fly");
    // the solve uses the setting: a route, and another job time than the step plan's
    let otf = solve(&mut h, "Run HHA");
    let l = h.state().toolpath(1).unwrap().unwrap().clone();
    assert!(l.on_the_fly());
    let (t_step, t_otf) = (
        step.metrics.job_time_s.unwrap(),
        otf.metrics.job_time_s.unwrap(),
    );
    assert!(
        (t_otf - t_step).abs() > 0.01 * t_step,
        "{t_otf} s vs {t_step} s"
    );
    assert_eq!(Some(l.duration_s()), otf.metrics.job_time_s);
    // the compare view puts both side by side, each with the job time of its solve
    h.get_by_label("Compare").click();
    settle(&mut h);
    for t_s in [t_step, t_otf] {
        let text = format!("{t_s:.3}");
        assert!(h.query_all_by_label(&text).count() >= 1, "{text}");
    }
    // one undoable settings step back to step-and-scan
    h.get_by_label("Workbench").click();
    settle(&mut h);
    h.get_by_label("Undo").click();
    settle(&mut h);
    assert_eq!(h.state().session.doc().settings.motion, MotionMode::Step);
    // the on-the-fly plan stays on the fly
    assert!(h.state().toolpath(1).unwrap().unwrap().on_the_fly());
}

#[test]
fn motion_plots_show_an_on_the_fly_plan() {
    let mut h = opened(&demo());
    set_motion(&mut h, "On the fly (stage moves while marking)");
    assert!(h.query_by_label_contains("Scanner offset").is_none());
    solve(&mut h, "Run HHA");
    let l = h.state().toolpath(0).unwrap().unwrap().clone();
    let s = l.motion.as_ref().expect("motion samples");
    assert!(
        s.t_s.len() > 100 && s.t_s.len() <= 20_001,
        "{}",
        s.t_s.len()
    );
    let reach_mm = 35.0 - h.state().session.doc().profile.otf_margin_mm;
    assert!(
        s.peak_offset_mm() <= reach_mm + 1e-6,
        "{}",
        s.peak_offset_mm()
    );
    assert!(s.peak_speed_mm_s() > 0.0);
    // the metrics speak of the stage's ride in a unit an operator reads: mean acceleration
    let plan = h.state().active_plan().unwrap().clone();
    let f = plan.metrics.motion.unwrap();
    let mean = f.stage_speed_variation_mm_s / plan.metrics.job_time_s.unwrap();
    h.get_by_label("Stage acceleration (mm/s²)");
    h.get_by_label(&format!("{mean:.0}"));
    assert!(h.query_by_label_contains("Stage speed variation").is_none());
    h.get_by_label_contains("Scanner offset (tool - stage), mm");
    h.get_by_label_contains("Stage speed, mm/s");
    // they fit under the canvas
    let canvas = h.get_by_label("Work area").rect();
    let speed = h.get_by_label_contains("Stage speed, mm/s").rect();
    assert!(
        canvas.bottom() < speed.top() && speed.bottom() < 950.0,
        "{speed:?}"
    );
    // hidden with their header, and gone for a step-and-scan toolpath
    h.get_by_label_contains("Motion plots").click();
    settle(&mut h);
    assert!(h.query_by_label_contains("Scanner offset").is_none());
    h.get_by_label_contains("Motion plots").click();
    settle(&mut h);
    h.get_by_label_contains("Scanner offset");
    // the setting does not change a plan's motion; a step-and-scan plan has no plots
    set_motion(&mut h, "Step-and-scan");
    h.get_by_label_contains("Scanner offset");
    solve(&mut h, "Run HHA");
    assert!(!h.state().toolpath(1).unwrap().unwrap().on_the_fly());
    assert!(h.query_by_label_contains("Scanner offset").is_none());
    assert!(h.query_by_label_contains("Motion plots").is_none());
}

#[test]
fn the_stage_route_switch_plans_seed001_routes() {
    use galvoplan::document::StageRouteKind;
    let mut h = opened(&demo());
    set_motion(&mut h, "On the fly (stage moves while marking)");
    h.get_by_label("Stage route").click();
    settle(&mut h);
    h.get_by_label("Follow a simplified path of the marks")
        .click();
    settle(&mut h);
    assert_eq!(
        h.state().session.doc().settings.stage_route,
        StageRouteKind::Lsa
    );
    let plan = solve(&mut h, "Run HHA");
    assert!(plan.stage_route.is_some());
    assert!(h.state().toolpath(0).unwrap().unwrap().on_the_fly());
}

fn two_layers() -> PathBuf {
    common::root().join("assets/examples/two-layers.svg")
}

/// The `n`-th widget labelled `label` (several layers have one each).
fn nth_by_label<'a>(h: &'a Harness<'_, App>, label: &'a str, n: usize) -> egui_kittest::Node<'a> {
    h.get_all_by_label(label).nth(n).expect(label)
}

#[test]
fn hatch_settings_in_the_layers_panel_rehatch_the_document() {
    let mut h = opened(&two_layers());
    let names: Vec<String> = h
        .state()
        .session
        .doc()
        .layers
        .iter()
        .map(|l| l.name.clone())
        .collect();
    assert_eq!(names, ["outline", "fill"]);
    let outlines = h.state().session.doc().geometries.len();
    h.get_by_label("Layers (2)");
    // choose a hatch for the second layer: a background job hatches and places fields again
    nth_by_label(&h, "Hatch", 1).click();
    settle(&mut h);
    h.get_by_label("zigzag").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    let doc = h.state().session.doc();
    let hatch = doc.layers[1].pen.hatch.clone().expect("a hatch");
    assert_eq!(hatch.style, galvoplan::hatch::HatchStyle::Zigzag);
    let hatched = doc.geometries.len();
    assert!(hatched > outlines, "{hatched} vs {outlines}");
    assert!(doc
        .geometries
        .iter()
        .filter(|g| galvoplan::hatch::is_hatch_output(g))
        .all(|g| g.layer == "fill"));
    assert!(h.state().uncovered().is_empty());
    // a finer spacing hatches again with more strokes
    enter_nth(&mut h, "Hatch spacing (mm)", 0, "0.25");
    wait_idle(&mut h, Duration::from_secs(60));
    let finer = h.state().session.doc().geometries.len();
    let len = |doc: &galvoplan::document::Document| -> f64 {
        doc.geometries.iter().map(|g| g.length_mm()).sum()
    };
    assert_eq!(
        h.state().session.doc().layers[1]
            .pen
            .hatch
            .as_ref()
            .unwrap()
            .spacing_mm,
        0.25
    );
    assert!(finer >= hatched);
    let fine_mm = len(h.state().session.doc());
    // undo goes back to the coarser hatch, then to outlines only
    h.key_press_modifiers(ctrl(), Key::Z);
    settle(&mut h);
    assert!(len(h.state().session.doc()) < fine_mm);
    assert_eq!(h.state().session.doc().geometries.len(), hatched);
    h.key_press_modifiers(ctrl(), Key::Z);
    settle(&mut h);
    assert_eq!(h.state().session.doc().geometries.len(), outlines);
    assert!(h.state().session.doc().layers[1].pen.hatch.is_none());
}

#[test]
fn a_disabled_layer_is_left_out_and_pens_change_at_once() {
    let mut h = opened(&two_layers());
    let all = h.state().session.doc().geometries.len();
    let fill = h
        .state()
        .session
        .doc()
        .geometries
        .iter()
        .filter(|g| g.layer == "fill")
        .count();
    h.get_by_label("fill").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    assert!(!h.state().session.doc().layers[1].pen.enabled);
    assert_eq!(h.state().session.doc().geometries.len(), all - fill);
    // a speed is a pen change only: no job, the geometries stay
    enter_nth(&mut h, "Mark speed (mm/s)", 0, "750");
    settle(&mut h);
    assert!(!h.state().is_busy());
    assert_eq!(
        h.state().session.doc().layers[0].pen.mark_speed_mm_s,
        Some(750.0)
    );
    assert_eq!(h.state().session.doc().geometries.len(), all - fill);
}

#[test]
fn a_rejected_pen_value_shows_a_worded_error() {
    let mut h = opened(&two_layers());
    let before = h.state().session.doc().layers.clone();
    let passes = h.get_all_by_label("Passes").count();
    assert_eq!(passes, 2);
    // the second layer's passes
    enter_nth(&mut h, "Passes", 1, "0");
    settle(&mut h);
    h.get_by_label("Layer 'fill': Passes must be a whole number from 1 to 100, not 0");
    assert_eq!(h.state().session.doc().layers, before);
    enter_nth(&mut h, "Mark speed (mm/s)", 0, "fast");
    settle(&mut h);
    h.get_by_label("Layer 'outline': Mark speed (mm/s) must be a number, not 'fast'");
    assert_eq!(h.state().session.doc().layers, before);
}

#[test]
fn without_a_file_dialog_a_path_field_is_offered() {
    let mut app = App::default();
    app.set_native_dialogs(false);
    let mut h = harness(app);
    settle(&mut h);
    h.get_by_label("Open…").click();
    settle(&mut h);
    h.get_by_label_contains("No file dialog can be shown");
    enter_nth(&mut h, "File path", 0, &demo().display().to_string());
    wait_idle(&mut h, Duration::from_secs(60));
    assert!(h.state().prompt().is_none());
    assert_eq!(h.state().session.doc().geometries.len(), 122);
    // Ctrl+S asks for the project's path the same way
    h.key_press_modifiers(ctrl(), Key::S);
    settle(&mut h);
    assert!(matches!(
        h.state().prompt(),
        Some(galvoplan::app::Prompt::Path {
            action: galvoplan::app::PathAction::SaveProject,
            ..
        })
    ));
    let dir = tempfile::tempdir().unwrap();
    let project = dir.path().join("demo.galvoplan");
    enter_nth(&mut h, "File path", 0, &project.display().to_string());
    settle(&mut h);
    assert!(project.exists(), "{}", h.state().status());
    assert!(!h.state().has_unsaved_changes());
}

#[test]
fn quitting_after_an_edit_asks_about_unsaved_changes() {
    let mut h = opened(&demo());
    assert!(!h.state().has_unsaved_changes());
    let id = h.state().session.doc().fields[0].id;
    h.state_mut()
        .execute(Command::SetLocked { id, locked: true })
        .unwrap();
    settle(&mut h);
    assert!(h.state().has_unsaved_changes());
    h.key_press_modifiers(ctrl(), Key::Q);
    settle(&mut h);
    h.get_by_label("Unsaved changes");
    h.get_by_label("Cancel").click();
    settle(&mut h);
    assert!(h.state().prompt().is_none());
    assert!(h.query_by_label("Unsaved changes").is_none());
    // opening another file asks too
    h.key_press_modifiers(ctrl(), Key::O);
    settle(&mut h);
    h.get_by_label("Unsaved changes");
    h.get_by_label("Discard changes").click();
    settle(&mut h);
    assert!(!matches!(
        h.state().prompt(),
        Some(galvoplan::app::Prompt::Unsaved(_))
    ));
}

#[test]
fn exporting_a_stale_plan_asks_first() {
    let mut h = opened(&demo());
    h.get_by_label("Run HHA").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(120));
    let id = h.state().session.doc().fields[0].id;
    let c = h.state().session.doc().fields[0].center;
    h.state_mut()
        .execute(Command::MoveField {
            id,
            center: galvoplan::geom::Pt::new(c.x + 1.0, c.y),
        })
        .unwrap();
    settle(&mut h);
    h.key_press_modifiers(ctrl(), Key::E);
    settle(&mut h);
    h.get_by_label("The plan shown is stale");
    h.get_by_label("• the scan fields changed");
}

#[test]
fn fields_are_numbered_from_one_in_placement_then_visiting_order() {
    use galvoplan::app::field_number;
    let mut h = opened(&demo());
    let fields = h.state().session.doc().fields.clone();
    for (k, f) in fields.iter().enumerate() {
        assert_eq!(field_number(&fields, None, f.id), k + 1);
    }
    h.get_by_label("Run HHA").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(120));
    let plan = h.state().active_plan().unwrap().clone();
    for (k, f) in plan.fields.iter().enumerate() {
        assert_eq!(field_number(&fields, Some(&plan.fields), f.id), k + 1);
    }
    // no debug timings in the status bar unless the View option asks for them
    assert!(h.query_by_label_contains(" ms (max ").is_none());
}

#[test]
fn a_dropped_dxf_opens_with_its_layers() {
    let mut h = harness(App::default());
    settle(&mut h);
    let path = common::root().join("tests/data/dxf/entities-inch.dxf");
    h.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(path)));
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    let doc = h.state().session.doc();
    assert_eq!(doc.geometries.len(), 26, "{}", h.state().status());
    assert!(doc.geometries.iter().any(|g| g.source.layer == "CUT"));
    assert!(!doc.fields.is_empty());
}

/// two-layers.svg solved with HHA, native dialogs off (file actions ask for a path).
fn two_layers_solved() -> Harness<'static, App> {
    let mut app = App::default();
    app.set_native_dialogs(false);
    assert!(app.open(&two_layers()), "{}", app.status());
    let mut h = harness(app);
    settle(&mut h);
    solve(&mut h, "Run HHA");
    h
}

#[test]
fn a_pen_edit_makes_the_plan_stale_and_re_solve_and_export_writes_the_new_feed() {
    let mut h = two_layers_solved();
    assert!(h.state().plan_staleness(0).is_empty());
    // a pen that now sets what its profile gave is no change
    let profile_speed = h.state().session.doc().profile.scanner.mark_speed_mm_s;
    enter_nth(&mut h, "Mark speed (mm/s)", 1, &profile_speed.to_string());
    settle(&mut h);
    assert!(h.state().plan_staleness(0).is_empty());
    enter_nth(&mut h, "Mark speed (mm/s)", 1, "300");
    settle(&mut h);
    // stale, with the reason in words (the speed the plan had, not "unset"), in the plan list
    // and under the metrics
    let why = format!("fill: mark speed {profile_speed} → 300 mm/s");
    assert_eq!(h.state().plan_staleness(0), [why.as_str()]);
    h.get_by_label("stale");
    h.get_by_label_contains(&format!(
        "HHA · job time · step-and-scan is stale: {why} since it was made"
    ));
    // export asks; re-solving is the default answer and writes the new feed
    h.key_press_modifiers(ctrl(), Key::E);
    settle(&mut h);
    h.get_by_label("The plan shown is stale");
    h.get_by_label(&format!("• {why}"));
    h.get_by_label("Re-solve and export").click();
    settle(&mut h);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("job.gcode");
    enter_nth(&mut h, "File path", 0, &out.display().to_string());
    wait_idle(&mut h, Duration::from_secs(120));
    wait_idle(&mut h, Duration::from_secs(120));
    let g = std::fs::read_to_string(&out).unwrap_or_else(|e| panic!("{e}: {}", h.state().status()));
    assert!(g.contains(" F18000"), "no feed of 300 mm/s in the G-code");
    assert_eq!(h.state().session.doc().plans.len(), 2);
    assert!(h.state().plan_staleness(1).is_empty());
    assert!(h.state().plan_staleness(0).len() == 1);
    let job_s = h.state().session.doc().plans[1].metrics.job_time_s.unwrap();
    assert!(g.contains(&format!("job time {job_s:.3} s")));
}

#[test]
fn a_profile_edit_makes_the_headline_stale() {
    let mut h = two_layers_solved();
    section(&mut h, "Machine profile");
    set_text(&mut h, "Base X max velocity (mm/s)", "100");
    settle(&mut h);
    assert_eq!(
        h.state().session.doc().profile.axis_x.max_velocity_mm_s,
        100.0
    );
    let why = h.state().plan_staleness(0).to_vec();
    assert_eq!(why.len(), 1, "{why:?}");
    assert!(why[0].starts_with("base X max velocity ") && why[0].ends_with("→ 100 mm/s"));
    h.get_by_label_contains("HHA · job time · step-and-scan is stale: base X max velocity");
    h.get_by_label("stale");
    // the plan keeps the figures and the toolpath of its own profile
    let plan = h.state().session.doc().plans[0].clone();
    let l = h.state().toolpath(0).unwrap().unwrap().clone();
    assert_eq!(Some(l.duration_s()), plan.metrics.job_time_s);
}

#[test]
fn exports_never_overwrite_the_artwork() {
    let mut h = two_layers_solved();
    let source = two_layers();
    let before = std::fs::read(&source).unwrap();
    h.state_mut().request_export(
        galvoplan::app::files::ExportKind::Preview,
        &egui::Context::default(),
    );
    settle(&mut h);
    let Some(galvoplan::app::Prompt::Path { text, .. }) = h.state().prompt().cloned() else {
        panic!("no path field: {:?}", h.state().prompt());
    };
    assert!(text.ends_with("two-layers.preview.svg"), "{text}");
    // typing the artwork's own path is refused and the file is unchanged
    h.get_by_label("Cancel").click();
    settle(&mut h);
    let e = h
        .state_mut()
        .export(galvoplan::app::files::ExportKind::Preview, &source)
        .unwrap_err();
    assert!(e.contains("refusing"), "{e}");
    h.state_mut().export_in_background(
        galvoplan::app::files::ExportKind::Preview,
        &source,
        &egui::Context::default(),
    );
    settle(&mut h);
    assert!(
        h.state().status().contains("refusing"),
        "{}",
        h.state().status()
    );
    assert_eq!(std::fs::read(&source).unwrap(), before);
}

#[test]
fn a_hatch_edit_keeps_the_plans_and_marks_them_stale() {
    let mut h = two_layers_solved();
    nth_by_label(&h, "Hatch", 1).click();
    settle(&mut h);
    h.get_by_label("zigzag").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    assert_eq!(h.state().session.doc().plans.len(), 1);
    let why = h.state().plan_staleness(0);
    assert!(
        why.iter().any(|w| w.starts_with("the geometries changed")),
        "{why:?}"
    );
    assert!(
        why.iter()
            .any(|w| w.starts_with("fill: hatch none → zigzag")),
        "{why:?}"
    );
    // the plan is still drawn and exported on the geometries it was planned on
    let plan = h.state().session.doc().plans[0].clone();
    assert_eq!(
        Some(h.state().toolpath(0).unwrap().unwrap().duration_s()),
        plan.metrics.job_time_s
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("as-planned.gcode");
    h.state_mut()
        .export(galvoplan::app::files::ExportKind::Gcode, &out)
        .unwrap();
    assert!(std::fs::read_to_string(&out).unwrap().contains(&format!(
        "job time {:.3} s",
        plan.metrics.job_time_s.unwrap()
    )));
}

#[test]
fn the_status_of_a_delete_names_the_field_as_the_canvas_does() {
    use galvoplan::app::field_number;
    let mut h = opened(&demo());
    solve(&mut h, "Run HHA");
    let fields = h.state().session.doc().fields.clone();
    let visiting = h.state().active_plan().unwrap().fields.clone();
    // a field whose visiting number is not its placement number
    let f = fields
        .iter()
        .find(|f| field_number(&fields, Some(&visiting), f.id) != field_number(&fields, None, f.id))
        .expect("the plan visits the fields in another order than placed");
    let label = field_number(&fields, Some(&visiting), f.id);
    assert_eq!(h.state().field_label(f.id), label);
    h.state_mut()
        .execute(Command::DeleteField { id: f.id })
        .unwrap();
    settle(&mut h);
    assert!(
        h.state()
            .status()
            .starts_with(&format!("delete field {label}:")),
        "{}",
        h.state().status()
    );
    assert_eq!(h.state().session.doc().plans.len(), 1);
}

#[test]
fn stage_routes_and_settings_are_offered_in_an_operators_words() {
    let mut h = opened(&demo());
    set_motion(&mut h, "On the fly (stage moves while marking)");
    h.get_by_label("Stage route").click();
    settle(&mut h);
    for option in [
        "Tracked route (default)",
        "Follow a simplified path of the marks",
        "Genetic algorithm route (slow)",
    ] {
        h.get_by_label(option);
    }
    // the research names are gone from the words; the command line's names are in the hover
    assert!(h.query_by_label_contains("seed 001").is_none());
    assert!(h.query_by_label_contains("LSA)").is_none());
    h.get_by_label("Follow a simplified path of the marks")
        .hover();
    settle(&mut h);
    h.get_by_label_contains("--stage-route lsa");
    h.get_by_label("Genetic algorithm route (slow)").click();
    settle(&mut h);
    assert_eq!(
        h.state().session.doc().settings.stage_route,
        galvoplan::document::StageRouteKind::CetspGa
    );
    // the other choices: words, with the command line in the hover
    h.get_by_label("Field placement").click();
    settle(&mut h);
    h.get_by_label("Fewest fields (automatic)");
    h.get_by_label("Quick greedy cover").hover();
    settle(&mut h);
    h.get_by_label_contains("--fields greedy");
    h.key_press(Key::Escape);
    settle(&mut h);
    h.get_by_label("Start points").click();
    settle(&mut h);
    h.get_by_label("Best start points (exact)");
    h.get_by_label("Quick start points (estimate)");
    assert!(h.query_by_label_contains("(seed 000)").is_none());
}

#[test]
fn layers_named_after_their_colour_show_a_colour_word() {
    let mut h = opened(&demo());
    // the demo's layers are its stroke colours
    let names: Vec<String> = h
        .state()
        .session
        .doc()
        .layers
        .iter()
        .map(|l| l.name.clone())
        .collect();
    assert!(names.iter().any(|n| n == "#1f2937"), "{names:?}");
    h.get_by_label("dark grey (#1f2937)");
    h.get_by_label("red (#b91c1c)");
    h.get_by_label("blue (#1d4ed8)");
    // a rejected value names the layer by its label ...
    let k = names.iter().position(|n| n == "#1f2937").unwrap();
    enter_nth(&mut h, "Mark speed (mm/s)", k, "fast");
    settle(&mut h);
    h.get_by_label("Layer 'dark grey (#1f2937)': Mark speed (mm/s) must be a number, not 'fast'");
    // ... and a valid edit leaves the document's name (what pens files match) as it was
    enter_nth(&mut h, "Mark speed (mm/s)", k, "400");
    settle(&mut h);
    let layer = &h.state().session.doc().layers[k];
    assert_eq!(layer.name, "#1f2937");
    assert_eq!(layer.pen.mark_speed_mm_s, Some(400.0));
    assert!(h.query_by_label_contains("must be a number").is_none());
}

#[test]
fn a_rejected_profile_or_settings_value_clears_after_a_valid_edit_of_another() {
    let mut h = opened(&demo());
    section(&mut h, "Machine profile");
    set_text(&mut h, "Field width (mm)", "-5");
    h.get_by_label("Field width (mm) must be a positive number, not -5");
    assert!(h
        .query_by_label("Values apply on Enter or when leaving a field.")
        .is_none());
    // a valid edit of another value: applied, the rejected one is no longer shown (nor red:
    // its field holds the value in force again) and the hint is back
    set_text(&mut h, "Stroke X (mm)", "290");
    assert_eq!(h.state().session.doc().profile.stroke_mm[0], 290.0);
    assert!(h
        .query_by_label_contains("must be a positive number")
        .is_none());
    assert_eq!(
        h.get_by_label("Field width (mm)").value().as_deref(),
        Some("70")
    );
    h.get_by_label("Values apply on Enter or when leaving a field.");
    // likewise when the other value is valid but unchanged
    set_text(&mut h, "Field width (mm)", "abc");
    h.get_by_label_contains("must be a number, not 'abc'");
    set_text(&mut h, "Stroke Y (mm)", "300");
    assert!(h.query_by_label_contains("must be a number").is_none());
    assert_eq!(
        h.get_by_label("Field width (mm)").value().as_deref(),
        Some("70")
    );
    // the name takes its whole width and commits on Enter like the numbers
    set_text(&mut h, "Name", "bench machine");
    assert_eq!(h.state().session.doc().profile.name, "bench machine");
    // the settings form behaves the same
    section(&mut h, "Solver settings");
    set_text(&mut h, "GA mutation rate", "1.5");
    h.get_by_label("GA mutation rate must be between 0 and 1, not 1.5");
    set_text(&mut h, "Seed", "3");
    assert_eq!(h.state().session.doc().settings.seed, 3);
    assert!(h.query_by_label_contains("must be between").is_none());
    assert_eq!(
        h.get_by_label("GA mutation rate").value().as_deref(),
        Some("0.3")
    );
}

#[test]
fn the_built_in_picker_names_the_profile_shown() {
    let mut h = opened(&demo());
    section(&mut h, "Machine profile");
    let picked = |h: &Harness<'_, App>| h.get_by_label("Machine").value();
    let reference = "Reference machine: 300 mm stage, 70 mm field";
    assert_eq!(picked(&h).as_deref(), Some(reference));
    set_text(&mut h, "Stroke X (mm)", "290");
    // the reference machine's name, other values: an edited reference machine
    assert_eq!(
        picked(&h).as_deref(),
        Some(format!("{reference}, edited").as_str())
    );
    set_text(&mut h, "Name", "bench machine");
    assert_eq!(
        picked(&h).as_deref(),
        Some("bench machine (loaded or edited)")
    );
    h.get_by_label("Machine").click();
    settle(&mut h);
    let small = galvoplan::document::MachineProfile::builtin("small-field").unwrap();
    h.get_by_label(&small.name).click();
    settle(&mut h);
    assert_eq!(picked(&h).as_deref(), Some(small.name.as_str()));
    // no internal key is shown
    assert!(h.query_by_label_contains("seed000").is_none());
}

#[test]
fn an_on_the_fly_region_larger_than_the_scan_field_is_called_a_region() {
    // one circle larger than the field: marked whole on the fly (0.493 s), faster than cut
    // (0.495 s), so the solve keeps one region
    let dir = tempfile::tempdir().unwrap();
    let circle = dir.path().join("circle.svg");
    std::fs::write(
        &circle,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="300mm" height="300mm" viewBox="0 0 300 300"><circle cx="150" cy="150" r="60" stroke="black" fill="none"/></svg>"#,
    )
    .unwrap();
    let mut h = opened(&circle);
    section(&mut h, "Solver settings");
    h.get_by_label("Motion").click();
    settle(&mut h);
    h.get_by_label("On the fly (stage moves while marking)")
        .click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    let field_mm = h.state().session.doc().profile.field_mm;
    let region = h
        .state()
        .session
        .doc()
        .fields
        .iter()
        .find(|f| f.size[0] > field_mm[0])
        .expect("one region holds the shapes larger than the scan field")
        .clone();
    let n = h.state().field_label(region.id);
    assert_eq!(h.state().field_name(region.id), format!("region {n}"));
    // counted and named as a region in the window's words
    assert_eq!(h.state().session.doc().fields.len(), 1);
    h.get_by_label_contains("1 region ·");
    assert!(h.query_by_label_contains("1 field").is_none());
    // selected: its heading and what a region is
    let at = h.state().field_screen_pos(region.id).unwrap();
    h.hover_at(at);
    h.step();
    for pressed in [true, false] {
        h.event(Event::PointerButton {
            pos: at,
            button: PointerButton::Primary,
            pressed,
            modifiers: Modifiers::NONE,
        });
    }
    settle(&mut h);
    assert_eq!(h.state().selected_field(), Some(region.id));
    h.get_by_label(&format!("Region {n}"));
    h.get_by_label_contains("Larger than the 70 × 70 mm scan field");
    // the undo menu and status say "region" too
    h.key_press(Key::Delete);
    settle(&mut h);
    assert!(
        h.state()
            .status()
            .starts_with(&format!("delete region {n}")),
        "{}",
        h.state().status()
    );
}

#[test]
fn uncovered_geometries_are_told_apart_from_every_layer_colour() {
    use galvoplan::document::parse_colour;
    let mut h = opened(&two_layers());
    // uncover some geometries: delete a field
    let id = h.state().session.doc().fields[0].id;
    h.state_mut().execute(Command::DeleteField { id }).unwrap();
    settle(&mut h);
    assert!(!h.state().uncovered().is_empty());
    // the side panel names the highlight (as the canvas's caption does), not a layer's colour
    h.get_by_label_contains("(magenta halo on the canvas)");
    assert!(h.query_by_label_contains("(red)").is_none());
    // its colour is none of the layers' (the palette's red here, the demo's stroke colours)
    let uncovered = galvoplan::app::uncovered_rgb();
    let demo = opened(&demo());
    for l in h
        .state()
        .session
        .doc()
        .layers
        .iter()
        .chain(&demo.state().session.doc().layers)
    {
        let rgb = l.pen.colour.as_deref().and_then(parse_colour).unwrap();
        assert_ne!(rgb, uncovered, "layer {}", l.name);
    }
}

/// A harness at the window's smallest size.
fn small(path: &Path) -> Harness<'static, App> {
    let mut app = App::default();
    assert!(app.open(path), "{}", app.status());
    let mut h = Harness::builder()
        // a canvas raster drawn in the background asks for a frame when it is done (to show
        // it): a few steps more than egui's default of 4 before the UI settles
        .with_max_steps(MAX_STEPS)
        .with_size(Vec2::new(900.0, 600.0))
        .build_ui_state(|ui, app: &mut App| app.ui(ui), app);
    settle(&mut h);
    h
}

#[test]
fn nothing_is_cut_off_on_the_smallest_window() {
    let mut h = small(&two_layers());
    let side = |h: &Harness<'_, App>| h.get_by_label("Document").rect().left();
    let canvas_left = |h: &Harness<'_, App>| h.get_by_label("Work area").rect().left();
    // layers panel: every value's edit beside the canvas, not under it
    for label in ["Power", "Pulse frequency (kHz)", "Mark speed (mm/s)"] {
        for node in h.get_all_by_label(label) {
            assert!(node.rect().right() <= canvas_left(&h), "{label}");
        }
    }
    // the profile's name wraps within the panel
    section(&mut h, "Machine profile");
    let name = h.get_all_by_label("Name").last().unwrap().rect();
    assert!(name.right() <= canvas_left(&h), "{name:?}");
    assert!(name.height() > 30.0, "the long name wraps: {name:?}");
    // on the fly: the plots' titles and the time beside the playback controls stay in view
    set_motion(&mut h, "On the fly (stage moves while marking)");
    solve(&mut h, "Run HHA");
    for title in ["Scanner offset", "Stage speed, mm/s", "t = 0.00 s of"] {
        let r = h.get_by_label_contains(title).rect();
        assert!(
            r.right() <= side(&h) + 0.5,
            "{title}: {r:?} side {}",
            side(&h)
        );
    }
    solve(&mut h, "Run as-is");
    h.get_by_label("Compare").click();
    settle(&mut h);
    for label in ["Fit view", "Overlay", "Plan B", "B vs A"] {
        for node in h.get_all_by_label(label) {
            let r = node.rect();
            assert!(r.right() <= side(&h) + 0.5, "{label}: {r:?}");
        }
    }
}

#[test]
fn hidden_layers_are_listed_greyed_and_included_with_one_click_then_undone() {
    let dxf = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/hidden/hidden-layers.dxf");
    let mut h = opened(&dxf);
    let before = h.state().session.doc().geometries.len();
    assert_eq!(before, 1);
    assert!(
        h.state()
            .status()
            .contains("2 layers the drawing hides not marked"),
        "{}",
        h.state().status()
    );
    let layers = format!("Layers ({})", h.state().session.doc().layers.len());
    section(&mut h, &layers);
    h.get_by_label_contains("OFF: off, 1 item, not marked");
    h.get_by_label_contains("FROZEN: frozen, 1 item, not marked");
    // the first "Include" is the OFF layer's
    h.get_all_by_label("Include").next().unwrap().click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    assert_eq!(h.state().session.doc().geometries.len(), 2);
    assert_eq!(h.state().session.doc().import.included, ["OFF"]);
    h.get_by_label_contains("OFF: off, 1 item, marked");
    assert!(h.state().uncovered().is_empty());
    let layers = h.state().session.doc().layers.len();
    // left out again: its geometry and its layer (with the pen) go
    h.get_by_label("Leave out").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    assert_eq!(h.state().session.doc().geometries.len(), 1);
    assert_eq!(h.state().session.doc().layers.len(), layers - 1);
    h.get_by_label_contains("OFF: off, 1 item, not marked");
    // undo brings the included layer back, a second undo the first import
    h.get_by_label("Undo").click();
    settle(&mut h);
    assert_eq!(h.state().session.doc().geometries.len(), 2);
    h.get_by_label("Undo").click();
    settle(&mut h);
    assert_eq!(h.state().session.doc().geometries.len(), 1);
    h.get_by_label_contains("OFF: off, 1 item, not marked");
}

#[test]
fn placement_centres_the_artwork_on_the_base_stroke() {
    let sheet = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/hidden/boxes-331x351.svg");
    let mut h = opened(&sheet);
    let bbox = |h: &Harness<'_, App>| {
        h.state()
            .session
            .doc()
            .geometries
            .iter()
            .fold(galvoplan::geom::BBox::EMPTY, |b, g| b.union(g.bbox()))
    };
    let layers = format!("Layers ({})", h.state().session.doc().layers.len());
    section(&mut h, &layers);
    // as in the file: out of reach, and the error names the control that helps
    h.get_by_label("Placement").click();
    settle(&mut h);
    h.get_by_label("as in the file").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    assert!((bbox(&h).min_x - 10.0).abs() < 1e-3, "{:?}", bbox(&h));
    let status = h.state().status().to_string();
    assert!(
        status.contains("out of reach") && status.contains("Placement: centred"),
        "{status}"
    );
    h.get_by_label("Placement").click();
    settle(&mut h);
    h.get_by_label("centred").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    let b = bbox(&h);
    let stroke = h.state().session.doc().profile.stroke_mm;
    assert!(
        ((b.min_x + b.max_x) / 2.0 - stroke[0] / 2.0).abs() < 1e-3,
        "{b:?}"
    );
    assert!(
        ((b.min_y + b.max_y) / 2.0 - stroke[1] / 2.0).abs() < 1e-3,
        "{b:?}"
    );
    assert!(h.state().uncovered().is_empty());
}

#[test]
fn convergence_plot_speaks_the_tables_figures_and_names_say_what_a_plan_is() {
    let mut h = opened(&demo());
    for label in ["Run HHA", "Run HGA"] {
        h.get_by_label(label).click();
        h.step();
        wait_idle(&mut h, Duration::from_secs(180));
    }
    let plans = h.state().session.doc().plans.clone();
    let (hha, hga) = (&plans[0], &plans[1]);
    assert_eq!(hha.name, "HHA · job time · step-and-scan");
    assert_eq!(hga.name, "HGA · job time · step-and-scan");
    let (th, ta) = (
        hha.metrics.job_time_s.unwrap(),
        hga.metrics.job_time_s.unwrap(),
    );
    assert!(ta <= th + 1e-12, "HGA {ta} s vs HHA {th} s");
    h.get_by_label("Compare").click();
    settle(&mut h);
    // the table's figures (3 decimals) …
    h.get_all_by_label(&format!("{th:.3}")).next().unwrap();
    h.get_all_by_label(&format!("{ta:.3}")).next().unwrap();
    // … are the plot's HHA line and the end of HGA's best curve, in seconds
    h.get_by_label_contains(&format!("HHA plan: {th:.3} s"));
    h.get_by_label_contains(&format!("B as made: {ta:.3} s"));
    h.get_by_label_contains(&format!("B: {}", hga.name));
    let last = hga.history.last().unwrap();
    assert!(last.finished && (last.best - ta).abs() <= 1e-9 * ta);
    h.get_by_label_contains("B: population mean");
}

/// A hostile file (a fuzzer's edit of demo.svg: a path starting at x = 4.7·10⁶⁰, which took
/// 24 GB before the bounds) dropped on a window with unsaved edits: refused at once, the error
/// shown, the document and its edits still there and still unsaved.
#[test]
fn a_hostile_file_leaves_the_open_document_and_its_edits() {
    let mut h = opened(&demo());
    let id = h.state().session.doc().fields[0].id;
    h.state_mut()
        .execute(Command::SetLocked { id, locked: true })
        .unwrap();
    settle(&mut h);
    let before = h.state().session.doc().clone();
    let hostile = common::root().join("tests/data/hostile/demo-huge-coordinate.svg");
    h.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(hostile)));
    h.step();
    settle(&mut h);
    // the edits are unsaved: the operator is asked first, and goes on without saving
    h.get_by_label("Discard changes").click();
    // the open runs in the background: step until it is done, never run() (which gives up
    // after 16 repaints while a job is polled)
    h.step();
    wait_idle(&mut h, Duration::from_secs(30));
    let status = h.state().status().to_string();
    assert!(
        status.contains("demo-huge-coordinate.svg") && status.contains("<path> (line 124)"),
        "{status}"
    );
    h.get_by_label_contains("<path> (line 124)");
    assert!(*h.state().session.doc() == before, "the document changed");
    assert!(h.state().has_unsaved_changes(), "the edits count as saved");
}

fn part_svg() -> PathBuf {
    common::root().join("assets/examples/part.svg")
}

/// Opens part.svg and sets a tray in the Tray section, a value at a time (each makes the tray
/// again in the background).
fn tray(cols: &str, rows: &str, first_serial: &str) -> Harness<'static, App> {
    let mut h = opened(&part_svg());
    section(&mut h, "Tray");
    for (label, text) in [
        ("Pitch X (mm)", "40"),
        ("Pitch Y (mm)", "32"),
        ("First serial", first_serial),
        ("Columns", cols),
        ("Rows", rows),
    ] {
        enter_nth(&mut h, label, 0, text);
        wait_idle(&mut h, Duration::from_secs(60));
        assert!(
            !h.state().status().starts_with("cannot"),
            "{}",
            h.state().status()
        );
    }
    h
}

/// Hovers the canvas over part `n` and returns the frame's tooltip lines.
fn hover_part(h: &mut Harness<'_, App>, n: u32) {
    let at = h.state().part_screen_pos(n).unwrap();
    h.hover_at(at);
    h.step();
    settle(h);
}

#[test]
fn a_three_by_two_tray_shows_six_numbered_parts_and_their_serials() {
    let mut h = tray("3", "2", "1001");
    let doc = h.state().session.doc();
    assert_eq!(doc.parts.len(), 6);
    let serials: Vec<i64> = doc.parts.iter().map(|p| p.serial).collect();
    assert_eq!(serials, [1001, 1002, 1003, 1004, 1005, 1006]);
    h.get_by_label_contains("a tray of 6 parts, numbered 1 to 6");
    h.get_by_label("6 parts");
    h.get_by_label("Next tray starts at 1007");
    // hovering part 4 tells its serial and what it will carry
    hover_part(&mut h, 4);
    h.get_by_label_contains("part 4 (cell 4, row 2, column 1): serial 1004");
    h.get_by_label_contains("“SN 01004”");
}

/// Right-clicks tray cell `cell` on the canvas and clicks `item` in its context menu; waits
/// for the tray to be made again.
fn cell_menu(h: &mut Harness<'_, App>, cell: u32, item: &str) {
    let at = h.state().cell_screen_pos(cell).unwrap();
    h.hover_at(at);
    h.step();
    for pressed in [true, false] {
        h.event(Event::PointerButton {
            pos: at,
            button: PointerButton::Secondary,
            pressed,
            modifiers: Modifiers::NONE,
        });
    }
    settle(h);
    h.get_by_label(item).click();
    h.step();
    wait_idle(h, Duration::from_secs(60));
}

#[test]
fn a_part_is_skipped_and_marked_again_from_its_context_menu() {
    let mut h = tray("3", "2", "1");
    cell_menu(&mut h, 2, "Skip this part");
    let doc = h.state().session.doc();
    assert_eq!(doc.parts.len(), 5);
    assert!(doc.parts.iter().all(|p| p.cell != 2));
    // the skipped cell takes no serial: cell 3 is part 2
    assert_eq!((doc.parts[1].cell, doc.parts[1].serial), (3, 2));
    h.get_by_label_contains("(1 skipped: cells 2)");
    // its context menu marks it again
    cell_menu(&mut h, 2, "Mark this part");
    assert_eq!(h.state().session.doc().parts.len(), 6);
}

#[test]
fn export_and_advance_logs_the_parts_moves_the_serial_on_and_cannot_be_undone() {
    let mut h = tray("3", "2", "1001");
    h.get_by_label("Run HHA").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(120));
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("parts.csv");
    let program = dir.path().join("tray.gcode");
    enter_nth(&mut h, "Parts log", 0, &log.display().to_string());
    settle(&mut h);
    h.get_by_label("Export and advance").click();
    settle(&mut h);
    // no file dialog in the tests: the path is typed
    // (the next tray's texts are made in the background: no settling before it ends)
    enter_nth(&mut h, "File path", 0, &program.display().to_string());
    wait_idle(&mut h, Duration::from_secs(60));
    assert!(program.exists(), "{}", h.state().status());
    let rows = std::fs::read_to_string(&log).unwrap();
    assert_eq!(rows.lines().count(), 7, "{rows}");
    assert!(
        rows.lines().last().unwrap().ends_with(",6,1006,SN 01006"),
        "{rows}"
    );
    let p = h.state().session.doc().production.clone().unwrap();
    assert_eq!((p.serial.start, p.logged_through), (1007, Some(1006)));
    // the next tray's texts are made: part 1 now says 1007
    assert_eq!(h.state().session.doc().parts[0].texts[0], "SN 01007");
    h.get_by_label("Next tray starts at 1013");
    // undo takes back the remade texts, then refuses to hand out the logged serials again
    h.key_press_modifiers(ctrl(), Key::Z);
    settle(&mut h);
    h.key_press_modifiers(ctrl(), Key::Z);
    settle(&mut h);
    let status = h.state().status().to_string();
    assert!(
        status.contains("cannot undo") && status.contains("1001 … 1006 are in the parts log"),
        "{status}"
    );
    assert_eq!(
        h.state()
            .session
            .doc()
            .production
            .as_ref()
            .unwrap()
            .serial
            .start,
        1007
    );
    // nor can the tray be set back onto them
    enter_nth(&mut h, "First serial", 0, "1003");
    settle(&mut h);
    assert!(
        h.state().status().contains("never handed out again"),
        "{}",
        h.state().status()
    );
}

#[test]
fn a_datamatrix_on_a_three_by_two_tray_is_drawn_and_tells_part_4s_content() {
    let mut h = tray("3", "2", "1001");
    h.get_by_label("Add a code").click();
    settle(&mut h);
    for (label, text) in [
        ("Code content", "GP{serial:05}"),
        ("Code X (mm)", "3"),
        ("Code Y (mm)", "3"),
        ("Code size (mm)", "6"),
    ] {
        enter_nth(&mut h, label, 0, text);
        settle(&mut h);
    }
    h.get_by_label("Apply codes").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    let doc = h.state().session.doc();
    assert_eq!(doc.parts[3].codes, ["GP01004"]);
    // its modules are on the canvas: strokes on the codes layer, in part 4 too
    let modules = doc
        .geometries
        .iter()
        .filter(|g| g.layer == "codes" && g.source.part == 4)
        .count();
    assert!(modules > 10, "{modules} strokes");
    h.get_by_label_contains("code: GP01001");
    hover_part(&mut h, 4);
    h.get_by_label_contains("code “GP01004”");
    // a code that cannot be made says why, in the section
    enter_nth(&mut h, "Code size (mm)", 0, "0.5");
    settle(&mut h);
    h.get_by_label("Apply codes").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    assert!(
        h.state().status().contains("at least") && h.state().status().contains("mm wide"),
        "{}",
        h.state().status()
    );
    assert_eq!(h.state().session.doc().parts[3].codes, ["GP01004"]);
    // dragging the code on part 4 moves it on every part, in one undoable step
    enter_nth(&mut h, "Code size (mm)", 0, "6");
    settle(&mut h);
    let before = code_box_of_part(&h, 1);
    let from = h.state().code_centre_mm(0, 4).unwrap();
    let to = from.plus(galvoplan::geom::Pt::new(2.0, 1.0));
    let (p0, p1) = (
        h.state().mm_screen_pos(from).unwrap(),
        h.state().mm_screen_pos(to).unwrap(),
    );
    h.hover_at(p0);
    h.step();
    h.drag_at(p0);
    h.step();
    for i in 1..=4 {
        h.hover_at(p0 + (p1 - p0) * (i as f32 / 4.0));
        h.step();
    }
    h.drop_at(p1);
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    let status = h.state().status().to_string();
    assert!(status.contains("move code 1 to ("), "{status}");
    let spec = &h.state().session.doc().production.as_ref().unwrap().codes[0];
    // the drag's mm on screen, to the canvas's pixel
    let px_mm = 1.0 / f64::from(h.state().workbench_px_per_mm());
    assert!(
        (spec.at_mm[0] - 5.0).abs() <= px_mm + 0.01,
        "{:?}",
        spec.at_mm
    );
    assert!(
        (spec.at_mm[1] - 4.0).abs() <= px_mm + 0.01,
        "{:?}",
        spec.at_mm
    );
    let after = code_box_of_part(&h, 1);
    assert!((after.0 - before.0 - (spec.at_mm[0] - 3.0)).abs() < 1e-6);
    assert!((after.1 - before.1 - (spec.at_mm[1] - 3.0)).abs() < 1e-6);
    assert_eq!(h.state().session.doc().parts[3].codes, ["GP01004"]);
    h.key_press_modifiers(ctrl(), Key::Z);
    settle(&mut h);
    let spec = &h.state().session.doc().production.as_ref().unwrap().codes[0];
    assert_eq!(spec.at_mm, [3.0, 3.0]);
}

/// The top-left of part `part`'s code marks, mm.
fn code_box_of_part(h: &Harness<'_, App>, part: u32) -> (f64, f64) {
    h.state()
        .session
        .doc()
        .artwork
        .iter()
        .filter(|g| g.layer == "codes" && g.source.part == part)
        .flat_map(|g| g.points.iter())
        .fold((f64::INFINITY, f64::INFINITY), |(x, y), p| {
            (x.min(p.x), y.min(p.y))
        })
}

/// Hovering Run HHA and Run HGA tells in one sentence each how they differ; the settings that
/// only a GA specialist knew by name say what they do.
#[test]
fn the_solvers_and_their_settings_say_what_they_do() {
    let mut h = opened(&demo());
    for (button, says) in [
        ("Run HHA", "Heuristic ordering: fields in a good order"),
        ("Run HGA", "Genetic algorithm: starts from the HHA plan"),
    ] {
        let at = h.get_by_label(button).rect().center();
        h.hover_at(at);
        for _ in 0..40 {
            h.step();
            if h.query_by_label_contains(says).is_some() {
                break;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        h.get_by_label_contains(says);
    }
    // the machine is named in an operator's words, not by a paper's numbering
    assert_eq!(
        h.state().session.doc().profile.name,
        "Reference machine: 300 mm stage, 70 mm field"
    );
    let specs = galvoplan::document::spec::settings_specs();
    for key in ["ga.elite_fraction", "direction_weight", "ga.mutation_rate"] {
        let s = specs.iter().find(|s| s.key == key).unwrap();
        assert!(s.help.split_whitespace().count() >= 8, "{key}: {}", s.help);
    }
}

/// F shows the machine's whole reach (so the artwork's place on the stage can be checked by
/// eye), and *Re-place automatically* fits the view to the new fields.
#[test]
fn f_fits_the_whole_base_stroke_and_re_placing_refits() {
    let mut h = opened(&demo());
    h.key_press(Key::F);
    settle(&mut h);
    let rect = h.state().workbench_rect().unwrap();
    let [sw, sh] = h.state().session.doc().profile.stroke_mm;
    for corner in [(0.0, 0.0), (sw, 0.0), (0.0, sh), (sw, sh)] {
        let p = h
            .state()
            .mm_screen_pos(galvoplan::geom::Pt::new(corner.0, corner.1))
            .unwrap();
        assert!(rect.contains(p), "{corner:?} at {p:?} outside {rect:?}");
    }
    let whole = h.state().workbench_px_per_mm();
    h.get_by_label("Re-place automatically").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    // fitted to the artwork and its fields again: closer than the whole machine
    assert!(
        h.state().workbench_px_per_mm() > whole * 1.05,
        "{} vs {whole}",
        h.state().workbench_px_per_mm()
    );
    for f in &h.state().session.doc().fields {
        let p = h.state().mm_screen_pos(f.center).unwrap();
        assert!(rect.contains(p), "field {} off the canvas", f.id);
    }
}

/// A plan stale for several reasons names the first under the metrics, and "and N more" opens
/// the others.
#[test]
fn the_other_stale_reasons_are_one_click_away() {
    let mut h = two_layers_solved();
    enter_nth(&mut h, "Mark speed (mm/s)", 1, "300");
    settle(&mut h);
    enter_nth(&mut h, "Mark speed (mm/s)", 0, "250");
    settle(&mut h);
    let why = h.state().plan_staleness(0).to_vec();
    assert_eq!(why.len(), 2, "{why:?}");
    assert!(h.query_by_label(&format!("• {}", why[1])).is_none());
    h.get_by_label_contains("and 1 more").click();
    settle(&mut h);
    h.get_by_label(&format!("• {}", why[1]));
}

/// An export onto the drawing it was made from is refused, and the path field stays open with
/// the reason inside it (nothing written, the drawing kept).
#[test]
fn a_refused_export_keeps_its_path_field_open_with_the_reason() {
    let mut h = two_layers_solved();
    let source = two_layers();
    let before = std::fs::read(&source).unwrap();
    h.key_press_modifiers(ctrl(), Key::E);
    settle(&mut h);
    h.get_by_label("Export G-code");
    enter_nth(&mut h, "File path", 0, &source.display().to_string());
    settle(&mut h);
    // still open, saying why
    assert!(h.state().prompt().is_some(), "{}", h.state().status());
    h.get_by_label("File path");
    h.get_by_label_contains("Choose another file.");
    assert!(h.state().status().contains(&source.display().to_string()));
    assert_eq!(std::fs::read(&source).unwrap(), before);
}

/// The advice for geometries larger than a field never proposes what is already chosen: with
/// step-and-scan it offers splitting or on the fly; with on the fly chosen, only splitting.
#[test]
fn the_oversize_advice_never_proposes_what_is_chosen() {
    let (mut h, _) = opened_oversize();
    h.get_by_label("Mark on the fly").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    assert_eq!(
        h.state().session.doc().settings.motion,
        galvoplan::document::MotionMode::OnTheFly
    );
    assert!(h.query_by_label("Mark on the fly").is_none());
    h.get_by_label_contains("The next solve marks them on the fly");
    h.get_by_label("Split at field borders");
}

#[test]
fn hovering_a_shape_says_what_it_is_not_its_internal_path() {
    let (mut h, _) = opened_oversize();
    // the small circle 'dot' (r 6 mm at 60, 150): hovered on its rightmost point
    let at = h
        .state()
        .mm_screen_pos(galvoplan::geom::Pt::new(66.0, 150.0))
        .unwrap();
    h.hover_at(at);
    h.step();
    settle(&mut h);
    h.get_by_label_contains("circle ⌀12.00 mm, layer");
    h.get_by_label_contains("from 'dot'");
}

/// Drags with the primary button from `from` to `to` (screen points), in six steps.
fn drag_from_to(h: &mut Harness<'_, App>, from: egui::Pos2, to: egui::Pos2) {
    h.hover_at(from);
    h.step();
    h.drag_at(from);
    h.step();
    for i in 1..=6 {
        h.hover_at(from + (to - from) * (i as f32 / 6.0));
        h.step();
    }
    h.drop_at(to);
    settle(h);
}

/// oversize.svg split at field borders: its seams' x positions.
fn oversize_split() -> (Harness<'static, App>, Vec<f64>) {
    let (mut h, _) = opened_oversize();
    h.get_by_label("Split at field borders").click();
    h.step();
    wait_idle(&mut h, Duration::from_secs(60));
    let xs = h.state().session.doc().tiling.as_ref().unwrap().xs.clone();
    (h, xs)
}

#[test]
fn a_dragged_seam_goes_as_far_as_its_neighbours_allow_and_says_why() {
    use galvoplan::geom::Pt;
    let (mut h, xs) = oversize_split();
    // the seam near 110 mm: both its cells are as wide as a field already, it cannot move
    let k = (1..xs.len() - 1)
        .min_by(|&a, &b| (xs[a] - 110.0).abs().total_cmp(&(xs[b] - 110.0).abs()))
        .unwrap();
    let at = |h: &Harness<'_, App>, x: f64| h.state().mm_screen_pos(Pt::new(x, 150.0)).unwrap();
    let (from, to) = (at(&h, xs[k]), at(&h, xs[k] + 25.0));
    // hovered, the seam says it is what a drag moves
    h.hover_at(from);
    h.step();
    settle(&mut h);
    h.get_by_label_contains(&format!("seam x = {:.1} mm: drag it to move it", xs[k]));
    drag_from_to(&mut h, from, to);
    let status = h.state().status().to_string();
    assert!(
        status.contains(&format!(
            "seam x = {:.1} mm stays where it is: the cell from",
            xs[k]
        )),
        "{status}"
    );
    assert!(status.contains("the widest a scan field holds"), "{status}");
    assert_eq!(h.state().session.doc().tiling.as_ref().unwrap().xs, xs);
    // the next seam moves left as far as the cell on its right allows, and says so
    let (from, to) = (at(&h, xs[k + 1]), at(&h, xs[k + 1] - 25.0));
    drag_from_to(&mut h, from, to);
    wait_idle(&mut h, Duration::from_secs(60));
    let status = h.state().status().to_string();
    let moved = h.state().session.doc().tiling.as_ref().unwrap().xs[k + 1];
    assert!(
        moved < xs[k + 1] - 0.5 && moved > xs[k + 1] - 25.0,
        "{moved} {status}"
    );
    assert!(
        status.contains(&format!(
            "move seam x = {:.1} mm to {moved:.1} mm (it stops there: the cell up to {:.1} mm",
            xs[k + 1],
            xs[k + 2]
        )),
        "{status}"
    );
}

#[test]
fn a_drag_on_the_artwork_pans_and_only_a_fields_free_area_moves_it() {
    use galvoplan::geom::Pt;
    let (mut h, _) = opened_oversize();
    let fields = h.state().session.doc().fields.clone();
    // the small square's left edge (140, 150) lies in a field: a drag there pans
    let on_edge = h.state().mm_screen_pos(Pt::new(140.0, 150.0)).unwrap();
    h.hover_at(on_edge);
    h.step();
    assert_eq!(
        h.output().platform_output.cursor_icon,
        egui::CursorIcon::Default
    );
    drag_from_to(&mut h, on_edge, on_edge + Vec2::new(60.0, 40.0));
    assert_eq!(h.state().session.doc().fields, fields);
    let after = h.state().mm_screen_pos(Pt::new(140.0, 150.0)).unwrap();
    assert!(
        (after - on_edge - Vec2::new(60.0, 40.0)).length() < 2.0,
        "{after:?}"
    );
    // the square's centre is a field's free area: hovered, the field is offered (grab), and a
    // drag there moves it
    let centre = h.state().mm_screen_pos(Pt::new(150.0, 150.0)).unwrap();
    h.hover_at(centre);
    h.step();
    assert_eq!(
        h.output().platform_output.cursor_icon,
        egui::CursorIcon::Grab
    );
    drag_from_to(&mut h, centre, centre + Vec2::new(-30.0, 0.0));
    assert_ne!(h.state().session.doc().fields, fields);
    // the controls are named on the canvas
    h.get_by_label_contains("middle-drag: pan · wheel: zoom");
}

#[test]
fn equal_plans_show_no_winner() {
    let mut h = opened(&demo());
    for _ in 0..2 {
        solve(&mut h, "Run HHA");
    }
    h.get_by_label("Compare").click();
    settle(&mut h);
    h.get_by_label("B vs A");
    // the same solve twice: the same job time, not coloured as a win, a 0 % difference
    assert!(h.query_by_label("faster").is_none());
    h.get_by_label("0.00 %");
}

/// A harness of `size` px with `path` open.
fn sized(path: &Path, size: Vec2) -> Harness<'static, App> {
    let mut app = App::default();
    assert!(app.open(path), "{}", app.status());
    let mut h = Harness::builder()
        .with_max_steps(MAX_STEPS)
        .with_size(size)
        .build_ui_state(|ui, app: &mut App| app.ui(ui), app);
    settle(&mut h);
    h
}

#[test]
fn the_motion_plots_titles_are_never_cut() {
    for width in [1000.0, 1500.0] {
        let mut h = sized(
            &common::root().join("assets/examples/oversize.svg"),
            Vec2::new(width, 1000.0),
        );
        set_motion(&mut h, "On the fly (stage moves while marking)");
        wait_idle(&mut h, Duration::from_secs(60));
        solve(&mut h, "Run HHA");
        // the limits read in full: what the peak is measured against
        // the limits read in full (what the peak is measured against): no title row is cut
        for title in ["Stage speed", "Scanner offset"] {
            let rows: Vec<String> = h
                .query_all_by_label_contains(title)
                .map(|n| format!("{n:?}"))
                .collect();
            assert!(!rows.is_empty(), "{width} px: {title}");
            for row in rows {
                assert!(!row.contains("…"), "{width} px: {row}");
            }
        }
        h.get_by_label_contains("707 both");
    }
}

#[test]
fn a_plans_name_carries_its_seed_only_when_two_plans_differ_by_seed_alone() {
    let mut h = opened(&demo());
    let first = solve(&mut h, "Run HHA");
    assert_eq!(first.name, "HHA · job time · step-and-scan");
    // the same settings again: numbered
    let again = solve(&mut h, "Run HHA");
    assert_eq!(again.name, "HHA · job time · step-and-scan #2");
    // another seed alone: named by its seed
    section(&mut h, "Solver settings");
    set_text(&mut h, "Seed", "7");
    settle(&mut h);
    let seeded = solve(&mut h, "Run HHA");
    assert_eq!(seeded.name, "HHA · job time · step-and-scan · seed 7");
    // the seed is in every plan's details
    assert!(h.query_by_label_contains("· seed 1").is_none());
}

#[test]
fn the_compare_table_and_its_heading_stay_in_view_on_a_1000_pixel_screen() {
    for size in [Vec2::new(1600.0, 1000.0), Vec2::new(1280.0, 1000.0)] {
        let mut h = sized(&demo(), size);
        solve(&mut h, "Run HHA");
        set_motion(&mut h, "On the fly (stage moves while marking)");
        wait_idle(&mut h, Duration::from_secs(60));
        solve(&mut h, "Run HHA");
        h.get_by_label("Compare").click();
        settle(&mut h);
        // the compare view's table (the side panel, on the right, has its own)
        let side_px = size.x * 0.6;
        for label in [
            "B vs A",
            "Job time (s)",
            "Stage route (mm)",
            "Solve time (s)",
        ] {
            let nodes: Vec<_> = h
                .get_all_by_label(label)
                .map(|n| n.rect())
                .filter(|r| r.left() < side_px)
                .collect();
            assert!(!nodes.is_empty(), "{size:?} {label}");
            for r in nodes {
                assert!(r.bottom() <= size.y, "{size:?} {label}: {r:?}");
            }
        }
        for heading in ["A: HHA", "B: HHA"] {
            let r = h.get_by_label_contains(heading).rect();
            assert!(r.top() >= 0.0 && r.bottom() <= size.y, "{heading}: {r:?}");
        }
        // side by side: two canvases of the same size, next to each other
        let canvas = |label: &str| {
            h.get_all_by_label(label)
                .find(|n| format!("{n:?}").contains("role: Canvas"))
                .map(|n| n.rect())
                .unwrap()
        };
        let (a, b) = (canvas("Plan A"), canvas("Plan B"));
        assert!((a.width() - b.width()).abs() < 2.0, "{a:?} {b:?}");
        assert!(
            a.right() <= b.left() + 1.0 && a.width() > 200.0,
            "{a:?} {b:?}"
        );
    }
}

#[test]
fn the_view_follows_a_resized_window_until_the_operator_moves_it() {
    let mut h = sized(&demo(), Vec2::new(1000.0, 700.0));
    let small_px = h.state().workbench_px_per_mm();
    // the window grows (a window manager's first resize): the drawing is fitted again
    h.set_size(Vec2::new(1600.0, 1000.0));
    settle(&mut h);
    let large_px = h.state().workbench_px_per_mm();
    assert!(large_px > small_px * 1.2, "{small_px} -> {large_px}");
    // once the operator has panned, a resize keeps the view's scale
    let canvas = h.get_by_label("Work area").rect();
    let at = canvas.left_bottom() + Vec2::new(20.0, -60.0);
    drag_from_to(&mut h, at, at + Vec2::new(40.0, -30.0));
    h.set_size(Vec2::new(1200.0, 800.0));
    settle(&mut h);
    assert_eq!(h.state().workbench_px_per_mm(), large_px);
}

#[test]
fn a_linuxcnc_machine_without_the_stream_says_why_on_the_fly_takes_longer() {
    use galvoplan::app::commands::Command;
    let (mut h, _) = opened_oversize();
    let mut p = galvoplan::document::MachineProfile::builtin("linuxcnc").unwrap();
    p.controller.stream_period_s = None;
    h.state_mut()
        .execute(Command::SetProfile(Box::new(p)))
        .unwrap();
    settle(&mut h);
    set_motion(&mut h, "On the fly (stage moves while marking)");
    wait_idle(&mut h, Duration::from_secs(60));
    solve(&mut h, "Run HHA");
    h.get_by_label_contains("LinuxCNC runs on-the-fly G-code without look-ahead: ");
    h.get_by_label_contains("step-and-scan would take");
}

#[test]
fn an_edit_of_passes_moves_no_row() {
    let mut h = opened(&demo());
    // the passes' own row is there with one pass, greyed, so that the rows below stay put
    let rows = |h: &Harness<'_, App>| -> Vec<egui::Rect> {
        h.get_all_by_label("Shift seams between passes")
            .map(|n| n.rect())
            .collect()
    };
    let before = rows(&h);
    assert!(!before.is_empty());
    enter_nth(&mut h, "Passes", 0, "2");
    settle(&mut h);
    assert_eq!(h.state().session.doc().layers[0].pen.passes, 2);
    assert_eq!(rows(&h), before);
}

#[test]
fn a_streamed_plan_says_why_its_job_time_is_what_it_is() {
    use galvoplan::app::commands::Command;
    let (mut h, _) = opened_oversize();
    let p = galvoplan::document::MachineProfile::builtin("linuxcnc").unwrap();
    h.state_mut()
        .execute(Command::SetProfile(Box::new(p)))
        .unwrap();
    settle(&mut h);
    set_motion(&mut h, "On the fly (stage moves while marking)");
    wait_idle(&mut h, Duration::from_secs(60));
    solve(&mut h, "Run HHA");
    h.get_by_label_contains("Streamed to LinuxCNC's joints every 0.1 ms");
}

/// `tests/data/projects/cap-stand-in.galvoplan`: 40 of texture-3043's placements laid on a
/// spherical cap (`galvoplan cap-bench`), a spot each, on the five-axis machine.
fn cap_stand_in() -> PathBuf {
    common::root().join("tests/data/projects/cap-stand-in.galvoplan")
}

#[test]
fn a_five_axis_job_shows_its_axes_in_their_units_and_compares_time_with_distance() {
    let mut h = opened(&cap_stand_in());
    assert!(h
        .state()
        .session
        .doc()
        .fields
        .iter()
        .all(|f| !f.pose.is_rest()));
    section(&mut h, "Machine profile");
    for row in [
        "Base X max velocity (mm/s)",
        "Axis Z max velocity (mm/s)",
        "Axis A max velocity (deg/s)",
        "Axis B max accel (deg/s²)",
        "Axis B travel from (deg)",
    ] {
        h.get_by_label(row);
    }
    // time against distance, side by side
    let by_time = solve(&mut h, "Run HHA");
    section(&mut h, "Solver settings");
    h.get_by_label("Cost model").click();
    settle(&mut h);
    h.get_by_label("Idle travel distance").click();
    settle(&mut h);
    let by_distance = solve(&mut h, "Run HHA");
    let (t, d) = (
        by_time.metrics.job_time_s.unwrap(),
        by_distance.metrics.job_time_s.unwrap(),
    );
    assert!(t <= d, "{t} s !<= {d} s");
    // the plan shown turns Z, A and B: its plots are the axes' speeds
    if h.query_by_label("Motion plots (axis speeds): show")
        .is_some()
    {
        h.get_by_label("Motion plots (axis speeds): show").click();
        settle(&mut h);
    }
    h.get_by_label("Motion plots (axis speeds): hide");
    h.get_by_label_contains("Axis speeds, % of each axis's limit (dashed 100 %): peak X");
    h.get_by_label("Compare").click();
    settle(&mut h);
    h.get_by_label("B vs A");
    h.get_by_label("Workbench").click();
    settle(&mut h);
    // the rotary machine has no Z, no B, no Y: their rows go, and the solve says why it cannot
    let rotary = galvoplan::document::MachineProfile::builtin("rotary").unwrap();
    h.state_mut()
        .execute(Command::SetProfile(Box::new(rotary)))
        .unwrap();
    settle(&mut h);
    assert!(h
        .state()
        .status()
        .contains("the job cannot run on this machine"));
    section(&mut h, "Machine profile");
    h.get_by_label("Axis A max velocity (deg/s)");
    for gone in [
        "Axis B max velocity (deg/s)",
        "Axis Z max velocity (mm/s)",
        "Base Y max velocity (mm/s)",
    ] {
        assert!(h.query_by_label(gone).is_none(), "{gone}");
    }
    // the plan is stale for the machine's change, said without the rows of the axes it lacks
    let stale = h.state().plan_staleness(0).to_vec();
    assert!(
        stale.iter().any(|w| w.starts_with("stroke Y 300 → 0")),
        "{stale:?}"
    );
    assert!(
        stale.iter().any(|w| w.starts_with("axis A max velocity ")),
        "{stale:?}"
    );
    assert!(!stale.iter().any(|w| w.starts_with("base Y")), "{stale:?}");
    let why = h.state().solve_blocker().unwrap();
    assert!(
        why.contains("needs axis Z (") && !why.contains("0000"),
        "{why}"
    );
}

/// A cylinder job in the workbench: the Cylinder section says the strips in focus in words,
/// typing the diameter places strips of that height on the unrolled surface posed at their
/// angles, the solve marks them, and the playback shows the angle.
#[test]
fn a_cylinder_job_places_strips_in_focus_and_says_their_height() {
    let mut h = opened(&common::root().join("assets/examples/sleeve.svg"));
    let rotary = galvoplan::document::MachineProfile::builtin("rotary").unwrap();
    h.state_mut()
        .execute(Command::SetProfile(Box::new(rotary)))
        .unwrap();
    settle(&mut h);
    section(&mut h, "Cylinder");
    h.get_by_label_contains("A flat job.");
    set_text(&mut h, "Cylinder diameter (mm)", "40");
    settle(&mut h);
    h.get_by_label_contains("Cylinder ⌀40 mm: strips in focus are 11.35 mm high");
    let doc = h.state().session.doc();
    assert!(doc.fields.len() > 3);
    for f in &doc.fields {
        assert!((f.size[1] - 11.35).abs() < 0.01, "{:?}", f.size);
        assert!((f.pose.a_deg - (f.center.y / 20.0).to_degrees()).abs() < 1e-9);
    }
    let plan = solve(&mut h, "Run HHA");
    assert!(plan.metrics.job_time_s.unwrap() > 0.0);
    // the playback's readout: the stage's X (the machine has no Y) and the part's angle
    let l = h.state().session.toolpath(0).unwrap().unwrap();
    let words = galvoplan::app::playback::state_text(l, l.duration_s() / 2.0);
    assert!(
        words.contains("; stage X ") && words.contains(", A "),
        "{words}"
    );
    // too thin a tube for this drawing: said in words
    set_text(&mut h, "Cylinder diameter (mm)", "30");
    settle(&mut h);
    h.get_by_label_contains(
        "Cylinder ⌀30 mm cannot be marked: the drawing spans 106.00 mm around the cylinder, \
         more than its circumference 94.25 mm",
    );
    assert!(h.state().status().contains("more than its circumference"));
    // the solve buttons say why they cannot run
    let why = h.state().solve_blocker().unwrap();
    assert!(
        why.contains("more than its circumference 94.25 mm"),
        "{why}"
    );
}
