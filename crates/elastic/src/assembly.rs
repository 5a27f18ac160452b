//! Global assembly of the stiffness matrix and load vector (dof = node · dim + component).
//!
//! The block sparsity pattern comes from the cell connectivity once; cells are coloured so
//! that no two cells of a colour share a node, and each colour is assembled in parallel.
//! Every matrix entry therefore receives its contributions one colour after the other,
//! in the same order whatever the number of threads: the matrix is bitwise reproducible.

use std::sync::atomic::{AtomicU64, Ordering};

use hocurve_mesh::{HighOrderMesh, MeshError};
use rayon::prelude::*;

use crate::condensation::{CondensedPattern, Constraints};
use crate::element_matrix::{element_stiffness, invert_jacobian, ElementScratch};
use crate::reference_element::ReferenceStiffness;
use crate::sparsity::{colour_cells, node_cells, node_graph, Adjacency};
use crate::{ElasticError, Material};

/// A CSR matrix with 32-bit column indices (sprs).
pub type StiffnessMatrix = sprs::CsMatI<f64, u32, usize>;

/// A body force density f(x) (force per unit volume; per unit area in 2D).
pub type BodyForce<'a> = dyn Fn([f64; 3]) -> [f64; 3] + Sync + 'a;

/// The assembled, condensed stiffness matrix with what later steps reuse.
pub(crate) struct Assembled {
    /// Tᵀ K T (the constrained dofs eliminated, see [`crate::condensation`]).
    pub matrix: StiffnessMatrix,
    /// −Tᵀ K u_p: the load that the prescribed displacements put on the reduced unknowns.
    pub rhs: Vec<f64>,
    /// Node adjacency: the block pattern of `matrix`.
    pub graph: Adjacency,
    /// Cells around each node.
    pub cells_of_node: Adjacency,
}

fn check_dim(mesh: &HighOrderMesh) -> Result<(), ElasticError> {
    if mesh.dim == 2 || mesh.dim == 3 {
        Ok(())
    } else {
        Err(MeshError::UnsupportedDimension(mesh.dim).into())
    }
}

/// The stiffness matrix K of `mesh` (size N·dim, dof = node · dim + component), with every
/// node's row present (a node in no cell has an empty, zero row block).
///
/// K_ij = a(Φ_j e_d, Φ_i e_c) with a(u, v) = ∫ λ div u div v + 2μ ε(u) : ε(v) dx.
pub fn assemble_stiffness(
    mesh: &HighOrderMesh,
    material: &Material,
) -> Result<StiffnessMatrix, ElasticError> {
    Ok(assemble(mesh, material)?.matrix)
}

/// The unconstrained stiffness matrix (every node free: T = I).
pub(crate) fn assemble(
    mesh: &HighOrderMesh,
    material: &Material,
) -> Result<Assembled, ElasticError> {
    let free = Constraints::free(mesh.nodes.len(), mesh.dim);
    assemble_condensed(mesh, material, None, &free, &mut |_| {})
}

