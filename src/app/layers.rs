//! The layers panel: one block per layer (colour swatch, name, geometry count, whether it is
//! marked, mark speed, power, passes, pulse frequency, hatch settings), validated when a value
//! is committed, like the profile editor. A change that alters the geometries (enabled, hatch)
//! is made in a background job by the caller.

use super::prompt::PathAction;
use crate::document::spec::{self, Row};
use crate::document::FillShapes;
use crate::document::{ArtworkImport, Layer, MachineProfile, Pen, Place};
use crate::geom::seam::SeamForm;
use crate::hatch::{HatchSettings, HatchStyle, OutlineMode};
use egui::{Color32, RichText};

/// Red of rejected values and their messages.
const ERROR: Color32 = Color32::from_rgb(200, 30, 30);
/// Lines reserved for the message above the layers, so that a message never moves the
/// widgets under the pointer.
const MESSAGE_LINES: f32 = 3.0;

/// Width of a value's edit field, px.
const EDIT_PX: f32 = 64.0;
/// Gap between the grid's columns, px.
const GRID_GAP_PX: f32 = 6.0;

/// A text-edited number of a pen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Col {
    Speed,
    Power,
    Frequency,
    Passes,
    Spacing,
    Angle,
    Edge,
    SeamWidth,
}

/// The row a column edits: a pen's or its hatch's.
enum ColRow {
    Pen(Row<Pen>),
    Hatch(Row<HatchSettings>),
}

impl Col {
    /// Its row in the pen's or the hatch's spec table.
    fn row(self) -> ColRow {
        use spec::rows::*;
        match self {
            Col::Speed => ColRow::Pen(PEN_SPEED),
            Col::Power => ColRow::Pen(PEN_POWER),
            Col::Frequency => ColRow::Pen(PEN_FREQUENCY),
            Col::Passes => ColRow::Pen(PEN_PASSES),
            Col::SeamWidth => ColRow::Pen(PEN_SEAM_WIDTH),
            Col::Spacing => ColRow::Hatch(HATCH_SPACING),
            Col::Angle => ColRow::Hatch(HATCH_ANGLE),
            Col::Edge => ColRow::Hatch(HATCH_EDGE),
        }
    }
    /// The label, as the pen's validation words it.
    fn label(self) -> String {
        match self.row() {
            ColRow::Pen(r) => r.spec().map_or_else(String::new, |s| s.words()),
            ColRow::Hatch(r) => r.spec().map_or_else(String::new, |s| s.words()),
        }
    }
    fn get(self, p: &Pen) -> String {
        match self.row() {
            ColRow::Pen(r) => r.spec().map_or_else(String::new, |s| (s.show)(p)),
            ColRow::Hatch(r) => p
                .hatch
                .as_ref()
                .zip(r.spec())
                .map_or_else(String::new, |(h, s)| (s.show)(h)),
        }
    }
    /// Parses `text` into `p` (empty: unset, where a value may be unset). A hatch value of a
    /// pen without a hatch is refused (the grid greys it).
    fn set(self, p: &mut Pen, text: &str) -> Result<(), String> {
        // every handle resolves (spec's editor-rows test): this names one that would not
        let unknown = |key: &str| format!("no setting '{key}' in the pen's table");
        match self.row() {
            ColRow::Pen(r) => {
                let s = r.spec().ok_or_else(|| unknown(r.key))?;
                s.set_text(p, text).map_err(|e| e.to_string())
            }
            ColRow::Hatch(r) => {
                let s = r.spec().ok_or_else(|| unknown(r.key))?;
                let Some(h) = &mut p.hatch else {
                    return Err(format!("{}: this layer has no hatch", s.words()));
                };
                if !s.optional && text.trim().is_empty() {
                    return Err(format!("{} needs a value", s.words()));
                }
                s.set_text(h, text).map_err(|e| e.to_string())
            }
        }
    }
}

