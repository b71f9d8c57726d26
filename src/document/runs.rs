//! Runs as planning nodes: strokes whose marking order a fill already fixes
//! ([`Run`], e.g. the border pieces of a hatch loop) are one node each to the field and order
//! stages, and the nodes' fields and steps are expanded back to strokes for lowering, metrics
//! and export.
//!
//! A dense fill makes thousands of tiny strokes per shape (a 12 mm disc hatched `cross` at
//! 0.01 mm leaves about 2,400 border pieces between the lines' joins), which the stages would
//! otherwise place and order one by one. Their order is not in question: round their loop.
//!
//! A *chunk* is a maximal stretch of consecutive members of one run that the caller keeps
//! together (within one field, or small enough for one). Its node is a proxy geometry:
//! - **closed** when the chunk is a whole loop (its last member ends about as near its first
//!   as members are to each other): its vertices are the starts of up to [`ENTRIES_MAX`]
//!   members, evenly spread, plus the members' extreme points; starting at a vertex marks
//!   the members round from the member that vertex leads into. Vertex choices are capped
//!   because the exact vertex choice is quadratic in choices per neighbouring pair.
//! - **open** otherwise: from the first member's start through the extreme points to the last
//!   member's end. Forwards marks the members in order: a loop's pieces each its own way; a
//!   sweep's parts each from the end nearer the last one's end (the first towards the second),
//!   so back and forth. Backwards is exactly that path reversed.
//!
//! The proxy's bounding box is the chunk's own (its extreme points are vertices), so a field
//! that holds the proxy holds every member. Its length and marking time are not the chunk's:
//! a stage that ranks candidates on them (a step-and-scan field's marking time is the same in
//! any order) sees a constant per chunk; every plan is lowered and judged on its strokes.

use crate::document::{Geometry, Run, RunOrder, ScanField, Step};
use crate::geom::{BBox, Pt};

/// Most start vertices of a closed proxy (besides its extreme points).
pub const ENTRIES_MAX: usize = 32;

/// A loop's chunk is closed when its last member ends within this many times the widest gap
/// between consecutive members of its first member's start.
const CLOSE_GAP_FACTOR: f64 = 2.0;

/// Where a node's strokes come from.
#[derive(Debug, Clone)]
enum Node {
    /// A geometry on its own.
    Loose(usize),
    /// Members `first..end` of a run.
    Chunk {
        first: usize,
        end: usize,
        /// Swept back and forth (every other member reversed).
        sweep: bool,
        /// Closed proxy: per proxy vertex, the member (offset from `first`) it starts at.
        entries: Option<Vec<u32>>,
    },
}

/// The nodes of a geometry list: loose geometries and chunks of runs (see the module doc).
#[derive(Debug, Clone)]
pub struct Contraction {
    nodes: Vec<Geometry>,
    kinds: Vec<Node>,
    /// Per geometry, its node.
    node_of: Vec<u32>,
}

/// The key consecutive members of one run share.
fn run_key(g: &Geometry) -> Option<(Run, &str, &str, u32)> {
    g.run
        .map(|r| (r, g.source.element.as_str(), g.layer.as_str(), g.pass))
}

/// True when `next`, listed right after `prev`, is a member of the same run.
pub fn continues_run(prev: &Geometry, next: &Geometry) -> bool {
    next.run.is_some() && run_key(prev) == run_key(next)
}

impl Contraction {
    /// Chunks no wider or taller than `max_mm` (the field stage: a chunk must fit a field and
    /// leave the cover room to move). None when no chunk has two members.
    pub fn within(geometries: &[Geometry], max_mm: [f64; 2]) -> Option<Contraction> {
        let mut bbox = BBox::EMPTY;
        Self::build(geometries, |prev, next| {
            let b = geometries[next].bbox();
            let grown = if prev.is_none() { b } else { bbox.union(b) };
            let fits = grown.width() <= max_mm[0] && grown.height() <= max_mm[1];
            bbox = if fits && prev.is_some() { grown } else { b };
            fits && prev.is_some()
        })
    }

    /// Chunks within one field each (the order stage, on allocated fields). None when no chunk
    /// has two members.
    pub fn in_fields(geometries: &[Geometry], fields: &[ScanField]) -> Option<Contraction> {
        let mut field_of = vec![usize::MAX; geometries.len()];
        for f in fields {
            for &g in &f.geometries {
                if let Some(slot) = field_of.get_mut(g) {
                    *slot = f.id;
                }
            }
        }
        Self::build(geometries, |prev, next| {
            prev.is_some_and(|p| field_of[p] == field_of[next] && field_of[p] != usize::MAX)
        })
    }

