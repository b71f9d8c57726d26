//! Machine-profile and solver-settings editors with validated edit buffers.
//!
//! Every value is edited as text. It is checked when the operator commits it (Enter or leaving
//! the field): a value that does not parse or that the profile/settings validation rejects shows
//! an error under the field and is not applied; a valid value becomes one
//! [`Command::SetProfile`] / [`Command::SetSettings`] (so it can be undone).

use super::commands::Command;
use crate::document::{
    CostModel, FieldsMode, MachineProfile, MotionMode, SolverSettings, StageRouteKind, VertexMode,
    BUILTIN,
};
use egui::{Color32, RichText};

/// One editable value of a `T`: shown as text, parsed back when committed.
struct Spec<T> {
    label: &'static str,
    help: &'static str,
    get: fn(&T) -> String,
    set: fn(&mut T, &str) -> Result<(), String>,
}

fn num(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{}' is not a number", s.trim()))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("'{}' is not a finite number", s.trim()))
    }
}

fn count(s: &str) -> Result<u64, String> {
    s.trim()
        .parse()
        .map_err(|_| format!("'{}' is not a whole number (0 or more)", s.trim()))
}

fn fmt(v: f64) -> String {
    format!("{v}")
}

fn opt_num(s: &str) -> Result<Option<f64>, String> {
    if s.trim().is_empty() {
        Ok(None)
    } else {
        num(s).map(Some)
    }
}

fn opt_fmt(v: Option<f64>) -> String {
    v.map(fmt).unwrap_or_default()
}

macro_rules! spec {
    ($label:expr, $help:expr, |$v:ident| $get:expr, |$m:ident, $s:ident| $set:expr) => {
        Spec {
            label: $label,
            help: $help,
            get: |$v| $get,
            set: |$m, $s| {
                $set;
                Ok(())
            },
        }
    };
}

fn profile_specs() -> Vec<Spec<MachineProfile>> {
    vec![
        spec!("Name", "display name", |p| p.name.clone(), |p, s| p.name =
            s.trim().to_string()),
        spec!(
            "Stroke X (mm)",
            "base-stage travel in x: field centres range over [0, stroke]",
            |p| fmt(p.stroke_mm[0]),
            |p, s| p.stroke_mm[0] = num(s)?
        ),
        spec!(
            "Stroke Y (mm)",
            "base-stage travel in y",
            |p| fmt(p.stroke_mm[1]),
            |p, s| p.stroke_mm[1] = num(s)?
        ),
        spec!(
            "Field width (mm)",
            "scan-field size in x",
            |p| fmt(p.field_mm[0]),
            |p, s| p.field_mm[0] = num(s)?
        ),
        spec!(
            "Field height (mm)",
            "scan-field size in y",
            |p| fmt(p.field_mm[1]),
            |p, s| p.field_mm[1] = num(s)?
        ),
        spec!(
            "Base X max velocity (mm/s)",
            "",
            |p| fmt(p.axis_x.max_velocity_mm_s),
            |p, s| p.axis_x.max_velocity_mm_s = num(s)?
        ),
        spec!(
            "Base X max accel (mm/s²)",
            "",
            |p| fmt(p.axis_x.max_accel_mm_s2),
            |p, s| p.axis_x.max_accel_mm_s2 = num(s)?
        ),
        spec!(
            "Base Y max velocity (mm/s)",
            "",
            |p| fmt(p.axis_y.max_velocity_mm_s),
            |p, s| p.axis_y.max_velocity_mm_s = num(s)?
        ),
        spec!(
            "Base Y max accel (mm/s²)",
            "",
            |p| fmt(p.axis_y.max_accel_mm_s2),
            |p, s| p.axis_y.max_accel_mm_s2 = num(s)?
        ),
        spec!(
            "Scanner jump speed (mm/s)",
            "laser off",
            |p| fmt(p.scanner.jump_speed_mm_s),
            |p, s| p.scanner.jump_speed_mm_s = num(s)?
        ),
        spec!(
            "Scanner mark speed (mm/s)",
            "laser on",
            |p| fmt(p.scanner.mark_speed_mm_s),
            |p, s| p.scanner.mark_speed_mm_s = num(s)?
        ),
        spec!(
            "Laser on delay (s)",
            "",
            |p| fmt(p.laser.on_delay_s),
            |p, s| p.laser.on_delay_s = num(s)?
        ),
        spec!(
            "Laser off delay (s)",
            "",
            |p| fmt(p.laser.off_delay_s),
            |p, s| p.laser.off_delay_s = num(s)?
        ),
        spec!(
            "Jump delay (s)",
            "scanner settling after a jump",
            |p| fmt(p.laser.jump_delay_s),
            |p, s| p.laser.jump_delay_s = num(s)?
        ),
        spec!(
            "Laser on word",
            "M3 or M4",
            |p| p.gcode.laser_on.clone(),
            |p, s| p.gcode.laser_on = s.trim().to_string()
        ),
        spec!(
            "Laser off word",
            "usually M5",
            |p| p.gcode.laser_off.clone(),
            |p, s| p.gcode.laser_off = s.trim().to_string()
        ),
        spec!(
            "Power S (empty: none)",
            "written after the laser-on word",
            |p| opt_fmt(p.gcode.power),
            |p, s| p.gcode.power = opt_num(s)?
        ),
        spec!(
            "Feed (mm/min)",
            "on G1 moves",
            |p| fmt(p.gcode.feed_mm_min),
            |p, s| p.gcode.feed_mm_min = num(s)?
        ),
        spec!(
            "Decimals",
            "digits after the point in G-code",
            |p| p.gcode.decimals.to_string(),
            |p, s| p.gcode.decimals = count(s)? as usize
        ),
    ]
}

