//! Edit commands: the only way the GUI changes a [`Document`], and the undo/redo history.
//!
//! Every command is applied by [`History::execute`], which first takes a snapshot of what the
//! command can change (fields, profile, settings; for a re-placement also the geometries, plans
//! and warnings, since splitting oversize geometries rewrites them). Undo restores the snapshot.
//! Consecutive commands of one gesture (the moves of one field drag) share a group and so undo
//! together.

use crate::document::{
    validate_layers, ArtworkImport, DerivedKey, Document, Geometry, GeometryRevision, Layer,
    MachineProfile, PartRecord, Plan, Production, ScanField, SolverSettings, Warning,
};
use crate::fields::{add_field, delete_field, move_field, reallocate, set_locked};
use crate::geom::seam::SeamStats;
use crate::geom::tiling::Tiling;
use crate::geom::Pt;
use crate::job::JobCtx;
use crate::pipeline::place_what_fits;

/// Number of undo steps kept.
pub const UNDO_LIMIT: usize = 200;

/// An edit of the document.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Moves a field's centre (clamped into the base stroke); locked fields refuse.
    MoveField {
        /// Field id.
        id: usize,
        /// New centre, mm.
        center: Pt,
    },
    /// Adds an unlocked field at a centre.
    AddField {
        /// Centre, mm.
        center: Pt,
    },
    /// Deletes a field.
    DeleteField {
        /// Field id.
        id: usize,
    },
    /// Locks or unlocks a field.
    SetLocked {
        /// Field id.
        id: usize,
        /// New state.
        locked: bool,
    },
    /// Replaces the unlocked fields by the automatic placement of the settings (keeps locked
    /// fields; splits oversize geometries first when the settings say so), as the CLI does.
    ReplaceAutomatically,
    /// Replaces the machine profile (already validated); fields take the new size and stay
    /// inside the new stroke.
    SetProfile(Box<MachineProfile>),
    /// Replaces the solver settings (already validated).
    SetSettings(Box<SolverSettings>),
    /// Replaces the layer table when only pens change that do not change the geometries
    /// (speed, power, frequency, passes, colour); refused otherwise.
    SetLayers(Vec<Layer>),
    /// Starts the next tray at `next` after *Export and advance* logged the serials up to
    /// `logged_through`: those are never handed out again, so this cannot be undone.
    AdvanceSerial {
        /// The first serial of the next tray.
        next: i64,
        /// The last serial written to the parts log.
        logged_through: i64,
    },
    /// Puts the result of a background job into the document: geometries, layers, fields,
    /// plans and warnings made from this document (re-placement, re-hatching).
    SetContent {
        /// The document the job returned.
        doc: Box<Document>,
        /// What the job did, for the status line and the undo menu.
        what: String,
    },
}

impl Command {
    /// A short description for the status line and the undo menu; `name` gives what the
    /// canvas calls a field id ("field 3", "region 1").
    pub fn describe(&self, name: &dyn Fn(usize) -> String) -> String {
        match self {
            Command::MoveField { id, .. } => format!("move {}", name(*id)),
            Command::AddField { .. } => "add field".into(),
            Command::DeleteField { id } => format!("delete {}", name(*id)),
            Command::SetLocked { id, locked: true } => format!("lock {}", name(*id)),
            Command::SetLocked { id, locked: false } => format!("unlock {}", name(*id)),
            Command::ReplaceAutomatically => "re-place fields automatically".into(),
            Command::SetProfile(_) => "change machine profile".into(),
            Command::SetSettings(_) => "change solver settings".into(),
            Command::SetLayers(_) => "change pens".into(),
            Command::AdvanceSerial { next, .. } => format!("start the next tray at serial {next}"),
            Command::SetContent { what, .. } => what.clone(),
        }
    }
}

/// What an applied command reports.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outcome {
    /// Geometries no field holds after the command.
    pub uncovered: Vec<usize>,
    /// The id of a field the command added.
    pub added: Option<usize>,
}

