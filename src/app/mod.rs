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

pub mod canvas;
pub mod commands;
pub mod compare;
pub mod files;
pub mod jobs;
mod layout;
pub mod motion_plots;
mod paint;
pub mod panels;
pub mod playback;
pub mod toolpaths;

pub use canvas::{Canvas, CanvasAction, CanvasState, Layers, View};

use crate::document::{
    Algo, Document, MachineProfile, MotionMode, Plan, ScanField, SolverSettings,
};
use commands::{Command, History, Outcome};
use compare::CompareState;
use files::{ExportKind, Recent};
use jobs::{Job, JobOutcome};
use playback::Playback;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use toolpaths::{Lowered, ToolpathCache};

/// Key of the preferences in eframe's storage.
const PREFS_KEY: &str = "galvoplan-prefs";

/// Solvers offered by the GUI: (algorithm, button label).
pub const SOLVERS: &[(Algo, &str)] = &[
    (Algo::Hha, "Run HHA"),
    (Algo::Hga, "Run HGA"),
    (Algo::Baseline, "Run baseline"),
    (Algo::AsIs, "Run as-is"),
];

/// What is kept between runs (eframe storage).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
}

impl Default for Prefs {
    fn default() -> Self {
        Self {
            profile: MachineProfile::builtin("seed000").unwrap_or_default(),
            settings: SolverSettings::default(),
            recent: Recent::default(),
            layers: Layers::default(),
        }
    }
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
            app.frame_log =
                std::env::var_os("GALVOPLAN_FRAME_LOG").and_then(|p| std::fs::File::create(p).ok());
            if let Some(f) = file {
                app.open(&f);
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

/// Application state.
pub struct App {
    /// The open document (empty until a file is opened).
    pub doc: Document,
    /// Where the project was loaded from or saved to.
    project_path: Option<PathBuf>,
    history: History,
    job: Option<Job>,
    editors: panels::Editors,
    /// Compare view state.
    pub compare: CompareState,
    workbench: CanvasState,
    selected: Option<usize>,
    add_tool: bool,
    /// The central view.
    pub tab: Tab,
    /// Index of the plan drawn on the workbench.
    active: Option<usize>,
    /// Each plan's lowered toolpath (run time only).
    toolpaths: ToolpathCache,
    /// Playback on the workbench canvas (run time only).
    playback: Playback,
    /// The motion plots below the workbench canvas are shown (on-the-fly plans).
    motion_plots_open: bool,
    /// What was under the workbench canvas in the last frame: (plots header, plots).
    workbench_below: (bool, bool),
    uncovered: Vec<usize>,
    /// A problem with the open document (e.g. fields could not be placed).
    problem: Option<String>,
    recent: Recent,
    layers: Layers,
    status: Status,
    frames: FrameStats,
    drag_group: u64,
    dragging: bool,
    title: String,
    /// Per-frame timing log (`GALVOPLAN_FRAME_LOG=path`), for measuring responsiveness.
    frame_log: Option<std::fs::File>,
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
            doc: Document {
                profile: prefs.profile,
                settings: prefs.settings,
                ..Document::default()
            },
            project_path: None,
            history: History::default(),
            job: None,
            editors: panels::Editors::default(),
            compare: CompareState::default(),
            workbench: CanvasState::default(),
            selected: None,
            add_tool: false,
            tab: Tab::Workbench,
            active: None,
            toolpaths: ToolpathCache::default(),
            playback: Playback::default(),
            motion_plots_open: true,
            workbench_below: (false, false),
            uncovered: Vec::new(),
            problem: None,
            recent: prefs.recent,
            layers: prefs.layers,
            status: Status {
                text: "Open an SVG, a DXF or a project (File menu, or drag and drop) to start."
                    .into(),
                error: false,
            },
            frames: FrameStats::default(),
            drag_group: 0,
            dragging: false,
            title: String::new(),
            frame_log: None,
        }
    }

    /// The preferences to store.
    pub fn prefs(&self) -> Prefs {
        Prefs {
            profile: self.doc.profile.clone(),
            settings: self.doc.settings.clone(),
            recent: self.recent.clone(),
            layers: self.layers,
        }
    }

    fn set_status(&mut self, text: impl Into<String>, error: bool) {
        self.status = Status {
            text: text.into(),
            error,
        };
    }

    /// The status line text.
    pub fn status(&self) -> &str {
        &self.status.text
    }

