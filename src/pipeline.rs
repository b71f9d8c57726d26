//! The whole pipeline on a [`Document`]: import → fields → order → metrics, with stage times.

use crate::document::{
    is_hatch_output, sync_layers, ArtworkImport, DerivedKey, Document, Geometry, MachineProfile,
    Motion, MotionMode, Pen, PenLibrary, Plan, PlanInputs, Production, ScanField, SolverSettings,
    StageRouteKind, Stamp, TraySettings, Warning,
};
use crate::fields::{
    check_artwork, cut_hatch_at_tiling, place_fields, split_oversize, FieldError, Placement,
    SPLIT_WORDS,
};
use crate::geom::seam::SeamStats;
use crate::geom::tiling::Tiling;
use crate::hatch::{layer_geometries, HatchError};
use crate::import::{import_file, ImportError, ImportOptions, SkippedLayer};
use crate::job::JobCtx;
use crate::motion::{lower_motion, plan_stage_route, MotionError, OtfError, Toolpath};
pub use crate::order::expand_passes;
use crate::order::{order_plan, OrderError};
use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;
use thiserror::Error;

mod cylinder;
pub use cylinder::{cylinder_strips, Strips};

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
    /// A project could not be read.
    #[error(transparent)]
    Project(Box<crate::document::ProjectError>),
    /// A field's pose the machine cannot take.
    #[error("{file}: {source}")]
    Pose {
        /// The document's source file.
        file: String,
        /// The cause.
        source: Box<crate::document::PoseError>,
    },
    /// Placements that turn or lift axes beyond X/Y, planned on the fly.
    #[error("{file}: the fields turn or lift axes beyond X/Y ({axes}), which only step-and-scan moves between fields; plan with step-and-scan")]
    PosesOnTheFly {
        /// The document's source file.
        file: String,
        /// The profile's axes in words.
        axes: String,
    },
    /// Every layer is disabled.
    #[error("{file}: every layer is disabled: nothing to mark")]
    AllDisabled {
        /// The document's source file.
        file: String,
    },
    /// The document no longer has the geometries the plan was planned on.
    #[error("{file}: the geometries this plan was planned on are no longer in the document; solve again")]
    LostGeometries {
        /// The document's source file.
        file: String,
    },
    /// The production job (tray, serials, texts with fields, data) cannot be made.
    #[error("{file}: {source}")]
    Production {
        /// The document's source file.
        file: String,
        /// The cause.
        source: crate::document::ProductionError,
    },
    /// A cylinder job the machine or the drawing cannot make.
    #[error("{file}: {source}")]
    Cylinder {
        /// The document's source file.
        file: String,
        /// The cause.
        source: crate::document::CylinderError,
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

/// Something the operator can do about a failure (the CLI and the GUI each say it in their
/// own words: a flag, or the control that does the same).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Remedy {
    /// Geometries are larger than a scan field: cut them at field borders, or mark on the fly.
    SplitOversize,
    /// The artwork fits within the laser's reach but lies outside it: place it elsewhere
    /// (centred on the base stroke, or at a corner).
    Place,
    /// The machine has no Y stroke (it turns the part on its A axis instead): the artwork lies
    /// beyond a flat job's reach; mark it around a cylinder.
    Cylinder,
}

impl PipelineError {
    /// What could help, when the operator can act on the cause.
    pub fn remedy(&self) -> Option<Remedy> {
        match self {
            PipelineError::Fields {
                source:
                    FieldError::Artwork { stroke_mm, .. } | FieldError::OutOfReach { stroke_mm, .. },
                ..
            } if stroke_mm[1] <= 0.0 => Some(Remedy::Cylinder),
            PipelineError::Fields {
                source: FieldError::Oversize { .. },
                ..
            } => Some(Remedy::SplitOversize),
            PipelineError::Fields { source, .. } if source.fits_once_moved() => Some(Remedy::Place),
            _ => None,
        }
    }
}

/// Imports an SVG or DXF file ([`import_file`]) into a new document with the given profile and
/// settings; returns it with the import time in s. The artwork is placed on the profile's
/// machine as `opts.place` says (unset `opts.work_area_mm` and `opts.field_mm` are the
/// profile's base stroke and field; `opts.resolution_mm` is the G-code's: offsets below a unit
/// of its last decimal are not made).
pub fn load_svg(
    path: &Path,
    profile: MachineProfile,
    settings: SolverSettings,
    opts: &ImportOptions,
) -> Result<(Document, f64), PipelineError> {
    load_artwork(path, profile, settings, opts).map(|l| (l.doc, l.import_s))
}

/// A document made by [`load_artwork`], with what the import left out or changed.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The new document.
    pub doc: Document,
    /// Import time, s.
    pub import_s: f64,
    /// Layers the drawing hides, not imported (import them with
    /// [`ImportOptions::hidden_layers`]).
    pub skipped_layers: Vec<SkippedLayer>,
    /// How far the placement moved the artwork, mm (zero: as in the file).
    pub moved_mm: [f64; 2],
}

/// [`load_svg`] with the import's skipped layers and placement offset. A drawing whose texts
/// hold fields is a production job of one part: its artwork is made by `tray::expand`.
pub fn load_artwork(
    path: &Path,
    profile: MachineProfile,
    settings: SolverSettings,
    opts: &ImportOptions,
) -> Result<Loaded, PipelineError> {
    load_production(path, profile, settings, opts, &TraySettings::default())
}

