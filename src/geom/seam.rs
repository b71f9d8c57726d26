//! Cutting strokes at a tiling's seams, in one of four seam forms, and measuring the seams.
//!
//! A stroke that crosses a seam is cut into pieces, each marked from one field. Where the
//! pieces of neighbouring fields meet, any stitching error of the machine shows: the seam form
//! says how the meeting is spread.
//!
//! - **straight**: every cut lies on the seam line.
//! - **interlocked** (band b): the cut of the k-th crossing along the seam (crossings sorted by
//!   their position along the seam: line by line for a fill) lies at `+b/2` past the seam for
//!   even k and `−b/2` for odd k, so the meeting points form a comb, not a line.
//! - **staggered** (band b, seed): the cut lies at an offset drawn uniformly from `[−b/2, b/2]`
//!   per crossing (ChaCha8 seeded by the seed, the axis and the seam's index: the same seed gives
//!   the same cuts).
//! - **overlap** (d): both pieces mark past the cut. *Kept dose* (the default): crossing k's
//!   cut lies at `+d` for even k and `−d` for odd k, so every line is marked once and the band
//!   of `2d` is shared line by line between the two fields (on a fill the dose is unchanged;
//!   this is an interlocked seam of band `2d`). *Doubled*: the piece before the cut runs `d`
//!   past the seam and the piece after it starts `d` before it, so `2d` of each crossing (along
//!   the seam's normal) is marked twice; that length is [`SeamStats::extra_marked_mm`].
//!
//! Every form is exact: the pieces together are the stroke (plus, for doubled overlap, the
//! declared overlaps), and no cut leaves its segment: a cut offset that would pass the end of
//! the crossing segment stops at that end (the cut then lies within the band, not at its edge).
//! A piece passes its cell by at most [`SeamForm::reach_mm`], which the tiling's cells leave
//! room for.

use super::tiling::Tiling;
use super::{polyline_length, Pt};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Pieces shorter than this are dropped, mm: below the resolution of the exported G-code (a
/// crumb where a cut passes near a vertex would print as no move at all).
pub const MIN_PIECE_MM: f64 = 1e-3;
/// Crossings of one seam closer than this along it belong to one stretch of marked area (a
/// fill's lines); a seam's length through marked area sums its stretches, mm.
pub const SEAM_BRIDGE_MM: f64 = 2.0;
/// The widest band or overlap a seam form may have, mm.
pub const MAX_SEAM_BAND_MM: f64 = 10.0;

/// How strokes are cut where they cross a seam (see the module notes).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum SeamForm {
    /// Cut on the seam line.
    #[default]
    Straight,
    /// Both sides mark past the cut.
    Overlap {
        /// How far each side marks past the seam, mm.
        overlap_mm: f64,
        /// True: the overlap is marked twice. False: the cut alternates ±overlap line by line
        /// (the dose is kept).
        doubled: bool,
    },
    /// The cut alternates ±band/2 line by line.
    Interlocked {
        /// Width of the comb, mm.
        band_mm: f64,
    },
    /// The cut lies at a seeded random offset within the band.
    Staggered {
        /// Width of the band, mm.
        band_mm: f64,
        /// Random seed.
        seed: u64,
    },
}

impl SeamForm {
    /// How far a piece may pass the seam line, mm.
    pub fn reach_mm(&self) -> f64 {
        match *self {
            SeamForm::Straight => 0.0,
            SeamForm::Overlap { overlap_mm, .. } => overlap_mm,
            SeamForm::Interlocked { band_mm } | SeamForm::Staggered { band_mm, .. } => {
                band_mm / 2.0
            }
        }
    }

