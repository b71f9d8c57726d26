//! The Tray section: the part repeated over a tray, its serial numbers, what a part will carry,
//! and *Export and advance*. A panel with its own state (the form's buffers, the part
//! previewed, the parts log's path); it reads the document and returns what the operator asked.

use super::panels::{combo, Form};
use crate::document::spec::{check_all, tray_specs, CODE_KINDS, NUMBERINGS};
use crate::document::{CodeKind, CodeSpec, Document, Ecc, Production, TraySetup, CODE_LAYER};
use egui::RichText;

/// What the operator asked of the Tray section.
#[derive(Debug, Clone, PartialEq)]
pub enum TrayAction {
    /// Make the tray with this tray and serials (in a background job, undoable).
    Set(TraySetup),
    /// Give every part these codes (in a background job, undoable).
    SetCodes(Vec<CodeSpec>),
    /// Write the program of the shown plan, log its parts and move the serials on.
    ExportAndAdvance,
}

/// One code as the Tray section edits it: its kind and the text of each value.
#[derive(Debug, Clone, PartialEq)]
struct CodeRow {
    kind: CodeKind,
    content: String,
    x: String,
    y: String,
    size: String,
    options: String,
}

impl CodeRow {
    fn of(c: &CodeSpec) -> Self {
        let o = &c.options;
        let mut opts = Vec::new();
        if o.inverted {
            opts.push("inverted".to_string());
        }
        if o.rect {
            opts.push("rect".into());
        }
        if o.gs1 {
            opts.push("gs1".into());
        }
        if o.dots {
            opts.push("dots".into());
        }
        if c.kind == CodeKind::Qr && o.ecc != Ecc::M {
            opts.push(format!("ecc={:?}", o.ecc));
        }
        Self {
            kind: c.kind,
            content: c.content.clone(),
            x: c.at_mm[0].to_string(),
            y: c.at_mm[1].to_string(),
            size: c.size_mm.to_string(),
            options: opts.join(","),
        }
    }

    /// The code, read as `--code` reads it (one parser for both).
    fn spec(&self) -> Result<CodeSpec, String> {
        let text = format!(
            "{}:{}@{},{}:{}:{}",
            self.kind,
            self.content,
            self.x.trim(),
            self.y.trim(),
            self.size.trim(),
            self.options.trim()
        );
        CodeSpec::parse(&text).map_err(|e| e.to_string())
    }
}

/// The Tray section's state.
pub struct TrayPanel {
    form: Form<TraySetup>,
    /// The codes being edited, and the document's codes they were filled from.
    codes: Vec<CodeRow>,
    codes_synced: Option<Vec<CodeSpec>>,
    /// Why the codes as typed cannot be applied.
    codes_error: Option<String>,
    /// The part whose texts the preview shows (from 1).
    preview: u32,
    /// Where *Export and advance* appends its rows (empty: beside the artwork).
    pub log_path: String,
}

impl Default for TrayPanel {
    fn default() -> Self {
        Self {
            form: Form::new(tray_specs()),
            codes: Vec::new(),
            codes_synced: None,
            codes_error: None,
            preview: 1,
            log_path: String::new(),
        }
    }
}

fn validate(p: &TraySetup) -> Result<(), String> {
    check_all(&tray_specs(), p).map_err(|e| e.to_string())?;
    p.tray.validate().map_err(|e| e.to_string())
}

/// The production the section edits: the document's, or one of its artwork as a single part.
pub fn production_or_part(doc: &Document) -> Production {
    doc.production.clone().unwrap_or_else(|| {
        Production::of_part(
            doc.artwork.clone(),
            Vec::new(),
            Production::default().chord_tol_mm,
        )
    })
}