/// What the panel asks the window to do.
#[derive(Debug, Clone, PartialEq)]
pub enum LayerAction {
    /// A new, valid layer table.
    Set(Vec<Layer>),
    /// Load or save a pen library.
    File(PathAction),
    /// Import the artwork again with these choices (placement, hidden layers included).
    Reimport(ArtworkImport),
}

/// Edit buffers of the layers panel.
#[derive(Debug, Default)]
pub struct LayerEditor {
    synced: Option<Vec<Layer>>,
    text: Vec<Vec<String>>,
    /// The rejected value: (layer, column) and the message.
    error: Option<(usize, Col, String)>,
    /// The placement's corner as typed (x, y, mm), and the choice it was typed for.
    corner_text: Option<(Place, [String; 2])>,
}

/// The typed values, in the grid's order; the seam width (last) has a row of its own below the
/// seam's form.
const COLS: [Col; 8] = [
    Col::Speed,
    Col::Power,
    Col::Passes,
    Col::Frequency,
    Col::Spacing,
    Col::Angle,
    Col::Edge,
    Col::SeamWidth,
];

impl LayerEditor {
    /// Forgets a rejected value (the table changed).
    pub fn clear_error(&mut self) {
        self.error = None;
    }

    /// The message of the rejected value, if any.
    pub fn error(&self) -> Option<&str> {
        self.error.as_ref().map(|e| e.2.as_str())
    }

