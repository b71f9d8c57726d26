//! Seed 003's experiment: hatch the contest's contours at several spacings (edge offset =
//! spacing) and report counts, lengths and mean generation times.
//!
//! Contours come from the contest's CSV attachments (`HatchData`, then per contour a
//! `MainCurveN` line, an `X,Y` header and one `x,y` row per point, in mm) or from an SVG (all
//! closed geometries as one region).

use crate::geom::Pt;
use crate::hatch::{
    hatch_contours, HatchError, HatchSettings, HatchStats, HatchStyle, OutlineMode,
};
use crate::import::{import_svg_file, ImportOptions};
use crate::job::JobCtx;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;
use thiserror::Error;

/// Why a benchmark input could not be used.
#[derive(Debug, Error)]
pub enum BenchError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a contour CSV.
    #[error("{file}: line {line}: {reason}")]
    Csv {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// The SVG could not be imported.
    #[error(transparent)]
    Import(#[from] crate::import::ImportError),
    /// No closed contour in the input.
    #[error("{file}: no closed contour with at least 3 points")]
    Empty {
        /// The file.
        file: String,
    },
    /// Hatching failed.
    #[error(transparent)]
    Hatch(#[from] HatchError),
}

/// Parses a contest CSV into contours (mm). `file` names it in errors.
pub fn parse_contours_csv(text: &str, file: &str) -> Result<Vec<Vec<Pt>>, BenchError> {
    let mut contours: Vec<Vec<Pt>> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim().trim_start_matches('\u{feff}').trim();
        if line.is_empty()
            || line.eq_ignore_ascii_case("hatchdata")
            || line.eq_ignore_ascii_case("x,y")
        {
            continue;
        }
        if line.to_ascii_lowercase().starts_with("maincurve") {
            contours.push(Vec::new());
            continue;
        }
        let err = |reason: String| BenchError::Csv {
            file: file.into(),
            line: i + 1,
            reason,
        };
        let mut it = line.split(',').map(str::trim);
        let (Some(x), Some(y), None) = (it.next(), it.next(), it.next()) else {
            return Err(err(format!("expected `x,y`, got {line:?}")));
        };
        let (x, y) = match (x.parse::<f64>(), y.parse::<f64>()) {
            (Ok(x), Ok(y)) if x.is_finite() && y.is_finite() => (x, y),
            _ => return Err(err(format!("not a pair of numbers: {line:?}"))),
        };
        match contours.last_mut() {
            Some(c) => c.push(Pt::new(x, y)),
            None => contours.push(vec![Pt::new(x, y)]),
        }
    }
    contours.retain(|c| c.len() >= 3);
    if contours.is_empty() {
        return Err(BenchError::Empty { file: file.into() });
    }
    Ok(contours)
}

/// Reads contours from a contest CSV or an SVG file.
pub fn read_contours(path: &Path) -> Result<Vec<Vec<Pt>>, BenchError> {
    let file = path.display().to_string();
    let is_svg = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg") || e.eq_ignore_ascii_case("svgz"));
    if is_svg {
        let imported = import_svg_file(path, &ImportOptions::default())?;
        let contours: Vec<Vec<Pt>> = imported
            .geometries
            .into_iter()
            .filter(|g| g.closed && g.points.len() >= 3)
            .map(|g| g.points)
            .collect();
        if contours.is_empty() {
            return Err(BenchError::Empty { file });
        }
        return Ok(contours);
    }
    let text = std::fs::read_to_string(path).map_err(|source| BenchError::Io {
        file: file.clone(),
        source,
    })?;
    parse_contours_csv(&text, &file)
}

/// One row of the experiment.
#[derive(Debug, Clone, Serialize)]
pub struct BenchCase {
    /// Input name (file stem).
    pub instance: String,
    /// Style.
    pub style: HatchStyle,
    /// Spacing = edge offset, mm.
    pub spacing_mm: f64,
    /// Counts and lengths.
    pub stats: HatchStats,
    /// Timed runs.
    pub runs: usize,
    /// Mean generation time, ms.
    pub mean_ms: f64,
    /// Median generation time, ms.
    pub median_ms: f64,
    /// Fastest run, ms.
    pub min_ms: f64,
}

/// Hatches `contours` (even-odd) `runs` times after one untimed warm-up; edge offset = spacing,
/// angle 0°.
pub fn run_case(
    instance: &str,
    contours: &[Vec<Pt>],
    style: HatchStyle,
    spacing_mm: f64,
    runs: usize,
) -> Result<BenchCase, BenchError> {
    let settings = HatchSettings {
        style,
        spacing_mm,
        edge_offset_mm: Some(spacing_mm),
        outline: OutlineMode::None,
        ..HatchSettings::default()
    };
    let ctx = JobCtx::default();
    let mut stats = hatch_contours(contours, &settings, &ctx)?.stats;
    let mut times = Vec::with_capacity(runs.max(1));
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        let h = hatch_contours(contours, &settings, &ctx)?;
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        stats = std::hint::black_box(h).stats;
    }
    let mean_ms = times.iter().sum::<f64>() / times.len() as f64;
    times.sort_by(f64::total_cmp);
    let n = times.len();
    let median_ms = if n % 2 == 1 {
        times[n / 2]
    } else {
        (times[n / 2 - 1] + times[n / 2]) / 2.0
    };
    Ok(BenchCase {
        instance: instance.into(),
        style,
        spacing_mm,
        stats,
        runs: n,
        mean_ms,
        median_ms,
        min_ms: times[0],
    })
}