/// [`load_artwork`] as a production job: with any of `tray`'s options, they are set on the
/// document's production (made of its artwork when it has none); a production's tray is then
/// expanded into the artwork.
pub fn load_production(
    path: &Path,
    profile: MachineProfile,
    settings: SolverSettings,
    opts: &ImportOptions,
    tray: &TraySettings,
) -> Result<Loaded, PipelineError> {
    let t0 = Instant::now();
    if path.extension().is_some_and(|e| e == "galvoplan") {
        return load_project_job(path, profile, settings, t0);
    }
    let mut opts = opts.clone();
    // around a cylinder: its unrolled surface
    let reach = crate::document::Cylinder::reach_profile(&profile, settings.cylinder);
    opts.work_area_mm.get_or_insert(reach.stroke_mm);
    opts.field_mm.get_or_insert(reach.field_mm);
    // the G-code's resolution: a unit in its last decimal
    opts.resolution_mm = profile.resolution_mm();
    let imported = import_file(path, &opts)?;
    let mut layers = Vec::new();
    sync_layers(&mut layers, &imported.geometries, &settings.default_pen());
    let templates = !imported.templates.is_empty();
    let production = (templates || tray.is_set()).then(|| {
        Production::of_part(
            unplaced(&imported.geometries, imported.moved_mm),
            imported.templates.clone(),
            opts.chord_tol_mm,
        )
    });
    let mut doc = Document {
        source: Some(path.display().to_string()),
        page_mm: imported.page_mm,
        artwork: imported.geometries.clone(),
        layers,
        geometries: imported.geometries,
        warnings: imported.warnings,
        profile,
        settings,
        import: ArtworkImport {
            place: opts.place,
            hidden_layers: imported.skipped_layers.clone(),
            included: Vec::new(),
        },
        production,
        ..Document::default()
    };
    if let Some(p) = doc.production.as_mut() {
        tray.apply(p).map_err(|source| PipelineError::Production {
            file: path.display().to_string(),
            source,
        })?;
        expand_production(&mut doc)?;
    }
    Ok(Loaded {
        doc,
        import_s: t0.elapsed().as_secs_f64(),
        skipped_layers: imported.skipped_layers,
        moved_mm: imported.moved_mm,
    })
}

/// A project's artwork and fields as a job for `profile` and `settings` (the command line's;
/// a cylinder job's cylinder unless they name one): its fields are kept as placed (locked),
/// with their poses.
fn load_project_job(
    path: &Path,
    profile: MachineProfile,
    settings: SolverSettings,
    t0: Instant,
) -> Result<Loaded, PipelineError> {
    let mut doc =
        crate::document::load_project(path).map_err(|e| PipelineError::Project(Box::new(e)))?;
    doc.profile = profile;
    // a cylinder job stays one unless the command line names another cylinder
    let cylinder = settings.cylinder.or(doc.settings.cylinder);
    doc.settings = SolverSettings {
        cylinder,
        ..settings
    };
    doc.plans.clear();
    for f in &mut doc.fields {
        f.locked = true;
    }
    doc.source = Some(path.display().to_string());
    Ok(Loaded {
        doc,
        import_s: t0.elapsed().as_secs_f64(),
        skipped_layers: Vec::new(),
        moved_mm: [0.0, 0.0],
    })
}

/// Geometries moved back by a placement's offset: in the file's coordinates again.
fn unplaced(geometries: &[Geometry], moved_mm: [f64; 2]) -> Vec<Geometry> {
    let back = crate::geom::Pt::new(-moved_mm[0], -moved_mm[1]);
    geometries
        .iter()
        .map(|g| {
            let mut g = g.clone();
            for p in &mut g.points {
                *p = p.plus(back);
            }
            g
        })
        .collect()
}

/// Makes the document's artwork from its production (`tray::expand`, the date and time now
/// where the production fixes none); the error names the document's file. The geometries are
/// made from the new artwork by the next [`derive_geometries`] (every solve and placement
/// starts with it).
pub fn expand_production(doc: &mut Document) -> Result<(), PipelineError> {
    crate::tray::expand(doc, Stamp::now()).map_err(|source| PipelineError::Production {
        file: doc.source.clone().unwrap_or_default(),
        source,
    })
}

/// Places fields (replacing the document's unlocked ones; locked fields stay) and orders the
/// geometries; returns the plan with `solve_s.fields` and `solve_s.order` filled in. With
/// `split_oversize`, geometries larger than a field are first cut into pieces (and reported as
/// warnings). The plan is not added to `doc.plans`.
pub fn plan_document(doc: &mut Document, ctx: &JobCtx) -> Result<Plan, PipelineError> {
    plan_document_lowered(doc, ctx).map(|(plan, _)| plan)
}

/// [`plan_document`] with the plan's toolpath (see [`order_document_lowered`]).
pub fn plan_document_lowered(
    doc: &mut Document,
    ctx: &JobCtx,
) -> Result<(Plan, Toolpath), PipelineError> {
    if doc.settings.cylinder.is_some() {
        return plan_cylinder(doc, ctx);
    }
    check_poses(doc, &doc.fields)?;
    // a job whose fields turn Z, A or B has one motion: auto plans it step-and-scan
    let posed = doc.fields.iter().any(|f| !f.pose.is_rest());
    let auto = doc.settings.motion;
    if posed {
        doc.settings.motion = MotionMode::Step;
    }
    let made = plan_step_or_auto(doc, ctx);
    doc.settings.motion = auto;
    made
}

