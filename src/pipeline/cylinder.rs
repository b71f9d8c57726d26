//! A cylinder job in the pipeline ([`crate::document::Cylinder`]): the strips in focus are
//! placed on the unrolled surface as fields of a work profile (the machine's, with the strips'
//! height), each field is posed at its strip's angle, and the job is ordered and lowered as
//! step-and-scan on the machine itself.

use super::PipelineError;
use crate::document::{Cylinder, CylinderError, Document, MotionMode, ScanField};
use crate::geom::BBox;

/// A document's cylinder job as [`cylinder_strips`] finds it: the cylinder and its strips'
/// height in focus (mm), none on a flat job, or why it cannot be made.
pub type Strips = Result<Option<(Cylinder, f64)>, CylinderError>;

/// [`cylinder_strips`] failing with the document's file.
pub(super) fn setup(doc: &Document) -> Result<Option<(Cylinder, f64)>, PipelineError> {
    cylinder_strips(doc).map_err(|source| PipelineError::Cylinder {
        file: doc.source.clone().unwrap_or_else(|| "document".into()),
        source,
    })
}

/// The document's cylinder and its strips' height in focus, mm; none on a flat job. Fails with
/// the job's one-line reason ([`Cylinder::check`]; on the fly, which a cylinder is not marked).
pub fn cylinder_strips(doc: &Document) -> Strips {
    let Some(cylinder) = doc.settings.cylinder else {
        return Ok(None);
    };
    let drawn = if doc.artwork.is_empty() {
        &doc.geometries
    } else {
        &doc.artwork
    };
    let extent = drawn.iter().fold(BBox::EMPTY, |b, g| b.union(g.bbox()));
    let height = if extent.is_empty() {
        0.0
    } else {
        extent.max_y - extent.min_y
    };
    if doc.settings.motion == MotionMode::OnTheFly {
        return Err(CylinderError::OnTheFly);
    }
    let strip = cylinder.check(&doc.profile, height)?;
    Ok(Some((cylinder, strip)))
}

/// Runs `f` on the document with the profile its fields are made for: on a cylinder, a flat
/// job on the work profile ([`Cylinder::work_profile`]) that cuts what is larger than a strip
/// at the strips' borders, step-and-scan; the machine's profile and the settings come back
/// afterwards, and the fields get their strips' poses ([`pose_strips`]).
pub(super) fn with_work_profile<T>(
    doc: &mut Document,
    f: impl FnOnce(&mut Document) -> Result<T, PipelineError>,
) -> Result<T, PipelineError> {
    let Some((cylinder, strip)) = setup(doc)? else {
        return f(doc);
    };
    let work = cylinder.work_profile(&doc.profile, strip);
    let machine = std::mem::replace(&mut doc.profile, work);
    let settings = doc.settings.clone();
    doc.settings.split_oversize = true;
    doc.settings.motion = MotionMode::Step;
    // the work profile is the cylinder's already (`Document::reach_profile` is not applied twice)
    doc.settings.cylinder = None;
    let out = f(doc);
    doc.profile = machine;
    doc.settings = settings;
    let out = out?;
    doc.fields = pose_strips(&doc.fields, &cylinder, doc);
    group_cuts(doc, &cylinder, strip);
    Ok(out)
}

/// The words that begin the one warning of a cylinder's cuts.
const CUTS_PREFIX: &str = "around the cylinder: ";

/// On a cylinder, cutting what is taller than a strip is the job's way, not a surprise per
/// geometry: the cut warnings become notes (kept in the report), and one warning says how many
/// geometries are cut where the part turns between strips (a seam on the part).
fn group_cuts(doc: &mut Document, cylinder: &Cylinder, strip: f64) {
    doc.warnings.retain(|w| !w.message.starts_with(CUTS_PREFIX));
    let mut cut = 0;
    for w in &mut doc.warnings {
        if w.message.contains(crate::fields::SPLIT_WORDS) {
            w.note = true;
            cut += 1;
        }
    }
    if cut > 0 {
        doc.warnings.push(crate::document::Warning {
            element: String::new(),
            line: None,
            message: format!(
                "{CUTS_PREFIX}{cut} geometr{} taller than a strip in focus ({strip:.2} mm on ⌀{} mm) \
                 {} cut at the strips' borders, where the part turns between them",
                if cut == 1 { "y" } else { "ies" },
                crate::geom::format_mm(cylinder.diameter_mm, 3),
                if cut == 1 { "is" } else { "are" },
            ),
            note: false,
        });
    }
}

/// `fields` each posed at its strip's angle on `cylinder` ([`Cylinder::strip_pose`]).
pub(super) fn pose_strips(
    fields: &[ScanField],
    cylinder: &Cylinder,
    doc: &Document,
) -> Vec<ScanField> {
    fields
        .iter()
        .map(|f| ScanField {
            pose: cylinder.strip_pose(&doc.profile, f.center.y),
            ..f.clone()
        })
        .collect()
}

/// The fields an ordering of the document starts from when they are not its own (none: its
/// own): on a cylinder each posed at its strip's angle (fields moved by hand since their
/// placement turn with them); on a flat job, strips left from a cylinder job at rest (their
/// poses were the cylinder's).
pub(super) fn job_fields(doc: &Document) -> Result<Option<Vec<ScanField>>, PipelineError> {
    if let Some((cylinder, _)) = setup(doc)? {
        return Ok(Some(pose_strips(&doc.fields, &cylinder, doc)));
    }
    if doc.fields.iter().all(|f| f.pose.stage_y_mm.is_none()) {
        return Ok(None);
    }
    let flat = doc.fields.iter().map(|f| ScanField {
        pose: if f.pose.stage_y_mm.is_some() {
            Default::default()
        } else {
            f.pose
        },
        ..f.clone()
    });
    Ok(Some(flat.collect()))
}
