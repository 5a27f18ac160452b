//! Times the direct and the CG solver on 2D unit-square triangle meshes of growing size,
//! to place `SolverOptions::direct_limit_2d`.
//!
//! `cargo run --release -p hocurve-elastic --example direct_vs_cg_2d`

use hocurve_elastic::{
    boundary_nodes, solve_displacement, BoundaryConditions, Material, SolverKind, SolverOptions,
};
use hocurve_mesh::Shape;
use hocurve_nodes::NodeFamily;
use hocurve_testmeshes::{high_order, unit_square};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!(
        "{:>4} {:>2} {:>8} {:>9} {:>9} {:>6}",
        "n", "p", "dofs", "direct", "cg", "iters"
    );
    for (n, p) in [(20, 2), (40, 3), (60, 4), (100, 4), (140, 4)] {
        let mesh = high_order(&unit_square(n, Shape::Tri, 0.1), p, NodeFamily::Fekete);
        let mut bc = BoundaryConditions::default();
        for node in boundary_nodes(&mesh)? {
            let x = mesh.nodes[node as usize];
            let bump = if x[1] < 1e-12 {
                0.05 * (std::f64::consts::PI * x[0]).sin()
            } else {
                0.0
            };
            bc.prescribed.insert(node, [0.0, bump, 0.0]);
        }
        let run = |kind| {
            let options = SolverOptions {
                kind,
                ..Default::default()
            };
            solve_displacement(&mesh, &Material::default(), &bc, &options)
        };
        let direct = run(SolverKind::Direct)?;
        let cg = run(SolverKind::Cg)?;
        println!(
            "{n:>4} {p:>2} {:>8} {:>8.2}s {:>8.2}s {:>6}",
            direct.dofs, direct.timings.solve, cg.timings.solve, cg.iterations
        );
    }
    Ok(())
}
