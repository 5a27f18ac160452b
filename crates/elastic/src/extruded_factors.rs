//! Sum factorisation of the gradients of shapes that are a base times a line: the prism
//! (triangle × line), the hexahedron (quadrilateral × line) and the quadrilateral (line ×
//! line), whose nodes and degree-2p quadrature points are tensor products.
//!
//! With nodes (t, l) — base node t, line node l — the basis is Φ_(t,l)(ξ̄, ζ) = φ_t(ξ̄) ψ_l(ζ),
//! so at a point (q, j) of the rule the reference gradient of u = Σ X_(t,l) Φ_(t,l) is
//!
//! ∂u/∂ξ_α = Σ_t ∂_α φ_t(ξ̄_q) A_tj (α in the base),  ∂u/∂ζ = Σ_t φ_t(ξ̄_q) A′_tj,
//! A_tj = Σ_l ψ_l(ζ_j) X_(t,l),  A′_tj = Σ_l ψ′_l(ζ_j) X_(t,l):
//!
//! n_b n_l q_l + n_b q_b q_l multiplications per direction instead of the dense n q = n_b n_l
//! q_b q_l (at p = 3 on the prism 672 against 1 920; the hexahedron 1 280 against 4 096), and
//! the transposed sums in reverse for Rᵀ V. The matrix-free operator uses this for the action
//! of these shapes ([`crate::matrix_free`]); the factors are checked against the tabulated
//! basis when built, and a node set that is not a tensor product keeps the dense path.
//! Each sum runs over B outputs side by side (B dividing [`LANES`]: one AVX2 register) —
//! base nodes t for A and C, base points q for the gradients — for every component at once,
//! so the modes are ordered line point first (j q_b + q).

use hocurve_nodes::{ReferenceElement, Shape};

use crate::matrix_free::CellReal;
use crate::reference_element::ReferenceStiffness;

/// Coordinates closer than this (reference element of size 1) are the same.
const SAME_COORDINATE: f64 = 1e-12;
/// Largest relative difference between a factored gradient and the tabulated one accepted.
const FACTOR_CHECK: f64 = 1e-10;
/// The tables' rows are padded to a multiple of this (one AVX2 register of f32, two of
/// f64).
const LANES: usize = 8;

/// The factors of one shape (see the module documentation).
#[derive(Debug, Clone)]
pub(crate) struct ExtrudedFactors {
    /// Base nodes n_b, line nodes n_l, base points q_b, line points q_l; n_b and q_b
    /// rounded up to whole lanes.
    nb: usize,
    nl: usize,
    qb: usize,
    ql: usize,
    nb_padded: usize,
    qb_padded: usize,
    /// Local node of (t, l) at `t n_l + l`.
    node: Vec<u32>,
    /// Rule point of (q, j) at `j q_b + q`: the order of the modes.
    point: Vec<u32>,
    /// The tables in f64 (CG's operator) and in f32 (the smoothers').
    double: FactorTables<f64>,
    single: FactorTables<f32>,
}

/// The factors' numbers in one precision; the padding entries are zero.
#[derive(Debug, Clone)]
pub(crate) struct FactorTables<T> {
    /// The rule's weight of point (q, j) at `j q_b' + q` (q_b' = q_b padded).
    weight: Vec<T>,
    /// ∂_α φ_t(ξ̄_q) for the base directions α, then (α = dim − 1) φ_t(ξ̄_q), at
    /// `(α n_b + t) q_b' + q`: consecutive points side by side.
    by_point: Vec<T>,
    /// The same at `(α q_b + q) n_b' + t`: consecutive nodes side by side.
    by_node: Vec<T>,
    /// ψ_l(ζ_j) and ψ′_l(ζ_j) at `l q_l + j`.
    line_value: Vec<T>,
    line_deriv: Vec<T>,
}

impl FactorTables<f64> {
    fn narrowed<T: CellReal>(&self) -> FactorTables<T> {
        let to = |v: &[f64]| v.iter().map(|&x| T::of(x)).collect();
        FactorTables {
            weight: to(&self.weight),
            by_point: to(&self.by_point),
            by_node: to(&self.by_node),
            line_value: to(&self.line_value),
            line_deriv: to(&self.line_deriv),
        }
    }
}