/// Tᵀ K T and −Tᵀ K u_p under `constraints`, assembled element by element straight into the
/// condensed pattern (the full K is never formed), each cell c's Lamé parameters multiplied
/// by `stiffening[c]` when given, calling `progress` with the fraction of cells done after
/// each colour. An element block between two free nodes is added as it is; a sliding node's
/// rows and columns are rotated into its free directions, Q_a K_ab Q_bᵀ, before adding; a
/// block against a prescribed node b goes to the right-hand side as −Q_a K_ab u_b.
pub(crate) fn assemble_condensed(
    mesh: &HighOrderMesh,
    material: &Material,
    stiffening: Option<&[f64]>,
    constraints: &Constraints,
    progress: &mut dyn FnMut(f64),
) -> Result<Assembled, ElasticError> {
    material.validate()?;
    check_dim(mesh)?;
    if let Some(scale) = stiffening {
        check_stiffening(mesh, scale)?;
    }
    let references = ReferenceStiffness::for_mesh(mesh)?;
    let dim = mesh.dim;
    // Constraints are built here from the mesh's own node count (not user data).
    debug_assert!(constraints.count.len() == mesh.nodes.len() && constraints.dim == dim);
    let (lambda, mu) = material.lame();
    let cells_of_node = node_cells(mesh);
    let graph = node_graph(mesh, &cells_of_node);
    let pattern = CondensedPattern::new(&graph, constraints);

    // Cells of one colour touch disjoint rows, so plain load/store on the atomics never
    // races; atomics only make that sharing expressible without `unsafe`.
    let values: Vec<AtomicU64> = (0..pattern.indices.len())
        .into_par_iter()
        .map(|_| AtomicU64::new(0))
        .collect();
    let rhs: Vec<AtomicU64> = (0..constraints.len())
        .into_par_iter()
        .map(|_| AtomicU64::new(0))
        .collect();
    let add = |slot: &AtomicU64, value: f64| {
        let sum = f64::from_bits(slot.load(Ordering::Relaxed)) + value;
        slot.store(sum.to_bits(), Ordering::Relaxed);
    };
    let (count, first) = (&constraints.count, &constraints.first);

    let mut done = 0;
    for class in colour_cells(mesh, &cells_of_node) {
        done += class.len();
        class
            .par_iter()
            .try_for_each_init(ElementScratch::default, |scratch, &c| {
                let c = c as usize;
                let cell = &mesh.cells[c];
                let reference = &references[&cell.kind];
                scratch.coords.clear();
                scratch
                    .coords
                    .extend(cell.nodes.iter().map(|&n| mesh.nodes[n as usize]));
                let s = stiffening.map_or(1.0, |scale| scale[c]);
                element_stiffness(reference, s * lambda, s * mu, c, scratch)?;
                let size = cell.nodes.len() * dim;
                // Columns in increasing node order: each row of the pattern is then walked
                // once, front to back, instead of searched per entry.
                scratch.order.clear();
                scratch.order.extend(0..cell.nodes.len());
                scratch.order.sort_unstable_by_key(|&b| cell.nodes[b]);
                let (k, order) = (&scratch.matrix, &scratch.order);
                for (a, &na) in cell.nodes.iter().enumerate() {
                    let na = na as usize;
                    let ka = count[na] as usize;
                    if ka == 0 {
                        continue;
                    }
                    let qa = &constraints.directions[na];
                    let row = graph.row(na);
                    let columns = pattern.column_offsets(na);
                    // Row (a, c) of the element matrix starts at block (a, b) here.
                    let at = |b: usize, c: usize, d: usize| k[(a * dim + c) * size + b * dim + d];
                    let mut pos = 0;
                    for &b in order {
                        let nb = cell.nodes[b];
                        let nb_u = nb as usize;
                        let kb = count[nb_u] as usize;
                        if kb == 0 {
                            let ub = &constraints.prescribed[nb_u * dim..(nb_u + 1) * dim];
                            if ub.iter().all(|&v| v == 0.0) {
                                continue;
                            }
                            for i in 0..ka {
                                let mut sum = 0.0;
                                for cc in 0..dim {
                                    let q = if constraints.identity[na] {
                                        if i == cc {
                                            1.0
                                        } else {
                                            0.0
                                        }
                                    } else {
                                        qa[i][cc]
                                    };
                                    if q != 0.0 {
                                        for d in 0..dim {
                                            sum += q * at(b, cc, d) * ub[d];
                                        }
                                    }
                                }
                                add(&rhs[first[na] + i], -sum);
                            }
                            continue;
                        }
                        while pos < row.len() && row[pos] < nb {
                            pos += 1;
                        }
                        if row.get(pos) != Some(&nb) {
                            continue; // unreachable: the graph holds every cell's nodes
                        }
                        let column = columns[pos] as usize;
                        let qb = &constraints.directions[nb_u];
                        let both_free = constraints.identity[na] && constraints.identity[nb_u];
                        for i in 0..ka {
                            let start = pattern.indptr[first[na] + i] + column;
                            for j in 0..kb {
                                let value = if both_free {
                                    at(b, i, j)
                                } else {
                                    let mut sum = 0.0;
                                    for cc in 0..dim {
                                        for d in 0..dim {
                                            sum += qa[i][cc] * at(b, cc, d) * qb[j][d];
                                        }
                                    }
                                    sum
                                };
                                add(&values[start + j], value);
                            }
                        }
                    }
                }
                Ok::<(), ElasticError>(())
            })?;
        progress(done as f64 / mesh.cells.len().max(1) as f64);
    }
    // Sequential on purpose: `into_iter().map().collect()` reuses the allocation (same size
    // and alignment), where a parallel collect would hold both arrays, 16 bytes per entry,
    // at the peak of the whole run.
    let unpack = |v: Vec<AtomicU64>| -> Vec<f64> {
        v.into_iter()
            .map(|v| f64::from_bits(v.into_inner()))
            .collect()
    };
    let size = constraints.len();
    let CondensedPattern {
        indptr, indices, ..
    } = pattern;
    Ok(Assembled {
        matrix: StiffnessMatrix::new((size, size), indptr, indices, unpack(values)),
        rhs: unpack(rhs),
        graph,
        cells_of_node,
    })
}

