//! The chromosome enhancement algorithm (seed 000 §3.3.2) and field-contiguity repair.

use super::Chromosome;
use crate::document::{Geometry, Step};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use crate::order::cost::TravelCost;
use crate::order::tsp::{LocalSearch, LsOptions, Node, PathProblem, Tour, NO_CLUSTER};
use crate::order::vertex::{optimal_vertices, optimal_vertices_between, vea};

/// Steps on each side of a changed position whose start choices are re-optimised with it.
pub const VERTEX_WINDOW_MARGIN: usize = 4;

/// A parent's order as its lineage reads it: its first gene and each gene's successor
/// (`usize::MAX` for the last), made once per parent and generation, not per offspring.
pub struct Parent {
    first: Option<usize>,
    succ: Vec<usize>,
}

impl Parent {
    /// The parent with geometry order `order`.
    pub fn of(order: &[usize]) -> Self {
        let mut succ = vec![usize::MAX; order.len()];
        for w in order.windows(2) {
            succ[w[0]] = w[1];
        }
        Self {
            first: order.first().copied(),
            succ,
        }
    }
}

/// Where a chromosome came from: its parents (twice the same for a mutant) and the genes a
/// mutation gave new start choices.
pub struct Lineage<'a> {
    /// The parents.
    pub parents: [&'a Parent; 2],
    /// Mutated genes (geometries).
    pub mutated: &'a [usize],
}

impl Lineage<'_> {
    /// The path nodes (geometry g is node g + 1) where `order` differs from both parents: a
    /// gene whose successor is neither parent's successor for it, that successor, the corner
    /// (node 0) when the first gene is neither parent's, and the mutated genes; the local
    /// search starts from these.
    pub fn changed_nodes(&self, order: &[usize]) -> Vec<usize> {
        let [p1, p2] = self.parents;
        let mut out: Vec<usize> = Vec::new();
        let first = order.first().copied();
        if first != p1.first && first != p2.first {
            out.push(0);
        }
        for w in order.windows(2) {
            if p1.succ[w[0]] != w[1] && p2.succ[w[0]] != w[1] {
                out.push(w[0] + 1);
                out.push(w[1] + 1);
            }
        }
        out.extend(self.mutated.iter().map(|&g| g + 1));
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// What every chromosome of one run shares.
pub struct Shared<'a> {
    /// The geometries.
    pub geometries: &'a [Geometry],
    /// Field id of each geometry (its allocation).
    pub field_of: Vec<usize>,
    /// The work area's top-left corner: where every path starts.
    pub corner: Pt,
    /// Penalty on edges between fields: the field diagonal.
    pub penalty: f64,
    /// Neighbour lists over path nodes (node 0 = the corner, node g + 1 = geometry g).
    pub neighbours: Vec<Vec<usize>>,
    /// Use the exact vertex DP after VEA.
    pub exact_vertices: bool,
    /// The objective of strokes in marking order (see `super::Fitness`).
    pub fitness: &'a (dyn Fn(&[Step]) -> f64 + Sync),
}

