//! The solvers: CG against direct, iteration counts of the p-multigrid preconditioner,
//! sliding walls, thread-count independence and error cases.

use hocurve_elastic::{
    assemble_stiffness, boundary_nodes, solve_displacement, solve_displacement_from,
    solve_displacement_with_load, solve_displacement_with_progress, BoundaryConditions,
    ElasticError, ElasticSolution, Material, SolveProgress, SolverKind, SolverOptions,
};
use hocurve_mesh::{HighOrderMesh, Shape};
use hocurve_nodes::NodeFamily;
use hocurve_testmeshes::{high_order, unit_cube, unit_square, Fill, Kuhn};

/// Bottom face fixed, top face pushed sideways and down with a bump profile: a genuinely
/// 3D deformation.
fn clamped_and_pushed(mesh: &HighOrderMesh) -> BoundaryConditions {
    let mut bc = BoundaryConditions::default();
    for n in boundary_nodes(mesh).unwrap() {
        let x = mesh.nodes[n as usize];
        if x[2] < 1e-12 {
            bc.prescribed.insert(n, [0.0; 3]);
        } else if x[2] > 1.0 - 1e-12 {
            let bump = x[0] * (1.0 - x[0]) * x[1] * (1.0 - x[1]);
            bc.prescribed.insert(n, [0.05, 0.02 * x[0], -0.3 * bump]);
        }
    }
    bc
}

fn solve(mesh: &HighOrderMesh, bc: &BoundaryConditions, kind: SolverKind) -> ElasticSolution {
    let options = SolverOptions {
        kind,
        ..Default::default()
    };
    let gravity = |_: [f64; 3]| [0.0, 0.0, -0.5];
    solve_displacement_with_load(mesh, &Material::default(), bc, Some(&gravity), &options).unwrap()
}

