use super::*;
use crate::assembly::assemble;
use crate::block_matrix::{BlockOperator, BlockPattern};
use crate::condensation::condense_matrix;
use crate::pcg::pcg;
use crate::smoother::largest_eigenvalue;
use crate::sparse::product;
use crate::vector_ops::spmv;
use crate::{BoundaryConditions, Material};
use hocurve_mesh::LinearMesh;
use hocurve_nodes::NodeFamily;
use hocurve_testmeshes::{unit_cube, Fill, Kuhn, Perturbation};

/// The unit cube as n³ small cubes of 6 tetrahedra each, interior vertices moved by 20 % of
/// h (up to 60 % towards the origin, see [`Perturbation`]) so that the cells are general;
/// integer hash weights: the mesh the iteration counts below were measured on.
pub(crate) fn tet_cube(n: usize) -> LinearMesh {
    let perturbation = Perturbation {
        amplitude: 0.2,
        weights: [12.0, 78.0, 37.0, 4.0],
    };
    unit_cube(n, Fill::Tet(Kuhn::Paired), perturbation)
}

/// The condensed system of the cube with its bottom fixed, its top pushed sideways and,
/// if `slide`, its side x = 0 sliding in its plane.
fn cube_system(
    n: usize,
    p: usize,
    slide: bool,
) -> (
    HighOrderMesh,
    StiffnessMatrix,
    Vec<f64>,
    Constraints,
    Adjacency,
) {
    let mesh = HighOrderMesh::from_linear(&tet_cube(n), p, NodeFamily::Fekete).unwrap();
    let assembled = assemble(&mesh, &Material::default()).unwrap();
    let mut bc = BoundaryConditions::default();
    for (node, x) in mesh.nodes.iter().enumerate() {
        if x[2] < 1e-12 {
            bc.prescribed.insert(node as u32, [0.0; 3]);
        } else if x[2] > 1.0 - 1e-12 {
            bc.prescribed.insert(node as u32, [0.1, 0.05 * x[0], 0.0]);
        } else if slide && x[0] < 1e-12 {
            bc.sliding.insert(node as u32, [-1.0, 0.0, 0.0]);
        }
    }
    let constraints = Constraints::new(mesh.nodes.len(), 3, &bc);
    let mut full = vec![0.0; mesh.nodes.len() * 3];
    spmv(&assembled.matrix, &constraints.prescribed, &mut full);
    full.iter_mut().for_each(|v| *v = -*v);
    let rhs = constraints.restrict(&full);
    let a = condense_matrix(&assembled.matrix, &assembled.graph, &constraints);
    (mesh, a, rhs, constraints, assembled.graph)
}

/// Point Jacobi, z = diag(A)⁻¹ r: the reference whose iteration count grows with p.
struct PointJacobi(Vec<f64>);
impl Preconditioner for PointJacobi {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        z.iter_mut()
            .zip(r.iter().zip(&self.0))
            .for_each(|(z, (r, d))| *z = r / d);
    }
}

#[test]
fn lanczos_estimates_the_smoothed_spectrum() {
    let (mesh, a, _, constraints, _) = cube_system(2, 3, false);
    let cuts = dof_cuts(&entity_node_cuts(&mesh), &constraints.first);
    let smoother = ChebyshevSmoother::new(&a, &a, &cuts, 3);
    let estimate = smoother.estimate_lambda_max(&a);
    // Reference: many power steps on B A, which is similar to the symmetric positive
    // definite B^½ A B^½; the Lanczos value must be just below it.
    let n = a.rows();
    let mut x: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
    let (mut ax, mut y) = (vec![0.0; n], vec![0.0; n]);
    let mut lambda = 0.0;
    for _ in 0..2000 {
        let len = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        x.iter_mut().for_each(|v| *v /= len);
        spmv(&a, &x, &mut ax);
        smoother.block_jacobi.apply(&ax, &mut y);
        lambda = y.iter().map(|v| v * v).sum::<f64>().sqrt();
        std::mem::swap(&mut x, &mut y);
    }
    println!("Lanczos {estimate}, power {lambda}");
    assert!(estimate <= lambda * (1.0 + 1e-8), "{estimate} > {lambda}");
    assert!(estimate > 0.95 * lambda, "{estimate} ≪ {lambda}");
}

#[test]
fn largest_eigenvalue_of_tridiagonal_matrices() {
    // tridiag(−1, 2, −1) of size m: λ_max = 2 + 2 cos(π/(m + 1)).
    let m = 9;
    let exact = 2.0 + 2.0 * (std::f64::consts::PI / (m + 1) as f64).cos();
    let lambda = largest_eigenvalue(&vec![2.0; m], &vec![-1.0; m - 1]);
    assert!((lambda - exact).abs() < 1e-12, "{lambda} vs {exact}");
    assert_eq!(largest_eigenvalue(&[3.5], &[]), 3.5);
    assert_eq!(largest_eigenvalue(&[], &[]), 0.0);
}

