//! Machine-profile and solver-settings editors with validated edit buffers.
//!
//! Every value is edited as text. It is checked when the operator commits it (Enter or leaving
//! the field): a value that does not parse or that the profile/settings validation rejects shows
//! an error under the field and is not applied; a valid value becomes one
//! [`Command::SetProfile`] / [`Command::SetSettings`] (so it can be undone).

use super::commands::Command;
use crate::document::spec::{
    self, Choice, FieldSpec, Rule, CONTROLLERS, COST_MODELS, FIELD_PLACEMENTS, GCODE_DIALECTS,
    MOTION_MODES, STAGE_ROUTES, START_POINTS,
};
use crate::document::{ControllerKind, GcodeMode, MachineProfile, SolverSettings, BUILTIN};
use egui::{Color32, RichText};

/// The profile editor's rows: every value of the profile's table that is typed.
fn profile_specs() -> Vec<FieldSpec<MachineProfile>> {
    spec::profile_specs()
        .into_iter()
        .filter(|s| s.rule != Rule::Choice)
        .collect()
}

/// The settings editor's typed rows (the choices have controls of their own).
fn settings_specs() -> Vec<FieldSpec<SolverSettings>> {
    spec::settings_specs()
        .into_iter()
        .filter(|s| s.rule != Rule::Choice)
        .collect()
}

/// Checks solver settings (the library's [`SolverSettings::validate`]), as a message.
pub fn validate_settings(s: &SolverSettings) -> Result<(), String> {
    s.validate().map_err(|e| e.to_string())
}

/// Checks a machine profile (the library's [`MachineProfile::validate`]), as a message.
pub fn validate_profile(p: &MachineProfile) -> Result<(), String> {
    p.validate().map_err(|e| e.to_string())
}

/// Red of rejected values and their messages.
const ERROR: Color32 = Color32::from_rgb(200, 30, 30);
/// Width of a number's edit field, px.
const NARROW_EDIT_PX: f32 = 90.0;

/// Lines reserved above a form for its message, so that a message never moves the fields.
const MESSAGE_LINES: f32 = 3.0;

/// Text buffers of one form, re-read whenever the value changes from elsewhere (undo, open).
pub(super) struct Form<T> {
    specs: Vec<FieldSpec<T>>,
    synced: Option<T>,
    text: Vec<String>,
    error: Vec<Option<String>>,
    /// Whether a row's value is used by the value as it stands (a row that is not is greyed).
    applies: fn(&FieldSpec<T>, &T) -> bool,
    /// Whether a row belongs to the value at all (a machine's axis rows): rows that do not are
    /// left out.
    present: fn(&FieldSpec<T>, &T) -> bool,
}

impl<T: Clone + PartialEq> Form<T> {
    pub(super) fn new(specs: Vec<FieldSpec<T>>) -> Self {
        Self {
            specs,
            synced: None,
            text: Vec::new(),
            error: Vec::new(),
            applies: |_, _| true,
            present: |_, _| true,
        }
    }

