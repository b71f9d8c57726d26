//! Benchmark runner behind `galvoplan bench`: the whole pipeline per instance, timed per stage.

use crate::document::{MachineProfile, SolverSettings};
use crate::export::{report_json, write_gcode};
use crate::import::ImportOptions;
use crate::job::JobCtx;
use crate::pipeline::{load_svg, plan_document, PipelineError};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One instance's figures. Times are medians over the repeats, in ms.
#[derive(Debug, Clone, Serialize)]
pub struct BenchRow {
    /// File stem.
    pub instance: String,
    /// Geometries imported.
    pub geometries: usize,
    /// Scan fields.
    pub fields: usize,
    /// Lower bound on fields, when known.
    pub fields_lower_bound: Option<usize>,
    /// Overlap, %.
    pub overlap_pct: f64,
    /// Idle travel, mm.
    pub idle_mm: f64,
    /// Base travel, mm.
    pub base_mm: f64,
    /// Marked length, mm.
    pub marked_mm: f64,
    /// Direction changes.
    pub direction_changes: usize,
    /// Estimated job time, s.
    pub job_time_s: Option<f64>,
    /// Import, ms.
    pub import_ms: f64,
    /// Field placement, ms.
    pub fields_ms: f64,
    /// Ordering, ms.
    pub order_ms: f64,
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
            let mut v: Vec<PathBuf> = std::fs::read_dir(p)?
                .filter_map(|e| e.ok().map(|e| e.path()))
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

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => 0.0,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// Runs the pipeline `repeat` times on one SVG (import, fields, order, export to memory).
pub fn run_instance(
    path: &Path,
    profile: &MachineProfile,
    settings: &SolverSettings,
    opts: &ImportOptions,
    repeat: usize,
    ctx: &JobCtx,
) -> Result<BenchRow, PipelineError> {
    let mut times: [Vec<f64>; 5] = Default::default();
    let mut last = None;
    for _ in 0..repeat.max(1) {
        let t_all = Instant::now();
        let (mut doc, import_s) = load_svg(path, profile.clone(), settings.clone(), opts)?;
        let plan = plan_document(&mut doc, ctx)?;
        let t0 = Instant::now();
        let g = write_gcode(
            &doc.geometries,
            &plan,
            &doc.profile,
            doc.page_mm[1],
            "bench",
        );
        let r = report_json("bench", &plan, &doc.settings, &doc.warnings);
        std::hint::black_box((g.len(), r.len()));
        let export_s = t0.elapsed().as_secs_f64();
        times[0].push(import_s * 1e3);
        times[1].push(plan.metrics.solve_s.fields * 1e3);
        times[2].push(plan.metrics.solve_s.order * 1e3);
        times[3].push(export_s * 1e3);
        times[4].push(t_all.elapsed().as_secs_f64() * 1e3);
        last = Some((doc.geometries.len(), plan));
    }
    let (geometries, plan) = last.ok_or_else(|| {
        PipelineError::Import(crate::import::ImportError::Empty {
            file: path.display().to_string(),
        })
    })?;
    let m = &plan.metrics;
    let [mut a, mut b, mut c, mut d, mut e] = times;
    Ok(BenchRow {
        instance: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        geometries,
        fields: m.fields,
        fields_lower_bound: m.fields_lower_bound,
        overlap_pct: m.overlap_pct,
        idle_mm: m.idle_mm,
        base_mm: m.base_mm,
        marked_mm: m.marked_mm,
        direction_changes: m.direction_changes,
        job_time_s: m.job_time_s,
        import_ms: median(&mut a),
        fields_ms: median(&mut b),
        order_ms: median(&mut c),
        export_ms: median(&mut d),
        total_ms: median(&mut e),
    })
}

/// Formats rows as a Markdown table.
pub fn format_table(rows: &[BenchRow]) -> String {
    let mut s = String::from(
        "| instance | geometries | fields | LB | overlap % | idle mm | base mm | marked mm | dir. changes | job s | import ms | fields ms | order ms | export ms | total ms |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |\n",
            r.instance,
            r.geometries,
            r.fields,
            r.fields_lower_bound.map_or("–".to_string(), |v| v.to_string()),
            r.overlap_pct,
            r.idle_mm,
            r.base_mm,
            r.marked_mm,
            r.direction_changes,
            r.job_time_s.map_or("–".to_string(), |v| format!("{v:.2}")),
            r.import_ms,
            r.fields_ms,
            r.order_ms,
            r.export_ms,
            r.total_ms
        ));
    }
    s
}