    /// Nodes from chunks: `join(prev, next)` says whether geometry `next` joins the chunk whose
    /// last member is `prev` (called with `None` for the first geometry of a run, and for every
    /// run member in list order).
    fn build(
        geometries: &[Geometry],
        mut join: impl FnMut(Option<usize>, usize) -> bool,
    ) -> Option<Contraction> {
        let mut spans: Vec<(usize, usize)> = Vec::new();
        let mut i = 0;
        while i < geometries.len() {
            if geometries[i].run.is_none() {
                spans.push((i, i + 1));
                i += 1;
                continue;
            }
            join(None, i);
            let mut end = i + 1;
            while end < geometries.len()
                && continues_run(&geometries[end - 1], &geometries[end])
                && join(Some(end - 1), end)
            {
                end += 1;
            }
            spans.push((i, end));
            i = end;
        }
        if spans.iter().all(|&(a, b)| b - a < 2) {
            return None;
        }
        let mut c = Contraction {
            nodes: Vec::with_capacity(spans.len()),
            kinds: Vec::with_capacity(spans.len()),
            node_of: vec![0; geometries.len()],
        };
        for (a, b) in spans {
            let n = c.nodes.len() as u32;
            c.node_of[a..b].iter_mut().for_each(|v| *v = n);
            if b - a == 1 {
                c.nodes.push(geometries[a].clone());
                c.kinds.push(Node::Loose(a));
            } else {
                let (proxy, entries) = proxy(&geometries[a..b]);
                c.nodes.push(proxy);
                c.kinds.push(Node::Chunk {
                    first: a,
                    end: b,
                    sweep: is_sweep(&geometries[a]),
                    entries,
                });
            }
        }
        Some(c)
    }

    /// The nodes the stages see.
    pub fn nodes(&self) -> &[Geometry] {
        &self.nodes
    }

    /// One real geometry per node (a chunk's first member): pairwise-disjoint feasible regions
    /// among these prove a lower bound on fields for the real geometries.
    pub fn representatives(&self) -> Vec<usize> {
        self.kinds
            .iter()
            .map(|k| match *k {
                Node::Loose(g) => g,
                Node::Chunk { first, .. } => first,
            })
            .collect()
    }

    /// The geometries of node `n`.
    fn members(&self, n: usize) -> std::ops::Range<usize> {
        match self.kinds.get(n) {
            Some(&Node::Loose(g)) => g..g + 1,
            Some(&Node::Chunk { first, end, .. }) => first..end,
            None => 0..0,
        }
    }

    /// Fields over geometries as fields over nodes (a node goes where its first member is;
    /// [`Contraction::in_fields`] keeps every member of a node in one field).
    pub fn fields_to_nodes(&self, fields: &[ScanField]) -> Vec<ScanField> {
        fields
            .iter()
            .map(|f| ScanField {
                geometries: f
                    .geometries
                    .iter()
                    .filter(|&&g| self.members(self.node_of[g] as usize).start == g)
                    .map(|&g| self.node_of[g] as usize)
                    .collect(),
                ..f.clone()
            })
            .collect()
    }

    /// Fields over nodes as fields over geometries.
    pub fn fields_to_geometries(&self, fields: Vec<ScanField>) -> Vec<ScanField> {
        fields
            .into_iter()
            .map(|f| ScanField {
                geometries: f.geometries.iter().flat_map(|&n| self.members(n)).collect(),
                ..f
            })
            .collect()
    }

