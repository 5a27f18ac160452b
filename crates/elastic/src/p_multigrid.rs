//! The preconditioner of the PCG solver: a p-multigrid V-cycle over orders p → … → 1 on
//! the same mesh (see [`level_orders`]), with an exact solve of the p = 1 problem on the
//! vertices.
//!
//! Each coarser order q is the straight-sided mesh of order q on the same vertices and cells
//! ([`HighOrderMesh::straight_of_order`]), its stiffness matrix assembled afresh (for
//! straight simplices this is the Galerkin product Pᵀ A P, at a fraction of its cost) and
//! condensed with the constraints of the finest level carried over entity by entity: a
//! node of order q on a vertex, edge, face or cell takes the free directions of the order-p
//! nodes of that entity (prescribed facets stay fixed, sliding facets slide in the same
//! plane), with homogeneous values since the cycle works on corrections. The prolongation
//! P from order q to order r is Lagrange interpolation: an order-r node takes the values of
//! the order-q basis of a cell containing it at its reference position (exact, since the
//! order-q space lies inside the order-r one), rotated into the nodes' free directions.
//!
//! One application z = M r at a level with operator A and smoother S (see
//! [`crate::smoother`]), symmetric so that PCG stays valid:
//!
//! z = S r;  e = M_c Pᵀ (r − A z);  z ← z + P e;  z ← z + S (r − A z),
//!
//! with M_c the V-cycle of the next coarser order and, at p = 1, the sparse Cholesky
//! solve. Every M_c is SPD, so M is SPD whenever the smoothers converge (the symmetric two-grid argument,
//! applied level by level).

use std::collections::BTreeMap;
use std::time::Instant;

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::Shape;
use rayon::prelude::*;

use crate::aggregation::aggregation_level;
use crate::assembly::assemble_condensed;
use crate::block_jacobi::{dof_cuts, entity_node_cuts};
use crate::block_matrix::{BlockOperator, BlockPattern};
use crate::condensation::Constraints;
use crate::matrix_free::{MatrixFreeStiffness, SinglePrecision};
use crate::pcg::{LinearOperator, Preconditioner};
use crate::smoother::{ChebyshevSmoother, SmootherScratch};
use crate::sparse::{from_rows, transpose, Cholesky};
use crate::sparsity::{node_cells, Adjacency};
use crate::transfer::{interpolation_weights, CellTransfer};
use crate::vector_ops::spmv;
use crate::{ElasticError, Material, SolverOptions, StiffnessMatrix};

/// The orders of the hierarchy for a mesh of order p: two orders down per level while the
/// order is at least 4, then one (p = 4: 4, 2, 1; p = 5: 5, 3, 2, 1; p = 8: 8, 6, 4, 2, 1).
///
/// The curving solves stop once the displacement error is far below the geometry's
/// tolerance (5–10 iterations), so a level's set-up (operator, block inverses, spectrum
/// estimate) weighs as much as its share of the iterations. Measured on the 6 k sphere
/// (whole process, best of 5, 2 cores), one order per level against this: p = 4 0.62 s
/// (5 CG iterations) against 0.56 s (7); p = 5 1.46 s (6) against 1.38 s (9); with 8
/// Lanczos steps on both sides, p = 6 3.5 s (8) against 3.2 s (11), p = 8 23 s (15)
/// against 21 s (22). Halving the order from p = 5 on (5, 2, 1; 6, 3, 1) cost more
/// iterations than it saved (11 and 14).
pub(crate) fn level_orders(p: usize) -> Vec<usize> {
    let mut orders = vec![p.max(1)];
    let mut q = p.max(1);
    while q > 1 {
        q = if q >= 4 { q - 2 } else { q - 1 };
        orders.push(q);
    }
    orders
}

/// Chebyshev degree of the matrix-free levels of order p − 2 and below (the finest level
/// keeps [`SolverOptions::smoother_degree`]). Measured (CG iterations, 3 → 2) with one
/// order per level: coarse sphere p = 6 8 → 8, p = 8 15 → 15; 6 k sphere p = 4 5 → 5;
/// boundary-layer tetrahedra (`sphere_layers_coarse`, p = 4) 64 → 66; a third fewer
/// mat-vecs on those levels, which cost about as much as the finest one together. Degree
/// 2 on the p − 1 level too cost iterations everywhere (15 → 16, 5 → 6, 64 → 70).
const LOW_LEVEL_SMOOTHER_DEGREE: usize = 2;

