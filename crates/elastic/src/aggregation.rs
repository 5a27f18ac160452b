//! A coarse level below p = 1 for large meshes: aggregates of vertices, each carrying the
//! rigid-body motions of elasticity (plain aggregation with the near-null space, Vaněk,
//! Mandel & Brezina 1996, without the smoothing of the prolongator).
//!
//! The p = 1 problem of a mesh with V vertices is solved exactly by sparse Cholesky, whose
//! cost grows like V² in 3D: 3.9 s at 17.7 k vertices, 48 s at 49 k (sphere in a box). Above
//! [`DIRECT_COARSE_LIMIT`] unknowns the p = 1 level is smoothed like the finer ones instead
//! and corrected from this level: each aggregate (a vertex and its untaken neighbours) gets
//! the six rigid-body modes (three in 2D) restricted to its vertices, orthonormalised, as
//! the columns of the tentative prolongator P; the coarse matrix Pᵀ A P has six unknowns
//! per aggregate of ~15 vertices, about a seventh of the p = 1 unknowns, and is factorised.

use crate::condensation::Constraints;
use crate::sparse::{from_rows, product, transpose};
use crate::sparsity::Adjacency;
use crate::vector_ops::{axpy, dot, norm};
use crate::StiffnessMatrix;

/// Above this many p = 1 unknowns, the p = 1 level is smoothed and corrected from the
/// aggregates instead of factorised.
pub(crate) const DIRECT_COARSE_LIMIT: usize = 40_000;

/// A mode's part below this fraction of its norm, after removing the earlier modes, is
/// dependent on them (an aggregate of one vertex, or of vertices on one line).
const RANK_TOLERANCE: f64 = 1e-8;

/// The aggregation level of the p = 1 matrix `a` (unknowns numbered by `constraints`, node
/// graph `graph`, vertex positions `points`): P and Pᵀ A P.
pub(crate) fn aggregation_level(
    a: &StiffnessMatrix,
    graph: &Adjacency,
    constraints: &Constraints,
    points: &[[f64; 3]],
) -> (StiffnessMatrix, StiffnessMatrix) {
    let (aggregate_of, count) = aggregates(graph, constraints);
    let p = tentative_prolongation(&aggregate_of, count, constraints, points);
    let coarse = product(&transpose(&p), &product(a, &p));
    (p, coarse)
}

/// Greedy aggregation (Vaněk et al.'s first two passes): in vertex order, a vertex with
/// unknowns whose neighbours are all untaken starts an aggregate with them; then every
/// untaken vertex joins the aggregate of its first taken neighbour, or starts its own.
/// Returns each vertex's aggregate (`u32::MAX` for a vertex without unknowns) and the count.
fn aggregates(graph: &Adjacency, constraints: &Constraints) -> (Vec<u32>, usize) {
    let n = constraints.count.len();
    let free = |v: usize| constraints.count[v] > 0;
    let mut of = vec![u32::MAX; n];
    let mut count = 0u32;
    for v in 0..n {
        if !free(v) || of[v] != u32::MAX {
            continue;
        }
        let ring = graph.row(v);
        if ring.iter().all(|&m| of[m as usize] == u32::MAX) {
            for &m in ring {
                if free(m as usize) {
                    of[m as usize] = count;
                }
            }
            of[v] = count;
            count += 1;
        }
    }
    for v in 0..n {
        if !free(v) || of[v] != u32::MAX {
            continue;
        }
        match graph.row(v).iter().find(|&&m| of[m as usize] != u32::MAX) {
            Some(&m) => of[v] = of[m as usize],
            None => {
                of[v] = count;
                count += 1;
            }
        }
    }
    (of, count as usize)
}

/// P: for each aggregate, the rigid-body modes (translations, and rotations about the
/// aggregate's centroid scaled by its size) at its vertices' unknowns (rotated into sliding
/// vertices' free directions), orthonormalised by modified Gram–Schmidt; dependent modes
/// are dropped.
fn tentative_prolongation(
    aggregate_of: &[u32],
    aggregates: usize,
    constraints: &Constraints,
    points: &[[f64; 3]],
) -> StiffnessMatrix {
    let dim = constraints.dim;
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); aggregates];
    for (v, &a) in aggregate_of.iter().enumerate() {
        if a != u32::MAX {
            members[a as usize].push(v);
        }
    }
    let modes = if dim == 2 { 3 } else { 6 };
    let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); constraints.len()];
    let mut column = 0u32;
    for vertices in &members {
        let centroid = mean(vertices.iter().map(|&v| points[v]));
        let size = vertices
            .iter()
            .map(|&v| distance(points[v], centroid))
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        // The modes as columns over the aggregate's unknowns.
        let dofs: Vec<(usize, usize)> = vertices
            .iter()
            .flat_map(|&v| (0..constraints.count[v] as usize).map(move |i| (v, i)))
            .collect();
        let mut basis: Vec<Vec<f64>> = Vec::new();
        for k in 0..modes {
            let mut col: Vec<f64> = dofs
                .iter()
                .map(|&(v, i)| {
                    let x = points[v];
                    let r = [0, 1, 2].map(|d| (x[d] - centroid[d]) / size);
                    let motion = rigid_mode(k, r, dim);
                    if constraints.identity[v] {
                        motion[i]
                    } else {
                        (0..dim)
                            .map(|d| constraints.directions[v][i][d] * motion[d])
                            .sum()
                    }
                })
                .collect();
            let norm0 = norm(&col);
            for b in &basis {
                axpy(-dot(&col, b), b, &mut col);
            }
            let norm1 = norm(&col);
            if norm0 > 0.0 && norm1 > RANK_TOLERANCE * norm0 {
                col.iter_mut().for_each(|x| *x /= norm1);
                basis.push(col);
            }
        }
        for (row, &(v, i)) in dofs.iter().enumerate() {
            let dof = constraints.first[v] + i;
            for (j, b) in basis.iter().enumerate() {
                rows[dof].push((column + j as u32, b[row]));
            }
        }
        column += basis.len() as u32;
    }
    from_rows(column as usize, rows)
}

/// Rigid-body mode k at position r: translations along x, y, z, then rotations about them
/// (2D: x, y and the rotation about z).
fn rigid_mode(k: usize, r: [f64; 3], dim: usize) -> [f64; 3] {
    match (dim, k) {
        (_, 0) => [1.0, 0.0, 0.0],
        (_, 1) => [0.0, 1.0, 0.0],
        (2, _) => [-r[1], r[0], 0.0],
        (_, 2) => [0.0, 0.0, 1.0],
        (_, 3) => [0.0, -r[2], r[1]],
        (_, 4) => [r[2], 0.0, -r[0]],
        _ => [-r[1], r[0], 0.0],
    }
}

fn mean(points: impl Iterator<Item = [f64; 3]>) -> [f64; 3] {
    let (mut sum, mut n) = ([0.0; 3], 0.0);
    for p in points {
        (0..3).for_each(|d| sum[d] += p[d]);
        n += 1.0;
    }
    sum.map(|s| s / f64::max(n, 1.0))
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|d| (a[d] - b[d]).powi(2)).sum::<f64>().sqrt()
}

#[cfg(test)]
#[path = "tests/aggregation.rs"]
mod tests;
