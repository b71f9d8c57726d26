//! The desktop GUI (feature `gui`): the operator's workbench around a [`Document`].
//!
//! The GUI only draws and sends commands to the document; the planning itself is the same
//! library code the CLI runs.

mod canvas;

pub use canvas::{Canvas, View};

use crate::document::{Document, MachineProfile, Plan, SolverSettings};
use crate::import::ImportOptions;
use crate::job::JobCtx;
use crate::pipeline::{load_svg, plan_document};
use std::path::{Path, PathBuf};

/// Opens the main window, with `file` loaded when given.
pub fn run(file: Option<PathBuf>) -> anyhow::Result<()> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("galvoplan")
            .with_inner_size([1400.0, 900.0]),
        ..Default::default()
    };
    eframe::run_native(
        "galvoplan",
        options,
        Box::new(move |_cc| {
            let mut app = App::default();
            if let Some(f) = file {
                app.open(&f);
            }
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| anyhow::anyhow!("cannot open the window: {e}"))
}

/// Application state.
#[derive(Default)]
pub struct App {
    /// The open document, if any.
    pub doc: Option<Document>,
    /// The latest plan.
    pub plan: Option<Plan>,
    /// Status or error line.
    pub status: String,
    /// Canvas view (pan and zoom).
    pub view: View,
}

impl App {
    /// Loads an SVG, replacing the current document; errors go to the status line.
    pub fn open(&mut self, path: &Path) {
        match load_svg(
            path,
            MachineProfile::default(),
            SolverSettings::default(),
            &ImportOptions::default(),
        ) {
            Ok((doc, _)) => {
                self.status = format!(
                    "{}: {} geometries, {} warnings",
                    path.display(),
                    doc.geometries.len(),
                    doc.warnings.len()
                );
                self.doc = Some(doc);
                self.plan = None;
                self.view = View::default();
            }
            Err(e) => self.status = e.to_string(),
        }
    }

    /// Plans the open document with its settings.
    pub fn plan(&mut self) {
        if let Some(doc) = &mut self.doc {
            match plan_document(doc, &JobCtx::default()) {
                Ok(p) => {
                    self.status = format!(
                        "{} fields, idle {:.1} mm, base {:.1} mm",
                        p.metrics.fields, p.metrics.idle_mm, p.metrics.base_mm
                    );
                    self.plan = Some(p);
                }
                Err(e) => self.status = e.to_string(),
            }
        }
    }

    /// Draws one frame.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        egui::Panel::top("top").show(ui, |ui| {
            ui.horizontal(|ui| {
                if ui.button("Open SVG…").clicked() {
                    if let Some(p) = rfd::FileDialog::new()
                        .add_filter("SVG", &["svg", "svgz"])
                        .pick_file()
                    {
                        self.open(&p);
                    }
                }
                if ui
                    .add_enabled(self.doc.is_some(), egui::Button::new("Plan"))
                    .clicked()
                {
                    self.plan();
                }
                ui.label(&self.status);
            });
        });
        let dropped: Vec<PathBuf> = ui.ctx().input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        if let Some(p) = dropped.first() {
            self.open(p);
        }
        egui::CentralPanel::default().show(ui, |ui| {
            if let Some(doc) = &self.doc {
                Canvas {
                    doc,
                    plan: self.plan.as_ref(),
                }
                .show(ui, &mut self.view);
            } else {
                ui.centered_and_justified(|ui| {
                    ui.label("Open an SVG (button or drag and drop) to start.");
                });
            }
        });
    }
}

impl eframe::App for App {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        App::ui(self, ui);
    }
}
