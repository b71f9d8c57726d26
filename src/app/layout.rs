//! The window layout: menu bar, toolbar, side panels, status bar and the central view.

use super::commands::Command;
use super::draw::colour;
use super::draw::colour::STALE;
use super::files::ExportKind;
use super::layers::LayerAction;
use super::scene::{Canvas, PathLayer};
use super::words::stale_text;
use super::{compare, motion_plots, playback, App, Section, Tab, SOLVERS};
use egui::{Color32, RichText};

const ERROR: Color32 = Color32::from_rgb(200, 30, 30);
/// The most of the window's width the left panel takes (370 px of 1500 by default).
const LEFT_SHARE: f32 = 0.3;
/// The most of the window's width the right panel takes (330 px of 1500 by default).
const RIGHT_SHARE: f32 = 0.28;
/// The side panels' width on the smallest window, at least, px.
const SIDE_MIN_PX: f32 = 200.0;

impl App {
    /// Lays out the whole window.
    pub(super) fn layout(&mut self, ui: &mut egui::Ui) {
        // the side panels give way on a small window, so that the central view keeps room
        let window_px = ui.available_width();
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::top("toolbar").show(ui, |ui| self.toolbar(ui));
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        if self.view.tab == Tab::Workbench {
            egui::Panel::left("left")
                .resizable(true)
                .default_size(370.0)
                .max_size((window_px * LEFT_SHARE).max(SIDE_MIN_PX))
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| self.left_panel(ui));
                });
        }
        egui::Panel::right("right")
            .resizable(true)
            .default_size(330.0)
            .max_size((window_px * RIGHT_SHARE).max(SIDE_MIN_PX))
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.right_panel(ui));
            });
        egui::CentralPanel::default().show(ui, |ui| match self.view.tab {
            Tab::Workbench => self.workbench_view(ui),
            Tab::Compare => {
                if self.has_document() {
                    let revision = self.canvas_revision();
                    compare::show(
                        ui,
                        &mut self.panels.compare,
                        self.session.doc(),
                        self.session.toolpaths(),
                        self.session.stale(),
                        self.prefs.layers,
                        revision,
                    );
                } else {
                    ui.label("Open a document first.");
                }
            }
        });
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| self.file_menu(ui));
            ui.menu_button("Edit", |ui| self.edit_menu(ui));
            ui.menu_button("View", |ui| self.view_menu(ui));
        });
    }

    /// New, open, save, export and quit.
    fn file_menu(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        if ui
            .add(egui::Button::new("New").shortcut_text("Ctrl+N"))
            .clicked()
        {
            self.request_new();
        }
        if ui
            .add(egui::Button::new("Open SVG, DXF or project…").shortcut_text("Ctrl+O"))
            .clicked()
        {
            self.request_open(None, &ctx);
        }
        ui.menu_button("Open recent", |ui| {
            if self.prefs.recent.0.is_empty() {
                ui.label("(none)");
            }
            for p in self.prefs.recent.0.clone() {
                if ui.button(p.display().to_string()).clicked() {
                    self.request_open(Some(p), &ctx);
                }
            }
        });
        ui.separator();
        let doc = self.has_document();
        if ui
            .add_enabled(
                doc,
                egui::Button::new("Save project").shortcut_text("Ctrl+S"),
            )
            .clicked()
        {
            self.request_save(false, &ctx);
        }
        if ui
            .add_enabled(
                doc,
                egui::Button::new("Save project as…").shortcut_text("Ctrl+Shift+S"),
            )
            .clicked()
        {
            self.request_save(true, &ctx);
        }
        ui.separator();
        let plan = self.active_plan().is_some();
        for (kind, label, keys) in [
            (ExportKind::Gcode, "Export G-code…", "Ctrl+E"),
            (ExportKind::Report, "Export report (JSON)…", ""),
            (ExportKind::Preview, "Export SVG preview…", ""),
            (ExportKind::Trajectory, "Export trajectory (CSV)…", ""),
        ] {
            let b = egui::Button::new(label).shortcut_text(keys);
            if ui
                .add_enabled(plan, b)
                .on_disabled_hover_text("Run a solver first")
                .clicked()
            {
                self.request_export(kind, &ctx);
            }
        }
        ui.separator();
        if ui
            .add(egui::Button::new("Quit").shortcut_text("Ctrl+Q"))
            .clicked()
        {
            self.request_quit(&ctx);
        }
    }

    /// Undo and redo, named for what they undo and redo.
    fn edit_menu(&mut self, ui: &mut egui::Ui) {
        let u = self
            .session
            .history()
            .undo_label()
            .map(|w| format!("Undo {w}"));
        if ui
            .add_enabled(
                u.is_some(),
                egui::Button::new(u.unwrap_or("Undo".into())).shortcut_text("Ctrl+Z"),
            )
            .clicked()
        {
            self.undo();
        }
        let r = self
            .session
            .history()
            .redo_label()
            .map(|w| format!("Redo {w}"));
        if ui
            .add_enabled(
                r.is_some(),
                egui::Button::new(r.unwrap_or("Redo".into())).shortcut_text("Ctrl+Shift+Z"),
            )
            .clicked()
        {
            self.redo();
        }
    }

    /// The canvas layers and fitting the view.
    fn view_menu(&mut self, ui: &mut egui::Ui) {
        self.layer_toggles(ui);
        if ui
            .add(egui::Button::new("Fit to view").shortcut_text("F"))
            .on_hover_text("the machine's whole reach with the artwork and fields")
            .clicked()
        {
            self.fit_whole();
        }
    }

    fn layer_toggles(&mut self, ui: &mut egui::Ui) {
        let l = &mut self.prefs.layers;
        ui.checkbox(&mut l.fields, "Scan fields");
        ui.checkbox(&mut l.path, "Planned path");
        ui.checkbox(&mut l.arrows, "Direction arrows");
        ui.checkbox(&mut l.base_path, "Base path / stage route");
        ui.checkbox(&mut l.order_colours, "Colour marks by order");
        ui.checkbox(
            &mut self.prefs.frame_times,
            "Frame timings in the status bar",
        );
    }

    fn toolbar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            let ctx = ui.ctx().clone();
            if ui
                .button("Open…")
                .on_hover_text(
                    "Open an SVG, a DXF or a project (Ctrl+O, or drop a file on the window)",
                )
                .clicked()
            {
                self.request_open(None, &ctx);
            }
            if ui
                .add_enabled(self.has_document(), egui::Button::new("Save"))
                .on_hover_text("Save the project (Ctrl+S)")
                .clicked()
            {
                self.request_save(false, &ctx);
            }
            ui.separator();
            let can_undo = self.session.history().undo_label().is_some();
            if ui
                .add_enabled(can_undo, egui::Button::new("Undo"))
                .on_hover_text("Ctrl+Z")
                .clicked()
            {
                self.undo();
            }
            let can_redo = self.session.history().redo_label().is_some();
            if ui
                .add_enabled(can_redo, egui::Button::new("Redo"))
                .on_hover_text("Ctrl+Shift+Z")
                .clicked()
            {
                self.redo();
            }
            ui.separator();
            self.field_tools(ui);
            ui.separator();
            let blocker = self.solve_blocker();
            for (algo, label, what) in SOLVERS {
                let b = ui.add_enabled(blocker.is_none(), egui::Button::new(*label));
                let b = match &blocker {
                    Some(why) => b.on_disabled_hover_text(why),
                    None => b.on_hover_text(*what),
                };
                if b.clicked() {
                    self.start_solve(*algo, ui.ctx());
                }
            }
            ui.separator();
            ui.selectable_value(&mut self.view.tab, Tab::Workbench, "Workbench");
            ui.selectable_value(&mut self.view.tab, Tab::Compare, "Compare");
        });
    }

    /// Select and add tools, and what the selected field can have done to it.
    fn field_tools(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        ui.selectable_value(&mut self.view.add_tool, false, "Select")
            .on_hover_text(
                "Click a field to select it, drag it to move it; drag empty space to pan",
            );
        ui.selectable_value(&mut self.view.add_tool, true, "Add field")
            .on_hover_text(
                "Click to add a field (double-click also adds one with the select tool)",
            );
        let sel = self
            .view
            .selected
            .and_then(|id| self.session.doc().fields.iter().find(|f| f.id == id))
            .map(|f| (f.id, f.locked));
        if ui
            .add_enabled(sel.is_some(), egui::Button::new("Delete field"))
            .on_hover_text("Delete key")
            .clicked()
        {
            if let Some((id, _)) = sel {
                let _ = self.execute(Command::DeleteField { id });
            }
        }
        let lock_label = if sel.is_some_and(|s| s.1) {
            "Unlock"
        } else {
            "Lock"
        };
        if ui
            .add_enabled(sel.is_some(), egui::Button::new(lock_label))
            .on_hover_text("Locked fields do not move and survive automatic re-placement")
            .clicked()
        {
            if let Some((id, locked)) = sel {
                let _ = self.execute(Command::SetLocked {
                    id,
                    locked: !locked,
                });
            }
        }
        if ui
            .add_enabled(
                self.has_document() && self.runtime.job.is_none(),
                egui::Button::new("Re-place automatically"),
            )
            .on_hover_text(
                "Replace the unlocked fields by the automatic placement; locked fields stay",
            )
            .clicked()
        {
            self.replace_fields(&ctx);
        }
    }

    fn status_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            if let Some(job) = &self.runtime.job {
                job.show(ui);
                ui.separator();
            }
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                if self.has_document() {
                    let u = self.session.uncovered().len();
                    let t = RichText::new(format!(
                        "{} · {} uncovered",
                        super::words::fields_count(
                            &self.session.doc().fields,
                            &self.session.doc().profile
                        ),
                        u
                    ));
                    ui.label(if u > 0 { t.color(ERROR) } else { t });
                    ui.separator();
                }
                if self.prefs.frame_times {
                    let f = &self.diagnostics.frames;
                    let cpu = f
                        .cpu_ms
                        .map_or(String::new(), |c| format!(", whole frame {c:.1} ms"));
                    ui.label(
                        RichText::new(format!(
                            "ui {:.1} ms (max {:.1}){cpu}",
                            f.last_ms(),
                            f.recent_max_ms(120)
                        ))
                        .small()
                        .weak(),
                    )
                    .on_hover_text(
                        "time of App::ui in the last frame (and the maximum of the last 120 \
                         frames); whole frame: the integration's CPU time including tessellation",
                    );
                    ui.separator();
                }
                ui.with_layout(egui::Layout::left_to_right(egui::Align::Center), |ui| {
                    // the running job's words replace the status line that started it, in
                    // full (wrapped); an error said meanwhile stays beside them
                    let status = RichText::new(&self.view.status.text);
                    let status = if self.view.status.error {
                        status.color(ERROR)
                    } else {
                        status
                    };
                    match &self.runtime.job {
                        Some(job) if self.view.status.error => {
                            ui.vertical(|ui| {
                                ui.add(egui::Label::new(job.progress_text()).wrap());
                                ui.add(egui::Label::new(status).wrap());
                            });
                        }
                        Some(job) => {
                            ui.add(egui::Label::new(job.progress_text()).wrap());
                        }
                        None => {
                            ui.add(egui::Label::new(status).wrap());
                        }
                    }
                });
            });
        });
    }

    fn layers_ui(&mut self, ui: &mut egui::Ui) {
        let busy = self.runtime.job.as_ref().map(|j| j.name.clone());
        let import = (self.session.can_reimport()).then_some(&self.session.doc().import);
        let action = self.panels.layer_editor.ui(
            ui,
            &self.session.doc().layers,
            self.session.layer_counts(),
            &self.session.doc().profile,
            import,
            busy.as_deref(),
        );
        let ctx = ui.ctx().clone();
        match action {
            Some(LayerAction::Set(layers)) => self.set_layers(layers, &ctx),
            Some(LayerAction::File(a)) => self.choose_path(a, &ctx),
            Some(LayerAction::Reimport(import)) => self.reimport(import, &ctx),
            None => {}
        }
    }

    fn left_panel(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            let layers = format!("Layers ({})", self.session.doc().layers.len());
            ui.selectable_value(&mut self.view.section, Section::Layers, layers)
                .on_hover_text("Layers and their pens: speed, power, passes, hatch");
            ui.selectable_value(&mut self.view.section, Section::Settings, "Solver settings");
            ui.selectable_value(&mut self.view.section, Section::Profile, "Machine profile");
            ui.selectable_value(&mut self.view.section, Section::Tray, "Tray")
                .on_hover_text("Repeat the part over a tray: columns, rows, pitch, serial numbers");
            ui.selectable_value(&mut self.view.section, Section::Cylinder, "Cylinder")
                .on_hover_text("Mark around a cylinder on the rotary axis: its diameter");
        });
        ui.separator();
        match self.view.section {
            Section::Layers => self.layers_ui(ui),
            Section::Settings => {
                if let Some(cmd) = self
                    .panels
                    .editors
                    .settings_ui(ui, &self.session.doc().settings)
                {
                    let motion = self.session.doc().settings.motion;
                    let changed =
                        self.execute(cmd).is_ok() && self.session.doc().settings.motion != motion;
                    // on the fly holds what no scan field could (and back): fields placed for
                    // the other motion that leave geometries uncovered are placed again at once
                    if changed && !self.session.uncovered().is_empty() && !self.is_busy() {
                        self.replace_fields(ui.ctx());
                    }
                }
            }
            Section::Tray => self.tray_ui(ui),
            Section::Cylinder => self.cylinder_ui(ui),
            Section::Profile => {
                if let Some(cmd) = self
                    .panels
                    .editors
                    .profile_ui(ui, &self.session.doc().profile)
                {
                    let _ = self.execute(cmd);
                }
                if let Some(a) = self.panels.editors.take_file_request() {
                    let ctx = ui.ctx().clone();
                    self.choose_path(a, &ctx);
                }
            }
        }
        ui.separator();
        egui::CollapsingHeader::new("View")
            .default_open(false)
            .show(ui, |ui| self.layer_toggles(ui));
    }

    fn right_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Document");
        match &self.session.doc().source {
            Some(s) => {
                ui.label(RichText::new(s).small());
            }
            None => {
                ui.label("No document. Open an SVG, a DXF or a project.");
            }
        }
        if self.has_document() {
            self.coverage_ui(ui);
        }
        if let Some(p) = self.session.problem() {
            ui.add(egui::Label::new(RichText::new(p).color(ERROR)).wrap());
        }
        self.selected_field_ui(ui);
        ui.separator();
        self.plans_ui(ui);
        if let Some(plan) = self.active_plan() {
            ui.separator();
            ui.heading("Metrics");
            // stale figures are said to be so before they are shown
            let stale = self
                .session
                .active()
                .map_or(&[][..], |k| self.plan_staleness(k));
            compare::stale_notes(ui, &[(plan, stale)]);
            // why the plan's motion and time are what they are (auto's choice, LinuxCNC's pace)
            if let Some(note) = &plan.metrics.motion_note {
                ui.add(egui::Label::new(RichText::new(note).italics()).wrap());
            }
            compare::metrics_table(ui, "active-metrics", plan, None);
        }
        ui.separator();
        self.warnings_and_recent_ui(ui);
    }

    /// What the document holds and what no field holds yet, each with what helps it.
    fn coverage_ui(&mut self, ui: &mut egui::Ui) {
        let closed = self.session.closed();
        ui.label(format!(
            "{} ({closed} closed, {} open strokes), {}",
            super::words::shapes_and_strokes(self.session.doc()),
            self.session.doc().geometries.len() - closed,
            super::words::fields_count(&self.session.doc().fields, &self.session.doc().profile)
        ));
        let far = self.session.out_of_reach().len();
        let near = self.session.uncovered().len() - far;
        // larger than a field (cut them, or mark on the fly) or beyond the reach (move the
        // artwork): each told what helps it
        let [fw, fh] = self.session.doc().profile.field_mm;
        let large = self
            .session
            .out_of_reach()
            .iter()
            .filter(|&&g| {
                let b = self.session.doc().geometries[g].bbox();
                b.width() > fw || b.height() > fh
            })
            .count();
        // a machine that turns the part instead of moving it in Y: a cylinder is the way, for
        // the large and the far alike
        let doc = self.session.doc();
        let turns = doc.profile.stroke_mm[1] <= 0.0 && doc.settings.cylinder.is_none();
        let (large, beyond) = if turns {
            (0, far)
        } else {
            (large, far - large)
        };
        if large > 0 {
            self.oversize_ui(ui, large);
        }
        let cylinder = format!(
            "beyond the stage's stroke plus half a field: {}.",
            super::words::CYLINDER_ADVICE
        );
        let advice = [(
            beyond,
            if turns {
                cylinder.as_str()
            } else {
                "beyond the stage's stroke plus half a field: choose \"Placement: \
                 centred\" in the Layers panel to move the artwork within reach."
            },
        )];
        for (n, what) in advice.into_iter().filter(|(n, _)| *n > 0) {
            ui.add(
                egui::Label::new(
                    RichText::new(format!(
                        "{} (dashed purple) cannot be held by any scan field, {} {what}",
                        super::words::count(n, "stroke", "strokes"),
                        if n == 1 { "it is" } else { "they are" },
                    ))
                    .color(colour::OUT_OF_REACH),
                )
                .wrap(),
            );
        }
        if near > 0 {
            ui.add(
                egui::Label::new(
                    RichText::new(format!(
                        "{} (magenta halo on the canvas) {} not covered by a scan field \
                 yet: add a field (Add field) or press \"Re-place automatically\".",
                        super::words::count(near, "stroke", "strokes"),
                        if near == 1 { "is" } else { "are" }
                    ))
                    .color(colour::UNCOVERED),
                )
                .wrap(),
            );
        }
    }

    /// The document's warnings (open on each import that has some) and the recent files.
    fn warnings_and_recent_ui(&mut self, ui: &mut egui::Ui) {
        // the same message for many elements is one line with its count and a few of them
        let lines = self.session.warning_lines();
        let n = lines.len();
        let title = if n > 0 {
            // import, cut and whole-or-cut warnings alike: what the drawing and the placement say
            RichText::new(format!("Warnings ({n})"))
                .strong()
                .color(Color32::from_rgb(180, 83, 9))
        } else {
            RichText::new("Warnings (0)")
        };
        // a new id per import: the list opens on each import that has warnings
        egui::CollapsingHeader::new(title)
            .id_salt(("warnings", self.session.imports()))
            .default_open(n > 0)
            .show(ui, |ui| {
                if n == 0 {
                    ui.label("none");
                }
                for w in lines {
                    ui.add(
                        egui::Label::new(RichText::new(w).color(Color32::from_rgb(180, 83, 9)))
                            .wrap(),
                    );
                }
            });
        egui::CollapsingHeader::new("Recent files")
            .default_open(false)
            .show(ui, |ui| {
                for p in self.prefs.recent.0.clone() {
                    if ui.link(p.display().to_string()).clicked() {
                        let ctx = ui.ctx().clone();
                        self.request_open(Some(p), &ctx);
                    }
                }
            });
    }

    fn selected_field_ui(&mut self, ui: &mut egui::Ui) {
        let Some(f) = self
            .view
            .selected
            .and_then(|id| self.session.doc().fields.iter().find(|f| f.id == id))
        else {
            return;
        };
        ui.separator();
        let visiting = self.active_plan().map(|p| p.fields.as_slice());
        let word = super::words::field_word(f, &self.session.doc().profile);
        let mut heading = format!(
            "{word} {}",
            super::words::field_number(&self.session.doc().fields, visiting, f.id)
        );
        if let Some(first) = heading.get_mut(..1) {
            first.make_ascii_uppercase();
        }
        ui.heading(heading);
        ui.add(
            egui::Label::new(format!(
                "centre ({:.2}, {:.2}) mm, {:.0} × {:.0} mm, {}{}",
                f.center.x,
                f.center.y,
                f.size[0],
                f.size[1],
                super::words::count(f.geometries.len(), "stroke", "strokes"),
                if f.locked { ", locked" } else { "" }
            ))
            .wrap(),
        );
        let pose = super::words::pose_words(&f.pose, &self.session.doc().profile);
        if !pose.is_empty() {
            ui.label(format!("pose {pose}"));
        }
        if word == "region" {
            let [w, h] = self.session.doc().profile.field_mm;
            ui.add(
                egui::Label::new(
                    RichText::new(format!(
                        "Larger than the {w:.0} × {h:.0} mm scan field: marked on the fly, the \
                         stage carrying the scan field across it."
                    ))
                    .weak(),
                )
                .wrap(),
            );
        }
    }

    fn plans_ui(&mut self, ui: &mut egui::Ui) {
        ui.heading("Plans");
        if self.session.doc().plans.is_empty() {
            ui.label("none yet: run a solver");
        }
        let (mut remove, mut show) = (None, None);
        for k in 0..self.session.doc().plans.len() {
            let p = &self.session.doc().plans[k];
            let stale = self.plan_staleness(k).to_vec();
            // the name (what the plan is: algorithm, cost, motion) wraps on its own line; its
            // random seed is in its details
            let selected = self.session.active() == Some(k);
            ui.set_max_width(ui.available_width());
            if ui
                .add(egui::Button::selectable(selected, p.name.as_str()).wrap())
                .on_hover_text(format!(
                    "{}\nrandom seed {} (a solve is the same for the same seed), solved in {:.2} s",
                    p.name, p.settings.seed, p.metrics.solve_s.total
                ))
                .clicked()
            {
                show = Some(k);
            }
            ui.horizontal_wrapped(|ui| {
                let text = match p.metrics.job_time_s {
                    Some(t) => format!("job time {t:.2} s"),
                    None => format!("idle travel {:.1} mm", p.metrics.idle_mm),
                };
                ui.label(text);
                if !stale.is_empty() {
                    ui.label(RichText::new("stale").color(STALE))
                        .on_hover_text(stale_text(&stale));
                }
                if ui
                    .small_button("Remove")
                    .on_hover_text(format!("Remove {}", p.name))
                    .clicked()
                {
                    remove = Some(k);
                }
            });
        }
        if let Some(k) = show {
            self.session.show_plan(k);
        }
        if let Some(p) = remove.and_then(|k| self.session.remove_plan(k)) {
            self.panels.compare = super::CompareState {
                canvas: std::mem::take(&mut self.panels.compare.canvas),
                ..Default::default()
            };
            self.set_status(format!("removed {}", p.name), false);
        }
    }

    fn workbench_view(&mut self, ui: &mut egui::Ui) {
        if !self.has_document() {
            ui.centered_and_justified(|ui| {
                ui.label(
                    "Open an SVG, a DXF or a project (File > Open, or drag and drop a file here).",
                );
            });
            return;
        }
        let lowered = self
            .session
            .active()
            .and_then(|k| self.session.toolpaths().get(k));
        playback::controls(ui, "workbench", &mut self.panels.playback, lowered, true);
        let stale = self
            .session
            .active()
            .map_or_else(Vec::new, |k| self.plan_staleness(k).to_vec());
        let playback_t_s = lowered
            .and_then(Result::ok)
            .and_then(|_| self.panels.playback.shown_t_s());
        let canvas = workbench_canvas(
            &self.session,
            (self.view.selected, self.view.add_tool),
            self.prefs.layers,
            &stale,
            playback_t_s,
            self.canvas_revision(),
        );
        let motion = lowered.and_then(Result::ok).and_then(|l| l.motion.as_ref());
        let axes = lowered.and_then(Result::ok).and_then(|l| l.axes.as_ref());
        let plots = motion.is_some() || axes.is_some();
        let header_px = 2.0 * ui.spacing().interact_size.y;
        let plots_px = motion_plots::PLOTS_HEIGHT_PX.min(ui.available_height() * 0.4);
        let below_px = match plots {
            true if self.panels.plots_open => header_px + plots_px,
            true => header_px,
            false => 0.0,
        };
        let below = (plots, plots && self.panels.plots_open);
        if below != self.panels.plots_below {
            // the canvas changes height when the plots come or go: fit the content again
            self.panels.plots_below = below;
            self.panels.workbench.fit_requested = true;
        }
        let size = ui.available_size() - egui::Vec2::Y * below_px;
        let (_, actions) = canvas.show(ui, &mut self.panels.workbench, Some(size));
        if plots {
            motion_plots_header(ui, &mut self.panels.plots_open, motion.is_none());
        }
        if self.panels.plots_open {
            // the plan's own machine: its motion was made on it, whatever the document's is now
            let doc = self.session.doc();
            let profile = self
                .session
                .active()
                .and_then(|k| doc.plans.get(k))
                .map_or(&doc.profile, |p| &p.profile);
            if let Some(samples) = motion {
                motion_plots::show(ui, samples, profile, playback_t_s, plots_px);
            } else if let Some(samples) = axes {
                super::axis_plot::show(ui, samples, profile, playback_t_s, plots_px);
            }
        }
        let repaint = ui.ctx().clone();
        self.on_canvas(actions, &repaint);
    }
}

