//! Probe: plain 2-opt/Or-opt quality on an instance with fixed seams (as vpype sees it).
use galvoplan::import::{import_svg_file, ImportOptions};
use galvoplan::job::JobCtx;
use galvoplan::order::tsp::{cheapest_arc, local_search, LsOptions, Node, PathProblem, Tour};

fn main() -> anyhow::Result<()> {
    let path = std::env::args().nth(1).unwrap_or_default();
    let im = import_svg_file(std::path::Path::new(&path), &ImportOptions::default())?;
    let g = &im.geometries;
    let nodes: Vec<Node> = g
        .iter()
        .map(|g| {
            let (s, e) = g.ends(0);
            Node { s, e, p: 0.0 }
        })
        .collect();
    let flippable: Vec<bool> = g.iter().map(|g| !g.closed).collect();
    let n = nodes.len();
    let prob = PathProblem {
        nodes: nodes.clone(),
        lambda: 0.0,
        fixed_first: false,
        fixed_last: false,
        flippable,
    };
    let arc = |i: usize, j: usize| nodes[i].e.dist(nodes[j].s).min(nodes[i].e.dist(nodes[j].e));
    let order = cheapest_arc(n, 0, None, &arc);
    let mut t = Tour {
        order,
        flipped: vec![false; n],
    };
    println!("greedy {:.1}", prob.tour_distance(&t));
    for k in [10, 16, 24] {
        let mut t2 = t.clone();
        let c = local_search(
            &prob,
            &mut t2,
            LsOptions {
                neighbours: k,
                or_max: 3,
            },
            &JobCtx::default(),
        )?;
        println!("ls k={k} {c:.1}");
    }
    for kicks in [1000, 5000, 20000] {
        let mut t2 = t.clone();
        let t0 = std::time::Instant::now();
        let c = galvoplan::order::tsp::LocalSearch::new(&prob, LsOptions::default()).iterated(
            &mut t2,
            kicks,
            1,
            &JobCtx::default(),
        )?;
        println!(
            "ils {kicks}: {c:.1} in {:.0} ms",
            t0.elapsed().as_secs_f64() * 1e3
        );
    }
    let c = local_search(&prob, &mut t, LsOptions::default(), &JobCtx::default())?;
    println!("final {c:.1}");
    Ok(())
}
