//! Newton's method on a patch's distortion energy, from where the conjugate gradients
//! stopped: they stop after a fixed budget or a small relative decrease, at a point that
//! depends on the path they took, so that the same patch with its fixed nodes moved by
//! round-off (one model read from STEP and from IGES) ends 1e-3 of an element apart.
//! Newton's steps converge quadratically to the minimum itself, which moves only as much
//! as the data do.

use rayon::prelude::*;

use crate::energy::{DistortionEnergy, Mat};
use crate::optimise::{dot, moved, neg, norm};
use crate::NodeConstraint;

/// Newton iterations at most (each converges the next digits; 10–20 are typical).
const MAX_NEWTON: usize = 60;
/// Conjugate-gradient iterations per Newton step, at most.
const MAX_LINEAR: usize = 1000;
/// Pairs of free nodes coupled by the cells of a patch (counted per cell) beyond which
/// Newton's method is not tried (the conjugate gradients' result stays): ~34 MB of
/// pattern and at most ~600 MB of 3 × 3 blocks, reached by patches of ~7000 tetrahedra at
/// p = 4 (~40 000 free nodes), far beyond the few hundred nodes a repair usually moves.
const MAX_COUPLINGS: usize = 1 << 23;
/// Σ over a patch's cells of (free nodes)² × (sample points) beyond which Newton's method
/// is not tried (the conjugate gradients' result stays): forming the Hessian costs ~27
/// flops per unit, so this is ~3 GFlop (about a second here) per Newton iteration. The
/// parts whose repair decides STEP ≡ IGES need up to 4e7 (filleted_boss at p = 4); a
/// patch of p = 9 tetrahedra needs 1.5e9 and took minutes. (A Hessian-free Newton–CG,
/// whose products cost a gradient each, would lift this limit.)
const MAX_HESSIAN_WORK: usize = 100_000_000;
/// Cells whose Hessian blocks are formed at once (bounds the scratch memory).
const CHUNK: usize = 256;
/// A Newton step shorter than this fraction of the edge length ends the iteration: the
/// next would move the nodes by about its square.
const CONVERGED_STEP: f64 = 1e-11;
/// Below this fraction of the edge length a full step is in the region where Newton
/// converges quadratically, and the energy's decrease (its square) is below round-off: it
/// is taken when the energy does not rise beyond round-off, and kept when the gradient
/// shrinks.
const SMALL_STEP: f64 = 1e-5;

/// The Hessian of a patch's energy in 3 × 3 blocks, rows by free node (both triangles
/// stored, so a product is one pass over the rows).
#[derive(Debug, Clone)]
pub(crate) struct BlockHessian {
    row_start: Vec<usize>,
    columns: Vec<u32>,
    blocks: Vec<Mat>,
}

impl BlockHessian {
    /// The pattern of `energy`'s Hessian: free nodes coupled when some cell has both.
    /// None when the cells couple more than [`MAX_COUPLINGS`] pairs of free nodes (counted
    /// per cell, before the ones shared by cells are merged).
    pub(crate) fn pattern(energy: &DistortionEnergy<'_>, variables: usize) -> Option<Self> {
        let couplings: usize = energy.cells.iter().map(free_pairs).sum();
        if couplings > MAX_COUPLINGS {
            return None;
        }
        let mut rows: Vec<Vec<u32>> = vec![Vec::new(); variables];
        let mut cell_free = Vec::new();
        for cell in &energy.cells {
            cell_free.clear();
            cell_free.extend(cell.nodes.iter().filter_map(|s| match *s {
                crate::energy::Slot::Free(v) => Some(v),
                crate::energy::Slot::Fixed(_) => None,
            }));
            for &r in &cell_free {
                rows[r as usize].extend_from_slice(&cell_free);
            }
        }
        let mut row_start = Vec::with_capacity(variables + 1);
        let mut columns = Vec::new();
        row_start.push(0);
        for mut row in rows {
            row.sort_unstable();
            row.dedup();
            columns.extend_from_slice(&row);
            row_start.push(columns.len());
        }
        let blocks = vec![[[0.0; 3]; 3]; columns.len()];
        Some(BlockHessian {
            row_start,
            columns,
            blocks,
        })
    }

    fn position(&self, row: u32, column: u32) -> Option<usize> {
        let (a, b) = (
            self.row_start[row as usize],
            self.row_start[row as usize + 1],
        );
        self.columns[a..b]
            .binary_search(&column)
            .ok()
            .map(|k| a + k)
    }

