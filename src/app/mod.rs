//! The desktop GUI (feature `gui`): the operator's workbench around a [`Document`].
//!
//! The GUI only draws and sends commands to the document: field edits, profile and settings
//! changes go through [`commands::History::execute`] (which also gives undo/redo), and every solve
//! runs the library's [`order_document`](crate::pipeline::order_document) on a snapshot in a
//! background thread ([`jobs`]). [`App::ui`] draws one frame; eframe and the headless tests
//! (egui_kittest) both call it.
//!
//! Modules: [`canvas`] (pan/zoom, field dragging, hover) and `paint` (drawing), [`panels`]
//! (profile and settings editors), [`jobs`] (background solves), [`toolpaths`] (each plan's
//! lowered toolpath, the one the canvas draws and plays), [`playback`] (playing a job on the
//! canvas), [`compare`] (side-by-side view, metrics table, convergence plot), [`commands`]
//! (edits and undo), [`motion_plots`] (the on-the-fly stage route and motion plots), [`files`]
//! (open/save/export/recent), `layout` (menus, toolbar, side panels, status bar).

#![deny(clippy::too_many_lines)]

pub mod axis_plot;
pub mod canvas;
pub mod commands;
pub mod compare;
mod cylinder_panel;
pub mod draw;
pub mod files;
mod hit;
pub mod jobs;
pub mod layers;
mod layout;
pub mod motion_plots;
mod paint;
pub mod panels;
pub mod playback;
mod prompt;
mod prompts;
mod raster;
pub mod scene;
pub mod session;
pub mod toolpaths;
mod tray_actions;
pub mod tray_panel;
pub mod words;

pub use canvas::{CanvasAction, CanvasState};
pub use draw::View;
pub use scene::{Canvas, Layers};
pub use words::{count, field_number, field_numbers, field_word, fields_count, gui_error};

use crate::document::{
    Algo, DerivedKey, Document, Layer, MachineProfile, Motion, MotionMode, Plan, SolverSettings,
};
use crate::job::JobCtx;
use crate::pipeline::{derive_geometries, move_seam, place_what_fits};
use commands::{Command, Outcome};
use compare::CompareState;
use files::{ExportKind, Recent};
use jobs::{Job, JobOutcome, JobResult};
use playback::Playback;
pub use prompt::{PathAction, Prompt};
use serde::{Deserialize, Serialize};
use session::Session;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use toolpaths::Lowered;

/// Key of the preferences in eframe's storage.
const PREFS_KEY: &str = "galvoplan-prefs";

/// Solvers offered by the GUI: (algorithm, button label, what it does in one sentence).
pub const SOLVERS: &[(Algo, &str, &str)] = &[
    (
        Algo::Hha,
        "Run HHA",
        "Heuristic ordering: fields in a good order, then each field's marks in a short path; \
         a plan in seconds.",
    ),
    (
        Algo::Hga,
        "Run HGA",
        "Genetic algorithm: starts from the HHA plan and keeps searching for a shorter job for \
         as long as it improves or the time limit allows (can be cancelled).",
    ),
    (
        Algo::Baseline,
        "Run baseline",
        "A simple ordering to compare the others with: fields as placed, the nearest mark next \
         inside each.",
    ),
    (
        Algo::AsIs,
        "Run as-is",
        "The drawing's own order, no optimisation: what the machine would do without galvoplan.",
    ),
];

/// What is kept between runs (eframe storage). The default profile is the built-in seed
/// machine (`MachineProfile::default()`, a unit test keeps them equal).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Prefs {
    /// Machine profile used for newly opened artwork (SVG, DXF).
    pub profile: MachineProfile,
    /// Solver settings used for newly opened artwork (SVG, DXF).
    pub settings: SolverSettings,
    /// Recent files.
    pub recent: Recent,
    /// Canvas layers.
    pub layers: Layers,
    /// Show the frame timings in the status bar (View menu; a debugging aid).
    pub frame_times: bool,
    /// The folder last exported to, per kind of export.
    pub export_dirs: files::ExportDirs,
}

/// Opens the main window, with `file` (an SVG or a project) loaded when given.
pub fn run(file: Option<PathBuf>) -> anyhow::Result<()> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("galvoplan")
            // matches StartupWMClass in packaging/linux/galvoplan.desktop
            .with_app_id("galvoplan")
            .with_inner_size([1500.0, 950.0])
            .with_min_inner_size([900.0, 600.0]),
        ..Default::default()
    };
    eframe::run_native(
        "galvoplan",
        options,
        Box::new(move |cc| {
            let prefs = cc
                .storage
                .and_then(|s| eframe::get_value::<Prefs>(s, PREFS_KEY))
                .unwrap_or_default();
            let mut app = App::with_prefs(prefs);
            app.diagnostics.frame_log =
                std::env::var_os("GALVOPLAN_FRAME_LOG").and_then(|p| std::fs::File::create(p).ok());
            if let Some(f) = file {
                app.open_in_background(&f, &cc.egui_ctx);
            }
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| anyhow::anyhow!("cannot open the window: {e}"))
}

/// The central view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tab {
    /// Canvas with field editing.
    Workbench,
    /// Two plans side by side.
    Compare,
}

/// The sections of the left panel (one shown at a time, so that none scrolls out of sight).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Section {
    /// Layers and their pens.
    Layers,
    /// Solver settings.
    Settings,
    /// Machine profile.
    Profile,
    /// A production job: the part repeated over a tray, serials.
    Tray,
    /// A cylinder job: the diameter, the strips in focus.
    Cylinder,
}

/// Durations of recent frames.
#[derive(Debug, Clone, Default)]
pub struct FrameStats {
    /// (duration of `App::ui` in ms, a solve was running), newest last, at most 600.
    pub samples: std::collections::VecDeque<(f64, bool)>,
    /// CPU time of the previous whole frame (ui, tessellation, painting) as eframe measures
    /// it, ms; unknown in headless tests.
    pub cpu_ms: Option<f64>,
}