/// From a level's next coarser unknowns to its own, and back.
enum Transfer {
    /// P and Pᵀ as sparse matrices.
    Matrices {
        prolongation: StiffnessMatrix,
        restriction: StiffnessMatrix,
    },
    /// Applied cell by cell.
    Cells(Box<CellTransfer>),
}

impl Transfer {
    fn matrix(prolongation: StiffnessMatrix) -> Self {
        let restriction = transpose(&prolongation);
        Transfer::Matrices {
            prolongation,
            restriction,
        }
    }

    fn coarse_len(&self) -> usize {
        match self {
            Transfer::Matrices { prolongation, .. } => prolongation.cols(),
            Transfer::Cells(t) => t.coarse_len(),
        }
    }

    /// fine = P coarse.
    fn prolong(&self, coarse: &[f64], fine: &mut [f64]) {
        match self {
            Transfer::Matrices { prolongation, .. } => spmv(prolongation, coarse, fine),
            Transfer::Cells(t) => t.prolong(coarse, fine),
        }
    }

    /// coarse = Pᵀ fine.
    fn restrict(&self, fine: &[f64], coarse: &mut [f64]) {
        match self {
            Transfer::Matrices { restriction, .. } => spmv(restriction, fine, coarse),
            Transfer::Cells(t) => t.restrict(fine, coarse),
        }
    }
}

/// A level above the coarsest.
struct Level<'a> {
    /// The operator of the smoother and the residuals: the caller's on the finest level,
    /// an f32 node-block copy of the matrix on the others (the f64 matrix is dropped once
    /// the smoother is set up).
    operator: Box<dyn LinearOperator + 'a>,
    smoother: ChebyshevSmoother,
    /// From the next coarser level's unknowns to this level's.
    transfer: Transfer,
    smoothing: SmootherScratch,
    /// This level's residual and post-smoothing correction.
    residual: Vec<f64>,
    correction: Vec<f64>,
    /// The next coarser level's right-hand side and solution.
    coarse_rhs: Vec<f64>,
    coarse_solution: Vec<f64>,
}

/// The p-multigrid preconditioner.
pub(crate) struct PMultigrid<'a> {
    /// Finest first; the coarsest (p = 1) level is `coarsest`.
    levels: Vec<Level<'a>>,
    /// None when the p = 1 problem has no unknowns (every vertex fixed).
    coarsest: Option<Cholesky>,
    /// Seconds spent on the coarse levels (meshes, assembly, prolongations, factorisation)
    /// and on the smoothers (block inverses, spectrum estimates).
    pub coarse_seconds: f64,
    pub smoother_seconds: f64,
}

/// What the set-up needs of a level besides its matrix.
pub(crate) struct LevelMesh<'m> {
    pub mesh: std::borrow::Cow<'m, HighOrderMesh>,
    pub constraints: std::borrow::Cow<'m, Constraints>,
    /// The cells holding each node, where the caller has them (assembled levels); the
    /// matrix transfers use them, the cell-by-cell ones do not.
    pub cells_of_node: Option<std::borrow::Cow<'m, Adjacency>>,
}