/// Why auto planned one motion only, said like the whole-or-cut choice: the last solve's note
/// replaces the one before.
fn motion_notes(doc: &mut Document, plan: &Plan) {
    doc.warnings.retain(|w| {
        !w.message.starts_with(crate::order::FLY_NOT_PLANNED)
            && !w.message.starts_with(crate::order::LINUXCNC_OTF_NOTE)
            && !w.message.starts_with(crate::order::STREAMED_NOTE)
    });
    if let Some(note) = &plan.metrics.motion_note {
        doc.warnings.push(choice_warning(note.clone()));
    }
}

/// [`plan_document_lowered`] on a cylinder: the strips placed on the work profile
/// ([`cylinder::with_work_profile`]), then ordered and lowered on the machine.
fn plan_cylinder(doc: &mut Document, ctx: &JobCtx) -> Result<(Plan, Toolpath), PipelineError> {
    let t0 = Instant::now();
    let (hatch_s, lower_bound) = cylinder::with_work_profile(doc, |doc| {
        let hatch_s = derive_geometries(doc, ctx)?;
        let (lower_bound, _) = place_and_choose(doc, ctx)?;
        Ok((hatch_s, lower_bound))
    })?;
    let fields_s = (t0.elapsed().as_secs_f64() - hatch_s).max(0.0);
    let (mut plan, toolpath) = order_document_lowered(doc, ctx)?;
    motion_notes(doc, &plan);
    plan.metrics.solve_s.hatch = hatch_s;
    plan.metrics.solve_s.fields = fields_s;
    plan.metrics.fields_lower_bound = Some(lower_bound);
    plan.metrics.solve_s.total =
        plan.metrics.solve_s.hatch + plan.metrics.solve_s.fields + plan.metrics.solve_s.order;
    Ok((plan, toolpath))
}

/// [`plan_document_lowered`] once the poses are checked.
fn plan_step_or_auto(doc: &mut Document, ctx: &JobCtx) -> Result<(Plan, Toolpath), PipelineError> {
    let hatch_s = derive_geometries(doc, ctx)?;
    let t0 = Instant::now();
    let (lower_bound, made) = place_and_choose(doc, ctx)?;
    // the orderings of a whole-or-cut choice are the order stage's time, not the field stage's
    let choice_s = made.as_ref().map_or(0.0, |(p, _)| p.metrics.solve_s.order);
    let fields_s = (t0.elapsed().as_secs_f64() - choice_s).max(0.0);
    let (mut plan, toolpath) = match made {
        Some((plan, toolpath)) => {
            log_inputs(doc, ctx);
            complete_plan(doc, plan, toolpath, ctx)?
        }
        None => order_document_lowered(doc, ctx)?,
    };
    plan.metrics.solve_s.hatch = hatch_s;
    plan.metrics.solve_s.fields = fields_s;
    plan.metrics.fields_lower_bound = Some(lower_bound);
    motion_notes(doc, &plan);
    if doc.geometries.iter().any(|g| g.pass > 0) {
        compare_unshifted(doc, &mut plan, &toolpath, ctx)?;
    }
    plan.metrics.solve_s.total =
        plan.metrics.solve_s.hatch + plan.metrics.solve_s.fields + plan.metrics.solve_s.order;
    Ok((plan, toolpath))
}

/// The machine can take every field's pose, and a job whose fields turn or lift axes beyond X/Y
/// is planned step-and-scan (on the fly keeps Z, A and B still).
fn check_poses(doc: &Document, fields: &[ScanField]) -> Result<(), PipelineError> {
    let file = || doc.source.clone().unwrap_or_else(|| "document".into());
    for f in fields {
        doc.profile
            .check_pose(f.id, &f.pose)
            .map_err(|source| PipelineError::Pose {
                file: file(),
                source: Box::new(source),
            })?;
    }
    if doc.settings.motion == MotionMode::OnTheFly && fields.iter().any(|f| !f.pose.is_rest()) {
        return Err(PipelineError::PosesOnTheFly {
            file: file(),
            axes: doc.profile.axes_words(),
        });
    }
    Ok(())
}

/// Geometries cut on one tiling in the whole-or-cut choice, placed and ordered.
struct CutCandidate {
    /// What the choice's timing detail calls it.
    label: &'static str,
    pieces: Vec<crate::document::Geometry>,
    warnings: Vec<Warning>,
    seams: SeamStats,
    tiling: Option<Tiling>,
    placement: Placement,
    made: (Plan, Toolpath),
}

impl CutCandidate {
    /// Its job time, s.
    fn job_s(&self) -> f64 {
        self.made.1.duration_s()
    }
}

/// The field grid's cells are this much narrower than the field, mm.
const FIELD_GRID_SLACK_MM: f64 = 1e-6;

/// The words that begin the note comparing shifted passes with passes on the same seams.
const SHIFTED_PREFIX: &str = "shifted passes: ";