    /// Draws the form: its message, the free-text rows (a name) across the panel, then the
    /// other rows in a grid; returns the new value when one was committed and valid.
    pub(super) fn ui(
        &mut self,
        ui: &mut egui::Ui,
        grid_id: &str,
        value: &T,
        validate: fn(&T) -> Result<(), String>,
    ) -> Option<T> {
        if self.synced.as_ref() != Some(value) {
            self.text = self.specs.iter().map(|s| (s.show)(value)).collect();
            self.error = vec![None; self.specs.len()];
            self.synced = Some(value.clone());
        }
        self.message(ui);
        let mut out = None;
        let mut valid_commit = None;
        let wide: Vec<bool> = self.specs.iter().map(is_wide).collect();
        for k in (0..self.specs.len()).filter(|&k| wide[k]) {
            // free text wraps across the panel's width, so that none of it is hidden
            let label = ui.label(self.specs[k].words());
            let (bad, help) = (self.error[k].is_some(), self.specs[k].help);
            let edit = egui::TextEdit::multiline(&mut self.text[k])
                .desired_rows(1)
                .desired_width(f32::INFINITY)
                .return_key(None);
            let r = add_edit(ui, edit, bad, help, label.id, true);
            if r.has_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                // Enter commits, as in the one-line fields
                r.surrender_focus();
            }
            self.commit(k, &r, value, validate, &mut out, &mut valid_commit);
        }
        egui::Grid::new(grid_id)
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                let present = |k: &usize| (self.present)(&self.specs[*k], value);
                let shown: Vec<usize> = (0..self.specs.len())
                    .filter(|&k| !wide[k])
                    .filter(present)
                    .collect();
                for k in shown {
                    let label = ui.label(self.specs[k].words());
                    let (bad, help) = (self.error[k].is_some(), self.specs[k].help);
                    let edit =
                        egui::TextEdit::singleline(&mut self.text[k]).desired_width(NARROW_EDIT_PX);
                    let used = (self.applies)(&self.specs[k], value);
                    let r = add_edit(ui, edit, bad, help, label.id, used);
                    ui.end_row();
                    self.commit(k, &r, value, validate, &mut out, &mut valid_commit);
                }
            });
        if let Some(k) = valid_commit {
            // a valid value: a value rejected earlier is no longer current; its text goes back
            // to the value applied (the whole form is read again when the value changes)
            for (j, e) in self.error.iter_mut().enumerate() {
                if j != k && e.take().is_some() {
                    self.text[j] = (self.specs[j].show)(value);
                }
            }
            self.error[k] = None;
        }
        out
    }

    /// Checks row `k`'s text when it is committed (Enter, leaving the field, or set without
    /// focus by accessibility): a valid new value goes to `out`, a rejected one is kept with
    /// its reason.
    fn commit(
        &mut self,
        k: usize,
        r: &egui::Response,
        value: &T,
        validate: fn(&T) -> Result<(), String>,
        out: &mut Option<T>,
        valid_commit: &mut Option<usize>,
    ) {
        if !(r.lost_focus() || (r.changed() && !r.has_focus())) {
            return;
        }
        let mut candidate = value.clone();
        let result = self.specs[k]
            .set_text(&mut candidate, &self.text[k])
            .map_err(|e| e.to_string())
            .and_then(|()| validate(&candidate));
        match result {
            Ok(()) => {
                *valid_commit = Some(k);
                if candidate != *value {
                    *out = Some(candidate);
                }
            }
            Err(e) => self.error[k] = Some(e),
        }
    }

    /// The form's message in reserved lines across the panel: the rejected value's reason,
    /// or a hint.
    fn message(&self, ui: &mut egui::Ui) {
        let h = MESSAGE_LINES * ui.text_style_height(&egui::TextStyle::Body);
        let text = match self.error.iter().flatten().next() {
            Some(e) => RichText::new(e).color(ERROR),
            None => RichText::new("Values apply on Enter or when leaving a field.").weak(),
        };
        reserved_message(ui, text, h);
    }
}

/// A message in a band `height_px` tall across the panel, wrapped and left-aligned from its
/// top: the band stays when the message changes, so that nothing below it moves.
pub(super) fn reserved_message(ui: &mut egui::Ui, text: RichText, height_px: f32) {
    let size = egui::vec2(ui.available_width(), height_px);
    ui.allocate_ui_with_layout(size, egui::Layout::top_down(egui::Align::LEFT), |ui| {
        ui.set_min_size(size);
        ui.add(egui::Label::new(text).wrap());
    });
}

/// Adds a row's edit (red while its value is rejected), labelled, with its help; greyed when
/// the value is not `used`.
fn add_edit(
    ui: &mut egui::Ui,
    edit: egui::TextEdit<'_>,
    bad: bool,
    help: &str,
    label: egui::Id,
    used: bool,
) -> egui::Response {
    let edit = if bad { edit.text_color(ERROR) } else { edit };
    let r = ui
        .add_enabled(used, edit)
        .labelled_by(label)
        .on_disabled_hover_text(format!(
            "Not used with this profile's G-code dialect and controller. {help}"
        ));
    match help {
        "" => r,
        help => r.on_hover_text(help),
    }
}

/// True for a free-text row (a name): it gets the panel's width, wrapped.
fn is_wide<T>(spec: &FieldSpec<T>) -> bool {
    spec.rule == Rule::AnyText && spec.key == spec::rows::PROFILE_NAME.key
}

/// The profile and settings editors.
pub struct Editors {
    profile: Form<MachineProfile>,
    settings: Form<SolverSettings>,
    /// The Cylinder section's diameter.
    cylinder: Form<SolverSettings>,
    /// Last error of choosing a built-in profile.
    file_error: Option<String>,
    /// A profile file to load or save, for the window to ask a path for.
    file_request: Option<super::prompt::PathAction>,
}

impl Default for Editors {
    fn default() -> Self {
        Self {
            profile: Form {
                applies: spec::profile_row_applies,
                present: spec::profile_row_present,
                ..Form::new(profile_specs())
            },
            settings: Form::new(settings_specs()),
            cylinder: Form::new(spec::cylinder_specs()),
            file_error: None,
            file_request: None,
        }
    }
}

impl Editors {
    /// True when some field holds a rejected value.
    pub fn has_errors(&self) -> bool {
        self.profile
            .error
            .iter()
            .chain(&self.settings.error)
            .chain(&self.cylinder.error)
            .any(Option::is_some)
    }