impl<'a> PMultigrid<'a> {
    /// The preconditioner of `matrix`, the condensed stiffness matrix of `mesh` under
    /// `constraints`; the finest smoother's mat-vecs go through `a`, an operator equal (or
    /// close) to `matrix`. `options` give the Chebyshev degree of every smoother and the size
    /// above which the p = 1 level is aggregated rather than factorised.
    ///
    /// Also returns `matrix` as CG's operator: in the f64 node-block form of `exact_pattern`
    /// when given, converted as soon as the finest smoother is built, so that the CSR column
    /// indices (a quarter of the matrix) are freed before the coarser levels are assembled.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        matrix: StiffnessMatrix,
        exact_pattern: Option<BlockPattern>,
        a: &'a dyn LinearOperator,
        constraints: &Constraints,
        mesh: &HighOrderMesh,
        cells_of_node: &Adjacency,
        material: &Material,
        stiffening: Option<&[f64]>,
        options: &SolverOptions,
    ) -> Result<(Self, Box<dyn LinearOperator>), ElasticError> {
        let degree = options.smoother_degree;
        let start = Instant::now();
        let exact = |matrix: StiffnessMatrix| -> Box<dyn LinearOperator> {
            match exact_pattern {
                Some(p) => Box::new(BlockOperator::double(p, matrix)),
                None => Box::new(matrix),
            }
        };
        if mesh.order <= 1 {
            // The coarse problem is the problem: solve it exactly.
            let coarsest = Some(Cholesky::new(&matrix, "coarse matrix")?);
            let multigrid = PMultigrid {
                levels: Vec::new(),
                coarsest,
                coarse_seconds: start.elapsed().as_secs_f64(),
                smoother_seconds: 0.0,
            };
            return Ok((multigrid, exact(matrix)));
        }
        let mut smoother_seconds = 0.0;
        let finest = LevelMesh {
            mesh: std::borrow::Cow::Borrowed(mesh),
            constraints: std::borrow::Cow::Borrowed(constraints),
            cells_of_node: Some(std::borrow::Cow::Borrowed(cells_of_node)),
        };
        let smoother = {
            let start = Instant::now();
            let cuts = dof_cuts(&entity_node_cuts(mesh), &constraints.first);
            let smoother = ChebyshevSmoother::new(&matrix, a, &cuts, degree);
            smoother_seconds += start.elapsed().as_secs_f64();
            smoother
        };
        let exact = exact(matrix);
        let multigrid = Self::with_coarse_levels(
            (Box::new(a), smoother),
            finest,
            material,
            stiffening,
            options,
            false,
            start,
            smoother_seconds,
        )?;
        Ok((multigrid, exact))
    }

    /// The preconditioner of the matrix-free operator `a` of `mesh` under `constraints`:
    /// its levels of order ≥ 2 matrix-free too, the p = 1 level assembled.
    pub fn matrix_free(
        a: &'a MatrixFreeStiffness,
        constraints: &Constraints,
        mesh: &HighOrderMesh,
        material: &Material,
        stiffening: Option<&[f64]>,
        options: &SolverOptions,
    ) -> Result<Self, ElasticError> {
        let start = Instant::now();
        let finest = LevelMesh {
            mesh: std::borrow::Cow::Borrowed(mesh),
            constraints: std::borrow::Cow::Borrowed(constraints),
            cells_of_node: None,
        };
        // The finest smoother's spectrum estimate (parallel mat-vecs) and the coarser levels
        // (largely serial: meshes, the p = 1 assembly and factorisation) built together, so
        // that both cores stay busy (6 k sphere at p = 4: set-up 105 → 93 ms, best of 7).
        let ((smoother, smoother_seconds), mut coarse) = rayon::join(
            || {
                let begin = Instant::now();
                let smoother = matrix_free_smoother(a, &finest, options.smoother_degree);
                (smoother, begin.elapsed().as_secs_f64())
            },
            || CoarseLevels::new(&finest, material, stiffening, options, true),
        );
        // Their smoothers' time is in the wall time the coarse levels add.
        if let Ok(coarse) = &mut coarse {
            coarse.smoother_seconds = 0.0;
        }
        Ok(Self::stacked(
            (Box::new(SinglePrecision(a)), smoother),
            coarse?,
            start,
            smoother_seconds,
        ))
    }

    /// The hierarchy below the finest level (its operator and smoother given): the orders
    /// of [`level_orders`] below p on the same cells, matrix-free above p = 1 when
    /// `matrix_free`.
    #[allow(clippy::too_many_arguments)]
    fn with_coarse_levels(
        finest: (Box<dyn LinearOperator + 'a>, ChebyshevSmoother),
        finest_mesh: LevelMesh,
        material: &Material,
        stiffening: Option<&[f64]>,
        options: &SolverOptions,
        matrix_free: bool,
        start: Instant,
        smoother_seconds: f64,
    ) -> Result<Self, ElasticError> {
        let coarse = CoarseLevels::new(&finest_mesh, material, stiffening, options, matrix_free)?;
        Ok(Self::stacked(finest, coarse, start, smoother_seconds))
    }

    /// The finest level's operator and smoother on top of the coarser levels; `start` is
    /// when the set-up began, `finest_smoother_seconds` the finest smoother's share.
    fn stacked(
        finest: (Box<dyn LinearOperator + 'a>, ChebyshevSmoother),
        coarse: CoarseLevels<'a>,
        start: Instant,
        finest_smoother_seconds: f64,
    ) -> Self {
        let CoarseLevels {
            smoothers: coarse_smoothers,
            sizes,
            transfers,
            coarsest,
            smoother_seconds,
        } = coarse;
        let smoother_seconds = finest_smoother_seconds + smoother_seconds;
        // With the coarse levels built during the finest smoother's set-up: what they add.
        let coarse_seconds = (start.elapsed().as_secs_f64() - smoother_seconds).max(0.0);
        let smoothers = std::iter::once(finest).chain(
            coarse_smoothers
                .into_iter()
                .map(|(operator, smoother)| (operator as Box<dyn LinearOperator + 'a>, smoother)),
        );
        let mut levels = Vec::new();
        let mut transfers = transfers.into_iter();
        for ((operator, smoother), size) in smoothers.zip(sizes) {
            let transfer = transfers
                .next()
                .unwrap_or_else(|| Transfer::matrix(from_rows(0, vec![Vec::new(); size])));
            let coarse_size = transfer.coarse_len();
            levels.push(Level {
                operator,
                smoother,
                transfer,
                smoothing: SmootherScratch::new(size),
                residual: vec![0.0; size],
                correction: vec![0.0; size],
                coarse_rhs: vec![0.0; coarse_size],
                coarse_solution: vec![0.0; coarse_size],
            });
        }
        PMultigrid {
            levels,
            coarsest,
            coarse_seconds,
            smoother_seconds,
        }
    }
}

/// The levels below the finest of a [`PMultigrid`]: built on their own, so that the matrix-
/// free set-up can build them while the finest smoother estimates its spectrum.
struct CoarseLevels<'a> {
    /// The operator and smoother of each level below the finest, the finer first.
    smoothers: Vec<(Box<dyn LinearOperator + Send + 'a>, ChebyshevSmoother)>,
    /// The unknowns of every level, the finest's first.
    sizes: Vec<usize>,
    /// From each level's next coarser unknowns to its own.
    transfers: Vec<Transfer>,
    /// The p = 1 factorisation, if the hierarchy reached it.
    coarsest: Option<Cholesky>,
    /// Seconds spent setting up these levels' smoothers.
    smoother_seconds: f64,
}

impl<'a> CoarseLevels<'a> {
    /// The orders of [`level_orders`] below the finest one on the same cells, matrix-free
    /// above p = 1 when `matrix_free`.
    fn new(
        finest_mesh: &LevelMesh,
        material: &Material,
        stiffening: Option<&[f64]>,
        options: &SolverOptions,
        matrix_free: bool,
    ) -> Result<Self, ElasticError> {
        let degree = options.smoother_degree;
        let smoothed = |matrix: &StiffnessMatrix,
                        operator: Box<dyn LinearOperator + Send + 'a>,
                        level: &LevelMesh,
                        seconds: &mut f64| {
            let start = Instant::now();
            let cuts = dof_cuts(&entity_node_cuts(&level.mesh), &level.constraints.first);
            let smoother = ChebyshevSmoother::new(matrix, &*operator, &cuts, degree);
            *seconds += start.elapsed().as_secs_f64();
            (operator, smoother)
        };
        let mesh = &*finest_mesh.mesh;
        let constraints = &*finest_mesh.constraints;
        let mut smoothers: Vec<(Box<dyn LinearOperator + Send + 'a>, ChebyshevSmoother)> =
            Vec::new();
        let mut smoother_seconds = 0.0;
        let mut level_meshes = vec![LevelMesh {
            mesh: std::borrow::Cow::Borrowed(mesh),
            constraints: std::borrow::Cow::Borrowed(constraints),
            cells_of_node: finest_mesh.cells_of_node.clone(),
        }];
        let mut coarsest_matrix = None;
        let mut aggregation = None;
        // Only a mesh whose layout describes its nodes (always, unless built by hand) gets
        // coarser levels: without them the preconditioner degrades, the solve stays correct.
        let layout_ok = mesh.expected_node_count() == mesh.nodes.len()
            && mesh.layout().num_edges() == mesh.topology().edges().len()
            && mesh.layout().num_vertices() <= mesh.nodes.len();
        for q in level_orders(mesh.order).into_iter().skip(1) {
            let Some(coarse) = layout_ok.then(|| mesh.straight_of_order(q).ok()).flatten() else {
                break;
            };
            let coarse_constraints = carried_constraints(mesh, constraints, &coarse);
            if coarse_constraints.len() == 0 {
                break;
            }
            if matrix_free && q >= 2 {
                let operator =
                    MatrixFreeStiffness::new(&coarse, material, stiffening, &coarse_constraints)?;
                let level = LevelMesh {
                    mesh: std::borrow::Cow::Owned(coarse),
                    constraints: std::borrow::Cow::Owned(coarse_constraints),
                    cells_of_node: None,
                };
                let begin = Instant::now();
                // Two orders below the finest and lower: a cheaper smoother.
                let level_degree = if q + 1 >= mesh.order {
                    degree
                } else {
                    degree.min(LOW_LEVEL_SMOOTHER_DEGREE)
                };
                let smoother = matrix_free_smoother(&operator, &level, level_degree);
                smoother_seconds += begin.elapsed().as_secs_f64();
                smoothers.push((Box::new(SinglePrecision(Box::new(operator))), smoother));
                level_meshes.push(level);
                continue;
            }
            // The coarse mesh has the fine mesh's cells, in the same order.
            let assembled = assemble_condensed(
                &coarse,
                material,
                stiffening,
                &coarse_constraints,
                &mut |_| {},
            )?;
            let condensed = assembled.matrix;
            let level = LevelMesh {
                mesh: std::borrow::Cow::Owned(coarse),
                constraints: std::borrow::Cow::Owned(coarse_constraints),
                cells_of_node: Some(std::borrow::Cow::Owned(assembled.cells_of_node)),
            };
            let aggregated = q == 1 && condensed.rows() > options.coarse_direct_limit;
            if aggregated {
                let (p, coarse) = aggregation_level(
                    &condensed,
                    &assembled.graph,
                    &level.constraints,
                    &level.mesh.nodes,
                );
                aggregation = Some(p);
                coarsest_matrix = Some(coarse);
            }
            if q == 1 && !aggregated {
                // Factorised below.
                coarsest_matrix = Some(condensed);
            } else {
                // The f64 matrix is dropped once the smoother is set up: only its f32
                // node-block copy stays.
                let pattern = BlockPattern::new(&condensed, &assembled.graph, &level.constraints);
                let operator: Box<dyn LinearOperator + Send> = match pattern {
                    Some(p) => Box::new(BlockOperator::single(p, &condensed)),
                    None => Box::new(condensed.clone()),
                };
                smoothers.push(smoothed(
                    &condensed,
                    operator,
                    &level,
                    &mut smoother_seconds,
                ));
            }
            level_meshes.push(level);
        }
        // Between matrix-free levels of one shape, cell by cell; else as sparse matrices.
        let one_shape = mesh.cells.windows(2).all(|w| w[0].kind == w[1].kind);
        let mut transfers = level_meshes
            .windows(2)
            .map(|pair| {
                if matrix_free && one_shape {
                    let (fine, coarse) = (&pair[0], &pair[1]);
                    let transfer = CellTransfer::new(
                        &fine.mesh,
                        &fine.constraints,
                        &coarse.mesh,
                        &coarse.constraints,
                    )?;
                    Ok(Transfer::Cells(Box::new(transfer)))
                } else {
                    prolongation(&pair[0], &pair[1]).map(Transfer::matrix)
                }
            })
            .collect::<Result<Vec<_>, ElasticError>>()?;
        // Below a smoothed p = 1 level: the aggregates.
        transfers.extend(aggregation.map(Transfer::matrix));
        // The p = 1 matrix (or, above DIRECT_COARSE_LIMIT unknowns, its aggregates'), if the
        // hierarchy reached it, is factorised; if the hierarchy stopped early (no free
        // vertex), the last level has no coarse correction.
        let coarsest = coarsest_matrix
            .map(|m| Cholesky::new(&m, "coarse matrix"))
            .transpose()?;
        Ok(CoarseLevels {
            smoothers,
            sizes: level_meshes.iter().map(|l| l.constraints.len()).collect(),
            transfers,
            coarsest,
            smoother_seconds,
        })
    }
}

/// The entity-block Chebyshev smoother of a matrix-free level, its spectrum estimated with
/// the f32 action it will smooth with.
fn matrix_free_smoother(
    operator: &MatrixFreeStiffness,
    level: &LevelMesh,
    degree: usize,
) -> ChebyshevSmoother {
    let cuts = dof_cuts(&entity_node_cuts(&level.mesh), &level.constraints.first);
    ChebyshevSmoother::from_block_jacobi(
        operator.block_jacobi(&cuts),
        &SinglePrecision(operator),
        degree,
    )
}

/// The free directions of the nodes of `coarse` (the same vertices, edges, faces and
/// cells as `fine`, another order), taken from the nodes of `fine` on the same entity;
/// prescribed values are zero.
fn carried_constraints(
    fine: &HighOrderMesh,
    fine_constraints: &Constraints,
    coarse: &HighOrderMesh,
) -> Constraints {
    let nodes = coarse.nodes.len();
    let dim = fine_constraints.dim;
    let mut count = Vec::with_capacity(nodes);
    let mut directions = Vec::with_capacity(nodes);
    let mut identity = Vec::with_capacity(nodes);
    for n in 0..nodes {
        match same_entity_node(coarse, fine, n) {
            Some(m) => {
                count.push(fine_constraints.count[m]);
                directions.push(fine_constraints.directions[m]);
                identity.push(fine_constraints.identity[m]);
            }
            // Unreachable for a coarser order (every entity with nodes at order q has
            // nodes at order p > q); a free node keeps the preconditioner valid anyway.
            None => {
                let mut rows = [[0.0; 3]; 3];
                (0..3).for_each(|d| rows[d][d] = 1.0);
                count.push(dim as u8);
                directions.push(rows);
                identity.push(true);
            }
        }
    }
    Constraints::from_directions(dim, count, directions, identity)
}

/// A node of `to` on the same mesh entity (vertex, edge, face or cell interior) as node
/// `n` of `from`; both meshes share their vertices, edges, faces and cells.
fn same_entity_node(from: &HighOrderMesh, to: &HighOrderMesh, n: usize) -> Option<usize> {
    same_entity_node_unchecked(from, to, n).filter(|&m| m < to.nodes.len())
}

fn same_entity_node_unchecked(from: &HighOrderMesh, to: &HighOrderMesh, n: usize) -> Option<usize> {
    let (lf, lt) = (from.layout(), to.layout());
    if n < lf.num_vertices() {
        return Some(n);
    }
    let edge_nodes = from.order.saturating_sub(1);
    let edges_end = lf.num_vertices() + lf.num_edges() * edge_nodes;
    if n < edges_end {
        let e = (n - lf.num_vertices()) / edge_nodes;
        return (to.order >= 2).then(|| lt.edge_first_node(e, to.order));
    }
    for (first_from, first_to) in [
        (lf.face_first_nodes(), lt.face_first_nodes()),
        (lf.cell_first_nodes(), lt.cell_first_nodes()),
    ] {
        let end = first_from.last().map_or(0, |&e| e as usize);
        if n < end {
            let k = first_from
                .partition_point(|&s| s as usize <= n)
                .checked_sub(1)?;
            let (start, stop) = (*first_to.get(k)?, *first_to.get(k + 1)?);
            return (stop > start).then_some(start as usize);
        }
    }
    None
}

/// P from the unknowns of `coarse` to those of `fine` (consecutive levels).
pub(crate) fn prolongation(
    fine: &LevelMesh,
    coarse: &LevelMesh,
) -> Result<StiffnessMatrix, ElasticError> {
    let (fm, cm) = (&*fine.mesh, &*coarse.mesh);
    let (fc, cc) = (&*fine.constraints, &*coarse.constraints);
    let built;
    let cells_of_node = match &fine.cells_of_node {
        Some(cells) => &**cells,
        None => {
            built = node_cells(fm);
            &built
        }
    };
    // Per shape: the order-q basis at each order-p reference node, nonzero weights only.
    let mut weights: BTreeMap<Shape, Vec<Vec<(u16, f64)>>> = BTreeMap::new();
    for cell in &fm.cells {
        let shape = cell.kind;
        if weights.contains_key(&shape) {
            continue;
        }
        let table = interpolation_weights(shape, fm, cm)?;
        weights.insert(shape, table);
    }
    let dim = fc.dim;
    let rows: Vec<Vec<(u32, f64)>> = (0..fm.nodes.len())
        .into_par_iter()
        .flat_map_iter(|n| {
            let mut entries: Vec<(usize, f64)> = Vec::new();
            if let Some(&c) = cells_of_node.row(n).first() {
                let (fine_cell, coarse_cell) = (&fm.cells[c as usize], &cm.cells[c as usize]);
                let table = weights.get(&fine_cell.kind);
                let local = fine_cell.nodes.iter().position(|&x| x as usize == n);
                if let (Some(table), Some(local)) = (table, local) {
                    entries.extend(
                        table[local]
                            .iter()
                            .map(|&(j, w)| (coarse_cell.nodes[j as usize] as usize, w)),
                    );
                }
            }
            entries.sort_by_key(|e| e.0);
            (0..fc.count[n] as usize).map(move |i| {
                let qn = &fc.directions[n];
                let mut row = Vec::new();
                for &(v, w) in &entries {
                    let qv = &cc.directions[v];
                    for j in 0..cc.count[v] as usize {
                        let q: f64 = (0..dim).map(|c| qn[i][c] * qv[j][c]).sum();
                        if q != 0.0 {
                            row.push(((cc.first[v] + j) as u32, w * q));
                        }
                    }
                }
                row
            })
        })
        .collect();
    Ok(from_rows(cc.len(), rows))
}

/// One V-cycle z = M r from the first of `levels` down to `coarsest`.
fn v_cycle(levels: &mut [Level], coarsest: Option<&Cholesky>, r: &[f64], z: &mut [f64]) {
    let Some((level, coarser)) = levels.split_first_mut() else {
        match coarsest {
            Some(c) => {
                z.copy_from_slice(r);
                c.solve_in_place(z);
            }
            None => z.iter_mut().for_each(|v| *v = 0.0),
        }
        return;
    };
    let a = &*level.operator;
    level.smoother.apply(a, r, z, &mut level.smoothing);
    if !level.coarse_rhs.is_empty() {
        a.residual(r, z, &mut level.residual);
        level
            .transfer
            .restrict(&level.residual, &mut level.coarse_rhs);
        v_cycle(
            coarser,
            coarsest,
            &level.coarse_rhs,
            &mut level.coarse_solution,
        );
        level
            .transfer
            .prolong(&level.coarse_solution, &mut level.correction);
        z.par_iter_mut()
            .zip(&level.correction)
            .for_each(|(zi, ci)| *zi += ci);
    }
    a.residual(r, z, &mut level.residual);
    level.smoother.apply(
        a,
        &level.residual,
        &mut level.correction,
        &mut level.smoothing,
    );
    z.par_iter_mut()
        .zip(&level.correction)
        .for_each(|(zi, ci)| *zi += ci);
}

impl Preconditioner for PMultigrid<'_> {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        v_cycle(&mut self.levels, self.coarsest.as_ref(), r, z);
    }
}

#[cfg(test)]
#[path = "tests/p_multigrid.rs"]
pub(crate) mod tests;