    /// Parses `straight`, `overlap:D[:doubled]`, `interlocked:BAND` or `staggered:BAND[:SEED]`
    /// (mm).
    pub fn parse(spec: &str) -> Result<Self, SeamParseError> {
        let parts: Vec<&str> = spec.trim().split(':').map(str::trim).collect();
        let mm = |k: usize, what: &'static str| -> Result<f64, SeamParseError> {
            let text = parts.get(k).ok_or_else(|| SeamParseError::Missing {
                spec: spec.into(),
                what,
            })?;
            let v: f64 = text.parse().map_err(|_| SeamParseError::NotANumber {
                spec: spec.into(),
                what,
                text: (*text).into(),
            })?;
            if !(v > 0.0 && v <= MAX_SEAM_BAND_MM) {
                return Err(SeamParseError::OutOfRange {
                    spec: spec.into(),
                    what,
                });
            }
            Ok(v)
        };
        let extra = |n: usize| -> Result<(), SeamParseError> {
            match parts.get(n..) {
                Some(rest) if !rest.is_empty() => Err(SeamParseError::Unexpected {
                    spec: spec.into(),
                    rest: rest.join(":"),
                }),
                _ => Ok(()),
            }
        };
        let form = match parts[0] {
            "straight" => {
                extra(1)?;
                SeamForm::Straight
            }
            "overlap" => {
                let doubled = match parts.get(2).copied() {
                    None | Some("kept") => false,
                    Some("doubled") => true,
                    Some(other) => {
                        return Err(SeamParseError::OverlapKind {
                            spec: spec.into(),
                            word: other.into(),
                        })
                    }
                };
                extra(3)?;
                SeamForm::Overlap {
                    overlap_mm: mm(1, "overlap")?,
                    doubled,
                }
            }
            "interlocked" => {
                extra(2)?;
                SeamForm::Interlocked {
                    band_mm: mm(1, "band")?,
                }
            }
            "staggered" => {
                let seed = match parts.get(2) {
                    None => 1,
                    Some(s) => s.parse().map_err(|_| SeamParseError::Seed {
                        spec: spec.into(),
                        text: (*s).into(),
                    })?,
                };
                extra(3)?;
                SeamForm::Staggered {
                    band_mm: mm(1, "band")?,
                    seed,
                }
            }
            other => return Err(SeamParseError::UnknownForm { form: other.into() }),
        };
        Ok(form)
    }

    /// Words for the operator ("interlocked, band 0.5 mm").
    pub fn describe(&self) -> String {
        match *self {
            SeamForm::Straight => "straight".into(),
            SeamForm::Overlap {
                overlap_mm,
                doubled,
            } => format!(
                "overlap {overlap_mm} mm ({})",
                if doubled {
                    "marked twice"
                } else {
                    "dose kept: alternating ends"
                }
            ),
            SeamForm::Interlocked { band_mm } => format!("interlocked, band {band_mm} mm"),
            SeamForm::Staggered { band_mm, seed } => {
                format!("staggered, band {band_mm} mm, seed {seed}")
            }
        }
    }
}

impl std::fmt::Display for SeamForm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            SeamForm::Straight => write!(f, "straight"),
            SeamForm::Overlap {
                overlap_mm,
                doubled,
            } => write!(
                f,
                "overlap:{overlap_mm}{}",
                if doubled { ":doubled" } else { "" }
            ),
            SeamForm::Interlocked { band_mm } => write!(f, "interlocked:{band_mm}"),
            SeamForm::Staggered { band_mm, seed } => write!(f, "staggered:{band_mm}:{seed}"),
        }
    }
}

impl TryFrom<String> for SeamForm {
    type Error = SeamParseError;
    fn try_from(s: String) -> Result<Self, SeamParseError> {
        SeamForm::parse(&s)
    }
}

/// Why a seam form (`--seam`, a pen's `seam`) does not read; every message quotes it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SeamParseError {
    /// The form's width is not given.
    #[error("seam '{spec}': {what} missing (mm)")]
    Missing {
        /// The seam form as given.
        spec: String,
        /// The width it lacks (`overlap`, `band`).
        what: &'static str,
    },
    /// The form's width is not a number.
    #[error("seam '{spec}': {what} '{text}' is not a number")]
    NotANumber {
        /// The seam form as given.
        spec: String,
        /// The width (`overlap`, `band`).
        what: &'static str,
        /// Its text.
        text: String,
    },
    /// The form's width is 0 or less, or beyond [`MAX_SEAM_BAND_MM`].
    #[error("seam '{spec}': {what} must be above 0 and at most {MAX_SEAM_BAND_MM} mm")]
    OutOfRange {
        /// The seam form as given.
        spec: String,
        /// The width (`overlap`, `band`).
        what: &'static str,
    },
    /// More parts than the form takes.
    #[error("seam '{spec}': unexpected '{rest}'")]
    Unexpected {
        /// The seam form as given.
        spec: String,
        /// The parts beyond the form, as written.
        rest: String,
    },
    /// An overlap's third part that is neither `kept` nor `doubled`.
    #[error("seam '{spec}': '{word}' is neither 'kept' nor 'doubled'")]
    OverlapKind {
        /// The seam form as given.
        spec: String,
        /// The word given.
        word: String,
    },
    /// A staggered seam's seed that is not a whole number.
    #[error("seam '{spec}': seed '{text}' is not a whole number")]
    Seed {
        /// The seam form as given.
        spec: String,
        /// The seed's text.
        text: String,
    },
    /// None of the forms.
    #[error(
        "seam '{form}': expected straight, overlap:D[:doubled], interlocked:BAND or \
         staggered:BAND[:SEED]"
    )]
    UnknownForm {
        /// The form's name as given.
        form: String,
    },
}

