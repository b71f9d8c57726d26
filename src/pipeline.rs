//! The whole pipeline on a [`Document`]: import → fields → order → metrics, with stage times.

use crate::document::{Document, MachineProfile, MotionMode, Plan, ScanField, SolverSettings};
use crate::fields::{place_fields, split_oversize, FieldError, Placement};
use crate::hatch::{hatch_geometries, is_hatch_output, HatchError};
use crate::import::{import_file, ImportError, ImportOptions};
use crate::job::JobCtx;
use crate::motion::{lower_motion, MotionError, Toolpath};
use crate::order::{order_plan, OrderError};
use std::path::Path;
use std::time::Instant;
use thiserror::Error;

/// A pipeline failure; the message names the file where one is involved.
#[derive(Debug, Error)]
pub enum PipelineError {
    /// The artwork could not be imported.
    #[error(transparent)]
    Import(#[from] ImportError),
    /// Fields could not be placed.
    #[error("{file}: {source}")]
    Fields {
        /// The document's source file.
        file: String,
        /// The cause.
        source: FieldError,
    },
    /// Ordering failed.
    #[error("{file}: {source}")]
    Order {
        /// The document's source file.
        file: String,
        /// The cause.
        source: OrderError,
    },
    /// The plan could not be lowered to machine motion.
    #[error("{file}: {source}")]
    Lower {
        /// The document's source file.
        file: String,
        /// The cause.
        source: MotionError,
    },
    /// The plan cannot be written as G-code in the profile's dialect.
    #[error("{file}: {source}")]
    Gcode {
        /// The document's source file.
        file: String,
        /// The cause.
        source: crate::export::GcodeError,
    },
    /// Hatching failed.
    #[error("{file}: {source}")]
    Hatch {
        /// The document's source file.
        file: String,
        /// The cause.
        source: HatchError,
    },
}

/// Imports an SVG or DXF file ([`import_file`]) into a new document with the given profile and
/// settings; returns it with the import time in s. A DXF drawing is placed in the profile's
/// base stroke where its extents allow (`opts.work_area_mm` unset is taken from the profile).
pub fn load_svg(
    path: &Path,
    profile: MachineProfile,
    settings: SolverSettings,
    opts: &ImportOptions,
) -> Result<(Document, f64), PipelineError> {
    let t0 = Instant::now();
    let mut opts = opts.clone();
    if opts.work_area_mm.is_none() {
        opts.work_area_mm = Some(profile.stroke_mm);
    }
    let imported = import_file(path, &opts)?;
    let doc = Document {
        source: Some(path.display().to_string()),
        page_mm: imported.page_mm,
        geometries: imported.geometries,
        warnings: imported.warnings,
        profile,
        settings,
        fields: Vec::new(),
        plans: Vec::new(),
    };
    Ok((doc, t0.elapsed().as_secs_f64()))
}

/// Places fields (replacing the document's unlocked ones; locked fields stay) and orders the
/// geometries; returns the plan with `solve_s.fields` and `solve_s.order` filled in. With
/// `split_oversize`, geometries larger than a field are first cut into pieces (and reported as
/// warnings). The plan is not added to `doc.plans`.
pub fn plan_document(doc: &mut Document, ctx: &JobCtx) -> Result<Plan, PipelineError> {
    let hatch_s = apply_hatch(doc, ctx)?;
    let t0 = Instant::now();
    let lower_bound = place_document_fields(doc, ctx)?;
    let fields_s = t0.elapsed().as_secs_f64();
    let mut plan = order_document(doc, ctx)?;
    plan.metrics.solve_s.hatch = hatch_s;
    plan.metrics.solve_s.fields = fields_s;
    plan.metrics.fields_lower_bound = Some(lower_bound);
    plan.metrics.solve_s.total =
        plan.metrics.solve_s.hatch + plan.metrics.solve_s.fields + plan.metrics.solve_s.order;
    Ok(plan)
}

/// The hatch stage: with `settings.hatch` set, fills the closed geometries (one region per SVG
/// element, see [`hatch_geometries`]) and replaces the document's geometries with the outlines
/// (as the settings say) and the hatch, each hatch geometry small enough for one scan field.
/// Does nothing when the document already holds hatch output (so it runs once per import).
/// Returns the wall time in s.
pub fn apply_hatch(doc: &mut Document, ctx: &JobCtx) -> Result<f64, PipelineError> {
    let t0 = Instant::now();
    let Some(settings) = doc.settings.hatch.clone() else {
        return Ok(0.0);
    };
    if doc.geometries.iter().any(is_hatch_output) {
        return Ok(0.0);
    }
    let hatched = hatch_geometries(&doc.geometries, &settings, doc.profile.field_mm, ctx).map_err(
        |source| PipelineError::Hatch {
            file: doc.source.clone().unwrap_or_else(|| "document".into()),
            source,
        },
    )?;
    doc.geometries = hatched.geometries;
    for w in hatched.warnings {
        // a hatch that left no output runs again on the next call: report it once
        if !doc.warnings.contains(&w) {
            doc.warnings.push(w);
        }
    }
    // indices changed: fields and plans of the old geometry list are void
    doc.fields.clear();
    doc.plans.clear();
    Ok(t0.elapsed().as_secs_f64())
}

/// The field stage alone: hatches (once, when the settings ask for it), splits oversize
/// geometries when the settings say so, then places the fields (keeping locked ones) and
/// allocates the geometries. Returns the lower bound on fields.
pub fn place_document_fields(doc: &mut Document, ctx: &JobCtx) -> Result<usize, PipelineError> {
    apply_hatch(doc, ctx)?;
    let file = doc.source.clone().unwrap_or_else(|| "document".into());
    if doc.settings.split_oversize {
        let warnings = split_oversize(&mut doc.geometries, doc.profile.field_mm);
        if !warnings.is_empty() {
            // indices changed: fields and plans of the old geometry list are void
            doc.fields.clear();
            doc.plans.clear();
        }
        doc.warnings.extend(warnings);
    }
    let locked: Vec<ScanField> = doc.fields.iter().filter(|f| f.locked).cloned().collect();
    let placed = place_fields(&doc.geometries, &doc.profile, &doc.settings, &locked, ctx);
    let placement = match placed {
        // on the fly the stage follows the work: a geometry larger than the field needs no cut,
        // and one region holding everything is ordered as a whole
        Err(FieldError::Oversize { .. }) if doc.settings.motion == MotionMode::OnTheFly => {
            whole_work_region(&doc.geometries)
        }
        other => other.map_err(|source| PipelineError::Fields { file, source })?,
    };
    doc.fields = placement.fields;
    Ok(placement.lower_bound)
}

/// One region around all the geometries (on-the-fly ordering when some geometry is larger than
/// a scan field): id 0, centred on their bounding box, as large as it.
fn whole_work_region(geometries: &[crate::document::Geometry]) -> Placement {
    let mut b = crate::geom::BBox::EMPTY;
    for g in geometries {
        b = b.union(g.bbox());
    }
    Placement {
        fields: vec![ScanField {
            id: 0,
            center: b.center(),
            size: [b.width(), b.height()],
            locked: false,
            geometries: (0..geometries.len()).collect(),
        }],
        lower_bound: 1,
    }
}

/// The ordering stage alone, on the document's current fields and allocation (as the operator
/// left them). Takes `&Document` so that it can run on a snapshot in a background thread.
pub fn order_document(doc: &Document, ctx: &JobCtx) -> Result<Plan, PipelineError> {
    let file = doc.source.clone().unwrap_or_else(|| "document".into());
    if let Some(r) = ctx.recorder() {
        r.geometry(&doc.geometries);
        r.fields(&doc.fields);
    }
    let mut plan = order_plan(
        &doc.geometries,
        &doc.fields,
        &doc.profile,
        &doc.settings,
        ctx,
    )
    .map_err(|source| PipelineError::Order { file, source })?;
    plan.metrics.solve_s.total = plan.metrics.solve_s.order;
    if let Some(r) = ctx.recorder() {
        r.plan(&plan, &lower_plan(doc, &plan)?);
    }
    Ok(plan)
}

/// The machine motion of one of the document's plans, in the motion mode it was planned for
/// ([`crate::motion::lower_motion`]).
pub fn lower_plan(doc: &Document, plan: &Plan) -> Result<Toolpath, PipelineError> {
    lower_plan_on(doc, plan, None)
}

/// [`lower_plan`] on a controller clock of `period_s` (what a trajectory at that period runs).
pub fn lower_plan_on(
    doc: &Document,
    plan: &Plan,
    clock_s: Option<f64>,
) -> Result<Toolpath, PipelineError> {
    // exports and the GUI's display run to the end: no cancel
    let ctx = JobCtx::default();
    lower_motion(&doc.geometries, plan, &doc.profile, clock_s, &ctx).map_err(|source| {
        PipelineError::Lower {
            file: doc.source.clone().unwrap_or_else(|| "document".into()),
            source,
        }
    })
}
