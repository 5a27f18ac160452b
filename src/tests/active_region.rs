use hocurve_elastic::{solve_displacement_from, Material, SolverOptions};
use hocurve_mesh::{LinearMesh, Shape};
use hocurve_nodes::NodeFamily;
use hocurve_testmeshes::{high_order, unit_cube, unit_square, Fill, Kuhn};

use super::*;

/// The unit cube in n³ × 6 tetrahedra at order 2, every boundary node fixed except a bump
/// of height `amplitude` pushed into the face z = 1 around its centre (radius 0.2).
fn cube_with_a_bump(n: usize, amplitude: f64) -> (HighOrderMesh, BoundaryConditions) {
    with_a_bump(&unit_cube(n, Fill::Tet(Kuhn::Paired), 0.0), 2, amplitude)
}

/// `linear` at order `order`, every boundary node fixed except a bump of height
/// `amplitude` pushed into the side x_dim = 1 (z in 3D, y in 2D) around its centre.
fn with_a_bump(
    linear: &LinearMesh,
    order: usize,
    amplitude: f64,
) -> (HighOrderMesh, BoundaryConditions) {
    let mesh = high_order(linear, order, NodeFamily::Fekete);
    let top = mesh.dim - 1;
    let mut bc = BoundaryConditions::default();
    for (_, nodes) in mesh.boundary_facet_nodes().unwrap() {
        for m in nodes {
            let x = mesh.nodes[m as usize];
            let r2: f64 = (0..top).map(|k| (x[k] - 0.5).powi(2)).sum();
            let mut u = [0.0; 3];
            if x[top] > 1.0 - 1e-12 && r2 < 0.04 {
                u[top] = -amplitude * (1.0 - r2 / 0.04).powi(2);
            }
            bc.prescribed.insert(m, u);
        }
    }
    (mesh, bc)
}

fn elastic(
    mesh: &HighOrderMesh,
    bc: &BoundaryConditions,
    _stiffening: Option<&[f64]>,
    initial: Option<&[[f64; 3]]>,
) -> Result<ElasticSolution, CurveError> {
    let zero = vec![[0.0; 3]; mesh.nodes.len()];
    Ok(solve_displacement_from(
        mesh,
        &Material::default(),
        None,
        bc,
        initial.unwrap_or(&zero),
        &SolverOptions::default(),
        &mut |_| {},
    )?)
}

fn largest_difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0, f64::max)
}

/// The largest whole-solve displacement of a node the region holds fixed (outside it or on
/// its outer boundary): what the region's solve gives up.
fn held_back(region: &RegionSolution, bc: &BoundaryConditions, whole: &[[f64; 3]]) -> f64 {
    let length = |u: [f64; 3]| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    (0..whole.len())
        .filter(|&m| region.displacement[m] == [0.0; 3] && !bc.prescribed.contains_key(&(m as u32)))
        .map(|m| length(whole[m]))
        .fold(0.0, f64::max)
}

#[test]
fn a_local_bump_is_solved_on_a_region_that_matches_the_whole_solve() {
    let (mesh, bc) = cube_with_a_bump(10, 0.002);
    let whole = elastic(&mesh, &bc, None, None).unwrap();
    let region = solve_in_active_region(&mesh, &bc, None, 5e-3, None, elastic).unwrap();
    assert!(
        region.cells < mesh.cells.len(),
        "{} of {} cells",
        region.cells,
        mesh.cells.len()
    );
    // What the region differs by is the displacement held back where it ends (at most
    // 5e-3 of its cells' thickness, h / √6 here with h = √3 / 10) and no more.
    let error = largest_difference(&region.displacement, &whole.displacement);
    let held = held_back(&region, &bc, &whole.displacement);
    assert!(held <= 5e-3 * 0.18 && held > 0.0, "held back {held:.3e}");
    assert!(
        error <= 1.5 * held,
        "region differs from the whole solve by {error:.3e}, held back {held:.3e}"
    );
    // The prescribed nodes move exactly as prescribed, the far ones not at all.
    for (&m, u) in &bc.prescribed {
        assert_eq!(region.displacement[m as usize], *u);
    }
}

#[test]
fn a_region_missing_the_cutoff_grows_and_one_missing_it_far_gives_way_to_the_whole_mesh() {
    let (mesh, bc) = cube_with_a_bump(14, 0.002);
    let whole = elastic(&mesh, &bc, None, None).unwrap();
    let grown = solve_in_active_region(&mesh, &bc, None, 5e-3, None, elastic).unwrap();
    assert!(
        grown.solves >= 2 && 2 * grown.cells < mesh.cells.len(),
        "{grown:?}"
    );
    let error = largest_difference(&grown.displacement, &whole.displacement);
    assert!(error <= 1.5 * held_back(&grown, &bc, &whole.displacement));
    // Missing the cutoff by more than twice: straight to the whole mesh.
    let given_up = solve_in_active_region(&mesh, &bc, None, 1e-4, None, elastic).unwrap();
    assert_eq!((given_up.cells, given_up.solves), (mesh.cells.len(), 2));
    // The whole solve starts from the region's displacement (CG here: 14³ · 6 cells at
    // p = 2), so it ends elsewhere within CG's tolerance, and in fewer iterations.
    assert_eq!(
        given_up.solution.solver_used,
        hocurve_elastic::SolverKind::Cg
    );
    let scale = whole
        .displacement
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let error = largest_difference(&given_up.displacement, &whole.displacement);
    assert!(error <= 1e-8 * scale, "{error:e} of {scale:e}");
    assert!(
        given_up.solution.iterations < whole.iterations,
        "{} warm vs {} cold",
        given_up.solution.iterations,
        whole.iterations
    );
}

