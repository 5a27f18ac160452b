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
    // h^{2/d}: a cube root squared in 3D (powf was a sixth of untangling's time).
    let h_pow = match dim {
        3 => {
            let c = h.cbrt();
            c * c
        }
        2 => h,
        _ => h.powf(2.0 / n),
    };
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
        // Every cell's node gradients in one buffer (none without `grad`), each cell's
        // slice filled in parallel; cells summed in cell order afterwards: the same bits
        // for any thread count, and no allocation per cell (a seventh of the time).
        let slots = if grad.is_some() {
            self.cells.iter().map(|c| c.nodes.len()).sum()
        } else {
            0
        };
        let mut node_gradients = vec![[0.0; 3]; slots];
        let mut slices: Vec<&mut [[f64; 3]]> = Vec::with_capacity(self.cells.len());
        let mut rest = &mut node_gradients[..];
        for cell in &self.cells {
            let len = if slots > 0 { cell.nodes.len() } else { 0 };
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
            slices.push(head);
            rest = tail;
        }
        let terms: Vec<(f64, f64)> = self
            .cells
            .par_iter()
            .zip(slices.into_par_iter())
            .map_init(Vec::new, |coords, (cell, gradient)| match self.dim {
                2 => self.cell::<2>(cell, x, delta, coords, gradient),
                _ => self.cell::<3>(cell, x, delta, coords, gradient),
            })
            .collect();
        let mut energy = 0.0;
        let mut min_ratio = f64::INFINITY;
        for &(e, m) in &terms {
            energy += e;
            min_ratio = min_ratio.min(m);
        }
        if let Some(g_out) = grad {
            g_out.fill([0.0; 3]);
            let slots = self.cells.iter().flat_map(|cell| &cell.nodes);
            for (slot, g) in slots.zip(&node_gradients) {
                if let Slot::Free(v) = *slot {
                    for d in 0..3 {
                        g_out[v as usize][d] += g[d];
                    }
                }
            }
        }
        Evaluation { energy, min_ratio }
    }

    /// One cell's energy and smallest det T; its gradient with respect to its nodes is
    /// added into `gradient` (empty: not asked for). `coords` is scratch space. The
    /// dimension `D` is a constant: the 3 × 3 loops unrolled (the same sums in the same
    /// order, so the same bits), where untangling spends its time.
    fn cell<const D: usize>(
        &self,
        cell: &CellTerm,
        x: &[[f64; 3]],
        delta: f64,
        coords: &mut Vec<[f64; 3]>,
        gradient: &mut [[f64; 3]],
    ) -> (f64, f64) {
        let dim = D;
        let with_gradient = !gradient.is_empty();
        let sampler = &self.samplers[cell.sampler];
        coords.clear();
        coords.extend(cell.nodes.iter().map(|s| match *s {
            Slot::Free(v) => x[v as usize],
            Slot::Fixed(p) => p,
        }));
        let mut energy = 0.0;
        let mut min_ratio = f64::INFINITY;
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
            min_ratio = min_ratio.min(det(&t, dim));
            let Some((f, df_dt)) = inverse_mean_ratio(&t, dim, delta) else {
                energy = f64::INFINITY;
                continue;
            };
            energy += f;
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
            for (gi, g) in gradient.iter_mut().zip(gradients) {
                for d in 0..dim {
                    gi[d] += (0..dim).map(|k| df_dj[d][k] * g[k]).sum::<f64>();
                }
            }
        }
        (energy, min_ratio)
    }
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
