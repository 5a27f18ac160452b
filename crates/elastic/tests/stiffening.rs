//! Per-cell stiffening: a bar of two materials pulled along x (ν = 0) has the exact
//! solution u = (u_x(x), 0, 0), piecewise linear with the strain ratio the inverse of the
//! stiffness ratio, which the solver must reproduce when the stiffening is applied.

use hocurve_elastic::{
    boundary_nodes, solve_displacement_stiffened, BoundaryConditions, ElasticError, Material,
    SolverKind, SolverOptions,
};
use hocurve_nodes::NodeFamily;
use hocurve_testmeshes::{high_order, unit_cube, Fill, Kuhn};

/// u_x of the bar [0, 1] with stiffness 1 for x < 1/2 and `s` beyond, u_x(0) = 0 and
/// u_x(1) = 1: equal stress E ε on both sides gives ε = 2s/(1 + s) then 2/(1 + s).
fn two_material_bar(x: f64, s: f64) -> f64 {
    let (left, right) = (2.0 * s / (1.0 + s), 2.0 / (1.0 + s));
    if x <= 0.5 {
        left * x
    } else {
        0.5 * left + (x - 0.5) * right
    }
}

#[test]
fn a_two_material_bar_is_reproduced_exactly() {
    let s = 9.0;
    let material = Material::new(1.0, 0.0).unwrap();
    for (fill, name) in [(Fill::Tet(Kuhn::Paired), "tet"), (Fill::Hex, "hex")] {
        for (p, kind) in [
            (1, SolverKind::Direct),
            (2, SolverKind::Direct),
            (3, SolverKind::Cg),
        ] {
            let mesh = high_order(&unit_cube(4, fill, 0.0), p, NodeFamily::Fekete);
            let stiffening: Vec<f64> = mesh
                .cells
                .iter()
                .map(|cell| {
                    let x: f64 = cell.nodes.iter().map(|&n| mesh.nodes[n as usize][0]).sum();
                    if x / (cell.nodes.len() as f64) < 0.5 {
                        1.0
                    } else {
                        s
                    }
                })
                .collect();
            let mut bc = BoundaryConditions::default();
            for n in boundary_nodes(&mesh).unwrap() {
                let x = mesh.nodes[n as usize][0];
                bc.prescribed.insert(n, [two_material_bar(x, s), 0.0, 0.0]);
            }
            let options = SolverOptions {
                kind,
                tolerance: 1e-13,
                ..Default::default()
            };
            let solution = solve_displacement_stiffened(
                &mesh,
                &material,
                &stiffening,
                &bc,
                &options,
                &mut |_| {},
            )
            .unwrap();
            let mut worst = 0.0f64;
            for (x, u) in mesh.nodes.iter().zip(&solution.displacement) {
                let exact = [two_material_bar(x[0], s), 0.0, 0.0];
                for d in 0..3 {
                    worst = worst.max((u[d] - exact[d]).abs());
                }
            }
            assert!(worst < 1e-10, "{name} p = {p}: error {worst:e}");
            // Without the stiffening the interface node is where a uniform bar has it.
            let uniform = vec![1.0; mesh.cells.len()];
            let plain = solve_displacement_stiffened(
                &mesh,
                &material,
                &uniform,
                &bc,
                &options,
                &mut |_| {},
            )
            .unwrap();
            let moved = plain
                .displacement
                .iter()
                .zip(&solution.displacement)
                .map(|(a, b)| (a[0] - b[0]).abs())
                .fold(0.0, f64::max);
            assert!(moved > 0.05, "{name} p = {p}: {moved}");
        }
    }
}

#[test]
fn stiffening_that_is_not_one_positive_factor_per_cell_is_an_error() {
    let mesh = high_order(
        &unit_cube(1, Fill::Tet(Kuhn::Paired), 0.0),
        1,
        NodeFamily::Fekete,
    );
    let mut bc = BoundaryConditions::default();
    bc.prescribed.insert(0, [0.0; 3]);
    let cells = mesh.cells.len();
    for bad in [
        vec![1.0; cells - 1],
        {
            let mut v = vec![1.0; cells];
            v[2] = 0.0;
            v
        },
        {
            let mut v = vec![1.0; cells];
            v[1] = f64::NAN;
            v
        },
    ] {
        let result = solve_displacement_stiffened(
            &mesh,
            &Material::default(),
            &bad,
            &bc,
            &SolverOptions::default(),
            &mut |_| {},
        );
        assert!(
            matches!(result, Err(ElasticError::InvalidStiffening { .. })),
            "{result:?}"
        );
    }
}
