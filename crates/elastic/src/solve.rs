//! The public entry point: assemble, condense, solve, check, expand.

use std::time::Instant;

use hocurve_mesh::HighOrderMesh;

use crate::aggregation::DIRECT_COARSE_LIMIT;
use crate::assembly::{assemble_condensed, assemble_load, Assembled, BodyForce};
use crate::block_matrix::{BlockOperator, BlockPattern};
use crate::condensation::Constraints;
use crate::matrix_free::MatrixFreeStiffness;
use crate::p_multigrid::PMultigrid;
use crate::pcg::{pcg_with_progress, LinearOperator};
use crate::sparse::Cholesky;
use crate::vector_ops::norm;
use crate::{BoundaryConditions, ElasticError, Material};

/// Which linear solver to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SolverKind {
    /// Direct below [`SolverOptions::direct_limit_2d`] / [`SolverOptions::direct_limit_3d`]
    /// unknowns, else CG.
    #[default]
    Auto,
    /// Sparse Cholesky (faer) of the condensed system.
    Direct,
    /// Conjugate gradients with the p-multigrid preconditioner.
    Cg,
}

impl std::str::FromStr for SolverKind {
    type Err = String;
    /// "auto", "direct" or "cg" (as on the command line).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "auto" => Ok(Self::Auto),
            "direct" => Ok(Self::Direct),
            "cg" => Ok(Self::Cg),
            _ => Err(format!(
                "unknown solver \"{s}\" (expected auto, direct or cg)"
            )),
        }
    }
}

/// Options of [`solve_displacement`].
#[derive(Debug, Clone, PartialEq)]
pub struct SolverOptions {
    /// Solver choice.
    pub kind: SolverKind,
    /// CG stops when ‖r‖ ≤ tolerance · ‖b‖ (default 1e-10).
    pub tolerance: f64,
    /// CG also stops once its estimate of the largest error of a displacement component
    /// (tangential on sliding walls) is at most this length (see `pcg`'s error estimate);
    /// the residual limit is then not required. None (the default): the residual alone.
    pub displacement_tolerance: Option<f64>,
    /// CG iteration limit (default 2000).
    pub max_iterations: usize,
    /// Degree of the Chebyshev smoother of every p-multigrid level (default 3).
    pub smoother_degree: usize,
    /// `Auto` solves 2D problems with at most this many unknowns directly.
    pub direct_limit_2d: usize,
    /// `Auto` solves 3D problems with at most this many unknowns directly.
    pub direct_limit_3d: usize,
    /// CG's p-multigrid factorises its p = 1 problem when it has at most this many
    /// unknowns; above, the p = 1 level is smoothed and corrected from aggregates of
    /// vertices carrying the rigid-body modes, whose far smaller system is factorised (a
    /// Cholesky factor of a 3D problem costs ~ n²: 48 s at 140 k unknowns).
    pub coarse_direct_limit: usize,
    /// CG applies the stiffness of meshes of straight simplices (tets, triangles) cell by
    /// cell from reference factors instead of assembling it, on every p-multigrid level
    /// above p = 1 (see `matrix_free`): no matrix in memory, no assembly time. Default true;
    /// false assembles (kept for comparison; results agree to round-off).
    pub matrix_free: bool,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            kind: SolverKind::Auto,
            tolerance: 1e-10,
            displacement_tolerance: None,
            max_iterations: 2000,
            smoother_degree: 3,
            // Measured (release, 2-core machine): in 2D faer's Cholesky beats the
            // p-multigrid CG (12-15 iterations) up to at least ~600 k unknowns (318 k: 2.8 s
            // vs 3.1 s, 625 k: 5.7 s vs 6.3 s; examples/direct_vs_cg_2d.rs); in 3D CG wins
            // from ~2 k unknowns on (sphere p = 2, 19 k: 1.5 s vs 0.2 s;
            // examples/sphere_iterations.rs).
            direct_limit_2d: 500_000,
            direct_limit_3d: 5_000,
            coarse_direct_limit: DIRECT_COARSE_LIMIT,
            matrix_free: true,
        }
    }
}