impl FrameStats {
    fn push(&mut self, ms: f64, busy: bool) {
        if self.samples.len() >= 600 {
            self.samples.pop_front();
        }
        self.samples.push_back((ms, busy));
    }
    /// The last frame's duration, ms.
    pub fn last_ms(&self) -> f64 {
        self.samples.back().map_or(0.0, |s| s.0)
    }
    /// The longest of the last `n` frames, ms.
    pub fn recent_max_ms(&self, n: usize) -> f64 {
        self.samples
            .iter()
            .rev()
            .take(n)
            .map(|s| s.0)
            .fold(0.0, f64::max)
    }
}

/// Status line.
#[derive(Debug, Clone, Default)]
struct Status {
    text: String,
    error: bool,
}

/// The window, in rooms: the session (the document and what derives from it), the view (what
/// is shown where), the panels (each with its own state), the preferences (read from this one
/// place and stored), the diagnostics (frame timing) and the job runtime (the background work
/// and what follows it).
pub struct App {
    /// The open document, its history, plans and caches.
    pub session: Session,
    view: ViewState,
    panels: Panels,
    prefs: Prefs,
    diagnostics: Diagnostics,
    runtime: Runtime,
}

/// What the window shows and where: the central tab, the left panel's section, the field
/// selected and the add tool, the status line, the title, and the quit and font state.
struct ViewState {
    selected: Option<usize>,
    add_tool: bool,
    tab: Tab,
    /// The section shown in the left panel.
    section: Section,
    status: Status,
    title: String,
    /// The operator chose to quit without saving.
    quit_confirmed: bool,
    /// DejaVu Sans is installed as the fallback font (arrows, symbols, layer names in other
    /// scripts would otherwise miss glyphs).
    fonts_installed: bool,
}

/// The panels and windows, each owning its state (edit buffers, what it shows).
struct Panels {
    /// The profile and settings editors' buffers.
    editors: panels::Editors,
    /// The layers panel's edit buffers.
    layer_editor: layers::LayerEditor,
    /// The Tray section.
    tray: tray_panel::TrayPanel,
    /// The Compare tab.
    compare: CompareState,
    /// The workbench canvas (view, gestures, the drag under way).
    workbench: CanvasState,
    /// Playback on the workbench canvas.
    playback: Playback,
    /// The motion plots below the workbench canvas are shown (on-the-fly plans).
    plots_open: bool,
    /// What was under the workbench canvas in the last frame: (plots header, plots).
    plots_below: (bool, bool),
    /// A question or path field waiting for the operator.
    prompt: Option<Prompt>,
}

/// How responsive the window is: recent frame times and the optional per-frame log.
#[derive(Default)]
struct Diagnostics {
    frames: FrameStats,
    /// Per-frame timing log (`GALVOPLAN_FRAME_LOG=path`), for measuring responsiveness.
    frame_log: Option<std::fs::File>,
}

/// The background work and what is to follow it.
struct Runtime {
    /// The running job (one at a time).
    job: Option<Job>,
    /// An export to write once the solve running now ends (re-solve and export).
    export_after_solve: Option<(ExportKind, PathBuf)>,
    /// Native file dialogs can be shown (else a path field is offered).
    dialogs: bool,
}

impl Default for App {
    fn default() -> Self {
        Self::with_prefs(Prefs::default())
    }
}

impl App {
    /// A new window state with stored preferences.
    pub fn with_prefs(prefs: Prefs) -> Self {
        Self {
            session: Session::with_document(Document {
                profile: prefs.profile.clone(),
                settings: prefs.settings.clone(),
                ..Document::default()
            }),
            view: ViewState {
                selected: None,
                add_tool: false,
                tab: Tab::Workbench,
                section: Section::Layers,
                status: Status {
                    text: "Open an SVG, a DXF or a project (File menu, or drag and drop) to start."
                        .into(),
                    error: false,
                },
                title: String::new(),
                quit_confirmed: false,
                fonts_installed: false,
            },
            panels: Panels {
                editors: panels::Editors::default(),
                layer_editor: layers::LayerEditor::default(),
                tray: tray_panel::TrayPanel::default(),
                compare: CompareState::default(),
                workbench: CanvasState::default(),
                playback: Playback::default(),
                plots_open: true,
                plots_below: (false, false),
                prompt: None,
            },
            prefs,
            diagnostics: Diagnostics::default(),
            runtime: Runtime {
                job: None,
                export_after_solve: None,
                dialogs: files::native_dialogs_available(),
            },
        }
    }

    /// The preferences to store.
    pub fn prefs(&self) -> Prefs {
        Prefs {
            profile: self.session.doc().profile.clone(),
            settings: self.session.doc().settings.clone(),
            ..self.prefs.clone()
        }
    }

    /// Whether native file dialogs are tried (without them every file action asks for a path
    /// in a text field).
    pub fn set_native_dialogs(&mut self, on: bool) {
        self.runtime.dialogs = on;
    }

    /// The question or path field shown, if any.
    pub fn prompt(&self) -> Option<&Prompt> {
        self.panels.prompt.as_ref()
    }

    /// True when the document has changes that are not saved in a project file.
    pub fn has_unsaved_changes(&self) -> bool {
        self.session.has_unsaved_changes()
    }

    fn set_status(&mut self, text: impl Into<String>, error: bool) {
        self.view.status = Status {
            text: text.into(),
            error,
        };
    }

    /// The status line text.
    pub fn status(&self) -> &str {
        &self.view.status.text
    }

    /// True when a document is open.
    pub fn has_document(&self) -> bool {
        self.session.has_document()
    }

