//! Orthonormal polynomial bases on the reference elements (modal bases): the building block
//! of Vandermonde matrices, Lagrange bases on any nodal set and Fekete-point searches.
//!
//! Functions are orthonormal for ∫ over *hocurve's* reference element (unit box / unit
//! simplex), so the constant function is 1/√volume.
//!
//! * Line: √2 p̃ᵢ(2x − 1), p̃ the orthonormal Legendre polynomials on [-1, 1]; space Pₚ.
//! * Quad, Hex: tensor products of the line functions; space Qₚ.
//! * Tri (Dubiner): ψᵢⱼ = 2^(i+3/2) p̃ᵢ(2u − 1) (1 − y)ⁱ p̃ⱼ⁽²ⁱ⁺¹·⁰⁾(2y − 1), u = x/(1 − y).
//! * Tet (Koornwinder): ψᵢⱼₖ = 2^(2i+j+3) p̃ᵢ(2u − 1) (1 − y − z)ⁱ p̃ⱼ⁽²ⁱ⁺¹·⁰⁾(2v − 1) (1 − z)ʲ
//!   p̃ₖ⁽²ⁱ⁺²ʲ⁺²·⁰⁾(2z − 1), u = x/(1 − y − z), v = y/(1 − z);
//! * Prism: Tri functions × line functions in z; space Pₚ(x, y) ⊗ Pₚ(z).
//!
//! These are Hesthaven & Warburton's (Nodal DG, §6.1 and §10.1) bases moved to the unit
//! simplex. The collapsed factors p̃ᵢ(2u − 1) wⁱ are evaluated as polynomials in (x, w) by a
//! homogenised recurrence, so values and gradients are exact everywhere, including at the
//! collapsed vertices ((0, 1) of the triangle, (0, 1, 0) and (0, 0, 1) of the tetrahedron)
//! and outside the element.

use nalgebra::DMatrix;

use crate::gauss::JacobiRecurrence;
use crate::Shape;

/// Largest order an [`OrthonormalBasis`] supports (evaluation works in stack buffers).
pub const MAX_BASIS_ORDER: usize = 40;

const N: usize = MAX_BASIS_ORDER + 1;

/// Values, s-derivatives and w-derivatives of one family of homogenised polynomials.
struct Family1D {
    value: [f64; N],
    d_s: [f64; N],
    d_w: [f64; N],
}

impl Family1D {
    fn eval(rec: &JacobiRecurrence, count: usize, s: f64, w: f64) -> Self {
        let mut f = Family1D {
            value: [0.0; N],
            d_s: [0.0; N],
            d_w: [0.0; N],
        };
        rec.eval_homogeneous(
            s,
            w,
            &mut f.value[..count],
            &mut f.d_s[..count],
            &mut f.d_w[..count],
        );
        f
    }
}

/// An orthonormal basis of the complete polynomial space of order p on a reference shape
/// (Pₚ on simplices and lines, Qₚ on boxes, Pₚ ⊗ Pₚ on prisms).
///
/// Ordering of the functions: Line by degree i; Quad/Hex by (i, j, k) with i fastest;
/// Tri by i (outer) then j; Tet by i, j, k; Prism by k (z-degree, outer) then the Tri order.
#[derive(Debug, Clone, PartialEq)]
pub struct OrthonormalBasis {
    shape: Shape,
    order: usize,
    len: usize,
    /// Orthonormal Legendre (α = β = 0).
    legendre: JacobiRecurrence,
    /// Jacobi α = 2i + 1, β = 0 for i = 0..=p (triangle and tetrahedron second direction).
    odd: Vec<JacobiRecurrence>,
    /// Jacobi α = 2m + 2, β = 0 for m = i + j = 0..=p (tetrahedron third direction).
    even: Vec<JacobiRecurrence>,
}