    /// Steps over nodes as steps over geometries: a chunk's members in its marking order.
    pub fn steps_to_geometries(&self, steps: &[Step], geometries: &[Geometry]) -> Vec<Step> {
        let mut out = Vec::with_capacity(geometries.len());
        for s in steps {
            match self.kinds.get(s.geometry) {
                None => {}
                Some(&Node::Loose(g)) => out.push(Step { geometry: g, ..*s }),
                Some(Node::Chunk {
                    first,
                    end,
                    entries: Some(entries),
                    ..
                }) => {
                    let m = end - first;
                    let e = entries.get(s.start_vertex).map_or(0, |&e| e as usize);
                    out.extend((0..m).map(|i| {
                        let g = first + (e + i) % m;
                        Step::from_choice(g, s.field, &geometries[g], 0)
                    }));
                }
                Some(&Node::Chunk {
                    first,
                    end,
                    sweep,
                    entries: None,
                }) => {
                    let members = &geometries[first..end];
                    let forwards = forward_choices(members, sweep);
                    let step = |k: usize, backwards: bool| {
                        let g = first + k;
                        let c = if backwards && !members[k].closed {
                            1 - forwards[k]
                        } else {
                            forwards[k]
                        };
                        Step::from_choice(g, s.field, &geometries[g], c)
                    };
                    if s.reversed {
                        out.extend((0..end - first).rev().map(|k| step(k, true)));
                    } else {
                        out.extend((0..end - first).map(|k| step(k, false)));
                    }
                }
            }
        }
        out
    }
}

/// The chunk's extreme points (least x, greatest x, least y, greatest y) as (member, vertex).
fn extremes(members: &[Geometry]) -> [(usize, usize); 4] {
    let mut best = [(0, 0); 4];
    let mut val = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for (k, g) in members.iter().enumerate() {
        for (j, p) in g.points.iter().enumerate() {
            let cand = [p.x, p.x, p.y, p.y];
            for e in 0..4 {
                let better = if e % 2 == 0 {
                    cand[e] < val[e]
                } else {
                    cand[e] > val[e]
                };
                if better {
                    val[e] = cand[e];
                    best[e] = (k, j);
                }
            }
        }
    }
    best
}

/// A member's first and last points (a closed member ends where it starts).
fn ends(g: &Geometry) -> (Pt, Pt) {
    g.ends(0)
}

/// True for a member of a sweep.
fn is_sweep(g: &Geometry) -> bool {
    g.run.is_some_and(|r| r.order == RunOrder::Sweep)
}

/// The start choices (0 or 1; 0 for a closed member) of an open chunk's members marked
/// forwards: a loop's pieces each its own way; a sweep's first part ends at whichever end is
/// nearer the second part, every later one starts at the end nearer the last one's end.
fn forward_choices(members: &[Geometry], sweep: bool) -> Vec<usize> {
    let mut out = vec![0; members.len()];
    if !sweep {
        return out;
    }
    let near = |p: Pt, g: &Geometry| (0..2).map(|c| g.ends(c).0.dist(p)).fold(f64::MAX, f64::min);
    let mut at: Option<Pt> = None;
    for (k, g) in members.iter().enumerate() {
        if g.closed {
            at = Some(g.ends(0).1);
            continue;
        }
        let cost = |c: usize| match at {
            Some(p) => g.ends(c).0.dist(p),
            None => members
                .get(k + 1)
                .map_or(0.0, |next| near(g.ends(c).1, next)),
        };
        let c = usize::from(cost(1) < cost(0));
        out[k] = c;
        at = Some(g.ends(c).1);
    }
    out
}

