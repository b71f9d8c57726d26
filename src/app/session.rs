//! The open document and everything derived from it, without egui: the document, where it
//! came from, its undo history, its plans' toolpaths and staleness, coverage and the plan
//! shown. The window ([`super::App`]) draws it and sends it commands; the tests below drive it
//! without a window.

use super::commands::{Command, History, Outcome};
use super::toolpaths::{Lowered, Prelowered, ToolpathCache};
use super::words::{field_number, field_word};
use crate::document::{staleness, Document, MachineProfile, Plan};
use std::path::PathBuf;

/// The open document and its derived state.
#[derive(Default)]
pub struct Session {
    /// The open document (empty until a file is opened).
    doc: Document,
    /// Where the project was loaded from or saved to.
    project_path: Option<PathBuf>,
    /// Undo and redo.
    history: History,
    /// Index of the plan shown (workbench, exports, field numbers).
    active: Option<usize>,
    /// Each plan's lowered toolpath (run time only).
    toolpaths: ToolpathCache,
    /// Counts changes of the document (edits, plans, layers).
    revision: u64,
    /// `revision` when the document was last opened or saved.
    saved_revision: u64,
    /// Geometries no field holds.
    uncovered: Vec<usize>,
    /// Uncovered geometries no scan field can ever hold (larger than a field, or beyond the
    /// stage's stroke plus half a field).
    out_of_reach: Vec<usize>,
    /// (imported, marked) geometries per layer.
    layer_counts: Vec<(usize, usize)>,
    /// Closed geometries (counted once per change, not every frame).
    closed: usize,
    /// The cylinder job's strips in focus (cylinder, height mm), none on a flat job, or why it
    /// cannot be made (checked once per change: the solve buttons and the Cylinder section
    /// read it every frame).
    /// (None until the first refresh: a flat job.)
    strips: Option<crate::pipeline::Strips>,
    /// Per plan, what changed since it was planned, in words (empty: current).
    stale: Vec<Vec<String>>,
    /// A problem with the open document (e.g. fields could not be placed).
    problem: Option<String>,
    /// The artwork's file is there to be imported again (placement, hidden layers); checked
    /// when the document changes, not every frame.
    can_reimport: bool,
    /// The tray's cells as the canvas shows them (made when the document changes).
    part_boxes: Vec<super::tray_panel::PartBox>,
    /// Every part's codes, boxed (the canvas drags them).
    code_boxes: Vec<super::tray_panel::CodeBox>,
    /// Each geometry's layer colour.
    colours: Vec<egui::Color32>,
    /// The document's warnings as listed (grouped, notes left out).
    warning_lines: Vec<String>,
    /// Counts imports: the warnings list opens again on each one.
    imports: u64,
    /// Counts refreshes of what the canvases draw (with `revision`: the canvases' raster
    /// caches are redrawn when it changes).
    canvas_revision: u64,
}

impl Session {
    /// The open document (empty until a file is opened).
    pub fn doc(&self) -> &Document {
        &self.doc
    }
    /// Where the project was loaded from or saved to.
    pub fn project_path(&self) -> Option<&std::path::Path> {
        self.project_path.as_deref()
    }
    /// Undo and redo.
    pub fn history(&self) -> &History {
        &self.history
    }
    /// Index of the plan shown (workbench, exports, field numbers).
    pub fn active(&self) -> Option<usize> {
        self.active
    }
    /// Counts changes of the document (edits, plans, layers).
    pub fn revision(&self) -> u64 {
        self.revision
    }
    /// Geometries no field holds.
    pub fn uncovered(&self) -> &[usize] {
        &self.uncovered
    }