/// Scratch of one cell action.
#[derive(Debug, Default)]
pub(crate) struct ExtrudedScratch<T> {
    a: Vec<T>,
    a_prime: Vec<T>,
    v: Vec<T>,
}

/// Base points, line values, and the point of each (base, line) pair at `t n_l + l`.
type TensorSplit = (Vec<[f64; 3]>, Vec<f64>, Vec<usize>);

/// Splits `points` into a base part (coordinates before `axis`) and a line part (coordinate
/// `axis`): the distinct base points, the distinct line values (in order of first
/// appearance), and each point's (base, line) index — None unless every pair occurs exactly
/// once.
fn split(points: &[[f64; 3]], axis: usize) -> Option<TensorSplit> {
    let mut bases: Vec<[f64; 3]> = Vec::new();
    let mut lines: Vec<f64> = Vec::new();
    let mut pairs = Vec::with_capacity(points.len());
    for p in points {
        let mut base = [0.0; 3];
        base[..axis].copy_from_slice(&p[..axis]);
        let t = match bases
            .iter()
            .position(|b| (0..axis).all(|k| (b[k] - base[k]).abs() <= SAME_COORDINATE))
        {
            Some(t) => t,
            None => {
                bases.push(base);
                bases.len() - 1
            }
        };
        let l = match lines
            .iter()
            .position(|&z| (z - p[axis]).abs() <= SAME_COORDINATE)
        {
            Some(l) => l,
            None => {
                lines.push(p[axis]);
                lines.len() - 1
            }
        };
        pairs.push((t, l));
    }
    let (nb, nl) = (bases.len(), lines.len());
    if nb * nl != points.len() {
        return None;
    }
    let mut index = vec![usize::MAX; nb * nl];
    for (i, &(t, l)) in pairs.iter().enumerate() {
        if index[t * nl + l] != usize::MAX {
            return None;
        }
        index[t * nl + l] = i;
    }
    Some((bases, lines, index))
}

impl ExtrudedFactors {
    /// The factors of `reference` (a prism, hexahedron or quadrilateral), or None for
    /// simplices and for node sets or rules that are not tensor products.
    pub(crate) fn new(reference: &ReferenceStiffness) -> Option<Self> {
        if !matches!(reference.shape, Shape::Prism | Shape::Hex | Shape::Quad) {
            return None;
        }
        let dim = reference.dim;
        let axis = dim - 1;
        let element =
            ReferenceElement::shared(reference.shape, reference.order, reference.family).ok()?;
        let (base_nodes, line_nodes, node) = split(element.nodes().points(), axis)?;
        let rule = &reference.stiffness_rule;
        let (base_points, line_points, point) = split(rule.points(), axis)?;
        let (nb, nl, qb, ql) = (
            base_nodes.len(),
            line_nodes.len(),
            base_points.len(),
            line_points.len(),
        );
        let n = element.len();
        let (nb_padded, qb_padded) = (nb.div_ceil(LANES) * LANES, qb.div_ceil(LANES) * LANES);
        let (mut values, mut grads) = (vec![0.0; n], vec![[0.0; 3]; n]);
        // φ_t and its gradient: the basis of nodes (t, 0) on the line of node 0, where
        // ψ_0 = 1.
        let mut by_point = vec![0.0; dim * nb * qb_padded];
        let mut by_node = vec![0.0; dim * qb * nb_padded];
        for (q, b) in base_points.iter().enumerate() {
            let mut xi = *b;
            xi[axis] = line_nodes[0];
            element.basis().eval(xi, &mut values);
            element.basis().eval_grad(xi, &mut grads);
            for t in 0..nb {
                let at = node[t * nl];
                for alpha in 0..dim {
                    let v = if alpha < axis {
                        grads[at][alpha]
                    } else {
                        values[at]
                    };
                    by_point[(alpha * nb + t) * qb_padded + q] = v;
                    by_node[(alpha * qb + q) * nb_padded + t] = v;
                }
            }
        }
        // ψ_l and ψ′_l: the basis of nodes (0, l) at base node 0, where φ_0 = 1.
        let mut line_value = vec![0.0; ql * nl];
        let mut line_deriv = vec![0.0; ql * nl];
        for (j, &z) in line_points.iter().enumerate() {
            let mut xi = base_nodes[0];
            xi[axis] = z;
            element.basis().eval(xi, &mut values);
            element.basis().eval_grad(xi, &mut grads);
            for l in 0..nl {
                let at = node[l];
                line_value[l * ql + j] = values[at];
                line_deriv[l * ql + j] = grads[at][axis];
            }
        }
        // `split` numbers the rule's points (q, j) at q q_l + j; the modes go j-major.
        let point = &point;
        let order: Vec<usize> = (0..ql)
            .flat_map(|j| (0..qb).map(move |q| point[q * ql + j]))
            .collect();
        let mut weight = vec![0.0; ql * qb_padded];
        for j in 0..ql {
            for q in 0..qb {
                weight[j * qb_padded + q] = rule.weights()[order[j * qb + q]];
            }
        }
        let double = FactorTables {
            weight,
            by_point,
            by_node,
            line_value,
            line_deriv,
        };
        let factors = ExtrudedFactors {
            nb,
            nl,
            qb,
            ql,
            nb_padded,
            qb_padded,
            node: node.iter().map(|&b| b as u32).collect(),
            point: order.iter().map(|&k| k as u32).collect(),
            single: double.narrowed(),
            double,
        };
        factors.reproduces(reference).then_some(factors)
    }

