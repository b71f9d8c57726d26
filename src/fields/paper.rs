//! `--fields paper`: seed 000 §3.1, step by step, seeded.
//!
//! 1. 256 random fields with centres in the base stroke.
//! 2. Coverage check, else step 1 again (after 100 failed draws, a random field inside the
//!    feasible rectangle of each still uncovered geometry is added instead of drawing forever —
//!    a bounded stand-in for "repeat").
//! 3. Removal test of each field.
//! 4. Unit moves (8 directions) of each field that reduce the area covered by all fields, then 3.
//! 5. Unit moves that reduce the overlap of the field with the others, then step 3.
//! 6. Unit moves that bring the field's centre towards the centre of its geometries.
//!
//! Every move keeps all geometries covered. Allocation follows in [`super::allocate`].

use super::{center_range, FieldError, INSIDE_EPS_MM};
use crate::document::{Geometry, MachineProfile, ScanField};
use crate::geom::{BBox, Pt};
use crate::job::JobCtx;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Number of random fields of step 1.
pub const INITIAL_FIELDS: usize = 256;
/// Displacement of one move, mm.
pub const UNIT_MM: f64 = 1.0;
const DIRS: [(f64, f64); 8] = [
    (1.0, 0.0),
    (-1.0, 0.0),
    (0.0, 1.0),
    (0.0, -1.0),
    (1.0, 1.0),
    (1.0, -1.0),
    (-1.0, 1.0),
    (-1.0, -1.0),
];

struct State<'a> {
    boxes: Vec<BBox>,
    profile: &'a MachineProfile,
    centers: Vec<Pt>,
    holds: Vec<Vec<usize>>,
    count: Vec<u32>,
}

impl State<'_> {
    fn field_box(&self, c: Pt) -> BBox {
        BBox::centered(c, self.profile.field_mm[0], self.profile.field_mm[1])
    }
    fn held_at(&self, c: Pt) -> Vec<usize> {
        let fb = self.field_box(c);
        (0..self.boxes.len())
            .filter(|&g| fb.contains_box(&self.boxes[g], INSIDE_EPS_MM))
            .collect()
    }
    fn add(&mut self, c: Pt) {
        let h = self.held_at(c);
        for &g in &h {
            self.count[g] += 1;
        }
        self.centers.push(c);
        self.holds.push(h);
    }
    fn remove(&mut self, f: usize) {
        for &g in &self.holds[f] {
            self.count[g] -= 1;
        }
        self.centers.remove(f);
        self.holds.remove(f);
    }
    fn uncovered(&self) -> Vec<usize> {
        (0..self.boxes.len())
            .filter(|&g| self.count[g] == 0)
            .collect()
    }
    /// Step 3: remove every field whose geometries are all held by another field too.
    fn reduce(&mut self) {
        let mut f = 0;
        while f < self.centers.len() {
            if self.holds[f].iter().all(|&g| self.count[g] >= 2) {
                self.remove(f);
            } else {
                f += 1;
            }
        }
    }
    /// Moving field `f` to `c` keeps every geometry covered (and the centre in the stroke).
    fn can_move(&self, f: usize, c: Pt) -> bool {
        let [sw, sh] = self.profile.stroke_mm;
        if c.x < 0.0 || c.y < 0.0 || c.x > sw || c.y > sh {
            return false;
        }
        let fb = self.field_box(c);
        self.holds[f]
            .iter()
            .all(|&g| self.count[g] >= 2 || fb.contains_box(&self.boxes[g], INSIDE_EPS_MM))
    }
    fn move_to(&mut self, f: usize, c: Pt) {
        for &g in &self.holds[f] {
            self.count[g] -= 1;
        }
        let h = self.held_at(c);
        for &g in &h {
            self.count[g] += 1;
        }
        self.centers[f] = c;
        self.holds[f] = h;
    }
    /// Area of field `f` at `c` that the other fields cover too, mm².
    fn shared_area(&self, f: usize, c: Pt) -> f64 {
        let fb = self.field_box(c);
        let clipped: Vec<BBox> = self
            .centers
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != f)
            .map(|(_, &o)| {
                let ob = self.field_box(o);
                BBox {
                    min_x: ob.min_x.max(fb.min_x),
                    min_y: ob.min_y.max(fb.min_y),
                    max_x: ob.max_x.min(fb.max_x),
                    max_y: ob.max_y.min(fb.max_y),
                }
            })
            .filter(|b| b.width() > 0.0 && b.height() > 0.0)
            .collect();
        union_area(&clipped)
    }
    /// Hill-climbs every field with unit moves minimising `cost(state, field, centre)`.
    fn climb(
        &mut self,
        ctx: &JobCtx,
        cost: &dyn Fn(&State, usize, Pt) -> f64,
    ) -> Result<(), FieldError> {
        for f in 0..self.centers.len() {
            ctx.check()?;
            for _ in 0..10_000 {
                let here = cost(self, f, self.centers[f]);
                let mut best = (here - 1e-9, None);
                for (dx, dy) in DIRS {
                    let c = Pt::new(
                        self.centers[f].x + dx * UNIT_MM,
                        self.centers[f].y + dy * UNIT_MM,
                    );
                    if self.can_move(f, c) {
                        let v = cost(self, f, c);
                        if v < best.0 {
                            best = (v, Some(c));
                        }
                    }
                }
                match best.1 {
                    Some(c) => self.move_to(f, c),
                    None => break,
                }
            }
        }
        Ok(())
    }
}

