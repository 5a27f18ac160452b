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

/// Second derivatives of f(T) with respect to the entries of T, indexed 3r + c.
pub(crate) type Mat9 = [[f64; 9]; 9];

/// [`inverse_mean_ratio`] with its second derivative (for Newton steps). With F = |T|²,
/// τ = det T, s = √(τ² + 4δ²), φ = h^{−2/d}, C = cof T (so f = F φ / d):
///
/// φ' = −(2/d) φ / s,  φ'' = (2/d)² φ / s² + (2/d) φ τ / s³,
///
/// d · ∂²f/∂T_α∂T_β = 2φ δ_αβ + 2φ' (T_α C_β + C_α T_β) + F φ'' C_α C_β + F φ' ∂C_α/∂T_β.
pub(crate) fn inverse_mean_ratio_second(
    t: &Mat,
    dim: usize,
    delta: f64,
) -> Option<(f64, Mat, Mat9)> {
    let (value, grad) = inverse_mean_ratio(t, dim, delta)?;
    let tau = det(t, dim);
    let s = (tau * tau + 4.0 * delta * delta).sqrt();
    let n = dim as f64;
    let mut fro = 0.0;
    for r in 0..dim {
        for c in 0..dim {
            fro += t[r][c] * t[r][c];
        }
    }
    // φ = f · d / F (F > 0 wherever the barrier is finite and T ≠ 0).
    let phi = value * n / fro;
    let d1 = -(2.0 / n) * phi / s;
    let d2 = (2.0 / n) * (2.0 / n) * phi / (s * s) + (2.0 / n) * phi * tau / (s * s * s);
    let cof = cofactor(t, dim);
    let cof_second = cofactor_derivative(t, dim);
    let mut hess = [[0.0; 9]; 9];
    for a in 0..dim * dim {
        let (ar, ac) = (a / dim, a % dim);
        for b in 0..dim * dim {
            let (br, bc) = (b / dim, b % dim);
            let mut v = 2.0 * d1 * (t[ar][ac] * cof[br][bc] + cof[ar][ac] * t[br][bc])
                + fro * d2 * cof[ar][ac] * cof[br][bc]
                + fro * d1 * cof_second[3 * ar + ac][3 * br + bc];
            if a == b {
                v += 2.0 * phi;
            }
            hess[3 * ar + ac][3 * br + bc] = v / n;
        }
    }
    Some((value, grad, hess))
}

