//! The chromosome enhancement algorithm (seed 000 §3.3.2) and field-contiguity repair.

use super::Chromosome;
use crate::document::{Geometry, Step};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use crate::order::cost::TravelCost;
use crate::order::tsp::{LocalSearch, LsOptions, Node, PathProblem, Tour, NO_CLUSTER};
use crate::order::vertex::{optimal_vertices, vea};

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
    /// penalty (seed 000 Algorithm 1), started from the nodes in `start` (all when `None`), then
    /// vertex enhancement (VEA; then the exact DP when enabled), with the field runs made
    /// contiguous in between. Sets `c.cost` to the fitness of the result.
    pub fn enhance(
        &self,
        c: &mut Chromosome,
        start: Option<&[usize]>,
        ctx: &JobCtx,
    ) -> Result<(), Cancelled> {
        ctx.check()?;
        let (prob, flipped) = self.problem(c);
        let mut order = Vec::with_capacity(c.sco.len() + 1);
        order.push(0);
        order.extend(c.sco.iter().map(|&g| g + 1));
        let mut tour = Tour { order, flipped };
        let ls = LocalSearch::with_neighbours(&prob, &self.neighbours, LsOptions::default());
        ls.run(&mut tour, start, ctx)?;
        c.sco = tour.order.iter().skip(1).map(|&v| v - 1).collect();
        for (g, geom) in self.geometries.iter().enumerate() {
            if !geom.closed {
                c.vo[g] = usize::from(tour.flipped[g + 1]);
            }
        }
        make_contiguous(&mut c.sco, &self.field_of);
        let mut steps = self.steps(c);
        vea(self.geometries, &mut steps, ctx)?;
        if self.exact_vertices {
            optimal_vertices(self.geometries, &mut steps, ctx)?;
        }
        for s in &steps {
            c.vo[s.geometry] = s.choice(&self.geometries[s.geometry]);
        }
        c.cost = (self.fitness)(&steps);
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
