//! The condensed stiffness operator Tᵀ K T applied cell by cell, never assembled.
//!
//! The elastic solve runs on the straight-sided mesh, whose simplices are affine: with
//! J⁻¹ = ∂ξ/∂x constant, the element matrix is a fixed combination of the reference
//! matrices S_αβ = ∫ ∂_αΦ ∂_βΦᵀ dξ (see [`crate::element_matrix`]). Every ∂Φ_b/∂ξ_α lies in
//! P_(p−1), of dimension m < n, so the stacked matrix [S_αβ] has rank m and factors as
//! S_αβ = R_αᵀ R_β with R_α of size m × n ([`ReferenceGradients`]). The action y_e = K_e x_e
//! of a cell with nodal displacements X (n × dim) is then
//!
//! U_α = R_α X (the gradient modes),  ∇u_k = Σ_α U_α[k] ⊗ J⁻¹_α,
//! σ_k = |det J| (λ tr(∇u_k) I + μ (∇u_k + ∇u_kᵀ)),  Y = Σ_α R_αᵀ (σ_k J⁻¹_α)_k,
//!
//! 4 dim² m n flops and nothing stored per cell but J⁻¹ and |det J| — where the assembled
//! matrix keeps about (n dim)²/2 numbers per cell (at p = 3, 1 800 against 10; at p = 8,
//! 120 000). Cells are visited in the coloured runs of [`crate::cell_runs`]: the result does
//! not depend on the number of threads.
//!
//! The same factors give the diagonal blocks of Tᵀ K T that the block-Jacobi smoother
//! inverts ([`MatrixFreeStiffness::block_jacobi`]).

use std::sync::atomic::AtomicU64;

use faer::{Mat, Side};
use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::Shape;
use rayon::prelude::*;

use crate::block_jacobi::{block_offsets, BlockJacobi};
use crate::cell_runs::{add_to, prefetch, CellRuns, ReducedNodes, SharedSum};
use crate::condensation::Constraints;
use crate::element_matrix::invert_jacobian;
use crate::pcg::LinearOperator;
use crate::reference_element::ReferenceStiffness;
use crate::{ElasticError, Material};

/// Eigenvalues of [S_αβ] below this fraction of the largest are round-off (the exact ones
/// are zero beyond rank m; the smallest kept one is above 1e-3 of the largest up to p = 10).
const RANK_TOLERANCE: f64 = 1e-10;
/// How many of a run's nodes ahead the gathers and scatters prefetch.
const PREFETCH_AHEAD: usize = 12;
/// Outputs accumulated together in the cell action's two products (two AVX2 registers).
const LANES: usize = 8;

/// The factors R_α of one simplex's reference stiffness matrices: S_αβ = R_αᵀ R_β.
#[derive(Debug, Clone)]
pub(crate) struct ReferenceGradients {
    dim: usize,
    /// Nodes n.
    n: usize,
    /// Rank m (the dimension of P_(p−1)).
    m: usize,
    /// dim m rounded up to [`LANES`], and n likewise.
    rows_padded: usize,
    n_padded: usize,
    /// R_α[k][b] at `(α m + k) n_padded + b`, zero beyond n.
    factors: Vec<f64>,
    /// The same transposed: R_α[k][b] at `b rows_padded + α m + k`, zero beyond dim m. Both
    /// orders let the two products of the action accumulate [`LANES`] outputs in registers
    /// along unit-stride rows.
    transposed: Vec<f64>,
    /// S_αβ[a][b] at `(α dim + β) n² + a n + b` (for the diagonal blocks).
    stiffness: Vec<Vec<f64>>,
}

