//! Zigzag linking: chords of consecutive lines joined along the boundary into polylines.
//!
//! A chord end on line `j` can be joined to a chord end on line `j + 1` when walking the boundary
//! from it into the band between the two lines reaches the other end before any other crossing of
//! the same family: the join then is a boundary piece inside that band, so it stays in the
//! region and the laser stays on. Lines are swept in order; every open polyline tries to continue
//! from its free end to the next line, chords nobody reaches start new polylines. Each polyline
//! is one part the laser sweeps without lifting; all of them run towards larger `v`.
//!
//! Where a walk is not free (a join of another family already marks that boundary piece), the
//! part ends and the chord it would have reached starts a new part of the same *sweep*, entered
//! at that end: parts of one sweep follow one another line by line, back and forth, one
//! boundary piece apart, so they are marked as one run (`document::RunOrder::Sweep`) with a
//! jump where the join would have been.

use super::boundary::Boundary;
use super::scan::{Chord, Scan};
use crate::geom::Pt;

/// A polyline of chords and joins.
#[derive(Debug, Clone)]
pub(crate) struct Part {
    /// Points in marking order.
    pub points: Vec<Pt>,
    /// Its sweep (numbered from 0 in order of first part); see the module doc.
    pub sweep: u32,
}

fn push(points: &mut Vec<Pt>, p: Pt) {
    if points.last().is_none_or(|q| q.dist2(p) > 1e-24) {
        points.push(p);
    }
}