/// The active-region solve (cutoff 1e-3) of `mesh` under `bc`: fewer than half of the
/// cells, displacement within 1e-3 of the edge length `h` of the whole solve's `whole`.
fn region_matches_the_whole_solve(
    mesh: &HighOrderMesh,
    bc: &BoundaryConditions,
    whole: &[[f64; 3]],
    h: f64,
) -> RegionSolution {
    let region = solve_in_active_region(mesh, bc, None, 1e-3, None, elastic).unwrap();
    assert!(
        2 * region.cells < mesh.cells.len(),
        "{} of {}",
        region.cells,
        mesh.cells.len()
    );
    let error = largest_difference(&region.displacement, whole);
    assert!(error < 1e-3 * h, "dim {}: {error:.3e}", mesh.dim);
    region
}

#[test]
fn regions_of_quadrilaterals_and_of_hexahedra_with_prisms_match_the_whole_solve() {
    for (linear, order, h, amplitude) in [
        (unit_square(40, Shape::Quad, 0.0), 3, 0.036, 2e-5),
        (unit_cube(12, Fill::HexPrism, 0.0), 2, 0.15, 2e-4),
    ] {
        let (mesh, bc) = with_a_bump(&linear, order, amplitude);
        let whole = elastic(&mesh, &bc, None, None).unwrap();
        region_matches_the_whole_solve(&mesh, &bc, &whole.displacement, h);
    }
}

#[test]
fn the_region_grows_to_the_whole_mesh_when_no_displacement_may_reach_its_edge() {
    let (mesh, bc) = cube_with_a_bump(4, 0.02);
    let whole = elastic(&mesh, &bc, None, None).unwrap();
    let region = solve_in_active_region(&mesh, &bc, None, 0.0, None, elastic).unwrap();
    assert_eq!(region.cells, mesh.cells.len());
    assert!(region.solves >= 1);
    assert_eq!(region.displacement, whole.displacement);
}

#[test]
fn nothing_moved_is_one_whole_solve() {
    let (mesh, mut bc) = cube_with_a_bump(2, 0.0);
    bc.prescribed.values_mut().for_each(|u| *u = [0.0; 3]);
    let region = solve_in_active_region(&mesh, &bc, None, 1e-3, None, elastic).unwrap();
    assert_eq!((region.cells, region.solves), (mesh.cells.len(), 1));
    assert!(region.displacement.iter().all(|u| *u == [0.0; 3]));
}

#[test]
fn solve_regions_parse_from_the_command_line() {
    assert_eq!("whole".parse::<SolveRegion>(), Ok(SolveRegion::Whole));
    assert_eq!("active".parse::<SolveRegion>(), Ok(SolveRegion::ACTIVE));
    assert_eq!(
        "active=0.05".parse::<SolveRegion>(),
        Ok(SolveRegion::Active { cutoff: 0.05 })
    );
    for bad in ["some", "active=", "active=-1", "active=nan", "active=x"] {
        assert!(bad.parse::<SolveRegion>().is_err(), "{bad}");
    }
}

#[test]
fn sliding_walls_inside_the_region_slide_and_outside_stay() {
    // The walls x = 0 and x = 1 slide in their planes instead of being fixed.
    let (mesh, mut bc) = cube_with_a_bump(10, 0.002);
    for (&m, u) in bc.prescribed.clone().iter() {
        let x = mesh.nodes[m as usize][0];
        if !(1e-12..=1.0 - 1e-12).contains(&x) && *u == [0.0; 3] {
            bc.prescribed.remove(&m);
            bc.sliding.insert(m, [1.0, 0.0, 0.0]);
        }
    }
    let whole = elastic(&mesh, &bc, None, None).unwrap();
    let region = solve_in_active_region(&mesh, &bc, None, 5e-3, None, elastic).unwrap();
    assert!(2 * region.cells < mesh.cells.len());
    let error = largest_difference(&region.displacement, &whole.displacement);
    assert!(error <= 1.5 * held_back(&region, &bc, &whole.displacement));
    for &m in bc.sliding.keys() {
        assert!(region.displacement[m as usize][0].abs() < 1e-12);
    }
}