/// A plan with shifted passes: plans the same job with every pass cut on the same seams and
/// says both job times in a warning, so the operator sees what shifting costs. Its planning
/// time is counted in the order stage ("unshifted").
fn compare_unshifted(
    doc: &mut Document,
    plan: &mut Plan,
    toolpath: &Toolpath,
    ctx: &JobCtx,
) -> Result<(), PipelineError> {
    let t = Instant::now();
    // the plans and the geometries they keep play no part: not cloned
    let plans = std::mem::take(&mut doc.plans);
    let kept = std::mem::take(&mut doc.kept_geometries);
    let mut same = Document {
        derived_with: None,
        fields: Vec::new(),
        ..doc.clone()
    };
    doc.plans = plans;
    doc.kept_geometries = kept;
    for l in &mut same.layers {
        l.pen.shift_passes = false;
    }
    let (_, unshifted) = plan_document_lowered(&mut same, ctx)?;
    let (a, b) = (toolpath.duration_s(), unshifted.duration_s());
    let note = format!(
        "{SHIFTED_PREFIX}the job takes {} s with each pass cut on its own seams ({} fields), against {} s with every pass on the same seams ({} fields)",
        format_s(a),
        plan.fields.len(),
        format_s(b),
        same.fields.len()
    );
    doc.warnings
        .retain(|w| !w.message.starts_with(SHIFTED_PREFIX));
    doc.warnings.push(choice_warning(note));
    let s = t.elapsed().as_secs_f64();
    plan.metrics.solve_s.order += s;
    plan.metrics
        .solve_s
        .order_detail
        .push(("unshifted".into(), s));
    Ok(())
}

/// The hatch stage: makes the geometries to mark from the artwork and its layers' pens
/// ([`layer_geometries`]: disabled layers left out, hatched layers filled, each hatch geometry
/// small enough for one scan field). Layers the table lacks are added first with the default
/// pen (whose hatch is `settings.hatch`, the CLI's `--hatch`). Runs only when the layers'
/// names, enabled flags or hatches or the field size changed since the geometries were last
/// made; when the geometries change, fields and plans of the old list are cleared (indices
/// changed). Returns the wall time in s.
pub fn derive_geometries(doc: &mut Document, ctx: &JobCtx) -> Result<f64, PipelineError> {
    let t0 = Instant::now();
    if doc.artwork.is_empty() {
        // a document made before pens (or by hand): its geometries are the artwork
        doc.artwork = doc
            .geometries
            .iter()
            .filter(|g| !is_hatch_output(g))
            .cloned()
            .collect();
    }
    sync_layers(&mut doc.layers, &doc.artwork, &doc.settings.default_pen());
    // fills fit the fields they are placed in: on a cylinder its strips
    let field_mm = doc.reach_profile().field_mm;
    let key = DerivedKey::of(&doc.layers, field_mm, doc.tiling_set.as_ref());
    if doc.derived_with.as_ref() == Some(&key) {
        return Ok(0.0);
    }
    doc.uncut_geometries = None;
    drop_cut_warnings(&mut doc.warnings);
    let made = layer_geometries(&doc.artwork, &doc.layers, ctx).map_err(|source| {
        PipelineError::Hatch {
            file: doc.source.clone().unwrap_or_else(|| "document".into()),
            source,
        }
    })?;
    // fills larger than a field are cut on the document's tiling
    let (tiling, cut) = cut_hatch_at_tiling(
        made.geometries,
        &doc.layers,
        field_mm,
        doc.tiling_set.as_ref(),
    );
    doc.tiling = tiling;
    doc.seams = cut.stats;
    // indices may change: the fields go, the plans keep the geometries they were planned on
    doc.set_geometries(cut.geometries);
    for w in made.warnings {
        if !doc.warnings.contains(&w) {
            doc.warnings.push(w);
        }
    }
    doc.derived_with = Some(key);
    Ok(t0.elapsed().as_secs_f64())
}

/// Moves the seam of `axis` (0: a vertical seam, x; 1: a horizontal one, y) nearest to
/// `from_mm` towards `to_mm` (as far as its neighbours allow: no cell wider than a field leaves
/// room for). The document keeps the moved tiling as the operator's (`tiling_set`): the next
/// [`derive_geometries`] cuts on it and the fields are placed again. Returns where the seam
/// went, mm; none when the document has no seam on that axis.
pub fn move_seam(doc: &mut Document, axis: usize, from_mm: f64, to_mm: f64) -> Option<f64> {
    let tiling = doc.tiling.as_ref()?;
    let cell_max = crate::fields::cell_max_mm(&doc.layers, doc.profile.field_mm);
    let (moved, at) = crate::fields::move_seam(tiling, axis, from_mm, to_mm, cell_max)?;
    doc.tiling_set = Some(moved);
    Some(at)
}

/// Gives the document's layers the pens of a library (`--pens`; the library's default pen, or
/// the settings' hatch as the default pen's hatch, for layers it does not name); returns the
/// names the library has but the document lacks. The geometries are made again on the next
/// [`derive_geometries`].
pub fn apply_pen_library(doc: &mut Document, library: &PenLibrary) -> Vec<String> {
    sync_layers(&mut doc.layers, &doc.artwork, &doc.settings.default_pen());
    let mut library = library.clone();
    if let Some(h) = &doc.settings.hatch {
        let d = library.default.get_or_insert_with(Pen::default);
        if d.hatch.is_none() {
            d.hatch = Some(h.clone());
        }
    }
    library.apply(&mut doc.layers)
}

/// On the fly with seed 001's routes (`lsa`, `cetsp-ga`): plans the stage route on the plan's
/// time law (its pens' speeds and passes) and adds the route's planning time to the order
/// stage. True when a route was planned: the plan must then be lowered along it.
fn plan_seed_route(doc: &Document, plan: &mut Plan, ctx: &JobCtx) -> Result<bool, PipelineError> {
    let s = &plan.settings;
    if plan.motion != Motion::OnTheFly || s.stage_route == StageRouteKind::Taut {
        return Ok(false);
    }
    let t = Instant::now();
    let file = || doc.source.clone().unwrap_or_else(|| "document".into());
    let route = plan_stage_route(
        &doc.geometries,
        plan,
        &plan.profile,
        s.stage_route,
        &s.route_ga,
        s.seed,
        ctx,
    )
    .map_err(|e| match e {
        OtfError::Cancelled(c) => PipelineError::Order {
            file: file(),
            source: OrderError::Cancelled(c),
        },
        other => PipelineError::Lower {
            file: file(),
            source: MotionError::OnTheFly(other),
        },
    })?;
    plan.stage_route = route;
    let route_s = t.elapsed().as_secs_f64();
    let solve = &mut plan.metrics.solve_s;
    solve.order += route_s;
    solve.total += route_s;
    solve.order_detail.push(("route".into(), route_s));
    Ok(true)
}

