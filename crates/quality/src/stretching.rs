//! Element stretching: the longest over the shortest straight edge (the paper's Sect. 5
//! measure of anisotropy, e.g. 381 for the boundary-layer Falcon mesh).

use hocurve_mesh::HighOrderMesh;

use crate::jacobian::check_cells;
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
            let shape = cell.kind;
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
#[path = "tests/stretching.rs"]
mod tests;