/// Area of the union of boxes, mm² (coordinate compression; for the handful of boxes around one field).
fn union_area(boxes: &[BBox]) -> f64 {
    if boxes.is_empty() {
        return 0.0;
    }
    let mut xs: Vec<f64> = boxes.iter().flat_map(|b| [b.min_x, b.max_x]).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let mut area = 0.0;
    for w in xs.windows(2) {
        let xm = (w[0] + w[1]) / 2.0;
        let mut iv: Vec<(f64, f64)> = boxes
            .iter()
            .filter(|b| b.min_x <= xm && xm <= b.max_x)
            .map(|b| (b.min_y, b.max_y))
            .collect();
        iv.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut len = 0.0;
        let mut cur: Option<(f64, f64)> = None;
        for (lo, hi) in iv {
            match cur {
                Some((cl, ch)) if lo <= ch => cur = Some((cl, ch.max(hi))),
                Some((cl, ch)) => {
                    len += ch - cl;
                    cur = Some((lo, hi));
                }
                None => cur = Some((lo, hi)),
            }
        }
        if let Some((cl, ch)) = cur {
            len += ch - cl;
        }
        area += len * (w[1] - w[0]);
    }
    area
}

/// Seed 000's field placement for the geometries in `subset`; ids start at `first_id`.
pub fn paper_fields(
    geometries: &[Geometry],
    subset: &[usize],
    profile: &MachineProfile,
    seed: u64,
    first_id: usize,
    ctx: &JobCtx,
) -> Result<Vec<ScanField>, FieldError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let boxes: Vec<BBox> = subset.iter().map(|&g| geometries[g].bbox()).collect();
    let n = boxes.len();
    let [sw, sh] = profile.stroke_mm;
    let mut st = State {
        boxes,
        profile,
        centers: Vec::new(),
        holds: Vec::new(),
        count: vec![0; n],
    };
    // steps 1 and 2
    for attempt in 0..100 {
        ctx.check()?;
        ctx.progress(
            "fields",
            1,
            6,
            format!("paper: random fields, draw {}", attempt + 1),
        );
        st.centers.clear();
        st.holds.clear();
        st.count = vec![0; n];
        for _ in 0..INITIAL_FIELDS {
            let c = Pt::new(rng.random_range(0.0..=sw), rng.random_range(0.0..=sh));
            st.add(c);
        }
        if st.uncovered().is_empty() {
            break;
        }
    }
    for g in st.uncovered() {
        if st.count[g] > 0 {
            continue;
        }
        let (xs, ys) = center_range(&st.boxes[g], profile);
        let mut draw = |lo: f64, hi: f64| {
            if lo < hi {
                rng.random_range(lo..=hi)
            } else {
                lo
            }
        };
        let c = Pt::new(draw(xs.lo, xs.hi), draw(ys.lo, ys.hi));
        st.add(c);
    }
    // step 3
    ctx.progress("fields", 2, 6, "paper: removal test");
    st.reduce();
    // step 4: reduce the area covered by all fields (= maximise the area shared with the others)
    ctx.progress("fields", 3, 6, "paper: reduce covered area");
    st.climb(ctx, &|s, f, c| -s.shared_area(f, c))?;
    st.reduce();
    // step 5: reduce overlap
    ctx.progress("fields", 4, 6, "paper: reduce overlap");
    st.climb(ctx, &|s, f, c| s.shared_area(f, c))?;
    st.reduce();
    // step 6: centre the geometries of each field (those it would be allocated: nearest centre)
    ctx.progress("fields", 5, 6, "paper: centre fields");
    let targets: Vec<Pt> = {
        let mut own: Vec<BBox> = vec![BBox::EMPTY; st.centers.len()];
        for g in 0..n {
            let c = st.boxes[g].center();
            let best = (0..st.centers.len())
                .filter(|&f| st.holds[f].contains(&g))
                .min_by(|&a, &b| c.dist2(st.centers[a]).total_cmp(&c.dist2(st.centers[b])));
            if let Some(f) = best {
                own[f] = own[f].union(st.boxes[g]);
            }
        }
        own.iter()
            .zip(&st.centers)
            .map(|(b, &c)| if b.is_empty() { c } else { b.center() })
            .collect()
    };
    st.climb(ctx, &|_, f, c| c.dist(targets[f]))?;
    st.reduce();
    ctx.progress("fields", 6, 6, "paper: done");
    Ok(st
        .centers
        .iter()
        .enumerate()
        .map(|(k, &c)| ScanField {
            id: first_id + k,
            center: c,
            size: profile.field_mm,
            locked: false,
            geometries: Vec::new(),
            pose: Default::default(),
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_area_of_overlapping_boxes() {
        let b = |x0: f64, y0: f64, x1: f64, y1: f64| BBox {
            min_x: x0,
            min_y: y0,
            max_x: x1,
            max_y: y1,
        };
        let a = union_area(&[b(0.0, 0.0, 2.0, 2.0), b(1.0, 1.0, 3.0, 3.0)]);
        assert!((a - 7.0).abs() < 1e-12);
    }
}
