//! Benchmark runner behind `galvoplan bench`: the whole pipeline per instance, timed per stage.

pub mod cap;
pub mod hatch;

use crate::document::{MachineProfile, SolverSettings, TraySettings};
use crate::export::{report_json, write_gcode_to};
use crate::import::ImportOptions;
use crate::job::JobCtx;
use crate::pipeline::{load_production, plan_document_lowered, PipelineError};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Mean and standard deviation of a figure over seeds.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq)]
pub struct Stat {
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation (0 for one run).
    pub sd: f64,
}

impl Stat {
    /// Mean and sample standard deviation of `v`.
    pub fn of(v: &[f64]) -> Stat {
        if v.is_empty() {
            return Stat::default();
        }
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let sd = if v.len() > 1 {
            (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
        } else {
            0.0
        };
        Stat { mean, sd }
    }
    fn show(&self, decimals: usize, with_sd: bool) -> String {
        if with_sd {
            format!("{:.*} ± {:.*}", decimals, self.mean, decimals, self.sd)
        } else {
            format!("{:.*}", decimals, self.mean)
        }
    }
}

/// One instance's figures: quality as mean ± sd over the seeds, times as medians over all runs
/// (ms).
#[derive(Debug, Clone, Serialize)]
pub struct BenchRow {
    /// File stem.
    pub instance: String,
    /// Geometries planned (hatch lines and pieces cut at seams included).
    pub geometries: usize,
    /// Strokes the toolpath marks (passes repeat strokes).
    pub strokes: usize,
    /// Peak resident memory of the process while the instance ran (from the OS, MB; none where
    /// the OS does not say). Memory earlier instances left allocated counts too: bench one
    /// instance per run for a clean figure.
    pub peak_rss_mb: Option<f64>,
    /// Seeds run.
    pub seeds: usize,
    /// Scan fields.
    pub fields: Stat,
    /// Lower bound on fields.
    pub fields_lower_bound: Option<usize>,
    /// Overlap, %.
    pub overlap_pct: Stat,
    /// Idle travel, mm.
    pub idle_mm: Stat,
    /// Base travel, mm.
    pub base_mm: Stat,
    /// Marked length, mm.
    pub marked_mm: f64,
    /// Direction changes.
    pub direction_changes: Stat,
    /// Job time (the lowered toolpath's duration), s.
    pub job_time_s: Stat,
    /// A lower bound on the job time of any order of the first seed's fields (step-and-scan;
    /// `order::objective::step_job_time_lower_bound_s`), s.
    pub job_time_lower_bound_s: Option<f64>,
    /// Stage moves and settling in the job time, s.
    pub stage_time_s: Stat,
    /// Length of the stage's route, mm.
    pub stage_route_mm: Stat,
    /// Largest scanner offset, mm.
    pub scan_peak_offset_mm: Stat,
    /// Peak stage speed (vector), mm/s.
    pub stage_peak_speed_mm_s: Stat,
    /// Total variation of the stage speed (seed 001 Table IV's sum of speed differences), mm/s.
    pub stage_speed_variation_mm_s: Stat,
    /// Import, ms.
    pub import_ms: f64,
    /// Hatch fills, ms.
    pub hatch_ms: f64,
    /// Field placement, ms.
    pub fields_ms: f64,
    /// Ordering, ms.
    pub order_ms: f64,
    /// The ordering's sub-stages of the first run (name, ms).
    pub order_detail_ms: Vec<(String, f64)>,
    /// Export (G-code and report text), ms.
    pub export_ms: f64,
    /// Whole pipeline, ms.
    pub total_ms: f64,
}

/// Expands files and folders into the sorted list of SVG files.
pub fn collect_svgs(paths: &[PathBuf]) -> std::io::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            // an unreadable entry is an error, not a file left out in silence
            let entries = std::fs::read_dir(p)?.collect::<std::io::Result<Vec<_>>>()?;
            let mut v: Vec<PathBuf> = entries
                .into_iter()
                .map(|e| e.path())
                .filter(|q| {
                    q.extension().is_some_and(|x| {
                        x.eq_ignore_ascii_case("svg") || x.eq_ignore_ascii_case("svgz")
                    })
                })
                .collect();
            v.sort();
            out.extend(v);
        } else {
            out.push(p.clone());
        }
    }
    Ok(out)
}

/// Resets the process's peak resident memory to its current one (Linux ≥ 4.0:
/// `/proc/self/clear_refs`); false where the OS cannot.
fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// The process's peak resident memory since the last reset, MB (Linux: `VmHWM` of
/// `/proc/self/status`; none elsewhere).
fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => 0.0,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// A writer that counts the bytes it is given.
struct ByteCount(usize);