    /// True when a document is open.
    pub fn has_document(&self) -> bool {
        !self.doc.geometries.is_empty()
    }

    /// Opens an SVG or DXF (fields placed automatically) or a project file; errors go to the status
    /// line. Returns true on success.
    pub fn open(&mut self, path: &Path) -> bool {
        match files::open(path, &self.doc.profile, &self.doc.settings) {
            Ok(o) => {
                self.job = None;
                self.doc = o.doc;
                self.project_path = o.is_project.then(|| path.to_path_buf());
                self.history.clear();
                self.selected = None;
                self.active = self.doc.plans.len().checked_sub(1);
                self.compare = CompareState::default();
                self.playback = Playback::default();
                self.workbench.fit_requested = true;
                self.compare.canvas.fit_requested = true;
                self.recent.push(path);
                self.refresh();
                let msg = format!(
                    "{}: {} geometries, {} fields, {} import warnings",
                    path.display(),
                    self.doc.geometries.len(),
                    self.doc.fields.len(),
                    self.doc.warnings.len()
                );
                match o.problem {
                    Some(p) => {
                        self.set_status(format!("{msg}; fields not placed: {p}"), true);
                        self.problem = Some(p);
                    }
                    None => {
                        self.problem = None;
                        self.set_status(msg, false);
                    }
                }
                true
            }
            Err(e) => {
                self.set_status(e, true);
                false
            }
        }
    }

    /// Saves the document (with its plans) as a project file, atomically.
    pub fn save_project(&mut self, path: &Path) -> Result<(), String> {
        crate::document::save_project(&self.doc, path).map_err(|e| e.to_string())?;
        self.project_path = Some(path.to_path_buf());
        self.recent.push(path);
        self.set_status(format!("saved {}", path.display()), false);
        Ok(())
    }

    /// Exports the plan shown on the workbench.
    pub fn export(&mut self, kind: ExportKind, path: &Path) -> Result<(), String> {
        let plan = self
            .active_plan()
            .ok_or("no plan to export: run a solver first")?;
        let stale = is_stale(plan, &self.doc);
        files::export(&self.doc, plan, kind, path)?;
        let note = if stale {
            " (note: the plan is stale, the fields changed since)"
        } else {
            ""
        };
        self.set_status(format!("wrote {}{note}", path.display()), false);
        Ok(())
    }

    /// Applies an edit command through the undo history.
    pub fn execute(&mut self, cmd: Command) -> Result<Outcome, String> {
        self.execute_grouped(cmd, None)
    }

    fn execute_grouped(&mut self, cmd: Command, group: Option<u64>) -> Result<Outcome, String> {
        let what = cmd.describe();
        let r = self.history.execute(&mut self.doc, cmd, group);
        self.refresh();
        match &r {
            Ok(o) => {
                if group.is_none() {
                    self.set_status(
                        format!("{what}: {} geometries uncovered", o.uncovered.len()),
                        false,
                    );
                }
                if o.uncovered.is_empty() && self.problem.is_some() {
                    self.problem = None;
                }
            }
            Err(e) => self.set_status(format!("cannot {what}: {e}"), true),
        }
        r
    }

    /// Undoes the last edit.
    pub fn undo(&mut self) {
        match self.history.undo(&mut self.doc) {
            Some(w) => self.set_status(format!("undid: {w}"), false),
            None => self.set_status("nothing to undo", false),
        }
        self.refresh();
    }

    /// Redoes the last undone edit.
    pub fn redo(&mut self) {
        match self.history.redo(&mut self.doc) {
            Some(w) => self.set_status(format!("redid: {w}"), false),
            None => self.set_status("nothing to redo", false),
        }
        self.refresh();
    }

    /// Recomputes what derives from the document after a change.
    fn refresh(&mut self) {
        let mut held = vec![false; self.doc.geometries.len()];
        for f in &self.doc.fields {
            for &g in &f.geometries {
                if let Some(h) = held.get_mut(g) {
                    *h = true;
                }
            }
        }
        self.uncovered = (0..held.len()).filter(|&g| !held[g]).collect();
        if self
            .selected
            .is_some_and(|id| !self.doc.fields.iter().any(|f| f.id == id))
        {
            self.selected = None;
        }
        if self.active.is_some_and(|k| k >= self.doc.plans.len()) {
            self.active = self.doc.plans.len().checked_sub(1);
        }
        self.toolpaths.sync(&self.doc);
    }