/// Lowers `plan` again (along its new stage route) and computes its metrics on that toolpath
/// (keeping its solve times and field lower bound); returns the toolpath.
fn relower(doc: &Document, plan: &mut Plan) -> Result<Toolpath, PipelineError> {
    let toolpath = lower_plan(doc, plan)?;
    let m = crate::order::metrics::compute(
        &doc.geometries,
        &plan.fields,
        &plan.order,
        &plan.profile,
        plan.settings.cylinder,
        &toolpath,
    );
    plan.metrics = crate::document::Metrics {
        solve_s: std::mem::take(&mut plan.metrics.solve_s),
        fields_lower_bound: plan.metrics.fields_lower_bound,
        motion_note: plan.metrics.motion_note.take(),
        motion_regions: toolpath.motion_regions(),
        ..m
    };
    Ok(toolpath)
}

/// The field stage alone: makes the geometries from the layers (when they changed, see
/// [`derive_geometries`]), splits oversize geometries when the settings say so, then places the
/// fields (keeping locked ones) and allocates the geometries. Returns the lower bound on fields.
///
/// Geometries larger than a field cannot be marked step-and-scan whole. On the fly they can:
/// unless the settings cut them (`split_oversize`), a solve that may fly marks them whole or cut
/// at field borders, whichever the lowered job time says is faster ([`whole_or_cut`]); a
/// step-and-scan solve stops with [`FieldError::Oversize`].
pub fn place_document_fields(doc: &mut Document, ctx: &JobCtx) -> Result<usize, PipelineError> {
    cylinder::with_work_profile(doc, |doc| {
        place_and_choose(doc, ctx).map(|(lower_bound, _)| lower_bound)
    })
}

/// [`place_document_fields`] for a workbench: where step-and-scan geometries are larger than
/// a field (and neither splitting nor on the fly is chosen), fields are still placed for every
/// geometry that fits, and the larger ones are left uncovered; returns that error beside the
/// placement (`Some`), for the caller to say once. Any other error is returned.
pub fn place_what_fits(
    doc: &mut Document,
    ctx: &JobCtx,
) -> Result<Option<PipelineError>, PipelineError> {
    let oversize = match place_document_fields(doc, ctx) {
        Ok(_) => return Ok(None),
        Err(
            e @ PipelineError::Fields {
                source: FieldError::Oversize { .. },
                ..
            },
        ) => e,
        Err(e) => return Err(e),
    };
    let field_mm = doc.profile.field_mm;
    let fits: Vec<usize> = (0..doc.geometries.len())
        .filter(|&i| !crate::fields::is_oversize(&doc.geometries[i], field_mm))
        .collect();
    let subset: Vec<crate::document::Geometry> =
        fits.iter().map(|&i| doc.geometries[i].clone()).collect();
    let locked: Vec<ScanField> = doc.fields.iter().filter(|f| f.locked).cloned().collect();
    let file = doc.source.clone().unwrap_or_else(|| "document".into());
    let placement = place_fields(&subset, &doc.profile, &doc.settings, &[], ctx)
        .map_err(|source| PipelineError::Fields { file, source })?;
    // locked fields stay where they are, holding what they held
    let mut fields = locked;
    let next_id = fields.iter().map(|f| f.id + 1).max().unwrap_or(0);
    let held: std::collections::HashSet<usize> = fields
        .iter()
        .flat_map(|f| f.geometries.iter().copied())
        .collect();
    for (k, mut f) in placement.fields.into_iter().enumerate() {
        f.id = next_id + k;
        f.geometries = f
            .geometries
            .iter()
            .map(|&j| fits[j])
            .filter(|g| !held.contains(g))
            .collect();
        if !f.geometries.is_empty() {
            fields.push(f);
        }
    }
    doc.fields = fields;
    Ok(Some(oversize))
}

/// A plan and its toolpath made while choosing the geometries, reusable by the solve.
type Made = Option<(Plan, Toolpath)>;