impl From<SeamForm> for String {
    fn from(f: SeamForm) -> String {
        f.to_string()
    }
}

/// One seam line and where it runs through marked area.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeamLine {
    /// 0: a vertical seam (x = `at_mm`); 1: a horizontal one (y = `at_mm`).
    pub axis: usize,
    /// Its position, mm.
    pub at_mm: f64,
    /// Stretches along it through marked area (crossings closer than [`SEAM_BRIDGE_MM`]
    /// joined), `[from, to]` in the other coordinate, mm, ascending.
    pub spans: Vec<[f64; 2]>,
}

/// What cutting at seams did.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SeamStats {
    /// Cuts made.
    pub cuts: usize,
    /// Strokes cut (each became two or more pieces).
    pub split_strokes: usize,
    /// Length marked twice on purpose (doubled overlap seams), mm.
    pub extra_marked_mm: f64,
    /// The seam lines that cut something.
    pub lines: Vec<SeamLine>,
}

impl SeamStats {
    /// Seam lines that cut something.
    pub fn seams(&self) -> usize {
        self.lines.len()
    }

    /// Seam length through marked area, mm.
    pub fn length_mm(&self) -> f64 {
        // a fold from +0: an empty `sum` of floats is −0
        self.lines
            .iter()
            .flat_map(|l| l.spans.iter())
            .fold(0.0, |acc, s| acc + (s[1] - s[0]))
    }

    /// Adds another cut's figures (seam lines at the same place merge).
    pub fn merge(&mut self, other: SeamStats) {
        self.cuts += other.cuts;
        self.split_strokes += other.split_strokes;
        self.extra_marked_mm += other.extra_marked_mm;
        for l in other.lines {
            match self
                .lines
                .iter_mut()
                .find(|m| m.axis == l.axis && (m.at_mm - l.at_mm).abs() < 1e-9)
            {
                Some(m) => {
                    m.spans = merge_spans(m.spans.iter().chain(l.spans.iter()).copied());
                }
                None => self.lines.push(l),
            }
        }
        self.lines
            .sort_by(|a, b| a.axis.cmp(&b.axis).then(a.at_mm.total_cmp(&b.at_mm)));
    }
}

/// Joins spans that overlap or lie within [`SEAM_BRIDGE_MM`].
fn merge_spans(spans: impl Iterator<Item = [f64; 2]>) -> Vec<[f64; 2]> {
    let mut v: Vec<[f64; 2]> = spans.collect();
    v.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(v.len());
    for s in v {
        match out.last_mut() {
            Some(l) if s[0] - l[1] <= SEAM_BRIDGE_MM => l[1] = l[1].max(s[1]),
            _ => out.push(s),
        }
    }
    out
}

/// Strokes cut at seams.
#[derive(Debug, Clone, Default)]
pub struct SeamCut {
    /// Pieces in stroke order, each with the index of the stroke it came from (a stroke that
    /// crosses no seam is one piece, as it was; a closed stroke stays closed then).
    pub pieces: Vec<(usize, Vec<Pt>, bool)>,
    /// What the cut did.
    pub stats: SeamStats,
}