    /// Draws the panel; `counts` are (imported, marked) geometries per layer; `import` is how
    /// the artwork was imported (`None`: it cannot be imported again, e.g. its file is gone).
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        layers: &[Layer],
        counts: &[(usize, usize)],
        profile: &MachineProfile,
        import: Option<&ArtworkImport>,
        busy: Option<&str>,
    ) -> Option<LayerAction> {
        if self.synced.as_deref() != Some(layers) {
            // the table changed (a valid edit, undo, another file): nothing typed is pending
            self.error = None;
            self.text = layers
                .iter()
                .map(|l| COLS.iter().map(|c| c.get(&l.pen)).collect())
                .collect();
            self.synced = Some(layers.to_vec());
        }
        let mut out = None;
        ui.horizontal(|ui| {
            if ui
                .button("Load pens…")
                .on_hover_text("Pens by layer name from a TOML file")
                .clicked()
            {
                out = Some(LayerAction::File(PathAction::LoadPens));
            }
            if ui
                .button("Save pens…")
                .on_hover_text("The layers' pens as a TOML file")
                .clicked()
            {
                out = Some(LayerAction::File(PathAction::SavePens));
            }
        });
        self.message(ui, busy);
        if let Some(import) = import {
            if let Some(a) = self.artwork_ui(ui, import, busy.is_none()) {
                out = Some(a);
            }
            ui.separator();
        }
        if layers.is_empty() {
            ui.label("No layers: open an SVG or a project.");
        }
        for (k, layer) in layers.iter().enumerate() {
            let count = counts.get(k).copied().unwrap_or((0, 0));
            if let Some(new) = self.layer_ui(ui, k, layer, count, profile) {
                let mut table = layers.to_vec();
                table[k] = new;
                out = Some(LayerAction::Set(table));
            }
            ui.separator();
        }
        out
    }

    /// Where the artwork lies on the machine, and the layers the drawing hides (greyed, each
    /// with a button that imports it or leaves it out again).
    fn artwork_ui(
        &mut self,
        ui: &mut egui::Ui,
        import: &ArtworkImport,
        enabled: bool,
    ) -> Option<LayerAction> {
        let mut out = None;
        let again = |place: Place, included: Vec<String>| {
            Some(LayerAction::Reimport(ArtworkImport {
                place,
                hidden_layers: import.hidden_layers.clone(),
                included,
            }))
        };
        ui.add_enabled_ui(enabled, |ui| {
            ui.horizontal(|ui| {
                let label = ui.label("Placement").on_hover_text(
                    "Where the artwork goes on the machine (choosing another imports the file \
                     again): automatic keeps the file's coordinates and centres the artwork on \
                     the base stroke when it lies out of reach; centred puts the middle of its \
                     bounding box on the middle of the base stroke; corner at x, y puts its \
                     top-left corner there (mm)",
                );
                let mut choice = import.place;
                let combo = egui::ComboBox::from_id_salt("placement")
                    .selected_text(place_words(&choice))
                    .show_ui(ui, |ui| {
                        let corner = match import.place {
                            Place::Corner(xy) => Place::Corner(xy),
                            _ => Place::Corner([0.0, 0.0]),
                        };
                        for p in [Place::Auto, Place::AsIs, Place::Centre, corner] {
                            let words = place_words(&p);
                            ui.selectable_value(&mut choice, p, words);
                        }
                    });
                combo.response.labelled_by(label.id);
                if choice != import.place {
                    out = again(choice, import.included.clone());
                }
            });
            if let Place::Corner(xy) = import.place {
                if let Some(place) = self.corner_ui(ui, xy) {
                    out = again(place, import.included.clone());
                }
            }
            if let Some(action) = hidden_layers_ui(ui, import) {
                out = Some(action);
            }
        });
        out
    }

    /// The corner's x and y edits (mm); a new corner once both are numbers and one was
    /// committed.
    fn corner_ui(&mut self, ui: &mut egui::Ui, xy: [f64; 2]) -> Option<Place> {
        let current = Place::Corner(xy);
        if self.corner_text.as_ref().map(|c| c.0) != Some(current) {
            self.corner_text = Some((current, xy.map(|v| format!("{v}"))));
        }
        let (_, text) = self.corner_text.as_mut()?;
        let mut committed = false;
        ui.horizontal(|ui| {
            ui.label("top-left corner at");
            for (k, axis) in ["x", "y"].iter().enumerate() {
                let label = ui.label(*axis);
                let r = ui
                    .add(
                        egui::TextEdit::singleline(&mut text[k])
                            .desired_width(EDIT_PX)
                            .id_salt(("corner", *axis)),
                    )
                    .labelled_by(label.id);
                committed |= r.lost_focus();
            }
            ui.label("mm");
        });
        let parsed = [text[0].trim().parse::<f64>(), text[1].trim().parse::<f64>()];
        match parsed {
            [Ok(x), Ok(y)] if committed && x.is_finite() && y.is_finite() && [x, y] != xy => {
                Some(Place::Corner([x, y]))
            }
            [Ok(_), Ok(_)] => None,
            _ => {
                ui.colored_label(ERROR, "x and y must be numbers (mm)");
                None
            }
        }
    }

    /// The reserved message lines: the rejected value, the running job, or a hint.
    fn message(&self, ui: &mut egui::Ui, busy: Option<&str>) {
        let h = MESSAGE_LINES * ui.text_style_height(&egui::TextStyle::Body);
        let text = match (&self.error, busy) {
            (Some(e), _) => RichText::new(&e.2).color(ERROR),
            (None, Some(job)) => RichText::new(format!("{job}…")).italics(),
            (None, None) => RichText::new(
                "Values apply on Enter or when leaving a field; empty speed or power: the \
                 profile's.",
            )
            .weak(),
        };
        super::panels::reserved_message(ui, text, h);
    }

    fn layer_ui(
        &mut self,
        ui: &mut egui::Ui,
        k: usize,
        layer: &Layer,
        (imported, marked): (usize, usize),
        profile: &MachineProfile,
    ) -> Option<Layer> {
        let mut out = layer_header(ui, layer, (imported, marked));
        let pairs = grid_pairs(ui);
        egui::Grid::new(("layer-grid", k))
            .num_columns(2 * pairs)
            .spacing([GRID_GAP_PX, 3.0])
            .show(ui, |ui| {
                let hint = |c: Col| match c {
                    Col::Speed => format!("{}", profile.scanner.mark_speed_mm_s),
                    Col::Power => profile.gcode.power.map_or("none".into(), |p| p.to_string()),
                    // empty: inset by the hatch's spacing, shown as its value
                    Col::Edge => layer
                        .pen
                        .hatch
                        .as_ref()
                        .map_or(String::new(), |h| format!("{} (the spacing)", h.spacing_mm)),
                    _ => String::new(),
                };
                let hatched = layer.pen.hatch.is_some();
                for (n, &c) in COLS.iter().enumerate().filter(|(_, c)| **c != Col::SeamWidth) {
                    if matches!(c, Col::Spacing) {
                        if let Some(l) = hatch_style_ui(ui, k, layer) {
                            out = Some(l);
                        }
                        if !hatched {
                            break;
                        }
                    }
                    if let Some(l) = self.cell(ui, k, n, c, layer, &hint(c)) {
                        out = Some(l);
                    }
                    if (n + 1) % pairs == 0 {
                        ui.end_row();
                    }
                }
                if hatched {
                    if let Some(l) = outline_ui(ui, k, layer) {
                        out = Some(l);
                    }
                    ui.end_row();
                    if let Some(l) = shapes_ui(ui, k, layer) {
                        out = Some(l);
                    }
                    ui.end_row();
                }
                // the seam, its width and shifted passes each on a row of their own
                if let Some(l) = seam_ui(ui, k, layer) {
                    out = Some(l);
                }
                ui.end_row();
                if crate::document::spec::seam_width(&layer.pen.seam).is_some() {
                    let n = COLS.len() - 1;
                    if let Some(l) = self.cell(ui, k, n, Col::SeamWidth, layer, "") {
                        out = Some(l);
                    }
                    ui.end_row();
                }
                // always there (greyed with one pass): an edit of Passes moves no row
                let mut shift = layer.pen.shift_passes;
                ui.label("");
                if ui
                    .add_enabled(
                        layer.pen.passes > 1,
                        egui::Checkbox::new(&mut shift, "Shift seams between passes"),
                    )
                    .on_hover_text(
                        "Each pass is cut on a tiling shifted by a fraction of a cell, so no two passes meet at the same seam (more fields)",
                    )
                    .on_disabled_hover_text("with two passes or more")
                    .changed()
                {
                    let mut l = layer.clone();
                    l.pen.shift_passes = shift;
                    out = Some(l);
                }
                ui.end_row();
            });
        out
    }

    /// One labelled number; returns the changed layer when a valid value was committed.
    fn cell(
        &mut self,
        ui: &mut egui::Ui,
        k: usize,
        n: usize,
        c: Col,
        layer: &Layer,
        hint: &str,
    ) -> Option<Layer> {
        let label = ui.label(c.label());
        let bad = self.error.as_ref().is_some_and(|e| e.0 == k && e.1 == c);
        let mut edit = egui::TextEdit::singleline(&mut self.text[k][n])
            .desired_width(EDIT_PX)
            .hint_text(hint);
        if bad {
            edit = edit.text_color(ERROR);
        }
        let r = ui.add(edit).labelled_by(label.id).on_hover_text(format!(
            "{} of layer '{}'",
            c.label(),
            layer_label(&layer.name)
        ));
        if !(r.lost_focus() || (r.changed() && !r.has_focus())) {
            return None;
        }
        let mut candidate = layer.clone();
        let shown = layer_label(&layer.name);
        let result = c
            .set(&mut candidate.pen, &self.text[k][n])
            .map_err(|e| format!("Layer '{shown}': {e}"))
            .and_then(|()| {
                candidate.validate().map_err(|e| {
                    // the library names the layer by its name: the panel by its label
                    e.to_string().replace(
                        &format!("Layer '{}'", layer.name),
                        &format!("Layer '{shown}'"),
                    )
                })
            });
        match result {
            Ok(()) => {
                // a valid value: an earlier rejected one is no longer current
                if self.error.take().is_some_and(|e| (e.0, e.1) != (k, c)) {
                    self.synced = None;
                }
                (candidate != *layer).then_some(candidate)
            }
            Err(e) => {
                self.error = Some((k, c, e));
                None
            }
        }
    }
}

