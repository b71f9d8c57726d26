//! Nested strokes on the fly: a group of closed strokes one inside the next (a cell of
//! concentric rings) is marked with the widest in the middle.
//!
//! Marking a stroke on the fly needs the stage within the scanner's reach of all of it: the
//! wider the stroke, the smaller that window. Where the windows of a group are nested and
//! small (the group at least as wide as the reach), the stage stops and goes from group to
//! group, and the group's order decides how much marking overlaps the stage's arrival and
//! departure. The widest stroke goes where the stage stands nearest the middle; the roomiest
//! last, while it leaves (it may go farthest); the next roomiest first, while it arrives.
//! The caller lowers the result beside the ordering it came from and keeps the faster job.

use super::Ordering;
use crate::document::{Geometry, Step};
use crate::geom::BBox;

/// Least share of a job's strokes in tight nested groups for [`nested_centred`] to apply.
const NESTED_SHARE: f64 = 0.5;

/// Slack when testing one stroke's box for lying inside another's, mm.
const NESTED_SLACK_MM: f64 = 1e-6;

/// `ordering` with each group of nested strokes (consecutive closed strokes of one field whose
/// boxes lie one inside the next: a cell of concentric rings, a letter's contours) rearranged for
/// the stage on the fly: the stroke that reaches farthest from the group's middle, which needs
/// the stage nearest it, is marked in the middle of the group; the one with the most room
/// last, while the stage leaves; the next most roomy first, while it arrives; the rest
/// alternately towards the middle. Only where such groups, each at least as wide as the
/// scanner's reach (`reach_mm`: its stage window is then at most the reach), hold at least
/// [`NESTED_SHARE`] of the strokes: the stage stops and goes from group to group there, and the
/// order of a group says how much of its marking can overlap the stops (texture.toml: 327.1 →
/// 310.6 s; with 10 mm fields, where the stage need not stop, it was slower). `None` when it
/// does not apply or changes nothing.
pub(super) fn nested_centred(
    ordering: &Ordering,
    geometries: &[Geometry],
    reach_mm: f64,
) -> Option<Ordering> {
    let steps = &ordering.steps;
    let boxes: Vec<BBox> = steps
        .iter()
        .map(|s| geometries[s.geometry].bbox())
        .collect();
    let width = |b: &BBox| (b.max_x - b.min_x).max(b.max_y - b.min_y);
    let groups: Vec<std::ops::Range<usize>> = std::iter::successors(Some(0..0), |r| {
        (r.end < steps.len()).then(|| r.end..nested_group_end(steps, geometries, &boxes, r.end))
    })
    .skip(1)
    .collect();
    let tight: usize = groups
        .iter()
        .filter(|r| {
            r.len() > 1 && boxes[r.start..r.end].iter().map(width).fold(0.0, f64::max) >= reach_mm
        })
        .map(|r| r.len())
        .sum();
    if (tight as f64) < NESTED_SHARE * steps.len() as f64 {
        return None;
    }
    let mut out = Vec::with_capacity(steps.len());
    for r in groups {
        let first = r.start;
        let size = |i: usize| width(&boxes[first + i]);
        let group = &steps[r];
        // roomiest first: by box size, then as they came
        let mut by_room: Vec<usize> = (0..group.len()).collect();
        by_room.sort_by(|&a, &b| size(a).total_cmp(&size(b)).then(a.cmp(&b)));
        let mut placed = vec![0usize; group.len()];
        let (mut front, mut back) = (0, group.len());
        for (i, &r) in by_room.iter().enumerate() {
            if i % 2 == 0 {
                back -= 1;
                placed[back] = r;
            } else {
                placed[front] = r;
                front += 1;
            }
        }
        out.extend(placed.iter().map(|&i| group[i]));
    }
    (out != *steps).then(|| Ordering {
        field_order: ordering.field_order.clone(),
        steps: out,
    })
}

