//! Ordering: which field after which, which geometry after which, where each one starts.

mod as_is;
mod bands;
mod baseline;
pub mod cost;
pub mod hga;
pub mod hha;
pub mod metrics;
mod mixed;
mod nested;
pub mod objective;
mod passes;
pub mod time;
pub mod tsp;
pub mod vertex;

pub use as_is::as_is_order;
pub use baseline::baseline_order;
pub use passes::expand_passes;

use crate::document::runs::Contraction;
use crate::document::{
    Algo, CostModel, GenerationRecord, Geometry, Motion, ObjectiveKind, Plan, PlanInputs,
    ScanField, SolverSettings, Step,
};
use crate::job::{Cancelled, JobCtx};
use crate::motion::{lower_motion, MotionError, OtfError, Toolpath};
use thiserror::Error;

/// Why ordering failed.
#[derive(Debug, Error)]
pub enum OrderError {
    /// The operator cancelled and there is no plan to return.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
    /// A geometry is not allocated to any field.
    #[error("{0} geometries are not allocated to a scan field (first: geometry {1})")]
    Unallocated(usize, usize),
    /// The plan cannot be turned into machine motion.
    #[error(transparent)]
    Lower(#[from] MotionError),
}

/// The ordered strokes of a run, before metrics.
#[derive(Debug, Clone, Default)]
pub struct Ordering {
    /// Field ids in visiting order.
    pub field_order: Vec<usize>,
    /// Strokes in marking order.
    pub steps: Vec<Step>,
}

/// Orders the allocated geometries with the algorithm in `inputs.settings` and returns the
/// plan with its metrics (stage times other than `order` are left for the caller to fill in)
/// and the toolpath they were computed on, so that the caller need not lower the plan again.
/// Every candidate is judged on the inputs' time law, pens and passes included
/// (`Candidates`). Under [`MotionMode::Auto`](crate::document::MotionMode::Auto) the plan is
/// made for each motion and the one with the shorter lowered job time is kept (HGA: the motion
/// of the faster HHA seed, whose GA then runs in that motion alone).
pub fn order_plan(
    geometries: &[Geometry],
    fields: &[ScanField],
    inputs: &PlanInputs,
    ctx: &JobCtx,
) -> Result<(Plan, Toolpath), OrderError> {
    check_allocation(geometries.len(), fields)?;
    // as-is marks the strokes as they come: no runs
    let nodes = Nodes::of(geometries, fields, inputs.settings.algo != Algo::AsIs);
    let settings = &inputs.settings;
    let motions = settings.motion.candidates();
    let t0 = std::time::Instant::now();
    let mut detail = Vec::new();
    let mut best: Option<Made> = None;
    // under auto, the on-the-fly plan when step-and-scan was faster (a mixed job starts from it)
    let mut flying: Option<Made> = None;
    let mut motion_note = None;
    // HGA under auto: the motion is chosen on finished HHA plans, the GA then runs in it alone
    let hga_after = settings.algo == Algo::Hga && motions.len() > 1;
    for &motion in motions {
        if best.is_some() && ctx.is_cancelled() {
            // a cancel keeps the plan made so far
            break;
        }
        if let (Motion::OnTheFly, Some(step)) = (motion, &best) {
            let t = std::time::Instant::now();
            if let Some(note) = flying_cannot_gain(&nodes, inputs, step.toolpath.duration_s()) {
                detail.push((FLY_NOT_PLANNED.into(), t.elapsed().as_secs_f64()));
                motion_note = Some(note);
                continue;
            }
        }
        let lower = Candidates::new(&nodes, inputs, motion, ctx);
        let mut stages = Vec::new();
        let made = match settings.algo {
            Algo::Hga if hga_after => hha_finished(&lower, t0, &mut stages)
                .map(|(ordering, toolpath)| (ordering, toolpath, Vec::new())),
            Algo::Hga => hga_plan(&lower, t0, None, &mut stages),
            Algo::AsIs | Algo::Baseline | Algo::Hha => run_algorithm(&lower, &mut stages)
                .and_then(|ordering| finish(&lower, ordering, hha_until(settings, t0), &mut stages))
                .map(|(ordering, toolpath)| (ordering, toolpath, Vec::new())),
        };
        let made = match made {
            Ok(made) => made,
            // a cancel while the next motion is planned keeps the plan made so far
            Err(OrderError::Cancelled(_)) if best.is_some() => break,
            Err(e) => return Err(e),
        };
        note_stages(&mut detail, motion, motions.len() > 1, stages);
        let made = Made {
            motion,
            ordering: made.0,
            toolpath: made.1,
            history: made.2,
            step_fields: Vec::new(),
        };
        best = Some(match best {
            Some(b) if b.toolpath.duration_s() <= made.toolpath.duration_s() => {
                flying = Some(made).filter(|m| m.motion == Motion::OnTheFly);
                b
            }
            _ => made,
        });
    }
    let mut best = best.ok_or(OrderError::Unallocated(0, 0))?;
    if hga_after && !ctx.is_cancelled() {
        // the GA runs in the motion whose HHA plan was faster, seeded with that plan
        let lower = Candidates::new(&nodes, inputs, best.motion, ctx);
        let mut stages = Vec::new();
        let hha = (best.ordering, best.toolpath);
        let seed = settings.ga.seed_with_hha.then_some(hha);
        let (ordering, toolpath, history) = hga_plan(&lower, t0, seed, &mut stages)?;
        note_stages(&mut detail, best.motion, true, stages);
        best = Made {
            motion: best.motion,
            ordering,
            toolpath,
            history,
            step_fields: Vec::new(),
        };
    }
    // auto: fields of the on-the-fly plan marked step-and-scan, where that is faster
    if motions.len() > 1 {
        let t = std::time::Instant::now();
        let from = match (&best, &flying) {
            (b, _) if b.motion == Motion::OnTheFly => Some(b),
            (_, f) => f.as_ref(),
        };
        let mixed = match from {
            Some(from) => match mixed::faster_mixed(&nodes, inputs, from, ctx) {
                Ok(m) => m.map(|(fields, toolpath)| Made {
                    motion: Motion::OnTheFly,
                    ordering: from.ordering.clone(),
                    toolpath,
                    history: from.history.clone(),
                    step_fields: fields,
                }),
                Err(OrderError::Cancelled(_)) => None,
                Err(e) => return Err(e),
            },
            None => None,
        };
        detail.push(("mixed".into(), t.elapsed().as_secs_f64()));
        if let Some(m) = mixed.filter(|m| m.toolpath.duration_s() < best.toolpath.duration_s()) {
            best = m;
        }
    }
    if motion_note.is_none() {
        motion_note = linuxcnc_note(&nodes, inputs, &best, ctx);
    }
    let order_s = t0.elapsed().as_secs_f64();
    let lower = Candidates::new(&nodes, inputs, best.motion, ctx);
    let mut plan = lower.plan(&best.ordering);
    plan.step_fields = best.step_fields;
    let mut m = metrics::compute(
        geometries,
        &plan.fields,
        &plan.order,
        &inputs.profile,
        settings.cylinder,
        &best.toolpath,
    );
    m.solve_s.order = order_s;
    m.solve_s.order_detail = detail;
    plan.name = settings.title_of(&plan);
    m.motion_note = motion_note;
    m.motion_regions = best.toolpath.motion_regions();
    plan.metrics = m;
    plan.history = best.history;
    Ok((plan, best.toolpath))
}

/// How the plan's motion note begins when an on-the-fly plan is streamed to LinuxCNC's joints.
pub const STREAMED_NOTE: &str = "Streamed to LinuxCNC's joints";

/// How the plan's motion note begins when LinuxCNC runs an on-the-fly plan.
pub const LINUXCNC_OTF_NOTE: &str = "LinuxCNC runs on-the-fly G-code without look-ahead";

/// On a LinuxCNC controller, an on-the-fly plan's note: why its job time is what it is. A
/// streamed plan: on the stream's clock, slowed at sharp corners ([`STREAMED_NOTE`]). A G93
/// program: LinuxCNC's pace, beside what step-and-scan would take on the same order ("LinuxCNC
/// runs on-the-fly G-code without look-ahead: 18.36 s; step-and-scan would take 8.16 s"; none
/// after a cancel, or where step-and-scan cannot mark the order). None elsewhere.
fn linuxcnc_note(nodes: &Nodes, inputs: &PlanInputs, best: &Made, ctx: &JobCtx) -> Option<String> {
    let controller = &inputs.profile.controller;
    if best.motion != Motion::OnTheFly
        || controller.kind != crate::document::ControllerKind::Linuxcnc
    {
        return None;
    }
    // a streamed plan runs at its own pace, on the stream's clock
    if let Some(period_s) = controller.stream_period_s {
        return Some(format!(
            "{STREAMED_NOTE} every {} ms: each mark starts and ends on a sample, and marks slow at \
             sharp corners so that the joints' straight moves between samples stay within {} mm \
             of the path",
            period_s * 1e3,
            inputs.profile.gcode.path_tol_mm
        ));
    }
    if ctx.is_cancelled() {
        return None;
    }
    let step = Candidates::new(nodes, inputs, Motion::Step, ctx)
        .toolpath(&best.ordering)
        .ok()?;
    Some(format!(
        "{LINUXCNC_OTF_NOTE}: {:.2} s on the fly; step-and-scan would take {:.2} s",
        best.toolpath.duration_s(),
        step.duration_s()
    ))
}

/// Under auto, on the fly is not planned for a job of more than this many strokes (passes
/// counted) when step-and-scan is already near the floor ([`FLY_GAIN_MIN`]).
pub const FLY_SKIP_STROKES_MIN: usize = 20_000;

/// The least share of the step-and-scan job time that on the fly must be able to gain to be
/// planned on a large job: its job time is at least the marking floor
/// ([`objective::marking_floor_s`]), so it can gain at most the step plan's time above that
/// floor. Its lowering costs about 55 µs a stroke (13 s on a 239,200-stroke fill, planned
/// twice: by fields and by bands; BENCHMARKS, issue 24), for at most this much.
pub const FLY_GAIN_MIN: f64 = 0.02;

/// How the order stage's detail and the plan's motion note ([`crate::document::Metrics::motion_note`]) begin
/// when on the fly was not planned.
pub const FLY_NOT_PLANNED: &str = "on the fly: not planned";

/// The plan's motion note when on the fly is not worth planning after a step-and-scan plan of
/// `step_s` on a large job: it could gain less than [`FLY_GAIN_MIN`] of it.
fn flying_cannot_gain(nodes: &Nodes, inputs: &PlanInputs, step_s: f64) -> Option<String> {
    let strokes: usize = nodes
        .geometries
        .iter()
        .map(|g| crate::document::passes_of(&inputs.layers, g) as usize)
        .sum();
    if strokes <= FLY_SKIP_STROKES_MIN {
        return None;
    }
    let floor_s = objective::marking_floor_s(nodes.geometries, &inputs.layers, &inputs.profile);
    (step_s - floor_s < FLY_GAIN_MIN * step_s).then(|| {
        format!(
            "{FLY_NOT_PLANNED}: step-and-scan takes {step_s:.3} s, within {:.0} % of the {floor_s:.3} s that marking and the laser's and jumps' delays take in any motion, so on the fly could gain less than that ({strokes} strokes)",
            FLY_GAIN_MIN * 100.0
        )
    })
}

/// A finished candidate plan: its motion, ordering, toolpath and GA history, and on the fly
/// the fields it marks step-and-scan ([`Plan::step_fields`]).
struct Made {
    motion: Motion,
    ordering: Ordering,
    toolpath: Toolpath,
    history: Vec<GenerationRecord>,
    step_fields: Vec<usize>,
}

/// Adds one motion's stage times to the solve's detail (named after the motion when a solve
/// tries both).
fn note_stages(
    detail: &mut Vec<(String, f64)>,
    motion: Motion,
    named: bool,
    stages: Vec<(String, f64)>,
) {
    let prefix = match (named, motion) {
        (false, _) => "",
        (true, Motion::Step) => "step: ",
        (true, Motion::OnTheFly) => "on the fly: ",
    };
    detail.extend(stages.into_iter().map(|(k, s)| (format!("{prefix}{k}"), s)));
}

/// When HHA's last search ends under a time limit (none for the other algorithms: HGA spends
/// its limit on its generations).
fn hha_until(settings: &SolverSettings, t0: std::time::Instant) -> Option<std::time::Instant> {
    (settings.algo == Algo::Hha)
        .then(|| hha::deadline(settings, t0, hha::LAST_SEARCH_SHARE))
        .flatten()
}

/// What every algorithm's ordering goes through to become a plan: on the fly, the sweep of
/// field-wide bands when it runs faster; under `--cost time` in step-and-scan, the refinement
/// for job time (kept only when faster; its searches end at `until`); then the lowering.
/// As-is orders are only lowered.
fn finish(
    lower: &Candidates,
    ordering: Ordering,
    until: Option<std::time::Instant>,
    detail: &mut Vec<(String, f64)>,
) -> Result<(Ordering, Toolpath), OrderError> {
    let settings = &lower.settings;
    let t = std::time::Instant::now();
    if settings.algo == Algo::AsIs {
        let toolpath = lower.toolpath(&ordering)?;
        return Ok((ordering, toolpath));
    }
    if lower.motion == Motion::OnTheFly {
        let best = faster_on_the_fly(lower, ordering)?;
        detail.push(("bands".into(), t.elapsed().as_secs_f64()));
        return Ok(best);
    }
    let ctx = lower.ctx;
    if settings.cost_model == CostModel::Time {
        ctx.progress("motion", 0, 1, "Step and scan: ordering for job time");
        let best = time_ordering(lower, ordering, until)?;
        detail.push(("time".into(), t.elapsed().as_secs_f64()));
        return Ok(best);
    }
    ctx.progress("motion", 0, 1, "Step and scan: timing the plan");
    let toolpath = lower.toolpath(&ordering)?;
    Ok((ordering, toolpath))
}

/// The HHA plan finished like any plan: HGA's seed.
fn hha_finished(
    lower: &Candidates,
    t0: std::time::Instant,
    detail: &mut Vec<(String, f64)>,
) -> Result<(Ordering, Toolpath), OrderError> {
    let t = std::time::Instant::now();
    let settings = &lower.settings;
    let o = hha::hha_order(
        lower.geometries,
        lower.fields,
        &lower.inputs.profile,
        settings,
        lower.ctx,
        detail,
    )?;
    let until = hha::deadline(settings, t0, hha::LAST_SEARCH_SHARE);
    let seed = finish(lower, o, until, detail)?;
    detail.push(("hha_seed".into(), t.elapsed().as_secs_f64()));
    Ok(seed)
}

/// HGA as a race on the plan's objective: the HHA plan, finished like any plan, seeds the GA
/// (when the settings say so; `seed` when it is already made); the GA ranks chromosomes on
/// the same objective
/// ([`objective`]); its best is finished the same way, and the better of the two finished
/// plans is returned, so HGA is never worse than its seed, also after a cancel or a time
/// limit. The history ends with the returned plan's table figure (when the GA's objective is
/// that figure: not on the fly, where it ranks on an estimate).
fn hga_plan(
    lower: &Candidates,
    t0: std::time::Instant,
    seed: Option<(Ordering, Toolpath)>,
    detail: &mut Vec<(String, f64)>,
) -> Result<(Ordering, Toolpath, Vec<GenerationRecord>), OrderError> {
    let (geometries, fields, inputs, ctx) =
        (lower.geometries, lower.fields, lower.inputs, lower.ctx);
    let settings = &lower.settings;
    let kind = ObjectiveKind::of(settings.cost_model, lower.motion);
    let seed = match seed {
        Some(seed) => Some(seed),
        None if settings.ga.seed_with_hha => Some(hha_finished(lower, t0, detail)?),
        None => None,
    };
    let step_time = objective::StepTime::new(geometries, fields, &inputs.layers, &inputs.profile);
    let of = |steps: &[Step]| match kind {
        ObjectiveKind::IdleMm => metrics::idle_mm(geometries, steps),
        ObjectiveKind::JobTimeS | ObjectiveKind::StepJobTimeEstimateS => {
            step_time.job_time_s(steps)
        }
    };
    let fitness = hga::Fitness { kind, of: &of };
    let t = std::time::Instant::now();
    let seed_ordering = seed.as_ref().map(|s| &s.0);
    let r = hga::hga_order(
        geometries,
        fields,
        &inputs.profile,
        settings,
        seed_ordering,
        &fitness,
        ctx,
    )?;
    detail.push(("ga".into(), t.elapsed().as_secs_f64()));
    let mut history = r.history;
    let ga = finish(lower, r.ordering, None, detail)?;
    let value = |c: &(Ordering, Toolpath)| match kind {
        ObjectiveKind::IdleMm => metrics::idle_mm(lower.real, &lower.plan(&c.0).order),
        ObjectiveKind::JobTimeS | ObjectiveKind::StepJobTimeEstimateS => c.1.duration_s(),
    };
    let best = match seed {
        Some(seed) if value(&seed) <= value(&ga) => seed,
        _ => ga,
    };
    if let (Some(last), ObjectiveKind::IdleMm | ObjectiveKind::JobTimeS) = (history.last(), kind) {
        let finished = GenerationRecord {
            best: value(&best),
            elapsed_s: t.elapsed().as_secs_f64(),
            finished: true,
            ..last.clone()
        };
        history.push(finished);
    }
    Ok((best.0, best.1, history))
}

/// The solve's geometries and fields, and the nodes its searches order: each chunk of a run
/// one node ([`Contraction::in_fields`]), or the geometries themselves when there is
/// no run.
struct Nodes<'a> {
    geometries: &'a [Geometry],
    fields: &'a [ScanField],
    runs: Option<(Contraction, Vec<ScanField>)>,
}

