//! Open-path TSP machinery shared by every ordering in galvoplan (HHA's field paths and
//! refinements, HGA's chromosome enhancement, the time objective's stage path): construction,
//! exact DP for small paths, and a Lin–Kernighan-class local search with iterated kicks.
//!
//! A node has a start and an end point (equal for a point-like node; the two ends of an open
//! geometry otherwise, swapped when the node is *flipped*) and a projection `p` on the sweep axis.
//! Travelling from node `i` to node `j` costs
//!
//! `c(i, j) = metric(end(i), start(j)) + λ · max(0, p_i − p_j) + cluster penalty`,
//!
//! the caller's travel cost (distance or stage time, [`TravelCost`](super::cost::TravelCost)) plus
//! a directional penalty on moving backwards along the sweep (λ = 0: none) and a penalty on
//! edges between clusters. The first node may be fixed (a fixed start); the last node may be
//! fixed (a fixed end) or free (an open path). Every user of the module states its cost this way
//! and gets the same engine.
//!
//! Files by concern: `problem` (nodes, costs, tours), `construct` (cheapest arc, Held–Karp),
//! `candidates` (neighbour lists), `ring` (the tour with cheap reversals), `engine` (move costs,
//! work queue, undo journal), `moves` (Or-opt, Or-3opt), `lk` (Lin–Kernighan chains), `ils`
//! (the driver: kicks, acceptance, budget), `bound` (the Held–Karp lower bound that measures
//! how far a path is from the optimum).

mod bound;
mod candidates;
mod construct;
mod engine;
mod ils;
mod lk;
mod moves;
mod problem;
mod ring;

pub use bound::held_karp_open_path;
pub use candidates::neighbour_lists;
pub use construct::{cheapest_arc, exact_path, space_filling_order};
pub use ils::{
    default_kicks, local_search, open_path, IlsBudget, LocalSearch, LsOptions, STALL_MIN,
    STALL_PER_NODE,
};
pub use problem::{Node, PathProblem, Tour, NO_CLUSTER, POINT_LIKE_MM};

#[cfg(test)]
mod tests;