impl TrayPanel {
    /// Draws the section; returns what the operator asked.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        doc: &Document,
        can_export: bool,
    ) -> Option<TrayAction> {
        if doc.artwork.is_empty() && doc.geometries.is_empty() {
            ui.label("Open the drawing of one part: the tray repeats it.");
            return None;
        }
        let current = doc
            .production
            .as_ref()
            .map(Production::setup)
            .unwrap_or_default();
        let mut out = None;
        if let Some(p) = self.form.ui(ui, "tray form", &current, validate) {
            out = Some(TrayAction::Set(p));
        }
        let mut numbering = current.tray.numbering;
        if combo(ui, "Numbering", &mut numbering, NUMBERINGS).changed() {
            let mut p = current.clone();
            p.tray.numbering = numbering;
            out = Some(TrayAction::Set(p));
        }
        ui.separator();
        if let Some(codes) = self.codes_ui(ui, doc) {
            out = Some(TrayAction::SetCodes(codes));
        }
        ui.separator();
        self.summary(ui, doc);
        self.preview_ui(ui, doc);
        ui.separator();
        // the file Export and advance appends to when none is typed: beside the drawing
        let default_log = doc
            .source
            .as_deref()
            .map(std::path::Path::new)
            .and_then(|p| {
                p.with_extension("parts.csv")
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
            })
            .unwrap_or_else(|| "parts.csv".into());
        ui.horizontal(|ui| {
            let l = ui.label("Parts log");
            ui.add(
                egui::TextEdit::singleline(&mut self.log_path)
                    .hint_text(default_log)
                    .desired_width(180.0),
            )
            .labelled_by(l.id)
            .on_hover_text("Export and advance appends one row per part marked to this CSV file");
        });
        let advance = ui
            .add_enabled(
                can_export && !doc.parts.is_empty(),
                egui::Button::new("Export and advance"),
            )
            .on_hover_text(
                "Write the shown plan's G-code, append its parts to the parts log and start the \
                 next tray at the serial after the last one (saved with the project)",
            )
            .on_disabled_hover_text("Solve a plan of the tray first");
        if advance.clicked() {
            out = Some(TrayAction::ExportAndAdvance);
        }
        out
    }

    /// The part's codes: kind, content (fields allowed), place and size, options; *Add a code*,
    /// *Remove*, *Apply codes*. Returns the codes to set when they are applied and read.
    fn codes_ui(&mut self, ui: &mut egui::Ui, doc: &Document) -> Option<Vec<CodeSpec>> {
        let current: Vec<CodeSpec> = doc
            .production
            .as_ref()
            .map(|p| p.codes.clone())
            .unwrap_or_default();
        if self.codes_synced.as_ref() != Some(&current) {
            self.codes = current.iter().map(CodeRow::of).collect();
            self.codes_synced = Some(current);
            self.codes_error = None;
        }
        ui.label(RichText::new("Codes on every part").strong());
        let mut remove = None;
        for (k, row) in self.codes.iter_mut().enumerate() {
            if ui.push_id(("code", k), |ui| code_row_ui(ui, row)).inner {
                remove = Some(k);
            }
            ui.separator();
        }
        if let Some(k) = remove {
            self.codes.remove(k);
        }
        let mut out = None;
        ui.horizontal(|ui| {
            if ui
                .button("Add a code")
                .on_hover_text("a DataMatrix at the part's top-left; edit it, then Apply codes")
                .clicked()
            {
                self.codes.push(CodeRow {
                    kind: CodeKind::DataMatrix,
                    content: "{serial}".into(),
                    x: "1".into(),
                    y: "1".into(),
                    size: "5".into(),
                    options: String::new(),
                });
            }
            let changed = self.codes_synced.as_ref().map(|c| c.len()) != Some(self.codes.len())
                || self
                    .codes_synced
                    .iter()
                    .flatten()
                    .zip(&self.codes)
                    .any(|(c, r)| CodeRow::of(c) != *r);
            if ui
                .add_enabled(changed, egui::Button::new("Apply codes"))
                .clicked()
            {
                match self.codes.iter().map(CodeRow::spec).collect() {
                    Ok(codes) => {
                        self.codes_error = None;
                        out = Some(codes);
                    }
                    Err(e) => self.codes_error = Some(e),
                }
            }
        });
        if let Some(e) = &self.codes_error {
            ui.add(
                egui::Label::new(RichText::new(e).color(egui::Color32::from_rgb(200, 30, 30)))
                    .wrap(),
            );
        }
        out
    }

    /// The parts, skipped cells and serials in words.
    fn summary(&self, ui: &mut egui::Ui, doc: &Document) {
        let Some(p) = &doc.production else {
            ui.label("One part: set columns and rows to repeat it.");
            return;
        };
        let marked = doc.parts.len();
        let skipped = p.tray.skip.len();
        let mut line = super::words::count(marked.max(1), "part", "parts");
        if skipped > 0 {
            line.push_str(&format!(
                " ({skipped} skipped: cells {})",
                join(&p.tray.skip)
            ));
        }
        ui.label(line);
        if let (Some(first), Some(last)) = (doc.parts.first(), doc.parts.last()) {
            ui.label(format!("Serials {} … {}", first.serial, last.serial));
            if let Some(next) = p.serial.after(marked as u32) {
                ui.label(RichText::new(format!("Next tray starts at {next}")).strong());
            }
        }
        if let Some(l) = p.logged_through {
            ui.label(RichText::new(format!("Serials up to {l} are in the parts log")).weak());
        }
    }

    /// Any part's texts, as they will be marked.
    fn preview_ui(&mut self, ui: &mut egui::Ui, doc: &Document) {
        if doc.parts.is_empty()
            || doc
                .parts
                .iter()
                .all(|p| p.texts.is_empty() && p.codes.is_empty())
        {
            return;
        }
        let n = doc.parts.len() as u32;
        self.preview = self.preview.clamp(1, n);
        ui.horizontal(|ui| {
            let l = ui.label("Preview part");
            ui.add(egui::DragValue::new(&mut self.preview).range(1..=n))
                .labelled_by(l.id);
        });
        if let Some(part) = doc.parts.get(self.preview as usize - 1) {
            for t in &part.texts {
                ui.label(RichText::new(t).monospace());
            }
            for c in &part.codes {
                ui.label(RichText::new(format!("code: {c}")).monospace());
            }
        }
    }
}

