//! `galvoplan bench`: one row per instance.

use super::BenchArgs;
use anyhow::{Context, Result};
use galvoplan::bench::{collect_svgs, format_table, run_instance};
use galvoplan::document::write_atomic;
use galvoplan::job::JobCtx;

pub fn run(a: &BenchArgs) -> Result<()> {
    let profile = a.job.profile()?;
    let settings = a.job.settings()?;
    let opts = a.job.import()?;
    let tray = a.job.tray.settings()?;
    let files = collect_svgs(&a.paths).context("cannot list the benchmark paths")?;
    anyhow::ensure!(!files.is_empty(), "no SVG files in {:?}", a.paths);
    let ctx = JobCtx::default();
    let mut rows = Vec::new();
    let mut failed = Vec::new();
    for f in &files {
        eprintln!("galvoplan: bench {}", f.display());
        match run_instance(
            f,
            &profile,
            &settings,
            (&opts, &tray),
            a.seeds,
            a.repeat,
            &ctx,
        ) {
            Ok(row) => rows.push(row),
            Err(e) => {
                eprintln!("galvoplan: error: {e}");
                failed.push(f.display().to_string());
            }
        }
    }
    print!("{}", format_table(&rows));
    if let Some(p) = &a.json {
        let text = serde_json::to_string_pretty(&rows)?;
        write_atomic(p, text.as_bytes())
            .with_context(|| format!("{}: cannot write", p.display()))?;
    }
    Ok(())
}