#[test]
fn cg_and_direct_agree_in_3d() {
    for (fill, p) in [
        (Fill::Tet(Kuhn::Paired), 2),
        (Fill::HexPrism, 3),
        (Fill::Hex, 3),
    ] {
        let mesh = high_order(&unit_cube(3, fill, 0.2), p, NodeFamily::Fekete);
        let bc = clamped_and_pushed(&mesh);
        let direct = solve(&mesh, &bc, SolverKind::Direct);
        let cg = solve(&mesh, &bc, SolverKind::Cg);
        assert_eq!(direct.solver_used, SolverKind::Direct);
        assert_eq!(cg.solver_used, SolverKind::Cg);
        assert_eq!(direct.dofs, cg.dofs);
        assert!(cg.relative_residual <= 1e-10, "{}", cg.relative_residual);
        let scale = direct
            .displacement
            .iter()
            .flat_map(|u| u.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = direct
            .displacement
            .iter()
            .zip(&cg.displacement)
            .flat_map(|(a, b)| (0..3).map(move |d| (a[d] - b[d]).abs()))
            .fold(0.0f64, f64::max);
        println!(
            "{fill:?} p={p}: {} dofs, {} CG iterations, max |u| {scale:.3e}, max diff {diff:.2e}",
            cg.dofs, cg.iterations
        );
        assert!(
            diff <= 1e-9 * scale,
            "{fill:?}: CG and direct differ by {diff:e}"
        );
    }
}

#[test]
fn multigrid_iterations_stay_flat_in_p() {
    for fill in [Fill::Tet(Kuhn::Paired), Fill::HexPrism] {
        let linear = unit_cube(3, fill, 0.2);
        let mut counts = Vec::new();
        for p in 1..=5 {
            let mesh = high_order(&linear, p, NodeFamily::Fekete);
            let solution = solve(&mesh, &clamped_and_pushed(&mesh), SolverKind::Cg);
            println!(
                "{fill:?} p = {p}: {} dofs, {} iterations, residual {:.1e}, solve {:.3} s",
                solution.dofs,
                solution.iterations,
                solution.relative_residual,
                solution.timings.solve
            );
            counts.push(solution.iterations);
        }
        // At p = 1 the coarse problem is the problem: the preconditioner is exact.
        assert!(counts[0] <= 2, "{fill:?}: {counts:?}");
        // Slowly growing from p = 2 on, to a tight tolerance (measured: tets 16, 17, 27, 31;
        // hexes and prisms 15, 14, 19, 19; with one order per level instead of two from p = 4,
        // 16, 17, 19, 21 and 15, 14, 14, 14 — more iterations, each cheaper).
        let low = counts[1..].iter().min().copied().unwrap_or(0);
        let high = counts[1..].iter().max().copied().unwrap_or(0);
        assert!(high as f64 <= 2.2 * low as f64, "{fill:?}: {counts:?}");
    }
}

#[test]
fn progress_reports_assembly_set_up_and_every_iteration() {
    let mesh = high_order(
        &unit_cube(2, Fill::Tet(Kuhn::Paired), 0.2),
        3,
        NodeFamily::Fekete,
    );
    let bc = clamped_and_pushed(&mesh);
    for kind in [SolverKind::Cg, SolverKind::Direct] {
        let options = SolverOptions {
            kind,
            ..Default::default()
        };
        let mut events = Vec::new();
        let solution = solve_displacement_with_progress(
            &mesh,
            &Material::default(),
            &bc,
            &options,
            &mut |p| events.push(p),
        )
        .unwrap();
        let fractions: Vec<f64> = events
            .iter()
            .filter_map(|e| match e {
                SolveProgress::Assembly { fraction } => Some(*fraction),
                _ => None,
            })
            .collect();
        assert!(fractions.windows(2).all(|w| w[0] < w[1]), "{fractions:?}");
        assert_eq!(fractions.last(), Some(&1.0));
        assert!(events.contains(&SolveProgress::Setup {
            solver: kind,
            dofs: solution.dofs
        }));
        let iterations: Vec<(usize, f64)> = events
            .iter()
            .filter_map(|e| match e {
                SolveProgress::Iteration {
                    iteration,
                    relative_residual,
                    tolerance,
                } => {
                    assert_eq!(*tolerance, options.tolerance);
                    Some((*iteration, *relative_residual))
                }
                _ => None,
            })
            .collect();
        if kind == SolverKind::Direct {
            assert!(iterations.is_empty());
            continue;
        }
        assert_eq!(iterations.len(), solution.iterations);
        assert!(iterations.iter().enumerate().all(|(k, it)| it.0 == k + 1));
        let last = iterations.last().map_or(f64::NAN, |it| it.1);
        assert!(last <= options.tolerance, "{last}");
        assert!(iterations[0].1 > options.tolerance);
    }
}

#[test]
fn progress_reports_the_last_iteration_of_a_solve_that_does_not_converge() {
    let mesh = high_order(
        &unit_cube(2, Fill::Tet(Kuhn::Paired), 0.2),
        3,
        NodeFamily::Fekete,
    );
    let bc = clamped_and_pushed(&mesh);
    let options = SolverOptions {
        kind: SolverKind::Cg,
        max_iterations: 3,
        ..Default::default()
    };
    let mut iterations = Vec::new();
    let result =
        solve_displacement_with_progress(&mesh, &Material::default(), &bc, &options, &mut |p| {
            if let SolveProgress::Iteration { iteration, .. } = p {
                iterations.push(iteration);
            }
        });
    assert!(matches!(result, Err(ElasticError::NotConverged { .. })));
    assert_eq!(iterations, vec![1, 2, 3]);
}

#[test]
fn a_hand_built_mesh_whose_layout_misses_a_node_is_still_solved() {
    // A node added by hand, outside every cell and held fixed: the layout no longer
    // describes the nodes, so the p-multigrid hierarchy cannot be built; CG must still
    // converge (on the smoother alone), not panic.
    let mut mesh = high_order(
        &unit_cube(2, Fill::Tet(Kuhn::Paired), 0.2),
        3,
        NodeFamily::Fekete,
    );
    let mut bc = clamped_and_pushed(&mesh);
    bc.prescribed.insert(mesh.nodes.len() as u32, [0.0; 3]);
    mesh.nodes.push([2.0, 2.0, 2.0]);
    let solution = solve(&mesh, &bc, SolverKind::Cg);
    assert!(solution.relative_residual <= 1e-10);
}

#[test]
fn sliding_walls_reproduce_uniaxial_stress() {
    // Symmetry planes x = 0, y = 0, z = 0 slide; the face x = 1 is pulled by ε with its
    // lateral contraction prescribed; y = 1, z = 1 are free. The exact solution
    // u = ε (x, −ν y, −ν z) is linear, hence reproduced exactly.
    let material = Material::default();
    let (eps, nu) = (0.01, material.poisson);
    let exact = |x: [f64; 3]| [eps * x[0], -nu * eps * x[1], -nu * eps * x[2]];
    for fill in [Fill::Tet(Kuhn::Paired), Fill::HexPrism] {
        let mesh = high_order(&unit_cube(2, fill, 0.2), 2, NodeFamily::Fekete);
        let mut bc = BoundaryConditions::default();
        for n in boundary_nodes(&mesh).unwrap() {
            let x = mesh.nodes[n as usize];
            if (x[0] - 1.0).abs() < 1e-12 {
                bc.prescribed.insert(n, exact(x));
            } else if let Some(axis) = (0..3).find(|&d| x[d].abs() < 1e-12) {
                let mut normal = [0.0; 3];
                normal[axis] = -2.0; // any length, any sign
                bc.sliding.insert(n, normal);
            }
        }
        for kind in [SolverKind::Direct, SolverKind::Cg] {
            let options = SolverOptions {
                kind,
                tolerance: 1e-13,
                ..Default::default()
            };
            let solution = solve_displacement(&mesh, &material, &bc, &options).unwrap();
            for (x, u) in mesh.nodes.iter().zip(&solution.displacement) {
                let e = exact(*x);
                for d in 0..3 {
                    assert!(
                        (u[d] - e[d]).abs() < 1e-12,
                        "{fill:?} {kind:?} at {x:?}: {u:?}"
                    );
                }
            }
        }
    }
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn results_are_bitwise_identical_for_any_thread_count() {
    let mesh = high_order(
        &unit_cube(3, Fill::Tet(Kuhn::Paired), 0.2),
        3,
        NodeFamily::Fekete,
    );
    let bc = clamped_and_pushed(&mesh);
    let bits = |s: ElasticSolution| -> Vec<u64> {
        s.displacement
            .iter()
            .flat_map(|u| u.map(f64::to_bits))
            .collect()
    };
    let matrix_bits = || -> Vec<u64> {
        let k = assemble_stiffness(&mesh, &Material::default()).unwrap();
        k.data().iter().map(|v| v.to_bits()).collect()
    };
    for kind in [SolverKind::Cg, SolverKind::Direct] {
        let one = in_pool(1, || bits(solve(&mesh, &bc, kind)));
        let two = in_pool(2, || bits(solve(&mesh, &bc, kind)));
        let three = in_pool(3, || bits(solve(&mesh, &bc, kind)));
        assert!(one == two && two == three, "{kind:?}");
    }
    assert!(in_pool(1, matrix_bits) == in_pool(2, matrix_bits));
}

#[test]
fn stiffness_is_symmetric_and_annihilates_rigid_motions() {
    let mesh = high_order(&unit_cube(2, Fill::HexPrism, 0.2), 2, NodeFamily::Fekete);
    let k = assemble_stiffness(&mesh, &Material::default()).unwrap();
    assert_eq!(k.rows(), 3 * mesh.nodes.len());
    let dense = k.to_dense();
    let scale = dense.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // Rigid motions u = a + ω × x have zero strain: K u = 0.
    let motions: [fn([f64; 3]) -> [f64; 3]; 4] = [
        |_| [1.0, 0.0, 0.0],
        |_| [0.0, 0.0, 1.0],
        |x| [-x[1], x[0], 0.0],
        |x| [0.0, -x[2], x[1]],
    ];
    for motion in motions {
        let u: Vec<f64> = mesh.nodes.iter().flat_map(|&x| motion(x)).collect();
        for r in 0..k.rows() {
            let ku: f64 = (0..k.cols()).map(|c| dense[[r, c]] * u[c]).sum();
            assert!(ku.abs() < 1e-12 * scale, "row {r}: {ku}");
        }
    }
    for r in 0..k.rows() {
        for c in 0..r {
            assert!((dense[[r, c]] - dense[[c, r]]).abs() <= 1e-14 * scale);
        }
    }
}

#[test]
fn auto_picks_direct_for_small_problems() {
    let mesh = high_order(&unit_square(2, Shape::Tri, 0.0), 2, NodeFamily::Fekete);
    let mut bc = BoundaryConditions::default();
    for n in boundary_nodes(&mesh).unwrap() {
        bc.prescribed
            .insert(n, [0.0, 0.01 * mesh.nodes[n as usize][0], 0.0]);
    }
    let auto =
        solve_displacement(&mesh, &Material::default(), &bc, &SolverOptions::default()).unwrap();
    assert_eq!(auto.solver_used, SolverKind::Direct);
    assert_eq!(auto.iterations, 0);
    let forced = SolverOptions {
        direct_limit_2d: 0,
        ..Default::default()
    };
    let cg = solve_displacement(&mesh, &Material::default(), &bc, &forced).unwrap();
    assert_eq!(cg.solver_used, SolverKind::Cg);
}

#[test]
fn errors_are_reported() {
    let mesh = high_order(&unit_square(2, Shape::Quad, 0.0), 2, NodeFamily::Fekete);
    let options = SolverOptions::default();
    let free = BoundaryConditions::default();
    assert!(matches!(
        solve_displacement(&mesh, &Material::default(), &free, &options),
        Err(ElasticError::NoDirichlet)
    ));
    let mut bc = BoundaryConditions::default();
    bc.prescribed.insert(0, [0.0; 3]);
    for material in [
        Material {
            young: 10.0,
            poisson: 0.5,
        },
        Material {
            young: -1.0,
            poisson: 0.3,
        },
    ] {
        assert!(matches!(
            solve_displacement(&mesh, &material, &bc, &options),
            Err(ElasticError::InvalidMaterial { .. })
        ));
    }
    let mut far = bc.clone();
    far.prescribed.insert(10_000, [0.0; 3]);
    assert!(matches!(
        solve_displacement(&mesh, &Material::default(), &far, &options),
        Err(ElasticError::NodeOutOfRange { node: 10_000, .. })
    ));
    let mut nan = bc.clone();
    nan.prescribed.insert(1, [f64::NAN, 0.0, 0.0]);
    assert!(matches!(
        solve_displacement(&mesh, &Material::default(), &nan, &options),
        Err(ElasticError::InvalidBoundaryValue { node: 1, .. })
    ));
    let mut flat = bc.clone();
    flat.sliding.insert(2, [0.0; 3]);
    assert!(matches!(
        solve_displacement(&mesh, &Material::default(), &flat, &options),
        Err(ElasticError::InvalidBoundaryValue { node: 2, .. })
    ));
    // One sliding node alone leaves rigid motions free: the factorisation says so.
    let mut loose = BoundaryConditions::default();
    loose.sliding.insert(0, [1.0, 0.0, 0.0]);
    loose.prescribed.clear();
    let gravity = |_: [f64; 3]| [0.0, -1.0, 0.0];
    let err = solve_displacement_with_load(
        &mesh,
        &Material::default(),
        &loose,
        Some(&gravity),
        &SolverOptions {
            kind: SolverKind::Direct,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            ElasticError::Factorization { .. } | ElasticError::NotConverged { .. }
        ),
        "{err}"
    );
}

#[test]
fn cg_stopped_on_the_displacement_tolerance_is_that_close_to_the_solution() {
    let mesh = high_order(
        &unit_cube(4, Fill::Tet(Kuhn::Paired), 0.2),
        3,
        NodeFamily::Fekete,
    );
    let bc = clamped_and_pushed(&mesh);
    let options = |displacement_tolerance| SolverOptions {
        kind: SolverKind::Cg,
        tolerance: 1e-14,
        displacement_tolerance,
        ..Default::default()
    };
    let material = Material::default();
    let exact = solve_displacement(&mesh, &material, &bc, &options(None)).unwrap();
    assert!(!exact.converged_by_displacement);
    for bound in [1e-5, 1e-7, 1e-9] {
        let early = solve_displacement(&mesh, &material, &bc, &options(Some(bound))).unwrap();
        assert!(early.converged_by_displacement, "{bound:e}");
        assert!(
            early.iterations < exact.iterations,
            "{} vs {}",
            early.iterations,
            exact.iterations
        );
        let error = early
            .displacement
            .iter()
            .zip(&exact.displacement)
            .flat_map(|(u, v)| (0..3).map(move |k| (u[k] - v[k]).abs()))
            .fold(0.0, f64::max);
        assert!(
            error <= bound,
            "bound {bound:e}: error {error:.3e} after {} iterations",
            early.iterations
        );
    }
}

#[test]
fn cg_started_near_the_solution_reaches_it_in_fewer_iterations() {
    let mesh = high_order(
        &unit_cube(4, Fill::Tet(Kuhn::Paired), 0.2),
        3,
        NodeFamily::Fekete,
    );
    let bc = clamped_and_pushed(&mesh);
    let options = SolverOptions {
        kind: SolverKind::Cg,
        ..Default::default()
    };
    let material = Material::default();
    let cold = solve_displacement(&mesh, &material, &bc, &options).unwrap();
    // A nearby problem's solution: this one's, off by 1e-3 of itself, with the prescribed
    // values wrong too (the boundary conditions override them).
    let nearby: Vec<[f64; 3]> = cold
        .displacement
        .iter()
        .enumerate()
        .map(|(n, u)| u.map(|v| v * (1.0 + 1e-3 * ((n % 7) as f64 - 3.0))))
        .collect();
    let warm = solve_displacement_from(&mesh, &material, None, &bc, &nearby, &options, &mut |_| {})
        .unwrap();
    println!(
        "{} iterations cold, {} warm",
        cold.iterations, warm.iterations
    );
    assert!(warm.iterations < cold.iterations);
    assert!(warm.relative_residual <= 1e-10);
    let scale = cold
        .displacement
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = cold
        .displacement
        .iter()
        .zip(&warm.displacement)
        .flat_map(|(a, b)| (0..3).map(move |d| (a[d] - b[d]).abs()))
        .fold(0.0f64, f64::max);
    assert!(diff <= 1e-9 * scale, "{diff:e}");
    for (&n, u) in &bc.prescribed {
        assert_eq!(warm.displacement[n as usize], *u);
    }
    // Started from the solution itself: no iteration beyond the check.
    let exact = solve_displacement_from(
        &mesh,
        &material,
        None,
        &bc,
        &cold.displacement,
        &options,
        &mut |_| {},
    )
    .unwrap();
    assert!(exact.iterations <= 1, "{}", exact.iterations);

    // Not one finite displacement per node: an error, not a guess.
    for bad in [vec![[0.0; 3]; 3], {
        let mut u = nearby.clone();
        u[5][1] = f64::NAN;
        u
    }] {
        let result =
            solve_displacement_from(&mesh, &material, None, &bc, &bad, &options, &mut |_| {});
        assert!(
            matches!(result, Err(ElasticError::InvalidInitialGuess { .. })),
            "{result:?}"
        );
    }
}

#[test]
fn nodes_where_two_sliding_planes_meet_move_along_their_line() {
    // As above, with each node on two symmetry planes held to their common line and the
    // corner on three fixed: the same exact solution, and line nodes move along the line.
    let material = Material::default();
    let (eps, nu) = (0.01, material.poisson);
    let exact = |x: [f64; 3]| [eps * x[0], -nu * eps * x[1], -nu * eps * x[2]];
    for fill in [Fill::Tet(Kuhn::Paired), Fill::HexPrism] {
        let mesh = high_order(&unit_cube(2, fill, 0.2), 3, NodeFamily::Fekete);
        let mut bc = BoundaryConditions::default();
        for n in boundary_nodes(&mesh).unwrap() {
            let x = mesh.nodes[n as usize];
            let planes: Vec<usize> = (0..3).filter(|&d| x[d].abs() < 1e-12).collect();
            if (x[0] - 1.0).abs() < 1e-12 {
                bc.prescribed.insert(n, exact(x));
            } else if planes.len() == 3 {
                bc.prescribed.insert(n, [0.0; 3]);
            } else if planes.len() == 2 {
                let free = 3 - planes[0] - planes[1];
                let mut direction = [0.0; 3];
                direction[free] = 0.5;
                bc.along_line.insert(n, direction);
                // A sliding entry too: the line takes precedence.
                bc.sliding.insert(n, [1.0, 0.0, 0.0]);
            } else if planes.len() == 1 {
                let mut normal = [0.0; 3];
                normal[planes[0]] = 1.0;
                bc.sliding.insert(n, normal);
            }
        }
        for kind in [SolverKind::Direct, SolverKind::Cg] {
            let options = SolverOptions {
                kind,
                tolerance: 1e-13,
                ..Default::default()
            };
            let solution = solve_displacement(&mesh, &material, &bc, &options).unwrap();
            for (n, (x, u)) in mesh.nodes.iter().zip(&solution.displacement).enumerate() {
                let e = exact(*x);
                for d in 0..3 {
                    assert!(
                        (u[d] - e[d]).abs() < 1e-12,
                        "{fill:?} {kind:?} at {x:?}: {u:?}"
                    );
                }
                if let Some(t) = bc.along_line.get(&(n as u32)) {
                    let off: f64 = (0..3).filter(|&d| t[d] == 0.0).map(|d| u[d].abs()).sum();
                    assert_eq!(off, 0.0, "{fill:?} {kind:?}: {u:?} along {t:?}");
                }
            }
        }
    }
    // A zero direction is an error, not a fixed node.
    let mesh = high_order(
        &unit_cube(1, Fill::Tet(Kuhn::Paired), 0.0),
        1,
        NodeFamily::Fekete,
    );
    let mut bc = BoundaryConditions::default();
    bc.prescribed.insert(0, [0.0; 3]);
    bc.along_line.insert(1, [0.0; 3]);
    let result = solve_displacement(&mesh, &Material::default(), &bc, &SolverOptions::default());
    assert!(
        matches!(
            result,
            Err(ElasticError::InvalidBoundaryValue { node: 1, .. })
        ),
        "{result:?}"
    );
}