/// The hatch style combo (none or a style); returns the changed layer.
fn hatch_style_ui(ui: &mut egui::Ui, k: usize, layer: &Layer) -> Option<Layer> {
    let current = layer.pen.hatch.as_ref().map(|h| h.style);
    let mut chosen = current;
    let label = ui.label("Hatch");
    egui::ComboBox::from_id_salt(("hatch-style", k))
        .selected_text(current.map_or("none (outlines)", HatchStyle::name))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut chosen, None, "none (outlines)");
            for s in HatchStyle::ALL {
                ui.selectable_value(&mut chosen, Some(s), s.name());
            }
        })
        .response
        .labelled_by(label.id)
        .on_hover_text(format!(
            "Fill the closed shapes of layer '{}' with hatch lines",
            layer_label(&layer.name)
        ));
    ui.end_row();
    if chosen == current {
        return None;
    }
    let mut l = layer.clone();
    l.pen.hatch = chosen.map(|style| HatchSettings {
        style,
        ..layer
            .pen
            .hatch
            .clone()
            .unwrap_or_else(|| HatchSettings::new(style, DEFAULT_SPACING_MM))
    });
    Some(l)
}

/// Spacing of a newly chosen hatch, mm: visible on screen and quick to make.
const DEFAULT_SPACING_MM: f64 = 0.5;