impl<'a> Nodes<'a> {
    fn of(geometries: &'a [Geometry], fields: &'a [ScanField], by_runs: bool) -> Self {
        let runs = by_runs
            .then(|| Contraction::in_fields(geometries, fields))
            .flatten()
            .map(|c| {
                let node_fields = c.fields_to_nodes(fields);
                (c, node_fields)
            });
        Self {
            geometries,
            fields,
            runs,
        }
    }
}

/// The one lower-and-compare helper: turns candidate orderings into plans of the solve's
/// inputs (pens, passes, profile, motion) and lowers them, so that every keep-the-faster
/// choice is judged on the time law the plan will have. Orderings are over the nodes
/// (`geometries`, `fields`); plans and toolpaths over the real geometries.
struct Candidates<'a> {
    /// The nodes the searches order.
    geometries: &'a [Geometry],
    /// The fields over the nodes.
    fields: &'a [ScanField],
    /// The geometries the plan marks.
    real: &'a [Geometry],
    /// The fields over them.
    real_fields: &'a [ScanField],
    /// How nodes expand to geometries (none: the nodes are the geometries).
    runs: Option<&'a Contraction>,
    inputs: &'a PlanInputs,
    /// The motion the candidates run in.
    motion: Motion,
    /// The inputs' settings with that motion (what the ordering reads).
    settings: SolverSettings,
    ctx: &'a JobCtx,
}