impl ReferenceGradients {
    /// From the reference matrices of `reference` (a simplex), by the eigen-decomposition of
    /// the stacked matrix [S_αβ] (size dim·n): R = Λ^½ Vᵀ over the eigenvalues above round-off.
    pub fn new(reference: &ReferenceStiffness) -> Result<Self, ElasticError> {
        let (dim, n) = (reference.dim, reference.len);
        let Some(s) = &reference.simplex_stiffness else {
            return Err(ElasticError::Factorization {
                what: "reference stiffness",
                message: format!("{} is not a simplex", reference.shape.name()),
            });
        };
        let size = dim * n;
        let stacked = Mat::from_fn(size, size, |i, j| {
            let (alpha, a) = (i / n, i % n);
            let (beta, b) = (j / n, j % n);
            s[alpha * dim + beta][a * n + b]
        });
        let eigen =
            stacked
                .self_adjoint_eigen(Side::Lower)
                .map_err(|e| ElasticError::Factorization {
                    what: "reference stiffness",
                    message: format!("eigen-decomposition: {e:?}"),
                })?;
        let values = eigen.S().column_vector();
        let vectors = eigen.U();
        let largest = (0..size).map(|i| values[i]).fold(0.0f64, f64::max);
        let kept: Vec<usize> = (0..size)
            .filter(|&i| values[i] > RANK_TOLERANCE * largest)
            .collect();
        let m = kept.len();
        let mut factors = vec![0.0; dim * m * n];
        for (k, &i) in kept.iter().enumerate() {
            let root = values[i].sqrt();
            for alpha in 0..dim {
                for b in 0..n {
                    factors[(alpha * m + k) * n + b] = root * vectors[(alpha * n + b, i)];
                }
            }
        }
        let rows = dim * m;
        let rows_padded = rows.div_ceil(LANES) * LANES;
        let n_padded = n.div_ceil(LANES) * LANES;
        let mut transposed = vec![0.0; rows_padded * n];
        let mut padded = vec![0.0; rows * n_padded];
        for i in 0..rows {
            for b in 0..n {
                transposed[b * rows_padded + i] = factors[i * n + b];
                padded[i * n_padded + b] = factors[i * n + b];
            }
        }
        Ok(ReferenceGradients {
            dim,
            n,
            m,
            rows_padded,
            n_padded,
            factors: padded,
            transposed,
            stiffness: s.clone(),
        })
    }

    /// The rank m.
    #[cfg(test)]
    pub fn rank(&self) -> usize {
        self.m
    }

    /// R_α[k][b].
    #[cfg(test)]
    pub fn factor(&self, alpha: usize, k: usize, b: usize) -> f64 {
        self.factors[(alpha * self.m + k) * self.n_padded + b]
    }
}

/// Tᵀ K T of a mesh of straight simplices, applied cell by cell.
pub(crate) struct MatrixFreeStiffness {
    dim: usize,
    reference: ReferenceGradients,
    /// The cells in coloured runs; `geometry` follows their order.
    runs: CellRuns,
    /// Per cell: J⁻¹ (`inv[α][c]` at 3α + c) and |det J| times the cell's stiffening.
    geometry: Vec<[f64; 10]>,
    lambda: f64,
    mu: f64,
    nodes: ReducedNodes,
    /// The [`ReducedNodes::slot`] of each of [`CellRuns::run_nodes`].
    slots: Vec<u32>,
    /// Whether the CPU has AVX2 (for [`MatrixFreeStiffness::cell_action`]).
    avx2: bool,
    sums: SharedSum,
}

impl MatrixFreeStiffness {
    /// Whether every cell of `mesh` is a straight-sided simplex of the mesh's dimension,
    /// all of one shape (what [`MatrixFreeStiffness::new`] takes).
    pub fn applies(mesh: &HighOrderMesh) -> bool {
        let shape = match mesh.dim {
            2 => Shape::Tri,
            3 => Shape::Tet,
            _ => return false,
        };
        if mesh.cells.iter().any(|c| c.kind != shape) || mesh.cells.is_empty() {
            return false;
        }
        let Ok(reference) = ReferenceStiffness::new(shape, mesh.order, mesh.family) else {
            return false;
        };
        mesh.cells.par_iter().all(|cell| {
            cell.nodes.len() == reference.len
                && cell.nodes.iter().all(|&n| (n as usize) < mesh.nodes.len())
                && {
                    let coords: Vec<[f64; 3]> =
                        cell.nodes.iter().map(|&n| mesh.nodes[n as usize]).collect();
                    reference.is_affine_simplex(&coords)
                }
        })
    }