/// Wall-clock seconds of the two phases, and of the parts of a CG solve.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Timings {
    /// Stiffness, load and condensation.
    pub assembly: f64,
    /// Preconditioner or factorisation set-up and the solve (includes the three below).
    pub solve: f64,
    /// CG: the coarser p-multigrid levels (meshes, assembly, prolongations) and the p = 1
    /// factorisation.
    pub coarse_setup: f64,
    /// CG: the smoother's block inverses and spectrum estimate.
    pub smoother_setup: f64,
    /// CG: the iterations.
    pub iterations: f64,
}

/// The displacement field and how it was obtained.
#[derive(Debug, Clone, PartialEq)]
pub struct ElasticSolution {
    /// Displacement of every node (z = 0 in 2D).
    pub displacement: Vec<[f64; 3]>,
    /// `Direct` or `Cg` (never `Auto`).
    pub solver_used: SolverKind,
    /// CG iterations (0 for the direct solver).
    pub iterations: usize,
    /// True relative residual ‖b − A x‖ / ‖b‖ of the condensed system (0 if b = 0).
    pub relative_residual: f64,
    /// CG stopped on [`SolverOptions::displacement_tolerance`], before the residual reached
    /// its tolerance.
    pub converged_by_displacement: bool,
    /// Number of unknowns of the condensed system.
    pub dofs: usize,
    /// Timings.
    pub timings: Timings,
}

/// What [`solve_displacement_with_progress`] reports while it runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolveProgress {
    /// The fraction of the cells whose stiffness is assembled.
    Assembly {
        /// In [0, 1].
        fraction: f64,
    },
    /// The factorisation (direct) or the preconditioner (CG) is being set up.
    Setup {
        /// `Direct` or `Cg`.
        solver: SolverKind,
        /// Unknowns of the condensed system.
        dofs: usize,
    },
    /// A CG iteration is done.
    Iteration {
        /// 1, 2, …
        iteration: usize,
        /// The updated relative residual ‖r‖ / ‖b‖.
        relative_residual: f64,
        /// The relative residual CG stops at.
        tolerance: f64,
    },
}

/// The condensed system: assembled, or applied cell by cell.
enum System {
    Assembled(Box<Assembled>),
    MatrixFree(Box<MatrixFreeStiffness>),
}

/// The largest acceptable true relative residual.
const RESIDUAL_LIMIT: f64 = 1e-8;

/// Solves the elasticity problem K u = 0 (no body force) with the given boundary
/// conditions; see [`solve_displacement_with_load`].
pub fn solve_displacement(
    mesh: &HighOrderMesh,
    material: &Material,
    bc: &BoundaryConditions,
    options: &SolverOptions,
) -> Result<ElasticSolution, ElasticError> {
    solve_displacement_with_load(mesh, material, bc, None, options)
}

/// Solves −div σ(u) = f in the mesh with the boundary conditions `bc` (the paper's Eqs.
/// (1)–(3); f = 0 for mesh curving), by a direct or a p-multigrid PCG solve of the condensed
/// system. The true relative residual is always computed; an error if it exceeds
/// max(1e-8, `options.tolerance`).
pub fn solve_displacement_with_load(
    mesh: &HighOrderMesh,
    material: &Material,
    bc: &BoundaryConditions,
    body_force: Option<&BodyForce<'_>>,
    options: &SolverOptions,
) -> Result<ElasticSolution, ElasticError> {
    solve(
        mesh,
        material,
        None,
        bc,
        body_force,
        None,
        options,
        &mut |_| {},
    )
}