impl<'a> Candidates<'a> {
    fn new(nodes: &'a Nodes<'a>, inputs: &'a PlanInputs, motion: Motion, ctx: &'a JobCtx) -> Self {
        let settings = SolverSettings {
            motion: motion.into(),
            ..inputs.settings.clone()
        };
        let (geometries, fields, runs) = match &nodes.runs {
            Some((c, node_fields)) => (c.nodes(), node_fields.as_slice(), Some(c)),
            None => (nodes.geometries, nodes.fields, None),
        };
        Self {
            geometries,
            fields,
            real: nodes.geometries,
            real_fields: nodes.fields,
            runs,
            inputs,
            motion,
            settings,
            ctx,
        }
    }

    /// The plan of an ordering (unnamed, without metrics): its fields in visiting order, its
    /// strokes repeated for their layers' passes.
    fn plan(&self, ordering: &Ordering) -> Plan {
        let layers = &self.inputs.layers;
        let order = match self.runs {
            // a million steps: not copied again when no pen repeats its strokes
            Some(c) if layers.iter().all(|l| l.pen.passes <= 1) => {
                c.steps_to_geometries(&ordering.steps, self.real)
            }
            Some(c) => expand_passes(
                &c.steps_to_geometries(&ordering.steps, self.real),
                self.real,
                layers,
            ),
            None => expand_passes(&ordering.steps, self.real, layers),
        };
        Plan::new(
            self.inputs,
            self.motion,
            fields_in_order(self.real_fields, &ordering.field_order),
            order,
        )
    }
    /// The toolpath of an ordering. A search cancelled with a result (HGA's best so far) still
    /// gets its toolpath; a cancel during the lowering itself (on the fly, seconds on large
    /// jobs) stops it.
    fn toolpath(&self, ordering: &Ordering) -> Result<Toolpath, OrderError> {
        self.toolpath_with(ordering, &[])
    }
    /// The toolpath of an ordering with `step_fields` marked step-and-scan (on the fly: a
    /// mixed job; [`Plan::step_fields`]).
    fn toolpath_with(
        &self,
        ordering: &Ordering,
        step_fields: &[usize],
    ) -> Result<Toolpath, OrderError> {
        let finish = JobCtx::default();
        let ctx = if self.ctx.is_cancelled() {
            &finish
        } else {
            self.ctx
        };
        self.lower_with(ordering, step_fields, ctx)
    }
    /// The toolpath of an ordering, lowered to the end whatever cancel comes.
    fn toolpath_to_the_end(&self, ordering: &Ordering) -> Result<Toolpath, OrderError> {
        self.lower_with(ordering, &[], &JobCtx::default())
    }
    /// The toolpath of an ordering with `step_fields` marked step-and-scan, on `ctx`.
    fn lower_with(
        &self,
        ordering: &Ordering,
        step_fields: &[usize],
        ctx: &JobCtx,
    ) -> Result<Toolpath, OrderError> {
        let mut plan = self.plan(ordering);
        plan.step_fields = step_fields.to_vec();
        let clock_s = plan.profile.controller.marks_clock_s(plan.motion);
        match lower_motion(self.real, &plan, clock_s, ctx) {
            Err(MotionError::OnTheFly(OtfError::Cancelled(c))) => Err(OrderError::Cancelled(c)),
            other => Ok(other?),
        }
    }
}

