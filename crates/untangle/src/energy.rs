//! The distortion energy of a patch and its gradient with respect to the free nodes.

use hocurve_quality::JacobianSampler;
use rayon::prelude::*;

/// A 3×3 matrix (rows); in 2D only the leading 2×2 block is used.
pub(crate) type Mat = [[f64; 3]; 3];

/// The inverse mean ratio f(T) = |T|²_F / (d · h(det T)^{2/d}) with the regularised
/// determinant h(τ) = (τ + √(τ² + 4δ²)) / 2, and its derivative ∂f/∂T:
///
/// ∂f/∂T = 2T / (d h^{2/d}) − 2|T|² / (d² h^{2/d} √(τ² + 4δ²)) · cof T,
///
/// (using dh/dτ = h / √(τ² + 4δ²) and ∂ det T/∂T = cof T). f = 1 for a similarity
/// (T = sR), f > 1 otherwise. None when h ≤ 0, i.e. δ = 0 and det T ≤ 0: the barrier.
pub fn inverse_mean_ratio(t: &Mat, dim: usize, delta: f64) -> Option<(f64, Mat)> {
    let tau = det(t, dim);
    let s = (tau * tau + 4.0 * delta * delta).sqrt();
    // For τ < 0 the sum τ + s cancels; h = 2δ² / (s − τ) is the same number, exactly formed.
    let h = if tau >= 0.0 {
        0.5 * (tau + s)
    } else {
        2.0 * delta * delta / (s - tau)
    };
    if !(h > 0.0 && h.is_finite()) {
        return None;
    }
    let n = dim as f64;
    let mut fro = 0.0;
    for r in 0..dim {
        for c in 0..dim {
            fro += t[r][c] * t[r][c];
        }
    }
    let h_pow = h.powf(2.0 / n);
    let value = fro / (n * h_pow);
    let cof = cofactor(t, dim);
    let a = 2.0 / (n * h_pow);
    let b = 2.0 * fro / (n * n * h_pow * s);
    let mut grad = [[0.0; 3]; 3];
    for r in 0..dim {
        for c in 0..dim {
            grad[r][c] = a * t[r][c] - b * cof[r][c];
        }
    }
    Some((value, grad))
}

/// det of the leading dim×dim block.
pub(crate) fn det(m: &Mat, dim: usize) -> f64 {
    if dim == 2 {
        m[0][0] * m[1][1] - m[0][1] * m[1][0]
    } else {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    }
}

/// The cofactor matrix ∂ det M / ∂M of the leading dim×dim block.
fn cofactor(m: &Mat, dim: usize) -> Mat {
    let mut c = [[0.0; 3]; 3];
    if dim == 2 {
        c[0][0] = m[1][1];
        c[0][1] = -m[1][0];
        c[1][0] = -m[0][1];
        c[1][1] = m[0][0];
    } else {
        for r in 0..3 {
            for k in 0..3 {
                let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
                let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
                c[r][k] = m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1];
            }
        }
    }
    c
}

/// The inverse of the leading dim×dim block, None when singular or not finite.
pub(crate) fn inverse(m: &Mat, dim: usize) -> Option<Mat> {
    let d = det(m, dim);
    if !(d.is_finite() && d != 0.0) {
        return None;
    }
    let c = cofactor(m, dim);
    let mut inv = [[0.0; 3]; 3];
    for r in 0..dim {
        for k in 0..dim {
            inv[r][k] = c[k][r] / d; // adjugate = cofactorᵀ
        }
    }
    Some(inv)
}

/// Where a local node of a cell of the patch is: a free variable, or fixed at a position.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Slot {
    Free(u32),
    Fixed([f64; 3]),
}

/// One cell's share of the energy.
#[derive(Debug, Clone)]
pub(crate) struct CellTerm {
    /// Index of the cell's sampler in [`DistortionEnergy::samplers`].
    pub sampler: usize,
    /// Its nodes in canonical local order.
    pub nodes: Vec<Slot>,
    /// W⁻¹ at each sample point (W: the straight-sided element's Jacobian); None where W is
    /// singular (such points are left out).
    pub ideal_inverse: Vec<Option<Mat>>,
}

/// E(x) = Σ_cells Σ_q f(J_q(x) W_q⁻¹) over the cells of one patch, as a function of the
/// positions x of its free nodes.
#[derive(Debug, Clone)]
pub struct DistortionEnergy<'a> {
    pub(crate) dim: usize,
    pub(crate) samplers: &'a [JacobianSampler],
    pub(crate) cells: Vec<CellTerm>,
}