    /// Whether the factored gradients equal the tabulated ones at every rule point.
    fn reproduces(&self, reference: &ReferenceStiffness) -> bool {
        let rule = &reference.stiffness_rule;
        let dim = reference.dim;
        let axis = dim - 1;
        let largest = (0..rule.len())
            .flat_map(|k| rule.gradients(k).iter())
            .flat_map(|g| g.iter())
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        for q in 0..self.qb {
            for j in 0..self.ql {
                let k = self.point[j * self.qb + q] as usize;
                let g = rule.gradients(k);
                for t in 0..self.nb {
                    for l in 0..self.nl {
                        let b = self.node[t * self.nl + l] as usize;
                        let base = |alpha: usize| {
                            self.double.by_point[(alpha * self.nb + t) * self.qb_padded + q]
                        };
                        let (line, slope) = (
                            self.double.line_value[l * self.ql + j],
                            self.double.line_deriv[l * self.ql + j],
                        );
                        // ∂_α Φ = ∂_α φ ψ in the base, φ ψ′ along the line.
                        let factored = |alpha: usize| {
                            if alpha < axis {
                                base(alpha) * line
                            } else {
                                base(axis) * slope
                            }
                        };
                        if (0..dim).any(|a| (factored(a) - g[b][a]).abs() > FACTOR_CHECK * largest)
                        {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }

    /// The rule's points in the factors' order: entry j q_b + q is the rule index of
    /// point (q, j). The modes of [`Self::gradients`] and [`Self::transpose`] are in this
    /// order.
    pub(crate) fn points(&self) -> &[u32] {
        &self.point
    }

    /// The weighted gradient modes of one cell: `modes[d stride + α m + j q_b + q]` =
    /// w ∂u_d/∂ξ_α at point (q, j), from `x[d n + b]` (m the rule's size, n the nodes).
    #[inline(always)]
    pub(crate) fn gradients<T: CellReal, const D: usize, const B: usize>(
        &self,
        x: &[T],
        n: usize,
        modes: &mut [T],
        stride: usize,
        scratch: &mut ExtrudedScratch<T>,
    ) {
        let (nb, nl, qb, ql) = (self.nb, self.nl, self.qb, self.ql);
        let (nbp, qbp) = (self.nb_padded, self.qb_padded);
        let m = qb * ql;
        let tables = T::extruded_tables(self);
        let ExtrudedScratch { a, a_prime, v: xt } = scratch;
        // Xᵀ[l][d][t] = X_d(t, l), zero beyond n_b (the only entries read but not written).
        zeroed(xt, nl * D * nbp);
        for t in 0..nb {
            for l in 0..nl {
                let b = self.node[t * nl + l] as usize;
                for d in 0..D {
                    xt[(l * D + d) * nbp + t] = x[d * n + b];
                }
            }
        }
        // A[j][d][t] = Σ_l ψ_l(ζ_j) Xᵀ[l][d][t], A′ with ψ′: B nodes t of every
        // component at a time (2 D independent sums).
        resized(a, ql * D * nbp);
        resized(a_prime, ql * D * nbp);
        for j in 0..ql {
            for t0 in (0..nb).step_by(B) {
                let mut s = [[T::default(); B]; D];
                let mut s_prime = [[T::default(); B]; D];
                for l in 0..nl {
                    let (f, g) = (tables.line_value[l * ql + j], tables.line_deriv[l * ql + j]);
                    for d in 0..D {
                        let xs = &xt[(l * D + d) * nbp + t0..][..B];
                        for i in 0..B {
                            s[d][i] += f * xs[i];
                            s_prime[d][i] += g * xs[i];
                        }
                    }
                }
                for d in 0..D {
                    a[(j * D + d) * nbp + t0..][..B].copy_from_slice(&s[d]);
                    a_prime[(j * D + d) * nbp + t0..][..B].copy_from_slice(&s_prime[d]);
                }
            }
        }
        // U_d[α][(q, j)] = w Σ_t ∂_α φ_t(ξ̄_q) A[j][d][t] (α in the base), w Σ_t φ_t(ξ̄_q)
        // A′[j][d][t] along the line: B points q of every component at a time, so that
        // each table row loaded serves D sums and D² sums run independently.
        for j in 0..ql {
            let at = &a[j * D * nbp..][..D * nbp];
            let at_prime = &a_prime[j * D * nbp..][..D * nbp];
            for q0 in (0..qb).step_by(B) {
                let mut acc = [[[T::default(); B]; D]; D];
                for t in 0..nb {
                    let mut f = [[T::default(); B]; D];
                    for (alpha, row) in f.iter_mut().enumerate() {
                        row.copy_from_slice(&tables.by_point[(alpha * nb + t) * qbp + q0..][..B]);
                    }
                    for (d, acc_d) in acc.iter_mut().enumerate() {
                        let (v, v_prime) = (at[d * nbp + t], at_prime[d * nbp + t]);
                        for (alpha, sums) in acc_d.iter_mut().enumerate().take(D - 1) {
                            for i in 0..B {
                                sums[i] += v * f[alpha][i];
                            }
                        }
                        for i in 0..B {
                            acc_d[D - 1][i] += v_prime * f[D - 1][i];
                        }
                    }
                }
                let w = &tables.weight[j * qbp + q0..][..B];
                for (d, acc_d) in acc.iter().enumerate() {
                    for (alpha, sums) in acc_d.iter().enumerate() {
                        let out = &mut modes[d * stride + alpha * m + j * qb + q0..];
                        if q0 + B <= qb {
                            let out = &mut out[..B];
                            for i in 0..B {
                                out[i] = w[i] * sums[i];
                            }
                        } else {
                            for i in 0..qb - q0 {
                                out[i] = w[i] * sums[i];
                            }
                        }
                    }
                }
            }
        }
    }

    /// The transpose: `y[d n_padded + b]` = Σ_(α, k) ∂_α Φ_b(k) `modes[d stride + α m + k]`,
    /// the points k in the order of [`Self::points`] (unweighted).
    #[inline(always)]
    pub(crate) fn transpose<T: CellReal, const D: usize, const B: usize>(
        &self,
        modes: &[T],
        stride: usize,
        y: &mut [T],
        n_padded: usize,
        scratch: &mut ExtrudedScratch<T>,
    ) {
        let (nb, nl, qb, ql) = (self.nb, self.nl, self.qb, self.ql);
        let nbp = self.nb_padded;
        let m = qb * ql;
        let tables = T::extruded_tables(self);
        let ExtrudedScratch {
            a: c,
            a_prime: c_prime,
            v: yt,
        } = scratch;
        // C[j][d][t] = Σ_q Σ_α ∂_α φ_t(ξ̄_q) V_d[α][(q, j)] (α in the base), C′[j][d][t] =
        // Σ_q φ_t(ξ̄_q) V_d[last][(q, j)]: B nodes t of every component at a time.
        resized(c, ql * D * nbp);
        resized(c_prime, ql * D * nbp);
        for j in 0..ql {
            for t0 in (0..nb).step_by(B) {
                let mut s = [[T::default(); B]; D];
                let mut s_prime = [[T::default(); B]; D];
                for q in 0..qb {
                    for alpha in 0..D - 1 {
                        let f = &tables.by_node[(alpha * qb + q) * nbp + t0..][..B];
                        for (d, sums) in s.iter_mut().enumerate() {
                            let v = modes[d * stride + alpha * m + j * qb + q];
                            for i in 0..B {
                                sums[i] += v * f[i];
                            }
                        }
                    }
                    let f = &tables.by_node[((D - 1) * qb + q) * nbp + t0..][..B];
                    for (d, sums) in s_prime.iter_mut().enumerate() {
                        let v = modes[d * stride + (D - 1) * m + j * qb + q];
                        for i in 0..B {
                            sums[i] += v * f[i];
                        }
                    }
                }
                for d in 0..D {
                    c[(j * D + d) * nbp + t0..][..B].copy_from_slice(&s[d]);
                    c_prime[(j * D + d) * nbp + t0..][..B].copy_from_slice(&s_prime[d]);
                }
            }
        }
        // Yᵀ[l][d][t] = Σ_j ψ_l(ζ_j) C[j][d][t] + ψ′_l(ζ_j) C′[j][d][t].
        resized(yt, nl * D * nbp);
        for l in 0..nl {
            for t0 in (0..nb).step_by(B) {
                let mut s = [[T::default(); B]; D];
                for j in 0..ql {
                    let (f, g) = (tables.line_value[l * ql + j], tables.line_deriv[l * ql + j]);
                    for (d, sums) in s.iter_mut().enumerate() {
                        let cs = &c[(j * D + d) * nbp + t0..][..B];
                        let cps = &c_prime[(j * D + d) * nbp + t0..][..B];
                        for i in 0..B {
                            sums[i] += f * cs[i] + g * cps[i];
                        }
                    }
                }
                for d in 0..D {
                    yt[(l * D + d) * nbp + t0..][..B].copy_from_slice(&s[d]);
                }
            }
        }
        // Y_d(t, l) into the cell's node order.
        for t in 0..nb {
            for l in 0..nl {
                let b = self.node[t * nl + l] as usize;
                for d in 0..D {
                    y[d * n_padded + b] = yt[(l * D + d) * nbp + t];
                }
            }
        }
    }
}

/// `buffer` as `len` zeros, reusing its allocation.
fn zeroed<T: CellReal>(buffer: &mut Vec<T>, len: usize) {
    buffer.clear();
    buffer.resize(len, T::default());
}

/// `buffer` `len` long, its old entries kept: for scratch whose every entry is written
/// before it is read.
fn resized<T: CellReal>(buffer: &mut Vec<T>, len: usize) {
    buffer.resize(len, T::default());
}

impl ExtrudedFactors {
    /// The tables in f64.
    pub(crate) fn double(&self) -> &FactorTables<f64> {
        &self.double
    }

    /// The tables in f32.
    pub(crate) fn single(&self) -> &FactorTables<f32> {
        &self.single
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_nodes::NodeFamily;

    /// Every prism, hexahedron and quadrilateral node family in use is a tensor product, and
    /// the factored gradients and their transpose equal the dense products with the tabulated
    /// gradients (to rounding) on a random field.
    #[test]
    fn factored_gradients_equal_the_tabulated_ones_for_every_tensor_shape() {
        for shape in [Shape::Quad, Shape::Prism, Shape::Hex] {
            for family in [
                NodeFamily::Fekete,
                NodeFamily::GaussLobatto,
                NodeFamily::WarpBlend,
                NodeFamily::Equispaced,
            ] {
                for order in 1..=5 {
                    let reference = ReferenceStiffness::new(shape, order, family).unwrap();
                    let factors = ExtrudedFactors::new(&reference)
                        .unwrap_or_else(|| panic!("{shape:?} {family:?} p = {order}"));
                    check_against_dense(&reference, &factors);
                }
            }
        }
        for shape in [Shape::Tri, Shape::Tet] {
            let reference = ReferenceStiffness::new(shape, 3, NodeFamily::Fekete).unwrap();
            assert!(ExtrudedFactors::new(&reference).is_none());
        }
    }

    fn check_against_dense(reference: &ReferenceStiffness, factors: &ExtrudedFactors) {
        const D: usize = 3;
        let dim = reference.dim;
        let (n, rule) = (reference.len, &reference.stiffness_rule);
        let m = rule.len();
        let stride = D * m;
        let x: Vec<f64> = (0..D * n)
            .map(|i| ((i * 37 % 101) as f64) / 50.0 - 1.0)
            .collect();
        let mut modes = vec![0.0; D * stride];
        let mut scratch = ExtrudedScratch::default();
        match dim {
            2 => factors.gradients::<f64, 2, 4>(&x, n, &mut modes, stride, &mut scratch),
            _ => factors.gradients::<f64, 3, 4>(&x, n, &mut modes, stride, &mut scratch),
        }
        // Any block width gives the same sums in the same order.
        let mut wide = vec![0.0; D * stride];
        match dim {
            2 => factors.gradients::<f64, 2, 8>(&x, n, &mut wide, stride, &mut scratch),
            _ => factors.gradients::<f64, 3, 8>(&x, n, &mut wide, stride, &mut scratch),
        }
        assert_eq!(modes, wide);
        let mut largest = 0.0_f64;
        let mut error = 0.0_f64;
        for d in 0..dim {
            for (at, &k) in factors.points().iter().enumerate() {
                let k = k as usize;
                let g = rule.gradients(k);
                for alpha in 0..dim {
                    let want: f64 =
                        rule.weights()[k] * (0..n).map(|b| g[b][alpha] * x[d * n + b]).sum::<f64>();
                    largest = largest.max(want.abs());
                    error = error.max((modes[d * stride + alpha * m + at] - want).abs());
                }
            }
        }
        assert!(
            error <= 1e-12 * largest,
            "{:?} p = {}: {error:e}",
            reference.shape,
            reference.order
        );
        // The transpose: y_d[b] = Σ_(α, k) ∂_α Φ_b(k) V_d[α m + k].
        let v: Vec<f64> = (0..D * stride)
            .map(|i| ((i * 53 % 97) as f64) / 40.0 - 1.0)
            .collect();
        let mut y = vec![0.0; D * n];
        match dim {
            2 => factors.transpose::<f64, 2, 4>(&v, stride, &mut y, n, &mut scratch),
            _ => factors.transpose::<f64, 3, 4>(&v, stride, &mut y, n, &mut scratch),
        }
        let mut wide = vec![0.0; D * n];
        match dim {
            2 => factors.transpose::<f64, 2, 8>(&v, stride, &mut wide, n, &mut scratch),
            _ => factors.transpose::<f64, 3, 8>(&v, stride, &mut wide, n, &mut scratch),
        }
        assert_eq!(y, wide);
        let (mut largest, mut error) = (0.0_f64, 0.0_f64);
        for d in 0..dim {
            for b in 0..n {
                let want: f64 = (0..m)
                    .map(|at| {
                        let k = factors.points()[at] as usize;
                        (0..dim)
                            .map(|alpha| {
                                rule.gradients(k)[b][alpha] * v[d * stride + alpha * m + at]
                            })
                            .sum::<f64>()
                    })
                    .sum();
                largest = largest.max(want.abs());
                error = error.max((y[d * n + b] - want).abs());
            }
        }
        assert!(
            error <= 1e-12 * largest,
            "{:?} p = {}: {error:e}",
            reference.shape,
            reference.order
        );
    }
}