/// The levels' meshes of the cube system at order p and q < p.
fn levels(p: usize, q: usize, slide: bool) -> (LevelMesh<'static>, LevelMesh<'static>) {
    levels_of(2, p, q, slide)
}

/// The same on the n × n × n cube.
pub(crate) fn levels_of(
    n: usize,
    p: usize,
    q: usize,
    slide: bool,
) -> (LevelMesh<'static>, LevelMesh<'static>) {
    let (mesh, _, _, constraints, _) = cube_system(n, p, slide);
    let coarse = mesh.straight_of_order(q).unwrap();
    let coarse_constraints = carried_constraints(&mesh, &constraints, &coarse);
    let level = |mesh: HighOrderMesh, constraints: Constraints| LevelMesh {
        cells_of_node: Some(std::borrow::Cow::Owned(crate::sparsity::node_cells(&mesh))),
        mesh: std::borrow::Cow::Owned(mesh),
        constraints: std::borrow::Cow::Owned(constraints),
    };
    (level(mesh, constraints), level(coarse, coarse_constraints))
}

#[test]
fn carried_constraints_fix_and_slide_the_same_entities() {
    let (fine, coarse) = levels(4, 2, true);
    let (fm, cm) = (&*fine.mesh, &*coarse.mesh);
    for (n, x) in cm.nodes.iter().enumerate() {
        let expected = if x[2] < 1e-12 || x[2] > 1.0 - 1e-12 {
            0
        } else if x[0] < 1e-12 {
            2
        } else {
            3
        };
        assert_eq!(coarse.constraints.count[n], expected, "node {n} at {x:?}");
        // The fine node it was taken from lies on the same entity: same vertex, or on
        // the same edge/face/cell (its position is a convex combination of the same
        // vertices, checked through the constraint only).
        let m = same_entity_node(cm, fm, n).unwrap();
        assert_eq!(
            coarse.constraints.directions[n],
            fine.constraints.directions[m]
        );
    }
    assert!(coarse.constraints.prescribed.iter().all(|&v| v == 0.0));
}

#[test]
fn prolongation_interpolates_polynomials_of_the_coarse_order_exactly() {
    // u(x) = (x^q, y^(q−1) z, x z^(q−1) − y) has degree q: sampled at the coarse nodes and
    // prolongated, it equals the samples at the fine nodes (free dofs only: no
    // constraints here).
    for (p, q) in [(2, 1), (3, 2), (5, 4), (5, 2)] {
        let mesh = HighOrderMesh::from_linear(&tet_cube(2), p, NodeFamily::Fekete).unwrap();
        let free = Constraints::new(mesh.nodes.len(), 3, &BoundaryConditions::default());
        let coarse = mesh.straight_of_order(q).unwrap();
        let coarse_free = carried_constraints(&mesh, &free, &coarse);
        let field = |x: &[f64; 3]| {
            [
                x[0].powi(q as i32),
                x[1].powi(q as i32 - 1) * x[2],
                x[0] * x[2].powi(q as i32 - 1) - x[1],
            ]
        };
        let sample = |m: &HighOrderMesh| -> Vec<f64> { m.nodes.iter().flat_map(field).collect() };
        let fine_level = LevelMesh {
            cells_of_node: Some(std::borrow::Cow::Owned(crate::sparsity::node_cells(&mesh))),
            mesh: std::borrow::Cow::Borrowed(&mesh),
            constraints: std::borrow::Cow::Borrowed(&free),
        };
        let coarse_level = LevelMesh {
            cells_of_node: Some(std::borrow::Cow::Owned(crate::sparsity::node_cells(
                &coarse,
            ))),
            mesh: std::borrow::Cow::Borrowed(&coarse),
            constraints: std::borrow::Cow::Borrowed(&coarse_free),
        };
        let prolongation = prolongation(&fine_level, &coarse_level).unwrap();
        let mut out = vec![0.0; free.len()];
        spmv(&prolongation, &sample(&coarse), &mut out);
        let exact = sample(&mesh);
        let error = out
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(error < 1e-12, "p = {p}, q = {q}: {error:e}");
    }
}

