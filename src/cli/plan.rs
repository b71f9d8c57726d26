//! `galvoplan plan`: one job, SVG in, G-code / report / preview out.

use super::progress::BarProgress;
use super::PlanArgs;
use anyhow::{Context, Result};
use galvoplan::document::{write_atomic, write_atomic_with};
use galvoplan::export::{
    check_outputs, geometry_svg, preview_svg, report_json, trajectory_csv, trajectory_period_s,
    waypoints_csv, write_gcode_to,
};
use galvoplan::import::Place;
use galvoplan::job::Progress;
use galvoplan::job::ProgressSink;
use galvoplan::job::{CancelToken, JobCtx};
use galvoplan::pipeline::{apply_pen_library, load_production, plan_document_lowered};
use std::sync::Arc;
use std::time::Instant;

pub fn run(a: &PlanArgs) -> Result<()> {
    check_outputs(&a.inputs(), &a.outputs())?;
    let profile = a.job.profile_for(&a.input)?;
    let settings = a.job.settings()?;
    let opts = a.job.import()?;
    // an impossible period is refused before any work; one the plan's clock differs from, once
    // the plan (and so its motion) is made
    if let (Some(_), Some(ms)) = (&a.trajectory, a.trajectory_period_ms) {
        trajectory_period_s(ms)?;
    }
    let pens = a.job.pens()?;
    let progress = Arc::new(BarProgress::new());
    let import_progress = |done| {
        progress.report(&Progress {
            stage: "import",
            done,
            total: 1,
            message: a.input.display().to_string(),
        })
    };
    import_progress(0);
    let tray = a.job.tray.settings()?;
    let loaded = load_production(&a.input, profile, settings, &opts, &tray);
    import_progress(1);
    let loaded = loaded?;
    let (mut doc, import_s) = (loaded.doc, loaded.import_s);
    for w in galvoplan::document::grouped(&doc.warnings) {
        eprintln!("galvoplan: warning: {}: {w}", a.input.display());
    }
    let hidden = loaded.skipped_layers.len();
    if hidden > 0 {
        eprintln!(
            "galvoplan: {}: --include-hidden-layers imports the {hidden} {} the drawing hides",
            a.input.display(),
            if hidden == 1 { "layer" } else { "layers" }
        );
    }
    let [dx, dy] = loaded.moved_mm;
    if opts.place != Place::Auto && (dx != 0.0 || dy != 0.0) {
        let n = doc.profile.gcode.decimals;
        eprintln!(
            "galvoplan: {}: artwork placed (--place {}): moved by ({}, {}) mm",
            a.input.display(),
            opts.place,
            galvoplan::geom::format_mm(dx, n),
            galvoplan::geom::format_mm(dy, n)
        );
    }
    if let Some(lib) = &pens {
        for name in apply_pen_library(&mut doc, lib) {
            let known: Vec<&str> = doc.layers.iter().map(|l| l.name.as_str()).collect();
            eprintln!(
                "galvoplan: warning: {}: the pens file names layer '{name}', which the artwork does not have (its layers: {})",
                a.input.display(),
                galvoplan::document::short_list(&known, ", ")
            );
        }
    }
    let mut ctx = JobCtx::new(CancelToken::new(), progress.clone());
    let recorder = recorder(a.rerun.as_deref())?;
    if let Some(r) = &recorder {
        ctx = ctx.with_recorder(r.clone());
    }
    let imported_warnings = doc.warnings.len();
    let result = plan_document_lowered(&mut doc, &ctx);
    progress.finish();
    for w in
        galvoplan::document::grouped(&doc.warnings[imported_warnings.min(doc.warnings.len())..])
    {
        eprintln!("galvoplan: warning: {}: {w}", a.input.display());
    }
    let (mut plan, toolpath) = result?;
    let t0 = Instant::now();
    let source = a.input.display().to_string();
    // the trajectory samples the toolpath the plan was ordered and measured on (on the
    // profile's clock when it has one): an export never changes the plan's figures
    let period_s = a
        .trajectory
        .as_ref()
        .map(|_| sampling_period_s(&plan.profile, plan.motion, a.trajectory_period_ms))
        .transpose()?;
    let axes = plan.profile.extra_axes();
    let trajectory = period_s.map(|p| trajectory_csv(&toolpath, p, &axes));
    let waypoints = a
        .waypoints
        .as_ref()
        .map(|_| waypoints_csv(&toolpath, &axes));
    let stream = stream_of(a, &plan, &toolpath)?;
    // streamed into the output file (atomically: written whole or not at all)
    let mut gcode_error = None;
    write_atomic_with(&a.output, |f| {
        write_gcode_to(f, &toolpath, &plan, doc.page_mm[1], &source).map_err(|e| {
            let io = std::io::Error::other(e.to_string());
            gcode_error = Some(e);
            io
        })
    })
    .map_err(|e| match gcode_error.take() {
        Some(g) => anyhow::Error::new(g),
        None => anyhow::Error::new(e),
    })
    .with_context(|| format!("{}: cannot write G-code", a.output.display()))?;
    let preview = a
        .preview
        .as_ref()
        .map(|_| preview_svg(&toolpath, &plan, doc.page_mm));
    let geometry = a
        .export_geometry
        .as_ref()
        .map(|_| geometry_svg(&doc.geometries, doc.page_mm));
    let export_s = t0.elapsed().as_secs_f64();
    let t = &mut plan.metrics.solve_s;
    t.import = import_s;
    t.export = export_s;
    t.total = t.import + t.hatch + t.fields + t.order + t.export;
    let write = |path: &std::path::Path, text: &str| {
        write_atomic(path, text.as_bytes())
            .with_context(|| format!("{}: cannot write", path.display()))
    };
    finish_recording(recorder.as_ref())?;
    if let Some(p) = &a.report {
        write(p, &report_json(&source, &plan, &doc.warnings))?;
    }
    if let (Some(p), Some(s)) = (&a.preview, &preview) {
        write(p, s)?;
    }
    if let (Some(p), Some(s)) = (&a.export_geometry, &geometry) {
        write(p, s)?;
    }
    if let (Some(p), Some(s)) = (&a.trajectory, &trajectory) {
        write(p, s)?;
    }
    if let (Some(p), Some(s)) = (&a.waypoints, &waypoints) {
        write(p, s)?;
    }
    if let (Some(p), Some(s)) = (&a.stream, &stream) {
        write(p, s)?;
    }
    if let Some(log) = &a.parts_log {
        let program = a.output.display().to_string();
        galvoplan::export::append_parts_log(log, &program, &plan.parts, chrono_now())
            .with_context(|| format!("{}: cannot append to the parts log", log.display()))?;
    }
    let m = &plan.metrics;
    eprintln!(
        "galvoplan: {}: {}, {}, job time {:.3} s, idle {:.1} mm, base {:.1} mm, marked {:.1} mm, {} direction changes, planned in {:.1} ms",
        source,
        super::count(doc.geometries.len(), "geometry", "geometries"),
        super::count(m.fields, "field", "fields"),
        m.job_time_s.unwrap_or(0.0),
        m.idle_mm,
        m.base_mm,
        m.marked_mm,
        m.direction_changes,
        m.solve_s.total * 1e3
    );
    Ok(())
}