fn join(v: &[u32]) -> String {
    v.iter().map(u32::to_string).collect::<Vec<_>>().join(", ")
}

/// A tray cell as the canvas shows it: where it is, and what its part carries.
#[derive(Debug, Clone, PartialEq)]
pub struct PartBox {
    /// The part marked there (none: the cell is skipped).
    pub part: Option<u32>,
    /// The cell (row by row from 1).
    pub cell: u32,
    /// Its extent on the machine, mm.
    pub bbox: crate::geom::BBox,
    /// What hovering it tells: part, cell, serial, its texts.
    pub words: Vec<String>,
}

/// The cells of the document's tray: each marked part's extent, and the skipped cells at the
/// extent a part would have there (empty when the document is not a tray of several cells).
pub fn part_boxes(doc: &Document) -> Vec<PartBox> {
    use crate::geom::BBox;
    let Some(p) = &doc.production else {
        return Vec::new();
    };
    if p.tray.cells() < 2 || doc.parts.is_empty() {
        return Vec::new();
    }
    let mut boxes: Vec<BBox> = vec![BBox::EMPTY; doc.parts.len()];
    for g in &doc.artwork {
        if let Some(b) = (g.source.part as usize)
            .checked_sub(1)
            .and_then(|k| boxes.get_mut(k))
        {
            *b = b.union(BBox::of(&g.points));
        }
    }
    let mut out: Vec<PartBox> = doc
        .parts
        .iter()
        .zip(&boxes)
        .map(|(r, &bbox)| {
            let mut words = vec![format!(
                "part {} (cell {}, row {}, column {}): serial {}",
                r.part, r.cell, r.row, r.col, r.serial
            )];
            words.extend(r.texts.iter().map(|t| format!("  “{t}”")));
            words.extend(r.codes.iter().map(|c| format!("  code “{c}”")));
            PartBox {
                part: Some(r.part),
                cell: r.cell,
                bbox,
                words,
            }
        })
        .collect();
    // a skipped cell: the first part's extent moved by the pitch
    if let (Some(first), Some(b0)) = (doc.parts.first(), boxes.first()) {
        let at = |cell: u32| p.tray.cell_offset(cell).unwrap_or_default();
        let o0 = at(first.cell);
        for &cell in &p.tray.skip {
            let d = at(cell).minus(o0);
            let bbox = BBox {
                min_x: b0.min_x + d.x,
                min_y: b0.min_y + d.y,
                max_x: b0.max_x + d.x,
                max_y: b0.max_y + d.y,
            };
            out.push(PartBox {
                part: None,
                cell,
                bbox,
                words: vec![format!(
                    "cell {cell}: skipped (no part, no serial); right-click to mark it"
                )],
            });
        }
    }
    out
}