/// [`solve_displacement`], reporting the assembly's and the solve's progress to
/// `progress` (for progress bars).
pub fn solve_displacement_with_progress(
    mesh: &HighOrderMesh,
    material: &Material,
    bc: &BoundaryConditions,
    options: &SolverOptions,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<ElasticSolution, ElasticError> {
    solve(mesh, material, None, bc, None, None, options, progress)
}

/// [`solve_displacement_with_progress`] with cell c's Young's modulus multiplied by
/// `stiffening[c]` (finite, > 0; one per cell): a solid stiffer where it must not distort,
/// e.g. E_c ∝ 1/|J_c| so that small cells move rigidly (Tezduyar's Jacobian-based
/// stiffening).
pub fn solve_displacement_stiffened(
    mesh: &HighOrderMesh,
    material: &Material,
    stiffening: &[f64],
    bc: &BoundaryConditions,
    options: &SolverOptions,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<ElasticSolution, ElasticError> {
    solve(
        mesh,
        material,
        Some(stiffening),
        bc,
        None,
        None,
        options,
        progress,
    )
}

/// [`solve_displacement_with_progress`] (stiffened cell by cell when `stiffening` is
/// given, as in [`solve_displacement_stiffened`]) with CG started from `initial`, a
/// displacement of every node close to the solution — e.g. the solution of a nearby problem
/// (a smaller region, other stiffening): CG then needs fewer iterations to reach the same
/// accuracy. Its prescribed components are ignored (the boundary conditions set them) and
/// its normal components on sliding nodes are dropped. The direct solver ignores it.
pub fn solve_displacement_from(
    mesh: &HighOrderMesh,
    material: &Material,
    stiffening: Option<&[f64]>,
    bc: &BoundaryConditions,
    initial: &[[f64; 3]],
    options: &SolverOptions,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<ElasticSolution, ElasticError> {
    solve(
        mesh,
        material,
        stiffening,
        bc,
        None,
        Some(initial),
        options,
        progress,
    )
}

#[allow(clippy::too_many_arguments)]
fn solve(
    mesh: &HighOrderMesh,
    material: &Material,
    stiffening: Option<&[f64]>,
    bc: &BoundaryConditions,
    body_force: Option<&BodyForce<'_>>,
    initial: Option<&[[f64; 3]]>,
    options: &SolverOptions,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<ElasticSolution, ElasticError> {
    material.validate()?;
    bc.validate(mesh.nodes.len(), mesh.dim)?;
    if let Some(initial) = initial {
        if initial.len() != mesh.nodes.len() {
            return Err(ElasticError::InvalidInitialGuess {
                reason: format!(
                    "{} displacements for {} nodes",
                    initial.len(),
                    mesh.nodes.len()
                ),
            });
        }
        if let Some(n) = initial
            .iter()
            .position(|u| u.iter().any(|v| !v.is_finite()))
        {
            return Err(ElasticError::InvalidInitialGuess {
                reason: format!("node {n}'s displacement is not finite"),
            });
        }
    }
    if bc.prescribed.is_empty() && bc.sliding.is_empty() && bc.along_line.is_empty() {
        return Err(ElasticError::NoDirichlet);
    }
    let start = Instant::now();
    let dim = mesh.dim;
    let constraints = Constraints::new(mesh.nodes.len(), dim, bc);
    let dofs = constraints.len();
    let solver = match options.kind {
        SolverKind::Auto => {
            let limit = if dim == 2 {
                options.direct_limit_2d
            } else {
                options.direct_limit_3d
            };
            if dofs <= limit {
                SolverKind::Direct
            } else {
                SolverKind::Cg
            }
        }
        other => other,
    };
    let matrix_free = solver == SolverKind::Cg
        && options.matrix_free
        && mesh.order >= 2
        && MatrixFreeStiffness::applies(mesh);
    // b = Tᵀ (F − K u_p), and the matrix Tᵀ K T straight from the elements, or the
    // operator applying it cell by cell.
    let (system, mut rhs) = if matrix_free {
        let operator = MatrixFreeStiffness::new(mesh, material, stiffening, &constraints)?;
        let rhs = operator.prescribed_load(&constraints);
        progress(SolveProgress::Assembly { fraction: 1.0 });
        (System::MatrixFree(Box::new(operator)), rhs)
    } else {
        let mut assembled =
            assemble_condensed(mesh, material, stiffening, &constraints, &mut |fraction| {
                progress(SolveProgress::Assembly { fraction })
            })?;
        let rhs = std::mem::take(&mut assembled.rhs);
        (System::Assembled(Box::new(assembled)), rhs)
    };
    if let Some(f) = body_force {
        let load = constraints.restrict(&assemble_load(mesh, f)?);
        rhs.iter_mut().zip(&load).for_each(|(r, l)| *r += l);
    }
    let assembly_time = start.elapsed().as_secs_f64();

    let start = Instant::now();
    // The free components of the initial guess: y_n = Q_n u_n (u = T y + u_p, and u_p
    // vanishes on the nodes that keep free directions).
    let mut x = match (initial, solver) {
        (Some(initial), SolverKind::Cg) => {
            let full: Vec<f64> = initial.iter().flat_map(|u| u[..dim].to_vec()).collect();
            constraints.restrict(&full)
        }
        _ => vec![0.0; dofs],
    };
    let mut iterations = 0;
    let mut by_displacement = false;
    let (mut coarse_setup, mut smoother_setup, mut iteration_time) = (0.0, 0.0, 0.0);
    let b_norm = norm(&rhs);
    // ‖b − A x‖ / ‖b‖ (0 when b = 0).
    let relative = |a: &dyn LinearOperator, x: &[f64]| {
        if b_norm > 0.0 {
            let mut r = vec![0.0; dofs];
            a.residual(&rhs, x, &mut r);
            norm(&r) / b_norm
        } else {
            0.0
        }
    };
    let relative_residual = if dofs > 0 && b_norm > 0.0 {
        progress(SolveProgress::Setup { solver, dofs });
        let mut cg = |a: &dyn LinearOperator, preconditioner: &mut PMultigrid| {
            coarse_setup = preconditioner.coarse_seconds;
            smoother_setup = preconditioner.smoother_seconds;
            let start = Instant::now();
            let tolerance = options.tolerance;
            let outcome = pcg_with_progress(
                a,
                &rhs,
                &mut x,
                preconditioner,
                tolerance,
                options.displacement_tolerance,
                options.max_iterations,
                &mut |iteration, relative_residual| {
                    progress(SolveProgress::Iteration {
                        iteration,
                        relative_residual,
                        tolerance,
                    })
                },
            );
            iterations = outcome.iterations;
            by_displacement = outcome.by_error_estimate;
            iteration_time = start.elapsed().as_secs_f64();
        };
        match system {
            System::Assembled(assembled) => {
                let Assembled {
                    matrix,
                    graph,
                    cells_of_node,
                    ..
                } = *assembled;
                if solver == SolverKind::Direct {
                    x.copy_from_slice(&rhs);
                    Cholesky::new(&matrix, "condensed system")?.solve_in_place(&mut x);
                    relative(&matrix, &x)
                } else {
                    // The smoothers' mat-vecs in node-block f32 (0.8× the time of the f64
                    // CSR one: block_matrix::tests::mat_vec_timings); CG's own mat-vec and
                    // the residual check in f64 node blocks, once the preconditioner is built
                    // from the CSR matrix: as fast as CSR, without its column indices (a
                    // quarter of its memory).
                    let pattern = BlockPattern::new(&matrix, &graph, &constraints);
                    let smoothing: Box<dyn LinearOperator> = match &pattern {
                        Some(p) => Box::new(BlockOperator::single(p.clone(), &matrix)),
                        // Beyond 2³⁰ unknowns (no machine we know holds them): a CSR copy.
                        None => Box::new(matrix.clone()),
                    };
                    let (mut preconditioner, exact) = PMultigrid::new(
                        matrix,
                        pattern,
                        &*smoothing,
                        &constraints,
                        mesh,
                        &cells_of_node,
                        material,
                        stiffening,
                        options,
                    )?;
                    cg(&*exact, &mut preconditioner);
                    relative(&*exact, &x)
                }
            }
            System::MatrixFree(operator) => {
                let mut preconditioner = PMultigrid::matrix_free(
                    &operator,
                    &constraints,
                    mesh,
                    material,
                    stiffening,
                    options,
                )?;
                cg(&*operator, &mut preconditioner);
                relative(&*operator, &x)
            }
        }
    } else {
        0.0
    };
    let solve_time = start.elapsed().as_secs_f64();
    let limit = RESIDUAL_LIMIT.max(options.tolerance);
    if relative_residual.is_nan() || (relative_residual > limit && !by_displacement) {
        return Err(ElasticError::NotConverged {
            solver: if solver == SolverKind::Direct {
                "direct"
            } else {
                "cg"
            },
            iterations,
            residual: relative_residual,
            limit,
        });
    }
    Ok(ElasticSolution {
        displacement: constraints.expand(&x),
        solver_used: solver,
        iterations,
        relative_residual,
        converged_by_displacement: by_displacement,
        dofs,
        timings: Timings {
            assembly: assembly_time,
            solve: solve_time,
            coarse_setup,
            smoother_setup,
            iterations: iteration_time,
        },
    })
}
