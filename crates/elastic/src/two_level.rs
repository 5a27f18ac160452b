//! The two-level preconditioner of the PCG solver: a Chebyshev-accelerated node-block
//! Jacobi smoother on the order-p problem and an exact coarse solve of the p = 1 problem
//! on the mesh vertices.
//!
//! Coarse space: vertex displacements, prolongated to every node by the vertex (linear,
//! bilinear, …) shape functions of a cell containing it, P; the coarse matrix is the
//! Galerkin product A_c = Pᵀ A P on the reduced (free) dofs, factorised once by sparse
//! Cholesky. One application (a symmetric V-cycle, so that PCG stays valid):
//!
//! z = S r;  z ← z + P A_c⁻¹ Pᵀ (r − A z);  z ← z + S (r − A z),
//!
//! where S = q(D⁻¹A) D⁻¹ is the Chebyshev polynomial smoother on [λ_max/ratio, λ_max] of
//! the block-diagonal-preconditioned operator (D = the dim × dim diagonal blocks of A,
//! λ_max estimated by power iteration and enlarged by 10 %). S is symmetric and
//! ‖I − S A‖_A < 1 when λ_max is an upper bound, so the preconditioner is SPD.

use hocurve_mesh::HighOrderMesh;
use rayon::prelude::*;

use crate::condensation::Constraints;
use crate::pcg::Preconditioner;
use crate::reference_element::ReferenceElement;
use crate::sparse::{from_rows, product, transpose, Cholesky};
use crate::sparsity::Adjacency;
use crate::vector_ops::{norm, residual, spmv};
use crate::{ElasticError, StiffnessMatrix};
use hocurve_nodes::Shape;
use std::collections::BTreeMap;

/// Lower end of the smoothed spectrum: λ_max / SMOOTHING_RATIO (30 halved the solve time
/// of 15 at equal iterations on a 4³-cube tet mesh, p = 2..5).
const SMOOTHING_RATIO: f64 = 30.0;
/// Power iterations for λ_max(D⁻¹A).
const POWER_ITERATIONS: usize = 25;

pub(crate) struct TwoLevel<'a> {
    a: &'a StiffnessMatrix,
    /// Node of each reduced dof and its index within the node.
    dof_node: Vec<(u32, u8)>,
    first: &'a [usize],
    /// Inverse of each node's diagonal block, row-major in a 3 × 3 array.
    block_inverse: Vec<[f64; 9]>,
    prolongation: StiffnessMatrix,
    restriction: StiffnessMatrix,
    coarse: Option<Cholesky>,
    /// Chebyshev interval [low, high] and degree.
    low: f64,
    high: f64,
    degree: usize,
    scratch: [Vec<f64>; 5],
    coarse_rhs: Vec<f64>,
}

/// Inverse of a k × k symmetric block (k ≤ 3) stored row-major with stride 3; falls back
/// to the inverse diagonal if the block is singular.
fn invert_block(m: &[[f64; 3]; 3], k: usize) -> [f64; 9] {
    let mut out = [0.0; 9];
    let det = match k {
        1 => m[0][0],
        2 => m[0][0] * m[1][1] - m[0][1] * m[1][0],
        _ => crate::element_matrix::invert_jacobian(m, 3).1,
    };
    if !(det.is_finite() && det.abs() > 0.0) {
        for i in 0..k {
            out[i * 3 + i] = if m[i][i] != 0.0 { 1.0 / m[i][i] } else { 0.0 };
        }
        return out;
    }
    match k {
        1 => out[0] = 1.0 / m[0][0],
        2 => {
            out[0] = m[1][1] / det;
            out[1] = -m[0][1] / det;
            out[3] = -m[1][0] / det;
            out[4] = m[0][0] / det;
        }
        _ => {
            let (inv, _) = crate::element_matrix::invert_jacobian(m, 3);
            for i in 0..3 {
                for j in 0..3 {
                    out[i * 3 + j] = inv[i][j];
                }
            }
        }
    }
    out
}

