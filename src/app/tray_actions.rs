//! What the window does for the Tray section: makes the tray again (a background job, one
//! undoable step), skips cells, moves codes, and *Export and advance* (writes the program, logs
//! the parts, moves the serials on).

use super::tray_panel::{production_or_part, TrayAction};
use crate::document::{Production, TraySetup};

impl super::App {
    /// The Tray section and what it asks.
    pub(super) fn tray_ui(&mut self, ui: &mut egui::Ui) {
        let can_export = self
            .session
            .active()
            .is_some_and(|k| self.plan_staleness(k).is_empty());
        match self.panels.tray.ui(ui, self.session.doc(), can_export) {
            Some(TrayAction::Set(setup)) => self.set_tray(setup, ui.ctx()),
            Some(TrayAction::SetCodes(codes)) => {
                let what = match codes.len() {
                    0 => "remove the codes".to_string(),
                    1 => "set the part's code".to_string(),
                    n => format!("set the part's {n} codes"),
                };
                self.remake_tray(what, ui.ctx(), move |p| p.codes = codes);
            }
            Some(TrayAction::ExportAndAdvance) => {
                let ctx = ui.ctx().clone();
                self.choose_path(super::PathAction::ExportAdvance, &ctx);
            }
            None => {}
        }
    }

    /// Makes the tray with `setup` (the part repeated, its texts shaped per part, geometries
    /// made and fields placed again) in a background job, undoable when it ends.
    pub fn set_tray(&mut self, setup: TraySetup, repaint: &egui::Context) {
        let logged = self
            .session
            .doc()
            .production
            .as_ref()
            .and_then(|p| p.logged_through);
        if let Some(l) = logged.filter(|&l| setup.serial.start <= l) {
            self.set_status(
                format!(
                    "cannot start the tray at serial {}: serials up to {l} are in the parts log \
                     and are never handed out again",
                    setup.serial.start
                ),
                true,
            );
            return;
        }
        let what = format!(
            "set the tray: {} × {} parts at {} × {} mm",
            setup.tray.cols, setup.tray.rows, setup.tray.pitch_mm[0], setup.tray.pitch_mm[1]
        );
        self.remake_tray(what, repaint, move |p| {
            p.tray = setup.tray;
            p.serial = setup.serial;
        });
    }

    /// Changes the production (`change`), then makes the tray again (the part repeated, texts
    /// and codes made per part, geometries made and fields placed again) in a background job,
    /// undoable as `what` when it ends.
    fn remake_tray(
        &mut self,
        what: String,
        repaint: &egui::Context,
        change: impl FnOnce(&mut Production),
    ) {
        let mut work = self.session.doc().clone();
        let mut p = production_or_part(&work);
        change(&mut p);
        work.production = Some(p);
        self.start_job(what.clone(), "tray", repaint, move |ctx| {
            use crate::pipeline::{derive_geometries, expand_production, place_what_fits};
            expand_production(&mut work).map_err(|e| super::words::gui_error(&e))?;
            derive_geometries(&mut work, ctx).map_err(|e| super::words::gui_error(&e))?;
            let problem = match place_what_fits(&mut work, ctx) {
                Ok(_) => None,
                Err(e) if ctx.is_cancelled() => return Err(format!("cancelled ({e})")),
                Err(e) => {
                    work.fields.retain(|f| f.locked);
                    Some(super::words::gui_error(&e))
                }
            };
            Ok(super::jobs::JobResult::Placed {
                doc: Box::new(work),
                what,
                problem,
                refit: true,
            })
        });
    }

    /// Moves code `code` of the part by `by` (mm, rounded to 0.01 mm) on every part, through a
    /// background job like any tray change (undoable when it ends).
    pub fn move_code(&mut self, code: usize, by: crate::geom::Pt, repaint: &egui::Context) {
        let Some(spec) = self
            .session
            .doc()
            .production
            .as_ref()
            .and_then(|p| p.codes.get(code))
        else {
            return;
        };
        let round = |v: f64| (v * 100.0).round() / 100.0;
        let at = [round(spec.at_mm[0] + by.x), round(spec.at_mm[1] + by.y)];
        let what = format!(
            "move code {} to ({}, {}) mm from the part's top-left",
            code + 1,
            at[0],
            at[1]
        );
        self.remake_tray(what, repaint, move |p| {
            if let Some(c) = p.codes.get_mut(code) {
                c.at_mm = at;
            }
        });
    }

