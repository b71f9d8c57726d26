//! Files: opening SVGs and projects, saving projects (atomically), exports, recent files.
//! Dialogs (rfd) are optional: without a desktop portal they return `None` at once, and every
//! operation is also reachable through the [`App`](super::App) methods that take a path.

use crate::document::{
    load_project, write_atomic, ArtworkImport, Document, MachineProfile, Plan, SolverSettings,
};
use crate::export::{preview_svg, report_json, trajectory_csv, trajectory_period_s, write_gcode};
use crate::import::{HiddenLayers, ImportOptions};
use crate::job::JobCtx;
use crate::motion::Toolpath;
use crate::pipeline::{derive_geometries, lower_plan};
use crate::pipeline::{load_artwork, place_what_fits};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// How many recent files are kept.
pub const RECENT_MAX: usize = 10;

/// File extension of project files.
pub const PROJECT_EXT: &str = "galvoplan";

/// Recently opened or saved files, newest first.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Recent(pub Vec<PathBuf>);

impl Recent {
    /// Puts `path` first (once).
    pub fn push(&mut self, path: &Path) {
        let p = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        self.0.retain(|q| *q != p);
        self.0.insert(0, p);
        self.0.truncate(RECENT_MAX);
    }
}

/// Extensions of artwork files (imported by [`crate::import::import_file`]).
pub const ARTWORK_EXTS: [&str; 3] = ["svg", "svgz", "dxf"];

/// True for artwork, SVG or DXF (by extension); everything else is read as a project file.
pub fn is_artwork(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| ARTWORK_EXTS.iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// The result of opening a file.
pub struct Opened {
    /// The document.
    pub doc: Document,
    /// A problem that did not prevent opening (e.g. fields could not be placed).
    pub problem: Option<String>,
    /// True for a project file (Save writes back to it).
    pub is_project: bool,
}

/// Opens an SVG or DXF (imported with `profile` and `settings`, fields placed automatically as the CLI
/// places them) or a project file (with its own profile, settings, fields and plans).
pub fn open(
    path: &Path,
    profile: &MachineProfile,
    settings: &SolverSettings,
    ctx: &JobCtx,
) -> Result<Opened, String> {
    if is_artwork(path) {
        let mut doc = load_artwork(
            path,
            profile.clone(),
            settings.clone(),
            &ImportOptions::default(),
        )
        .map_err(|e| e.to_string())?
        .doc;
        let problem = match place_what_fits(&mut doc, ctx) {
            Ok(_) => None,
            Err(e) if ctx.is_cancelled() => {
                return Err(format!("{}: cancelled ({e})", path.display()))
            }
            Err(e) => Some(super::words::gui_error(&e)),
        };
        Ok(Opened {
            doc,
            problem,
            is_project: false,
        })
    } else {
        let doc = load_project(path).map_err(|e| e.to_string())?;
        Ok(Opened {
            doc,
            problem: None,
            is_project: true,
        })
    }
}

/// Imports `doc`'s artwork file again with the choices of `import` (placement, hidden layers
/// included) into a copy of `doc`: its layers and pens, profile, settings and plans stay;
/// geometries are made again and the unlocked fields placed again when they changed. Fields
/// that cannot be placed (artwork out of reach) leave the document without unlocked fields and
/// say why, as opening does.
pub fn reimport(
    doc: &Document,
    import: ArtworkImport,
    ctx: &JobCtx,
) -> Result<(Document, Option<String>), String> {
    let source = doc
        .source
        .clone()
        .ok_or("the document has no artwork file to import again")?;
    let opts = ImportOptions {
        place: import.place,
        hidden_layers: HiddenLayers::Include(import.included.clone()),
        ..ImportOptions::default()
    };
    let loaded = load_artwork(
        Path::new(&source),
        doc.profile.clone(),
        doc.settings.clone(),
        &opts,
    )
    .map_err(|e| super::words::gui_error(&e))?;
    let mut work = doc.clone();
    work.artwork = loaded.doc.artwork;
    work.page_mm = loaded.doc.page_mm;
    work.warnings = loaded.doc.warnings;
    // every hidden layer stays known, also those imported this time
    let mut hidden = import.hidden_layers;
    for l in loaded.skipped_layers {
        if !hidden.iter().any(|h| h.name == l.name) {
            hidden.push(l);
        }
    }
    work.import = ArtworkImport {
        place: import.place,
        hidden_layers: hidden,
        included: import.included,
    };
    // a hidden layer left out again goes from the layer table (with its pen)
    let left_out: Vec<String> = work.import.skipped().map(|l| l.name.clone()).collect();
    let artwork = &work.artwork;
    work.layers.retain(|l| {
        !left_out.iter().any(|n| n.eq_ignore_ascii_case(&l.name))
            || artwork.iter().any(|g| g.layer == l.name)
    });
    work.derived_with = None;
    let before = work.geometry_rev;
    derive_geometries(&mut work, ctx).map_err(|e| super::words::gui_error(&e))?;
    if work.geometry_rev == before {
        return Ok((work, None));
    }
    match place_what_fits(&mut work, ctx) {
        Ok(_) => Ok((work, None)),
        Err(e) if ctx.is_cancelled() => Err(format!("cancelled ({e})")),
        Err(e) => {
            work.fields.retain(|f| f.locked);
            Ok((work, Some(super::words::gui_error(&e))))
        }
    }
}

/// True when `doc`'s artwork can be imported again: it came from an SVG or DXF that is
/// still there.
pub fn can_reimport(doc: &Document) -> bool {
    doc.source
        .as_deref()
        .map(Path::new)
        .is_some_and(|p| is_artwork(p) && p.is_file())
}

/// What can be exported from a plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ExportKind {
    /// G-code of the TCP path.
    Gcode,
    /// The JSON report.
    Report,
    /// An SVG preview of the planned path.
    Preview,
    /// The stage and scanner trajectory sampled every millisecond (CSV).
    Trajectory,
}