impl std::io::Write for ByteCount {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0 += buf.len();
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Runs the pipeline on one SVG (imported with `input`'s options, as a tray with its tray
/// settings) for `seeds` consecutive seeds (from the settings' seed), each `repeat` times
/// (import, fields, order, export: the G-code streamed and counted, the report in memory).
pub fn run_instance(
    path: &Path,
    profile: &MachineProfile,
    settings: &SolverSettings,
    input: (&ImportOptions, &TraySettings),
    seeds: usize,
    repeat: usize,
    ctx: &JobCtx,
) -> Result<BenchRow, PipelineError> {
    let (opts, tray) = input;
    let mut times: [Vec<f64>; 6] = Default::default();
    let mut quality: [Vec<f64>; 11] = Default::default();
    let (mut geometries, mut marked_mm, mut lower, mut job_lb) = (0, 0.0, None, None);
    let (mut strokes, mut order_detail_ms) = (0, Vec::new());
    // the peak is the instance's only when it could be reset
    let peak_is_own = reset_peak_rss();
    for k in 0..seeds.max(1) {
        let mut s = settings.clone();
        s.seed = settings.seed.wrapping_add(k as u64);
        for r in 0..repeat.max(1) {
            let t_all = Instant::now();
            let loaded = load_production(path, profile.clone(), s.clone(), opts, tray)?;
            let (mut doc, import_s) = (loaded.doc, loaded.import_s);
            let (plan, toolpath) = plan_document_lowered(&mut doc, ctx)?;
            let t0 = Instant::now();
            // the G-code streamed as the CLI writes it, counted rather than kept
            let mut g = ByteCount(0);
            write_gcode_to(&mut g, &toolpath, &plan, doc.page_mm[1], "bench").map_err(
                |source| crate::pipeline::PipelineError::Gcode {
                    file: path.display().to_string(),
                    source,
                },
            )?;
            let rep = report_json("bench", &plan, &doc.warnings);
            std::hint::black_box((g.0, rep.len()));
            let export_s = t0.elapsed().as_secs_f64();
            for (v, x) in times.iter_mut().zip([
                import_s,
                plan.metrics.solve_s.hatch,
                plan.metrics.solve_s.fields,
                plan.metrics.solve_s.order,
                export_s,
                t_all.elapsed().as_secs_f64(),
            ]) {
                v.push(x * 1e3);
            }
            if r == 0 {
                let m = &plan.metrics;
                let b = toolpath.breakdown();
                let motion = toolpath.motion_figures(crate::order::metrics::MOTION_SAMPLE_PERIOD_S);
                for (v, x) in quality.iter_mut().zip([
                    m.fields as f64,
                    m.overlap_pct,
                    m.idle_mm,
                    m.base_mm,
                    m.direction_changes as f64,
                    toolpath.duration_s(),
                    b.stage + b.settle,
                    motion.stage_route_mm,
                    motion.scan_peak_offset_mm,
                    motion.stage_peak_speed_mm_s,
                    motion.stage_speed_variation_mm_s,
                ]) {
                    v.push(x);
                }
                geometries = doc.geometries.len();
                strokes = toolpath.strokes.len();
                order_detail_ms = (m.solve_s.order_detail.iter())
                    .map(|(k, s)| (k.clone(), s * 1e3))
                    .collect();
                marked_mm = m.marked_mm;
                job_lb = (plan.motion == crate::document::Motion::Step).then(|| {
                    crate::order::objective::step_job_time_lower_bound_s(
                        &doc.geometries,
                        &plan.fields,
                        &doc.layers,
                        &doc.profile,
                    )
                });
                lower = m.fields_lower_bound;
            }
        }
    }
    let peak_rss_mb = peak_rss_mb().filter(|_| peak_is_own);
    let [mut a, mut h, mut b, mut c, mut d, mut e] = times;
    let [f, o, i, bm, dc, jt, st, route, offset, peak, variation] = quality;
    Ok(BenchRow {
        instance: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        geometries,
        strokes,
        peak_rss_mb,
        seeds: seeds.max(1),
        fields: Stat::of(&f),
        fields_lower_bound: lower,
        overlap_pct: Stat::of(&o),
        idle_mm: Stat::of(&i),
        base_mm: Stat::of(&bm),
        marked_mm,
        direction_changes: Stat::of(&dc),
        job_time_s: Stat::of(&jt),
        job_time_lower_bound_s: job_lb,
        stage_time_s: Stat::of(&st),
        stage_route_mm: Stat::of(&route),
        scan_peak_offset_mm: Stat::of(&offset),
        stage_peak_speed_mm_s: Stat::of(&peak),
        stage_speed_variation_mm_s: Stat::of(&variation),
        import_ms: median(&mut a),
        hatch_ms: median(&mut h),
        fields_ms: median(&mut b),
        order_ms: median(&mut c),
        order_detail_ms,
        export_ms: median(&mut d),
        total_ms: median(&mut e),
    })
}

/// Formats rows as a Markdown table (quality as mean ± sd when several seeds ran).
pub fn format_table(rows: &[BenchRow]) -> String {
    let mut s = String::from(
        "| instance | geometries | strokes | fields | LB | overlap % | idle mm | base mm | marked mm | dir. changes | job s | job LB s | stage s | route mm | offset mm | peak stage mm/s | stage speed var. mm/s | import ms | hatch ms | fields ms | order ms | export ms | total ms | peak MB |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let sd = r.seeds > 1;
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {:.1} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {} |\n",
            r.instance,
            r.geometries,
            r.strokes,
            r.fields.show(if sd { 1 } else { 0 }, sd),
            r.fields_lower_bound.map_or("–".to_string(), |v| v.to_string()),
            r.overlap_pct.show(1, sd),
            r.idle_mm.show(1, sd),
            r.base_mm.show(1, sd),
            r.marked_mm,
            r.direction_changes.show(if sd { 1 } else { 0 }, sd),
            r.job_time_s.show(3, sd),
            r.job_time_lower_bound_s
                .map_or("–".to_string(), |v| format!("{v:.3}")),
            r.stage_time_s.show(2, sd),
            r.stage_route_mm.show(0, sd),
            r.scan_peak_offset_mm.show(2, sd),
            r.stage_peak_speed_mm_s.show(0, sd),
            r.stage_speed_variation_mm_s.show(0, sd),
            r.import_ms,
            r.hatch_ms,
            r.fields_ms,
            r.order_ms,
            r.export_ms,
            r.total_ms,
            r.peak_rss_mb.map_or("–".to_string(), |v| format!("{v:.0}")),
        ));
    }
    s
}