/// A code of a part as the canvas shows it: which code of the part, and where its marks lie.
#[derive(Debug, Clone, PartialEq)]
pub struct CodeBox {
    /// The code's index in the production's codes (from 0).
    pub code: usize,
    /// The part it is on.
    pub part: u32,
    /// The box of its marks on the machine, mm.
    pub bbox: crate::geom::BBox,
    /// What it is, in words (`DataMatrix code 1`).
    pub name: String,
}

/// Every part's codes, boxed (dragging one on the canvas moves that code on every part).
pub fn code_boxes(doc: &Document) -> Vec<CodeBox> {
    use crate::geom::BBox;
    let Some(p) = &doc.production else {
        return Vec::new();
    };
    let mut boxes: std::collections::BTreeMap<(u32, usize), BBox> = Default::default();
    for g in doc.artwork.iter().filter(|g| g.layer == CODE_LAYER) {
        // the element is "KIND code N" (`tray::expand`)
        let Some(k) = g
            .source
            .element
            .rsplit_once(" code ")
            .and_then(|(_, n)| n.parse::<usize>().ok())
            .and_then(|n| n.checked_sub(1))
        else {
            continue;
        };
        let b = boxes.entry((g.source.part, k)).or_insert(BBox::EMPTY);
        *b = b.union(BBox::of(&g.points));
    }
    boxes
        .into_iter()
        .filter_map(|((part, code), bbox)| {
            let spec = p.codes.get(code)?;
            let kind = CODE_KINDS
                .iter()
                .find(|(k, _, _)| *k == spec.kind)
                .map_or("Code", |(_, words, _)| *words);
            Some(CodeBox {
                code,
                part,
                bbox,
                name: format!("{kind} code {}", code + 1),
            })
        })
        .collect()
}

/// One code's kind, content, place, size and options; true when *Remove this code* is pressed.
fn code_row_ui(ui: &mut egui::Ui, row: &mut CodeRow) -> bool {
    combo(ui, "Code kind", &mut row.kind, CODE_KINDS);
    let text = |ui: &mut egui::Ui, label: &str, value: &mut String, hint: &str| {
        ui.horizontal(|ui| {
            let l = ui.label(label);
            ui.add(
                egui::TextEdit::singleline(value)
                    .hint_text(hint)
                    .desired_width(150.0),
            )
            .labelled_by(l.id);
        });
    };
    text(ui, "Code content", &mut row.content, "GP{serial:05}");
    text(ui, "Code X (mm)", &mut row.x, "from the part's left");
    text(ui, "Code Y (mm)", &mut row.y, "from the part's top");
    text(ui, "Code size (mm)", &mut row.size, "width");
    text(ui, "Code options", &mut row.options, "e.g. inverted");
    ui.weak("drag the code on the canvas to move it on every part");
    ui.button("Remove this code").clicked()
}