/// The faster of two lowered candidates; the first on a tie.
fn faster(a: (Ordering, Toolpath), b: (Ordering, Toolpath)) -> (Ordering, Toolpath) {
    if b.1.duration_s() < a.1.duration_s() {
        b
    } else {
        a
    }
}

/// The ordering of the settings' algorithm (HGA goes through [`hga_plan`]).
fn run_algorithm(
    lower: &Candidates,
    detail: &mut Vec<(String, f64)>,
) -> Result<Ordering, OrderError> {
    let (geometries, fields, ctx) = (lower.geometries, lower.fields, lower.ctx);
    let (profile, settings) = (&lower.inputs.profile, &lower.settings);
    Ok(match settings.algo {
        Algo::AsIs => as_is_order(geometries, fields, ctx)?,
        Algo::Baseline => baseline_order(geometries, fields, ctx)?,
        Algo::Hha | Algo::Hga => {
            hha::hha_order(geometries, fields, profile, settings, ctx, detail)?
        }
    })
}

/// On the fly: the algorithm's ordering, the sweep of field-wide bands
/// ([`bands::band_order`]) or either with its nested rings centred
/// ([`nested::nested_centred`]), whichever runs faster on the taut route, with that toolpath.
/// Each candidate's lowering is reported as it ends ([`Tally`]). A cancel keeps the fastest
/// candidate finished so far (the solve then names its plan stopped): the algorithm's ordering
/// is lowered to the end whatever comes, the other candidates stop.
fn faster_on_the_fly(
    lower: &Candidates,
    ordering: Ordering,
) -> Result<(Ordering, Toolpath), OrderError> {
    let field_mm = lower.inputs.profile.field_mm;
    let band_mm = field_mm[0].min(field_mm[1]);
    let bands = bands::band_order(lower.geometries, lower.fields, band_mm, lower.ctx)?;
    let bands = (bands.steps != ordering.steps).then_some(bands);
    let reach_mm = band_mm / 2.0 - lower.inputs.profile.otf_margin_mm;
    let nest = |o: &Ordering| nested::nested_centred(o, lower.geometries, reach_mm);
    let centred = nest(&ordering);
    // the lowerings side by side where the stage stops and goes (texture.toml: the wait-first
    // tracking leaves the second core idle once the window rule has given up; 23.6 -> 17.6 s,
    // 1.1 GB at the peak against 0.7): the algorithm's ordering, the bands and each one's rings
    // centred. One after another elsewhere (side by side, the patterns' whole and cut
    // candidates, already in parallel, took longer) and on large jobs, with the rings centred
    // on the faster of the two orderings only.
    if centred.is_some() && lower.real.len() < FLY_SKIP_STROKES_MIN {
        let centred_bands = bands.as_ref().and_then(nest);
        // four candidates at most: those that are not are counted out
        let tally = Tally::new(lower, 4);
        let by_fields = ordering.clone();
        let ((a, b), (c, d)) = rayon::join(
            || rayon::join(|| tally.keep(by_fields), || tally.lower(bands)),
            || rayon::join(|| tally.lower(centred), || tally.lower(centred_bands)),
        );
        return tally.fastest([a, b, c, d]);
    }
    let tally = Tally::new(lower, 3);
    let by_fields = tally.keep(ordering);
    let by_bands = tally.lower(bands);
    let best = tally.fastest([by_fields, by_bands])?;
    let by_centred = tally.lower(nest(&best.0));
    tally.fastest([Ok(Some(best)), by_centred])
}

