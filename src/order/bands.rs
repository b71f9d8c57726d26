//! On the fly: a sweep of field-wide bands. The work is cut into horizontal bands one field
//! high; the bands are marked top to bottom, left to right and right to left in turn
//! (boustrophedon), each geometry from the vertex nearest to where the tool is. A stage that
//! follows such a sweep moves smoothly along long straight rows with one reversal per band,
//! where a field-by-field ordering turns at every few fields. [`super::order_plan`] lowers
//! both and keeps the faster.

use super::{OrderError, Ordering};
use crate::document::{Geometry, ScanField, Step};
use crate::geom::{BBox, Pt};
use crate::job::JobCtx;

/// The band sweep of the allocated geometries, bands `band_mm` high (see the module
/// documentation). Steps keep the field each geometry is allocated to.
pub fn band_order(
    geometries: &[Geometry],
    fields: &[ScanField],
    band_mm: f64,
    ctx: &JobCtx,
) -> Result<Ordering, OrderError> {
    ctx.check()?;
    let mut members: Vec<(usize, usize)> = fields
        .iter()
        .flat_map(|f| f.geometries.iter().map(move |&g| (g, f.id)))
        .collect();
    let top_mm = members
        .iter()
        .fold(BBox::EMPTY, |b, &(g, _)| b.union(geometries[g].bbox()))
        .min_y;
    let key = |g: usize| {
        let c = geometries[g].centroid();
        let band = ((c.y - top_mm) / band_mm).floor().max(0.0) as i64;
        let across = if band % 2 == 0 { c.x } else { -c.x };
        (band, across)
    };
    members.sort_by(|a, b| {
        let (ka, kb) = (key(a.0), key(b.0));
        ka.0.cmp(&kb.0)
            .then(ka.1.total_cmp(&kb.1))
            .then(a.0.cmp(&b.0))
    });
    let mut out = Ordering::default();
    let mut at: Option<Pt> = None;
    for (g, field) in members {
        let geometry = &geometries[g];
        let step = Step::from_choice(g, field, geometry, nearest_start(geometry, at));
        at = geometry
            .marking_path(step.start_vertex, step.reversed)
            .last()
            .copied();
        if !out.field_order.contains(&field) {
            out.field_order.push(field);
        }
        out.steps.push(step);
    }
    Ok(out)
}

/// The start choice of `g` nearest to `at` (a closed geometry's vertex, an open one's end;
/// the first without a position).
fn nearest_start(g: &Geometry, at: Option<Pt>) -> usize {
    let (Some(at), Some(&last)) = (at, g.points.last()) else {
        return 0;
    };
    if !g.closed {
        return usize::from(last.dist(at) < g.points[0].dist(at));
    }
    g.points
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.dist(at).total_cmp(&b.1.dist(at)))
        .map_or(0, |(k, _)| k)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::Source;

    fn square(x: f64, y: f64) -> Geometry {
        let pts = vec![
            Pt::new(x, y),
            Pt::new(x + 1.0, y),
            Pt::new(x + 1.0, y + 1.0),
            Pt::new(x, y + 1.0),
        ];
        Geometry::new(pts, true, Source::default())
    }

    #[test]
    fn bands_sweep_back_and_forth() {
        // two rows 20 mm apart, three squares each, in scrambled document order
        let spots = [
            (50.0, 30.0),
            (10.0, 10.0),
            (90.0, 30.0),
            (50.0, 10.0),
            (10.0, 30.0),
            (90.0, 10.0),
        ];
        let geometries: Vec<Geometry> = spots.iter().map(|&(x, y)| square(x, y)).collect();
        let field = ScanField {
            id: 3,
            center: Pt::new(50.0, 20.0),
            size: [100.0, 100.0],
            locked: false,
            geometries: (0..6).collect(),
            pose: Default::default(),
        };
        let o = band_order(&geometries, &[field], 15.0, &JobCtx::default()).unwrap();
        let order: Vec<usize> = o.steps.iter().map(|s| s.geometry).collect();
        // first band left to right, second right to left
        assert_eq!(order, vec![1, 3, 5, 2, 0, 4]);
        assert_eq!(o.field_order, vec![3]);
        assert!(o.steps.iter().all(|s| s.field == 3));
        // the second square starts at its vertex nearest the first one's end
        assert_eq!(o.steps[1].start_vertex, 0);
        // in the right-to-left band the squares start on their right side
        assert!(geometries[0].points[o.steps[4].start_vertex].x > 50.5);
    }
}