/// A stroke crossing a seam.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    stroke: usize,
    segment: usize,
    /// Where on the segment the seam line is crossed.
    t: f64,
    axis: usize,
    seam: usize,
    along: f64,
    /// The piece before the cut ends here, and the piece after it starts here (segment
    /// parameters; equal unless the overlap is doubled).
    t_end: f64,
    t_start: f64,
}

/// Cuts `strokes` (`points`, `closed`) where they cross the seams of `tiling`, in `form` (the
/// caller passes only the strokes to cut). A closed stroke's last and first piece are joined
/// when `fits` says the joined piece fits a field.
pub fn cut_at_seams(
    strokes: &[(&[Pt], bool)],
    tiling: &Tiling,
    form: SeamForm,
    fits: impl Fn(&[Pt]) -> bool,
) -> SeamCut {
    let mut crossings = find_crossings(strokes, tiling);
    place_cuts(&mut crossings, tiling, form, strokes);
    let mut out = SeamCut::default();
    out.stats.lines = seam_lines(&crossings, tiling);
    // crossings by stroke, then along the stroke
    crossings.sort_by(|a, b| {
        a.stroke
            .cmp(&b.stroke)
            .then(a.segment.cmp(&b.segment))
            .then(a.t.total_cmp(&b.t))
    });
    let mut next = 0;
    for (k, &(points, closed)) in strokes.iter().enumerate() {
        let start = next;
        while next < crossings.len() && crossings[next].stroke == k {
            next += 1;
        }
        let mine = &crossings[start..next];
        if mine.is_empty() {
            out.pieces.push((k, points.to_vec(), closed));
            continue;
        }
        let (pieces, extra) = cut_stroke(points, closed, mine, &fits);
        out.stats.cuts += mine.len();
        if pieces.len() > 1 {
            out.stats.split_strokes += 1;
        }
        out.stats.extra_marked_mm += extra;
        out.pieces
            .extend(pieces.into_iter().map(|(p, c)| (k, p, c)));
    }
    out
}

/// Every crossing of a stroke's segment with a seam line inside the tiling's extent: the seam
/// at `c` is crossed by a segment whose coordinate range has `min < c ≤ max` (a vertex on the
/// seam is cut once).
fn find_crossings(strokes: &[(&[Pt], bool)], tiling: &Tiling) -> Vec<Crossing> {
    let mut out = Vec::new();
    let extent = tiling.extent();
    let eps = 1e-9;
    for (k, &(points, closed)) in strokes.iter().enumerate() {
        if points.len() < 2 {
            continue;
        }
        let n = points.len();
        let segs = if closed { n } else { n - 1 };
        for segment in 0..segs {
            let (a, b) = (points[segment], points[(segment + 1) % n]);
            for axis in 0..2 {
                let (pa, pb) = if axis == 0 { (a.x, b.x) } else { (a.y, b.y) };
                if pa == pb {
                    continue;
                }
                let (lo, hi) = (pa.min(pb), pa.max(pb));
                let seams = tiling.seams(axis);
                let first = seams.partition_point(|&s| s <= lo);
                for (seam, &c) in seams.iter().enumerate().skip(first) {
                    if c > hi {
                        break;
                    }
                    let t = (c - pa) / (pb - pa);
                    let p = a.plus(b.minus(a).scale(t));
                    // seams end at the tiling's extent
                    let (along, lo_other, hi_other) = if axis == 0 {
                        (p.y, extent.min_y, extent.max_y)
                    } else {
                        (p.x, extent.min_x, extent.max_x)
                    };
                    if along < lo_other - eps || along > hi_other + eps {
                        continue;
                    }
                    out.push(Crossing {
                        stroke: k,
                        segment,
                        t,
                        axis,
                        seam,
                        along,
                        t_end: t,
                        t_start: t,
                    });
                }
            }
        }
    }
    out
}