/// The on-the-fly candidates of one solve as they are lowered: progress in words ("2 of 4
/// on-the-fly candidate plans made, the fastest 12.31 s") and the fastest of those finished.
struct Tally<'a> {
    lower: &'a Candidates<'a>,
    /// Candidates finished, the fastest job time among them, and candidates in all.
    done: std::sync::Mutex<(usize, f64, usize)>,
}

impl<'a> Tally<'a> {
    fn new(lower: &'a Candidates<'a>, total: usize) -> Self {
        let tally = Self {
            lower,
            done: std::sync::Mutex::new((0, f64::INFINITY, total)),
        };
        tally.report();
        tally
    }

    /// Reports how many candidates are made.
    fn report(&self) {
        let Ok(done) = self.done.lock() else { return };
        let (n, best_s, total) = *done;
        drop(done);
        let message = match (self.lower.ctx.is_cancelled(), best_s.is_finite()) {
            (false, false) => format!("{n} of {total} on-the-fly candidate plans made"),
            (false, true) => format!(
                "{n} of {total} on-the-fly candidate plans made, the fastest {best_s:.2} s"
            ),
            (true, false) => "Stopping once the first on-the-fly candidate plan is made".into(),
            (true, true) => format!(
                "Stopping: keeping the fastest of the {n} on-the-fly candidate plans made ({best_s:.2} s)"
            ),
        };
        self.lower
            .ctx
            .progress("motion", n as u64, total as u64, message);
    }