impl OrthonormalBasis {
    /// The basis of order `order` on `shape`.
    ///
    /// # Panics
    /// If `order > MAX_BASIS_ORDER`.
    pub fn new(shape: Shape, order: usize) -> Self {
        assert!(
            order <= MAX_BASIS_ORDER,
            "orthonormal basis order {order} exceeds the maximum {MAX_BASIS_ORDER}"
        );
        let p = order;
        let legendre = JacobiRecurrence::new(p, 0.0, 0.0);
        let simplex = matches!(shape, Shape::Tri | Shape::Tet | Shape::Prism);
        let odd = if simplex {
            (0..=p)
                .map(|i| JacobiRecurrence::new(p - i, (2 * i + 1) as f64, 0.0))
                .collect()
        } else {
            Vec::new()
        };
        let even = if shape == Shape::Tet {
            (0..=p)
                .map(|m| JacobiRecurrence::new(p - m, (2 * m + 2) as f64, 0.0))
                .collect()
        } else {
            Vec::new()
        };
        OrthonormalBasis {
            shape,
            order,
            len: shape.num_nodes(order),
            legendre,
            odd,
            even,
        }
    }

    /// The shape.
    pub fn shape(&self) -> Shape {
        self.shape
    }

    /// The polynomial order p.
    pub fn order(&self) -> usize {
        self.order
    }

    /// Number of basis functions (= dimension of the space = nodes of an order-p element).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always false (the constant function is in every space).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Values ψⱼ(ξ) into `out[..len()]`.
    pub fn eval(&self, xi: [f64; 3], out: &mut [f64]) {
        self.evaluate(xi, out, None);
    }

    /// Gradients ∇ψⱼ(ξ) with respect to the reference coordinates into `out[..len()]`
    /// (unused components are 0).
    pub fn eval_grad(&self, xi: [f64; 3], out: &mut [[f64; 3]]) {
        let mut values = [0.0; 0];
        self.evaluate_into(xi, &mut values, Some(out), false);
    }

    /// Values and gradients at once.
    pub fn eval_with_grad(&self, xi: [f64; 3], values: &mut [f64], grads: &mut [[f64; 3]]) {
        self.evaluate(xi, values, Some(grads));
    }

    /// The generalised Vandermonde matrix: `V[(i, j)] = ψⱼ(points[i])`.
    pub fn vandermonde(&self, points: &[[f64; 3]]) -> DMatrix<f64> {
        let mut v = DMatrix::zeros(points.len(), self.len);
        let mut row = vec![0.0; self.len];
        for (i, &x) in points.iter().enumerate() {
            self.eval(x, &mut row);
            for (j, &r) in row.iter().enumerate() {
                v[(i, j)] = r;
            }
        }
        v
    }

    /// The derivative Vandermonde matrices: `D[d][(i, j)] = ∂ψⱼ/∂ξ_d (points[i])`.
    pub fn gradient_vandermonde(&self, points: &[[f64; 3]]) -> [DMatrix<f64>; 3] {
        let mut d = [0, 1, 2].map(|_| DMatrix::zeros(points.len(), self.len));
        let mut row = vec![[0.0; 3]; self.len];
        for (i, &x) in points.iter().enumerate() {
            self.eval_grad(x, &mut row);
            for (j, g) in row.iter().enumerate() {
                for (dim, matrix) in d.iter_mut().enumerate() {
                    matrix[(i, j)] = g[dim];
                }
            }
        }
        d
    }

    fn evaluate(&self, xi: [f64; 3], values: &mut [f64], grads: Option<&mut [[f64; 3]]>) {
        self.evaluate_into(xi, values, grads, true);
    }

