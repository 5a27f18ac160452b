//! Block Jacobi: exact inverses of the diagonal blocks of A on a partition of the dofs into
//! contiguous ranges, B = blockdiag(A_ii)⁻¹.
//!
//! The smoother of every p-multigrid level uses one block per mesh entity: every
//! vertex, the interior nodes of every edge, of every face and of every cell (Pavarino and
//! Widlund's p-version Schwarz splitting, without overlap). The global numbering lists each
//! entity's nodes together (vertices, edges, faces, cells; see
//! [`hocurve_mesh::NodeLayout`]), so each block is a contiguous range of reduced dofs.
//! With the vertex (p = 1) coarse space it cuts the PCG iterations on the sphere fixture
//! from 40 to 35 at p = 4 and from 63 to 48 at p = 5 against node-wise (3 × 3) blocks
//! (identical at p ≤ 3, where edges and faces hold at most 2 nodes); it does not make them
//! flat in p: overlapping edge patches (edge + faces + cells around it) gave 24 at p = 4
//! but cost as much as a mat-vec to apply and 5× the set-up.

use hocurve_mesh::HighOrderMesh;
use rayon::prelude::*;

use crate::vector_ops::split_into;
use crate::StiffnessMatrix;

/// Blocks larger than this (dofs) are split at node boundaries: only hexahedra and prisms
/// of high order have such interiors, and their dense inverses would cost more than they
/// gain.
const MAX_BLOCK: usize = 96;
/// Dofs per parallel task when applying B.
const DOFS_PER_TASK: usize = 4096;

/// The dense inverses of the diagonal blocks of a matrix, each stored as its lower triangle
/// (symmetric: half the memory, which at p = 10 is most of the solver's — 1 GB of full
/// blocks over the levels of a 1 236-tetrahedron mesh).
#[derive(Debug, Clone)]
pub(crate) struct BlockJacobi {
    /// First dof of each block (`len = blocks + 1`); the blocks cover 0..n in order.
    starts: Vec<usize>,
    /// Start of each block's packed inverse in `inverses` (`len = blocks + 1`): row i of a
    /// k × k block holds columns 0..=i at [`packed_index`]`(i, 0)`.
    offsets: Vec<usize>,
    inverses: Vec<f64>,
    /// Blocks of each parallel task: task t applies blocks `tasks[t]..tasks[t + 1]`.
    tasks: Vec<usize>,
}

/// The node ranges of the mesh's entities (each vertex, then the interior nodes of each
/// edge, face and cell), as cut points `0 = c₀ < c₁ < … = nodes`; one range per node if
/// the layout does not describe the mesh's nodes.
pub(crate) fn entity_node_cuts(mesh: &HighOrderMesh) -> Vec<usize> {
    let nodes = mesh.nodes.len();
    let layout = mesh.layout();
    let mut cuts: Vec<usize> = (0..=layout.num_vertices()).collect();
    if mesh.order >= 2 {
        cuts.extend((1..=layout.num_edges()).map(|e| layout.edge_first_node(e, mesh.order)));
    }
    cuts.extend(layout.face_first_nodes().iter().map(|&f| f as usize));
    cuts.extend(layout.cell_first_nodes().iter().map(|&c| c as usize));
    let consistent = cuts.windows(2).all(|w| w[0] <= w[1]) && cuts.last() == Some(&nodes);
    if !consistent {
        return (0..=nodes).collect();
    }
    cuts.dedup();
    cuts
}

/// Dof cut points from node cut points, given the first reduced dof of each node
/// (`first`, `len = nodes + 1`): empty ranges (prescribed nodes) are dropped and ranges
/// above [`MAX_BLOCK`] dofs split at node boundaries.
pub(crate) fn dof_cuts(node_cuts: &[usize], first: &[usize]) -> Vec<usize> {
    let mut cuts = vec![0];
    for w in node_cuts.windows(2) {
        let mut start = first[w[0]];
        for n in w[0]..w[1] {
            if first[n + 1] - start > MAX_BLOCK {
                if first[n] > start {
                    cuts.push(first[n]);
                }
                start = first[n];
            }
        }
        if first[w[1]] > *cuts.last().unwrap_or(&0) {
            cuts.push(first[w[1]]);
        }
    }
    cuts
}

