//! Project files: the whole [`Document`] as versioned JSON, written atomically.

use super::validate::InvalidValue;
use super::{sync_layers, DerivedKey, Document};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;
use thiserror::Error;

/// Current project format version.
///
/// * 1: geometries, profile, settings, fields, plans.
/// * 2: layers and pens (`layers`, each geometry's `layer`, each plan's `layers`), the
///   imported `artwork` the geometries are made from, and `derived_with`. A version-1 project
///   is upgraded on load: its geometries (without hatch output) become the artwork, on one
///   default layer whose pen hatches as its settings' hatch did, and its geometries, fields
///   and plans stay as they were.
/// * 3: each plan records what it was made from (`profile`, `settings`, `geometry_rev`), the
///   document its geometry revision (`geometry_rev`) and the earlier geometry lists plans
///   still refer to (`kept_geometries`). Older plans get the document's profile and settings
///   on load (what they were last shown and exported with).
pub const PROJECT_VERSION: u32 = 3;
const FORMAT: &str = "galvoplan-project";

#[derive(Serialize, Deserialize)]
struct ProjectFile {
    format: String,
    version: u32,
    document: Document,
}

/// Errors reading or writing a project.
#[derive(Debug, Error)]
pub enum ProjectError {
    /// I/O failure.
    #[error("{file}: {what}: {source}")]
    Io {
        /// The file.
        file: String,
        /// What was attempted.
        what: &'static str,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a valid project.
    #[error("{file}: not a valid galvoplan project: {msg}")]
    Corrupt {
        /// The file.
        file: String,
        /// Parser message, with line and column.
        msg: String,
    },
    /// A value is out of range or the parts do not fit together.
    #[error("{file}: invalid project: {}", .error.with_key())]
    Invalid {
        /// The file.
        file: String,
        /// The first bad value.
        error: InvalidValue,
    },
    /// Written by a newer version.
    #[error(
        "{file}: project version {found} is newer than this build supports ({PROJECT_VERSION})"
    )]
    TooNew {
        /// The file.
        file: String,
        /// Version in the file.
        found: u64,
    },
}

/// Writes `bytes` to `path` atomically: a temporary file in the same folder, synced, then renamed
/// over the target, so a crash never leaves a half-written file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// [`write_atomic`] with the content streamed by `write` (buffered) into the temporary file.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    let result = (|| {
        let mut f = std::io::BufWriter::with_capacity(1 << 16, std::fs::File::create(&tmp)?);
        write(&mut f)?;
        let f = f.into_inner().map_err(|e| e.into_error())?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Saves a document as a project file (atomic).
pub fn save_project(doc: &Document, path: &Path) -> Result<(), ProjectError> {
    let file = ProjectFile {
        format: FORMAT.into(),
        version: PROJECT_VERSION,
        document: doc.clone(),
    };
    let text = serde_json::to_string_pretty(&file).map_err(|e| ProjectError::Corrupt {
        file: path.display().to_string(),
        msg: e.to_string(),
    })?;
    write_atomic(path, text.as_bytes()).map_err(|source| ProjectError::Io {
        file: path.display().to_string(),
        what: "cannot write project",
        source,
    })
}

/// Loads a project file, checking format and version.
pub fn load_project(path: &Path) -> Result<Document, ProjectError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| ProjectError::Io {
        file: name.clone(),
        what: "cannot read project",
        source,
    })?;
    parse_project(&text, &name)
}

/// Parses project text; `file` names it in errors.
pub fn parse_project(text: &str, file: &str) -> Result<Document, ProjectError> {
    let corrupt = |msg: String| ProjectError::Corrupt {
        file: file.into(),
        msg,
    };
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| corrupt(e.to_string()))?;
    if value.get("format").and_then(|v| v.as_str()) != Some(FORMAT) {
        return Err(corrupt(format!("missing \"format\": \"{FORMAT}\"")));
    }
    let version = value
        .get("version")
        .and_then(|v| v.as_u64())
        .ok_or_else(|| corrupt("missing \"version\"".into()))?;
    if version > u64::from(PROJECT_VERSION) {
        return Err(ProjectError::TooNew {
            file: file.into(),
            found: version,
        });
    }
    let mut value = value;
    if version < 3 {
        upgrade_v2_plans(&mut value);
    }
    let pf: ProjectFile = serde_json::from_value(value).map_err(|e| corrupt(e.to_string()))?;
    let mut doc = pf.document;
    if version == 1 {
        upgrade_v1(&mut doc);
    }
    doc.validate().map_err(|error| ProjectError::Invalid {
        file: file.into(),
        error,
    })?;
    Ok(doc)
}

/// Version 2 → 3: plans without their own profile and settings get the document's.
fn upgrade_v2_plans(value: &mut serde_json::Value) {
    let Some(doc) = value.get_mut("document").and_then(|d| d.as_object_mut()) else {
        return;
    };
    let inherited: Vec<(&str, serde_json::Value)> = ["profile", "settings"]
        .into_iter()
        .filter_map(|k| Some((k, doc.get(k)?.clone())))
        .collect();
    let Some(plans) = doc.get_mut("plans").and_then(|p| p.as_array_mut()) else {
        return;
    };
    for plan in plans.iter_mut().filter_map(|p| p.as_object_mut()) {
        for (k, v) in &inherited {
            plan.entry(k.to_string()).or_insert_with(|| v.clone());
        }
    }
}

/// Version 1 → 2: the geometries (without hatch output) become the artwork on the default
/// layer, whose pen hatches as the settings said; the geometries count as made from that
/// table, so fields and plans stay valid.
fn upgrade_v1(doc: &mut Document) {
    doc.artwork = doc
        .geometries
        .iter()
        .filter(|g| !super::is_hatch_output(g))
        .cloned()
        .collect();
    let default_pen = doc.settings.default_pen();
    sync_layers(&mut doc.layers, &doc.artwork, &default_pen);
    sync_layers(&mut doc.layers, &doc.geometries, &default_pen);
    doc.derived_with = Some(DerivedKey::of(
        &doc.layers,
        doc.profile.field_mm,
        doc.tiling_set.as_ref(),
    ));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::{Geometry, Source};
    use crate::geom::Pt;

    fn doc() -> Document {
        let mut d = Document::default();
        d.geometries.push(Geometry::new(
            vec![Pt::new(1.0, 2.0), Pt::new(3.5, 4.25)],
            false,
            Source {
                element: "l1".into(),
                subpath: 0,
                layer: "#000000".into(),
                part: 0,
            },
        ));
        d.settings.seed = 42;
        d
    }

    #[test]
    fn round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.galvoplan");
        save_project(&doc(), &p).unwrap();
        let back = load_project(&p).unwrap();
        assert_eq!(back, doc());
        // no temporary file left behind
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn corrupt_and_newer_files_are_reported() {
        let e = parse_project("{\"format\": \"galvoplan-project\", \"version\": 1, \"document\": {\"geometries\": 3}}", "x.json")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("x.json: not a valid galvoplan project"),
            "{e}"
        );
        let e = parse_project(
            "{\"format\": \"galvoplan-project\", \"version\": 7}",
            "x.json",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("version 7"), "{e}");
        let e = parse_project("{\"format\": \"galvo", "x.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 1"), "{e}");
        assert!(matches!(
            load_project(Path::new("/nonexistent/y.json")),
            Err(ProjectError::Io { .. })
        ));
    }
}
