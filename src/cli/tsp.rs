//! `galvoplan tsp`: orders plain point sets with the ordering engine (an open path on distance,
//! both ends free), so that anyone can compare it with LKH or Concorde; and writes the random
//! point sets the benchmarks use.

use anyhow::{Context, Result};
use clap::Args;
use galvoplan::geom::Pt;
use galvoplan::import::{import_svg_file, ImportOptions};
use galvoplan::job::JobCtx;
use galvoplan::order::tsp::{held_karp_open_path, open_path, IlsBudget};
use rand::{Rng, SeedableRng};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Side of the square the generated point sets fill, mm (one 420 mm field holds it).
const GENERATED_SIDE_MM: f64 = 400.0;

/// Points per cluster of a generated clustered set.
const CLUSTER_SIZE: usize = 100;

/// Standard deviation of a cluster, as a fraction of the side.
const CLUSTER_SIGMA: f64 = 1.0 / 40.0;

/// Length of the 2 µm strokes that stand for points in a generated SVG (above the importer's
/// 1 µm degenerate limit; a path through them differs from the point path by at most this per
/// point).
const DOT_MM: f64 = 0.002;

/// Arguments of `galvoplan tsp`.
#[derive(Args, Debug)]
pub struct TspArgs {
    /// Point sets: TSPLIB files (`NODE_COORD_SECTION`) or SVGs (a point per geometry: its
    /// centroid).
    inputs: Vec<PathBuf>,
    /// First random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Seeds per instance (from --seed on).
    #[arg(long, default_value_t = 1)]
    seeds: u64,
    /// Search for this many seconds instead of the kick budget (stops earlier after a long
    /// stall; default: the kick budget alone, deterministic).
    #[arg(long)]
    time_limit: Option<f64>,
    /// Kicks of the iterated local search (default: as many as the ordering uses for a field of
    /// that size).
    #[arg(long)]
    kicks: Option<usize>,
    /// Write the order of the last run (0-based point indices, one a line).
    #[arg(long, value_name = "OUT.txt")]
    tour: Option<PathBuf>,
    /// Instead of ordering: write a random point set KIND:N (uniform or clustered) as OUT.tsp
    /// and OUT.svg (2 µm strokes), drawn with --seed.
    #[arg(long, value_name = "KIND:N", requires = "out")]
    generate: Option<String>,
    /// Path stem for --generate.
    #[arg(long, value_name = "STEM")]
    out: Option<PathBuf>,
    /// Also compute the Held–Karp lower bound on the shortest open path with this many 1-tree
    /// evaluations (`O(n²)` each: about 0.3 s at 10⁴ points) and print each path's gap to it,
    /// an upper bound on its gap to the optimum and to LKH.
    #[arg(long, value_name = "ITERATIONS")]
    bound: Option<usize>,
}

/// Runs `galvoplan tsp`.
pub fn run(a: &TspArgs) -> Result<()> {
    if let Some(spec) = &a.generate {
        let out = a.out.as_deref().context("--generate needs --out")?;
        return generate(spec, a.seed, out);
    }
    anyhow::ensure!(!a.inputs.is_empty(), "no input: give TSPLIB or SVG files");
    if a.bound == Some(0) {
        anyhow::bail!("--bound needs at least 1 iteration");
    }
    if let Some(t) = a.time_limit {
        anyhow::ensure!(
            t.is_finite() && t > 0.0,
            "--time-limit must be positive, got {t}"
        );
    }
    let ctx = JobCtx::default();
    if a.bound.is_some() {
        println!(
            "| instance | points | seed | length | ms | Held–Karp bound | gap to bound | bound s |"
        );
        println!("|---|---|---|---|---|---|---|---|");
    } else {
        println!("| instance | points | seed | length | ms |");
        println!("|---|---|---|---|---|");
    }
    for path in &a.inputs {
        let points = read_points(path)?;
        anyhow::ensure!(
            points.len() >= 2,
            "{}: fewer than two points",
            path.display()
        );
        // the bound is computed once per instance, after its first path (which sizes its steps)
        let mut bound: Option<(f64, f64)> = None;
        for seed in a.seed..a.seed + a.seeds {
            let t = Instant::now();
            // a time limit replaces the kick budget (kicks until it, or until a long stall)
            let budget = match a.time_limit {
                Some(limit) => {
                    IlsBudget::until(points.len(), Some(t + Duration::from_secs_f64(limit)))
                }
                None => IlsBudget::for_nodes(points.len(), a.kicks),
            };
            let order = open_path(&points, budget, seed, &ctx)?;
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let length: f64 = order
                .windows(2)
                .map(|w| points[w[0]].dist(points[w[1]]))
                .sum();
            let name = path
                .file_stem()
                .map_or(String::new(), |s| s.to_string_lossy().into());
            let bound_cells = match (a.bound, bound) {
                (None, _) => String::new(),
                (Some(iterations), None) => {
                    let t = Instant::now();
                    let lower = held_karp_open_path(&points, length, iterations, &ctx)?;
                    let computed = (lower, t.elapsed().as_secs_f64());
                    bound = Some(computed);
                    bound_columns(length, computed)
                }
                (Some(_), Some(computed)) => bound_columns(length, computed),
            };
            println!(
                "| {name} | {} | {seed} | {length:.4} | {ms:.1} |{bound_cells}",
                points.len()
            );
            if let Some(out) = &a.tour {
                let text: String = order.iter().map(|v| format!("{v}\n")).collect();
                std::fs::write(out, text)
                    .with_context(|| format!("{}: cannot write", out.display()))?;
            }
        }
    }
    Ok(())
}