/// ∂(cof T)_α / ∂T_β, indexed 3r + c (the second derivative of det T).
fn cofactor_derivative(t: &Mat, dim: usize) -> Mat9 {
    let mut out = [[0.0; 9]; 9];
    if dim == 2 {
        // cof T = [[T11, −T10], [−T01, T00]].
        out[0][4] = 1.0;
        out[1][3] = -1.0;
        out[3][1] = -1.0;
        out[4][0] = 1.0;
        return out;
    }
    for r in 0..3 {
        for k in 0..3 {
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
            // C[r][k] = T[r1][k1] T[r2][k2] − T[r1][k2] T[r2][k1].
            let row = &mut out[3 * r + k];
            row[3 * r1 + k1] += t[r2][k2];
            row[3 * r2 + k2] += t[r1][k1];
            row[3 * r1 + k2] -= t[r2][k1];
            row[3 * r2 + k1] -= t[r1][k2];
        }
    }
    out
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

/// One cell's share of the energy's second derivative, for its free nodes only.
#[derive(Debug, Clone, Default)]
pub(crate) struct CellHessian {
    /// The free variables of the cell's nodes, in local order (a node listed once).
    pub variables: Vec<u32>,
    /// Its local node index for each of them.
    local: Vec<usize>,
    /// ∂E_cell/∂x of each variable.
    pub gradient: Vec<[f64; 3]>,
    /// ∂²E_cell/∂x_k∂x_l as blocks[k · n + l] (n = variables.len()), each [d][e].
    pub blocks: Vec<Mat>,
    /// The cell's energy and smallest det T.
    pub energy: f64,
    pub min_ratio: f64,
}

impl DistortionEnergy<'_> {
    /// The energy's gradient and Hessian of the cells in `range`, in their order (`delta`
    /// as in [`DistortionEnergy::evaluate`]). A cell whose energy is not finite has energy
    /// +∞.
    pub(crate) fn cell_hessians(
        &self,
        range: std::ops::Range<usize>,
        x: &[[f64; 3]],
        delta: f64,
    ) -> Vec<CellHessian> {
        self.cells[range]
            .par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(coords, a), cell| match self.dim {
                    2 => self.cell_hessian::<2>(cell, x, delta, coords, a),
                    _ => self.cell_hessian::<3>(cell, x, delta, coords, a),
                },
            )
            .collect()
    }

    /// With T = J W⁻¹ and J = Σ_i x_i ⊗ ∇Φ_i: ∂T[d][m]/∂x_i[d] = a_i[m], a_i = W⁻ᵀ ∇Φ_i, so
    /// ∂²f/∂x_k[d]∂x_l[e] = Σ_{m,n} ∂²f/∂T[d][m]∂T[e][n] a_k[m] a_l[n].
    fn cell_hessian<const D: usize>(
        &self,
        cell: &CellTerm,
        x: &[[f64; 3]],
        delta: f64,
        coords: &mut Vec<[f64; 3]>,
        a: &mut Vec<[f64; 3]>,
    ) -> CellHessian {
        let sampler = &self.samplers[cell.sampler];
        let mut out = CellHessian::default();
        coords.clear();
        for (i, s) in cell.nodes.iter().enumerate() {
            match *s {
                Slot::Free(v) => {
                    coords.push(x[v as usize]);
                    if !out.variables.contains(&v) {
                        out.variables.push(v);
                        out.local.push(i);
                    }
                }
                Slot::Fixed(p) => coords.push(p),
            }
        }
        let n = out.variables.len();
        out.gradient = vec![[0.0; 3]; n];
        out.blocks = vec![[[0.0; 3]; 3]; n * n];
        out.min_ratio = f64::INFINITY;
        for (q, w_inv) in cell.ideal_inverse.iter().enumerate() {
            let Some(w_inv) = w_inv else { continue };
            let gradients = sampler.point_gradients(q);
            let mut j = [[0.0; 3]; 3];
            for (xi, g) in coords.iter().zip(gradients) {
                for d in 0..D {
                    for k in 0..D {
                        j[d][k] += xi[d] * g[k];
                    }
                }
            }
            let t = mul(&j, w_inv, D);
            out.min_ratio = out.min_ratio.min(det(&t, D));
            let Some((f, df_dt, h)) = inverse_mean_ratio_second(&t, D, delta) else {
                out.energy = f64::INFINITY;
                continue;
            };
            out.energy += f;
            a.clear();
            for &i in &out.local {
                let g = gradients[i];
                let mut ai = [0.0; 3];
                for (m, am) in ai.iter_mut().enumerate().take(D) {
                    *am = (0..D).map(|k| w_inv[k][m] * g[k]).sum();
                }
                a.push(ai);
            }
            for k in 0..n {
                let ak = a[k];
                for d in 0..D {
                    out.gradient[k][d] += (0..D).map(|m| df_dt[d][m] * ak[m]).sum::<f64>();
                }
                // y[3e + m'][d] = Σ_m H[(d, m)][(e, m')] a_k[m].
                let mut y = [[0.0; 3]; 9];
                for e in 0..D {
                    for mp in 0..D {
                        for d in 0..D {
                            y[3 * e + mp][d] =
                                (0..D).map(|m| h[3 * d + m][3 * e + mp] * ak[m]).sum();
                        }
                    }
                }
                for l in k..n {
                    let al = a[l];
                    let block = &mut out.blocks[k * n + l];
                    for d in 0..D {
                        for e in 0..D {
                            block[d][e] += (0..D).map(|mp| y[3 * e + mp][d] * al[mp]).sum::<f64>();
                        }
                    }
                }
            }
        }
        // The lower blocks mirror the upper ones: H_lk = H_klᵀ.
        for k in 0..n {
            for l in 0..k {
                let upper = out.blocks[l * n + k];
                let block = &mut out.blocks[k * n + l];
                for d in 0..3 {
                    for e in 0..3 {
                        block[d][e] = upper[e][d];
                    }
                }
            }
        }
        out
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
