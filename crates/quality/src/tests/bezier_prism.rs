use super::*;
use crate::jacobian::jacobian_determinants;
use crate::test_meshes::{hash01, single_element_of_family};
use crate::BernsteinSpace;

/// Prisms of order p = 1..10 curved by a smooth map: the exact coefficients reproduce det J
/// (sampled through the Lagrange basis) at the vertices and random points, and the carried
/// rounding bound stays below det J by a margin that shrinks tenfold per order.
#[test]
fn exact_prism_coefficients_reproduce_det_j() {
    for p in 1..=10 {
        for family in [NodeFamily::Fekete, NodeFamily::Equispaced] {
            let mesh = single_element_of_family(Shape::Prism, p, family, |x| {
                [
                    x[0] + 0.15 * (2.0 * x[1]).sin() + 0.05 * x[2] * x[2],
                    x[1] + 0.15 * (1.5 * x[2] + x[0]).cos(),
                    x[2] + 0.1 * (x[0] * x[1]).sin(),
                ]
            });
            let coords: Vec<[f64; 3]> = mesh.cells[0]
                .nodes
                .iter()
                .map(|&n| mesh.nodes[n as usize])
                .collect();
            let exact = PrismJacobian::new(Shape::Prism, p, family)
                .unwrap()
                .unwrap();
            let (c, bound) = exact.coefficients(&coords);
            let space = BernsteinSpace::lattice_only(Shape::Prism, p).unwrap();
            assert_eq!(c.len(), space.len(), "p={p}");
            let mut points: Vec<[f64; 3]> = Shape::Prism.vertices().to_vec();
            let mut seed = 11;
            while points.len() < 26 {
                let x = [hash01(seed), hash01(seed + 1), hash01(seed + 2)];
                seed += 3;
                if x[0] + x[1] <= 1.0 {
                    points.push(x);
                }
            }
            let want = jacobian_determinants(&mesh, 0, &points).unwrap();
            let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (x, w) in points.iter().zip(&want) {
                let got = space.eval(&c, *x);
                assert!(
                    (got - w).abs() <= 1e-12 * 4f64.powi(p as i32) * scale + bound,
                    "p={p} {family} at {x:?}: {got} vs {w}"
                );
            }
            // Measured: 2e-10 at p = 4, 4e-8 at p = 6, 4e-6 at p = 8, 4e-4 at p = 10
            // (equispaced; Fekete 10× less): elements with Ĩ above it are certified.
            let allowed = 1e-13 * 10f64.powi(p as i32);
            assert!(
                bound < allowed * scale,
                "p={p} {family}: bound {:e}",
                bound / scale
            );
        }
    }
}

#[test]
fn other_shapes_have_no_prism_coefficients() {
    for shape in [Shape::Tri, Shape::Tet, Shape::Quad, Shape::Hex] {
        assert!(PrismJacobian::new(shape, 2, NodeFamily::Fekete)
            .unwrap()
            .is_none());
    }
}