impl ExportKind {
    /// (dialog filter name, extension).
    pub fn filter(self) -> (&'static str, &'static str) {
        match self {
            ExportKind::Gcode => ("G-code", "gcode"),
            ExportKind::Report => ("JSON report", "json"),
            ExportKind::Preview => ("SVG preview", "svg"),
            ExportKind::Trajectory => ("trajectory", "csv"),
        }
    }
    /// The default file name's ending after the artwork's stem: never the artwork's own
    /// (`demo.svg` → `demo.preview.svg`, not `demo.svg`).
    pub fn suffix(self) -> &'static str {
        match self {
            ExportKind::Gcode => "gcode",
            ExportKind::Report => "report.json",
            ExportKind::Preview => "preview.svg",
            ExportKind::Trajectory => "trajectory.csv",
        }
    }
}

/// The folder last exported to, per kind of export (kept between runs).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ExportDirs(pub Vec<(ExportKind, PathBuf)>);

impl ExportDirs {
    /// Remembers the folder of `path` for `kind`.
    pub fn remember(&mut self, kind: ExportKind, path: &Path) {
        let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) else {
            return;
        };
        let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
        self.0.retain(|(k, _)| *k != kind);
        self.0.push((kind, dir));
    }
    /// The folder last used for `kind`.
    pub fn get(&self, kind: ExportKind) -> Option<&Path> {
        self.0
            .iter()
            .find(|(k, _)| *k == kind)
            .map(|(_, d)| d.as_path())
    }
}

/// The text of an export of `plan` as planned (its own profile, pens and settings), from its
/// lowered toolpath (`toolpath`, else lowered here; a trajectory is lowered on its clock).
pub fn export_text(
    doc: &Document,
    plan: &Plan,
    toolpath: Option<&Toolpath>,
    kind: ExportKind,
) -> Result<String, String> {
    let source = doc.source.clone().unwrap_or_else(|| "document".into());
    if kind == ExportKind::Report {
        // the report needs no toolpath: never lowered for it
        return Ok(report_json(&source, plan, &doc.warnings));
    }
    let toolpath = &*toolpath_of(doc, plan, toolpath)?;
    Ok(match kind {
        ExportKind::Gcode => write_gcode(toolpath, plan, doc.page_mm[1], &source)
            .map_err(|e| format!("{source}: {e}"))?,
        ExportKind::Preview => preview_svg(toolpath, plan, doc.page_mm),
        ExportKind::Trajectory => {
            // sampled on the controller's clock when the profile has one, else every 1 ms
            let clock_ms = plan
                .profile
                .controller
                .clock_s(plan.motion)
                .map_or(1.0, |s| s * 1e3);
            let period_s = trajectory_period_s(clock_ms).map_err(|e| e.to_string())?;
            trajectory_csv(toolpath, period_s, &plan.profile.extra_axes())
        }
        ExportKind::Report => report_json(&source, plan, &doc.warnings),
    })
}