    /// The cylinder job's strips in focus, or why it cannot be made
    /// ([`crate::pipeline::cylinder_strips`], as of the last change).
    pub fn strips(&self) -> crate::pipeline::Strips {
        self.strips.clone().unwrap_or(Ok(None))
    }
    /// Uncovered geometries no scan field can ever hold.
    pub fn out_of_reach(&self) -> &[usize] {
        &self.out_of_reach
    }
    /// (imported, marked) geometries per layer.
    pub fn layer_counts(&self) -> &[(usize, usize)] {
        &self.layer_counts
    }
    /// Closed geometries.
    pub fn closed(&self) -> usize {
        self.closed
    }
    /// A problem with the open document (e.g. fields could not be placed).
    pub fn problem(&self) -> Option<&str> {
        self.problem.as_deref()
    }
    /// The artwork's file is there to be imported again.
    pub fn can_reimport(&self) -> bool {
        self.can_reimport
    }
    /// The tray's cells as the canvas shows them.
    pub fn part_boxes(&self) -> &[super::tray_panel::PartBox] {
        &self.part_boxes
    }
    /// Every part's codes, boxed.
    pub fn code_boxes(&self) -> &[super::tray_panel::CodeBox] {
        &self.code_boxes
    }
    /// Each geometry's layer colour.
    pub fn colours(&self) -> &[egui::Color32] {
        &self.colours
    }
    /// Counts imports (the warnings list opens again on each one).
    pub fn imports(&self) -> u64 {
        self.imports
    }
    /// Counts refreshes of what the canvases draw.
    pub fn canvas_revision(&self) -> u64 {
        self.canvas_revision
    }

    /// A session on `doc` (not yet refreshed: nothing derived from it).
    pub fn with_document(doc: Document) -> Self {
        Self {
            doc,
            ..Self::default()
        }
    }

    /// The document's warnings as the Warnings list shows them ([`crate::document::grouped`]),
    /// made when the document changes, not every frame.
    pub fn warning_lines(&self) -> &[String] {
        &self.warning_lines
    }

    /// Each plan's lowered toolpath.
    pub fn toolpaths(&self) -> &ToolpathCache {
        &self.toolpaths
    }
    /// Per plan, what changed since it was planned, in words (empty: current).
    pub fn stale(&self) -> &[Vec<String>] {
        &self.stale
    }

    /// Takes `doc` as the open document (read from `project_path` when that is a project; an
    /// import counts as one when `imported`): the history starts afresh, the last plan is
    /// shown, and the document counts as saved.
    pub fn replace(&mut self, doc: Document, project_path: Option<PathBuf>, imported: bool) {
        self.doc = doc;
        self.project_path = project_path;
        self.history.clear();
        self.problem = None;
        self.active = self.doc.plans.len().checked_sub(1);
        if imported {
            self.imports += 1;
        }
        self.refresh();
        self.changed();
        self.saved_revision = self.revision;
    }

    /// The document was saved (to `project_path` when given): it has no unsaved changes.
    pub fn mark_saved(&mut self, project_path: Option<PathBuf>) {
        if project_path.is_some() {
            self.project_path = project_path;
        }
        self.saved_revision = self.revision;
    }

    /// Says what is wrong with the open document (none: nothing).
    pub fn set_problem(&mut self, problem: Option<String>) {
        self.problem = problem;
    }

    /// Shows plan `k` (ignored when there is no such plan).
    pub fn show_plan(&mut self, k: usize) {
        if k < self.doc.plans.len() {
            self.active = Some(k);
        }
    }

    /// Lowers the plans added, loaded or changed since the last frame (and drops the removed
    /// ones' toolpaths).
    pub fn sync_toolpaths(&mut self) {
        self.toolpaths.sync(&self.doc);
    }

    /// Ends the undo group of a drag: the next edit is a step of its own.
    pub fn close_edit_group(&mut self) {
        self.history.close_group();
    }

    /// True when a document is open.
    pub fn has_document(&self) -> bool {
        !self.doc.geometries.is_empty()
    }

    /// True when the document has changes that are not saved in a project file.
    pub fn has_unsaved_changes(&self) -> bool {
        self.has_document() && self.revision != self.saved_revision
    }

    /// Counts a change of the document.
    pub fn changed(&mut self) {
        self.revision += 1;
    }