/// Inverse of the symmetric k × k matrix `m` (row-major, overwritten) by Cholesky, into
/// `out`; the inverse diagonal if `m` is not numerically positive definite.
pub(crate) fn invert_spd(m: &mut [f64], k: usize, out: &mut [f64]) {
    out.iter_mut().for_each(|v| *v = 0.0);
    let diagonal: Vec<f64> = (0..k).map(|i| m[i * k + i]).collect();
    // m ← L, lower triangle (A = L Lᵀ).
    for j in 0..k {
        let d = m[j * k + j] - (0..j).map(|l| m[j * k + l] * m[j * k + l]).sum::<f64>();
        if !(d > 0.0 && d.is_finite()) {
            // Only reachable for a singular system; keep the smoother defined.
            for (i, d) in diagonal.iter().enumerate() {
                out[i * k + i] = if *d != 0.0 && d.is_finite() {
                    1.0 / d
                } else {
                    0.0
                };
            }
            return;
        }
        let d = d.sqrt();
        m[j * k + j] = d;
        for i in j + 1..k {
            let s = m[i * k + j] - (0..j).map(|l| m[i * k + l] * m[j * k + l]).sum::<f64>();
            m[i * k + j] = s / d;
        }
    }
    // out ← L⁻¹ (lower triangular), column by column.
    for j in 0..k {
        out[j * k + j] = 1.0 / m[j * k + j];
        for i in j + 1..k {
            let s: f64 = (j..i).map(|l| m[i * k + l] * out[l * k + j]).sum();
            out[i * k + j] = -s / m[i * k + i];
        }
    }
    // A⁻¹ = L⁻ᵀ L⁻¹: (A⁻¹)_ab = Σ_{i ≥ max(a, b)} (L⁻¹)_ia (L⁻¹)_ib, through m as scratch.
    m.copy_from_slice(out);
    for a in 0..k {
        for b in 0..=a {
            let s: f64 = (a..k).map(|i| m[i * k + a] * m[i * k + b]).sum();
            out[a * k + b] = s;
            out[b * k + a] = s;
        }
    }
}

/// Where each k × k block over the ranges `cuts` starts in an array of packed lower
/// triangles (k(k + 1)/2 numbers each; `len = blocks + 1`).
pub(crate) fn block_offsets(cuts: &[usize]) -> Vec<usize> {
    let mut offsets = Vec::with_capacity(cuts.len());
    offsets.push(0);
    for w in cuts.windows(2) {
        let k = w[1] - w[0];
        offsets.push(offsets[offsets.len() - 1] + k * (k + 1) / 2);
    }
    offsets
}

/// Position of entry (i, j), j ≤ i, of a packed lower triangle (row-major).
#[inline]
pub(crate) fn packed_index(i: usize, j: usize) -> usize {
    i * (i + 1) / 2 + j
}

impl BlockJacobi {
    /// The inverses of the diagonal blocks of `a` on the ranges `cuts` (`0 = c₀ < … = n`).
    /// Rows of `a` must have sorted columns.
    pub fn new(a: &StiffnessMatrix, cuts: &[usize]) -> Self {
        let ptr = a.indptr().into_raw_storage();
        let (idx, val) = (a.indices(), a.data());
        let offsets = block_offsets(cuts);
        let blocks = cuts.len().saturating_sub(1);
        let mut dense = vec![0.0; offsets[blocks]];
        let parts = split_into(&mut dense, (0..blocks).map(|b| offsets[b + 1] - offsets[b]));
        parts
            .into_par_iter()
            .enumerate()
            .with_min_len(64)
            .for_each(|(b, block)| {
                let start = cuts[b];
                let k = cuts[b + 1] - start;
                for i in 0..k {
                    let row = start + i;
                    let cols = &idx[ptr[row]..ptr[row + 1]];
                    let from = cols.partition_point(|&c| (c as usize) < start);
                    for (&c, &v) in cols[from..].iter().zip(&val[ptr[row] + from..]) {
                        if c as usize > row {
                            break;
                        }
                        block[packed_index(i, c as usize - start)] = v;
                    }
                }
            });
        Self::from_blocks(cuts, offsets, dense)
    }

