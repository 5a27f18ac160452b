//! Elimination of constrained dofs, keeping the system symmetric.
//!
//! Every node n gets a matrix Q_n whose k_n rows are orthonormal directions in which it may
//! move: all dim axes for a free node, none for a prescribed node, and for a sliding node
//! the dim − 1 tangents of a local frame (n, t₁, t₂) — its displacement is u_n = Q_nᵀ y_n,
//! i.e. the node is rotated into the frame and the normal component, fixed at 0, removed.
//! With T the block-diagonal map from reduced unknowns y to all dofs and u_p the prescribed
//! values, u = T y + u_p and the condensed system is
//!
//! (Tᵀ K T) y = Tᵀ (F − K u_p),
//!
//! symmetric positive definite as soon as rigid motions are blocked. Blocks of free nodes
//! are copied as they are (Q = I), so a problem without sliding nodes is the plain row and
//! column elimination.

use rayon::prelude::*;

use crate::sparsity::Adjacency;
use crate::vector_ops::split_into;
use crate::BoundaryConditions;
#[cfg(test)]
use crate::StiffnessMatrix;

/// The free directions of each node and the reduced numbering.
#[derive(Debug, Clone)]
pub(crate) struct Constraints {
    pub dim: usize,
    /// Number of free directions k_n of each node.
    pub count: Vec<u8>,
    /// The free directions (rows of Q_n); only the first `count` are used.
    pub directions: Vec<[[f64; 3]; 3]>,
    /// Whether Q_n is the identity (free node).
    pub identity: Vec<bool>,
    /// First reduced dof of each node (`len = nodes + 1`).
    pub first: Vec<usize>,
    /// Prescribed displacement u_p as a full dof vector.
    pub prescribed: Vec<f64>,
}

/// Two unit tangents completing the unit normal `n` to an orthonormal frame (3D), or the
/// one tangent (−n_y, n_x) in 2D.
fn tangents(normal: [f64; 3], dim: usize) -> [[f64; 3]; 2] {
    let len = normal[..dim].iter().map(|v| v * v).sum::<f64>().sqrt();
    let n = normal.map(|v| v / len);
    if dim == 2 {
        return [[-n[1], n[0], 0.0], [0.0; 3]];
    }
    // Cross with the axis least aligned with n: well conditioned.
    let axis = (0..3)
        .min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[axis] = 1.0;
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let t1 = cross(n, e);
    let l1 = t1.iter().map(|v| v * v).sum::<f64>().sqrt();
    let t1 = t1.map(|v| v / l1);
    [t1, cross(n, t1)]
}

impl Constraints {
    pub fn new(nodes: usize, dim: usize, bc: &BoundaryConditions) -> Self {
        let mut identity_rows = [[0.0; 3]; 3];
        for d in 0..3 {
            identity_rows[d][d] = 1.0;
        }
        let mut count = vec![dim as u8; nodes];
        let mut directions = vec![identity_rows; nodes];
        let mut identity = vec![true; nodes];
        let mut prescribed = vec![0.0; nodes * dim];
        for (&n, normal) in &bc.sliding {
            let [t1, t2] = tangents(*normal, dim);
            let n = n as usize;
            count[n] = dim as u8 - 1;
            directions[n] = [t1, t2, [0.0; 3]];
            identity[n] = false;
        }
        for (&n, direction) in &bc.along_line {
            let len = direction[..dim].iter().map(|v| v * v).sum::<f64>().sqrt();
            let n = n as usize;
            count[n] = 1;
            directions[n] = [direction.map(|v| v / len), [0.0; 3], [0.0; 3]];
            identity[n] = false;
        }
        for (&n, value) in &bc.prescribed {
            let n = n as usize;
            count[n] = 0;
            identity[n] = false;
            prescribed[n * dim..(n + 1) * dim].copy_from_slice(&value[..dim]);
        }
        let mut constraints = Self::from_directions(dim, count, directions, identity);
        constraints.prescribed = prescribed;
        constraints
    }

    /// Every node free in every direction (T = I): the condensed system is K itself.
    pub fn free(nodes: usize, dim: usize) -> Self {
        let mut identity_rows = [[0.0; 3]; 3];
        for d in 0..3 {
            identity_rows[d][d] = 1.0;
        }
        Self::from_directions(
            dim,
            vec![dim as u8; nodes],
            vec![identity_rows; nodes],
            vec![true; nodes],
        )
    }

    /// Homogeneous constraints (u_p = 0) from each node's free directions.
    pub fn from_directions(
        dim: usize,
        count: Vec<u8>,
        directions: Vec<[[f64; 3]; 3]>,
        identity: Vec<bool>,
    ) -> Self {
        let mut first = Vec::with_capacity(count.len() + 1);
        first.push(0);
        for &k in &count {
            first.push(first[first.len() - 1] + k as usize);
        }
        Constraints {
            dim,
            prescribed: vec![0.0; count.len() * dim],
            count,
            directions,
            identity,
            first,
        }
    }

    /// Number of reduced unknowns.
    pub fn len(&self) -> usize {
        self.first[self.count.len()]
    }

