//! Questions and path fields: the unsaved-changes prompt (quit, open, new), the stale-export
//! question, and the path field offered when no native file dialog can be shown. Every file
//! action of the window (menus, toolbar, shortcuts) goes through here, so none of them can do
//! nothing silently.

use super::files::{self, ExportKind};
use super::prompt::{PathAction, Prompt, Then};
use super::App;
use crate::document::{Document, PenLibrary};
use egui::RichText;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A dialog that returns "nothing chosen" faster than this was never shown (no desktop
/// portal): no operator cancels a dialog within a fifth of a second.
const NO_DIALOG_S: Duration = Duration::from_millis(200);

/// What a prompt's answer does once the prompt is closed.
type Continuation = Box<dyn FnOnce(&mut App, &egui::Context)>;

impl App {
    /// Open (a file, or ask for one), after asking about unsaved changes.
    pub fn request_open(&mut self, path: Option<PathBuf>, ctx: &egui::Context) {
        if self.has_unsaved_changes() {
            self.panels.prompt = Some(Prompt::Unsaved(Then::Open(path)));
            return;
        }
        match path {
            Some(p) => self.open_in_background(&p, ctx),
            None => self.choose_path(PathAction::Open, ctx),
        }
    }

    /// Start an empty document, after asking about unsaved changes.
    pub fn request_new(&mut self) {
        if self.has_unsaved_changes() {
            self.panels.prompt = Some(Prompt::Unsaved(Then::New));
            return;
        }
        self.runtime.job = None;
        let empty = Document {
            profile: self.session.doc().profile.clone(),
            settings: self.session.doc().settings.clone(),
            ..Document::default()
        };
        self.session.replace(empty, None, false);
        self.refresh_view();
        self.set_status("new empty document: open an SVG or a project", false);
    }

    /// Close the window, after asking about unsaved changes.
    pub fn request_quit(&mut self, ctx: &egui::Context) {
        if self.has_unsaved_changes() && !self.view.quit_confirmed {
            self.panels.prompt = Some(Prompt::Unsaved(Then::Quit));
            return;
        }
        self.view.quit_confirmed = true;
        // eframe stores the preferences on the way out
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }

    /// Save the project (to its file, or ask where).
    pub fn request_save(&mut self, save_as: bool, ctx: &egui::Context) {
        if !self.has_document() {
            self.set_status("nothing to save: open an SVG or a project first", true);
            return;
        }
        match (self.session.project_path().map(Path::to_path_buf), save_as) {
            (Some(p), false) => {
                if let Err(e) = self.save_project(&p) {
                    self.set_status(e, true);
                }
            }
            _ => self.choose_path(PathAction::SaveProject, ctx),
        }
    }

    /// Export the plan shown (asking first when it is stale).
    pub fn request_export(&mut self, kind: ExportKind, ctx: &egui::Context) {
        match self.session.active() {
            None => self.set_status("no plan to export: run a solver first (Run HHA)", true),
            Some(k) if !self.plan_staleness(k).is_empty() => {
                self.panels.prompt = Some(Prompt::StaleExport(kind))
            }
            Some(_) => self.choose_path(PathAction::Export(kind), ctx),
        }
    }

    /// Asks for a path: the native dialog when one can be shown, else a path field.
    pub fn choose_path(&mut self, action: PathAction, ctx: &egui::Context) {
        let (title, _, ext, filter) = action.words();
        // LinuxCNC reads programs named .ngc
        let linuxcnc =
            self.session.doc().profile.gcode.mode == crate::document::GcodeMode::Linuxcnc;
        let gcode = matches!(
            action,
            PathAction::Export(ExportKind::Gcode)
                | PathAction::ResolveExport(ExportKind::Gcode)
                | PathAction::ExportAdvance
        );
        let ext = if gcode && linuxcnc { "ngc" } else { ext };
        let default_name = match action {
            PathAction::SavePens => "pens.toml".to_string(),
            PathAction::SaveProfile => "profile.toml".to_string(),
            PathAction::Export(_) | PathAction::ResolveExport(_) if gcode && linuxcnc => {
                files::default_name(self.session.doc(), "ngc")
            }
            PathAction::Export(kind) | PathAction::ResolveExport(kind) => {
                files::default_name(self.session.doc(), kind.suffix())
            }
            _ => files::default_name(self.session.doc(), ext),
        };
        let folder = match action {
            PathAction::Export(kind) | PathAction::ResolveExport(kind) => self
                .prefs
                .export_dirs
                .get(kind)
                .map(std::path::Path::to_path_buf),
            _ => None,
        }
        .or_else(|| {
            let source = self
                .session
                .doc()
                .source
                .as_deref()
                .map(std::path::Path::new)?;
            source.parent().map(std::path::Path::to_path_buf)
        });
        if self.runtime.dialogs {
            let t0 = Instant::now();
            let picked = match action {
                PathAction::Open => files::pick_open(),
                a if a.saves() => files::pick_save(filter, ext, &default_name, folder.as_deref()),
                _ => files::pick_load(filter, ext),
            };
            if let Some(p) = picked {
                self.perform(action, p, ctx);
                return;
            }
            if t0.elapsed() >= NO_DIALOG_S {
                // the operator closed the dialog
                self.set_status(format!("{title}: cancelled"), false);
                return;
            }
            self.runtime.dialogs = false;
        }
        let dir = folder.map(|d| {
            d.join(if action.saves() {
                default_name.as_str()
            } else {
                ""
            })
        });
        self.panels.prompt = Some(Prompt::Path {
            action,
            text: dir.map(|d| d.display().to_string()).unwrap_or_default(),
            note: "No file dialog can be shown on this desktop (no desktop portal is running). \
                   Type the file's path instead:"
                .into(),
        });
    }

    /// Does a file action on a chosen path.
    fn perform(&mut self, action: PathAction, path: PathBuf, ctx: &egui::Context) {
        if let PathAction::Export(kind) | PathAction::ResolveExport(kind) = action {
            // a refused export keeps its path field open, with the reason inside it
            if let Err(e) = self.check_export_path(kind, &path) {
                self.set_status(e.clone(), true);
                self.panels.prompt = Some(Prompt::Path {
                    action,
                    text: path.display().to_string(),
                    note: format!("{e}. Choose another file."),
                });
                return;
            }
        }
        let result = match action {
            PathAction::Open => {
                self.open_in_background(&path, ctx);
                Ok(())
            }
            PathAction::SaveProject => self.save_project(&path),
            PathAction::Export(kind) => {
                self.export_in_background(kind, &path, ctx);
                Ok(())
            }
            PathAction::ResolveExport(kind) => {
                self.resolve_and_export(kind, &path, ctx);
                Ok(())
            }
            PathAction::ExportAdvance => self.export_and_advance(&path, ctx),
            PathAction::LoadPens => PenLibrary::load(&path)
                .map_err(|e| e.to_string())
                .map(|lib| {
                    let mut layers = self.session.doc().layers.clone();
                    let missing = lib.apply(&mut layers);
                    self.set_layers(layers, ctx);
                    if !missing.is_empty() {
                        let msg = format!(
                            "loaded pens from {}; layers it names that the document lacks: {}",
                            path.display(),
                            missing.join(", ")
                        );
                        self.set_status(msg, false);
                    }
                }),
            PathAction::SavePens => PenLibrary::of(&self.session.doc().layers)
                .save(&path)
                .map_err(|e| e.to_string())
                .map(|()| self.set_status(format!("saved pens to {}", path.display()), false)),
            PathAction::LoadProfile => {
                crate::document::MachineProfile::load(&path.display().to_string())
                    .map_err(|e| e.to_string())
                    .and_then(|p| {
                        self.execute(super::Command::SetProfile(Box::new(p)))
                            .map(|_| ())
                    })
            }
            PathAction::SaveProfile => self
                .session
                .doc()
                .profile
                .to_toml()
                .map_err(|e| format!("the profile cannot be written as TOML: {e}"))
                .and_then(|text| {
                    crate::document::write_atomic(&path, text.as_bytes())
                        .map_err(|e| format!("{}: cannot write: {e}", path.display()))
                })
                .map(|()| self.set_status(format!("saved {}", path.display()), false)),
        };
        if let Err(e) = result {
            self.set_status(e, true);
        }
    }

    /// Continues what the unsaved-changes prompt held back.
    fn then(&mut self, then: Then, ctx: &egui::Context) {
        match then {
            // an open replaces the document only once the file has been read: until then (and
            // when the file is refused) the changes stay, still unsaved
            Then::Open(Some(p)) => self.open_in_background(&p, ctx),
            Then::Open(None) => self.choose_path(PathAction::Open, ctx),
            // the operator has answered for the current changes
            Then::Quit => {
                self.session.mark_saved(None);
                self.request_quit(ctx);
            }
            Then::New => {
                self.session.mark_saved(None);
                self.request_new();
            }
        }
    }

    /// Draws the prompt, if any, as a modal window.
    pub(super) fn prompt_ui(&mut self, ui: &mut egui::Ui) {
        let Some(mut shown) = self.panels.prompt.take() else {
            return;
        };
        let ctx = ui.ctx().clone();
        // what a stale export is asked with
        let why: Vec<String> = self
            .session
            .active()
            .map_or(&[][..], |k| self.plan_staleness(k))
            .to_vec();
        let name = self
            .active_plan()
            .map_or_else(|| "this plan".to_string(), |p| p.name.clone());
        let modal = egui::Modal::new(egui::Id::unique("galvoplan-prompt")).show(&ctx, |ui| {
            ui.set_max_width(460.0);
            let answer = match &mut shown {
                Prompt::Path { action, text, note } => path_prompt(ui, *action, text, note),
                Prompt::Unsaved(then) => unsaved_prompt(ui, then),
                Prompt::StaleExport(kind) => stale_prompt(ui, *kind, &name, &why),
            };
            ui.label(RichText::new("Esc closes this window.").small().weak());
            answer
        });
        let escaped = ui.input(|i| i.key_pressed(egui::Key::Escape));
        match modal.inner {
            None if !escaped => self.panels.prompt = Some(shown),
            Some(Answer::Then(f)) => f(self, &ctx),
            _ => {}
        }
    }
}

/// What the operator answered a prompt: close it, or close it and go on.
enum Answer {
    Close,
    Then(Continuation),
}

/// The path field for `action` (no file dialog); an answer once the path is given or the
/// operator cancels.
fn path_prompt(
    ui: &mut egui::Ui,
    action: PathAction,
    text: &mut String,
    note: &str,
) -> Option<Answer> {
    let (title, button, _, _) = action.words();
    ui.heading(title);
    ui.add(egui::Label::new(note).wrap());
    let l = ui.label("File path");
    let r = ui
        .add(
            egui::TextEdit::singleline(text)
                .desired_width(440.0)
                .hint_text("/path/to/file"),
        )
        .labelled_by(l.id);
    let enter = r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
    ui.horizontal(|ui| {
        let go = ui.button(button).clicked() || enter;
        if go && !text.trim().is_empty() {
            let p = PathBuf::from(text.trim());
            return Some(Answer::Then(Box::new(
                move |app: &mut App, ctx: &egui::Context| app.perform(action, p, ctx),
            )));
        }
        ui.button("Cancel").clicked().then_some(Answer::Close)
    })
    .inner
}

/// The unsaved-changes question before `then`.
fn unsaved_prompt(ui: &mut egui::Ui, then: &Then) -> Option<Answer> {
    ui.heading("Unsaved changes");
    ui.add(
        egui::Label::new(
            "The document has changes that are not saved in a project file \
             (scan fields, layers, plans). They are lost unless you save them.",
        )
        .wrap(),
    );
    ui.horizontal(|ui| {
        if ui.button("Save project").clicked() {
            let then = then.clone();
            return Some(Answer::Then(Box::new(
                move |app: &mut App, ctx: &egui::Context| {
                    app.request_save(false, ctx);
                    if !app.has_unsaved_changes() {
                        app.then(then, ctx);
                    }
                },
            )));
        }
        if ui.button("Discard changes").clicked() {
            let then = then.clone();
            return Some(Answer::Then(Box::new(
                move |app: &mut App, ctx: &egui::Context| app.then(then, ctx),
            )));
        }
        ui.button("Cancel").clicked().then_some(Answer::Close)
    })
    .inner
}

/// The question before exporting plan `name`, stale for the reasons `why`.
fn stale_prompt(ui: &mut egui::Ui, kind: ExportKind, name: &str, why: &[String]) -> Option<Answer> {
    ui.heading("The plan shown is stale");
    ui.add(
        egui::Label::new(format!(
            "The document changed since {name} was made. Exported as planned, \
             the file is {name} with the settings it was made with, not the \
             ones shown now:"
        ))
        .wrap(),
    );
    for w in why.iter().take(6) {
        ui.label(format!("• {w}"));
    }
    if why.len() > 6 {
        ui.label(format!("… and {} more", why.len() - 6));
    }
    let choose = |a: PathAction| {
        Some(Answer::Then(Box::new(
            move |app: &mut App, ctx: &egui::Context| app.choose_path(a, ctx),
        )))
    };
    ui.horizontal(|ui| {
        let resolve = ui
            .button("Re-solve and export")
            .on_hover_text("solve again with the current settings, then export");
        // the safe answer is the default: Enter re-solves
        if ui.memory(|m| m.focused().is_none()) {
            resolve.request_focus();
        }
        if resolve.clicked() {
            return choose(PathAction::ResolveExport(kind));
        }
        if ui.button("Export as planned").clicked() {
            return choose(PathAction::Export(kind));
        }
        ui.button("Cancel").clicked().then_some(Answer::Close)
    })
    .inner
}
