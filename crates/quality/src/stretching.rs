//! Element stretching: the longest over the shortest straight edge (the paper's Sect. 5
//! measure of anisotropy, e.g. 381 for the boundary-layer Falcon mesh).

use hocurve_mesh::HighOrderMesh;

use crate::jacobian::{cell_shape, check_cells};
use crate::QualityError;

/// Stretching of every cell (Vec indexed like `mesh.cells`): max / min length of the
/// vertex-to-vertex segments of its edges (the straight element's edges; curving moves only
/// the high-order nodes). 1 for an equilateral triangle or a cube.
pub fn stretching(mesh: &HighOrderMesh) -> Result<Vec<f64>, QualityError> {
    check_cells(mesh)?;
    mesh.cells
        .iter()
        .enumerate()
        .map(|(element, cell)| {
            let shape = cell_shape(element, cell)?;
            let mut longest = 0.0_f64;
            let mut shortest = f64::INFINITY;
            for &[a, b] in shape.edges() {
                let (x, y) = (
                    mesh.nodes[cell.nodes[a] as usize],
                    mesh.nodes[cell.nodes[b] as usize],
                );
                let length =
                    ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2)).sqrt();
                if length.is_nan() || length <= 0.0 {
                    return Err(QualityError::DegenerateEdge { element, a, b });
                }
                longest = longest.max(length);
                shortest = shortest.min(length);
            }
            Ok(longest / shortest)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_meshes::single_element;
    use hocurve_mesh::ElementType;

    #[test]
    fn stretching_is_longest_over_shortest_edge() {
        // Reference triangle: edges 1, √2, 1.
        let mesh = single_element(ElementType::Tri, 2, |x| x);
        assert!((stretching(&mesh).unwrap()[0] - 2f64.sqrt()).abs() < 1e-15);
        // A 1 × 1 × 10 box: 10 (curving the interior nodes does not change it).
        let mesh = single_element(ElementType::Hex, 2, |x| {
            [x[0] + 0.1 * x[1] * x[1] * (1.0 - x[1]), x[1], 10.0 * x[2]]
        });
        assert!((stretching(&mesh).unwrap()[0] - 10.0).abs() < 1e-13);
        // Reference tet stretched ×3 in z: edges 1, √2, 1, 3, √10, √10 → √10 / 1.
        let mesh = single_element(ElementType::Tet, 1, |x| [x[0], x[1], 3.0 * x[2]]);
        assert!((stretching(&mesh).unwrap()[0] - 10f64.sqrt()).abs() < 1e-14);
    }

    #[test]
    fn coincident_vertices_are_an_error() {
        let mut mesh = single_element(ElementType::Quad, 1, |x| x);
        let v = mesh.cells[0].nodes[1] as usize;
        mesh.nodes[v] = mesh.nodes[mesh.cells[0].nodes[0] as usize];
        assert!(matches!(
            stretching(&mesh),
            Err(QualityError::DegenerateEdge { element: 0, .. })
        ));
    }
}