    /// y_n = Q_n v_n for every node: full dof vector → reduced.
    pub fn restrict(&self, full: &[f64]) -> Vec<f64> {
        let dim = self.dim;
        let mut out = vec![0.0; self.len()];
        for n in 0..self.count.len() {
            let v = &full[n * dim..(n + 1) * dim];
            for i in 0..self.count[n] as usize {
                out[self.first[n] + i] = if self.identity[n] {
                    v[i]
                } else {
                    (0..dim).map(|c| self.directions[n][i][c] * v[c]).sum()
                };
            }
        }
        out
    }

    /// u = T y + u_p per node.
    pub fn expand(&self, reduced: &[f64]) -> Vec<[f64; 3]> {
        let dim = self.dim;
        (0..self.count.len())
            .map(|n| {
                let mut u = [0.0; 3];
                u[..dim].copy_from_slice(&self.prescribed[n * dim..(n + 1) * dim]);
                for i in 0..self.count[n] as usize {
                    let y = reduced[self.first[n] + i];
                    for c in 0..dim {
                        u[c] += self.directions[n][i][c] * y;
                    }
                }
                u
            })
            .collect()
    }
}

/// The sparsity pattern of Tᵀ K T: the k_n rows of node n each hold, for every neighbour m
/// of n in the node graph (in its order), the k_m reduced dofs of m.
pub(crate) struct CondensedPattern {
    pub indptr: Vec<usize>,
    pub indices: Vec<u32>,
    /// Where each neighbour's columns start within a row of node n:
    /// `offsets[row_start[n] + i]` for the i-th neighbour of n.
    row_start: Vec<usize>,
    offsets: Vec<u32>,
}

impl CondensedPattern {
    /// Built node by node in parallel (rows are independent: reproducible).
    pub fn new(graph: &Adjacency, constraints: &Constraints) -> Self {
        let nodes = constraints.count.len();
        let count = &constraints.count;
        let mut row_start = Vec::with_capacity(nodes + 1);
        row_start.push(0usize);
        let mut offsets = Vec::new();
        let mut indptr = Vec::with_capacity(constraints.len() + 1);
        indptr.push(0usize);
        for n in 0..nodes {
            let mut len = 0u32;
            for &m in graph.row(n) {
                offsets.push(len);
                len += count[m as usize] as u32;
            }
            row_start.push(offsets.len());
            for _ in 0..count[n] {
                indptr.push(indptr[indptr.len() - 1] + len as usize);
            }
        }
        let nnz = indptr[indptr.len() - 1];
        let mut indices = vec![0u32; nnz];
        // One slice of `indices` per node, filled in parallel.
        let parts = split_into(
            &mut indices,
            (0..nodes).map(|n| indptr[constraints.first[n + 1]] - indptr[constraints.first[n]]),
        );
        parts
            .into_par_iter()
            .enumerate()
            .with_min_len(64)
            .for_each(|(n, idx)| {
                let mut at = 0;
                for _ in 0..count[n] {
                    for &m in graph.row(n) {
                        let m = m as usize;
                        for j in 0..count[m] as usize {
                            idx[at] = (constraints.first[m] + j) as u32;
                            at += 1;
                        }
                    }
                }
            });
        CondensedPattern {
            indptr,
            indices,
            row_start,
            offsets,
        }
    }

    /// Start of each neighbour's columns within a row of node `n`, aligned with
    /// `graph.row(n)`.
    pub fn column_offsets(&self, n: usize) -> &[u32] {
        &self.offsets[self.row_start[n]..self.row_start[n + 1]]
    }
}

/// Tᵀ K T from an assembled K: the reference that the direct condensed assembly
/// ([`crate::assembly`]) is tested against.
#[cfg(test)]
pub(crate) fn condense_matrix(
    k: &StiffnessMatrix,
    graph: &Adjacency,
    constraints: &Constraints,
) -> StiffnessMatrix {
    let dim = constraints.dim;
    let nodes = constraints.count.len();
    let k_ptr = k.indptr().into_raw_storage();
    let k_val = k.data();
    let count = &constraints.count;
    let pattern = CondensedPattern::new(graph, constraints);
    let mut data = vec![0.0; pattern.indices.len()];
    for n in 0..nodes {
        let kn = count[n] as usize;
        let qn = &constraints.directions[n];
        for i in 0..kn {
            let mut at = pattern.indptr[constraints.first[n] + i];
            for (pos, &m) in graph.row(n).iter().enumerate() {
                let m = m as usize;
                let qm = &constraints.directions[m];
                for j in 0..count[m] as usize {
                    let mut sum = 0.0;
                    for c in 0..dim {
                        let start = k_ptr[n * dim + c] + pos * dim;
                        for d in 0..dim {
                            sum += qn[i][c] * k_val[start + d] * qm[j][d];
                        }
                    }
                    data[at] = sum;
                    at += 1;
                }
            }
        }
    }
    let size = constraints.len();
    StiffnessMatrix::new((size, size), pattern.indptr, pattern.indices, data)
}

#[cfg(test)]
#[path = "tests/condensation.rs"]
mod tests;