fn settings_specs() -> Vec<Spec<SolverSettings>> {
    vec![
        spec!(
            "Seed",
            "all randomised stages are deterministic for a seed",
            |t| t.seed.to_string(),
            |t, s| t.seed = count(s)?
        ),
        spec!(
            "Time limit (s, empty: none)",
            "for the ordering stage",
            |t| opt_fmt(t.time_limit_s),
            |t, s| t.time_limit_s = opt_num(s)?
        ),
        spec!(
            "Direction weight",
            "seed 000 Eq. 7 penalty weight w",
            |t| fmt(t.direction_weight),
            |t, s| t.direction_weight = num(s)?
        ),
        spec!(
            "GA population",
            "initial population size",
            |t| t.ga.population.to_string(),
            |t, s| t.ga.population = count(s)? as usize
        ),
        spec!(
            "GA population min",
            "",
            |t| t.ga.population_min.to_string(),
            |t, s| t.ga.population_min = count(s)? as usize
        ),
        spec!(
            "GA population max",
            "",
            |t| t.ga.population_max.to_string(),
            |t, s| t.ga.population_max = count(s)? as usize
        ),
        spec!(
            "GA elite fraction",
            "0 … 1",
            |t| fmt(t.ga.elite_fraction),
            |t, s| t.ga.elite_fraction = num(s)?
        ),
        spec!(
            "GA mutation rate",
            "0 … 1",
            |t| fmt(t.ga.mutation_rate),
            |t, s| t.ga.mutation_rate = num(s)?
        ),
        spec!(
            "GA stall generations",
            "stop after this many generations without improvement",
            |t| t.ga.stall_generations.to_string(),
            |t, s| t.ga.stall_generations = count(s)? as usize
        ),
    ]
}

/// Checks solver settings (the library's [`SolverSettings::validate`]), as a message.
pub fn validate_settings(s: &SolverSettings) -> Result<(), String> {
    s.validate().map_err(|e| e.to_string())
}

/// Checks a machine profile (the library's [`MachineProfile::validate`]), as a message.
pub fn validate_profile(p: &MachineProfile) -> Result<(), String> {
    p.validate().map_err(|e| e.to_string())
}

/// Lines reserved above a form for its message, so that a message never moves the fields.
const MESSAGE_LINES: f32 = 3.0;

/// Text buffers of one form, re-read whenever the value changes from elsewhere (undo, open).
struct Form<T> {
    specs: Vec<Spec<T>>,
    synced: Option<T>,
    text: Vec<String>,
    error: Vec<Option<String>>,
}

impl<T: Clone + PartialEq> Form<T> {
    fn new(specs: Vec<Spec<T>>) -> Self {
        Self {
            specs,
            synced: None,
            text: Vec::new(),
            error: Vec::new(),
        }
    }