    /// From the diagonal blocks themselves: block b (rows and columns `cuts[b]..cuts[b + 1]`,
    /// its lower triangle packed as [`packed_index`] says) at `dense[offsets[b]..offsets[b + 1]]`,
    /// with `offsets` those of [`block_offsets`]; inverted in place.
    pub fn from_blocks(cuts: &[usize], offsets: Vec<usize>, mut dense: Vec<f64>) -> Self {
        let blocks = cuts.len().saturating_sub(1);
        let parts = split_into(&mut dense, (0..blocks).map(|b| offsets[b + 1] - offsets[b]));
        parts
            .into_par_iter()
            .enumerate()
            .with_min_len(64)
            .for_each_init(
                || (Vec::new(), Vec::new()),
                |(full, inverse), (b, block)| {
                    let k = cuts[b + 1] - cuts[b];
                    full.clear();
                    full.resize(k * k, 0.0);
                    for i in 0..k {
                        for j in 0..=i {
                            let v = block[packed_index(i, j)];
                            full[i * k + j] = v;
                            full[j * k + i] = v;
                        }
                    }
                    inverse.clear();
                    inverse.resize(k * k, 0.0);
                    invert_spd(full, k, inverse);
                    for i in 0..k {
                        for j in 0..=i {
                            block[packed_index(i, j)] = inverse[i * k + j];
                        }
                    }
                },
            );
        let mut tasks = vec![0];
        for b in 0..blocks {
            if cuts[b + 1] - cuts[tasks[tasks.len() - 1]] >= DOFS_PER_TASK {
                tasks.push(b + 1);
            }
        }
        if tasks[tasks.len() - 1] != blocks {
            tasks.push(blocks);
        }
        BlockJacobi {
            starts: cuts.to_vec(),
            offsets,
            inverses: dense,
            tasks,
        }
    }

    /// Number of dofs.
    pub fn len(&self) -> usize {
        self.starts.last().copied().unwrap_or(0)
    }

    /// z = B r.
    pub fn apply(&self, r: &[f64], z: &mut [f64]) {
        self.apply_tasks(0, self.tasks.len() - 1, r, z, 0);
    }

    /// Tasks `t0..t1` on `z`, which starts at dof `offset`; halves recursively.
    fn apply_tasks(&self, t0: usize, t1: usize, r: &[f64], z: &mut [f64], offset: usize) {
        if t1 <= t0 {
            return;
        }
        if t1 - t0 == 1 {
            for b in self.tasks[t0]..self.tasks[t0 + 1] {
                let (start, end) = (self.starts[b], self.starts[b + 1]);
                let inverse = &self.inverses[self.offsets[b]..self.offsets[b + 1]];
                let rb = &r[start..end];
                let zb = &mut z[start - offset..end - offset];
                // The common sizes (a vertex or a one-node entity, two or three nodes) with
                // the size a constant: the loops unroll (the same sums, the same bits).
                match end - start {
                    3 => packed_product::<3>(inverse, rb, zb),
                    6 => packed_product::<6>(inverse, rb, zb),
                    9 => packed_product::<9>(inverse, rb, zb),
                    _ => packed_product_any(inverse, rb, zb),
                }
            }
            return;
        }
        let mid = (t0 + t1) / 2;
        let split = self.starts[self.tasks[mid]];
        let (left, right) = z.split_at_mut(split - offset);
        rayon::join(
            || self.apply_tasks(t0, mid, r, left, offset),
            || self.apply_tasks(mid, t1, r, right, split),
        );
    }
}

/// z = M r for the symmetric M whose lower triangle is packed in `inverse` (K × K), K a
/// constant.
#[inline(always)]
fn packed_product<const K: usize>(inverse: &[f64], r: &[f64], z: &mut [f64]) {
    let mut out = [0.0; K];
    packed_product_into(&inverse[..K * (K + 1) / 2], &r[..K], &mut out);
    z[..K].copy_from_slice(&out);
}

/// [`packed_product`] for any size.
fn packed_product_any(inverse: &[f64], r: &[f64], z: &mut [f64]) {
    z.fill(0.0);
    packed_product_into(inverse, r, z);
}

/// z += M r (`r.len()` × `r.len()`, packed lower triangle): row i gives z_i its columns
/// j ≤ i and, by symmetry, each z_j (j < i) its column i.
#[inline(always)]
fn packed_product_into(inverse: &[f64], r: &[f64], z: &mut [f64]) {
    for i in 0..r.len() {
        let row = &inverse[packed_index(i, 0)..packed_index(i, 0) + i + 1];
        let ri = r[i];
        let mut zi = 0.0;
        for j in 0..i {
            zi += row[j] * r[j];
            z[j] += row[j] * ri;
        }
        z[i] += zi + row[i] * ri;
    }
}

#[cfg(test)]
#[path = "tests/block_jacobi.rs"]
mod tests;