    /// The plan shown.
    pub fn active_plan(&self) -> Option<&Plan> {
        self.active.and_then(|k| self.doc.plans.get(k))
    }

    /// What changed since plan `k` was planned, in words (empty: it is current).
    pub fn plan_staleness(&self, k: usize) -> &[String] {
        self.stale.get(k).map_or(&[], Vec::as_slice)
    }

    /// The number the canvas shows for field `id`: 1…n in the visiting order of the plan
    /// shown, else in placement order.
    pub fn field_label(&self, id: usize) -> usize {
        let visiting = self.active_plan().map(|p| p.fields.as_slice());
        field_number(&self.doc.fields, visiting, id)
    }

    /// What the canvas calls field `id`: "field 3", or "region 1" for one larger than the
    /// profile's scan field.
    pub fn field_name(&self, id: usize) -> String {
        let word = self
            .doc
            .fields
            .iter()
            .find(|f| f.id == id)
            .map_or("field", |f| field_word(f, &self.doc.profile));
        format!("{word} {}", self.field_label(id))
    }

    /// Plan `k`'s lowered toolpath, or why it could not be lowered (`None`: no such plan).
    pub fn toolpath(&self, k: usize) -> Option<Result<&Lowered, &str>> {
        self.toolpaths.get(k)
    }

    /// The files the document was read from (artwork, project): no export may overwrite them.
    pub fn input_files(&self) -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = self.doc.source.iter().map(PathBuf::from).collect();
        v.extend(self.project_path.clone());
        v
    }

    /// Applies an edit through the undo history, described with the canvas's field numbers;
    /// returns the description and the outcome.
    pub fn execute(
        &mut self,
        cmd: Command,
        group: Option<u64>,
    ) -> (String, Result<Outcome, String>) {
        let what = cmd.describe(&|id| self.field_name(id));
        let r = self
            .history
            .execute(&mut self.doc, cmd, group, what.clone());
        self.refresh();
        if r.is_ok() {
            self.changed();
        }
        (what, r)
    }

    /// Undoes the last edit; returns its description (`Err`: the edit refuses to be undone,
    /// and why).
    pub fn undo(&mut self) -> Result<Option<String>, String> {
        if let Some(why) = self.history.undo_refused() {
            return Err(why.to_string());
        }
        let w = self.history.undo(&mut self.doc);
        if w.is_some() {
            self.changed();
        }
        self.refresh();
        Ok(w)
    }

    /// Redoes the last undone edit; returns its description.
    pub fn redo(&mut self) -> Option<String> {
        let w = self.history.redo(&mut self.doc);
        if w.is_some() {
            self.changed();
        }
        self.refresh();
        w
    }

    /// Adds a solved plan with the toolpath its job lowered, shows it; returns its index.
    pub fn add_plan(&mut self, plan: Plan, lowered: Prelowered) -> usize {
        self.doc.plans.push(plan);
        self.changed();
        let k = self.doc.plans.len() - 1;
        self.toolpaths.adopt(k, lowered);
        self.active = Some(k);
        self.refresh();
        k
    }

    /// Removes plan `k` (the plan shown moves with the list); returns it.
    pub fn remove_plan(&mut self, k: usize) -> Option<Plan> {
        if k >= self.doc.plans.len() {
            return None;
        }
        let p = self.doc.plans.remove(k);
        self.doc.prune_kept_geometries();
        self.active = self
            .active
            .and_then(|a| (a != k).then(|| if a > k { a - 1 } else { a }));
        self.changed();
        self.refresh();
        Some(p)
    }

    /// Recomputes what derives from the document after a change: coverage, layer counts,
    /// each plan's toolpath and staleness.
    pub fn refresh(&mut self) {
        let mut held = vec![false; self.doc.geometries.len()];
        for f in &self.doc.fields {
            for &g in &f.geometries {
                if let Some(h) = held.get_mut(g) {
                    *h = true;
                }
            }
        }
        self.uncovered = (0..held.len()).filter(|&g| !held[g]).collect();
        self.out_of_reach = self
            .uncovered
            .iter()
            .copied()
            .filter(|&k| !can_be_covered(&self.doc.geometries[k], &self.doc.reach_profile()))
            .collect();
        self.strips = Some(crate::pipeline::cylinder_strips(&self.doc));
        self.layer_counts = layer_counts(&self.doc);
        self.closed = self.doc.geometries.iter().filter(|g| g.closed).count();
        self.can_reimport = super::files::can_reimport(&self.doc);
        self.part_boxes = super::tray_panel::part_boxes(&self.doc);
        self.code_boxes = super::tray_panel::code_boxes(&self.doc);
        if self.active.is_some_and(|k| k >= self.doc.plans.len()) {
            self.active = self.doc.plans.len().checked_sub(1);
        }
        self.toolpaths.sync(&self.doc);
        self.warning_lines = crate::document::grouped(&self.doc.warnings);
        self.canvas_revision += 1;
        let rgb: std::collections::HashMap<&str, egui::Color32> = self
            .doc
            .layers
            .iter()
            .map(|l| {
                let [r, g, b] = l.rgb();
                (l.name.as_str(), egui::Color32::from_rgb(r, g, b))
            })
            .collect();
        self.colours = self
            .doc
            .geometries
            .iter()
            .map(|g| {
                rgb.get(g.layer.as_str())
                    .copied()
                    .unwrap_or(super::draw::colour::CLOSED)
            })
            .collect();
        self.stale = self
            .doc
            .plans
            .iter()
            .map(|p| staleness(p, &self.doc))
            .collect();
    }
}