    /// Opens an SVG or DXF (fields placed automatically) or a project file on this thread (the
    /// command-line argument and tests); errors go to the status line. Returns true on success.
    pub fn open(&mut self, path: &Path) -> bool {
        match files::open(
            path,
            &self.session.doc().profile,
            &self.session.doc().settings,
            &JobCtx::default(),
        ) {
            Ok(o) => {
                self.opened(path, o);
                true
            }
            Err(e) => {
                self.set_status(e, true);
                false
            }
        }
    }

    /// Opens a file in a background job (progress and Cancel in the status bar).
    pub fn open_in_background(&mut self, path: &Path, repaint: &egui::Context) {
        let (file, profile, settings) = (
            path.to_path_buf(),
            self.session.doc().profile.clone(),
            self.session.doc().settings.clone(),
        );
        let name = format!("opening {}", path.display());
        self.start_job(name, "open", repaint, move |ctx| {
            files::open(&file, &profile, &settings, ctx).map(|o| JobResult::Opened {
                path: file,
                opened: Box::new(o),
            })
        });
    }

    /// Takes an opened document into the window.
    fn opened(&mut self, path: &Path, o: files::Opened) {
        self.runtime.job = None;
        self.session
            .replace(o.doc, o.is_project.then(|| path.to_path_buf()), true);
        self.view.selected = None;
        self.panels.compare = CompareState::default();
        self.panels.playback = Playback::default();
        self.panels.workbench.fit_requested = true;
        self.panels.compare.canvas.fit_requested = true;
        self.prefs.recent.push(path);
        self.refresh_view();
        let hidden = self.session.doc().import.skipped().count();
        let hidden = if hidden > 0 {
            format!(
                "; {} the drawing hides not marked (Layers panel)",
                count(hidden, "layer", "layers")
            )
        } else {
            String::new()
        };
        let msg = format!(
            "{}: {} on {}, {}, {}{hidden}",
            path.display(),
            words::shapes_and_strokes(self.session.doc()),
            count(self.session.doc().layers.len(), "layer", "layers"),
            count(self.session.doc().fields.len(), "scan field", "scan fields"),
            // the Warnings panel's word
            // one line for the same warning on many elements, as the panel lists them
            count(
                crate::document::grouped(&self.session.doc().warnings).len(),
                "warning",
                "warnings"
            )
        );
        match o.problem {
            Some(p) => {
                self.set_status(format!("{msg}; scan fields not placed: {p}"), true);
                self.session.set_problem(Some(p));
            }
            None => {
                self.session.set_problem(None);
                self.set_status(msg, false);
            }
        }
    }

    /// Runs `work` as the background job (one at a time).
    fn start_job(
        &mut self,
        name: String,
        thread: &str,
        repaint: &egui::Context,
        work: impl FnOnce(&JobCtx) -> Result<JobResult, String> + Send + 'static,
    ) {
        if let Some(j) = &self.runtime.job {
            let msg = format!("cannot start {name}: {} is running", j.name);
            self.set_status(msg, true);
            return;
        }
        match Job::spawn(name.clone(), thread, None, repaint, work) {
            Ok(job) => {
                self.runtime.job = Some(job);
                self.set_status(format!("{name}…"), false);
            }
            Err(e) => self.set_status(format!("cannot start {name}: {e}"), true),
        }
    }

    /// Re-places the unlocked fields automatically in a background job (undoable).
    pub fn replace_fields(&mut self, repaint: &egui::Context) {
        let mut work = self.session.doc().clone();
        self.start_job(
            "re-placing scan fields".into(),
            "place",
            repaint,
            move |ctx| {
                place_what_fits(&mut work, ctx).map_err(|e| gui_error(&e))?;
                Ok(JobResult::Placed {
                    doc: Box::new(work),
                    what: "re-place fields automatically".into(),
                    problem: None,
                    // the new fields may lie where the view does not reach
                    refit: true,
                })
            },
        );
    }

    /// Imports the artwork again with other choices (placement, hidden layers) in a background
    /// job (undoable when it ends).
    pub fn reimport(&mut self, import: crate::document::ArtworkImport, repaint: &egui::Context) {
        let what = import_change(&self.session.doc().import, &import);
        let doc = self.session.doc().clone();
        self.start_job(
            format!("importing again: {what}"),
            "import",
            repaint,
            move |ctx| {
                let (doc, problem) = files::reimport(&doc, import, ctx)?;
                Ok(JobResult::Placed {
                    doc: Box::new(doc),
                    what,
                    problem,
                    refit: true,
                })
            },
        );
    }

    /// Gives the document a new layer table: at once when only speeds, powers, passes or
    /// colours change; else the geometries are made again (hatch) and the fields placed again
    /// in a background job (undoable when it ends).
    pub fn set_layers(&mut self, layers: Vec<Layer>, repaint: &egui::Context) {
        if let Err(e) = crate::document::validate_layers(&layers) {
            self.set_status(e.to_string(), true);
            return;
        }
        if Some(DerivedKey::of(
            &layers,
            self.session.doc().reach_profile().field_mm,
            self.session.doc().tiling_set.as_ref(),
        )) == self.session.doc().derived_with
        {
            let _ = self.execute(Command::SetLayers(layers));
            return;
        }
        let mut work = self.session.doc().clone();
        work.layers = layers;
        self.start_job("hatching".into(), "hatch", repaint, move |ctx| {
            let before = work.geometries.len();
            derive_geometries(&mut work, ctx).map_err(|e| e.to_string())?;
            if work.fields.is_empty() && !work.geometries.is_empty() {
                place_what_fits(&mut work, ctx).map_err(|e| gui_error(&e))?;
            }
            let what = format!(
                "change layers: {before} to {} strokes to mark",
                work.geometries.len()
            );
            Ok(JobResult::Placed {
                doc: Box::new(work),
                what,
                problem: None,
                refit: false,
            })
        });
    }