/// The rows as a Markdown table; the ratio column is the mean time over the mean time of the
/// same instance and style at the largest spacing.
pub fn format_table(rows: &[BenchCase]) -> String {
    let mut s = String::from(
        "| instance | style | d = s mm | lines | parts | rings (levels) | gap strokes | border strokes | fill mm | border + gap mm | total mm | mean ms | median ms | min ms | runs | ratio |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let base = rows
            .iter()
            .filter(|b| b.instance == r.instance && b.style == r.style)
            .max_by(|a, b| a.spacing_mm.total_cmp(&b.spacing_mm));
        let ratio = base.map_or(1.0, |b| r.mean_ms / b.mean_ms.max(1e-12));
        let st = &r.stats;
        let contour = r.style == HatchStyle::Contour;
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.2} | {} | {:.2} |\n",
            r.instance,
            r.style,
            r.spacing_mm,
            if contour { "–".into() } else { st.lines.to_string() },
            if contour { "–".into() } else { st.parts.to_string() },
            if contour { format!("{} ({})", st.rings, st.levels) } else { "–".into() },
            if contour { st.gaps.to_string() } else { "–".into() },
            st.borders,
            st.fill_mm,
            st.border_mm + st.gap_mm,
            st.total_mm,
            r.mean_ms,
            r.median_ms,
            r.min_ms,
            r.runs,
            ratio
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_contest_csv() {
        let text = "\u{feff}HatchData\nMainCurve1\nX,Y\n0,0\n10,0\n10,10\n0,10\nMainCurve2\nX,Y\n3,3\n3,7\n7,7\n";
        let c = parse_contours_csv(text, "t.csv").unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(c[1][2], Pt::new(7.0, 7.0));
        let e = parse_contours_csv("MainCurve1\n1,2\nx,3\n", "t.csv").unwrap_err();
        assert!(e.to_string().contains("t.csv: line 3"), "{e}");
        assert!(parse_contours_csv("HatchData\n", "t.csv").is_err());
    }

    #[test]
    fn runs_a_case() {
        let sq = vec![vec![
            Pt::new(0.0, 0.0),
            Pt::new(10.0, 0.0),
            Pt::new(10.0, 10.0),
            Pt::new(0.0, 10.0),
        ]];
        let c = run_case("sq", &sq, HatchStyle::Zigzag, 1.0, 2).unwrap();
        assert_eq!(c.runs, 2);
        // offset square 8 × 8: 8 lines
        assert_eq!(c.stats.lines, 8);
        assert!(
            (c.stats.total_mm - (8.0 * 8.0 + 32.0)).abs() < 1e-6,
            "{:?}",
            c.stats
        );
        let t = format_table(&[c]);
        assert!(t.contains("| sq | zigzag | 1 | 8 | 1 |"), "{t}");
    }
}
