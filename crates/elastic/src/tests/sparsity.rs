use super::*;
use hocurve_mesh::{Element, LinearMesh, Shape};
use hocurve_nodes::NodeFamily;

fn strip(n: usize) -> HighOrderMesh {
    // A row of n unit squares, each split into two triangles.
    let mut vertices = Vec::new();
    for i in 0..=n {
        vertices.push([i as f64, 0.0, 0.0]);
        vertices.push([i as f64, 1.0, 0.0]);
    }
    let mut cells = Vec::new();
    for i in 0..n as u32 {
        let (a, b, c, d) = (2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1);
        for v in [vec![a, b, c], vec![a, c, d]] {
            cells.push(Element {
                kind: Shape::Tri,
                vertices: v,
                entity: 1,
            });
        }
    }
    let mesh = LinearMesh {
        dim: 2,
        vertices,
        cells,
        ..Default::default()
    };
    HighOrderMesh::from_linear(&mesh, 2, NodeFamily::Equispaced).unwrap()
}

#[test]
fn colours_separate_cells_that_share_nodes() {
    let mesh = strip(5);
    let around = node_cells(&mesh);
    let classes = colour_cells(&mesh, &around);
    let mut seen = vec![false; mesh.cells.len()];
    for class in &classes {
        let mut used = vec![false; mesh.nodes.len()];
        for &c in class {
            assert!(!seen[c as usize]);
            seen[c as usize] = true;
            for &n in &mesh.cells[c as usize].nodes {
                assert!(!used[n as usize], "two cells of one colour share node {n}");
                used[n as usize] = true;
            }
        }
    }
    assert!(seen.iter().all(|&s| s));
    // Worked by hand: the sweep colours the lower/upper triangles of the squares
    // 0,1 | 1,2 | 0,3 | 1,2 | 0,3, i.e. four colours (the fourth first needed at the
    // third square's upper triangle, which meets colours 0, 1 and 2).
    assert_eq!(classes.len(), 4);
    let first_colours: Vec<usize> = (0..6)
        .map(|c| classes.iter().position(|k| k.contains(&c)).unwrap())
        .collect();
    assert_eq!(first_colours, vec![0, 1, 1, 2, 0, 3]);
}

#[test]
fn node_graph_of_quadratic_triangles() {
    let mesh = strip(1);
    let graph = node_graph(&mesh, &node_cells(&mesh));
    // Two P2 triangles: 9 nodes; nodes on the shared diagonal see all 9, the others 6.
    assert_eq!(graph.len(), 9);
    let shared = mesh.cells[0]
        .nodes
        .iter()
        .filter(|n| mesh.cells[1].nodes.contains(n))
        .count();
    assert_eq!(shared, 3);
    for n in 0..9 {
        let expected = if mesh.cells[0].nodes.contains(&(n as u32))
            && mesh.cells[1].nodes.contains(&(n as u32))
        {
            9
        } else {
            6
        };
        assert_eq!(graph.row(n).len(), expected);
        assert!(graph.row(n).windows(2).all(|w| w[0] < w[1]));
    }
}

#[test]
fn colouring_by_node_masks_equals_colouring_by_neighbours() {
    for p in [1, 3] {
        let linear = crate::p_multigrid::tests::tet_cube(4);
        let mesh = HighOrderMesh::from_linear(&linear, p, NodeFamily::Equispaced).unwrap();
        let around = node_cells(&mesh);
        let by_masks = colour_cells_by_masks(&mesh).unwrap();
        assert!(
            by_masks.len() > 4,
            "a real colouring: {} colours",
            by_masks.len()
        );
        assert_eq!(by_masks, colour_cells_by_neighbours(&mesh, &around));
    }
    let strip = strip(7);
    assert_eq!(
        colour_cells_by_masks(&strip).unwrap(),
        colour_cells_by_neighbours(&strip, &node_cells(&strip))
    );
}