/// A choice among a hatch's options as a labelled combo; returns the changed layer.
struct HatchChoice<T: 'static> {
    label: &'static str,
    id: &'static str,
    options: &'static [T],
    words: fn(T) -> &'static str,
    get: fn(&HatchSettings) -> T,
    set: fn(&mut HatchSettings, T),
    hover: Option<&'static str>,
}

impl<T: Copy + PartialEq + 'static> HatchChoice<T> {
    fn ui(&self, ui: &mut egui::Ui, k: usize, layer: &Layer) -> Option<Layer> {
        let h = layer.pen.hatch.as_ref()?;
        let current = (self.get)(h);
        let mut chosen = current;
        let label = ui.label(self.label);
        let r = egui::ComboBox::from_id_salt((self.id, k))
            .selected_text((self.words)(current))
            .show_ui(ui, |ui| {
                for &o in self.options {
                    ui.selectable_value(&mut chosen, o, (self.words)(o));
                }
            })
            .response
            .labelled_by(label.id);
        if let Some(text) = self.hover {
            r.on_hover_text(text);
        }
        (chosen != current).then(|| {
            let mut l = layer.clone();
            if let Some(h) = &mut l.pen.hatch {
                (self.set)(h, chosen);
            }
            l
        })
    }
}

/// Where a hatched layer's outlines go; returns the changed layer.
fn outline_ui(ui: &mut egui::Ui, k: usize, layer: &Layer) -> Option<Layer> {
    HatchChoice {
        label: "Outline",
        id: "hatch-outline",
        options: &[OutlineMode::Before, OutlineMode::After, OutlineMode::None],
        words: |o| match o {
            OutlineMode::Before => "before the hatch",
            OutlineMode::After => "after the hatch",
            OutlineMode::None => "not marked",
        },
        get: |h| h.outline,
        set: |h, o| h.outline = o,
        hover: None,
    }
    .ui(ui, k, layer)
}

/// Whether a hatched layer's shapes are filled together; returns the changed layer.
fn shapes_ui(ui: &mut egui::Ui, k: usize, layer: &Layer) -> Option<Layer> {
    HatchChoice {
        label: "Shapes",
        id: "hatch-shapes",
        options: &[FillShapes::Together, FillShapes::Apart],
        words: |s| match s {
            FillShapes::Together => "filled together (inner shapes are holes)",
            FillShapes::Apart => "each filled on its own",
        },
        get: |h| h.shapes,
        set: |h, s| h.shapes = s,
        hover: Some("Together: the layer's shapes that overlap or nest are filled as one region (even-odd: an inner shape is a hole), as LightBurn fills. Apart: each drawing element is filled on its own, as SVG paints it"),
    }
    .ui(ui, k, layer)
}