    /// Geometries no field holds.
    pub fn uncovered(&self) -> &[usize] {
        &self.uncovered
    }

    /// The selected field id.
    pub fn selected_field(&self) -> Option<usize> {
        self.selected
    }

    /// The plan drawn on the workbench.
    pub fn active_plan(&self) -> Option<&Plan> {
        self.active.and_then(|k| self.doc.plans.get(k))
    }

    /// Plan `k`'s lowered toolpath, or why it could not be lowered (`None`: no such plan).
    pub fn toolpath(&self, k: usize) -> Option<Result<&Lowered, &str>> {
        self.toolpaths.get(k)
    }

    /// The workbench playback (time, playing, speed).
    pub fn playback(&self) -> &Playback {
        &self.playback
    }

    /// True while a solve runs.
    pub fn is_busy(&self) -> bool {
        self.job.is_some()
    }

    /// The latest progress message of the running solve.
    pub fn job_message(&self) -> Option<String> {
        self.job
            .as_ref()
            .and_then(|j| j.progress())
            .map(|p| p.message)
    }

    /// Frame durations.
    pub fn frame_stats(&self) -> &FrameStats {
        &self.frames
    }

    /// Screen position of a field's centre on the workbench canvas (after the first frame).
    pub fn field_screen_pos(&self, id: usize) -> Option<egui::Pos2> {
        let f = self.doc.fields.iter().find(|f| f.id == id)?;
        let rect = self.workbench.rect?;
        Some(self.workbench.view.to_screen(rect, f.center))
    }

    /// Why a solve cannot start now, if it cannot.
    pub fn solve_blocker(&self) -> Option<String> {
        if self.job.is_some() {
            Some("a solve is running".into())
        } else if !self.has_document() {
            Some("no document open".into())
        } else if !self.uncovered.is_empty() {
            Some(format!(
                "{} geometries are not covered by a scan field",
                self.uncovered.len()
            ))
        } else {
            None
        }
    }

    /// Starts a background solve of the current fields with `algo`.
    pub fn start_solve(&mut self, algo: Algo, repaint: &egui::Context) {
        if let Some(why) = self.solve_blocker() {
            self.set_status(format!("cannot solve: {why}"), true);
            return;
        }
        let name = self.next_plan_name(algo);
        match Job::start(&self.doc, algo, name.clone(), repaint) {
            Ok(job) => {
                self.job = Some(job);
                self.set_status(format!("{name}: solving…"), false);
            }
            Err(e) => self.set_status(format!("cannot start the solver thread: {e}"), true),
        }
    }

    /// Asks the running solve to stop.
    pub fn cancel_solve(&mut self) {
        if let Some(j) = &self.job {
            j.cancel();
        }
    }

    fn next_plan_name(&self, algo: Algo) -> String {
        let label = match algo {
            Algo::Baseline => "Baseline".to_string(),
            Algo::AsIs => "As-is".to_string(),
            Algo::Hha | Algo::Hga => algo.label().to_uppercase(),
        };
        (1..)
            .map(|n| format!("{label} #{n}"))
            .find(|n| {
                !self
                    .doc
                    .plans
                    .iter()
                    .any(|p| p.name.starts_with(n.as_str()))
            })
            .unwrap_or(label)
    }

    fn poll_job(&mut self) {
        let Some(job) = &self.job else { return };
        let Some(outcome) = job.poll() else { return };
        let (name, cancelled, elapsed) = (job.name.clone(), job.is_cancelled(), job.elapsed());
        self.job = None;
        match outcome {
            JobOutcome::Plan(mut plan) => {
                plan.name = if cancelled {
                    format!("{name} (stopped)")
                } else {
                    name
                };
                let m = &plan.metrics;
                let job = m.job_time_s.map_or("job time unknown".to_string(), |t| {
                    format!("job time {t:.2} s")
                });
                let stage = match (plan.motion, m.motion) {
                    (MotionMode::OnTheFly, Some(f)) => {
                        format!("on the fly, stage route {:.1} mm", f.stage_route_mm)
                    }
                    _ => format!("stage travel {:.1} mm, {} scan fields", m.base_mm, m.fields),
                };
                let msg = format!(
                    "{}: {job}, idle travel {:.1} mm, {stage} (solved in {:.2} s)",
                    plan.name,
                    m.idle_mm,
                    elapsed.as_secs_f64()
                );
                self.doc.plans.push(*plan);
                self.toolpaths.sync(&self.doc);
                let k = self.doc.plans.len() - 1;
                self.active = Some(k);
                self.compare.push(k);
                match self.toolpaths.get(k) {
                    Some(Err(why)) => {
                        let msg = format!("{msg}; {why}");
                        self.set_status(msg, true);
                    }
                    _ => self.set_status(msg, false),
                }
            }
            JobOutcome::Failed(e) if cancelled => {
                self.set_status(format!("{name}: cancelled ({e})"), false)
            }
            JobOutcome::Failed(e) => self.set_status(format!("{name} failed: {e}"), true),
        }
    }

