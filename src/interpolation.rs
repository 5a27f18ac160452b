//! The interpolation-error study of the paper's Fig. 12b: how well the order-p nodal
//! interpolant on a mesh approximates a smooth function, measured in L2.

use std::collections::btree_map::Entry;
use std::collections::BTreeMap;

use hocurve_mesh::{Element, HighOrderMesh, LinearMesh, MeshError, Shape};
use hocurve_nodes::{determinant, ReferenceElement};

/// ‖f − Π_p f‖_{L2(Ω)} where Π_p f = Σⱼ f(xⱼ) Φⱼ interpolates `f` at the mesh's nodes,
/// integrated cell by cell with a quadrature of degree 2p + 6 (high enough that the
/// quadrature error is far below the interpolation error), |det J| from the cells' own maps.
pub fn interpolation_l2_error(
    mesh: &HighOrderMesh,
    f: impl Fn([f64; 3]) -> f64,
) -> Result<f64, MeshError> {
    let mut total = 0.0;
    let (mut current, mut fx) = (usize::MAX, Vec::new());
    integrate_over_cells(
        mesh,
        2 * mesh.order + 6,
        |cell, x, values, point, det_weight| {
            if cell != current {
                current = cell;
                fx = x.iter().map(|&xj| f(xj)).collect();
            }
            let interpolant: f64 = values.iter().zip(&fx).map(|(v, fj)| v * fj).sum();
            let e = interpolant - f(point);
            total += det_weight.abs() * e * e;
        },
    )?;
    Ok(total.sqrt())
}

/// The area (2D) or volume (3D) of the curved domain, ∫_Ω 1 = Σ_cells Σ_q w_q det J(ξ_q),
/// with a quadrature of degree 2·dim·p, exact for det J of a simplex map (degree dim·(p−1))
/// and far beyond the geometry error otherwise. Inverted regions count negative.
pub fn domain_measure(mesh: &HighOrderMesh) -> Result<f64, MeshError> {
    let mut total = 0.0;
    integrate_over_cells(mesh, 2 * mesh.dim * mesh.order, |_, _, _, _, det_weight| {
        total += det_weight;
    })?;
    Ok(total)
}

/// Calls `visit(cell index, cell nodes, basis values, physical point, w·det J)` at every
/// point of a degree-`degree` quadrature rule in every cell, cell after cell.
fn integrate_over_cells(
    mesh: &HighOrderMesh,
    degree: usize,
    mut visit: impl FnMut(usize, &[[f64; 3]], &[f64], [f64; 3], f64),
) -> Result<(), MeshError> {
    let mut tables = BTreeMap::new();
    for (index, cell) in mesh.cells.iter().enumerate() {
        let shape = cell.kind;
        if let Entry::Vacant(slot) = tables.entry(shape) {
            slot.insert(
                ReferenceElement::shared(shape, mesh.order, mesh.family)?.quadrature(degree),
            );
        }
        let table = &tables[&shape];
        let x: Vec<[f64; 3]> = cell.nodes.iter().map(|&n| mesh.nodes[n as usize]).collect();
        for (q, w) in table.weights().iter().enumerate() {
            let values = table.values(q);
            let mut point = [0.0; 3];
            for (phi, xj) in values.iter().zip(&x) {
                for a in 0..3 {
                    point[a] += phi * xj[a];
                }
            }
            let det = determinant(&table.jacobian(&x, q), mesh.dim);
            visit(index, &x, values, point, w * det);
        }
    }
    Ok(())
}

/// The structured mesh of the unit square with `n × n` quadrilaterals, or `2n²` triangles
/// (each square cut along its diagonal), counter-clockwise.
pub fn unit_square_mesh(n: usize, kind: Shape) -> LinearMesh {
    let id = |i: usize, j: usize| (i + (n + 1) * j) as u32;
    let mut vertices = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            vertices.push([i as f64 / n as f64, j as f64 / n as f64, 0.0]);
        }
    }
    let mut cells = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let mut push = |kind, vertices| {
                cells.push(Element {
                    kind,
                    vertices,
                    entity: 1,
                })
            };
            if kind == Shape::Quad {
                push(Shape::Quad, vec![a, b, c, d]);
            } else {
                push(Shape::Tri, vec![a, b, c]);
                push(Shape::Tri, vec![a, c, d]);
            }
        }
    }
    LinearMesh {
        dim: 2,
        vertices,
        cells,
        ..Default::default()
    }
}

/// The paper's test function f(x, y) = x cos y + y sin x (Sect. 5, Fig. 12b).
pub fn paper_test_function(x: [f64; 3]) -> f64 {
    x[0] * x[1].cos() + x[1] * x[0].sin()
}

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_nodes::NodeFamily;

    #[test]
    fn polynomials_of_degree_p_are_interpolated_exactly() {
        for kind in [Shape::Tri, Shape::Quad] {
            let mesh = unit_square_mesh(3, kind);
            for p in 1..=4 {
                let ho = HighOrderMesh::from_linear(&mesh, p, NodeFamily::Fekete).unwrap();
                let f = |x: [f64; 3]| (x[0] - 2.0 * x[1] + 0.5).powi(p as i32);
                assert!(interpolation_l2_error(&ho, f).unwrap() < 1e-12);
                // One degree more is not: the study can fail.
                let g = |x: [f64; 3]| (x[0] - 2.0 * x[1] + 0.5).powi(p as i32 + 1);
                assert!(interpolation_l2_error(&ho, g).unwrap() > 1e-6);
            }
        }
    }

    /// Linear interpolation of x² on the diagonal-cut grid of spacing h is the 1D one on
    /// every horizontal line, so ‖x² − Π₁x²‖² = ∫₀ʰ x²(x − h)² dx / h = h⁴/30 exactly.
    #[test]
    fn linear_interpolation_error_of_x_squared_is_h4_over_30() {
        let mesh = unit_square_mesh(4, Shape::Tri);
        let ho = HighOrderMesh::from_linear(&mesh, 2, NodeFamily::Equispaced).unwrap();
        let p1 = HighOrderMesh::from_linear(&mesh, 1, NodeFamily::Equispaced).unwrap();
        let h = 0.25f64;
        let e = interpolation_l2_error(&p1, |x| x[0] * x[0]).unwrap();
        assert!((e * e - h.powi(4) / 30.0).abs() < 1e-14, "{e}");
        assert!(interpolation_l2_error(&ho, |x| x[0] * x[0]).unwrap() < 1e-14);
    }
}