#[test]
fn reassembled_coarse_matrices_are_the_galerkin_products() {
    // For straight simplices the order-q space lies in the order-p space and the
    // integrals are exact, so the re-assembled, condensed coarse matrix equals Pᵀ A P,
    // with fixed and sliding nodes.
    for (p, q) in [(2, 1), (3, 2), (4, 3), (4, 1)] {
        let (fine, coarse) = levels(p, q, true);
        let material = Material::default();
        let fine_assembled = assemble(&fine.mesh, &material).unwrap();
        let a = condense_matrix(
            &fine_assembled.matrix,
            &fine_assembled.graph,
            &fine.constraints,
        );
        let coarse_assembled = assemble(&coarse.mesh, &material).unwrap();
        let direct = condense_matrix(
            &coarse_assembled.matrix,
            &coarse_assembled.graph,
            &coarse.constraints,
        );
        let prolongation = prolongation(&fine, &coarse).unwrap();
        let galerkin = product(&transpose(&prolongation), &product(&a, &prolongation));
        let scale = direct.data().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut difference = 0.0f64;
        for (v, (r, c)) in galerkin.iter() {
            let d = direct.get(r as usize, c as usize).copied().unwrap_or(0.0);
            difference = difference.max((v - d).abs());
        }
        for (v, (r, c)) in direct.iter() {
            let g = galerkin.get(r as usize, c as usize).copied().unwrap_or(0.0);
            difference = difference.max((v - g).abs());
        }
        assert!(
            difference < 1e-10 * scale,
            "p = {p}, q = {q}: {difference:e} of {scale:e}"
        );
    }
}

/// The p-multigrid of the condensed matrix `a` of `mesh`, smoothing with `single`.
fn multigrid<'a>(
    a: &StiffnessMatrix,
    single: &'a BlockOperator,
    constraints: &Constraints,
    mesh: &HighOrderMesh,
    options: &crate::SolverOptions,
) -> PMultigrid<'a> {
    let cells_of_node = crate::sparsity::node_cells(mesh);
    PMultigrid::new(
        a.clone(),
        None,
        single,
        constraints,
        mesh,
        &cells_of_node,
        &Material::default(),
        None,
        options,
    )
    .unwrap()
    .0
}

/// PCG iterations with the p-multigrid preconditioner and with point Jacobi.
fn iterations(n: usize, p: usize) -> (usize, usize) {
    let (mesh, a, rhs, constraints, graph) = cube_system(n, p, true);
    let single = BlockOperator::single(BlockPattern::new(&a, &graph, &constraints).unwrap(), &a);
    let mut multigrid = multigrid(
        &a,
        &single,
        &constraints,
        &mesh,
        &crate::SolverOptions::default(),
    );
    let mut x = vec![0.0; rhs.len()];
    let with_multigrid = pcg(&a, &rhs, &mut x, &mut multigrid, 1e-10, 5000);
    let diagonal = (0..a.rows())
        .map(|r| a.get(r, r).copied().unwrap_or(1.0))
        .collect();
    let mut x = vec![0.0; rhs.len()];
    let with_jacobi = pcg(&a, &rhs, &mut x, &mut PointJacobi(diagonal), 1e-10, 5000);
    (with_multigrid, with_jacobi)
}

#[test]
fn iterations_stay_nearly_flat_in_p() {
    let counts: Vec<(usize, usize)> = (1..=5).map(|p| iterations(3, p)).collect();
    println!("(p-multigrid, point Jacobi) for p = 1..5: {counts:?}");
    // p = 1: the coarse problem is the problem.
    assert!(counts[0].0 <= 2, "{counts:?}");
    // Two orders down per level from p = 4 (`level_orders`): more iterations there to
    // a tight tolerance, (16, 18, 30, 34) against (16, 18, 20, 23) with one order per
    // level, but far from point Jacobi's growth.
    let (low, high) = counts[1..]
        .iter()
        .fold((usize::MAX, 0), |(l, h), c| (l.min(c.0), h.max(c.0)));
    assert!(high as f64 <= 2.5 * low as f64, "{counts:?}");
    // Point Jacobi grows with p and needs many times more.
    assert!(counts[4].1 > 3 * counts[1].1, "{counts:?}");
    assert!(counts[4].0 * 10 < counts[4].1, "{counts:?}");
}

#[test]
fn an_aggregated_p1_level_keeps_pcg_converging_to_the_same_solution() {
    let (mesh, a, rhs, constraints, graph) = cube_system(6, 3, true);
    let single = BlockOperator::single(BlockPattern::new(&a, &graph, &constraints).unwrap(), &a);
    let solve = |coarse_direct_limit: usize| {
        let options = crate::SolverOptions {
            coarse_direct_limit,
            ..Default::default()
        };
        let mut multigrid = multigrid(&a, &single, &constraints, &mesh, &options);
        let levels = multigrid.levels.len();
        let mut x = vec![0.0; rhs.len()];
        let its = pcg(&a, &rhs, &mut x, &mut multigrid, 1e-10, 5000);
        (x, its, levels)
    };
    let (direct, direct_its, direct_levels) = solve(usize::MAX);
    let (aggregated, aggregated_its, aggregated_levels) = solve(0);
    // One more smoothed level (p = 1), then the aggregates.
    assert_eq!(aggregated_levels, direct_levels + 1);
    println!("iterations: direct p = 1 solve {direct_its}, aggregates {aggregated_its}");
    assert!(
        aggregated_its <= 3 * direct_its,
        "{aggregated_its} vs {direct_its}"
    );
    let scale = direct.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let difference = direct
        .iter()
        .zip(&aggregated)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(difference <= 1e-8 * scale, "{difference:e} of {scale:e}");
}