    /// H at `x` into the blocks, ∇E into `grad`; the energy and smallest det T (energy +∞
    /// where the barrier is crossed). Cells are added in their order: the same bits for any
    /// thread count.
    pub(crate) fn assemble(
        &mut self,
        energy: &DistortionEnergy<'_>,
        x: &[[f64; 3]],
        delta: f64,
        grad: &mut [[f64; 3]],
    ) -> (f64, f64) {
        self.blocks.fill([[0.0; 3]; 3]);
        grad.fill([0.0; 3]);
        let (mut total, mut min_ratio) = (0.0, f64::INFINITY);
        let cells = energy.cells.len();
        let mut start = 0;
        while start < cells {
            let end = (start + CHUNK).min(cells);
            for cell in energy.cell_hessians(start..end, x, delta) {
                total += cell.energy;
                min_ratio = min_ratio.min(cell.min_ratio);
                let n = cell.variables.len();
                for (k, &r) in cell.variables.iter().enumerate() {
                    for d in 0..3 {
                        grad[r as usize][d] += cell.gradient[k][d];
                    }
                    for (l, &c) in cell.variables.iter().enumerate() {
                        if let Some(at) = self.position(r, c) {
                            let block = &mut self.blocks[at];
                            let local = &cell.blocks[k * n + l];
                            for d in 0..3 {
                                for e in 0..3 {
                                    block[d][e] += local[d][e];
                                }
                            }
                        }
                    }
                }
            }
            start = end;
        }
        (total, min_ratio)
    }

    /// out = H v, row by row (each row summed in column order).
    pub(crate) fn multiply(&self, v: &[[f64; 3]], out: &mut [[f64; 3]]) {
        out.par_iter_mut().enumerate().for_each(|(r, o)| {
            let mut sum = [0.0; 3];
            for at in self.row_start[r]..self.row_start[r + 1] {
                let (b, x) = (&self.blocks[at], &v[self.columns[at] as usize]);
                for d in 0..3 {
                    sum[d] += b[d][0] * x[0] + b[d][1] * x[1] + b[d][2] * x[2];
                }
            }
            *o = sum;
        });
    }

    /// The inverse of each diagonal block (the leading dim × dim part), or a multiple of
    /// the identity where that block is not positive definite.
    fn diagonal_inverses(&self, dim: usize) -> Vec<Mat> {
        (0..self.row_start.len() - 1)
            .map(|r| {
                let diagonal = self
                    .position(r as u32, r as u32)
                    .map_or([[0.0; 3]; 3], |at| self.blocks[at]);
                spd_inverse(&diagonal, dim)
            })
            .collect()
    }
}

/// The pairs of free nodes a cell couples: (its free nodes)².
fn free_pairs(cell: &crate::energy::CellTerm) -> usize {
    let free = cell
        .nodes
        .iter()
        .filter(|s| matches!(s, crate::energy::Slot::Free(_)))
        .count();
    free * free
}