    /// Draws the rows into a grid; returns the new value when one was committed and valid.
    fn ui(
        &mut self,
        ui: &mut egui::Ui,
        value: &T,
        validate: fn(&T) -> Result<(), String>,
    ) -> Option<T> {
        if self.synced.as_ref() != Some(value) {
            self.text = self.specs.iter().map(|s| (s.get)(value)).collect();
            self.error = vec![None; self.specs.len()];
            self.synced = Some(value.clone());
        }
        let mut out = None;
        self.message(ui);
        ui.end_row();
        for (k, spec) in self.specs.iter().enumerate() {
            let label = ui.label(spec.label);
            let bad = self.error[k].is_some();
            let mut edit = egui::TextEdit::singleline(&mut self.text[k]).desired_width(90.0);
            if bad {
                edit = edit.text_color(Color32::from_rgb(200, 30, 30));
            }
            let mut r = ui.add(edit).labelled_by(label.id);
            if !spec.help.is_empty() {
                r = r.on_hover_text(spec.help);
            }
            ui.end_row();
            // commit on Enter / leaving the field, or when set without focus (accessibility)
            if r.lost_focus() || (r.changed() && !r.has_focus()) {
                let mut candidate = value.clone();
                let result = (spec.set)(&mut candidate, &self.text[k])
                    .map_err(|e| format!("{}: {e}", spec.label))
                    .and_then(|()| validate(&candidate));
                match result {
                    Ok(()) if candidate != *value => out = Some(candidate),
                    Ok(()) => self.error[k] = None,
                    Err(e) => self.error[k] = Some(e),
                }
            }
        }
        out
    }

    /// The form's message in reserved lines spanning the grid: the rejected value's reason,
    /// or a hint.
    fn message(&self, ui: &mut egui::Ui) {
        let h = MESSAGE_LINES * ui.text_style_height(&egui::TextStyle::Body);
        let text = match self.error.iter().flatten().next() {
            Some(e) => RichText::new(e).color(Color32::from_rgb(200, 30, 30)),
            None => RichText::new("Values apply on Enter or when leaving a field.").weak(),
        };
        ui.label("");
        let (rect, _) =
            ui.allocate_exact_size(egui::vec2(MESSAGE_WIDTH_PX, h), egui::Sense::hover());
        ui.put(rect, egui::Label::new(text).wrap());
    }
}

/// Width of a form's message (the value column's edits are narrower; the label column's
/// width comes first).
const MESSAGE_WIDTH_PX: f32 = 150.0;

/// The profile and settings editors.
pub struct Editors {
    profile: Form<MachineProfile>,
    settings: Form<SolverSettings>,
    /// Last error of choosing a built-in profile.
    file_error: Option<String>,
    /// A profile file to load or save, for the window to ask a path for.
    file_request: Option<super::prompts::PathAction>,
}

impl Default for Editors {
    fn default() -> Self {
        Self {
            profile: Form::new(profile_specs()),
            settings: Form::new(settings_specs()),
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
            .any(Option::is_some)
    }

    /// A profile file to load or save that the operator asked for.
    pub fn take_file_request(&mut self) -> Option<super::prompts::PathAction> {
        self.file_request.take()
    }

    /// The machine-profile editor; returns the command for an accepted change.
    pub fn profile_ui(&mut self, ui: &mut egui::Ui, profile: &MachineProfile) -> Option<Command> {
        let mut out = None;
        ui.horizontal(|ui| {
            let label = ui.label("Built-in");
            egui::ComboBox::from_id_salt("builtin-profile")
                .selected_text("choose…")
                .show_ui(ui, |ui| {
                    for (name, _) in BUILTIN {
                        if ui.button(*name).clicked() {
                            match MachineProfile::builtin(name) {
                                Ok(p) => out = Some(p),
                                Err(e) => self.file_error = Some(e.to_string()),
                            }
                        }
                    }
                })
                .response
                .labelled_by(label.id);
        });
        ui.horizontal(|ui| {
            if ui.button("Load TOML…").clicked() {
                self.file_request = Some(super::prompts::PathAction::LoadProfile);
            }
            if ui.button("Save TOML…").clicked() {
                self.file_request = Some(super::prompts::PathAction::SaveProfile);
            }
        });
        if let Some(e) = &self.file_error {
            ui.add(egui::Label::new(RichText::new(e).color(Color32::from_rgb(200, 30, 30))).wrap());
        }
        egui::Grid::new("profile-grid")
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                if let Some(p) = self.profile.ui(ui, profile, validate_profile) {
                    out = Some(p);
                }
            });
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
        combo(
            ui,
            "Field placement",
            &mut s.fields,
            &[
                (FieldsMode::Auto, "auto (set cover)"),
                (FieldsMode::Paper, "paper (seed 000 §3.1)"),
                (FieldsMode::Greedy, "greedy (baseline)"),
            ],
        );
        combo(
            ui,
            "Start vertices",
            &mut s.vertex,
            &[
                (VertexMode::Exact, "exact (VEA + DP)"),
                (VertexMode::Vea, "VEA only"),
            ],
        );
        combo(
            ui,
            "Cost model",
            &mut s.cost_model,
            &[
                (CostModel::Time, "Job time (machine dynamics)"),
                (CostModel::Distance, "Idle distance (seed 000)"),
            ],
        )
        .on_hover_text(COST_MODEL_HELP);
        combo(ui, "Motion", &mut s.motion, MOTION_MODES).on_hover_text(MOTION_HELP);
        ui.add_enabled_ui(s.motion == MotionMode::OnTheFly, |ui| {
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
        egui::Grid::new("settings-grid")
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                if let Some(s) = self.settings.ui(ui, settings, validate_settings) {
                    out = Some(s);
                }
            });
        out.map(|s| Command::SetSettings(Box::new(s)))
    }
}

