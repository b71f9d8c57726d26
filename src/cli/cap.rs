//! `galvoplan cap-bench`: seed 002's experiment (docs/REFERENCES.md): a scan-field layout laid
//! on a spherical cap, its placements ordered as is, by 3-D distance and by 5-axis time, each
//! timed on a 5-axis profile; a Markdown table to stdout.

use super::progress::BarProgress;
use anyhow::{Context, Result};
use clap::Args;
use galvoplan::bench::cap::{order_three_ways, Cap, CapOrder};
use galvoplan::document::{
    save_project, sync_layers, write_atomic, Document, Geometry, MachineProfile, ScanField, Source,
    DEFAULT_LAYER,
};
use galvoplan::export::check_outputs;
use galvoplan::geom::Pt;
use galvoplan::import::ImportOptions;
use galvoplan::job::{CancelToken, JobCtx};
use galvoplan::pipeline::{load_production, place_document_fields};
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Args, Debug)]
pub struct CapBenchArgs {
    /// The artwork whose scan-field layout is laid on the cap (SVG or DXF).
    artwork: PathBuf,
    /// The profile whose field size makes the layout (texture-3043 with bench/texture's
    /// texture.toml: 3,043 fields).
    #[arg(long, value_name = "PROFILE")]
    layout_profile: String,
    /// The 5-axis profile the placements are timed on (a file or a built-in name).
    #[arg(long, default_value = "five-axis")]
    profile: String,
    /// The cap's sphere radius, mm; its apex stands over the stage's centre.
    #[arg(long, default_value_t = 200.0)]
    radius: f64,
    /// Seed of the searches.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Also write the rows as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write a project of the stand-in: the first N placements of the layout (or all), each with
    /// its pose and one spot at its centre, for `galvoplan plan` and the workbench.
    #[arg(long, value_name = "OUT.galvoplan")]
    project: Option<PathBuf>,
    /// How many placements the project holds (from the layout's first).
    #[arg(long, value_name = "N", requires = "project")]
    placements: Option<usize>,
}

/// The files the run reads that exist (built-in profile names are not files).
fn inputs(a: &CapBenchArgs) -> Vec<&Path> {
    [
        a.artwork.as_path(),
        Path::new(&a.layout_profile),
        Path::new(&a.profile),
    ]
    .into_iter()
    .filter(|p| p.exists())
    .collect()
}

/// The files the run writes, with what each is.
fn outputs(a: &CapBenchArgs) -> Vec<(&'static str, &Path)> {
    [("JSON rows", &a.json), ("project", &a.project)]
        .into_iter()
        .filter_map(|(what, p)| Some((what, p.as_deref()?)))
        .collect()
}

pub fn run(a: &CapBenchArgs) -> Result<()> {
    check_outputs(&inputs(a), &outputs(a))?;
    anyhow::ensure!(
        a.radius.is_finite() && a.radius > 0.0,
        "--radius must be a positive number of mm, not {}",
        a.radius
    );
    let layout_profile = MachineProfile::load(&a.layout_profile)?;
    let profile = MachineProfile::load(&a.profile)?;
    let loaded = load_production(
        &a.artwork,
        layout_profile.clone(),
        Default::default(),
        &ImportOptions::default(),
        &Default::default(),
    )?;
    let mut doc = loaded.doc;
    // a layout only: strokes larger than a field are cut at field borders
    doc.settings.split_oversize = true;
    let progress = Arc::new(BarProgress::new());
    let ctx = JobCtx::new(CancelToken::new(), progress.clone());
    place_document_fields(&mut doc, &ctx)?;
    let cap = Cap {
        radius_mm: a.radius,
        centre: Pt::new(profile.stroke_mm[0] / 2.0, profile.stroke_mm[1] / 2.0),
    };
    let source = a.artwork.display().to_string();
    let laid = cap
        .lay(&doc.fields)
        .with_context(|| format!("{source}: the layout does not fit on the cap"))?;
    for f in &laid {
        profile
            .check_pose(f.id, &f.pose)
            .with_context(|| format!("{source}: on the cap of radius {} mm", a.radius))?;
    }
    let rows = order_three_ways(&laid, &profile, a.seed, &ctx);
    progress.finish();
    let rows = rows?;
    print!("{}", table(&rows, laid.len(), &profile.name, a.radius));
    if let Some(p) = &a.json {
        let text = serde_json::to_string_pretty(&rows)?;
        write_atomic(p, text.as_bytes())
            .with_context(|| format!("{}: cannot write", p.display()))?;
    }
    if let Some(p) = &a.project {
        let n = a.placements.unwrap_or(laid.len()).min(laid.len());
        let stand_in = stand_in(&laid[..n], &doc, profile);
        save_project(&stand_in, p)?;
        eprintln!(
            "galvoplan: {}: the stand-in of {n} placements, one spot each",
            p.display()
        );
    }
    Ok(())
}

/// The three orders as a Markdown table.
fn table(rows: &[CapOrder], placements: usize, profile: &str, radius: f64) -> String {
    let mut out = format!(
        "{placements} placements on a spherical cap of radius {radius} mm, timed on {profile}\n\n| Order | Move time (s) | Gain over as is | 3-D distance (mm) |\n|---|---:|---:|---:|\n"
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {:.1} | {:.1} % | {:.0} |\n",
            r.method, r.move_time_s, r.gain_pct, r.distance_3d_mm
        ));
    }
    out
}

/// A document of `placements` (with their poses), one spot at each centre.
fn stand_in(placements: &[ScanField], layout: &Document, profile: MachineProfile) -> Document {
    let geometries: Vec<Geometry> = placements
        .iter()
        .enumerate()
        .map(|(k, f)| Geometry {
            points: vec![f.center],
            closed: false,
            source: Source {
                element: format!("placement {}", k + 1),
                subpath: 0,
                layer: DEFAULT_LAYER.into(),
                part: 0,
            },
            layer: DEFAULT_LAYER.into(),
            pass: 0,
            run: None,
        })
        .collect();
    let fields = placements
        .iter()
        .enumerate()
        .map(|(k, f)| ScanField {
            id: k,
            geometries: vec![k],
            locked: true,
            ..f.clone()
        })
        .collect();
    let mut layers = Vec::new();
    sync_layers(&mut layers, &geometries, &layout.settings.default_pen());
    // the artwork's name, not its path on this machine
    let source = layout.source.as_deref().map(|s| {
        std::path::Path::new(s)
            .file_name()
            .map_or(s.to_string(), |n| n.to_string_lossy().into_owned())
    });
    Document {
        source,
        page_mm: layout.page_mm,
        artwork: geometries.clone(),
        geometries,
        layers,
        profile,
        fields,
        ..Document::default()
    }
}