/// Sets each crossing's cut (`t_end`, `t_start`) for the form, ranking the crossings of a seam
/// along it.
fn place_cuts(
    crossings: &mut [Crossing],
    tiling: &Tiling,
    form: SeamForm,
    strokes: &[(&[Pt], bool)],
) {
    if form == SeamForm::Straight {
        return;
    }
    crossings.sort_by(|a, b| {
        a.axis
            .cmp(&b.axis)
            .then(a.seam.cmp(&b.seam))
            .then(a.along.total_cmp(&b.along))
    });
    let mut rank = 0usize;
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    for i in 0..crossings.len() {
        let x = crossings[i];
        let new_seam = i == 0 || {
            let p = crossings[i - 1];
            p.axis != x.axis || p.seam != x.seam
        };
        if new_seam {
            rank = 0;
            if let SeamForm::Staggered { seed, .. } = form {
                let key = seed
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .wrapping_add(((x.axis as u64) << 32) | x.seam as u64);
                rng = ChaCha8Rng::seed_from_u64(key);
            }
        }
        let c = tiling.seams(x.axis)[x.seam];
        let (points, closed) = strokes[x.stroke];
        let n = points.len();
        let (a, b) = (points[x.segment], points[(x.segment + 1) % n]);
        debug_assert!(closed || x.segment + 1 < n);
        let (pa, pb) = if x.axis == 0 { (a.x, b.x) } else { (a.y, b.y) };
        let t_at = |v: f64| ((v - pa) / (pb - pa)).clamp(0.0, 1.0);
        let sign = if rank % 2 == 0 { 1.0 } else { -1.0 };
        let (end, start) = match form {
            SeamForm::Straight => (c, c),
            SeamForm::Interlocked { band_mm } => {
                let v = c + sign * band_mm / 2.0;
                (v, v)
            }
            SeamForm::Staggered { band_mm, .. } => {
                let v = c + rng.random_range(-0.5..=0.5) * band_mm;
                (v, v)
            }
            SeamForm::Overlap {
                overlap_mm,
                doubled: false,
            } => {
                let v = c + sign * overlap_mm;
                (v, v)
            }
            SeamForm::Overlap {
                overlap_mm,
                doubled: true,
            } => {
                let dir = (pb - pa).signum();
                (c + dir * overlap_mm, c - dir * overlap_mm)
            }
        };
        crossings[i].t_end = t_at(end);
        crossings[i].t_start = t_at(start);
        rank += 1;
    }
}

/// The seam lines crossed, with their stretches through marked area.
fn seam_lines(crossings: &[Crossing], tiling: &Tiling) -> Vec<SeamLine> {
    let mut by_seam: std::collections::BTreeMap<(usize, usize), Vec<f64>> = Default::default();
    for x in crossings {
        by_seam.entry((x.axis, x.seam)).or_default().push(x.along);
    }
    by_seam
        .into_iter()
        .map(|((axis, seam), mut along)| {
            along.sort_by(f64::total_cmp);
            let spans = merge_spans(along.iter().map(|&a| [a, a]));
            SeamLine {
                axis,
                at_mm: tiling.seams(axis)[seam],
                spans,
            }
        })
        .collect()
}