/// The inverse of a symmetric positive definite dim × dim block by Cholesky, or
/// (1 / largest diagonal) I when it is not positive definite (I when that is not positive).
fn spd_inverse(m: &Mat, dim: usize) -> Mat {
    let mut l = [[0.0; 3]; 3];
    let mut ok = true;
    'outer: for i in 0..dim {
        for j in 0..=i {
            let mut s = m[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            if i == j {
                if s.is_nan() || s <= 0.0 {
                    ok = false;
                    break 'outer;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut inv = [[0.0; 3]; 3];
    if ok {
        // Columns of L⁻ᵀ L⁻¹ by solving L y = e_c, Lᵀ z = y.
        for c in 0..dim {
            let mut y = [0.0; 3];
            for i in 0..dim {
                let mut s = if i == c { 1.0 } else { 0.0 };
                for k in 0..i {
                    s -= l[i][k] * y[k];
                }
                y[i] = s / l[i][i];
            }
            for i in (0..dim).rev() {
                let mut s = y[i];
                for k in i + 1..dim {
                    s -= l[k][i] * inv[k][c];
                }
                inv[i][c] = s / l[i][i];
            }
        }
        if inv.iter().flatten().all(|v| v.is_finite()) {
            return inv;
        }
    }
    let largest = (0..dim).map(|i| m[i][i]).fold(0.0f64, f64::max);
    let scale = if largest > 0.0 { 1.0 / largest } else { 1.0 };
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate().take(dim) {
        row[i] = scale;
    }
    inv
}

/// Converges `x` to a minimum of the unregularised energy (δ = 0: every det T stays
/// positive) by Newton's method with Armijo backtracking, the Newton system solved by
/// preconditioned conjugate gradients to a tolerance shrinking with the gradient (inexact
/// Newton), stopped at a direction of negative curvature. `constraints` as in
/// [`crate::optimise::minimise`]. Returns the Newton iterations done (none for a patch
/// beyond [`MAX_HESSIAN_WORK`] or [`MAX_COUPLINGS`]).
pub(crate) fn converge(
    energy: &DistortionEnergy<'_>,
    x: &mut [[f64; 3]],
    length: f64,
    constraints: &[Option<NodeConstraint>],
) -> usize {
    let dim = energy.dim;
    let n = x.len();
    let project = |v: &mut [[f64; 3]]| {
        for (g, c) in v.iter_mut().zip(constraints) {
            if let Some(c) = c {
                *g = c.project(*g);
            }
        }
    };
    let work: usize = energy
        .cells
        .iter()
        .map(|cell| free_pairs(cell) * cell.ideal_inverse.len())
        .sum();
    if work > MAX_HESSIAN_WORK {
        return 0;
    }
    let Some(mut hessian) = BlockHessian::pattern(energy, n) else {
        return 0;
    };
    let mut grad = vec![[0.0; 3]; n];
    let mut trial = vec![[0.0; 3]; n];
    let mut first_norm = None;
    let mut previous: Option<(Vec<[f64; 3]>, f64)> = None;
    let mut iterations = 0;
    while iterations < MAX_NEWTON {
        let (current, _) = hessian.assemble(energy, x, 0.0, &mut grad);
        project(&mut grad);
        let g_norm = dot(&grad, &grad, dim).sqrt();
        if let Some((before, before_norm)) = previous.take() {
            // A small full step taken on round-off's word: kept only if it helped.
            if g_norm.is_nan() || g_norm >= before_norm {
                x.copy_from_slice(&before);
                break;
            }
        }
        if !current.is_finite() || g_norm == 0.0 {
            break;
        }
        let first = *first_norm.get_or_insert(g_norm);
        let eta = (g_norm / first).min(0.1);
        let mut step = newton_step(&hessian, &grad, eta, dim, &project);
        let mut slope = dot(&grad, &step, dim);
        if slope.is_nan() || slope >= 0.0 {
            step = grad.iter().map(neg).collect();
            slope = -g_norm * g_norm;
        }
        let longest = step.iter().map(|s| norm(s, dim)).fold(0.0f64, f64::max);
        if longest == 0.0 {
            break;
        }
        iterations += 1;
        // A full step, but never a move of more than half an edge at once.
        let mut alpha = (0.5 * length / longest).min(1.0);
        let small = alpha == 1.0 && longest <= SMALL_STEP * length;
        let mut accepted = false;
        for _ in 0..40 {
            moved(&mut trial, x, &step, alpha, dim);
            let e = energy.evaluate(&trial, 0.0, None).energy;
            let armijo = e <= current + 1e-4 * alpha * slope;
            let round_off = small && alpha == 1.0 && e <= current + 1e-13 * current.abs();
            if e.is_finite() && (armijo || round_off) {
                if !armijo {
                    previous = Some((x.to_vec(), g_norm));
                }
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            break;
        }
        x.copy_from_slice(&trial);
        if alpha * longest <= CONVERGED_STEP * length {
            break;
        }
    }
    iterations
}

/// An approximate solution p of H p = −g by preconditioned conjugate gradients (block
/// Jacobi), to a residual of `eta` |g|, within the constraints' directions; at a direction
/// of negative curvature, the solution so far (or the preconditioned steepest descent).
fn newton_step(
    hessian: &BlockHessian,
    grad: &[[f64; 3]],
    eta: f64,
    dim: usize,
    project: &dyn Fn(&mut [[f64; 3]]),
) -> Vec<[f64; 3]> {
    let n = grad.len();
    let inverses = hessian.diagonal_inverses(dim);
    let precondition = |r: &[[f64; 3]], z: &mut [[f64; 3]]| {
        for ((z, r), m) in z.iter_mut().zip(r).zip(&inverses) {
            for d in 0..3 {
                z[d] = m[d][0] * r[0] + m[d][1] * r[1] + m[d][2] * r[2];
            }
        }
        project(z);
    };
    let mut x = vec![[0.0; 3]; n];
    let mut r: Vec<[f64; 3]> = grad.iter().map(neg).collect();
    let mut z = vec![[0.0; 3]; n];
    precondition(&r, &mut z);
    let mut p = z.clone();
    let mut q = vec![[0.0; 3]; n];
    let mut rz = dot(&r, &z, dim);
    let target = eta * dot(grad, grad, dim).sqrt();
    for k in 0..MAX_LINEAR {
        hessian.multiply(&p, &mut q);
        project(&mut q);
        let pq = dot(&p, &q, dim);
        if pq.is_nan() || pq <= 0.0 {
            return if k == 0 { z } else { x };
        }
        let alpha = rz / pq;
        for i in 0..n {
            for d in 0..dim {
                x[i][d] += alpha * p[i][d];
                r[i][d] -= alpha * q[i][d];
            }
        }
        if dot(&r, &r, dim).sqrt() <= target {
            break;
        }
        precondition(&r, &mut z);
        let rz_next = dot(&r, &z, dim);
        let beta = rz_next / rz;
        rz = rz_next;
        for i in 0..n {
            for d in 0..dim {
                p[i][d] = z[i][d] + beta * p[i][d];
            }
        }
    }
    x
}