/// Applies a command to the document (no history); errors leave the document unchanged.
pub fn apply(doc: &mut Document, cmd: &Command) -> Result<Outcome, String> {
    let uncovered = |a: crate::fields::Allocation| Outcome {
        uncovered: a.uncovered,
        added: None,
    };
    match cmd {
        Command::MoveField { id, center } => move_field(doc, *id, *center)
            .map(uncovered)
            .map_err(|e| e.to_string()),
        Command::AddField { center } => {
            let (id, a) = add_field(doc, *center);
            Ok(Outcome {
                uncovered: a.uncovered,
                added: Some(id),
            })
        }
        Command::DeleteField { id } => delete_field(doc, *id)
            .map(uncovered)
            .map_err(|e| e.to_string()),
        Command::SetLocked { id, locked } => {
            set_locked(doc, *id, *locked).map_err(|e| e.to_string())?;
            Ok(uncovered(reallocate(doc)))
        }
        Command::ReplaceAutomatically => {
            let mut work = doc.clone();
            place_what_fits(&mut work, &JobCtx::default())
                .map_err(|e| super::words::gui_error(&e))?;
            *doc = work;
            Ok(uncovered(reallocate(doc)))
        }
        Command::SetProfile(p) => {
            p.validate().map_err(|e| e.to_string())?;
            set_profile(doc, p);
            Ok(uncovered(reallocate(doc)))
        }
        Command::SetSettings(s) => {
            s.validate().map_err(|e| e.to_string())?;
            doc.settings = (**s).clone();
            Ok(uncovered(reallocate(doc)))
        }
        Command::SetLayers(layers) => {
            validate_layers(layers).map_err(|e| e.to_string())?;
            if doc.derived_with.as_ref()
                != Some(&DerivedKey::of(
                    layers,
                    doc.reach_profile().field_mm,
                    doc.tiling_set.as_ref(),
                ))
            {
                return Err("the change needs the geometries made again (a background job)".into());
            }
            doc.layers = layers.clone();
            Ok(uncovered(reallocate(doc)))
        }
        Command::AdvanceSerial {
            next,
            logged_through,
        } => {
            let p = doc
                .production
                .as_mut()
                .ok_or("the document is not a tray: nothing to advance")?;
            p.serial.start = *next;
            p.logged_through = Some(
                p.logged_through
                    .map_or(*logged_through, |l| l.max(*logged_through)),
            );
            Ok(Outcome::default())
        }
        Command::SetContent { doc: new, .. } => {
            new.validate().map_err(|e| e.to_string())?;
            set_content(doc, new);
            Ok(uncovered(reallocate(doc)))
        }
    }
}

/// The profile `p` for `doc`: every field gets its scan field's size and stays within the
/// stage's stroke.
fn set_profile(doc: &mut Document, p: &MachineProfile) {
    doc.profile = p.clone();
    // on a cylinder: its strips
    let reach = doc.reach_profile().into_owned();
    let [sw, sh] = reach.stroke_mm;
    for f in &mut doc.fields {
        f.size = reach.field_mm;
        f.center = Pt::new(f.center.x.clamp(0.0, sw), f.center.y.clamp(0.0, sh));
    }
}

/// Takes what a background job made from the document (`new`: geometries, layers, fields,
/// plans, warnings, the tray) into `doc`; the profile, the settings, the source and the
/// history's view of the document stay.
fn set_content(doc: &mut Document, new: &Document) {
    doc.production = new.production.clone();
    doc.parts = new.parts.clone();
    doc.artwork = new.artwork.clone();
    doc.page_mm = new.page_mm;
    doc.import = new.import.clone();
    doc.geometries = new.geometries.clone();
    doc.geometry_rev = new.geometry_rev;
    doc.kept_geometries = new.kept_geometries.clone();
    doc.layers = new.layers.clone();
    doc.derived_with = new.derived_with.clone();
    doc.tiling = new.tiling.clone();
    doc.seams = new.seams.clone();
    doc.tiling_set = new.tiling_set.clone();
    doc.fields = new.fields.clone();
    doc.plans = new.plans.clone();
    doc.warnings = new.warnings.clone();
}