/// What the cost model means for the operator.
const COST_MODEL_HELP: &str = "What the ordering minimises.\n\
    Job time: the machine's time from the profile's dynamics (stage moves with acceleration \
    and settling, scanner jumps, laser delays); the plan is never slower than the \
    idle-distance plan.\n\
    Idle distance: the laser-off travel in mm (seed 000's objective), ignoring the machine's \
    dynamics.\n\
    Used by the next solve (HHA, HGA and baseline; as-is keeps the document order).";

/// The motion modes offered, in words.
pub const MOTION_MODES: &[(MotionMode, &str)] = &[
    (MotionMode::Step, "Step-and-scan"),
    (
        MotionMode::OnTheFly,
        "On the fly (stage moves while marking)",
    ),
];

/// What the motion modes mean for the operator.
const MOTION_HELP: &str = "How the machine moves while it marks.\n\
    Step-and-scan: the stage drives to a scan field, stops and settles, the scanner marks \
    the field, then the stage drives to the next one.\n\
    On the fly: the stage never stops; it follows a smooth route while the scanner marks, \
    keeping the laser point inside the field (less the profile's on-the-fly margin). Shapes \
    larger than the field need no splitting.\n\
    Used by the next solve; the plans' toolpaths on the canvas, the playback and the motion \
    plots are re-computed at once with this setting.";

/// The stage routes offered, in words.
pub const STAGE_ROUTES: &[(StageRouteKind, &str)] = &[
    (StageRouteKind::Taut, "Taut string (shortest)"),
    (StageRouteKind::Lsa, "Simplified pattern (seed 001 LSA)"),
    (
        StageRouteKind::CetspGa,
        "Genetic algorithm (seed 001 CETSP)",
    ),
];

/// What the stage routes mean for the operator.
const STAGE_ROUTE_HELP: &str = "How the stage's route is computed on the fly.\n\
    Taut string: per axis, the shortest route that keeps the laser point within the \
    scanner's reach, smoothed to the axes' speed and acceleration limits; the marking slows \
    where the stage cannot follow.\n\
    Simplified pattern: seed 001's benchmark, the stage follows the pattern simplified by \
    RDP and VW.\n\
    Genetic algorithm: seed 001's close-enough TSP route (slow to plan: 500 generations; \
    progress and Cancel as for the solves).\n\
    Used by the next solve.";

/// A labelled combo box; returns the combo's response.
fn combo<T: PartialEq + Copy>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    options: &[(T, &str)],
) -> egui::Response {
    ui.horizontal(|ui| {
        let l = ui.label(label);
        let current = options
            .iter()
            .find(|(v, _)| v == value)
            .map(|o| o.1)
            .unwrap_or("?");
        egui::ComboBox::from_id_salt(label)
            .selected_text(current)
            .show_ui(ui, |ui| {
                for (v, name) in options {
                    ui.selectable_value(value, *v, *name);
                }
            })
            .response
            .labelled_by(l.id)
    })
    .inner
}