/// The proxy of a chunk (two members or more) and, when closed, each vertex's entry member.
fn proxy(members: &[Geometry]) -> (Geometry, Option<Vec<u32>>) {
    let m = members.len();
    let widest_gap = members
        .windows(2)
        .map(|w| ends(&w[0]).1.dist(ends(&w[1]).0))
        .fold(0.0, f64::max);
    let closing = ends(&members[m - 1]).1.dist(ends(&members[0]).0);
    let closed = m >= 3
        && members[0].run.is_some_and(|r| r.order == RunOrder::Loop)
        && closing <= CLOSE_GAP_FACTOR * widest_gap + 1e-9;
    let ext = extremes(members);
    // (member, vertex) in marking order: sampled member starts and the extremes
    let stride = m.div_ceil(ENTRIES_MAX).max(1);
    let mut marks: Vec<(usize, usize)> = (0..m).step_by(stride).map(|k| (k, 0)).collect();
    marks.extend(ext);
    marks.sort_unstable();
    marks.dedup();
    let mut points: Vec<Pt> = marks
        .iter()
        .map(|&(k, j)| members[k].points.get(j).copied().unwrap_or_default())
        .collect();
    if !closed {
        // the ends of the chunk marked forwards
        let forwards = forward_choices(members, is_sweep(&members[0]));
        let last = &members[m - 1];
        points.insert(0, members[0].ends(forwards[0]).0);
        points.push(last.ends(forwards[m - 1]).1);
    }
    let first = &members[0];
    let g = Geometry {
        points,
        closed,
        source: first.source.clone(),
        layer: first.layer.clone(),
        pass: first.pass,
        run: first.run,
    };
    // a vertex inside a member leads into the next member
    let entries = closed.then(|| {
        marks
            .iter()
            .map(|&(k, j)| if j == 0 { k } else { (k + 1) % m } as u32)
            .collect()
    });
    (g, entries)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::Source;

    /// `n` pieces round a circle of radius `r` at `c`, each a short arc (3 points), with gaps.
    fn ring(c: Pt, r: f64, n: usize, id: u32) -> Vec<Geometry> {
        (0..n)
            .map(|k| {
                let a = |t: f64| {
                    let t = (k as f64 + t) / n as f64 * std::f64::consts::TAU;
                    Pt::new(c.x + r * t.cos(), c.y + r * t.sin())
                };
                let source = Source {
                    element: "disc".into(),
                    subpath: k,
                    layer: "hatch:#000000".into(),
                    part: 0,
                };
                Geometry::new(vec![a(0.0), a(0.25), a(0.5)], false, source).with_run(Some(Run {
                    id,
                    order: RunOrder::Loop,
                }))
            })
            .collect()
    }

    fn loose(p: Pt) -> Geometry {
        Geometry::new(vec![p, p.plus(Pt::new(1.0, 0.0))], false, Source::default())
    }

    fn field(id: usize, geometries: Vec<usize>) -> ScanField {
        ScanField {
            id,
            center: Pt::default(),
            size: [70.0, 70.0],
            locked: false,
            geometries,
            pose: Default::default(),
        }
    }

    #[test]
    fn a_loop_is_one_closed_node_with_the_chunks_bbox() {
        let mut gs = vec![loose(Pt::new(0.0, 0.0))];
        gs.extend(ring(Pt::new(20.0, 20.0), 6.0, 100, 0));
        gs.push(loose(Pt::new(40.0, 0.0)));
        let c = Contraction::within(&gs, [35.0, 35.0]).expect("a run");
        assert_eq!(c.nodes().len(), 3);
        let proxy = &c.nodes()[1];
        assert!(proxy.closed);
        assert!(proxy.points.len() <= ENTRIES_MAX + 4);
        let real = gs[1..101]
            .iter()
            .fold(BBox::EMPTY, |b, g| b.union(g.bbox()));
        assert_eq!(proxy.bbox(), real);
        assert_eq!(c.representatives(), vec![0, 1, 101]);
    }

    #[test]
    fn every_start_vertex_expands_to_each_member_once_round_the_loop() {
        let gs = ring(Pt::new(0.0, 0.0), 5.0, 77, 3);
        let c = Contraction::within(&gs, [70.0, 70.0]).expect("a run");
        let proxy = &c.nodes()[0];
        for v in 0..proxy.points.len() {
            let s = Step::from_choice(0, 4, proxy, v);
            let out = c.steps_to_geometries(&[s], &gs);
            assert_eq!(out.len(), 77);
            let mut seen: Vec<usize> = out.iter().map(|s| s.geometry).collect();
            // consecutive members, wrapping once
            for w in seen.windows(2) {
                assert_eq!(w[1], (w[0] + 1) % 77);
            }
            // the first member starts at or just after the chosen vertex
            let start = gs[out[0].geometry].points[0];
            assert!(start.dist(proxy.points[v]) < 5.0 * std::f64::consts::TAU / 77.0 + 1e-9);
            seen.sort_unstable();
            assert_eq!(seen, (0..77).collect::<Vec<_>>());
            assert!(out.iter().all(|s| s.field == 4 && !s.reversed));
        }
    }

    #[test]
    fn an_open_chunk_runs_forwards_or_backwards_with_each_member_reversed() {
        // half a loop: its ends are far apart, so it is marked end to end
        let gs: Vec<Geometry> = ring(Pt::new(0.0, 0.0), 5.0, 40, 0)
            .into_iter()
            .take(20)
            .collect();
        let c = Contraction::within(&gs, [70.0, 70.0]).expect("a run");
        let proxy = &c.nodes()[0];
        assert!(!proxy.closed);
        assert_eq!(proxy.points[0], gs[0].points[0]);
        assert_eq!(proxy.points.last(), gs[19].points.last());
        let back = c.steps_to_geometries(&[Step::from_choice(0, 0, proxy, 1)], &gs);
        assert_eq!(back.first().map(|s| s.geometry), Some(19));
        assert!(back.iter().all(|s| s.reversed && s.start_vertex == 2));
        let fwd = c.steps_to_geometries(&[Step::from_choice(0, 0, proxy, 0)], &gs);
        assert_eq!(
            fwd.iter().map(|s| s.geometry).collect::<Vec<_>>(),
            (0..20).collect::<Vec<_>>()
        );
    }

    /// `n` horizontal chords 10 mm long, `s` apart, all running towards +x (as zigzag parts
    /// come), in one sweep.
    fn chords(n: usize, s: f64) -> Vec<Geometry> {
        (0..n)
            .map(|k| {
                let y = k as f64 * s;
                let y = (y * 1e6).round() / 1e6;
                let source = Source {
                    element: "disc".into(),
                    subpath: k,
                    layer: "hatch:#000000".into(),
                    part: 0,
                };
                Geometry::new(vec![Pt::new(0.0, y), Pt::new(10.0, y)], false, source).with_run(
                    Some(Run {
                        id: 1,
                        order: RunOrder::Sweep,
                    }),
                )
            })
            .collect()
    }

    #[test]
    fn a_sweep_goes_back_and_forth_from_either_end() {
        let gs = chords(7, 0.1);
        let c = Contraction::within(&gs, [35.0, 35.0]).expect("a run");
        let proxy = &c.nodes()[0];
        assert!(!proxy.closed);
        // forwards: from (0, 0) to the end of the 7th chord, marked forwards (even)
        assert_eq!(proxy.points[0], Pt::new(0.0, 0.0));
        assert_eq!(proxy.points.last(), Some(&Pt::new(10.0, 0.6)));
        let path = |steps: &[Step]| -> Vec<(Pt, Pt)> {
            steps
                .iter()
                .map(|s| gs[s.geometry].ends(s.choice(&gs[s.geometry])))
                .collect()
        };
        let fwd = path(&c.steps_to_geometries(&[Step::from_choice(0, 0, proxy, 0)], &gs));
        let back = path(&c.steps_to_geometries(&[Step::from_choice(0, 0, proxy, 1)], &gs));
        for marks in [&fwd, &back] {
            assert_eq!(marks.len(), 7);
            // each chord starts where the last one ended, one spacing away
            for w in marks.windows(2) {
                assert!((w[0].1.dist(w[1].0) - 0.1).abs() < 1e-9, "{w:?}");
            }
        }
        assert_eq!(fwd[0].0, Pt::new(0.0, 0.0));
        // backwards: enters where forwards leaves, leaves where it enters
        assert_eq!(back[0].0, Pt::new(10.0, 0.6));
        assert_eq!(back[6].1, Pt::new(0.0, 0.0));
    }

    #[test]
    fn chunks_stay_within_the_size_and_within_one_field() {
        let gs = ring(Pt::new(0.0, 0.0), 10.0, 60, 0);
        // at most 8 mm: the 20 mm loop is cut into arcs
        let c = Contraction::within(&gs, [8.0, 8.0]).expect("a run");
        assert!(c.nodes().len() > 3);
        for n in c.nodes() {
            let b = n.bbox();
            assert!(b.width() <= 8.0 && b.height() <= 8.0 && !n.closed);
        }
        // two fields split the loop in two chunks
        let fields = vec![field(0, (0..30).collect()), field(1, (30..60).collect())];
        let c = Contraction::in_fields(&gs, &fields).expect("a run");
        assert_eq!(c.nodes().len(), 2);
        let nf = c.fields_to_nodes(&fields);
        assert_eq!(nf[0].geometries, vec![0]);
        assert_eq!(nf[1].geometries, vec![1]);
        let back = c.fields_to_geometries(nf);
        assert_eq!(back, fields);
    }

    #[test]
    fn runs_of_one_member_or_none_contract_to_nothing() {
        let gs = vec![loose(Pt::new(0.0, 0.0)), loose(Pt::new(3.0, 0.0))];
        assert!(Contraction::within(&gs, [70.0, 70.0]).is_none());
        let mut one = ring(Pt::new(0.0, 0.0), 5.0, 1, 0);
        one.extend(ring(Pt::new(20.0, 0.0), 5.0, 1, 1));
        assert!(Contraction::within(&one, [70.0, 70.0]).is_none());
    }
}