/// The artwork (with its page and import choices), the geometries (with their revision and
/// the kept revisions, their tiling and seams), plans and warnings.
#[derive(Debug, Clone)]
struct Content {
    artwork: Vec<Geometry>,
    page_mm: [f64; 2],
    import: ArtworkImport,
    geometries: Vec<Geometry>,
    geometry_rev: u64,
    kept_geometries: Vec<GeometryRevision>,
    plans: Vec<Plan>,
    warnings: Vec<Warning>,
    tiling: Option<Tiling>,
    seams: SeamStats,
    tiling_set: Option<Tiling>,
    parts: Vec<PartRecord>,
}

impl Content {
    fn of(doc: &Document) -> Self {
        Self {
            artwork: doc.artwork.clone(),
            page_mm: doc.page_mm,
            import: doc.import.clone(),
            geometries: doc.geometries.clone(),
            geometry_rev: doc.geometry_rev,
            kept_geometries: doc.kept_geometries.clone(),
            plans: doc.plans.clone(),
            warnings: doc.warnings.clone(),
            tiling: doc.tiling.clone(),
            seams: doc.seams.clone(),
            tiling_set: doc.tiling_set.clone(),
            parts: doc.parts.clone(),
        }
    }
    /// Puts this content into the document and returns what it replaced.
    fn swap(self, doc: &mut Document) -> Self {
        Self {
            artwork: std::mem::replace(&mut doc.artwork, self.artwork),
            page_mm: std::mem::replace(&mut doc.page_mm, self.page_mm),
            import: std::mem::replace(&mut doc.import, self.import),
            geometries: std::mem::replace(&mut doc.geometries, self.geometries),
            geometry_rev: std::mem::replace(&mut doc.geometry_rev, self.geometry_rev),
            kept_geometries: std::mem::replace(&mut doc.kept_geometries, self.kept_geometries),
            plans: std::mem::replace(&mut doc.plans, self.plans),
            warnings: std::mem::replace(&mut doc.warnings, self.warnings),
            tiling: std::mem::replace(&mut doc.tiling, self.tiling),
            seams: std::mem::replace(&mut doc.seams, self.seams),
            tiling_set: std::mem::replace(&mut doc.tiling_set, self.tiling_set),
            parts: std::mem::replace(&mut doc.parts, self.parts),
        }
    }
}

/// What a command may change, saved before it runs.
#[derive(Debug, Clone)]
struct Snapshot {
    fields: Vec<ScanField>,
    profile: MachineProfile,
    settings: SolverSettings,
    layers: Vec<Layer>,
    derived_with: Option<DerivedKey>,
    /// Geometries, plans and warnings, for commands that can rewrite them.
    content: Option<Content>,
    /// The production (tray, serials, what was logged).
    production: Option<Production>,
    /// Why this entry cannot be undone (serials written to a parts log).
    refuse_undo: Option<String>,
    what: String,
}

impl Snapshot {
    fn take(doc: &Document, cmd: &Command, what: String) -> Self {
        let rewrites = matches!(
            cmd,
            Command::ReplaceAutomatically | Command::SetContent { .. }
        );
        let content = rewrites.then(|| Content::of(doc));
        let refuse_undo = match (cmd, &doc.production) {
            (Command::AdvanceSerial { logged_through, .. }, Some(p)) => Some(format!(
                "the serials {} … {logged_through} are in the parts log: they are never handed \
                 out again",
                p.serial.start
            )),
            _ => None,
        };
        Self {
            fields: doc.fields.clone(),
            profile: doc.profile.clone(),
            settings: doc.settings.clone(),
            layers: doc.layers.clone(),
            derived_with: doc.derived_with.clone(),
            content,
            production: doc.production.clone(),
            refuse_undo,
            what,
        }
    }
    /// Puts the snapshot into the document and returns the snapshot of what it replaced.
    fn swap(self, doc: &mut Document) -> Snapshot {
        let content = self.content.map(|c| c.swap(doc));
        Snapshot {
            fields: std::mem::replace(&mut doc.fields, self.fields),
            profile: std::mem::replace(&mut doc.profile, self.profile),
            settings: std::mem::replace(&mut doc.settings, self.settings),
            layers: std::mem::replace(&mut doc.layers, self.layers),
            derived_with: std::mem::replace(&mut doc.derived_with, self.derived_with),
            content,
            production: std::mem::replace(&mut doc.production, self.production),
            refuse_undo: self.refuse_undo,
            what: self.what,
        }
    }
}