    /// Core evaluation; writes values if `want_values` and gradients if `grads` is given.
    fn evaluate_into(
        &self,
        xi: [f64; 3],
        values: &mut [f64],
        mut grads: Option<&mut [[f64; 3]]>,
        want_values: bool,
    ) {
        let p = self.order;
        let [x, y, z] = xi;
        if want_values {
            assert!(values.len() >= self.len, "value buffer too short");
        }
        if let Some(g) = grads.as_deref() {
            assert!(g.len() >= self.len, "gradient buffer too short");
        }
        let mut index = 0;
        let mut emit = |value: f64, grad: [f64; 3]| {
            if want_values {
                values[index] = value;
            }
            if let Some(g) = grads.as_deref_mut() {
                g[index] = grad;
            }
            index += 1;
        };
        // Orthonormal on [0, 1]: √2 Qᵢ(s, 1), derivative √2 ∂Qᵢ/∂s.
        let line = |s: f64| Family1D::eval(&self.legendre, p + 1, s, 1.0);
        let r2 = std::f64::consts::SQRT_2;
        match self.shape {
            Shape::Line => {
                let fx = line(x);
                for i in 0..=p {
                    emit(r2 * fx.value[i], [r2 * fx.d_s[i], 0.0, 0.0]);
                }
            }
            Shape::Quad => {
                let (fx, fy) = (line(x), line(y));
                for j in 0..=p {
                    for i in 0..=p {
                        let (a, b) = (fx.value[i], fy.value[j]);
                        emit(2.0 * a * b, [2.0 * fx.d_s[i] * b, 2.0 * a * fy.d_s[j], 0.0]);
                    }
                }
            }
            Shape::Hex => {
                let (fx, fy, fz) = (line(x), line(y), line(z));
                let c = 2.0 * r2;
                for k in 0..=p {
                    for j in 0..=p {
                        for i in 0..=p {
                            let (a, b, d) = (fx.value[i], fy.value[j], fz.value[k]);
                            emit(
                                c * a * b * d,
                                [
                                    c * fx.d_s[i] * b * d,
                                    c * a * fy.d_s[j] * d,
                                    c * a * b * fz.d_s[k],
                                ],
                            );
                        }
                    }
                }
            }
            Shape::Tri => self.triangle(x, y, 1.0, [0.0; 3], &mut emit),
            Shape::Prism => {
                let fz = line(z);
                for k in 0..=p {
                    let (c, dc) = (r2 * fz.value[k], r2 * fz.d_s[k]);
                    self.triangle(x, y, c, [0.0, 0.0, dc], &mut emit);
                }
            }
            Shape::Tet => {
                // ψ = C H(x, w1) K(y, w2) L(z), w1 = 1 − y − z, w2 = 1 − z.
                let (w1, w2) = (1.0 - y - z, 1.0 - z);
                let h = Family1D::eval(&self.legendre, p + 1, x, w1);
                for i in 0..=p {
                    let k_fam = Family1D::eval(&self.odd[i], p - i + 1, y, w2);
                    for j in 0..=p - i {
                        let l_fam = Family1D::eval(&self.even[i + j], p - i - j + 1, z, 1.0);
                        let c = 2f64.powi((2 * i + j + 3) as i32);
                        let (hv, hs, hw) = (h.value[i], h.d_s[i], h.d_w[i]);
                        let (kv, ks, kw) = (k_fam.value[j], k_fam.d_s[j], k_fam.d_w[j]);
                        for k in 0..=p - i - j {
                            let (lv, ls) = (c * l_fam.value[k], c * l_fam.d_s[k]);
                            emit(
                                hv * kv * lv,
                                [
                                    hs * kv * lv,
                                    (-hw * kv + hv * ks) * lv,
                                    -hw * kv * lv - hv * kw * lv + hv * kv * ls,
                                ],
                            );
                        }
                    }
                }
            }
        }
        debug_assert_eq!(index, self.len);
    }

    /// Emits the triangle functions times a factor `c(z)` with gradient `dc`:
    /// ψᵢⱼ = 2^(i+3/2) H(x, 1 − y) J(y) · c.
    fn triangle(&self, x: f64, y: f64, c: f64, dc: [f64; 3], emit: &mut impl FnMut(f64, [f64; 3])) {
        let p = self.order;
        let h = Family1D::eval(&self.legendre, p + 1, x, 1.0 - y);
        for i in 0..=p {
            let j_fam = Family1D::eval(&self.odd[i], p - i + 1, y, 1.0);
            let scale = 2f64.powi(2 * i as i32 + 3).sqrt();
            let (hv, hs, hw) = (scale * h.value[i], scale * h.d_s[i], scale * h.d_w[i]);
            for j in 0..=p - i {
                let (jv, js) = (j_fam.value[j], j_fam.d_s[j]);
                let value = hv * jv;
                emit(
                    value * c,
                    [hs * jv * c, (-hw * jv + hv * js) * c, value * dc[2]],
                );
            }
        }
    }
}

#[cfg(test)]
#[path = "tests/basis.rs"]
mod tests;