    /// The operator of `mesh` (which [`MatrixFreeStiffness::applies`] to) under
    /// `constraints`, each cell c's Lamé parameters multiplied by `stiffening[c]` when given.
    pub fn new(
        mesh: &HighOrderMesh,
        material: &Material,
        stiffening: Option<&[f64]>,
        constraints: &Constraints,
    ) -> Result<Self, ElasticError> {
        material.validate()?;
        let dim = mesh.dim;
        let shape = if dim == 2 { Shape::Tri } else { Shape::Tet };
        let stiffness = ReferenceStiffness::new(shape, mesh.order, mesh.family)?;
        let reference = ReferenceGradients::new(&stiffness)?;
        let n = stiffness.len;
        for (c, cell) in mesh.cells.iter().enumerate() {
            if cell.nodes.len() != n || cell.kind != shape {
                return Err(ElasticError::WrongNodeCount {
                    cell: c,
                    found: cell.nodes.len(),
                    expected: n,
                });
            }
        }
        let runs = CellRuns::new(mesh, n);
        let geometry = runs
            .order
            .par_iter()
            .map(|&c| {
                let c = c as usize;
                let cell = &mesh.cells[c];
                let vertex = |v: usize| mesh.nodes[cell.nodes[v] as usize];
                let mut jac = [[0.0; 3]; 3];
                for alpha in 0..dim {
                    for d in 0..dim {
                        jac[d][alpha] = vertex(alpha + 1)[d] - vertex(0)[d];
                    }
                }
                let (inv, det) = invert_jacobian(&jac, dim);
                if !det.is_finite() || det == 0.0 {
                    return Err(ElasticError::DegenerateCell {
                        cell: c,
                        jacobian: det,
                    });
                }
                let mut g = [0.0; 10];
                for alpha in 0..3 {
                    g[3 * alpha..3 * alpha + 3].copy_from_slice(&inv[alpha]);
                }
                g[9] = det.abs() * stiffening.map_or(1.0, |s| s[c]);
                Ok(g)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let (lambda, mu) = material.lame();
        let nodes = ReducedNodes::new(constraints);
        if !nodes.slots_fit() {
            return Err(ElasticError::Factorization {
                what: "matrix-free operator",
                message: format!("{} unknowns do not fit 31-bit indices", nodes.len()),
            });
        }
        let slots = runs
            .run_nodes()
            .par_iter()
            .map(|&v| nodes.slot(v as usize))
            .collect();
        Ok(MatrixFreeStiffness {
            dim,
            reference,
            runs,
            geometry,
            lambda,
            mu,
            nodes,
            slots,
            #[cfg(target_arch = "x86_64")]
            avx2: std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(not(target_arch = "x86_64"))]
            avx2: false,
            sums: SharedSum::default(),
        })
    }

    /// Number of reduced unknowns.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// The load −Tᵀ K u_p that the prescribed displacements (`constraints.prescribed`, a
    /// full dof vector) put on the reduced unknowns.
    pub fn prescribed_load(&self, constraints: &Constraints) -> Vec<f64> {
        let dim = self.dim;
        let u = &constraints.prescribed;
        let mut out = vec![0.0; self.len()];
        let run_nodes = self.runs.run_nodes();
        self.accumulate(
            |i| {
                let node = run_nodes[i] as usize;
                let mut v = [0.0; 3];
                if self.nodes.is_fixed(node) {
                    (0..dim).for_each(|d| v[d] = u[node * dim + d]);
                }
                v
            },
            &[],
            &mut out,
        );
        out.par_iter_mut().for_each(|v| *v = -*v);
        out
    }

    /// y = Σ over cells of Tᵀ K_e x_e, the displacement of each cell node from `gather(i)`,
    /// i its place in [`CellRuns::run_nodes`].
    /// `source` is the vector `gather` reads (for prefetching; empty if none).
    fn accumulate(&self, gather: impl Fn(usize) -> [f64; 3] + Sync, source: &[f64], y: &mut [f64]) {
        let (n, n_padded, dim) = (self.reference.n, self.reference.n_padded, self.dim);
        self.sums.collect(y, |sums| {
            self.runs
                .for_each_run(CellScratch::default, |scratch, run| {
                    let range = self.runs.run_range(run);
                    let len = range.len();
                    // The run's nodal values (component d of its node j at d len + j) and results.
                    scratch.run_x.resize(dim * len, 0.0);
                    scratch.run_y.clear();
                    scratch.run_y.resize(dim * len, 0.0);
                    for (j, i) in range.clone().enumerate() {
                        if let Some(&ahead) = self.slots.get(i + PREFETCH_AHEAD) {
                            if let Some(f) = self.nodes.first_of_slot(ahead) {
                                prefetch(source, f);
                            }
                        }
                        let v = gather(i);
                        for d in 0..dim {
                            scratch.run_x[d * len + j] = v[d];
                        }
                    }
                    for c in self.runs.cells_of_run(run) {
                        let local = self.runs.local(c);
                        // Every entry is overwritten.
                        scratch.x.resize(dim * n, 0.0);
                        for (a, &j) in local.iter().enumerate() {
                            for d in 0..dim {
                                scratch.x[d * n + a] = scratch.run_x[d * len + j as usize];
                            }
                        }
                        self.cell_action(c, scratch);
                        for (a, &j) in local.iter().enumerate() {
                            for d in 0..dim {
                                scratch.run_y[d * len + j as usize] += scratch.y[d * n_padded + a];
                            }
                        }
                    }
                    for (j, &slot) in self.slots[range.clone()].iter().enumerate() {
                        if let Some(&ahead) = self.slots.get(range.start + j + PREFETCH_AHEAD) {
                            if let Some(f) = self.nodes.first_of_slot(ahead) {
                                sums.prefetch(f);
                            }
                        }
                        let mut v = [0.0; 3];
                        (0..dim).for_each(|d| v[d] = scratch.run_y[d * len + j]);
                        self.nodes
                            .restrict_slot(slot, v, |i, value| sums.add(i, value));
                    }
                });
        });
    }

    /// scratch.y = K_c scratch.x for cell c (module documentation); both hold component d
    /// of node b at `d n + b`. With AVX2 where the CPU has it: the same operations in the
    /// same order (no fused multiply-add), so the same bits, on 4 lanes instead of 2.
    fn cell_action(&self, c: usize, scratch: &mut CellScratch) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only when the running CPU reports AVX2.
            unsafe { self.cell_action_avx2(c, scratch) };
            return;
        }
        self.cell_action_body(c, scratch);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn cell_action_avx2(&self, c: usize, scratch: &mut CellScratch) {
        self.cell_action_body(c, scratch);
    }

