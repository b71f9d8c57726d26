//! The questions the window asks, as data: a file action waiting for its path
//! ([`PathAction`]), what follows an answer about unsaved changes ([`Then`]) and the prompt
//! shown ([`Prompt`]). `super::prompts` asks them.

use super::files::{ExportKind, PROJECT_EXT};
use std::path::PathBuf;

/// A file action that needs a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathAction {
    /// Open an SVG or a project.
    Open,
    /// Save the project under a new name.
    SaveProject,
    /// Export the plan shown, as planned.
    Export(ExportKind),
    /// Solve the plan shown again on the current document, then export the new plan.
    ResolveExport(ExportKind),
    /// Load pens for the layers from a TOML library.
    LoadPens,
    /// Save the layers' pens as a TOML library.
    SavePens,
    /// Load a machine profile (TOML).
    LoadProfile,
    /// Save the machine profile (TOML).
    SaveProfile,
    /// Write the shown tray plan's G-code, log its parts and start the next tray.
    ExportAdvance,
}

impl PathAction {
    /// (title, button, extension, dialog filter name).
    pub(super) fn words(self) -> (&'static str, &'static str, &'static str, &'static str) {
        match self {
            PathAction::Open => ("Open a file", "Open", "svg", "SVG or galvoplan project"),
            PathAction::SaveProject => {
                ("Save the project", "Save", PROJECT_EXT, "galvoplan project")
            }
            PathAction::Export(kind) | PathAction::ResolveExport(kind) => {
                let (filter, ext) = kind.filter();
                let title = match kind {
                    ExportKind::Gcode => "Export G-code",
                    ExportKind::Report => "Export the JSON report",
                    ExportKind::Preview => "Export an SVG preview",
                    ExportKind::Trajectory => "Export the trajectory (CSV)",
                };
                (title, "Export", ext, filter)
            }
            PathAction::ExportAdvance => ("Export and advance", "Export", "gcode", "G-code"),
            PathAction::LoadPens => ("Load pens", "Load", "toml", "pens"),
            PathAction::SavePens => ("Save pens", "Save", "toml", "pens"),
            PathAction::LoadProfile => ("Load a machine profile", "Load", "toml", "profile"),
            PathAction::SaveProfile => ("Save the machine profile", "Save", "toml", "profile"),
        }
    }
    pub(super) fn saves(self) -> bool {
        !matches!(
            self,
            PathAction::Open | PathAction::LoadPens | PathAction::LoadProfile
        )
    }
}

/// What to do once the unsaved changes are dealt with.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Then {
    /// Close the window.
    Quit,
    /// Open a file (none: ask for one).
    Open(Option<PathBuf>),
    /// Start an empty document.
    New,
}

/// A question or path field waiting for the operator.
#[derive(Debug, Clone, PartialEq)]
pub enum Prompt {
    /// Type a path (no native dialog could be shown).
    Path {
        /// What the path is for.
        action: PathAction,
        /// The path typed so far.
        text: String,
        /// Why the field is shown.
        note: String,
    },
    /// The document has unsaved changes.
    Unsaved(Then),
    /// The plan to export is stale.
    StaleExport(ExportKind),
}