    fn on_canvas(&mut self, actions: Vec<CanvasAction>) {
        for a in actions {
            match a {
                CanvasAction::Select(id) => self.selected = id,
                CanvasAction::Move { id, center } => {
                    if !self.dragging {
                        self.dragging = true;
                        self.drag_group += 1;
                    }
                    let _ = self
                        .execute_grouped(Command::MoveField { id, center }, Some(self.drag_group));
                }
                CanvasAction::EndDrag => {
                    self.dragging = false;
                    self.history.close_group();
                    if let Some(f) = self.doc.fields.iter().find(|f| Some(f.id) == self.selected) {
                        let msg = format!(
                            "moved field {} to ({:.1}, {:.1}) mm: {} geometries, {} uncovered",
                            f.id,
                            f.center.x,
                            f.center.y,
                            f.geometries.len(),
                            self.uncovered.len()
                        );
                        self.set_status(msg, false);
                    }
                }
                CanvasAction::Add(center) => {
                    if let Ok(o) = self.execute(Command::AddField { center }) {
                        self.selected = o.added;
                    }
                }
            }
        }
    }

    /// Draws one frame.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let t0 = Instant::now();
        self.poll_job();
        self.handle_input(ui.ctx());
        // plans added, loaded or removed, the profile or the geometries changed
        self.toolpaths.sync(&self.doc);
        self.layout(ui);
        if self.job.is_some() {
            // keep the elapsed time ticking between progress reports
            ui.ctx().request_repaint_after(Duration::from_millis(100));
        }
        let title = match (&self.project_path, &self.doc.source) {
            (Some(p), _) => format!("galvoplan — {}", p.display()),
            (None, Some(s)) => format!("galvoplan — {s}"),
            (None, None) => "galvoplan".into(),
        };
        if title != self.title {
            ui.ctx()
                .send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
        self.frames
            .push(t0.elapsed().as_secs_f64() * 1e3, self.job.is_some());
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
            self.open(p);
        }
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        use egui::{Key, KeyboardShortcut, Modifiers};
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
            // eframe stores the preferences on the way out
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        let (delete, fit) = ctx.input(|i| {
            (
                i.key_pressed(Key::Delete),
                i.key_pressed(Key::F) || i.key_pressed(Key::Home),
            )
        });
        if delete {
            if let Some(id) = self.selected {
                let _ = self.execute(Command::DeleteField { id });
            }
        }
        if fit {
            self.workbench.fit_requested = true;
            self.compare.canvas.fit_requested = true;
        }
    }
}

/// A plan is stale when the fields it was planned on (centres, sizes, allocation) differ from
/// the document's current fields.
pub fn is_stale(plan: &Plan, doc: &Document) -> bool {
    type Key = (usize, [u64; 4], Vec<usize>);
    fn key(fields: &[ScanField]) -> Vec<Key> {
        let mut v: Vec<Key> = fields
            .iter()
            .filter(|f| !f.geometries.is_empty())
            .map(|f| {
                let mut g = f.geometries.clone();
                g.sort_unstable();
                let b = [f.center.x, f.center.y, f.size[0], f.size[1]].map(f64::to_bits);
                (f.id, b, g)
            })
            .collect();
        v.sort();
        v
    }
    key(&plan.fields) != key(&doc.fields)
}

impl eframe::App for App {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.frames.cpu_ms = frame.info().cpu_usage.map(|s| f64::from(s) * 1e3);
        App::ui(self, ui);
        if let Some(log) = &mut self.frame_log {
            use std::io::Write;
            // ui ms of this frame, whole-frame CPU ms of the previous one, solving 0/1
            let _ = writeln!(
                log,
                "{:.3} {:.3} {}",
                self.frames.last_ms(),
                self.frames.cpu_ms.unwrap_or(f64::NAN),
                u8::from(self.job.is_some())
            );
        }
    }
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, PREFS_KEY, &self.prefs());
    }
}