    /// Saves the document (with its plans) as a project file, atomically.
    pub fn save_project(&mut self, path: &Path) -> Result<(), String> {
        crate::document::save_project(self.session.doc(), path).map_err(|e| e.to_string())?;
        self.session.mark_saved(Some(path.to_path_buf()));
        self.prefs.recent.push(path);
        self.set_status(format!("saved {}", path.display()), false);
        Ok(())
    }

    /// Refuses an export path that is one of the document's input files.
    fn check_export_path(&self, kind: ExportKind, path: &Path) -> Result<(), String> {
        let inputs = self.session.input_files();
        let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        crate::export::check_outputs(&inputs, &[(kind.filter().0, path)]).map_err(|e| e.to_string())
    }

    /// Exports the plan shown on the workbench, as planned (with its own inputs), on this
    /// thread.
    pub fn export(&mut self, kind: ExportKind, path: &Path) -> Result<(), String> {
        self.check_export_path(kind, path)?;
        let k = self
            .session
            .active()
            .ok_or("no plan to export: run a solver first")?;
        let plan = self
            .session
            .doc()
            .plans
            .get(k)
            .ok_or("no plan to export: run a solver first")?;
        let toolpath = self
            .session
            .toolpaths()
            .get(k)
            .and_then(Result::ok)
            .map(|l| &l.toolpath);
        files::export(self.session.doc(), plan, toolpath, kind, path)?;
        self.prefs.export_dirs.remember(kind, path);
        let note = match self.session.stale().get(k) {
            Some(why) if !why.is_empty() => " as planned (stale: the document changed since)",
            _ => "",
        };
        self.set_status(format!("wrote {}{note}", path.display()), false);
        Ok(())
    }

    /// Exports the plan shown on the workbench in a background job, as planned.
    pub fn export_in_background(&mut self, kind: ExportKind, path: &Path, repaint: &egui::Context) {
        if let Err(e) = self.check_export_path(kind, path) {
            self.set_status(e, true);
            return;
        }
        let Some((k, plan)) = self
            .session
            .active()
            .and_then(|k| Some((k, self.session.doc().plans.get(k)?.clone())))
        else {
            self.set_status("no plan to export: run a solver first", true);
            return;
        };
        let lowered = self
            .session
            .toolpaths()
            .get(k)
            .and_then(Result::ok)
            .cloned();
        let doc = Document {
            plans: Vec::new(),
            artwork: Vec::new(),
            ..self.session.doc().clone()
        };
        self.prefs.export_dirs.remember(kind, path);
        let file = path.to_path_buf();
        let name = format!("exporting {}", path.display());
        self.start_job(name, "export", repaint, move |_| {
            let toolpath = lowered.as_ref().map(|l| &l.toolpath);
            files::export(&doc, &plan, toolpath, kind, &file)?;
            Ok(JobResult::Exported { path: file, kind })
        });
    }

    /// Solves the shown plan's algorithm again on the current document, then exports the new
    /// plan to `path` (the answer "re-solve and export" to a stale export).
    pub fn resolve_and_export(&mut self, kind: ExportKind, path: &Path, repaint: &egui::Context) {
        if let Err(e) = self.check_export_path(kind, path) {
            self.set_status(e, true);
            return;
        }
        let Some(algo) = self.active_plan().map(|p| p.algo) else {
            self.set_status("no plan to export: run a solver first", true);
            return;
        };
        self.start_solve(algo, repaint);
        if self.runtime.job.is_some() {
            self.runtime.export_after_solve = Some((kind, path.to_path_buf()));
        }
    }

    /// Applies an edit command through the undo history.
    pub fn execute(&mut self, cmd: Command) -> Result<Outcome, String> {
        self.execute_grouped(cmd, None)
    }

    fn execute_grouped(&mut self, cmd: Command, group: Option<u64>) -> Result<Outcome, String> {
        let (what, r) = self.session.execute(cmd, group);
        self.refresh_view();
        match &r {
            Ok(o) => {
                if group.is_none() {
                    let doc = self.session.doc();
                    let pose = doc
                        .fields
                        .iter()
                        .find_map(|f| doc.profile.check_pose(f.id, &f.pose).err());
                    // a machine that turns the part with no cylinder given: that is the way
                    let turns = doc.profile.stroke_mm[1] <= 0.0 && doc.settings.cylinder.is_none();
                    let cover = match (o.uncovered.len(), &pose) {
                        (_, Some(e)) => format!("the job cannot run on this machine: {e}"),
                        (0, None) => "every stroke is in a scan field".to_string(),
                        (n, None) if turns => format!(
                            "{} outside every scan field: {}",
                            count(n, "stroke", "strokes"),
                            words::CYLINDER_ADVICE
                        ),
                        (n, None) => format!(
                            "{} outside every scan field: \"Re-place automatically\" places \
                             fields for them",
                            count(n, "stroke", "strokes")
                        ),
                    };
                    self.set_status(format!("{what}: done; {cover}"), pose.is_some());
                }
                if o.uncovered.is_empty() && self.session.problem().is_some() {
                    self.session.set_problem(None);
                }
            }
            Err(e) => self.set_status(format!("cannot {what}: {e}"), true),
        }
        r
    }

    /// Undoes the last edit.
    pub fn undo(&mut self) {
        match self.session.undo() {
            Ok(Some(w)) => self.set_status(format!("undid: {w}"), false),
            Ok(None) => self.set_status("nothing to undo", false),
            Err(why) => self.set_status(format!("cannot undo: {why}"), true),
        }
        self.refresh_view();
    }