/// [`place_document_fields`], with the plan the whole-or-cut choice made on the chosen
/// geometries when it is the plan the solve would make (not under HGA, whose choice is made on
/// HHA plans).
fn place_and_choose(doc: &mut Document, ctx: &JobCtx) -> Result<(usize, Made), PipelineError> {
    derive_geometries(doc, ctx)?;
    if !doc.settings.split_oversize && !doc.settings.motion.may_fly() {
        // a placement that may not cut starts again from the whole geometries
        if let Some(whole) = doc.uncut_geometries.take() {
            doc.set_geometries(whole);
            doc.seams = std::mem::take(&mut doc.uncut_seams);
            drop_cut_warnings(&mut doc.warnings);
        }
    }
    if doc.geometries.is_empty() && !doc.artwork.is_empty() {
        return Err(PipelineError::AllDisabled {
            file: doc.source.clone().unwrap_or_else(|| "document".into()),
        });
    }
    let file = doc.source.clone().unwrap_or_else(|| "document".into());
    if doc.settings.split_oversize {
        // artwork beyond the reach is not helped by cutting: said before a warning per cut
        check_artwork(&doc.geometries, &doc.profile).map_err(|source| PipelineError::Fields {
            file: file.clone(),
            source,
        })?;
        let mut geometries = doc.geometries.clone();
        let (warnings, seams, tiling) = split_oversize(
            &mut geometries,
            doc.tiling.as_ref(),
            &doc.layers,
            doc.profile.field_mm,
        );
        if !warnings.is_empty() {
            cut_geometries(doc, geometries, warnings, seams, tiling);
        }
    }
    let locked: Vec<ScanField> = doc.fields.iter().filter(|f| f.locked).cloned().collect();
    let placed = place_fields(&doc.geometries, &doc.profile, &doc.settings, &locked, ctx);
    match placed {
        Err(FieldError::Oversize { .. }) if doc.settings.motion.may_fly() => {
            check_artwork(&doc.geometries, &doc.profile).map_err(|source| {
                PipelineError::Fields {
                    file: file.clone(),
                    source,
                }
            })?;
            whole_or_cut(doc, &locked, ctx)
        }
        other => {
            let placement = other.map_err(|source| PipelineError::Fields { file, source })?;
            doc.fields = placement.fields;
            Ok((placement.lower_bound, None))
        }
    }
}

/// Geometries larger than a field, in a solve that may fly: plans them whole (one region
/// around everything, on the fly) and cut at field borders (fields placed on the pieces, in
/// every motion the settings allow), and keeps the faster on the lowered job time. The
/// document gets the chosen geometries and fields, and a warning saying what was chosen and
/// why. Returns the lower bound on fields and the chosen plan (see [`place_and_choose`]).
fn whole_or_cut(
    doc: &mut Document,
    locked: &[ScanField],
    ctx: &JobCtx,
) -> Result<(usize, Made), PipelineError> {
    let file = doc.source.clone().unwrap_or_else(|| "document".into());
    let as_order_error = |source| PipelineError::Order {
        file: file.clone(),
        source,
    };
    // the choice is made on HHA plans when the solve is HGA (its GA runs once, afterwards)
    let mut judge = PlanInputs::of(doc);
    if judge.settings.algo == crate::document::Algo::Hga {
        judge.settings.algo = crate::document::Algo::Hha;
    }
    let reusable = judge.settings.algo == doc.settings.algo;
    // whole: one region, on the fly only
    let whole_region = whole_work_region(&doc.geometries);
    let mut on_the_fly = judge.clone();
    on_the_fly.settings.motion = MotionMode::OnTheFly;
    let whole_ctx = ctx.labelled("Marked whole");
    let order_whole = || {
        order_plan(
            &doc.geometries,
            &whole_region.fields,
            &on_the_fly,
            &whole_ctx,
        )
        .map_err(as_order_error)
    };
    let (mut made, lower_bound, note) = if judge.settings.stage_route != StageRouteKind::Taut {
        let whole = order_whole()?;
        // the route paper's routes are made for the whole pattern (cut, lissajous on lsa took
        // 75.6 s against 11.09 s whole)
        doc.fields = whole_region.fields;
        let note =
            "marked whole on the fly: the lsa and cetsp-ga stage routes follow the whole pattern"
                .to_string();
        (whole, whole_region.lower_bound, note)
    } else {
        let tilings = cut_tilings(doc);
        let cut = |tiling| plan_cut(doc, locked, &judge, tiling, &file, ctx);
        // the candidates are independent: planned side by side (each is deterministic)
        let started = Instant::now();
        let (whole, cuts_made) = rayon::join(order_whole, || {
            tilings.into_par_iter().map(cut).collect::<Vec<_>>()
        });
        let (whole, cuts_made) = finished_candidates(whole, cuts_made)?;
        // the order stage's wall time (the candidates' own times, in the detail, overlap)
        let order_s = started.elapsed().as_secs_f64();
        choose_whole_or_cut(doc, whole, whole_region, cuts_made, order_s)
            .ok_or_else(|| as_order_error(OrderError::Cancelled(crate::job::Cancelled)))?
    };
    // this choice replaces the last one's words
    doc.warnings
        .retain(|w| !w.message.starts_with(CHOICE_PREFIX));
    doc.warnings
        .push(choice_warning(format!("{CHOICE_PREFIX}{note}")));
    made.0.geometry_rev = doc.geometry_rev;
    made.0.settings.motion = doc.settings.motion;
    made.0.name = doc.settings.title_of(&made.0);
    Ok((lower_bound, reusable.then_some(made)))
}

/// The whole and cut candidates that were made: after a cancel, those finished (at least one;
/// the solve then names its plan stopped); any other error is the solve's.
#[allow(clippy::type_complexity)] // two results, each its own candidate type
fn finished_candidates(
    whole: Result<(Plan, Toolpath), PipelineError>,
    cuts: Vec<Result<CutCandidate, PipelineError>>,
) -> Result<(Option<(Plan, Toolpath)>, Vec<CutCandidate>), PipelineError> {
    let cancelled = |e: &PipelineError| {
        matches!(
            e,
            PipelineError::Order {
                source: OrderError::Cancelled(_),
                ..
            } | PipelineError::Fields {
                source: crate::fields::FieldError::Cancelled(_),
                ..
            }
        )
    };
    let mut stop = None;
    let whole = match whole {
        Ok(made) => Some(made),
        Err(e) if cancelled(&e) => {
            stop = Some(e);
            None
        }
        Err(e) => return Err(e),
    };
    let mut made = Vec::new();
    for c in cuts {
        match c {
            Ok(c) => made.push(c),
            Err(e) if cancelled(&e) => stop = Some(e),
            Err(e) => return Err(e),
        }
    }
    match stop {
        Some(e) if whole.is_none() && made.is_empty() => Err(e),
        _ => Ok((whole, made)),
    }
}