/// The energy at a point, the smallest det T over the sample points, and whether every term
/// was finite.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Evaluation {
    pub energy: f64,
    pub min_ratio: f64,
}

impl DistortionEnergy<'_> {
    /// E(x) with regularisation δ, and ∇E into `grad` (same length as `x`) when given.
    /// The energy is +∞ where the barrier is crossed (δ = 0 and some det T ≤ 0).
    pub(crate) fn evaluate(
        &self,
        x: &[[f64; 3]],
        delta: f64,
        grad: Option<&mut [[f64; 3]]>,
    ) -> Evaluation {
        let with_gradient = grad.is_some();
        // Cells in parallel, summed in cell order: the same bits for any thread count.
        let terms: Vec<CellEvaluation> = self
            .cells
            .par_iter()
            .map(|cell| match self.dim {
                2 => self.cell::<2>(cell, x, delta, with_gradient),
                _ => self.cell::<3>(cell, x, delta, with_gradient),
            })
            .collect();
        let mut energy = 0.0;
        let mut min_ratio = f64::INFINITY;
        for t in &terms {
            energy += t.energy;
            min_ratio = min_ratio.min(t.min_ratio);
        }
        if let Some(g_out) = grad {
            g_out.fill([0.0; 3]);
            for (cell, t) in self.cells.iter().zip(&terms) {
                for (slot, g) in cell.nodes.iter().zip(&t.gradient) {
                    if let Slot::Free(v) = *slot {
                        for d in 0..3 {
                            g_out[v as usize][d] += g[d];
                        }
                    }
                }
            }
        }
        Evaluation { energy, min_ratio }
    }

    /// One cell's energy, smallest det T, and gradient with respect to its nodes (empty
    /// unless asked for). The dimension `D` is a constant: the 3 × 3 loops unrolled (the same sums in the
    /// same order, so the same bits), where untangling spends its time.
    fn cell<const D: usize>(
        &self,
        cell: &CellTerm,
        x: &[[f64; 3]],
        delta: f64,
        with_gradient: bool,
    ) -> CellEvaluation {
        let dim = D;
        let sampler = &self.samplers[cell.sampler];
        let coords: Vec<[f64; 3]> = cell
            .nodes
            .iter()
            .map(|s| match *s {
                Slot::Free(v) => x[v as usize],
                Slot::Fixed(p) => p,
            })
            .collect();
        let mut out = CellEvaluation {
            energy: 0.0,
            min_ratio: f64::INFINITY,
            gradient: if with_gradient {
                vec![[0.0; 3]; coords.len()]
            } else {
                Vec::new()
            },
        };
        for (q, w_inv) in cell.ideal_inverse.iter().enumerate() {
            let Some(w_inv) = w_inv else { continue };
            let mut j = [[0.0; 3]; 3];
            let gradients = sampler.point_gradients(q);
            for (xi, g) in coords.iter().zip(gradients) {
                for d in 0..dim {
                    for k in 0..dim {
                        j[d][k] += xi[d] * g[k];
                    }
                }
            }
            let t = mul(&j, w_inv, dim);
            out.min_ratio = out.min_ratio.min(det(&t, dim));
            let Some((f, df_dt)) = inverse_mean_ratio(&t, dim, delta) else {
                out.energy = f64::INFINITY;
                continue;
            };
            out.energy += f;
            if !with_gradient {
                continue;
            }
            // ∂f/∂J = ∂f/∂T · W⁻ᵀ; ∂f/∂x_i[d] = Σ_k (∂f/∂J)[d][k] ∇Φ_i[k].
            let mut df_dj = [[0.0; 3]; 3];
            for d in 0..dim {
                for k in 0..dim {
                    df_dj[d][k] = (0..dim).map(|m| df_dt[d][m] * w_inv[k][m]).sum();
                }
            }
            for (gi, g) in out.gradient.iter_mut().zip(gradients) {
                for d in 0..dim {
                    gi[d] += (0..dim).map(|k| df_dj[d][k] * g[k]).sum::<f64>();
                }
            }
        }
        out
    }
}

/// One cell's share of an [`Evaluation`].
struct CellEvaluation {
    energy: f64,
    min_ratio: f64,
    gradient: Vec<[f64; 3]>,
}

/// The leading dim×dim block of a·b.
pub(crate) fn mul(a: &Mat, b: &Mat, dim: usize) -> Mat {
    let mut c = [[0.0; 3]; 3];
    for r in 0..dim {
        for k in 0..dim {
            c[r][k] = (0..dim).map(|m| a[r][m] * b[m][k]).sum();
        }
    }
    c
}