    /// Redoes the last undone edit.
    pub fn redo(&mut self) {
        match self.session.redo() {
            Some(w) => self.set_status(format!("redid: {w}"), false),
            None => self.set_status("nothing to redo", false),
        }
        self.refresh_view();
    }

    /// What the canvases' raster caches are keyed by besides what they compare by value: the
    /// document's revision and the view's refreshes.
    fn canvas_revision(&self) -> u64 {
        self.session.revision() ^ self.session.canvas_revision().rotate_left(32)
    }

    /// The view's part of a refresh (the session's is done): the selection.
    fn refresh_view(&mut self) {
        let doc = self.session.doc();
        if self
            .view
            .selected
            .is_some_and(|id| !doc.fields.iter().any(|f| f.id == id))
        {
            self.view.selected = None;
        }
    }

    /// What changed since plan `k` was planned, in words (empty: it is current).
    pub fn plan_staleness(&self, k: usize) -> &[String] {
        self.session.plan_staleness(k)
    }

    /// The number the canvas shows for field `id`: 1…n in the visiting order of the plan
    /// shown, else in placement order.
    pub fn field_label(&self, id: usize) -> usize {
        self.session.field_label(id)
    }

    /// What the canvas calls field `id`: "field 3", or "region 1" for one larger than the scan
    /// field.
    pub fn field_name(&self, id: usize) -> String {
        self.session.field_name(id)
    }

    /// Uncovered geometries that no scan field can hold.
    pub fn out_of_reach(&self) -> &[usize] {
        self.session.out_of_reach()
    }

    /// Geometries no field holds.
    pub fn uncovered(&self) -> &[usize] {
        self.session.uncovered()
    }

    /// The selected field id.
    pub fn selected_field(&self) -> Option<usize> {
        self.view.selected
    }

    /// The plan drawn on the workbench.
    pub fn active_plan(&self) -> Option<&Plan> {
        self.session.active_plan()
    }

    /// Plan `k`'s lowered toolpath, or why it could not be lowered (`None`: no such plan).
    pub fn toolpath(&self, k: usize) -> Option<Result<&Lowered, &str>> {
        self.session.toolpath(k)
    }

    /// The workbench playback (time, playing, speed).
    pub fn playback(&self) -> &Playback {
        &self.panels.playback
    }

    /// The compare view's state (plans shown, playback).
    pub fn compare_state(&self) -> &CompareState {
        &self.panels.compare
    }

    /// The central view shown.
    pub fn tab(&self) -> Tab {
        self.view.tab
    }

    /// True while a background job (solve, import, hatch, placement, export) runs.
    pub fn is_busy(&self) -> bool {
        self.runtime.job.is_some()
    }

    /// The latest progress message of the running solve.
    pub fn job_message(&self) -> Option<String> {
        self.runtime
            .job
            .as_ref()
            .and_then(|j| j.progress())
            .map(|p| p.message)
    }

    /// Frame durations.
    pub fn frame_stats(&self) -> &FrameStats {
        &self.diagnostics.frames
    }

    /// Screen position of a tray part's centre on the workbench canvas (after the first frame).
    pub fn part_screen_pos(&self, part: u32) -> Option<egui::Pos2> {
        let b = self
            .session
            .part_boxes()
            .iter()
            .find(|b| b.part == Some(part))?;
        self.cell_screen_pos(b.cell)
    }

    /// Screen position of a tray cell's centre (marked or skipped) on the workbench canvas.
    pub fn cell_screen_pos(&self, cell: u32) -> Option<egui::Pos2> {
        let b = self.session.part_boxes().iter().find(|b| b.cell == cell)?;
        let rect = self.panels.workbench.rect?;
        let c = crate::geom::Pt::new(
            (b.bbox.min_x + b.bbox.max_x) / 2.0,
            (b.bbox.min_y + b.bbox.max_y) / 2.0,
        );
        Some(self.panels.workbench.view.to_screen(rect, c))
    }

    /// Fits the canvases to the machine's whole reach with the content (F, *Fit to view*).
    fn fit_whole(&mut self) {
        for c in [&mut self.panels.workbench, &mut self.panels.compare.canvas] {
            c.fit_requested = true;
            c.fit_whole = true;
        }
    }

    /// Screen position of machine point `p` (mm) on the workbench canvas (after the first
    /// frame).
    pub fn mm_screen_pos(&self, p: crate::geom::Pt) -> Option<egui::Pos2> {
        let rect = self.panels.workbench.rect?;
        Some(self.panels.workbench.view.to_screen(rect, p))
    }

    /// The workbench canvas's rectangle on screen (after the first frame).
    pub fn workbench_rect(&self) -> Option<egui::Rect> {
        self.panels.workbench.rect
    }

    /// The workbench canvas's zoom: screen pixels per mm.
    pub fn workbench_px_per_mm(&self) -> f32 {
        self.panels.workbench.view.scale
    }

    /// The centre of code `code` (from 0) of part `part` on the machine, mm.
    pub fn code_centre_mm(&self, code: usize, part: u32) -> Option<crate::geom::Pt> {
        let b = self
            .session
            .code_boxes()
            .iter()
            .find(|c| c.code == code && c.part == part)?;
        Some(crate::geom::Pt::new(
            (b.bbox.min_x + b.bbox.max_x) / 2.0,
            (b.bbox.min_y + b.bbox.max_y) / 2.0,
        ))
    }

    /// Screen position of a field's centre on the workbench canvas (after the first frame).
    pub fn field_screen_pos(&self, id: usize) -> Option<egui::Pos2> {
        let f = self.session.doc().fields.iter().find(|f| f.id == id)?;
        let rect = self.panels.workbench.rect?;
        Some(self.panels.workbench.view.to_screen(rect, f.center))
    }