/// The stream of a streamed plan (checked against the machine's limits, written only with
/// `--stream`, which such a plan needs: its program runs nothing without it); says what it
/// holds. A plan that is not streamed has none.
fn stream_of(
    a: &PlanArgs,
    plan: &galvoplan::document::Plan,
    toolpath: &galvoplan::motion::Toolpath,
) -> Result<Option<String>> {
    let source = a.input.display();
    let streamed = toolpath.route.is_some() && plan.profile.controller.streamed(plan.motion);
    if !streamed {
        if let Some(p) = &a.stream {
            eprintln!(
                "galvoplan: {source}: the plan is {}, not streamed: {} is not written",
                plan.motion_words(),
                p.display()
            );
        }
        return Ok(None);
    }
    let Some(path) = &a.stream else {
        anyhow::bail!(
            "{source}: the plan is streamed on the fly (profile '{}'): give --stream JOB.stream for its stream, which the program waits for",
            plan.profile.name
        );
    };
    let (text, f) = galvoplan::export::stream_text(toolpath, plan)
        .with_context(|| format!("{}: cannot stream the plan", path.display()))?;
    eprintln!(
        "galvoplan: {source}: streamed on the fly: {} samples every {} ms ({:.3} s); between samples the joints stay within {:.4} mm of the planned path",
        f.samples,
        f.period_s * 1e3,
        (f.samples.saturating_sub(1)) as f64 * f.period_s,
        f.max_deviation_mm
    );
    Ok(Some(text))
}

/// The trajectory's sampling period, s: the clock of the profile's controller for a plan in
/// `motion` (a `--trajectory-period-ms` that differs from it is refused), else the period asked
/// for, else 1 ms.
fn sampling_period_s(
    profile: &galvoplan::document::MachineProfile,
    motion: galvoplan::document::Motion,
    asked_ms: Option<f64>,
) -> Result<f64> {
    let Some(clock_s) = profile.controller.clock_s(motion) else {
        return Ok(trajectory_period_s(asked_ms.unwrap_or(1.0))?);
    };
    match asked_ms {
        Some(ms) if (ms * 1e-3 - clock_s).abs() > 1e-12 * clock_s.max(1e-3) => anyhow::bail!(
            "--trajectory-period-ms {ms}: the profile '{}' plans on its controller's clock of {} ms; a trajectory is sampled on that clock (leave the option out)",
            profile.name,
            clock_s * 1e3
        ),
        _ => Ok(trajectory_period_s(clock_s * 1e3)?),
    }
}

/// The date-time a parts log records (local time, to the second).
fn chrono_now() -> String {
    chrono::Local::now().format("%Y-%m-%dT%H:%M:%S").to_string()
}

#[cfg(feature = "rerun")]
type Recorder = Arc<galvoplan::record::RerunRecorder>;
#[cfg(not(feature = "rerun"))]
type Recorder = Arc<dyn galvoplan::job::RunRecorder>;

#[cfg(feature = "rerun")]
fn recorder(path: Option<&std::path::Path>) -> Result<Option<Recorder>> {
    path.map(|p| Ok(Arc::new(galvoplan::record::RerunRecorder::create(p)?)))
        .transpose()
}

#[cfg(not(feature = "rerun"))]
fn recorder(path: Option<&std::path::Path>) -> Result<Option<Recorder>> {
    match path {
        Some(p) => anyhow::bail!(
            "{}: this build cannot record rerun files; rebuild with `--features rerun`",
            p.display()
        ),
        None => Ok(None),
    }
}

#[cfg(feature = "rerun")]
fn finish_recording(r: Option<&Recorder>) -> Result<()> {
    if let Some(r) = r {
        r.finish()?;
    }
    Ok(())
}

#[cfg(not(feature = "rerun"))]
fn finish_recording(_: Option<&Recorder>) -> Result<()> {
    Ok(())
}