/// The tilings a cut is tried on, each with its label (the order stage's detail) and words (its
/// progress): the document's and, when nothing is cut yet and no seam was
/// set by hand, also the plain field grid anchored at the corner (on the fly its pieces can run
/// faster: oversize.svg on the LinuxCNC clock 18.36 s against 20.71 s).
fn cut_tilings(doc: &Document) -> Vec<(&'static str, &'static str, Option<Tiling>)> {
    let mut tilings = vec![("cut", "Cut at field borders", doc.tiling.clone())];
    if doc.seams.cuts == 0 && doc.tiling_set.is_none() {
        let extent = doc
            .geometries
            .iter()
            .filter(|g| crate::fields::is_oversize(g, doc.profile.field_mm))
            .fold(crate::geom::BBox::EMPTY, |b, g| b.union(g.bbox()));
        // cells a hair under the field (the seam forms' reach does not apply: no overlap)
        let [fw, fh] = doc.profile.field_mm;
        let cell = [fw - FIELD_GRID_SLACK_MM, fh - FIELD_GRID_SLACK_MM];
        tilings.push((
            "cut on the field grid",
            "Cut on the field grid",
            Some(Tiling::anchored(extent, cell)),
        ));
    }
    tilings
}

/// The document's geometries cut on `tiling`, fields placed on the pieces and the plan made on
/// them with `judge` (every motion allowed).
fn plan_cut(
    doc: &Document,
    locked: &[ScanField],
    judge: &PlanInputs,
    (label, words, tiling): (&'static str, &'static str, Option<Tiling>),
    file: &str,
    ctx: &JobCtx,
) -> Result<CutCandidate, PipelineError> {
    let ctx = &ctx.labelled(words);
    let mut pieces = doc.geometries.clone();
    let (warnings, seams, tiling) = split_oversize(
        &mut pieces,
        tiling.as_ref(),
        &doc.layers,
        doc.profile.field_mm,
    );
    let placement =
        place_fields(&pieces, &doc.profile, &judge.settings, locked, ctx).map_err(|source| {
            PipelineError::Fields {
                file: file.to_string(),
                source,
            }
        })?;
    let made = order_plan(&pieces, &placement.fields, judge, ctx).map_err(|source| {
        PipelineError::Order {
            file: file.to_string(),
            source,
        }
    })?;
    Ok(CutCandidate {
        label,
        pieces,
        warnings,
        seams,
        tiling,
        placement,
        made,
    })
}

/// Keeps the faster of `whole` (one region, on the fly; none when a cancel stopped it) and the
/// best cut candidate on the lowered job time (none when neither was made), installs its geometries and fields in `doc`, and says why; the plan's
/// order stage gets every candidate's ordering time in its detail and `order_s` as its time.
fn choose_whole_or_cut(
    doc: &mut Document,
    whole: Option<(Plan, Toolpath)>,
    whole_region: Placement,
    cuts: Vec<CutCandidate>,
    order_s: f64,
) -> Option<((Plan, Toolpath), usize, String)> {
    let mut detail: Vec<(String, f64)> = whole
        .iter()
        .map(|w| ("whole".to_string(), w.0.metrics.solve_s.order))
        .collect();
    detail.extend(
        cuts.iter()
            .map(|c| (c.label.to_string(), c.made.0.metrics.solve_s.order)),
    );
    let best = cuts
        .into_iter()
        .min_by(|a, b| a.job_s().total_cmp(&b.job_s()));
    let cut_wins = match (&best, &whole) {
        (Some(c), Some(w)) => c.job_s() < w.1.duration_s(),
        (Some(_), None) => true,
        (None, _) => false,
    };
    let whole_s = whole.as_ref().map_or_else(
        || "– (stopped before it was planned)".into(),
        |w| format_s(w.1.duration_s()),
    );
    let (mut made, lower_bound, note) = match (best, whole) {
        (Some(c), _) if cut_wins => {
            let cut_s = format_s(c.job_s());
            cut_geometries(doc, c.pieces, c.warnings, c.seams, c.tiling);
            doc.fields = c.placement.fields;
            let note = format!("cut at field borders: the job takes {cut_s} s cut against {whole_s} s marked whole on the fly");
            (c.made, c.placement.lower_bound, note)
        }
        (best, Some(whole)) => {
            let cut_s = best.map_or_else(|| "–".into(), |c| format_s(c.job_s()));
            doc.fields = whole_region.fields;
            let note = format!("marked whole on the fly: the job takes {whole_s} s against {cut_s} s cut at field borders");
            (whole, whole_region.lower_bound, note)
        }
        // finished_candidates keeps at least one
        (_, None) => return None,
    };
    let solve = &mut made.0.metrics.solve_s;
    solve.order_detail = detail
        .into_iter()
        .chain(solve.order_detail.drain(..))
        .collect();
    solve.order = order_s;
    Some((made, lower_bound, note))
}

/// How the warning about the whole-or-cut choice begins (a placement replaces the last one's).
const CHOICE_PREFIX: &str = "geometries larger than a scan field are ";