/// (imported, marked) geometries per layer of the table.
fn layer_counts(doc: &Document) -> Vec<(usize, usize)> {
    let index: std::collections::HashMap<&str, usize> = doc
        .layers
        .iter()
        .enumerate()
        .map(|(k, l)| (l.name.as_str(), k))
        .collect();
    let mut counts = vec![(0, 0); doc.layers.len()];
    for g in &doc.artwork {
        if let Some(&k) = index.get(g.layer.as_str()) {
            counts[k].0 += 1;
        }
    }
    for g in &doc.geometries {
        if let Some(&k) = index.get(g.layer.as_str()) {
            counts[k].1 += 1;
        }
    }
    counts
}

/// True when some scan-field position within the stage's stroke holds all of `g`.
fn can_be_covered(g: &crate::document::Geometry, profile: &MachineProfile) -> bool {
    let (x, y) = crate::fields::center_range(&g.bbox(), profile);
    !x.is_empty() && !y.is_empty()
}

#[cfg(test)]
pub(super) mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::job::JobCtx;
    use crate::pipeline::{load_svg, order_document_lowered, place_document_fields};

    /// The demo artwork with its fields placed, as a session (also for the canvas's tests).
    pub(in crate::app) fn demo() -> Session {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/examples/demo.svg");
        let (mut doc, _) = load_svg(
            &path,
            MachineProfile::default(),
            Default::default(),
            &Default::default(),
        )
        .unwrap();
        place_document_fields(&mut doc, &JobCtx::default()).unwrap();
        let mut s = Session {
            doc,
            ..Session::default()
        };
        s.refresh();
        s
    }

    fn solve(s: &mut Session) -> usize {
        let (plan, toolpath) = order_document_lowered(&s.doc, &JobCtx::default()).unwrap();
        let lowered = Prelowered::of(&plan, toolpath);
        s.add_plan(plan, lowered)
    }

    #[test]
    fn edits_keep_plans_and_say_what_changed() {
        let mut s = demo();
        let k = solve(&mut s);
        assert!(s.plan_staleness(k).is_empty());
        let mut p = s.doc.profile.clone();
        p.axis_y.max_velocity_mm_s = 100.0;
        let (what, r) = s.execute(Command::SetProfile(Box::new(p)), None);
        assert!(r.is_ok() && what == "change machine profile");
        assert_eq!(s.doc.plans.len(), 1);
        let why = s.plan_staleness(k);
        assert_eq!(why.len(), 1, "{why:?}");
        assert!(why[0].starts_with("base Y max velocity "), "{why:?}");
        // the plan keeps its own machine: its toolpath is the one it was measured on
        let l = s.toolpath(k).unwrap().unwrap();
        assert_eq!(Some(l.duration_s()), s.doc.plans[k].metrics.job_time_s);
        // undo brings the document back to the plan's inputs: current again
        assert!(s.undo().unwrap().is_some());
        assert!(s.plan_staleness(k).is_empty());
        assert!(s.has_unsaved_changes());
    }

    #[test]
    fn field_numbers_in_messages_follow_the_plan_shown() {
        let mut s = demo();
        solve(&mut s);
        let visiting = s.active_plan().unwrap().fields.clone();
        let last = visiting.last().unwrap().id;
        let (what, r) = s.execute(Command::DeleteField { id: last }, None);
        assert!(r.is_ok());
        assert_eq!(what, format!("delete field {}", visiting.len()));
        assert_eq!(s.history.undo_label(), Some(what.as_str()));
    }

    /// The invariant the session's private fields keep: a plan is shown with the toolpath of
    /// its own geometry revision, whatever the document's geometries become (re-hatched here)
    /// and through undo and redo; the plans made afterwards get the new revision's.
    #[test]
    fn a_plan_is_never_shown_against_another_revisions_geometries() {
        let mut s = demo();
        let k = solve(&mut s);
        let strokes = |s: &Session, k: usize| -> Vec<Vec<crate::geom::Pt>> {
            let l = s.toolpath(k).unwrap().unwrap();
            (0..l.toolpath.strokes.len())
                .map(|j| l.toolpath.stroke_points(j).to_vec())
                .collect()
        };
        let before = strokes(&s, k);
        let rev = s.doc().plans[k].geometry_rev;
        // hatch every layer: new geometries, a new revision
        let mut work = s.doc().clone();
        for l in &mut work.layers {
            l.pen.hatch = Some(crate::document::HatchSettings::default());
        }
        crate::pipeline::derive_geometries(&mut work, &JobCtx::default()).unwrap();
        place_document_fields(&mut work, &JobCtx::default()).unwrap();
        let (_, r) = s.execute(
            Command::SetContent {
                doc: Box::new(work),
                what: "hatch".into(),
            },
            None,
        );
        assert!(r.is_ok());
        assert_ne!(s.doc().geometry_rev, rev);
        assert!(
            s.doc().geometries.len() > s.doc().plan_geometries(&s.doc().plans[k]).unwrap().len()
        );
        // the plan keeps its strokes, each on a geometry of its own revision
        assert_eq!(strokes(&s, k), before);
        let own = s.doc().plan_geometries(&s.doc().plans[k]).unwrap().to_vec();
        let l = s.toolpath(k).unwrap().unwrap();
        for (j, st) in l.toolpath.strokes.iter().enumerate() {
            let g = &own[st.geometry];
            let first = l.toolpath.stroke_points(j)[0];
            assert!(g.points.iter().any(|p| p.dist(first) < 1e-9));
        }
        assert!(!s.plan_staleness(k).is_empty());
        // through undo and redo too
        s.undo().unwrap();
        assert_eq!(strokes(&s, k), before);
        assert!(s.plan_staleness(k).is_empty());
        s.redo();
        assert_eq!(strokes(&s, k), before);
        // a plan made now is made on the hatched geometries
        let k2 = solve(&mut s);
        assert_eq!(s.doc().plans[k2].geometry_rev, s.doc().geometry_rev);
        assert!(strokes(&s, k2).len() > before.len());
    }

    #[test]
    fn removing_a_plan_keeps_the_one_shown() {
        let mut s = demo();
        solve(&mut s);
        let second = solve(&mut s);
        assert_eq!(s.active, Some(second));
        assert!(s.remove_plan(0).is_some());
        assert_eq!(s.active, Some(0));
        assert_eq!(s.stale.len(), 1);
        assert!(s.remove_plan(5).is_none());
    }
}