/// The header of the motion plots (on the fly, or the axes' speeds of a job that turns Z, A or
/// B: `axes`): shows or hides them.
fn motion_plots_header(ui: &mut egui::Ui, open: &mut bool, axes: bool) {
    let shown = *open;
    let what = if axes { "axis speeds" } else { "on the fly" };
    let text = format!(
        "Motion plots ({what}): {}",
        if shown { "hide" } else { "show" }
    );
    let hover = if axes {
        "Each axis's speed over the job as a share of its limit (of the plan shown, as it was \
         planned)"
    } else {
        "The scanner offset against the field limits and the stage speed over the job \
         (of the plan shown, as it was planned)"
    };
    if ui
        .selectable_label(shown, text)
        .on_hover_text(hover)
        .clicked()
    {
        *open = !shown;
    }
}

/// The workbench's canvas over `session`'s document and the plan shown: the field `selected`
/// and the add tool (`tools`), the canvas `layers`, the plan's staleness and the playback time.
fn workbench_canvas<'a>(
    session: &'a super::session::Session,
    (selected, add_tool): (Option<usize>, bool),
    layers: super::scene::Layers,
    stale: &'a [String],
    playback_t_s: Option<f64>,
    revision: u64,
) -> Canvas<'a> {
    let doc = session.doc();
    let plan = session.active().and_then(|k| doc.plans.get(k));
    let lowered = session.active().and_then(|k| session.toolpaths().get(k));
    Canvas {
        label: "Work area",
        geometries: &doc.geometries,
        profile: doc.reach_profile(),
        cylinder: doc.settings.cylinder,
        fields: &doc.fields,
        seams: &doc.seams.lines,
        tiling: doc.tiling.as_ref(),
        cell_max_mm: crate::fields::cell_max_mm(&doc.layers, doc.profile.field_mm),
        visiting: plan.map(|p| p.fields.as_slice()),
        // layer colours when the layers tell something apart (several, or a hatch)
        colours: (doc.layers.len() > 1 || doc.layers.iter().any(|l| l.pen.hatch.is_some()))
            .then_some(session.colours()),
        out_of_reach: session.out_of_reach(),
        paths: plan
            .zip(lowered)
            .map(|(p, lowered)| PathLayer {
                plan: p,
                lowered,
                colour: colour::PATH_A,
            })
            .into_iter()
            .collect(),
        uncovered: session.uncovered(),
        selected,
        editable: true,
        add_tool,
        layers,
        stale,
        playback_t_s,
        parts: session.part_boxes(),
        codes: session.code_boxes(),
        revision,
    }
}