/// Undo and redo stacks.
#[derive(Debug, Default)]
pub struct History {
    undo: Vec<Snapshot>,
    redo: Vec<Snapshot>,
    /// Group of the newest undo entry, while its gesture may still add to it.
    open_group: Option<u64>,
}

impl History {
    /// Runs a command; on success records the state before it under `what` (unless `group`
    /// equals the group of the newest entry, which then covers this command too). Clears the
    /// redo stack.
    pub fn execute(
        &mut self,
        doc: &mut Document,
        cmd: Command,
        group: Option<u64>,
        what: String,
    ) -> Result<Outcome, String> {
        let coalesce = group.is_some() && group == self.open_group && !self.undo.is_empty();
        let before = (!coalesce).then(|| Snapshot::take(doc, &cmd, what));
        let outcome = apply(doc, &cmd)?;
        if let Some(s) = before {
            self.undo.push(s);
            if self.undo.len() > UNDO_LIMIT {
                self.undo.remove(0);
            }
        }
        self.redo.clear();
        self.open_group = group;
        Ok(outcome)
    }
    /// Ends the current gesture: the next command starts a new undo entry.
    pub fn close_group(&mut self) {
        self.open_group = None;
    }
    /// Why the newest entry cannot be undone, if it cannot.
    pub fn undo_refused(&self) -> Option<&str> {
        self.undo.last()?.refuse_undo.as_deref()
    }
    /// Undoes the newest entry; returns its description (`None`: nothing to undo, or the
    /// entry refuses, see [`History::undo_refused`]).
    pub fn undo(&mut self, doc: &mut Document) -> Option<String> {
        if self.undo_refused().is_some() {
            return None;
        }
        let s = self.undo.pop()?;
        let what = s.what.clone();
        self.redo.push(s.swap(doc));
        self.open_group = None;
        Some(what)
    }
    /// Redoes the newest undone entry; returns its description.
    pub fn redo(&mut self, doc: &mut Document) -> Option<String> {
        let s = self.redo.pop()?;
        let what = s.what.clone();
        self.undo.push(s.swap(doc));
        self.open_group = None;
        Some(what)
    }
    /// Description of what Undo would undo.
    pub fn undo_label(&self) -> Option<&str> {
        self.undo.last().map(|s| s.what.as_str())
    }
    /// Description of what Redo would redo.
    pub fn redo_label(&self) -> Option<&str> {
        self.redo.last().map(|s| s.what.as_str())
    }
    /// Forgets everything (a new document).
    pub fn clear(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::{Geometry, Source};

    fn doc() -> Document {
        let sq = |x: f64, y: f64| {
            Geometry::new(
                vec![
                    Pt::new(x, y),
                    Pt::new(x + 2.0, y),
                    Pt::new(x + 2.0, y + 2.0),
                    Pt::new(x, y + 2.0),
                ],
                true,
                Source::default(),
            )
        };
        Document {
            geometries: vec![sq(10.0, 10.0), sq(150.0, 150.0)],
            ..Document::default()
        }
    }

    #[test]
    fn undo_restores_the_tiling_a_seam_move_changed() {
        let mut d = doc();
        let before = Tiling {
            xs: vec![0.0, 60.0, 120.0],
            ys: vec![0.0, 50.0],
        };
        d.tiling = Some(before.clone());
        let mut moved = d.clone();
        let after = Tiling {
            xs: vec![0.0, 55.0, 120.0],
            ys: vec![0.0, 50.0],
        };
        moved.tiling = Some(after.clone());
        moved.tiling_set = Some(after.clone());
        moved.seams.cuts = 9;
        let mut h = History::default();
        h.execute(
            &mut d,
            Command::SetContent {
                doc: Box::new(moved),
                what: "move seam".into(),
            },
            None,
            "move seam".into(),
        )
        .unwrap();
        assert_eq!(d.tiling_set.as_ref(), Some(&after));
        assert_eq!(d.seams.cuts, 9);
        h.undo(&mut d);
        assert_eq!(d.tiling.as_ref(), Some(&before));
        assert_eq!(d.tiling_set, None);
        assert_eq!(d.seams.cuts, 0);
        h.redo(&mut d);
        assert_eq!(d.tiling_set.as_ref(), Some(&after));
    }

    #[test]
    fn undo_redo_and_grouped_drag() {
        let mut d = doc();
        let mut h = History::default();
        let out = h
            .execute(
                &mut d,
                Command::AddField {
                    center: Pt::new(35.0, 35.0),
                },
                None,
                "add field".into(),
            )
            .unwrap();
        assert_eq!(out.uncovered, vec![1]);
        let id = out.added.unwrap();
        // a drag of three moves is one undo step
        for x in [60.0, 100.0, 151.0] {
            h.execute(
                &mut d,
                Command::MoveField {
                    id,
                    center: Pt::new(x, 151.0),
                },
                Some(7),
                "move field 0".into(),
            )
            .unwrap();
        }
        h.close_group();
        assert_eq!(d.fields[0].geometries, vec![1]);
        assert_eq!(h.undo(&mut d).as_deref(), Some("move field 0"));
        assert_eq!(d.fields[0].center, Pt::new(35.0, 35.0));
        assert_eq!(d.fields[0].geometries, vec![0]);
        assert_eq!(h.redo(&mut d).as_deref(), Some("move field 0"));
        assert_eq!(d.fields[0].center, Pt::new(151.0, 151.0));
        h.undo(&mut d);
        h.undo(&mut d);
        assert!(d.fields.is_empty());
        assert!(h.undo(&mut d).is_none());
    }

    #[test]
    fn failed_commands_change_nothing() {
        let mut d = doc();
        let mut h = History::default();
        assert!(h
            .execute(&mut d, Command::DeleteField { id: 3 }, None, "edit".into())
            .is_err());
        assert!(h.undo_label().is_none());
        let mut bad = MachineProfile::default();
        bad.field_mm[0] = -1.0;
        assert!(h
            .execute(
                &mut d,
                Command::SetProfile(Box::new(bad)),
                None,
                "edit".into()
            )
            .is_err());
        assert_eq!(d.profile, MachineProfile::default());
    }

    #[test]
    fn profile_change_resizes_fields_and_undoes() {
        let mut d = doc();
        let mut h = History::default();
        h.execute(&mut d, Command::ReplaceAutomatically, None, "edit".into())
            .unwrap();
        assert!(!d.fields.is_empty());
        let mut p = d.profile.clone();
        p.field_mm = [30.0, 30.0];
        p.stroke_mm = [100.0, 100.0];
        h.execute(
            &mut d,
            Command::SetProfile(Box::new(p)),
            None,
            "edit".into(),
        )
        .unwrap();
        assert!(d
            .fields
            .iter()
            .all(|f| f.size == [30.0, 30.0] && f.center.x <= 100.0 && f.center.y <= 100.0));
        h.undo(&mut d);
        assert!(d.fields.iter().all(|f| f.size == [70.0, 70.0]));
        assert_eq!(d.profile, MachineProfile::default());
    }
}