/// Width given to a seam form newly chosen, mm.
const DEFAULT_SEAM_MM: f64 = 0.5;

/// How the layer's strokes are cut at seams; returns the changed layer.
fn seam_ui(ui: &mut egui::Ui, k: usize, layer: &Layer) -> Option<Layer> {
    let current = layer.pen.seam;
    let width = crate::document::spec::seam_width(&current).unwrap_or(DEFAULT_SEAM_MM);
    let forms = [
        ("straight", SeamForm::Straight),
        (
            "overlap, dose kept",
            SeamForm::Overlap {
                overlap_mm: width,
                doubled: false,
            },
        ),
        (
            "overlap, marked twice",
            SeamForm::Overlap {
                overlap_mm: width,
                doubled: true,
            },
        ),
        ("interlocked", SeamForm::Interlocked { band_mm: width }),
        (
            "staggered",
            SeamForm::Staggered {
                band_mm: width,
                seed: 1,
            },
        ),
    ];
    let same_kind = |a: &SeamForm, b: &SeamForm| match (a, b) {
        (SeamForm::Overlap { doubled: x, .. }, SeamForm::Overlap { doubled: y, .. }) => x == y,
        _ => std::mem::discriminant(a) == std::mem::discriminant(b),
    };
    let shown = forms
        .iter()
        .find(|(_, f)| same_kind(f, &current))
        .map_or("straight", |(w, _)| *w);
    let mut chosen = current;
    let label = ui.label("Seam");
    egui::ComboBox::from_id_salt(("seam-form", k))
        .selected_text(shown)
        .show_ui(ui, |ui| {
            for (words, f) in forms {
                if ui.selectable_label(same_kind(&f, &current), words).clicked() {
                    chosen = f;
                }
            }
        })
        .response
        .labelled_by(label.id)
        .on_hover_text("Where artwork larger than a field is cut: straight on the seam; overlap (each side marks past the cut: alternating line by line, or twice); interlocked (cuts alternate within a band, a comb); staggered (a random offset per line within a band)");
    (chosen != current).then(|| {
        let mut l = layer.clone();
        l.pen.seam = chosen;
        l
    })
}

/// A placement in the panel's words.
pub fn place_words(place: &Place) -> String {
    match place {
        Place::Auto => "automatic".into(),
        Place::AsIs => "as in the file".into(),
        Place::Centre => "centred".into(),
        Place::Corner(_) => "corner at x, y".into(),
    }
}

pub use crate::document::{colour_word, layer_label};

/// The layers the drawing hides (greyed), each with a button that imports it or leaves it out
/// again.
fn hidden_layers_ui(ui: &mut egui::Ui, import: &ArtworkImport) -> Option<LayerAction> {
    if import.hidden_layers.is_empty() {
        return None;
    }
    let mut out = None;
    let again = |included: Vec<String>| {
        Some(LayerAction::Reimport(ArtworkImport {
            place: import.place,
            hidden_layers: import.hidden_layers.clone(),
            included,
        }))
    };
    ui.label("Layers the drawing hides:")
        .on_hover_text("Off, frozen or hidden in the file; not marked unless included");
    for hidden in &import.hidden_layers {
        let included = import
            .included
            .iter()
            .any(|n| n.eq_ignore_ascii_case(&hidden.name));
        ui.horizontal(|ui| {
            let what = format!(
                "{}: {}, {} {}",
                layer_label(&hidden.name),
                hidden.why,
                hidden.skipped,
                if hidden.skipped == 1 { "item" } else { "items" }
            );
            if included {
                ui.label(format!("{what}, marked"));
                if ui
                    .button("Leave out")
                    .on_hover_text("Import the file again without this layer")
                    .clicked()
                {
                    let rest = import
                        .included
                        .iter()
                        .filter(|n| !n.eq_ignore_ascii_case(&hidden.name))
                        .cloned()
                        .collect();
                    out = again(rest);
                }
            } else {
                ui.label(RichText::new(format!("{what}, not marked")).weak());
                if ui
                    .button("Include")
                    .on_hover_text("Import the file again with this layer, to mark it")
                    .clicked()
                {
                    let mut with = import.included.clone();
                    with.push(hidden.name.clone());
                    out = again(with);
                }
            }
        });
    }
    out
}