    /// Why a solve cannot start now, if it cannot.
    pub fn solve_blocker(&self) -> Option<String> {
        if let Some(j) = &self.runtime.job {
            Some(format!("{} is running", j.name))
        } else if !self.has_document() {
            Some("no document open".into())
        } else if !self.session.uncovered().is_empty() {
            Some(match self.session.uncovered().len() {
                1 => "1 stroke is not covered by a scan field".to_string(),
                n => format!("{n} strokes are not covered by a scan field"),
            })
        } else if let Err(e) = self.session.strips() {
            // a cylinder the machine or the drawing cannot make
            Some(e.to_string())
        } else {
            // a field whose pose the machine cannot take (an axis it lacks, beyond a travel)
            let doc = self.session.doc();
            doc.fields
                .iter()
                .find_map(|f| doc.profile.check_pose(f.id, &f.pose).err())
                .map(|e| e.to_string())
        }
    }

    /// Starts a background solve of the current fields with `algo`.
    pub fn start_solve(&mut self, algo: Algo, repaint: &egui::Context) {
        if let Some(why) = self.solve_blocker() {
            self.set_status(format!("cannot solve: {why}"), true);
            return;
        }
        let name = self.next_plan_name(algo);
        match Job::solve(self.session.doc(), algo, name.clone(), repaint) {
            Ok(job) => {
                self.runtime.job = Some(job);
                self.set_status(format!("{name}: solving…"), false);
            }
            Err(e) => self.set_status(format!("cannot start the solver thread: {e}"), true),
        }
    }

    /// Asks the running solve to stop.
    pub fn cancel_solve(&mut self) {
        if let Some(j) = &self.runtime.job {
            j.cancel();
        }
    }

    /// The name of the next plan of `algo`: what it is ([`SolverSettings::plan_title`]), with
    /// " #2", " #3"… when a plan of that name exists.
    fn next_plan_name(&self, algo: Algo) -> String {
        let mut settings = self.session.doc().settings.clone();
        settings.algo = algo;
        self.unique_plan_name(settings.plan_title(), &settings)
    }

    /// `title` for a plan solved with `settings`; when a plan of that name exists: with
    /// " · seed N" where the two differ by their random seed alone, else with " #2", " #3"….
    fn unique_plan_name(&self, title: String, settings: &SolverSettings) -> String {
        let plans = &self.session.doc().plans;
        let taken = |name: &str| {
            plans
                .iter()
                .any(|p| p.name == name || p.name.strip_suffix(" (stopped)") == Some(name))
        };
        if !taken(&title) {
            return title;
        }
        let unseeded = |s: &SolverSettings| SolverSettings {
            seed: 0,
            ..s.clone()
        };
        let by_seed_alone = plans.iter().any(|p| {
            p.name.starts_with(&title)
                && p.settings.seed != settings.seed
                && unseeded(&p.settings) == unseeded(settings)
        });
        let seeded = format!("{title} · seed {}", settings.seed);
        if by_seed_alone && !taken(&seeded) {
            return seeded;
        }
        (2..)
            .map(|n| format!("{title} #{n}"))
            .find(|n| !taken(n))
            .unwrap_or(title)
    }

    fn poll_job(&mut self, ui_ctx: &egui::Context) {
        let Some(job) = &self.runtime.job else { return };
        let Some(outcome) = job.poll() else { return };
        let (name, cancelled) = (job.name.clone(), job.is_cancelled());
        self.runtime.job = None;
        match outcome {
            JobOutcome::Done(JobResult::Opened { path, opened }) => self.opened(&path, *opened),
            JobOutcome::Done(JobResult::Placed {
                doc,
                what,
                problem,
                refit,
            }) => {
                if self.execute(Command::SetContent { doc, what }).is_ok() {
                    self.panels.layer_editor.clear_error();
                    if refit {
                        self.panels.workbench.fit_requested = true;
                        self.panels.compare.canvas.fit_requested = true;
                    }
                    if let Some(p) = problem {
                        self.set_status(format!("scan fields not placed: {p}"), true);
                        self.session.set_problem(Some(p));
                    }
                }
            }
            JobOutcome::Done(JobResult::Exported { path, kind }) => {
                let what = kind.filter().0;
                let streamed = self
                    .session
                    .active_plan()
                    .is_some_and(|p| p.profile.controller.streamed(p.motion));
                let beside = if kind == ExportKind::Gcode && streamed {
                    format!(
                        " and its stream to {} (the program waits for it)",
                        files::stream_path(&path).display()
                    )
                } else {
                    String::new()
                };
                self.set_status(
                    format!("wrote the {what} to {}{beside}", path.display()),
                    false,
                );
            }
            JobOutcome::Done(JobResult::Plan { plan, lowered }) => {
                self.solved(*plan, *lowered, (name, cancelled), ui_ctx)
            }
            JobOutcome::Failed(_) if cancelled => {
                self.runtime.export_after_solve = None;
                // a cancelled job leaves the document as it was (a solve cancelled after a
                // plan was made keeps it, named stopped: that is a result)
                self.set_status(
                    format!("{name}: cancelled before it made anything; nothing was changed"),
                    false,
                )
            }
            JobOutcome::Failed(e) => {
                self.runtime.export_after_solve = None;
                self.set_status(format!("{name} failed: {e}"), true)
            }
        }
    }