/// Cuts one stroke at its crossings (sorted along it); returns the pieces (closed only when
/// whole) and the length marked twice.
fn cut_stroke(
    points: &[Pt],
    closed: bool,
    crossings: &[Crossing],
    fits: &impl Fn(&[Pt]) -> bool,
) -> (Vec<(Vec<Pt>, bool)>, f64) {
    let mut path = points.to_vec();
    if closed {
        if let Some(&p) = points.first() {
            path.push(p);
        }
    }
    let mut pieces: Vec<Vec<Pt>> = Vec::new();
    let mut cur: Vec<Pt> = path.first().copied().into_iter().collect();
    let mut extra = 0.0;
    let mut c = 0;
    for (segment, w) in path.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        let at = |t: f64| a.plus(b.minus(a).scale(t));
        // cuts on one segment stay in order: none starts before the last one's start
        let mut floor = 0.0;
        while c < crossings.len() && crossings[c].segment == segment {
            let x = crossings[c];
            let t_end = x.t_end.max(floor);
            let t_start = x.t_start.max(floor).min(t_end);
            cur.push(at(t_end));
            pieces.push(std::mem::take(&mut cur));
            cur.push(at(t_start));
            extra += (t_end - t_start) * a.dist(b);
            floor = t_start;
            c += 1;
        }
        cur.push(b);
    }
    pieces.push(cur);
    let mut pieces: Vec<Vec<Pt>> = pieces
        .into_iter()
        .map(|mut p| {
            p.dedup_by(|a, b| a.dist2(*b) < 1e-24);
            p
        })
        .filter(|p| p.len() >= 2 && polyline_length(p, false) > MIN_PIECE_MM)
        .collect();
    // a closed stroke: its last piece runs into its first; join them when they fit together
    if closed && pieces.len() > 1 {
        let touch = pieces
            .last()
            .and_then(|l| l.last())
            .zip(pieces.first().and_then(|f| f.first()))
            .is_some_and(|(a, b)| a.dist(*b) < 1e-9);
        if touch {
            let mut joined = pieces[pieces.len() - 1].clone();
            joined.extend(pieces[0].iter().skip(1).copied());
            if fits(&joined) {
                pieces.remove(0);
                if let Some(last) = pieces.last_mut() {
                    *last = joined;
                }
            }
        }
    }
    let whole = pieces.len() == 1 && closed;
    (
        pieces
            .into_iter()
            .map(|mut p| {
                if whole {
                    // back to the closed form it came in
                    p.pop();
                }
                (p, whole)
            })
            .collect(),
        extra,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiling_x(seams: &[f64]) -> Tiling {
        let mut xs = vec![-100.0];
        xs.extend_from_slice(seams);
        xs.push(400.0);
        Tiling {
            xs,
            ys: vec![-100.0, 400.0],
        }
    }

    fn lines(n: usize) -> Vec<Vec<Pt>> {
        (0..n)
            .map(|k| {
                let y = k as f64 * 0.5;
                if k % 2 == 0 {
                    vec![Pt::new(0.0, y), Pt::new(240.0, y)]
                } else {
                    vec![Pt::new(240.0, y), Pt::new(0.0, y)]
                }
            })
            .collect()
    }

    fn cut(form: SeamForm, ls: &[Vec<Pt>], t: &Tiling) -> SeamCut {
        let strokes: Vec<(&[Pt], bool)> = ls.iter().map(|p| (p.as_slice(), false)).collect();
        cut_at_seams(&strokes, t, form, |_| true)
    }

    /// The x of every cut of stroke `k` (piece ends away from the stroke's ends).
    fn cuts_of(c: &SeamCut, k: usize) -> Vec<f64> {
        let mut xs: Vec<f64> = c
            .pieces
            .iter()
            .filter(|p| p.0 == k)
            .flat_map(|p| [p.1[0].x, p.1[p.1.len() - 1].x])
            .filter(|x| *x > 1e-9 && *x < 240.0 - 1e-9)
            .collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        xs
    }

    #[test]
    fn straight_cuts_on_the_seams_and_keeps_length() {
        let t = tiling_x(&[60.0, 120.0, 180.0]);
        let ls = lines(11);
        let c = cut(SeamForm::Straight, &ls, &t);
        assert_eq!(c.pieces.len(), 44);
        assert_eq!(c.stats.cuts, 33);
        assert_eq!(c.stats.split_strokes, 11);
        let total: f64 = c.pieces.iter().map(|p| polyline_length(&p.1, false)).sum();
        assert!((total - 11.0 * 240.0).abs() < 1e-9);
        for k in 0..11 {
            assert_eq!(cuts_of(&c, k), vec![60.0, 120.0, 180.0]);
        }
        assert_eq!(c.stats.seams(), 3);
        assert!((c.stats.length_mm() - 3.0 * 5.0).abs() < 1e-9);
    }

    #[test]
    fn interlocked_cuts_form_a_comb() {
        let t = tiling_x(&[60.0, 120.0]);
        let ls = lines(20);
        let c = cut(SeamForm::Interlocked { band_mm: 1.0 }, &ls, &t);
        for k in 0..20 {
            let want = if k % 2 == 0 {
                vec![60.5, 120.5]
            } else {
                vec![59.5, 119.5]
            };
            assert_eq!(cuts_of(&c, k), want, "line {k}");
        }
        let total: f64 = c.pieces.iter().map(|p| polyline_length(&p.1, false)).sum();
        assert!((total - 20.0 * 240.0).abs() < 1e-9);
        assert_eq!(c.stats.extra_marked_mm, 0.0);
    }

    #[test]
    fn staggered_cuts_stay_in_the_band_and_repeat_for_a_seed() {
        let t = tiling_x(&[100.0]);
        let ls = lines(50);
        let form = SeamForm::Staggered {
            band_mm: 2.0,
            seed: 7,
        };
        let a = cut(form, &ls, &t);
        let b = cut(form, &ls, &t);
        let xs: Vec<f64> = (0..50).flat_map(|k| cuts_of(&a, k)).collect();
        assert_eq!(xs.len(), 50);
        assert!(xs.iter().all(|x| (99.0..=101.0).contains(x)));
        assert!(xs.iter().any(|x| (x - 100.0).abs() > 0.3), "{xs:?}");
        assert_eq!(a.pieces, b.pieces);
    }

    #[test]
    fn doubled_overlap_declares_what_it_marks_twice() {
        let t = tiling_x(&[60.0, 120.0]);
        let ls = lines(4);
        let c = cut(
            SeamForm::Overlap {
                overlap_mm: 0.5,
                doubled: true,
            },
            &ls,
            &t,
        );
        let total: f64 = c.pieces.iter().map(|p| polyline_length(&p.1, false)).sum();
        // 4 lines × 2 seams × 2 × 0.5 mm
        assert!((c.stats.extra_marked_mm - 8.0).abs() < 1e-9);
        assert!((total - 4.0 * 240.0 - c.stats.extra_marked_mm).abs() < 1e-9);
        // each piece passes its seam by 0.5 mm on the far side of its travel
        let first = &c.pieces[0].1;
        assert!((first[1].x - 60.5).abs() < 1e-9);
        let kept = cut(
            SeamForm::Overlap {
                overlap_mm: 0.5,
                doubled: false,
            },
            &ls,
            &t,
        );
        assert_eq!(kept.stats.extra_marked_mm, 0.0);
        assert_eq!(cuts_of(&kept, 0), vec![60.5, 120.5]);
        assert_eq!(cuts_of(&kept, 1), vec![59.5, 119.5]);
    }

    #[test]
    fn closed_ring_stays_whole_without_a_seam_and_joins_around_its_start() {
        let ring = vec![
            Pt::new(0.0, 0.0),
            Pt::new(100.0, 0.0),
            Pt::new(100.0, 30.0),
            Pt::new(0.0, 30.0),
        ];
        let none = tiling_x(&[]);
        let c = cut_at_seams(&[(&ring, true)], &none, SeamForm::Straight, |_| true);
        assert_eq!(c.pieces, vec![(0, ring.clone(), true)]);
        let t = tiling_x(&[50.0]);
        let c = cut_at_seams(&[(&ring, true)], &t, SeamForm::Straight, |_| true);
        assert_eq!(c.pieces.len(), 2, "{:?}", c.pieces);
        let total: f64 = c.pieces.iter().map(|p| polyline_length(&p.1, false)).sum();
        assert!((total - 260.0).abs() < 1e-9);
        assert!(c.pieces.iter().all(|p| !p.2));
    }

    #[test]
    fn specs_round_trip() {
        for s in [
            "straight",
            "overlap:0.3",
            "overlap:0.3:doubled",
            "interlocked:0.5",
            "staggered:0.5:9",
        ] {
            let f = SeamForm::parse(s).unwrap();
            assert_eq!(SeamForm::parse(&f.to_string()).unwrap(), f);
        }
        let says = |spec: &str| SeamForm::parse(spec).unwrap_err().to_string();
        assert_eq!(says("overlap"), "seam 'overlap': overlap missing (mm)");
        assert_eq!(
            says("interlocked:-1"),
            "seam 'interlocked:-1': band must be above 0 and at most 10 mm"
        );
        assert_eq!(
            says("interlocked:x"),
            "seam 'interlocked:x': band 'x' is not a number"
        );
        assert_eq!(
            says("straight:1:2"),
            "seam 'straight:1:2': unexpected '1:2'"
        );
        assert_eq!(
            says("overlap:1:twice"),
            "seam 'overlap:1:twice': 'twice' is neither 'kept' nor 'doubled'"
        );
        assert_eq!(
            says("staggered:1:-3"),
            "seam 'staggered:1:-3': seed '-3' is not a whole number"
        );
        assert_eq!(
            says("comb:1"),
            "seam 'comb': expected straight, overlap:D[:doubled], interlocked:BAND or \
             staggered:BAND[:SEED]"
        );
    }
}
