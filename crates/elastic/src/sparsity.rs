//! Who couples with whom: the cells around each node, the node adjacency graph (the
//! block sparsity pattern of the stiffness matrix) and a colouring of the cells so that
//! cells of one colour share no node and can be assembled in parallel.

use hocurve_mesh::HighOrderMesh;
use rayon::prelude::*;

/// A compressed list of lists: row r is `items[offsets[r]..offsets[r + 1]]`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct Adjacency {
    pub offsets: Vec<usize>,
    pub items: Vec<u32>,
}

impl Adjacency {
    pub fn row(&self, r: usize) -> &[u32] {
        &self.items[self.offsets[r]..self.offsets[r + 1]]
    }

    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }
}

/// The cells containing each node, in increasing cell order.
pub(crate) fn node_cells(mesh: &HighOrderMesh) -> Adjacency {
    let mut counts = vec![0usize; mesh.nodes.len() + 1];
    for cell in &mesh.cells {
        for &n in &cell.nodes {
            counts[n as usize + 1] += 1;
        }
    }
    for i in 0..mesh.nodes.len() {
        counts[i + 1] += counts[i];
    }
    let offsets = counts.clone();
    let mut next = counts;
    let mut items = vec![0u32; offsets[mesh.nodes.len()]];
    for (c, cell) in mesh.cells.iter().enumerate() {
        for &n in &cell.nodes {
            items[next[n as usize]] = c as u32;
            next[n as usize] += 1;
        }
    }
    Adjacency { offsets, items }
}

/// For each node, the sorted nodes it shares a cell with (itself included, also when it is
/// in no cell, so that every row has a diagonal).
pub(crate) fn node_graph(mesh: &HighOrderMesh, cells_of_node: &Adjacency) -> Adjacency {
    let rows: Vec<Vec<u32>> = (0..mesh.nodes.len())
        .into_par_iter()
        .map(|n| {
            let mut row = vec![n as u32];
            for &c in cells_of_node.row(n) {
                row.extend_from_slice(&mesh.cells[c as usize].nodes);
            }
            row.sort_unstable();
            row.dedup();
            row
        })
        .collect();
    let mut offsets = Vec::with_capacity(rows.len() + 1);
    offsets.push(0);
    for row in &rows {
        offsets.push(offsets[offsets.len() - 1] + row.len());
    }
    Adjacency {
        offsets,
        items: rows.concat(),
    }
}

/// Greedy colouring: each cell, in order, takes the lowest colour not used by an earlier
/// cell sharing a node with it. Returns the cells of each colour, in increasing order.
pub(crate) fn colour_cells(mesh: &HighOrderMesh, cells_of_node: &Adjacency) -> Vec<Vec<u32>> {
    let mut colour = vec![u32::MAX; mesh.cells.len()];
    let mut taken: Vec<bool> = Vec::new();
    let mut classes: Vec<Vec<u32>> = Vec::new();
    for (c, cell) in mesh.cells.iter().enumerate() {
        for &n in &cell.nodes {
            for &other in cells_of_node.row(n as usize) {
                let k = colour[other as usize];
                if k != u32::MAX {
                    taken[k as usize] = true;
                }
            }
        }
        let k = taken.iter().position(|&t| !t).unwrap_or(taken.len());
        if k == taken.len() {
            taken.push(false);
            classes.push(Vec::new());
        }
        colour[c] = k as u32;
        classes[k].push(c as u32);
        taken.iter_mut().for_each(|t| *t = false);
    }
    classes
}

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_mesh::{Element, ElementType, LinearMesh};
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
                    kind: ElementType::Tri,
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
}