    #[inline(always)]
    fn cell_action_body(&self, c: usize, scratch: &mut CellScratch) {
        if self.dim == 2 {
            self.cell_action_in::<2>(c, scratch);
        } else {
            self.cell_action_in::<3>(c, scratch);
        }
    }

    /// The cell action in dimension D (a constant, so that the accumulators stay in
    /// registers).
    #[inline(always)]
    fn cell_action_in<const D: usize>(&self, c: usize, scratch: &mut CellScratch) {
        let ReferenceGradients {
            n,
            m,
            rows_padded,
            n_padded,
            ..
        } = self.reference;
        let rows = D * m;
        let g = &self.geometry[c];
        let inv = |alpha: usize, d: usize| g[3 * alpha + d];
        let w = g[9];
        let CellScratch { x, y, modes, .. } = scratch;
        // U_d[α m + k] = Σ_b R_α[k][b] X_d[b], LANES of (α, k) at a time.
        modes.resize(D * rows_padded, 0.0);
        lane_products::<D>(&self.reference.transposed, x, n, n, modes, rows_padded);
        // Per mode: ∇u[d][c] = ∂u_d/∂x_c, the stress, and back to reference directions.
        for k in 0..m {
            let mut grad = [[0.0; 3]; 3];
            for alpha in 0..D {
                for d in 0..D {
                    let u = modes[d * rows_padded + alpha * m + k];
                    for cc in 0..D {
                        grad[d][cc] += u * inv(alpha, cc);
                    }
                }
            }
            let trace: f64 = (0..D).map(|d| grad[d][d]).sum();
            let mut stress = [[0.0; 3]; 3];
            for d in 0..D {
                for cc in 0..D {
                    stress[d][cc] = w * self.mu * (grad[d][cc] + grad[cc][d]);
                }
                stress[d][d] += w * self.lambda * trace;
            }
            for alpha in 0..D {
                for d in 0..D {
                    modes[d * rows_padded + alpha * m + k] =
                        (0..D).map(|cc| stress[d][cc] * inv(alpha, cc)).sum();
                }
            }
        }
        // Y_d[b] = Σ_(α, k) R_α[k][b] V_d[α m + k], LANES of b at a time.
        y.resize(D * n_padded, 0.0);
        lane_products::<D>(
            &self.reference.factors,
            modes,
            rows_padded,
            rows,
            y,
            n_padded,
        );
    }