    /// The Cylinder section: the diameter, and what the machine makes of it in words
    /// (`words`); returns the command for an accepted change.
    pub fn cylinder_ui(
        &mut self,
        ui: &mut egui::Ui,
        settings: &SolverSettings,
        words: &str,
    ) -> Option<Command> {
        ui.add(egui::Label::new(words).wrap());
        ui.add_space(4.0);
        self.cylinder
            .ui(ui, "cylinder-grid", settings, validate_settings)
            .map(|s| Command::SetSettings(Box::new(s)))
    }

    /// A profile file to load or save that the operator asked for.
    pub fn take_file_request(&mut self) -> Option<super::prompt::PathAction> {
        self.file_request.take()
    }

    /// The machine-profile editor; returns the command for an accepted change.
    pub fn profile_ui(&mut self, ui: &mut egui::Ui, profile: &MachineProfile) -> Option<Command> {
        let mut out = None;
        ui.horizontal(|ui| {
            let label = ui.label("Machine");
            let current = builtin_words(profile);
            egui::ComboBox::from_id_salt("builtin-profile")
                .selected_text(current)
                .wrap()
                .show_ui(ui, |ui| {
                    for (key, _) in BUILTIN {
                        // the machine by its name; the command line's key on hover
                        let Ok(p) = MachineProfile::builtin(key) else {
                            continue;
                        };
                        if ui
                            .button(p.name.as_str())
                            .on_hover_text(format!("built in: --profile {key}"))
                            .clicked()
                        {
                            out = Some(p);
                        }
                    }
                })
                .response
                .labelled_by(label.id);
        });
        let mut p = profile.clone();
        combo(ui, "G-code dialect", &mut p.gcode.mode, GCODE_DIALECTS);
        combo(ui, "Controller", &mut p.controller.kind, CONTROLLERS);
        if p.gcode.mode != profile.gcode.mode && p.gcode.mode != GcodeMode::Linuxcnc {
            // LinuxCNC's time law times only LinuxCNC's program
            p.controller.kind = ControllerKind::Ideal;
        }
        if p != *profile {
            match validate_profile(&p) {
                Ok(()) => {
                    self.file_error = None;
                    out = Some(p);
                }
                Err(e) => self.file_error = Some(e),
            }
        }
        ui.horizontal(|ui| {
            if ui.button("Load TOML…").clicked() {
                self.file_request = Some(super::prompt::PathAction::LoadProfile);
            }
            if ui.button("Save TOML…").clicked() {
                self.file_request = Some(super::prompt::PathAction::SaveProfile);
            }
        });
        if let Some(e) = &self.file_error {
            ui.add(egui::Label::new(RichText::new(e).color(ERROR)).wrap());
        }
        if let Some(p) = self
            .profile
            .ui(ui, "profile-grid", profile, validate_profile)
        {
            out = Some(p);
        }
        let mut flip = profile.gcode.flip_y;
        if ui
            .checkbox(&mut flip, "Flip Y in G-code (y-up machine)")
            .changed()
        {
            let mut p = profile.clone();
            p.gcode.flip_y = flip;
            out = Some(p);
        }
        out.map(|p| Command::SetProfile(Box::new(p)))
    }

    /// The solver-settings editor; returns the command for an accepted change.
    pub fn settings_ui(&mut self, ui: &mut egui::Ui, settings: &SolverSettings) -> Option<Command> {
        let mut s = settings.clone();
        combo(ui, "Field placement", &mut s.fields, FIELD_PLACEMENTS).on_hover_text(FIELDS_HELP);
        combo(ui, "Start points", &mut s.vertex, START_POINTS).on_hover_text(VERTEX_HELP);
        combo(ui, "Cost model", &mut s.cost_model, COST_MODELS).on_hover_text(COST_MODEL_HELP);
        combo(ui, "Motion", &mut s.motion, MOTION_MODES).on_hover_text(MOTION_HELP);
        ui.add_enabled_ui(s.motion.may_fly(), |ui| {
            combo(ui, "Stage route", &mut s.stage_route, STAGE_ROUTES)
                .on_hover_text(STAGE_ROUTE_HELP)
                .on_disabled_hover_text("Only used on the fly: step-and-scan has no route.");
        });
        ui.checkbox(&mut s.hha_improve, "HHA local search and alternation");
        ui.checkbox(
            &mut s.split_oversize,
            "Split oversize geometries (on re-place)",
        );
        ui.checkbox(&mut s.ga.seed_with_hha, "Seed the GA with the HHA plan");
        let mut out = (s != *settings).then_some(s);
        if let Some(s) = self
            .settings
            .ui(ui, "settings-grid", settings, validate_settings)
        {
            out = Some(s);
        }
        out.map(|s| Command::SetSettings(Box::new(s)))
    }
}

/// What the field placements mean for the operator.
const FIELDS_HELP: &str = "How scan fields are placed when a file is opened or \
    \"Re-place automatically\" is pressed (locked fields stay).";

