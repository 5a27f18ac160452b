//! Manufactured solutions: polynomial fields of degree ≤ p with the body force they need are
//! reproduced exactly; a smooth field converges at the optimal rate p + 1 in L2.

use hocurve_elastic::{
    boundary_nodes, displacement_l2_error, solve_displacement_with_load, BoundaryConditions,
    Material, SolverKind, SolverOptions,
};
use hocurve_mesh::{HighOrderMesh, LinearMesh, Shape};
use hocurve_nodes::NodeFamily;
use hocurve_testmeshes::{high_order, unit_cube, unit_square, Fill, Kuhn};

/// A quadratic field in 3D (2D: its first two components at z = 0 drop the z terms, see
/// `quadratic_2d`): Δu = (0.6, 2, 2), ∇ div u = (1.2, 1.9, 2).
fn quadratic_3d(x: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = x;
    [
        x * x + 0.5 * x * y - y * y + 0.3 * z * z - x * z,
        0.3 * x * x - x * y + 0.7 * y * y + y * z,
        z * z - 0.4 * x * y + 0.2 * x * z,
    ]
}

/// Δu = (0, 2), ∇ div u = (1, 1.9).
fn quadratic_2d(x: [f64; 3]) -> [f64; 3] {
    let [x, y, _] = x;
    [
        x * x + 0.5 * x * y - y * y,
        0.3 * x * x - x * y + 0.7 * y * y,
        0.0,
    ]
}

/// f = −((λ + μ) ∇ div u + μ Δu).
fn body_force(lambda: f64, mu: f64, grad_div: [f64; 3], laplacian: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|d| -((lambda + mu) * grad_div[d] + mu * laplacian[d]))
}

fn solve_with_exact_boundary(
    mesh: &HighOrderMesh,
    exact: &(dyn Fn([f64; 3]) -> [f64; 3] + Sync),
    force: &(dyn Fn([f64; 3]) -> [f64; 3] + Sync),
    material: &Material,
) -> Vec<[f64; 3]> {
    let mut bc = BoundaryConditions::default();
    for n in boundary_nodes(mesh).unwrap() {
        bc.prescribed.insert(n, exact(mesh.nodes[n as usize]));
    }
    let options = SolverOptions {
        kind: SolverKind::Direct,
        ..Default::default()
    };
    solve_displacement_with_load(mesh, material, &bc, Some(force), &options)
        .unwrap()
        .displacement
}

/// A displacement field x ↦ u(x).
type Field = fn([f64; 3]) -> [f64; 3];

fn check_polynomial(linear: &LinearMesh, name: &str) {
    let material = Material::new(3.0, 0.3).unwrap();
    let (lambda, mu) = material.lame();
    let (exact, force): (Field, [f64; 3]) = if linear.dim == 2 {
        (
            quadratic_2d,
            body_force(lambda, mu, [1.0, 1.9, 0.0], [0.0, 2.0, 0.0]),
        )
    } else {
        (
            quadratic_3d,
            body_force(lambda, mu, [1.2, 1.9, 2.0], [0.6, 2.0, 2.0]),
        )
    };
    for p in 2..=3 {
        let mesh = high_order(linear, p, NodeFamily::Fekete);
        let u = solve_with_exact_boundary(&mesh, &exact, &move |_| force, &material);
        let mut worst = 0.0f64;
        for (x, u) in mesh.nodes.iter().zip(&u) {
            let e = exact(*x);
            for d in 0..mesh.dim {
                worst = worst.max((u[d] - e[d]).abs());
            }
        }
        assert!(worst < 1e-10, "{name} p={p}: nodal error {worst:e}");
        let l2 = displacement_l2_error(&mesh, &u, exact).unwrap();
        assert!(l2 < 1e-10, "{name} p={p}: L2 error {l2:e}");
    }
}

#[test]
fn quadratic_fields_are_exact_on_general_simplices() {
    check_polynomial(&unit_square(3, Shape::Tri, 0.2), "tri");
    check_polynomial(&unit_cube(2, Fill::Tet(Kuhn::Paired), 0.2), "tet");
}

#[test]
fn quadratic_fields_are_exact_on_affine_tensor_cells() {
    // The mapped Q_p space of a non-parallelogram quad does not contain every quadratic,
    // so these meshes are undistorted.
    check_polynomial(&unit_square(2, Shape::Quad, 0.0), "quad");
    check_polynomial(&unit_cube(2, Fill::HexPrism, 0.0), "hex+prism");
}

/// u = (sin 2x cos y, eˣ sin y): div u = (2 cos 2x + eˣ) cos y,
/// ∇ div u = ((eˣ − 4 sin 2x) cos y, −(2 cos 2x + eˣ) sin y), Δu = (−5 sin 2x cos y, 0).
fn smooth(x: [f64; 3]) -> [f64; 3] {
    [
        (2.0 * x[0]).sin() * x[1].cos(),
        x[0].exp() * x[1].sin(),
        0.0,
    ]
}

#[test]
fn smooth_solution_converges_at_rate_p_plus_one() {
    let material = Material::default();
    let (lambda, mu) = material.lame();
    let force = move |x: [f64; 3]| {
        let [x, y, _] = x;
        let grad_div = [
            (x.exp() - 4.0 * (2.0 * x).sin()) * y.cos(),
            -(2.0 * (2.0 * x).cos() + x.exp()) * y.sin(),
            0.0,
        ];
        body_force(
            lambda,
            mu,
            grad_div,
            [-5.0 * (2.0 * x).sin() * y.cos(), 0.0, 0.0],
        )
    };
    for p in 1..=3 {
        let errors: Vec<f64> = [4, 8, 16]
            .iter()
            .map(|&n| {
                let mesh = high_order(&unit_square(n, Shape::Tri, 0.0), p, NodeFamily::Fekete);
                let u = solve_with_exact_boundary(&mesh, &smooth, &force, &material);
                displacement_l2_error(&mesh, &u, smooth).unwrap()
            })
            .collect();
        let rate = (errors[1] / errors[2]).log2();
        println!("p = {p}: L2 errors {errors:?}, rate {rate:.2}");
        assert!(rate >= p as f64 + 0.7, "p = {p}: rate {rate} ({errors:?})");
    }
}