/// The table cells of a path of `length` mm against a bound `(lower, seconds)`.
fn bound_columns(length: f64, (lower, seconds): (f64, f64)) -> String {
    let gap = if lower > 0.0 {
        format!("{:+.2} %", (length / lower - 1.0) * 100.0)
    } else {
        "–".into()
    };
    format!(" {lower:.4} | {gap} | {seconds:.1} |")
}

/// The points of a TSPLIB file or an SVG.
fn read_points(path: &Path) -> Result<Vec<Pt>> {
    let is_svg = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg") || e.eq_ignore_ascii_case("svgz"));
    if is_svg {
        let imported = import_svg_file(path, &ImportOptions::default())?;
        return Ok(imported.geometries.iter().map(|g| g.centroid()).collect());
    }
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    parse_tsplib(&text).with_context(|| {
        format!(
            "{}: not a TSPLIB file with node coordinates",
            path.display()
        )
    })
}

/// The coordinates of a TSPLIB `NODE_COORD_SECTION` (`index x y` lines up to `EOF`).
fn parse_tsplib(text: &str) -> Result<Vec<Pt>> {
    let mut points = Vec::new();
    let mut in_section = false;
    for (no, line) in text.lines().enumerate() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.first() {
            None => continue,
            Some(&"NODE_COORD_SECTION") => in_section = true,
            Some(&"EOF") => break,
            Some(_) if in_section => {
                let coord = |k: usize| -> Result<f64> {
                    t.get(k)
                        .and_then(|s| s.parse::<f64>().ok())
                        .with_context(|| format!("line {}: expected `index x y`", no + 1))
                };
                points.push(Pt::new(coord(1)?, coord(2)?));
            }
            Some(_) => {}
        }
    }
    anyhow::ensure!(in_section, "no NODE_COORD_SECTION");
    Ok(points)
}

/// Writes a random point set `KIND:N` as `OUT.tsp` and `OUT.svg`.
fn generate(spec: &str, seed: u64, out: &Path) -> Result<()> {
    let (kind, n) = spec
        .split_once(':')
        .context("--generate takes KIND:N, e.g. uniform:1000")?;
    let n: usize = n
        .parse()
        .with_context(|| format!("--generate: `{n}` is not a count"))?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let s = GENERATED_SIDE_MM;
    let points: Vec<Pt> = match kind {
        "uniform" => (0..n)
            .map(|_| Pt::new(rng.random_range(0.0..s), rng.random_range(0.0..s)))
            .collect(),
        "clustered" => clustered(n, &mut rng),
        _ => anyhow::bail!("--generate: kind `{kind}` is not uniform or clustered"),
    };
    let stem = out.display().to_string();
    let mut tsp = format!("NAME : {stem}\nTYPE : TSP\nDIMENSION : {n}\nEDGE_WEIGHT_TYPE : EUC_2D\nNODE_COORD_SECTION\n");
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{s}mm\" height=\"{s}mm\" viewBox=\"0 0 {s} {s}\" fill=\"none\" stroke=\"black\" stroke-width=\"0.1\">\n"
    );
    for (i, q) in points.iter().enumerate() {
        writeln!(tsp, "{} {:.4} {:.4}", i + 1, q.x, q.y)?;
        writeln!(svg, "<path d=\"M {:.4} {:.4} h {DOT_MM}\"/>", q.x, q.y)?;
    }
    tsp.push_str("EOF\n");
    svg.push_str("</svg>\n");
    for (ext, text) in [("tsp", tsp), ("svg", svg)] {
        let p = PathBuf::from(format!("{stem}.{ext}"));
        std::fs::write(&p, text).with_context(|| format!("{}: cannot write", p.display()))?;
    }
    Ok(())
}

/// `n` points in Gaussian clusters of about [`CLUSTER_SIZE`] around uniform centres, kept inside
/// the square.
fn clustered(n: usize, rng: &mut rand_chacha::ChaCha8Rng) -> Vec<Pt> {
    let s = GENERATED_SIDE_MM;
    let margin = 0.05 * s;
    let centres: Vec<Pt> = (0..n.div_ceil(CLUSTER_SIZE).max(1))
        .map(|_| {
            Pt::new(
                rng.random_range(margin..s - margin),
                rng.random_range(margin..s - margin),
            )
        })
        .collect();
    let sigma = CLUSTER_SIGMA * s;
    let mut points = Vec::with_capacity(n);
    while points.len() < n {
        let c = centres[rng.random_range(0..centres.len())];
        // Box–Muller: two uniforms give a standard normal pair
        let (u, v): (f64, f64) = (
            rng.random_range(f64::EPSILON..1.0),
            rng.random_range(0.0..1.0),
        );
        let r = (-2.0 * u.ln()).sqrt() * sigma;
        let q = Pt::new(
            c.x + r * (std::f64::consts::TAU * v).cos(),
            c.y + r * (std::f64::consts::TAU * v).sin(),
        );
        if (0.0..=s).contains(&q.x) && (0.0..=s).contains(&q.y) {
            points.push(q);
        }
    }
    points
}