    /// Leaves a tray cell out, or marks it again (`skip`), through [`super::App::set_tray`].
    pub fn skip_cell(&mut self, cell: u32, skip: bool, repaint: &egui::Context) {
        let Some(p) = &self.session.doc().production else {
            return;
        };
        let mut setup = p.setup();
        setup.tray.skip.retain(|&c| c != cell);
        if skip {
            setup.tray.skip.push(cell);
            setup.tray.skip.sort_unstable();
        }
        self.set_tray(setup, repaint);
    }

    /// The parts log *Export and advance* appends to: the section's path, else
    /// `NAME.parts.csv` beside the drawing (or beside the program).
    pub fn parts_log_path(&self, program: &std::path::Path) -> std::path::PathBuf {
        let typed = self.panels.tray.log_path.trim();
        if !typed.is_empty() {
            return std::path::PathBuf::from(typed);
        }
        let base = self
            .session
            .doc()
            .source
            .as_deref()
            .map(std::path::Path::new)
            .unwrap_or(program);
        base.with_extension("parts.csv")
    }

    /// *Export and advance*: writes the shown plan's G-code to `path`, appends its parts to the
    /// parts log, starts the next tray at the serial after the last (an edit that cannot be
    /// undone: those serials are on record), saves the project where it has a file, and makes
    /// the next tray's texts in a background job.
    pub fn export_and_advance(
        &mut self,
        path: &std::path::Path,
        repaint: &egui::Context,
    ) -> Result<(), String> {
        let k = self
            .session
            .active()
            .ok_or("no plan to export: run a solver first")?;
        if !self.plan_staleness(k).is_empty() {
            return Err("the plan is stale: solve the tray again before marking it".into());
        }
        let plan = &self.session.doc().plans[k];
        let (first, last) = match (plan.parts.first(), plan.parts.last()) {
            (Some(f), Some(l)) => (f.serial, l.serial),
            _ => return Err("the plan marks no tray: set a tray and solve it".into()),
        };
        let parts = plan.parts.clone();
        let production = self
            .session
            .doc()
            .production
            .as_ref()
            .ok_or("the document is not a tray")?;
        if production.logged_through.is_some_and(|l| first <= l) {
            return Err(format!(
                "serial {first} is already in the parts log: set the tray's first serial above {}",
                production.logged_through.unwrap_or(first)
            ));
        }
        let next = production
            .serial
            .after(parts.len() as u32)
            .ok_or("the next serial overflows")?;
        let log = self.parts_log_path(path);
        self.export(crate::app::files::ExportKind::Gcode, path)?;
        let when = chrono::Local::now().format("%Y-%m-%dT%H:%M:%S").to_string();
        crate::export::append_parts_log(&log, &path.display().to_string(), &parts, when)
            .map_err(|e| format!("{}: cannot append to the parts log: {e}", log.display()))?;
        self.execute(super::commands::Command::AdvanceSerial {
            next,
            logged_through: last,
        })?;
        let saved = match self.session.project_path().map(|p| p.to_path_buf()) {
            Some(project) => self.save_project(&project).map(|()| " (project saved)"),
            None => Ok("; save the project to keep it"),
        }?;
        let done = format!(
            "wrote {}, logged serials {first} … {last} in {}; next tray starts at {next}{saved}",
            path.display(),
            log.display()
        );
        if let Some(setup) = self
            .session
            .doc()
            .production
            .as_ref()
            .map(Production::setup)
        {
            self.set_tray(setup, repaint);
        }
        self.set_status(done, false);
        Ok(())
    }
}