/// A layer's colour, its *Marked* box (a changed layer when it is ticked or unticked) and what
/// it holds (`imported` geometries or shapes, `marked` strokes with its hatch).
fn layer_header(
    ui: &mut egui::Ui,
    layer: &Layer,
    (imported, marked): (usize, usize),
) -> Option<Layer> {
    let mut out = None;
    let [r, g, b] = layer.rgb();
    let colour = Color32::from_rgb(r, g, b);
    ui.horizontal(|ui| {
        let (rect, _) = ui.allocate_exact_size(egui::vec2(14.0, 14.0), egui::Sense::hover());
        ui.painter().rect_filled(rect, 2.0, colour);
        let mut enabled = layer.pen.enabled;
        let r = ui
            .checkbox(
                &mut enabled,
                RichText::new(layer_label(&layer.name)).strong(),
            )
            .on_hover_text(format!(
                "Layer '{}'. Marked: untick to leave this layer out of the job",
                layer_label(&layer.name)
            ));
        if r.changed() {
            let mut l = layer.clone();
            l.pen.enabled = enabled;
            out = Some(l);
        }
        let words = if layer.pen.hatch.is_some() {
            format!("{imported} shapes, {marked} strokes with the hatch")
        } else {
            super::words::count(imported, "shape", "shapes")
        };
        ui.label(RichText::new(words).weak());
    });
    out
}

/// Values a row of the layer grid: two when both fit beside their labels, else one (never a
/// squeezed edit).
fn grid_pairs(ui: &egui::Ui) -> usize {
    let font = egui::TextStyle::Body.resolve(ui.style());
    let label_px = COLS
        .iter()
        .map(|c| {
            ui.painter()
                .layout_no_wrap(c.label(), font.clone(), Color32::WHITE)
                .size()
                .x
        })
        .fold(0.0, f32::max);
    let pair_px = label_px + EDIT_PX + 3.0 * GRID_GAP_PX;
    if ui.available_width() >= 2.0 * pair_px {
        2
    } else {
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_layers_are_shown_with_a_word() {
        assert_eq!(layer_label("#1f2937"), "dark grey (#1f2937)");
        assert_eq!(layer_label("#000000"), "black (#000000)");
        assert_eq!(layer_label("outline"), "outline");
        assert_eq!(layer_label("#12345"), "#12345");
        for (hex, word) in [
            ("#ffffff", "white"),
            ("#808080", "grey"),
            ("#d62728", "red"),
            ("#ff0000", "red"),
            ("#8b0000", "dark red"),
            ("#1f77b4", "blue"),
            ("#0000ff", "blue"),
            ("#2ca02c", "green"),
            ("#15803d", "green"),
            ("#047857", "dark green"),
            ("#9467bd", "purple"),
            ("#ff7f0e", "orange"),
            ("#8c564b", "brown"),
            ("#e377c2", "pink"),
            ("#ff00ff", "magenta"),
            ("#17becf", "cyan"),
            ("#ffff00", "yellow"),
            ("#add8e6", "light blue"),
        ] {
            let rgb = crate::document::parse_colour(hex).unwrap_or_default();
            assert_eq!(colour_word(rgb), word, "{hex}");
        }
    }
}