impl<'a> TwoLevel<'a> {
    pub fn new(
        a: &'a StiffnessMatrix,
        constraints: &'a Constraints,
        mesh: &HighOrderMesh,
        cells_of_node: &Adjacency,
        references: &BTreeMap<Shape, ReferenceElement>,
        degree: usize,
    ) -> Result<Self, ElasticError> {
        let nodes = constraints.count.len();
        let first = &constraints.first;
        let size = constraints.len();
        let mut dof_node = Vec::with_capacity(size);
        for n in 0..nodes {
            for i in 0..constraints.count[n] {
                dof_node.push((n as u32, i));
            }
        }
        // Diagonal blocks.
        let ptr = a.indptr().into_raw_storage();
        let (idx, val) = (a.indices(), a.data());
        let block_inverse: Vec<[f64; 9]> = (0..nodes)
            .into_par_iter()
            .map(|n| {
                let k = constraints.count[n] as usize;
                let mut m = [[0.0; 3]; 3];
                for i in 0..k {
                    let row = first[n] + i;
                    let cols = &idx[ptr[row]..ptr[row + 1]];
                    if let Ok(start) = cols.binary_search(&(first[n] as u32)) {
                        for j in 0..k {
                            m[i][j] = val[ptr[row] + start + j];
                        }
                    }
                }
                invert_block(&m, k)
            })
            .collect();

        // Prolongation from the vertices' reduced dofs (nodes 0..V come first, so their
        // reduced dofs are 0..first[V]) to all reduced dofs.
        let vertices = mesh.layout.num_vertices.min(nodes);
        let coarse_size = first[vertices];
        let rows: Vec<Vec<(u32, f64)>> = (0..nodes)
            .into_par_iter()
            .flat_map_iter(|n| {
                let kn = constraints.count[n] as usize;
                let mut entries = Vec::new();
                if let Some(&c) = cells_of_node.row(n).first() {
                    let cell = &mesh.cells[c as usize];
                    // Assembly has checked every cell's shape: the lookups cannot fail.
                    let reference = cell.kind.shape().ok().and_then(|s| references.get(&s));
                    let local = cell.nodes.iter().position(|&x| x as usize == n);
                    if let (Some(reference), Some(local)) = (reference, local) {
                        let weights = &reference.vertex_weights[local];
                        for v in 0..reference.shape.num_vertices() {
                            let vertex = cell.nodes[v] as usize;
                            let w = weights[v];
                            if w.abs() < 1e-14 || vertex >= vertices {
                                continue;
                            }
                            entries.push((vertex, w));
                        }
                    }
                }
                entries.sort_by_key(|e| e.0);
                let dim = constraints.dim;
                (0..kn).map(move |i| {
                    let qn = &constraints.directions[n];
                    let mut row = Vec::new();
                    for &(v, w) in &entries {
                        let qv = &constraints.directions[v];
                        for j in 0..constraints.count[v] as usize {
                            let q: f64 = (0..dim).map(|c| qn[i][c] * qv[j][c]).sum();
                            if q != 0.0 {
                                row.push(((first[v] + j) as u32, w * q));
                            }
                        }
                    }
                    row
                })
            })
            .collect();
        let prolongation = from_rows(coarse_size, rows);
        let restriction = transpose(&prolongation);
        let coarse = if coarse_size > 0 {
            let coarse_matrix = product(&restriction, &product(a, &prolongation));
            Some(Cholesky::new(&coarse_matrix, "coarse matrix")?)
        } else {
            None
        };

        let mut two_level = TwoLevel {
            a,
            dof_node,
            first,
            block_inverse,
            prolongation,
            restriction,
            coarse,
            low: 0.0,
            high: 0.0,
            degree: degree.max(1),
            scratch: std::array::from_fn(|_| vec![0.0; size]),
            coarse_rhs: vec![0.0; coarse_size],
        };
        let lambda_max = two_level.estimate_lambda_max();
        two_level.high = 1.1 * lambda_max;
        two_level.low = two_level.high / SMOOTHING_RATIO;
        Ok(two_level)
    }