    /// Lowers candidate `o` (none: not a candidate of this job; not started after a cancel,
    /// stopped by one).
    fn lower(&self, o: Option<Ordering>) -> Result<Option<(Ordering, Toolpath)>, OrderError> {
        let Some(o) = o.filter(|_| !self.lower.ctx.is_cancelled()) else {
            // one candidate fewer to wait for
            if let Ok(mut done) = self.done.lock() {
                done.2 = done.2.saturating_sub(1).max(done.0);
            }
            self.report();
            return Ok(None);
        };
        let toolpath = self.lower.toolpath(&o)?;
        Ok(Some(self.made(o, toolpath)))
    }

    /// Lowers candidate `o` to the end, cancelled or not: the plan a cancel keeps.
    fn keep(&self, o: Ordering) -> Result<Option<(Ordering, Toolpath)>, OrderError> {
        let toolpath = self.lower.toolpath_to_the_end(&o)?;
        Ok(Some(self.made(o, toolpath)))
    }

    /// Counts a finished candidate and reports.
    fn made(&self, o: Ordering, toolpath: Toolpath) -> (Ordering, Toolpath) {
        if let Ok(mut done) = self.done.lock() {
            done.0 += 1;
            done.1 = done.1.min(toolpath.duration_s());
        }
        self.report();
        (o, toolpath)
    }