impl Shared<'_> {
    /// The path problem for a chromosome's current vertex order.
    fn problem(&self, c: &Chromosome) -> (PathProblem, Vec<bool>) {
        let n = self.geometries.len();
        let mut nodes = Vec::with_capacity(n + 1);
        let mut flippable = Vec::with_capacity(n + 1);
        let mut flipped = Vec::with_capacity(n + 1);
        let mut cluster = Vec::with_capacity(n + 1);
        nodes.push(Node::point(self.corner, 0.0));
        flippable.push(false);
        flipped.push(false);
        cluster.push(NO_CLUSTER);
        for (g, geom) in self.geometries.iter().enumerate() {
            if geom.closed {
                let (p, _) = geom.ends(c.vo[g]);
                nodes.push(Node::point(p, 0.0));
                flippable.push(false);
                flipped.push(false);
            } else {
                let (s, e) = geom.ends(0);
                let (node, flips) = Node::open_stroke(s, e, 0.0);
                nodes.push(node);
                flippable.push(flips);
                flipped.push(c.vo[g] == 1);
            }
            cluster.push(self.field_of[g] as u32);
        }
        let prob = PathProblem {
            nodes,
            lambda: 0.0,
            fixed_first: true,
            fixed_last: false,
            flippable,
            cluster,
            cluster_penalty: self.penalty,
            metric: TravelCost::Distance,
        };
        (prob, flipped)
    }

    /// CEA: a TSP pass over the geometry order from the corner with a free end and the field
    /// penalty (seed 000 Algorithm 1), then vertex enhancement (VEA; then the exact DP when
    /// enabled), with the field runs made contiguous in between. Sets `c.cost` to the fitness
    /// of the result.
    ///
    /// A chromosome made from others (`lineage`: an offspring, or a mutant of the seed) is
    /// enhanced where it differs from them only: the local search starts from the nodes whose
    /// neighbours are new, and with exact vertices the start choices are re-optimised in
    /// windows around the positions whose neighbours are new (±[`VERTEX_WINDOW_MARGIN`] steps,
    /// anchored to the fixed choices beside them). Elsewhere every gene keeps the choice it had
    /// in its parent, next to the same neighbours.
    pub fn enhance(
        &self,
        c: &mut Chromosome,
        lineage: Option<&Lineage>,
        ctx: &JobCtx,
    ) -> Result<(), Cancelled> {
        ctx.check()?;
        let (prob, flipped) = self.problem(c);
        let mut order = Vec::with_capacity(c.sco.len() + 1);
        order.push(0);
        order.extend(c.sco.iter().map(|&g| g + 1));
        let mut tour = Tour { order, flipped };
        let ls = LocalSearch::with_neighbours(&prob, &self.neighbours, LsOptions::default());
        let start = lineage.map(|l| l.changed_nodes(&c.sco));
        ls.run(&mut tour, start.as_deref(), ctx)?;
        c.sco = tour.order.iter().skip(1).map(|&v| v - 1).collect();
        for (g, geom) in self.geometries.iter().enumerate() {
            if !geom.closed {
                c.vo[g] = usize::from(tour.flipped[g + 1]);
            }
        }
        make_contiguous(&mut c.sco, &self.field_of);
        let mut steps = self.steps(c);
        match lineage {
            Some(l) if self.exact_vertices => {
                let changed = l.changed_nodes(&c.sco);
                self.vertices_in_windows(&mut steps, &changed, ctx)?;
            }
            _ => {
                vea(self.geometries, &mut steps, ctx)?;
                if self.exact_vertices {
                    optimal_vertices(self.geometries, &mut steps, ctx)?;
                }
            }
        }
        for s in &steps {
            c.vo[s.geometry] = s.choice(&self.geometries[s.geometry]);
        }
        c.cost = (self.fitness)(&steps);
        Ok(())
    }

    /// Exact start choices in windows around the positions of `changed` path nodes (node g + 1
    /// is geometry g; node 0, the corner, is the first position), each anchored to the strokes
    /// before and after it.
    fn vertices_in_windows(
        &self,
        steps: &mut [Step],
        changed: &[usize],
        ctx: &JobCtx,
    ) -> Result<(), Cancelled> {
        let n = steps.len();
        let mut position = vec![0usize; self.geometries.len()];
        for (k, s) in steps.iter().enumerate() {
            position[s.geometry] = k;
        }
        let mut dirty: Vec<usize> = changed
            .iter()
            .map(|&v| if v == 0 { 0 } else { position[v - 1] })
            .collect();
        dirty.sort_unstable();
        let mut k = 0;
        while k < dirty.len() {
            let lo = dirty[k].saturating_sub(VERTEX_WINDOW_MARGIN);
            let mut hi = (dirty[k] + VERTEX_WINDOW_MARGIN + 1).min(n);
            while k + 1 < dirty.len() && dirty[k + 1].saturating_sub(VERTEX_WINDOW_MARGIN) <= hi {
                k += 1;
                hi = (dirty[k] + VERTEX_WINDOW_MARGIN + 1).min(n);
            }
            k += 1;
            let end_of = |s: &Step| {
                let g = &self.geometries[s.geometry];
                g.ends(s.choice(g))
            };
            let before = lo.checked_sub(1).map(|j| end_of(&steps[j]).1);
            let after = steps.get(hi).map(|s| end_of(s).0);
            optimal_vertices_between(self.geometries, &mut steps[lo..hi], before, after, ctx)?;
        }
        Ok(())
    }

    /// The chromosome as plan steps.
    pub fn steps(&self, c: &Chromosome) -> Vec<Step> {
        c.sco
            .iter()
            .map(|&g| Step::from_choice(g, self.field_of[g], &self.geometries[g], c.vo[g]))
            .collect()
    }
}

/// Makes every field's geometries one contiguous run: fields in the order of their first
/// appearance, geometries of a field in their relative order. (The field penalty makes this
/// the rule already; the repair guarantees it, since a plan must visit each field once.)
pub fn make_contiguous(sco: &mut Vec<usize>, field_of: &[usize]) {
    let mut fields: Vec<usize> = Vec::new();
    let mut runs: std::collections::HashMap<usize, Vec<usize>> = std::collections::HashMap::new();
    for &g in sco.iter() {
        let f = field_of[g];
        let run = runs.entry(f).or_insert_with(|| {
            fields.push(f);
            Vec::new()
        });
        run.push(g);
    }
    sco.clear();
    for f in fields {
        if let Some(run) = runs.remove(&f) {
            sco.extend(run);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repair_keeps_first_appearance_and_relative_order() {
        let field_of = [0, 1, 0, 2, 1];
        let mut sco = vec![1, 0, 3, 4, 2];
        make_contiguous(&mut sco, &field_of);
        assert_eq!(sco, vec![1, 4, 0, 2, 3]);
    }
}
