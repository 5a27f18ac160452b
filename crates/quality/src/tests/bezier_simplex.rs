use super::*;
use crate::jacobian::{jacobian_determinants, JacobianSampler};
use crate::test_meshes::{hash01, single_element_of_family};
use hocurve_mesh::HighOrderMesh;

/// A randomly curved triangle or tetrahedron of order `p` (nodes of `family` moved by up
/// to ±`amplitude` of the element size), as node coordinates in canonical order.
fn curved(shape: Shape, p: usize, family: NodeFamily, amplitude: f64) -> HighOrderMesh {
    let mut mesh = single_element_of_family(shape, p, family, |x| x);
    for (i, x) in mesh.nodes.iter_mut().enumerate() {
        for d in 0..shape.dim() {
            x[d] += amplitude * (hash01(131 * i as u64 + 7 * p as u64 + d as u64) - 0.5);
        }
    }
    mesh
}

fn coordinates(mesh: &HighOrderMesh) -> Vec<[f64; 3]> {
    mesh.cells[0]
        .nodes
        .iter()
        .map(|&n| mesh.nodes[n as usize])
        .collect()
}

#[test]
fn exact_coefficients_equal_the_converted_samples_within_their_bounds() {
    for shape in [Shape::Tri, Shape::Tet] {
        // From p = 5 on the tetrahedron (7 on the triangle) the sampled reference itself
        // rounds by more than its nominal margin (the order-p Lagrange gradients lose
        // digits): 5e-9 at p = 5, where these coefficients still reproduce det J to 1e-11
        // (the test below).
        let top = if shape == Shape::Tet { 4 } else { 6 };
        for p in 1..=top {
            for family in [NodeFamily::Equispaced, NodeFamily::Fekete] {
                let mesh = curved(shape, p, family, 0.08);
                let coords = coordinates(&mesh);
                let space = BernsteinSpace::for_jacobian(shape, p).unwrap();
                let exact = SimplexJacobian::new(shape, p, family, &space)
                    .unwrap()
                    .unwrap();
                let (c, bound) = exact.coefficients(&coords);
                // The reference: det J sampled at the lattice and converted (its own
                // rounding amplified by the conversion's norm).
                let sampler = JacobianSampler::at_points(shape, p, family, space.points()).unwrap();
                let mut reference = sampler.determinants(&coords);
                let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                space.values_to_coefficients(&mut reference, &mut Vec::new());
                let sampled_bound =
                    (32.0 + coords.len() as f64) * f64::EPSILON * scale * space.conversion_norm();
                let diff = c
                    .iter()
                    .zip(&reference)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(
                    diff <= bound + sampled_bound,
                    "{shape} p={p} {family}: differ by {diff:e}, bounds {bound:e} + {sampled_bound:e}"
                );
                // The bound is a rounding bound, not a guess far above it: within a few
                // times the sampled conversion's margin, which it replaces.
                assert!(
                    bound <= 5.0 * sampled_bound,
                    "{shape} p={p}: {bound:e} vs {sampled_bound:e}"
                );
                // Vertex coefficients are det J at the vertices.
                let vertices: Vec<[f64; 3]> = shape.vertices().to_vec();
                let at_vertices = jacobian_determinants(&mesh, 0, &vertices).unwrap();
                for (&v, want) in exact.vertices().iter().zip(&at_vertices) {
                    assert!(
                        (c[v] - want).abs() <= 1e-11 * scale,
                        "{shape} p={p}: vertex {} vs {want}",
                        c[v]
                    );
                }
            }
        }
    }
}

#[test]
fn exact_coefficients_reproduce_det_j_at_random_points() {
    // Up to p = 10 (tetrahedra: 4 060 coefficients of degree 27), past where the sampled
    // conversion's dense inverse was allowed, for both the family the solver curves on and
    // the equispaced one the written (certified) mesh has.
    for shape in [Shape::Tri, Shape::Tet] {
        for p in 1..=10 {
            for family in [NodeFamily::Fekete, NodeFamily::Equispaced] {
                let mesh = curved(shape, p, family, 0.1);
                let space = BernsteinSpace::lattice_only(shape, p).unwrap();
                let exact = SimplexJacobian::new(shape, p, family, &space)
                    .unwrap()
                    .unwrap();
                let (c, bound) = exact.coefficients(&coordinates(&mesh));
                let mut points = Vec::new();
                let mut seed = 3;
                while points.len() < 20 {
                    let x = [hash01(seed), hash01(seed + 1), hash01(seed + 2)];
                    seed += 3;
                    let x = if shape == Shape::Tri {
                        [x[0], x[1], 0.0]
                    } else {
                        x
                    };
                    if x.iter().sum::<f64>() <= 1.0 {
                        points.push(x);
                    }
                }
                let want = jacobian_determinants(&mesh, 0, &points).unwrap();
                let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let worst = points
                    .iter()
                    .zip(&want)
                    .map(|(x, w)| (space.eval(&c, *x) - w).abs())
                    .fold(0.0, f64::max);
                // Within both evaluations' rounding: the Lagrange one loses digits with p
                // (equispaced more), the Bernstein sum is within the carried bound.
                let lagrange = 1e-12 * 4f64.powi(p as i32) * scale;
                assert!(
                    worst <= lagrange + bound,
                    "{shape} p={p} {family}: {worst:e} > {lagrange:e} + {bound:e}"
                );
                // And the carried bound leaves room to certify: far below det J itself.
            }
        }
    }
}

/// On a smoothly curved element (what curving makes) the carried rounding bound stays far
/// below det J up to p = 10, so certification is not lost to it. (On the random-noise
/// elements above it reaches 2 % of det J at p = 10 — control points much larger than the
/// element — while the true error is 1e-11.)
#[test]
fn rounding_bound_is_small_on_smooth_elements() {
    for shape in [Shape::Tri, Shape::Tet] {
        for p in 1..=10 {
            for family in [NodeFamily::Fekete, NodeFamily::Equispaced] {
                let mesh = single_element_of_family(shape, p, family, |x| {
                    [
                        x[0] + 0.15 * (2.0 * x[1]).sin(),
                        x[1] + 0.15 * (1.5 * x[2] + x[0]).cos(),
                        x[2] + 0.1 * (x[0] * x[1]).sin(),
                    ]
                });
                let space = BernsteinSpace::lattice_only(shape, p).unwrap();
                let exact = SimplexJacobian::new(shape, p, family, &space)
                    .unwrap()
                    .unwrap();
                let (c, bound) = exact.coefficients(&coordinates(&mesh));
                let scale = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(
                    bound < 1e-6 * scale,
                    "{shape} p={p} {family}: bound {:e} of max det J",
                    bound / scale
                );
            }
        }
    }
}

#[test]
fn other_shapes_have_no_simplex_coefficients() {
    for shape in [Shape::Quad, Shape::Hex, Shape::Prism] {
        let space = BernsteinSpace::for_jacobian(shape, 2).unwrap();
        let none = SimplexJacobian::new(shape, 2, NodeFamily::Fekete, &space).unwrap();
        assert!(none.is_none(), "{shape}");
    }
}
