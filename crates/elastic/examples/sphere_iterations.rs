//! Assembly and solve times (split into coarse set-up, smoother set-up and iterations) and
//! p-multigrid PCG iterations on the bundled sphere-in-a-box mesh (5695 tetrahedra) at
//! p = 1..MAX_P, with the nodes of the physical group "sphere" moved
//! radially onto the unit sphere (the curving displacement) and "farfield" fixed.
//!
//! `cargo run --release -p hocurve-elastic --example sphere_iterations [MAX_P] [DIRECT_MAX_P]`
//! also runs the direct solver up to DIRECT_MAX_P (default 3) for comparison.

use std::path::Path;

use hocurve_elastic::{
    solve_displacement, BoundaryConditions, Material, SolverKind, SolverOptions,
};
use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::NodeFamily;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let max_p: usize = args.next().map_or(Ok(5), |a| a.parse())?;
    let direct_max_p: usize = args.next().map_or(Ok(3), |a| a.parse())?;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sphere/sphere.msh");
    let linear = hocurve_io::read_msh(&path)?;
    let tag = |name: &str| {
        linear
            .physical_group(name)
            .map(|g| g.tag)
            .ok_or_else(|| format!("no physical group {name:?} in {}", path.display()))
    };
    let (sphere, farfield) = (tag("sphere")?, tag("farfield")?);
    println!(
        "sphere.msh: {} vertices, {} cells, {} threads",
        linear.vertices.len(),
        linear.cells.len(),
        rayon::current_num_threads()
    );
    println!(
        "{:>2} {:>7} {:>7} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>6} {:>9} {:>9}",
        "p",
        "solver",
        "nodes",
        "dofs",
        "assemble",
        "coarse",
        "smoother",
        "iterate",
        "solve",
        "iters",
        "per iter",
        "residual"
    );
    for p in 1..=max_p {
        let mesh = HighOrderMesh::from_linear(&linear, p, NodeFamily::Fekete)?;
        let mut bc = BoundaryConditions::default();
        for facet in &mesh.facets {
            let tags = mesh.physical_tags(2, facet.entity);
            for &n in &facet.nodes {
                let x = mesh.nodes[n as usize];
                if tags.contains(&farfield) {
                    bc.prescribed.insert(n, [0.0; 3]);
                } else if tags.contains(&sphere) {
                    // Straight facet nodes lie inside the unit sphere: push them onto it.
                    let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
                    bc.prescribed.insert(n, x.map(|c| c / r - c));
                }
            }
        }
        let mut kinds = vec![SolverKind::Cg];
        if p <= direct_max_p {
            kinds.push(SolverKind::Direct);
        }
        for kind in kinds {
            let options = SolverOptions {
                kind,
                ..Default::default()
            };
            let s = solve_displacement(&mesh, &Material::default(), &bc, &options)?;
            let t = &s.timings;
            println!(
                "{:>2} {:>7} {:>7} {:>7} {:>8.2}s {:>8.2}s {:>8.2}s {:>8.2}s {:>8.2}s {:>6} {:>7.1}ms {:>9.1e}",
                p,
                format!("{:?}", s.solver_used),
                mesh.nodes.len(),
                s.dofs,
                t.assembly,
                t.coarse_setup,
                t.smoother_setup,
                t.iterations,
                t.solve,
                s.iterations,
                1e3 * t.iterations / s.iterations.max(1) as f64,
                s.relative_residual
            );
        }
    }
    Ok(())
}