    /// Takes a solve's plan into the session and shows it: named (`stopped` when `cancelled`),
    /// said in the status line, and exported when a re-solve and export waits for it.
    fn solved(
        &mut self,
        mut plan: Plan,
        lowered: toolpaths::Prelowered,
        (name, cancelled): (String, bool),
        ui_ctx: &egui::Context,
    ) {
        // an automatic motion is named for the motion the solve chose
        let name = if plan.settings.motion == MotionMode::Auto {
            self.unique_plan_name(plan.name.clone(), &plan.settings)
        } else {
            name
        };
        plan.name = if cancelled {
            format!("{name} (stopped)")
        } else {
            name
        };
        let lowered = lowered.renamed(&plan.name);
        let m = &plan.metrics;
        let job = m.job_time_s.map_or("job time unknown".to_string(), |t| {
            format!("job time {t:.2} s")
        });
        let stage = match (plan.motion, m.motion) {
            (Motion::OnTheFly, Some(f)) => format!(
                "{}, stage route {:.1} mm",
                plan.motion_words(),
                f.stage_route_mm
            ),
            _ => format!("stage travel {:.1} mm, {} scan fields", m.base_mm, m.fields),
        };
        // the solve time of the metrics table: one figure for one fact
        let msg = format!(
            "{}: {job}, idle travel {:.1} mm, {stage} (solved in {:.2} s)",
            plan.name, m.idle_mm, m.solve_s.total
        );
        let k = self.session.add_plan(plan, lowered);
        // a new plan is shown from its start
        self.panels.playback.t_s = 0.0;
        self.panels.playback.playing = false;
        self.panels.compare.push(k, &self.session.doc().plans);
        match self.session.toolpaths().get(k) {
            Some(Err(why)) => {
                let msg = format!("{msg}; {why}");
                self.set_status(msg, true);
            }
            _ => self.set_status(msg.clone(), false),
        }
        if let Some((kind, path)) = self.runtime.export_after_solve.take() {
            if cancelled {
                self.set_status(
                    format!("{msg}; stopped, so {} was not written", path.display()),
                    true,
                );
            } else {
                self.export_in_background(kind, &path, ui_ctx);
            }
        }
    }

    fn on_canvas(&mut self, actions: Vec<CanvasAction>, repaint: &egui::Context) {
        for a in actions {
            match a {
                CanvasAction::Select(id) => self.view.selected = id,
                CanvasAction::Move { id, center } => {
                    if !self.panels.workbench.dragging {
                        self.panels.workbench.dragging = true;
                        self.panels.workbench.drag_group += 1;
                    }
                    let _ = self.execute_grouped(
                        Command::MoveField { id, center },
                        Some(self.panels.workbench.drag_group),
                    );
                }
                CanvasAction::EndDrag => {
                    self.panels.workbench.dragging = false;
                    self.session.close_edit_group();
                    if let Some(f) = self
                        .session
                        .doc()
                        .fields
                        .iter()
                        .find(|f| Some(f.id) == self.view.selected)
                    {
                        let msg = format!(
                            "moved {} to ({:.1}, {:.1}) mm: {}, {} uncovered",
                            self.field_name(f.id),
                            f.center.x,
                            f.center.y,
                            count(f.geometries.len(), "stroke", "strokes"),
                            self.session.uncovered().len()
                        );
                        self.set_status(msg, false);
                    }
                }
                CanvasAction::Add(center) => {
                    if let Ok(o) = self.execute(Command::AddField { center }) {
                        self.view.selected = o.added;
                    }
                }
                CanvasAction::MoveSeam {
                    axis,
                    from_mm,
                    to_mm,
                } => self.move_seam(axis, from_mm, to_mm, repaint),
                CanvasAction::SeamStays {
                    axis,
                    from_mm,
                    to_mm,
                } => self.seam_stays(axis, from_mm, to_mm),
                CanvasAction::SkipCell { cell, skip } => self.skip_cell(cell, skip, repaint),
                CanvasAction::MoveCode { code, by } => self.move_code(code, by, repaint),
            }
        }
    }

    /// Why the document's seam of `axis` at `from_mm` dragged to `to_mm` stops short of it.
    fn seam_stop_reason(&self, axis: usize, from_mm: f64, to_mm: f64) -> Option<String> {
        let doc = self.session.doc();
        let cell_max = crate::fields::cell_max_mm(&doc.layers, doc.profile.field_mm);
        crate::fields::seam_stop_reason(doc.tiling.as_ref()?, axis, from_mm, to_mm, cell_max)
    }

    /// Says why a dragged seam stays where it is.
    fn seam_stays(&mut self, axis: usize, from_mm: f64, to_mm: f64) {
        let which = if axis == 0 { "x" } else { "y" };
        let why = self
            .seam_stop_reason(axis, from_mm, to_mm)
            .unwrap_or_else(|| "its neighbours keep it there".into());
        self.set_status(
            format!("seam {which} = {from_mm:.1} mm stays where it is: {why}"),
            true,
        );
    }

    /// Moves a seam: the geometries are cut again on the moved tiling and the fields placed
    /// again, in a background job (undoable when it ends).
    pub fn move_seam(&mut self, axis: usize, from_mm: f64, to_mm: f64, repaint: &egui::Context) {
        if self.runtime.job.is_some() {
            self.set_status("wait for the running job to end before moving a seam", true);
            return;
        }
        let mut work = self.session.doc().clone();
        let Some(at) = move_seam(&mut work, axis, from_mm, to_mm) else {
            self.set_status("no seam to move there", true);
            return;
        };
        let which = if axis == 0 { "x" } else { "y" };
        // a drag past what the neighbours allow stops there, and says why
        let limited = self
            .seam_stop_reason(axis, from_mm, to_mm)
            .map(|why| format!(" (it stops there: {why})"))
            .unwrap_or_default();
        self.start_job("moving a seam".into(), "seam", repaint, move |ctx| {
            derive_geometries(&mut work, ctx).map_err(|e| e.to_string())?;
            if work.fields.is_empty() && !work.geometries.is_empty() {
                place_what_fits(&mut work, ctx).map_err(|e| gui_error(&e))?;
            }
            let what = format!(
                "move seam {which} = {from_mm:.1} mm to {at:.1} mm{limited}: {}, {}",
                count(work.fields.len(), "field", "fields"),
                count(work.seams.split_strokes, "stroke split", "strokes split")
            );
            Ok(JobResult::Placed {
                doc: Box::new(work),
                what,
                problem: None,
                refit: false,
            })
        });
    }