/// Installs `pieces`, the document's geometries cut at field borders, with the cut `warnings`
/// (each once), keeping the whole geometries for a placement that may not cut
/// ([`Document::uncut_geometries`]).
fn cut_geometries(
    doc: &mut Document,
    pieces: Vec<crate::document::Geometry>,
    warnings: Vec<Warning>,
    seams: SeamStats,
    tiling: Option<Tiling>,
) {
    let whole = doc.geometries.clone();
    let whole_seams = doc.seams.clone();
    // indices changed: the plans keep the geometries they were planned on
    if doc.set_geometries(pieces) {
        if doc.uncut_geometries.is_none() {
            doc.uncut_geometries = Some(whole);
            doc.uncut_seams = whole_seams;
        }
        doc.seams.merge(seams);
        doc.tiling = tiling;
    }
    for w in warnings {
        if !doc.warnings.contains(&w) {
            doc.warnings.push(w);
        }
    }
}

/// Drops the warnings of a cut and of the whole-or-cut choice (the geometries are whole again).
fn drop_cut_warnings(warnings: &mut Vec<Warning>) {
    warnings.retain(|w| {
        !w.message.starts_with(CHOICE_PREFIX)
            && !w.message.starts_with(SHIFTED_PREFIX)
            && !w.message.contains(SPLIT_WORDS)
    });
}

/// A warning about a choice the solve made (no element of the drawing).
fn choice_warning(message: String) -> Warning {
    Warning {
        element: String::new(),
        line: None,
        message,
        note: false,
    }
}

/// A job time in s with the report's three decimals.
fn format_s(s: f64) -> String {
    format!("{s:.3}")
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
            pose: Default::default(),
        }],
        lower_bound: 1,
    }
}

/// The ordering stage alone, on the document's current fields and allocation (as the operator
/// left them). Takes `&Document` so that it can run on a snapshot in a background thread.
pub fn order_document(doc: &Document, ctx: &JobCtx) -> Result<Plan, PipelineError> {
    order_document_lowered(doc, ctx).map(|(plan, _)| plan)
}

/// [`order_document`] with the plan's toolpath, the one its metrics were computed on. The
/// plan records the document's inputs ([`PlanInputs`]): pens and passes are part of the time
/// law from the start, so the objective and every keep-the-faster choice see them, and the
/// plan is lowered once (twice only when seed 001's route is planned for it afterwards).
pub fn order_document_lowered(
    doc: &Document,
    ctx: &JobCtx,
) -> Result<(Plan, Toolpath), PipelineError> {
    let strips = cylinder::job_fields(doc)?;
    let fields = strips.as_deref().unwrap_or(&doc.fields);
    check_poses(doc, fields)?;
    let file = doc.source.clone().unwrap_or_else(|| "document".into());
    log_inputs(doc, ctx);
    let mut inputs = PlanInputs::of(doc);
    if fields.iter().any(|f| !f.pose.is_rest()) {
        // a job whose fields turn Z, A or B has one motion: auto plans it step-and-scan
        inputs.settings.motion = MotionMode::Step;
    }
    let (plan, toolpath) = order_plan(&doc.geometries, fields, &inputs, ctx)
        .map_err(|source| PipelineError::Order { file, source })?;
    complete_plan(doc, plan, toolpath, ctx)
}

/// Records the geometries and fields a solve starts from (with a recorder).
fn log_inputs(doc: &Document, ctx: &JobCtx) {
    if let Some(r) = ctx.recorder() {
        r.geometry(&doc.geometries);
        r.fields(&doc.fields);
    }
}

/// What follows the ordering: seed 001's stage route when the plan flies along one (and the
/// lowering along it), and the plan's recording.
fn complete_plan(
    doc: &Document,
    mut plan: Plan,
    mut toolpath: Toolpath,
    ctx: &JobCtx,
) -> Result<(Plan, Toolpath), PipelineError> {
    plan.metrics.solve_s.total = plan.metrics.solve_s.order;
    plan.tiling = doc.tiling.clone();
    plan.seams = doc.seams.clone();
    plan.parts = doc.parts.clone();
    if plan_seed_route(doc, &mut plan, ctx)? {
        toolpath = relower(doc, &mut plan)?;
    }
    if let Some(r) = ctx.recorder() {
        let marks: Vec<&[crate::geom::Pt]> = (0..toolpath.strokes.len())
            .map(|k| toolpath.stroke_points(k))
            .collect();
        r.plan(&plan, &marks);
    }
    Ok((plan, toolpath))
}

/// The machine motion of one of the document's plans: on its own geometries, machine, pens,
/// motion and controller clock ([`crate::motion::lower_motion`]), whatever the document's
/// current ones.
pub fn lower_plan(doc: &Document, plan: &Plan) -> Result<Toolpath, PipelineError> {
    lower_plan_on(
        doc,
        plan,
        plan.profile.controller.marks_clock_s(plan.motion),
    )
}

/// [`lower_plan`] on a clock of `clock_s` instead of its profile's (None: continuous).
pub fn lower_plan_on(
    doc: &Document,
    plan: &Plan,
    clock_s: Option<f64>,
) -> Result<Toolpath, PipelineError> {
    let file = || doc.source.clone().unwrap_or_else(|| "document".into());
    let geometries = doc
        .plan_geometries(plan)
        .ok_or_else(|| PipelineError::LostGeometries { file: file() })?;
    // exports and the GUI's display run to the end: no cancel
    let ctx = JobCtx::default();
    lower_motion(geometries, plan, clock_s, &ctx).map_err(|source| PipelineError::Lower {
        file: file(),
        source,
    })
}