/// Links the chords of `scan` (family `family` of `boundary`) into zigzag parts.
pub(crate) fn link(scan: &Scan, family: usize, boundary: &mut Boundary) -> Vec<Part> {
    let n_lines = scan.lines.len();
    // crossing → (chord index on its line, the other end)
    let mut chord_of = vec![(0u32, 0u32); scan.crossings.len()];
    for line in &scan.lines {
        for (ci, c) in line.iter().enumerate() {
            chord_of[c.lo as usize] = (ci as u32, c.hi);
            chord_of[c.hi as usize] = (ci as u32, c.lo);
        }
    }
    let mut taken: Vec<Vec<bool>> = scan.lines.iter().map(|l| vec![false; l.len()]).collect();
    let mut parts: Vec<Part> = Vec::new();
    // (part, crossing where the part left its last chord)
    let mut active: Vec<(usize, u32)> = Vec::new();
    // The chord end reached from `x` by walking the boundary into the next band, if that is an
    // untaken chord on the next line and the walk is free.
    // With `free`, the walk must also be free; without, the chord end is only adjacent.
    let reach = |x: u32, boundary: &Boundary, taken: &[Vec<bool>], free: bool| -> Option<u32> {
        let cx = scan.crossings[x as usize];
        let p = boundary.pos(family, x);
        let q = boundary.neighbour(p, cx.forward_down);
        let y = boundary.cross_at(q);
        let cy = scan.crossings[y as usize];
        let ok = cy.line == cx.line + 1
            && !taken[cy.line as usize][chord_of[y as usize].0 as usize]
            && (!free || boundary.is_free(p, q, cx.forward_down));
        ok.then_some(y)
    };
    let step = |x: u32, boundary: &Boundary, taken: &[Vec<bool>]| reach(x, boundary, taken, true);
    let mut sweeps = 0u32;
    for j in 0..n_lines {
        let mut next_active = Vec::new();
        // the sweep a chord of this line continues, when a part could not join it
        let mut inherit: Vec<Option<(u32, u32)>> = vec![None; scan.lines[j].len()];
        for &(part, exit) in &active {
            let Some(y) = step(exit, boundary, &taken) else {
                if let Some(y) = reach(exit, boundary, &taken, false) {
                    let ci = chord_of[y as usize].0 as usize;
                    inherit[ci].get_or_insert((parts[part].sweep, y));
                }
                continue;
            };
            let cx = scan.crossings[exit as usize];
            let (p, q) = (boundary.pos(family, exit), boundary.pos(family, y));
            boundary.take(p, q, cx.forward_down, &mut parts[part].points);
            let (ci, other) = chord_of[y as usize];
            taken[j][ci as usize] = true;
            push(&mut parts[part].points, scan.crossings[other as usize].pt);
            next_active.push((part, other));
        }
        for (ci, &Chord { lo, hi }) in scan.lines[j].iter().enumerate() {
            if taken[j][ci] {
                continue;
            }
            taken[j][ci] = true;
            // a sweep's chord enters at the end next to the last one (so the sweep goes back
            // and forth); a new part leaves through the end that can continue to the next
            // line, if either can
            let exit = match inherit[ci] {
                Some((_, y)) => {
                    if y == hi {
                        lo
                    } else {
                        hi
                    }
                }
                None if step(hi, boundary, &taken).is_some()
                    || step(lo, boundary, &taken).is_none() =>
                {
                    hi
                }
                None => lo,
            };
            let entry = if exit == hi { lo } else { hi };
            let mut points = vec![scan.crossings[entry as usize].pt];
            push(&mut points, scan.crossings[exit as usize].pt);
            next_active.push((parts.len(), exit));
            let sweep = inherit[ci].map_or_else(
                || {
                    sweeps += 1;
                    sweeps - 1
                },
                |(sweep, _)| sweep,
            );
            parts.push(Part { points, sweep });
        }
        active = next_active;
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::super::scan::scan;
    use super::*;
    use crate::geom::polyline_length;

    #[test]
    fn convex_region_is_one_part() {
        let loops = vec![vec![
            Pt::new(0.0, 0.0),
            Pt::new(10.0, 0.0),
            Pt::new(10.0, 10.0),
            Pt::new(0.0, 10.0),
        ]];
        let s = scan(&loops, 0.0, 1.0, 100).unwrap();
        let mut b = Boundary::new(&loops, &[&s]);
        let parts = link(&s, 0, &mut b);
        assert_eq!(parts.len(), 1);
        // 10 chords of 10 mm and 9 joins of 1 mm
        assert!((polyline_length(&parts[0].points, false) - 109.0).abs() < 1e-9);
        // the rest of the boundary: 40 − 9
        let rest: f64 = b.unused().iter().map(|(p, c)| polyline_length(p, *c)).sum();
        assert!((rest - 31.0).abs() < 1e-9, "{rest}");
    }

    #[test]
    fn u_shape_splits_into_sweepable_parts() {
        // a U: two prongs going up (towards smaller y) from a base
        let loops = vec![vec![
            Pt::new(0.0, 0.0),
            Pt::new(3.0, 0.0),
            Pt::new(3.0, 7.0),
            Pt::new(7.0, 7.0),
            Pt::new(7.0, 0.0),
            Pt::new(10.0, 0.0),
            Pt::new(10.0, 10.0),
            Pt::new(0.0, 10.0),
        ]];
        let s = scan(&loops, 0.0, 1.0, 100).unwrap();
        let mut b = Boundary::new(&loops, &[&s]);
        let parts = link(&s, 0, &mut b);
        // prongs then base: at least 2 parts, at most 3; every chord used exactly once
        assert!((2..=3).contains(&parts.len()), "{}", parts.len());
        let chords: f64 = s
            .lines
            .iter()
            .flatten()
            .map(|c| {
                let (a, q) = s.ends(*c);
                a.dist(q)
            })
            .sum();
        let in_parts: f64 = parts
            .iter()
            .flat_map(|p| p.points.windows(2))
            .filter(|w| (w[0].y - w[1].y).abs() < 1e-12)
            .map(|w| w[0].dist(w[1]))
            .sum();
        assert!((chords - in_parts).abs() < 1e-9, "{chords} vs {in_parts}");
        let rest: f64 = b.unused().iter().map(|(p, c)| polyline_length(p, *c)).sum();
        let joins: f64 = parts
            .iter()
            .map(|p| polyline_length(&p.points, false))
            .sum::<f64>()
            - in_parts;
        assert!((rest + joins - 54.0).abs() < 1e-9, "{rest} + {joins}");
    }
}
