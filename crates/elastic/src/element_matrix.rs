//! Element stiffness matrices of isoparametric vector Lagrange elements.
//!
//! With physical basis gradients ∂_c Φ_a and G_cd[a][b] = ∫_e ∂_c Φ_a ∂_d Φ_b dx, the
//! bilinear form a(u, v) = ∫ λ div u div v + 2μ ε(u) : ε(v) gives, for the dof pair
//! (node a, component c), (node b, component d),
//!
//! K[(a,c),(b,d)] = λ G_cd[a][b] + μ G_dc[a][b] + μ δ_cd Σ_k G_kk[a][b].
//!
//! On a straight simplex the Jacobian J = ∂x/∂ξ is constant, ∂_c Φ = Σ_α J⁻¹_αc ∂Φ/∂ξ_α and
//! G_cd = |det J| Σ_αβ J⁻¹_αc J⁻¹_βd S_αβ with the precomputed reference matrices S_αβ:
//! no quadrature per element. Other cells integrate G_cd with the degree-2p rule.

use crate::reference_element::ReferenceStiffness;
use crate::ElasticError;

/// Reusable buffers for one thread.
#[derive(Debug, Default)]
pub(crate) struct ElementScratch {
    /// Node coordinates of the cell.
    pub coords: Vec<[f64; 3]>,
    /// G_cd for c ≤ d at index c·dim + d, each n × n.
    g: Vec<f64>,
    /// Physical gradients at one quadrature point.
    grads: Vec<[f64; 3]>,
    /// The element matrix, (n·dim)² row-major, dof (a, c) at a·dim + c.
    pub matrix: Vec<f64>,
    /// The cell's local node indices in increasing global node order (for assembly).
    pub order: Vec<usize>,
}

/// J⁻¹ (`inv[α][c]` = ∂ξ_α/∂x_c) and det J of `jac[c][α]` = ∂x_c/∂ξ_α, for dim 2 or 3.
pub(crate) fn invert_jacobian(jac: &[[f64; 3]; 3], dim: usize) -> ([[f64; 3]; 3], f64) {
    let mut inv = [[0.0; 3]; 3];
    if dim == 2 {
        let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
        inv[0][0] = jac[1][1] / det;
        inv[0][1] = -jac[0][1] / det;
        inv[1][0] = -jac[1][0] / det;
        inv[1][1] = jac[0][0] / det;
        return (inv, det);
    }
    let j = jac;
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        j[r1][c1] * j[r2][c2] - j[r1][c2] * j[r2][c1]
    };
    let det = j[0][0] * cof(0, 0) + j[0][1] * cof(0, 1) + j[0][2] * cof(0, 2);
    for r in 0..3 {
        for c in 0..3 {
            // (J⁻¹)[c][r] = cofactor(r, c) / det.
            inv[c][r] = cof(r, c) / det;
        }
    }
    (inv, det)
}

fn checked_det(det: f64, cell: usize) -> Result<f64, ElasticError> {
    // Relative to nothing: a determinant that is exactly 0 or not finite cannot be used;
    // tiny but non-zero ones are the caller's geometry and are kept.
    if det.is_finite() && det != 0.0 {
        Ok(det.abs())
    } else {
        Err(ElasticError::DegenerateCell {
            cell,
            jacobian: det,
        })
    }
}

/// Computes the stiffness matrix of `cell` (coordinates in `scratch.coords`) into
/// `scratch.matrix`.
pub(crate) fn element_stiffness(
    reference: &ReferenceStiffness,
    lambda: f64,
    mu: f64,
    cell: usize,
    scratch: &mut ElementScratch,
) -> Result<(), ElasticError> {
    let n = reference.len;
    let dim = reference.dim;
    let nn = n * n;
    scratch.g.clear();
    scratch.g.resize(dim * dim * nn, 0.0);
    scratch.grads.resize(n, [0.0; 3]);
    let coords = &scratch.coords;

    match &reference.simplex_stiffness {
        Some(s) if reference.is_affine_simplex(coords) => {
            let mut jac = [[0.0; 3]; 3];
            for alpha in 0..dim {
                for c in 0..dim {
                    jac[c][alpha] = coords[alpha + 1][c] - coords[0][c];
                }
            }
            let (inv, det) = invert_jacobian(&jac, dim);
            let det = checked_det(det, cell)?;
            for c in 0..dim {
                for d in c..dim {
                    let g = &mut scratch.g[(c * dim + d) * nn..(c * dim + d + 1) * nn];
                    for alpha in 0..dim {
                        for beta in 0..dim {
                            let coefficient = det * inv[alpha][c] * inv[beta][d];
                            for (gk, sk) in g.iter_mut().zip(&s[alpha * dim + beta]) {
                                *gk += coefficient * sk;
                            }
                        }
                    }
                }
            }
        }
        _ => {
            let rule = &reference.stiffness_rule;
            for q in 0..rule.len() {
                let ref_grads = rule.gradients(q);
                let jac = rule.jacobian(coords, q);
                let (inv, det) = invert_jacobian(&jac, dim);
                let weight = rule.weights()[q] * checked_det(det, cell)?;
                for (phys, g) in scratch.grads.iter_mut().zip(ref_grads) {
                    for c in 0..dim {
                        phys[c] = (0..dim).map(|alpha| g[alpha] * inv[alpha][c]).sum();
                    }
                }
                let grads = &scratch.grads;
                for c in 0..dim {
                    for d in c..dim {
                        let g = &mut scratch.g[(c * dim + d) * nn..(c * dim + d + 1) * nn];
                        for a in 0..n {
                            let wa = weight * grads[a][c];
                            for (gk, gb) in g[a * n..(a + 1) * n].iter_mut().zip(grads) {
                                *gk += wa * gb[d];
                            }
                        }
                    }
                }
            }
        }
    }

    // K[(a,c),(b,d)] = λ G_cd[a][b] + μ G_dc[a][b] + μ δ_cd tr G[a][b], G_dc = G_cdᵀ.
    let size = n * dim;
    scratch.matrix.clear();
    scratch.matrix.resize(size * size, 0.0);
    let g = &scratch.g;
    let at = |c: usize, d: usize, a: usize, b: usize| {
        if c <= d {
            g[(c * dim + d) * nn + a * n + b]
        } else {
            g[(d * dim + c) * nn + b * n + a]
        }
    };
    for a in 0..n {
        for b in 0..n {
            let trace: f64 = (0..dim).map(|k| at(k, k, a, b)).sum();
            for c in 0..dim {
                let row = (a * dim + c) * size + b * dim;
                for d in 0..dim {
                    let mut value = lambda * at(c, d, a, b) + mu * at(d, c, a, b);
                    if c == d {
                        value += mu * trace;
                    }
                    scratch.matrix[row + d] = value;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
#[path = "tests/element_matrix.rs"]
mod tests;