    /// Block Jacobi over the reduced dof ranges `cuts` (each a whole number of nodes): the
    /// diagonal blocks of Tᵀ K T summed cell by cell from the reference matrices.
    pub fn block_jacobi(&self, cuts: &[usize]) -> BlockJacobi {
        let nodes = self.nodes.nodes();
        let first = self.nodes.first();
        let blocks = cuts.len().saturating_sub(1);
        // The block of each node with free directions.
        let mut block_of = vec![u32::MAX; nodes];
        let mut b = 0;
        for node in 0..nodes {
            if first[node + 1] > first[node] {
                while cuts[b + 1] <= first[node] {
                    b += 1;
                }
                block_of[node] = b as u32;
            }
        }
        let offsets = block_offsets(cuts);
        let dense: Vec<AtomicU64> = (0..offsets[blocks])
            .into_par_iter()
            .map(|_| AtomicU64::new(0))
            .collect();
        let add = |slot: usize, value: f64| add_to(&dense[slot], value);
        let ReferenceGradients { dim, n, .. } = self.reference;
        let s = &self.reference.stiffness;
        let (lambda, mu) = (self.lambda, self.mu);
        self.runs.for_each_run(Vec::new, |nodes, run| {
            let distinct = self.runs.nodes_of_run(run);
            for c in self.runs.cells_of_run(run) {
                nodes.clear();
                nodes.extend(self.runs.local(c).iter().map(|&j| distinct[j as usize]));
                let g = &self.geometry[c];
                for (a, &na) in nodes.iter().enumerate() {
                    let na = na as usize;
                    let block = block_of[na];
                    if block == u32::MAX {
                        continue;
                    }
                    let start = cuts[block as usize];
                    let k = cuts[block as usize + 1] - start;
                    for (bb, &nb) in nodes.iter().enumerate() {
                        let nb = nb as usize;
                        if block_of[nb] != block {
                            continue;
                        }
                        // G = |det J| J⁻ᵀ [S_αβ[a][bb]] J⁻¹, K_ab = λ G + μ Gᵀ + μ tr G I.
                        let mut t = [[0.0; 3]; 3];
                        for alpha in 0..dim {
                            for beta in 0..dim {
                                t[alpha][beta] = s[alpha * dim + beta][a * n + bb];
                            }
                        }
                        let mut gm = [[0.0; 3]; 3];
                        for cc in 0..dim {
                            for d in 0..dim {
                                let mut sum = 0.0;
                                for alpha in 0..dim {
                                    for beta in 0..dim {
                                        sum += g[3 * alpha + cc] * t[alpha][beta] * g[3 * beta + d];
                                    }
                                }
                                gm[cc][d] = g[9] * sum;
                            }
                        }
                        let trace: f64 = (0..dim).map(|d| gm[d][d]).sum();
                        let mut kab = [[0.0; 3]; 3];
                        for cc in 0..dim {
                            for d in 0..dim {
                                kab[cc][d] = lambda * gm[cc][d] + mu * gm[d][cc];
                            }
                            kab[cc][cc] += mu * trace;
                        }
                        let (qa, ka) = self.nodes.directions(na);
                        let (qb, kb) = self.nodes.directions(nb);
                        let (rows, cols) = (&qa[..ka], &qb[..kb]);
                        let (ra, rb) = (first[na] - start, first[nb] - start);
                        for (i, qi) in rows.iter().enumerate() {
                            for (j, qj) in cols.iter().enumerate() {
                                let mut v = 0.0;
                                for cc in 0..dim {
                                    for d in 0..dim {
                                        v += qi[cc] * kab[cc][d] * qj[d];
                                    }
                                }
                                add(offsets[block as usize] + (ra + i) * k + rb + j, v);
                            }
                        }
                    }
                }
            }
        });
        let dense: Vec<f64> = dense
            .into_iter()
            .map(|v| f64::from_bits(v.into_inner()))
            .collect();
        BlockJacobi::from_blocks(cuts, offsets, dense)
    }
}

impl LinearOperator for MatrixFreeStiffness {
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        self.accumulate(|i| self.nodes.expand_slot(self.slots[i], x), x, y);
    }
}

/// One thread's buffers for [`MatrixFreeStiffness::cell_action`].
#[derive(Default)]
struct CellScratch {
    run_x: Vec<f64>,
    run_y: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    modes: Vec<f64>,
}

/// out_d[j] = Σ_(i < inner) input_d[i] · matrix[i][j] for every component d < D, the
/// rows of `matrix` and of `out` being `width` long (a multiple of [`LANES`]), `input`'s
/// `input_stride`: both of the cell action's products (R X and Rᵀ V). LANES outputs per
/// component accumulate in registers, the sums in the order of i.
#[inline(always)]
fn lane_products<const D: usize>(
    matrix: &[f64],
    input: &[f64],
    input_stride: usize,
    inner: usize,
    out: &mut [f64],
    width: usize,
) {
    for j0 in (0..width).step_by(LANES) {
        let mut acc = [[0.0f64; LANES]; D];
        for i in 0..inner {
            let row = &matrix[i * width + j0..i * width + j0 + LANES];
            for d in 0..D {
                let v = input[d * input_stride + i];
                for k in 0..LANES {
                    acc[d][k] += v * row[k];
                }
            }
        }
        for d in 0..D {
            out[d * width + j0..d * width + j0 + LANES].copy_from_slice(&acc[d]);
        }
    }
}

#[cfg(test)]
#[path = "tests/matrix_free.rs"]
mod tests;