/// Error unless `scale` holds one finite positive factor per cell of `mesh`.
fn check_stiffening(mesh: &HighOrderMesh, scale: &[f64]) -> Result<(), ElasticError> {
    if scale.len() != mesh.cells.len() {
        return Err(ElasticError::InvalidStiffening {
            reason: format!("{} factors for {} cells", scale.len(), mesh.cells.len()),
        });
    }
    match scale.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
        Some(c) => Err(ElasticError::InvalidStiffening {
            reason: format!("cell {c} has factor {}", scale[c]),
        }),
        None => Ok(()),
    }
}

/// The load vector F_(a,c) = ∫ Φ_a f_c dx of a body force, integrated with the degree-(2p+2)
/// rule of each cell (dof = node · dim + component).
pub fn assemble_load(
    mesh: &HighOrderMesh,
    body_force: &BodyForce<'_>,
) -> Result<Vec<f64>, ElasticError> {
    check_dim(mesh)?;
    let references = ReferenceStiffness::for_mesh(mesh)?;
    let dim = mesh.dim;
    // Element vectors in parallel, summed in cell order: reproducible.
    let element_loads: Vec<Vec<f64>> = (0..mesh.cells.len())
        .into_par_iter()
        .map(|c| {
            let cell = &mesh.cells[c];
            let reference = &references[&cell.kind];
            let n = reference.len;
            let coords: Vec<[f64; 3]> =
                cell.nodes.iter().map(|&i| mesh.nodes[i as usize]).collect();
            let rule = &reference.load_rule;
            let mut load = vec![0.0; n * dim];
            for q in 0..rule.len() {
                let values = rule.values(q);
                let jac = rule.jacobian(&coords, q);
                let det = invert_jacobian(&jac, dim).1;
                if !det.is_finite() || det == 0.0 {
                    return Err(ElasticError::DegenerateCell {
                        cell: c,
                        jacobian: det,
                    });
                }
                let mut x = [0.0; 3];
                for (phi, xa) in values.iter().zip(&coords) {
                    for d in 0..3 {
                        x[d] += phi * xa[d];
                    }
                }
                let f = body_force(x);
                if f.iter().any(|v| !v.is_finite()) {
                    return Err(ElasticError::NonFiniteLoad { cell: c });
                }
                let w = rule.weights()[q] * det.abs();
                for (a, phi) in values.iter().enumerate() {
                    for d in 0..dim {
                        load[a * dim + d] += w * phi * f[d];
                    }
                }
            }
            Ok(load)
        })
        .collect::<Result<_, ElasticError>>()?;
    let mut total = vec![0.0; mesh.nodes.len() * dim];
    for (cell, load) in mesh.cells.iter().zip(&element_loads) {
        for (a, &n) in cell.nodes.iter().enumerate() {
            for d in 0..dim {
                total[n as usize * dim + d] += load[a * dim + d];
            }
        }
    }
    Ok(total)
}