    /// The fastest of `candidates` (the first on a tie): a cancelled one is left out, and an
    /// error is only returned when no candidate was made.
    fn fastest<const N: usize>(
        &self,
        candidates: [Result<Option<(Ordering, Toolpath)>, OrderError>; N],
    ) -> Result<(Ordering, Toolpath), OrderError> {
        if self.lower.ctx.is_cancelled() {
            // says what the cancel keeps
            self.report();
        }
        let mut best: Option<(Ordering, Toolpath)> = None;
        let mut cancelled = None;
        for c in candidates {
            match c {
                Ok(Some(c)) => {
                    best = Some(match best {
                        Some(b) => faster(b, c),
                        None => c,
                    })
                }
                Ok(None) => {}
                Err(OrderError::Cancelled(c)) => cancelled = Some(c),
                Err(e) => return Err(e),
            }
        }
        match (best, cancelled) {
            (Some(best), _) => Ok(best),
            (None, Some(c)) => Err(OrderError::Cancelled(c)),
            (None, None) => Err(OrderError::Cancelled(crate::job::Cancelled)),
        }
    }
}

/// The fields of `order` (ids) in that order.
fn fields_in_order(fields: &[ScanField], order: &[usize]) -> Vec<ScanField> {
    let by_id: std::collections::HashMap<usize, &ScanField> =
        fields.iter().map(|f| (f.id, f)).collect();
    order
        .iter()
        .filter_map(|id| by_id.get(id).map(|&f| f.clone()))
        .collect()
}

