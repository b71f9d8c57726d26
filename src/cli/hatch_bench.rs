//! `galvoplan hatch-bench`: seed 003's experiment (edge offset = spacing, zigzag at 0° and
//! contour-parallel) on the contest's contours; a Markdown table to stdout.

use anyhow::{Context, Result};
use clap::Args;
use galvoplan::bench::hatch::{format_table, read_contours, run_case};
use galvoplan::document::write_atomic;
use galvoplan::hatch::HatchStyle;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct HatchBenchArgs {
    /// Contour files (contest CSV, or SVG whose closed paths form one region) or folders of them.
    #[arg(required = true)]
    paths: Vec<PathBuf>,
    /// Spacings (= edge offsets) to run, mm.
    #[arg(long, value_delimiter = ',', default_value = "1,0.1,0.01")]
    spacing: Vec<f64>,
    /// Styles to run.
    #[arg(long, value_delimiter = ',', default_value = "zigzag,contour")]
    style: Vec<String>,
    /// Timed runs per case (after one warm-up); times are means, as the hatch paper gives them.
    #[arg(long, default_value_t = 10)]
    repeat: usize,
    /// Also write the rows as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
}

fn collect(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let entries = std::fs::read_dir(p)
                .and_then(|d| d.collect::<std::io::Result<Vec<_>>>())
                .with_context(|| format!("{}: cannot list", p.display()))?;
            let mut v: Vec<PathBuf> = entries
                .into_iter()
                .map(|e| e.path())
                .filter(|q| q.extension().is_some_and(|x| x.eq_ignore_ascii_case("csv")))
                .collect();
            v.sort();
            out.extend(v);
        } else {
            out.push(p.clone());
        }
    }
    anyhow::ensure!(!out.is_empty(), "no contour files in {paths:?}");
    Ok(out)
}

pub fn run(a: &HatchBenchArgs) -> Result<()> {
    let styles = a
        .style
        .iter()
        .map(|s| {
            HatchStyle::ALL
                .into_iter()
                .find(|h| h.name().eq_ignore_ascii_case(s.trim()))
                .with_context(|| {
                    format!("--style: unknown style {s:?} (zigzag | lines | cross | contour)")
                })
        })
        .collect::<Result<Vec<_>>>()?;
    for &s in &a.spacing {
        anyhow::ensure!(
            s.is_finite() && s > 0.0,
            "--spacing: {s} is not a positive number of mm"
        );
    }
    let mut rows = Vec::new();
    for f in collect(&a.paths)? {
        let contours = read_contours(&f)?;
        let name = f
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        for &style in &styles {
            for &s in &a.spacing {
                eprintln!("galvoplan: hatch-bench {name} {style} {s} mm");
                rows.push(run_case(&name, &contours, style, s, a.repeat)?);
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
