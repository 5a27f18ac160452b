use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::NodeFamily;

use super::*;
use crate::p_multigrid::tests::tet_cube;

/// Every run lies in exactly one colour (or the sequential list), and no two runs of a
/// colour share a node: the condition for adding a colour's runs in parallel.
fn assert_valid_colouring(runs: &CellRuns) {
    let count = runs.run_start.len() - 1;
    let mut seen = vec![0; count];
    for class in &runs.colours {
        assert!(!class.is_empty(), "an empty colour");
        assert!(
            class.windows(2).all(|w| w[0] < w[1]),
            "a colour's runs in order"
        );
        let mut owner = std::collections::HashMap::new();
        for &k in class {
            seen[k as usize] += 1;
            for &v in runs.nodes_of_run(k as usize) {
                if let Some(other) = owner.insert(v, k) {
                    panic!("runs {other} and {k} of one colour share node {v}");
                }
            }
        }
    }
    runs.sequential.iter().for_each(|&k| seen[k as usize] += 1);
    assert!(seen.iter().all(|&s| s == 1), "each run exactly once");
}

#[test]
fn runs_of_a_colour_share_no_node_and_two_threads_share_the_colours_evenly() {
    for (n, p) in [(10, 4), (6, 2), (3, 3)] {
        let mesh = HighOrderMesh::from_linear(&tet_cube(n), p, NodeFamily::Fekete).unwrap();
        let runs = CellRuns::new(&mesh, mesh.cells[0].nodes.len());
        assert_valid_colouring(&runs);
        let sizes: Vec<usize> = runs.colours.iter().map(|c| c.len()).collect();
        // Two threads take ⌈s / 2⌉ turns over a colour of s runs. The plain greedy rule
        // (lowest free colour) gave the 6 000-cell cube colours of 14, 14, 12, 11, 12, 12,
        // 11, 9, 7, 7, 6, 4, 4, 3, 1, 1 runs: 68 turns for 127 runs, 7 % above 63.5.
        let turns: usize = sizes.iter().map(|s| s.div_ceil(2)).sum();
        let ideal = sizes.iter().sum::<usize>() as f64 / 2.0;
        println!(
            "{} cells, p = {p}: colours of {sizes:?} runs, {turns} turns",
            mesh.cells.len()
        );
        // (A few runs of a small mesh each meet most others: nothing to balance.)
        if mesh.cells.len() >= 1000 {
            assert!(
                turns as f64 <= 1.04 * ideal + 1.0,
                "{turns} turns for {ideal} ideal: {sizes:?}"
            );
        }
    }
}

#[test]
fn a_run_that_meets_every_colour_is_done_on_its_own() {
    // 66 runs on one shared node: each would need its own colour; 64 colours exist.
    let runs: Vec<Vec<u32>> = (0..66).map(|k| vec![0, 1 + k]).collect();
    let mut run_start = vec![0];
    let mut run_nodes = Vec::new();
    for r in &runs {
        run_nodes.extend_from_slice(r);
        run_start.push(run_nodes.len());
    }
    let (colours, sequential) = colour_runs(&run_start, &run_nodes, 67);
    assert_eq!(colours.len(), 64);
    assert!(colours.iter().all(|c| c.len() == 1));
    assert_eq!(sequential, vec![64, 65]);
}