    /// Draws one frame.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let t0 = Instant::now();
        if !self.view.fonts_installed {
            install_fallback_font(ui.ctx());
            self.view.fonts_installed = true;
        }
        self.poll_job(ui.ctx());
        self.handle_input(ui.ctx());
        // plans added, loaded or removed, the profile or the geometries changed
        self.session.sync_toolpaths();
        self.layout(ui);
        self.prompt_ui(ui);
        if self.runtime.job.is_some() {
            // keep the elapsed time ticking between progress reports
            ui.ctx().request_repaint_after(Duration::from_millis(100));
        }
        let title = match (self.session.project_path(), &self.session.doc().source) {
            (Some(p), _) => format!("galvoplan — {}", p.display()),
            (None, Some(s)) => format!("galvoplan — {s}"),
            (None, None) => "galvoplan".into(),
        };
        if title != self.view.title {
            ui.ctx()
                .send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.view.title = title;
        }
        self.diagnostics
            .frames
            .push(t0.elapsed().as_secs_f64() * 1e3, self.runtime.job.is_some());
    }

    fn handle_input(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        if let Some(p) = dropped.first() {
            self.request_open(Some(p.clone()), ctx);
        }
        let closing = ctx.input(|i| i.viewport().close_requested());
        if closing && !self.view.quit_confirmed && self.has_unsaved_changes() {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.panels.prompt = Some(Prompt::Unsaved(prompt::Then::Quit));
        }
        if ctx.egui_wants_keyboard_input() || self.panels.prompt.is_some() {
            return;
        }
        use egui::{Key, KeyboardShortcut, Modifiers};
        let shortcut = |m: Modifiers, k: Key| {
            ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(m, k)))
        };
        let cmd_shift = Modifiers::COMMAND | Modifiers::SHIFT;
        if shortcut(cmd_shift, Key::S) {
            self.request_save(true, ctx);
        } else if shortcut(Modifiers::COMMAND, Key::S) {
            self.request_save(false, ctx);
        } else if shortcut(Modifiers::COMMAND, Key::O) {
            self.request_open(None, ctx);
        } else if shortcut(Modifiers::COMMAND, Key::E) {
            self.request_export(ExportKind::Gcode, ctx);
        } else if shortcut(Modifiers::COMMAND, Key::N) {
            self.request_new();
        }
        let redo = ctx.input_mut(|i| {
            i.consume_shortcut(&KeyboardShortcut::new(
                Modifiers::COMMAND | Modifiers::SHIFT,
                Key::Z,
            )) || i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Y))
        });
        let undo = ctx
            .input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Z)));
        if redo {
            self.redo();
        } else if undo {
            self.undo();
        }
        let quit = ctx
            .input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Q)));
        if quit {
            self.request_quit(ctx);
        }
        let (delete, fit) = ctx.input(|i| {
            (
                i.key_pressed(Key::Delete),
                i.key_pressed(Key::F) || i.key_pressed(Key::Home),
            )
        });
        if delete {
            if let Some(id) = self.view.selected {
                let _ = self.execute(Command::DeleteField { id });
            }
        }
        if fit {
            self.fit_whole();
        }
    }
}

/// Adds the bundled DejaVu Sans after egui's own fonts, for the glyphs they lack (→, ≤, …);
/// active from the next frame.
fn install_fallback_font(ctx: &egui::Context) {
    let mut fonts = egui::FontDefinitions::default();
    fonts.font_data.insert(
        "dejavu-sans".into(),
        std::sync::Arc::new(egui::FontData::from_static(crate::import::bundled_font())),
    );
    for family in [egui::FontFamily::Proportional, egui::FontFamily::Monospace] {
        fonts
            .families
            .entry(family)
            .or_default()
            .push("dejavu-sans".into());
    }
    ctx.set_fonts(fonts);
}

/// The colour of the canvas's highlight of geometries no field holds (a halo around them,
/// in a colour no layer is drawn in), and of the words about them.
pub fn uncovered_rgb() -> [u8; 3] {
    let c = draw::colour::UNCOVERED;
    [c.r(), c.g(), c.b()]
}

/// A change of import choices in words, for the status line and the undo menu.
fn import_change(
    before: &crate::document::ArtworkImport,
    after: &crate::document::ArtworkImport,
) -> String {
    if before.place != after.place {
        return match after.place {
            crate::document::Place::Corner([x, y]) => {
                format!("place the artwork's top-left corner at ({x}, {y}) mm")
            }
            p => format!("place the artwork {}", layers::place_words(&p)),
        };
    }
    let added = after.included.iter().find(|n| !before.included.contains(n));
    let removed = before.included.iter().find(|n| !after.included.contains(n));
    match (added, removed) {
        (Some(n), _) => format!("include hidden layer {}", layers::layer_label(n)),
        (None, Some(n)) => format!("leave out hidden layer {}", layers::layer_label(n)),
        (None, None) => "import the artwork again".into(),
    }
}

impl eframe::App for App {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.diagnostics.frames.cpu_ms = frame.info().cpu_usage.map(|s| f64::from(s) * 1e3);
        App::ui(self, ui);
        if let Some(log) = &mut self.diagnostics.frame_log {
            use std::io::Write;
            // ui ms of this frame, whole-frame CPU ms of the previous one, solving 0/1
            let _ = writeln!(
                log,
                "{:.3} {:.3} {}",
                self.diagnostics.frames.last_ms(),
                self.diagnostics.frames.cpu_ms.unwrap_or(f64::NAN),
                u8::from(self.runtime.job.is_some())
            );
        }
    }
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, PREFS_KEY, &self.prefs());
    }
}