/// The distance ordering refined for job time ([`time::refine_for_time`]); the refinement is
/// kept only when its toolpath is not slower, so `--cost time` never loses to `--cost distance`.
/// After a cancel the ordering is returned as it is (the best so far).
fn time_ordering(
    lower: &Candidates,
    ordering: Ordering,
    until: Option<std::time::Instant>,
) -> Result<(Ordering, Toolpath), OrderError> {
    let refined = match time::refine_for_time(
        lower.geometries,
        lower.fields,
        &ordering,
        &lower.inputs.profile,
        lower.settings.seed,
        until,
        lower.ctx,
    ) {
        Ok(refined) => refined,
        Err(Cancelled) => {
            let by_distance = lower.toolpath(&ordering)?;
            return Ok((ordering, by_distance));
        }
    };
    // one toolpath at a time (hundreds of MB on a million strokes): the distance ordering's
    // is made again when it wins
    let by_distance_s = lower.toolpath(&ordering)?.duration_s();
    let by_time = lower.toolpath(&refined)?;
    // the refinement on a tie: it is what the time objective chose
    if by_time.duration_s() <= by_distance_s {
        return Ok((refined, by_time));
    }
    drop(by_time);
    let by_distance = lower.toolpath(&ordering)?;
    Ok((ordering, by_distance))
}

/// Every geometry must be allocated to exactly one field.
pub fn check_allocation(n: usize, fields: &[ScanField]) -> Result<(), OrderError> {
    let mut seen = vec![false; n];
    for f in fields {
        for &g in &f.geometries {
            if let Some(s) = seen.get_mut(g) {
                *s = true;
            }
        }
    }
    let missing: Vec<usize> = seen
        .iter()
        .enumerate()
        .filter(|(_, s)| !**s)
        .map(|(i, _)| i)
        .collect();
    match missing.first() {
        Some(&first) => Err(OrderError::Unallocated(missing.len(), first)),
        None => Ok(()),
    }
}
