//! The L2 norm of the error of a displacement field against a known one.

use hocurve_mesh::HighOrderMesh;
use rayon::prelude::*;

use crate::element_matrix::invert_jacobian;
use crate::reference_element::ReferenceStiffness;
use crate::ElasticError;

/// ‖u_h − u‖_{L2(Ω)} = (∫ |u_h − u|² dx)^½ where u_h = Σ Φⱼ uⱼ is the finite element field
/// of the nodal `displacement`, integrated cell by cell with the degree-(2p+2) rule
/// (cell contributions summed in cell order).
pub fn displacement_l2_error(
    mesh: &HighOrderMesh,
    displacement: &[[f64; 3]],
    exact: impl Fn([f64; 3]) -> [f64; 3] + Sync,
) -> Result<f64, ElasticError> {
    let references = ReferenceStiffness::for_mesh(mesh)?;
    if displacement.len() != mesh.nodes.len() {
        return Err(ElasticError::NodeOutOfRange {
            node: displacement.len() as u32,
            count: mesh.nodes.len(),
        });
    }
    let dim = mesh.dim;
    let per_cell: Vec<f64> = (0..mesh.cells.len())
        .into_par_iter()
        .map(|c| {
            let cell = &mesh.cells[c];
            let rule = &references[&cell.kind].load_rule;
            let coords: Vec<[f64; 3]> =
                cell.nodes.iter().map(|&i| mesh.nodes[i as usize]).collect();
            let mut total = 0.0;
            for q in 0..rule.len() {
                let values = rule.values(q);
                let jac = rule.jacobian(&coords, q);
                let det = invert_jacobian(&jac, dim).1.abs();
                let (mut x, mut uh) = ([0.0; 3], [0.0; 3]);
                for ((phi, xa), &node) in values.iter().zip(&coords).zip(&cell.nodes) {
                    for d in 0..3 {
                        x[d] += phi * xa[d];
                        uh[d] += phi * displacement[node as usize][d];
                    }
                }
                let u = exact(x);
                let e2: f64 = (0..dim).map(|d| (uh[d] - u[d]).powi(2)).sum();
                total += rule.weights()[q] * det * e2;
            }
            Ok(total)
        })
        .collect::<Result<_, ElasticError>>()?;
    Ok(per_cell.iter().sum::<f64>().sqrt())
}