/// What the start points mean for the operator.
const VERTEX_HELP: &str = "Where the laser starts each closed shape and which end of an open \
    one it starts from. Used by the next solve.";

/// What the cost model means for the operator.
const COST_MODEL_HELP: &str = "What the ordering minimises.\n\
    Job time: the machine's time from the profile's dynamics (stage moves with acceleration \
    and settling, scanner jumps, laser delays); the plan is never slower than the \
    idle-distance plan.\n\
    Idle travel distance: the laser-off travel in mm, ignoring the machine's dynamics.\n\
    Used by the next solve (HHA, HGA and baseline; as-is keeps the document order).";

/// What the motion modes mean for the operator.
const MOTION_HELP: &str = "How the machine moves while it marks.\n\
    Step-and-scan: the stage drives to a scan field, stops and settles, the scanner marks \
    the field, then the stage drives to the next one.\n\
    On the fly: the stage never stops; it follows a smooth route while the scanner marks, \
    keeping the laser point inside the field (less the profile's on-the-fly margin). Shapes \
    larger than the field are marked whole or cut at field borders, whichever is faster.\n\
    Automatic: plans both and keeps the shorter job time (the plan is named for the motion \
    it chose); planning takes about twice as long.\n\
    Used by the next solve; a plan made already keeps the motion it was planned for (its \
    path, playback and motion plots), marked stale.";

/// What the stage routes mean for the operator.
const STAGE_ROUTE_HELP: &str = "How the stage's route is planned on the fly.\n\
    Tracked route: the stage follows the laser point within the scanner's reach as its \
    speed and acceleration limits allow; the scanner waits between marks only where the \
    stage cannot keep up, and where it would fall behind at almost every mark (a very small \
    field) the shortest route through the reach takes over.\n\
    Follow a simplified path of the marks: the stage follows the pattern's points, thinned \
    out by line simplification (a published benchmark route).\n\
    Genetic algorithm route: a route through circles around the marks, searched by a \
    genetic algorithm (a published benchmark route); slow to plan: 500 generations, with \
    a progress bar and Cancel.\n\
    Used by the next solve.";

/// A labelled combo box, each option with its hover text; returns the combo's response.
pub(super) fn combo<T: PartialEq + Copy>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    options: &[Choice<T>],
) -> egui::Response {
    ui.horizontal(|ui| {
        let l = ui.label(label);
        let current = options
            .iter()
            .find(|(v, ..)| v == value)
            .map_or("?", |o| o.1);
        egui::ComboBox::from_id_salt(label)
            .selected_text(current)
            // a narrow panel wraps the choice's words rather than cutting them
            .wrap()
            .show_ui(ui, |ui| {
                for (v, name, hover) in options {
                    ui.selectable_value(value, *v, *name).on_hover_text(*hover);
                }
            })
            .response
            .labelled_by(l.id)
    })
    .inner
}

/// What the machine picker shows for `profile`: the built-in machine it equals, by its name;
/// that name with "edited" when it carries a built-in's name but other values; else the
/// profile's own name, said to be the operator's.
pub fn builtin_words(profile: &MachineProfile) -> String {
    let builtins: Vec<MachineProfile> = BUILTIN
        .iter()
        .filter_map(|(key, _)| MachineProfile::builtin(key).ok())
        .collect();
    if builtins.iter().any(|b| b == profile) {
        return profile.name.clone();
    }
    if builtins.iter().any(|b| b.name == profile.name) {
        format!("{}, edited", profile.name)
    } else {
        format!("{} (loaded or edited)", profile.name)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::document::spec::profile_row_applies;

    #[test]
    fn rows_the_dialect_or_controller_does_not_use_are_greyed() {
        let specs = spec::profile_specs();
        let row = |key: &str| specs.iter().find(|s| s.key == key).unwrap();
        let seed = MachineProfile::default();
        let lcnc = MachineProfile::builtin("linuxcnc").unwrap();
        for key in [
            "gcode.laser_output",
            "gcode.path_tol_mm",
            "controller.servo_period_s",
        ] {
            assert!(!profile_row_applies(row(key), &seed), "{key}");
            assert!(profile_row_applies(row(key), &lcnc), "{key}");
        }
        for key in ["gcode.laser_on", "gcode.laser_off", "gcode.feed_mm_min"] {
            assert!(profile_row_applies(row(key), &seed), "{key}");
            assert!(!profile_row_applies(row(key), &lcnc), "{key}");
        }
        assert!(profile_row_applies(row("scanner.mark_speed_mm_s"), &lcnc));
        // the dialect and the controller are chosen from lists, with words for every value
        for (_, words, help) in GCODE_DIALECTS {
            assert!(!words.is_empty() && !help.is_empty());
        }
        assert_eq!(GCODE_DIALECTS.len(), 3);
        assert_eq!(CONTROLLERS.len(), 2);
    }
}
