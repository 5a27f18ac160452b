//! Patch test: a linear displacement prescribed on the boundary is reproduced exactly
//! inside, for every element type, hybrid meshes and p = 1..5.

use hocurve_elastic::{
    boundary_nodes, solve_displacement, BoundaryConditions, Material, SolverKind, SolverOptions,
};
use hocurve_mesh::{HighOrderMesh, LinearMesh, Shape};
use hocurve_nodes::NodeFamily;
use hocurve_testmeshes::{high_order, unit_cube, unit_square, Fill, Kuhn};

fn linear_field(x: [f64; 3]) -> [f64; 3] {
    let a = [[0.3, -0.2, 0.5], [0.7, 0.1, -0.4], [0.2, 0.9, -0.3]];
    let b = [0.05, -0.1, 0.2];
    let mut u = b;
    for c in 0..3 {
        for d in 0..3 {
            u[c] += a[c][d] * x[d];
        }
    }
    u
}

fn check_patch(linear: &LinearMesh, name: &str, kind: SolverKind) {
    // CG stops on a residual; ask for one small enough that the 1e-10 check is about
    // the discretisation, not the stopping rule.
    let options = SolverOptions {
        kind,
        tolerance: 1e-13,
        ..Default::default()
    };
    for p in 1..=5 {
        let mesh: HighOrderMesh = high_order(linear, p, NodeFamily::Fekete);
        let boundary = boundary_nodes(&mesh).unwrap();
        let mut bc = BoundaryConditions::default();
        for &n in &boundary {
            bc.prescribed
                .insert(n, linear_field(mesh.nodes[n as usize]));
        }
        assert!(
            boundary.len() < mesh.nodes.len(),
            "{name}: no interior nodes"
        );
        let solution = solve_displacement(&mesh, &Material::default(), &bc, &options).unwrap();
        let mut worst = 0.0f64;
        for (x, u) in mesh.nodes.iter().zip(&solution.displacement) {
            let exact = linear_field(*x);
            for d in 0..mesh.dim {
                worst = worst.max((u[d] - exact[d]).abs());
            }
        }
        assert!(worst < 1e-10, "{name} p={p}: error {worst:e}");
    }
}

#[test]
fn triangles_reproduce_linear_fields() {
    check_patch(&unit_square(3, Shape::Tri, 0.2), "tri", SolverKind::Direct);
}

#[test]
fn quadrilaterals_reproduce_linear_fields() {
    check_patch(
        &unit_square(3, Shape::Quad, 0.2),
        "quad",
        SolverKind::Direct,
    );
}

#[test]
fn tetrahedra_reproduce_linear_fields() {
    check_patch(
        &unit_cube(2, Fill::Tet(Kuhn::Paired), 0.2),
        "tet",
        SolverKind::Direct,
    );
}

#[test]
fn hexahedra_reproduce_linear_fields() {
    check_patch(&unit_cube(2, Fill::Hex, 0.2), "hex", SolverKind::Direct);
}

#[test]
fn prisms_reproduce_linear_fields() {
    check_patch(&unit_cube(2, Fill::Prism, 0.2), "prism", SolverKind::Direct);
}

#[test]
fn hybrid_hex_prism_meshes_reproduce_linear_fields() {
    check_patch(
        &unit_cube(2, Fill::HexPrism, 0.2),
        "hex+prism",
        SolverKind::Direct,
    );
}

#[test]
fn the_cg_solver_passes_the_patch_test_too() {
    check_patch(
        &unit_cube(2, Fill::HexPrism, 0.2),
        "hex+prism (cg)",
        SolverKind::Cg,
    );
}

#[test]
fn boundary_nodes_of_a_structured_cube() {
    // n = 2, p = 2: nodes on the 5 × 5 × 5 lattice, 3³ of them inside.
    for fill in [
        Fill::Tet(Kuhn::Paired),
        Fill::Hex,
        Fill::Prism,
        Fill::HexPrism,
    ] {
        let mesh = high_order(&unit_cube(2, fill, 0.0), 2, NodeFamily::Fekete);
        assert_eq!(mesh.nodes.len(), 125, "{fill:?}");
        let boundary = boundary_nodes(&mesh).unwrap();
        assert_eq!(boundary.len(), 125 - 27, "{fill:?}");
        for &n in &boundary {
            let x = mesh.nodes[n as usize];
            assert!(x
                .iter()
                .any(|&c| c.abs() < 1e-12 || (c - 1.0).abs() < 1e-12));
        }
    }
    // 2D: a 3 × 3 square at p = 3 has 10 × 10 nodes, 8 × 8 inside.
    let mesh = high_order(&unit_square(3, Shape::Quad, 0.0), 3, NodeFamily::Fekete);
    assert_eq!(boundary_nodes(&mesh).unwrap().len(), 100 - 64);
}