/// The end of the group of nested steps that starts at `start`: consecutive closed strokes of
/// one field whose boxes, taken by size, each lie inside the next (open strokes, such as the
/// pieces of a geometry cut at field borders, nest by their boxes only by chance).
fn nested_group_end(
    steps: &[Step],
    geometries: &[Geometry],
    boxes: &[BBox],
    start: usize,
) -> usize {
    if !geometries[steps[start].geometry].closed {
        return start + 1;
    }
    let inside = |a: &BBox, b: &BBox| {
        a.min_x >= b.min_x - NESTED_SLACK_MM
            && a.min_y >= b.min_y - NESTED_SLACK_MM
            && a.max_x <= b.max_x + NESTED_SLACK_MM
            && a.max_y <= b.max_y + NESTED_SLACK_MM
    };
    let mut end = start + 1;
    while end < steps.len()
        && steps[end].field == steps[start].field
        && geometries[steps[end].geometry].closed
    {
        let b = &boxes[end];
        // nested with every member so far: inside each or containing each
        let nests = boxes[start..end]
            .iter()
            .all(|a| inside(a, b) || inside(b, a));
        if !nests {
            break;
        }
        end += 1;
    }
    end
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::Source;
    use crate::document::Step;
    use crate::geom::Pt;

    /// A square of half-side `h` about `(x, y)`, closed or open.
    fn square(x: f64, y: f64, h: f64, closed: bool) -> Geometry {
        let pts = vec![
            Pt::new(x - h, y - h),
            Pt::new(x + h, y - h),
            Pt::new(x + h, y + h),
            Pt::new(x - h, y + h),
        ];
        Geometry::new(pts, closed, Source::default())
    }

    fn ordering(fields: &[usize]) -> Ordering {
        Ordering {
            field_order: Vec::new(),
            steps: fields
                .iter()
                .enumerate()
                .map(|(g, &field)| Step {
                    geometry: g,
                    field,
                    start_vertex: 0,
                    reversed: false,
                })
                .collect(),
        }
    }

    #[test]
    fn nested_strokes_put_the_widest_in_the_middle() {
        // two cells of four squares, widest first as a distance ordering may give them
        let mut g = Vec::new();
        for x in [10.0, 20.0] {
            for h in [2.0, 1.5, 1.0, 0.5] {
                g.push(square(x, 10.0, h, true));
            }
        }
        let o = ordering(&[0, 0, 0, 0, 1, 1, 1, 1]);
        let c = nested_centred(&o, &g, 2.0).expect("tight nested groups");
        let halves: Vec<f64> = c
            .steps
            .iter()
            .map(|s| (g[s.geometry].bbox().max_x - g[s.geometry].bbox().min_x) / 2.0)
            .collect();
        // roomiest last, next roomiest first, the widest in the middle
        assert_eq!(halves, vec![1.0, 2.0, 1.5, 0.5, 1.0, 2.0, 1.5, 0.5]);
        assert_eq!(c.field_order, o.field_order);
    }

    #[test]
    fn loose_open_or_unnested_strokes_keep_their_order() {
        let nested: Vec<Geometry> = [2.0, 1.0].map(|h| square(10.0, 10.0, h, true)).into();
        let o = ordering(&[0, 0]);
        // groups narrower than the reach: the stage need not stop for them
        assert!(nested_centred(&o, &nested, 4.5).is_none());
        // open strokes nest by their boxes only by chance
        let open: Vec<Geometry> = [2.0, 1.0].map(|h| square(10.0, 10.0, h, false)).into();
        assert!(nested_centred(&o, &open, 2.0).is_none());
        // side by side, not nested
        let apart = vec![square(10.0, 10.0, 2.0, true), square(20.0, 10.0, 2.0, true)];
        assert!(nested_centred(&o, &apart, 2.0).is_none());
        // in two fields: two groups of one
        assert!(nested_centred(&ordering(&[0, 1]), &nested, 2.0).is_none());
    }
}