    /// z = D⁻¹ r.
    fn block_jacobi(&self, r: &[f64], z: &mut [f64]) {
        z.par_iter_mut()
            .with_min_len(1024)
            .enumerate()
            .for_each(|(i, zi)| {
                let (n, local) = self.dof_node[i];
                let n = n as usize;
                let start = self.first[n];
                let k = self.first[n + 1] - start;
                let b = &self.block_inverse[n];
                *zi = (0..k)
                    .map(|j| b[local as usize * 3 + j] * r[start + j])
                    .sum();
            });
    }

    /// λ_max(D⁻¹A) by power iteration from a fixed start vector.
    fn estimate_lambda_max(&mut self) -> f64 {
        let n = self.dof_node.len();
        if n == 0 {
            return 1.0;
        }
        let mut x: Vec<f64> = (0..n)
            .map(|i| 1.0 + ((i.wrapping_mul(2_654_435_761) >> 7) % 1000) as f64 / 1000.0)
            .collect();
        let mut ax = vec![0.0; n];
        let mut y = vec![0.0; n];
        let mut lambda = 1.0;
        for _ in 0..POWER_ITERATIONS {
            let len = norm(&x);
            if len == 0.0 {
                break;
            }
            x.iter_mut().for_each(|v| *v /= len);
            spmv(self.a, &x, &mut ax);
            self.block_jacobi(&ax, &mut y);
            lambda = norm(&y);
            std::mem::swap(&mut x, &mut y);
        }
        if lambda.is_finite() && lambda > 0.0 {
            lambda
        } else {
            1.0
        }
    }

    /// x = S r: `degree` Chebyshev steps for A x = r from x = 0 (Saad, Alg. 12.1, with the
    /// block-Jacobi preconditioner).
    fn chebyshev(&self, r: &[f64], x: &mut [f64], res: &mut [f64], d: &mut [f64], w: &mut [f64]) {
        let theta = 0.5 * (self.high + self.low);
        let delta = 0.5 * (self.high - self.low);
        let sigma = theta / delta;
        let mut rho = 1.0 / sigma;
        self.block_jacobi(r, d);
        d.par_iter_mut().for_each(|v| *v /= theta);
        x.iter_mut().for_each(|v| *v = 0.0);
        res.copy_from_slice(r);
        for k in 0..self.degree {
            x.par_iter_mut().zip(&*d).for_each(|(xi, di)| *xi += di);
            if k + 1 == self.degree {
                break;
            }
            spmv(self.a, d, w);
            res.par_iter_mut().zip(&*w).for_each(|(ri, wi)| *ri -= wi);
            self.block_jacobi(res, w);
            let rho_next = 1.0 / (2.0 * sigma - rho);
            let (c1, c2) = (rho_next * rho, 2.0 * rho_next / delta);
            d.par_iter_mut()
                .zip(&*w)
                .for_each(|(di, wi)| *di = c1 * *di + c2 * wi);
            rho = rho_next;
        }
    }
}

impl Preconditioner for TwoLevel<'_> {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        let [mut t, mut res, mut d, mut w, mut s] = std::mem::take(&mut self.scratch);
        // Pre-smoothing from zero.
        self.chebyshev(r, z, &mut res, &mut d, &mut w);
        // Coarse correction on the residual.
        residual(self.a, r, z, &mut t);
        if let Some(coarse) = &self.coarse {
            let mut rc = std::mem::take(&mut self.coarse_rhs);
            spmv(&self.restriction, &t, &mut rc);
            coarse.solve_in_place(&mut rc);
            spmv(&self.prolongation, &rc, &mut w);
            z.par_iter_mut().zip(&w).for_each(|(zi, wi)| *zi += wi);
            self.coarse_rhs = rc;
        }
        // Post-smoothing: the same S on the new residual.
        residual(self.a, r, z, &mut t);
        self.chebyshev(&t, &mut s, &mut res, &mut d, &mut w);
        z.par_iter_mut().zip(&s).for_each(|(zi, si)| *zi += si);
        self.scratch = [t, res, d, w, s];
    }
}