impl App {
    /// The strokes larger than a scan field, said once (which they are), with what helps them
    /// as buttons: *Split at field borders* and *Mark on the fly*, each offered only when not
    /// already chosen.
    fn oversize_ui(&mut self, ui: &mut egui::Ui, large: usize) {
        use crate::document::MotionMode;
        let doc = self.session.doc();
        let [fw, fh] = doc.profile.field_mm;
        let names: Vec<String> = self
            .session
            .out_of_reach()
            .iter()
            .map(|&g| (g, &doc.geometries[g]))
            .filter(|(_, g)| crate::fields::is_oversize(g, [fw, fh]))
            .map(|(k, g)| format!("stroke {} ({})", k + 1, g.shape_words()))
            .collect();
        let more = names.len().saturating_sub(5);
        let mut list = names.into_iter().take(5).collect::<Vec<_>>().join("; ");
        if more > 0 {
            list.push_str(&format!(" and {more} more"));
        }
        let advice = oversize_advice(&doc.settings);
        ui.add(
            egui::Label::new(
                RichText::new(format!(
                    "{} (dashed purple) {} larger than the {fw} × {fh} mm scan field: {list}. \
                     {advice}",
                    super::words::count(large, "stroke", "strokes"),
                    if large == 1 { "is" } else { "are" },
                ))
                .color(colour::OUT_OF_REACH),
            )
            .wrap(),
        );
        let settings = doc.settings.clone();
        let idle = self.runtime.job.is_none();
        let repaint = ui.ctx().clone();
        ui.horizontal_wrapped(|ui| {
            if !settings.split_oversize
                && ui
                    .add_enabled(idle, egui::Button::new("Split at field borders"))
                    .on_hover_text(
                        "Cut them where fields meet and place fields on the pieces (step-and-scan)",
                    )
                    .clicked()
            {
                let s = crate::document::SolverSettings {
                    split_oversize: true,
                    ..settings.clone()
                };
                if self.execute(Command::SetSettings(Box::new(s))).is_ok() {
                    self.replace_fields(&repaint);
                }
            }
            if settings.motion == MotionMode::Step
                && ui
                    .add_enabled(idle, egui::Button::new("Mark on the fly"))
                    .on_hover_text(
                        "Mark them whole while the stage moves: the next solve plans on the fly",
                    )
                    .clicked()
            {
                let s = crate::document::SolverSettings {
                    motion: MotionMode::OnTheFly,
                    ..settings.clone()
                };
                let _ = self.execute(Command::SetSettings(Box::new(s)));
            }
        });
    }
}

/// What helps geometries larger than a scan field, in words beside the buttons of
/// [`App::oversize_ui`], never proposing what `settings` already chose.
fn oversize_advice(settings: &crate::document::SolverSettings) -> String {
    use crate::document::MotionMode;
    let flies = settings.motion != MotionMode::Step;
    match (settings.split_oversize, flies) {
        (false, false) => "Split them at field borders, or mark them on the fly:".into(),
        (false, true) => "The next solve marks them on the fly (a region carries them); to \
                          mark them step-and-scan, split them at field borders:"
            .into(),
        (true, _) => "Splitting is chosen: press \"Re-place automatically\" to cut them at \
                      field borders."
            .into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_oversize_advice_offers_only_what_is_not_chosen() {
        let mut s = crate::document::SolverSettings {
            motion: crate::document::MotionMode::Step,
            ..Default::default()
        };
        let step = oversize_advice(&s);
        assert!(step.contains("Split them") && step.contains("on the fly"));
        s.motion = crate::document::MotionMode::OnTheFly;
        let otf = oversize_advice(&s);
        assert!(otf.contains("The next solve marks them on the fly"));
        s.split_oversize = true;
        assert!(oversize_advice(&s).contains("Splitting is chosen"));
    }
}