/// Writes an export atomically.
pub fn export(
    doc: &Document,
    plan: &Plan,
    toolpath: Option<&Toolpath>,
    kind: ExportKind,
    path: &Path,
) -> Result<(), String> {
    if kind != ExportKind::Gcode || !plan.profile.controller.streamed(plan.motion) {
        return write_atomic(path, export_text(doc, plan, toolpath, kind)?.as_bytes())
            .map_err(|e| format!("{}: cannot write: {e}", path.display()));
    }
    // a streamed plan's program runs nothing without its stream: written beside it, first
    // (from the one lowering both take)
    let toolpath = toolpath_of(doc, plan, toolpath)?;
    let stream = stream_path(path);
    let (text, _) = crate::export::stream_text(&toolpath, plan)
        .map_err(|e| format!("{}: cannot stream the plan: {e}", stream.display()))?;
    write_atomic(&stream, text.as_bytes())
        .map_err(|e| format!("{}: cannot write: {e}", stream.display()))?;
    write_atomic(
        path,
        export_text(doc, plan, Some(&toolpath), kind)?.as_bytes(),
    )
    .map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

/// `toolpath`, or the plan lowered when none is given.
fn toolpath_of<'a>(
    doc: &Document,
    plan: &Plan,
    toolpath: Option<&'a Toolpath>,
) -> Result<std::borrow::Cow<'a, Toolpath>, String> {
    match toolpath {
        Some(t) => Ok(std::borrow::Cow::Borrowed(t)),
        None => lower_plan(doc, plan)
            .map(std::borrow::Cow::Owned)
            .map_err(|e| e.to_string()),
    }
}

/// Where a streamed plan's stream goes beside its program: `job.ngc` → `job.stream`.
pub fn stream_path(program: &Path) -> PathBuf {
    program.with_extension("stream")
}

/// The open dialog (SVG, DXF or project).
pub fn pick_open() -> Option<PathBuf> {
    rfd::FileDialog::new()
        .add_filter(
            "SVG, DXF or galvoplan project",
            &["svg", "svgz", "dxf", PROJECT_EXT, "json"],
        )
        .add_filter("SVG or DXF artwork", &ARTWORK_EXTS)
        .add_filter("galvoplan project", &[PROJECT_EXT, "json"])
        .pick_file()
}

/// An open dialog for one kind of file.
pub fn pick_load(filter: &str, ext: &str) -> Option<PathBuf> {
    rfd::FileDialog::new()
        .add_filter(filter, &[ext])
        .pick_file()
}

/// True when a native file dialog may be shown: on Linux and the BSDs the dialogs go through
/// the desktop portal on the session bus, so without a session bus there is none (rfd then
/// returns "nothing chosen" at once).
pub fn native_dialogs_available() -> bool {
    if cfg!(any(target_os = "windows", target_os = "macos")) {
        return true;
    }
    let bus_env = std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some_and(|v| !v.is_empty());
    let bus_socket = std::env::var_os("XDG_RUNTIME_DIR")
        .map(|d| PathBuf::from(d).join("bus"))
        .is_some_and(|p| p.exists());
    bus_env || bus_socket
}

/// A save dialog for one kind of file, in `folder` when given.
pub fn pick_save(
    filter: &str,
    ext: &str,
    default_name: &str,
    folder: Option<&Path>,
) -> Option<PathBuf> {
    let mut d = rfd::FileDialog::new()
        .add_filter(filter, &[ext])
        .set_file_name(default_name);
    if let Some(f) = folder {
        d = d.set_directory(f);
    }
    d.save_file()
}

/// A default file name after the source's stem: `demo.svg` → `demo.<ending>`.
pub fn default_name(doc: &Document, ending: &str) -> String {
    let stem = doc
        .source
        .as_deref()
        .map(Path::new)
        .and_then(Path::file_stem)
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "job".into());
    format!("{stem}.{ending}")
}
