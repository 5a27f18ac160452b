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
//! Each sum runs over B outputs side by side (one AVX2 register: 4 in f64, 8 in f32) —
//! base nodes t for A and C, base points q for the gradients — for every component at once,
//! so the modes are ordered line point first (j q_b + q). A last block that would leave
//! half a register or more empty runs on a register of half the width (the prism's 12
//! points at p = 3 are 8 + 4 lanes, not 16), and the transpose takes two blocks of nodes
//! per pass so that each mode broadcast serves both: the same operations on each lane,
//! so the same bits.

use hocurve_nodes::{ReferenceElement, Shape};

use crate::lanes::Lanes;
use crate::matrix_free::CellReal;
use crate::reference_element::ReferenceStiffness;

/// Coordinates closer than this (reference element of size 1) are the same.
const SAME_COORDINATE: f64 = 1e-12;
/// Largest relative difference between a factored gradient and the tabulated one accepted.
const FACTOR_CHECK: f64 = 1e-10;
/// Outputs summed side by side: one AVX2 register of f64, of f32.
const DOUBLE_BLOCK: usize = 4;
const SINGLE_BLOCK: usize = 8;

/// The factors of one shape (see the module documentation).
#[derive(Debug, Clone)]
pub(crate) struct ExtrudedFactors {
    /// Base nodes n_b, line nodes n_l, base points q_b, line points q_l.
    nb: usize,
    nl: usize,
    qb: usize,
    ql: usize,
    /// Local node of (t, l) at `t n_l + l`.
    node: Vec<u32>,
    /// Rule point of (q, j) at `j q_b + q`: the order of the modes.
    point: Vec<u32>,
    /// ∂_α φ_t(ξ̄_q) for the base directions α, then (α = dim − 1) φ_t(ξ̄_q), at
    /// `(α n_b + t) q_b + q`.
    base: Vec<f64>,
    /// ψ_l(ζ_j) and ψ′_l(ζ_j) at `l q_l + j`.
    line_value: Vec<f64>,
    line_deriv: Vec<f64>,
    /// The tables of the cell actions in f64 (CG's operator, blocks of 4) and in f32 (the
    /// smoothers', blocks of 8): one AVX2 register of outputs.
    double: FactorTables<f64>,
    single: FactorTables<f32>,
}

/// The factors' numbers in one precision, in the order the sums read them: outputs in
/// blocks of `block` side by side, every direction α of one base node or point after
/// another. Entries beyond n_b or q_b are zero.
#[derive(Debug, Clone)]
pub(crate) struct FactorTables<T> {
    block: usize,
    /// q_b rounded up to whole blocks.
    qb_padded: usize,
    /// The rule's weight of point (q, j) at `j q_b' + q` (q_b' = q_b padded).
    weight: Vec<T>,
    /// ∂_α φ_t(ξ̄_q) (φ_t for the last α) at `((q / block) n_b + t) dim block + α block
    /// + q % block`: the gradients' sums read one row of dim blocks per node t.
    by_point: Vec<T>,
    /// The same at `((t / block) q_b + q) dim block + α block + t % block`: the
    /// transpose's sums read one row per point q.
    by_node: Vec<T>,
    /// ψ_l(ζ_j) and ψ′_l(ζ_j) at `l q_l + j`.
    line_value: Vec<T>,
    line_deriv: Vec<T>,
}

impl<T: CellReal> FactorTables<T> {
    /// From the factors' values (`base`, `weight` at `j q_b + q`, the line's), in blocks of
    /// `block`.
    fn new(factors: &ExtrudedFactors, weight: &[f64], dim: usize, block: usize) -> Self {
        let (nb, qb, ql) = (factors.nb, factors.qb, factors.ql);
        let (nb_padded, qb_padded) = (nb.div_ceil(block) * block, qb.div_ceil(block) * block);
        let row = dim * block;
        let mut by_point = vec![T::default(); qb_padded * nb * dim];
        let mut by_node = vec![T::default(); nb_padded * qb * dim];
        for alpha in 0..dim {
            for t in 0..nb {
                for q in 0..qb {
                    let v = T::of(factors.base[(alpha * nb + t) * qb + q]);
                    by_point[(q / block * nb + t) * row + alpha * block + q % block] = v;
                    by_node[(t / block * qb + q) * row + alpha * block + t % block] = v;
                }
            }
        }
        let mut padded = vec![T::default(); ql * qb_padded];
        for j in 0..ql {
            for q in 0..qb {
                padded[j * qb_padded + q] = T::of(weight[j * qb + q]);
            }
        }
        let to = |v: &[f64]| v.iter().map(|&x| T::of(x)).collect();
        FactorTables {
            block,
            qb_padded,
            weight: padded,
            by_point,
            by_node,
            line_value: to(&factors.line_value),
            line_deriv: to(&factors.line_deriv),
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
        let (mut values, mut grads) = (vec![0.0; n], vec![[0.0; 3]; n]);
        // φ_t and its gradient: the basis of nodes (t, 0) on the line of node 0, where
        // ψ_0 = 1.
        let mut base = vec![0.0; dim * nb * qb];
        for (q, b) in base_points.iter().enumerate() {
            let mut xi = *b;
            xi[axis] = line_nodes[0];
            element.basis().eval(xi, &mut values);
            element.basis().eval_grad(xi, &mut grads);
            for t in 0..nb {
                let at = node[t * nl];
                for alpha in 0..dim {
                    base[(alpha * nb + t) * qb + q] = if alpha < axis {
                        grads[at][alpha]
                    } else {
                        values[at]
                    };
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
        let weight: Vec<f64> = order.iter().map(|&k| rule.weights()[k]).collect();
        let mut factors = ExtrudedFactors {
            nb,
            nl,
            qb,
            ql,
            node: node.iter().map(|&b| b as u32).collect(),
            point: order.iter().map(|&k| k as u32).collect(),
            base,
            line_value,
            line_deriv,
            double: FactorTables::empty(),
            single: FactorTables::empty(),
        };
        factors.double = FactorTables::new(&factors, &weight, dim, DOUBLE_BLOCK);
        factors.single = FactorTables::new(&factors, &weight, dim, SINGLE_BLOCK);
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
                        let base = |alpha: usize| self.base[(alpha * self.nb + t) * self.qb + q];
                        let (line, slope) = (
                            self.line_value[l * self.ql + j],
                            self.line_deriv[l * self.ql + j],
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
    /// V is one register of the precision's tables (4 f64, 8 f32).
    #[inline(always)]
    pub(crate) fn gradients<V: Lanes, const D: usize>(
        &self,
        x: &[V::Real],
        n: usize,
        modes: &mut [V::Real],
        stride: usize,
        scratch: &mut ExtrudedScratch<V::Real>,
    ) {
        let (nb, nl, qb, ql) = (self.nb, self.nl, self.qb, self.ql);
        let tables = <V::Real as CellReal>::extruded_tables(self);
        let b = V::WIDTH;
        assert_eq!(tables.block, b, "the tables' block");
        let qbp = tables.qb_padded;
        let m = qb * ql;
        // The nodes' values in base-node order, every component of one node side by side,
        // rounded up to whole blocks.
        let span = (nb * D).div_ceil(b) * b;
        let ExtrudedScratch { a, a_prime, v: xt } = scratch;
        // Xᵀ[l][t][d] = X_d(t, l) at `l span + t D + d`, zero beyond n_b D (read, not
        // written).
        zeroed(xt, nl * span);
        for t in 0..nb {
            for l in 0..nl {
                let node = self.node[t * nl + l] as usize;
                for d in 0..D {
                    xt[l * span + t * D + d] = x[d * n + node];
                }
            }
        }
        // A[j][t][d] = Σ_l ψ_l(ζ_j) Xᵀ[l][t][d], A′ with ψ′: a register of (t, d) at a time.
        resized(a, ql * span);
        resized(a_prime, ql * span);
        for j in 0..ql {
            for k0 in (0..span).step_by(b) {
                let (mut s, mut s_prime) = (V::zero(), V::zero());
                for l in 0..nl {
                    let f = V::splat(tables.line_value[l * ql + j]);
                    let g = V::splat(tables.line_deriv[l * ql + j]);
                    let xs = V::load(&xt[l * span + k0..]);
                    s = s.plus_product(f, xs);
                    s_prime = s_prime.plus_product(g, xs);
                }
                s.store(&mut a[j * span + k0..]);
                s_prime.store(&mut a_prime[j * span + k0..]);
            }
        }
        // U_d[α][(q, j)] = w Σ_t ∂_α φ_t(ξ̄_q) A[j][t][d] (α in the base), w Σ_t φ_t(ξ̄_q)
        // A′[j][t][d] along the line: a register of points q of every component at a time,
        // so that each table row loaded serves D sums and D² sums run independently; the
        // last block on a half register where that holds every point left.
        for j in 0..ql {
            let at = &a[j * span..][..nb * D];
            let at_prime = &a_prime[j * span..][..nb * D];
            for (block, rows) in tables.by_point.chunks_exact(nb * D * b).enumerate() {
                let q0 = block * b;
                let points = PointBlock {
                    rows,
                    block: b,
                    weight: &tables.weight[j * qbp + q0..],
                    first: j * qb + q0,
                    len: (qb - q0).min(b),
                };
                if points.len <= V::Half::WIDTH {
                    points.gradients::<V::Half, D>(at, at_prime, modes, stride, m);
                } else {
                    points.gradients::<V, D>(at, at_prime, modes, stride, m);
                }
            }
        }
    }

    /// The transpose: `y[d n_padded + b]` = Σ_(α, k) ∂_α Φ_b(k) `modes[d stride + α m + k]`,
    /// the points k in the order of [`Self::points`] (unweighted); V as in
    /// [`Self::gradients`].
    #[inline(always)]
    pub(crate) fn transpose<V: Lanes, const D: usize>(
        &self,
        modes: &[V::Real],
        stride: usize,
        y: &mut [V::Real],
        n_padded: usize,
        scratch: &mut ExtrudedScratch<V::Real>,
    ) {
        let (nb, nl, qb, ql) = (self.nb, self.nl, self.qb, self.ql);
        let tables = <V::Real as CellReal>::extruded_tables(self);
        let b = V::WIDTH;
        assert_eq!(tables.block, b, "the tables' block");
        // Base nodes rounded up to whole blocks, the last to a half one where that holds it.
        let half = V::Half::WIDTH;
        let nbp = nb / b * b
            + match nb % b {
                0 => 0,
                r if r <= half => half,
                _ => b,
            };
        let m = qb * ql;
        let ExtrudedScratch {
            a: c,
            a_prime: c_prime,
            v: yt,
        } = scratch;
        // C[j][d][t] = Σ_q Σ_α ∂_α φ_t(ξ̄_q) V_d[α][(q, j)] (α in the base), C′[j][d][t] =
        // Σ_q φ_t(ξ̄_q) V_d[last][(q, j)]: a register of nodes t of every component at a
        // time.
        resized(c, ql * D * nbp);
        resized(c_prime, ql * D * nbp);
        let row = D * b;
        for j in 0..ql {
            // V_d[α][(·, j)].
            let mut v: [[&[V::Real]; D]; D] = [[&[]; D]; D];
            for (d, v_d) in v.iter_mut().enumerate() {
                for (alpha, v_da) in v_d.iter_mut().enumerate() {
                    *v_da = &modes[d * stride + alpha * m + j * qb..][..qb];
                }
            }
            // Two blocks at a time, so that each mode broadcast serves both.
            let mut blocks = tables.by_node.chunks_exact(qb * row);
            let mut t0 = 0;
            while let Some(rows) = blocks.next() {
                let out = NodeBlocks {
                    block: b,
                    qb,
                    nbp,
                    at: j * D * nbp + t0,
                };
                match blocks.next() {
                    None if nb - t0 <= half => {
                        out.pair::<V::Half, V::Half, D, false>(rows, rows, &v, c, c_prime)
                    }
                    None => out.pair::<V, V, D, false>(rows, rows, &v, c, c_prime),
                    Some(next) if nb - t0 - b <= half => {
                        out.pair::<V, V::Half, D, true>(rows, next, &v, c, c_prime)
                    }
                    Some(next) => out.pair::<V, V, D, true>(rows, next, &v, c, c_prime),
                }
                t0 += 2 * b;
            }
        }
        // Yᵀ[l][d][t] = Σ_j ψ_l(ζ_j) C[j][d][t] + ψ′_l(ζ_j) C′[j][d][t].
        let span = D * nbp;
        resized(yt, nl * span);
        for l in 0..nl {
            let mut k0 = 0;
            while k0 + b <= span {
                line_block::<V>(tables, ql, l, c, c_prime, yt, span, k0);
                k0 += b;
            }
            if k0 < span {
                line_block::<V::Half>(tables, ql, l, c, c_prime, yt, span, k0);
            }
        }
        // Y_d(t, l) into the cell's node order.
        for t in 0..nb {
            for l in 0..nl {
                let node = self.node[t * nl + l] as usize;
                for d in 0..D {
                    y[d * n_padded + node] = yt[l * span + d * nbp + t];
                }
            }
        }
    }
}

/// One block of base points of [`ExtrudedFactors::gradients`]: the table's rows of its
/// points (every node t, every direction α, `block` lanes each), the weights from its
/// first point, its first mode (j q_b + q0) and how many of its lanes are points.
struct PointBlock<'a, T> {
    rows: &'a [T],
    block: usize,
    weight: &'a [T],
    first: usize,
    len: usize,
}

impl<T: CellReal> PointBlock<'_, T> {
    /// The block's gradient modes on registers W (of at most `block` lanes; the first
    /// W::WIDTH of each row).
    #[inline(always)]
    fn gradients<W: Lanes<Real = T>, const D: usize>(
        &self,
        at: &[T],
        at_prime: &[T],
        modes: &mut [T],
        stride: usize,
        m: usize,
    ) {
        let b = self.block;
        let mut acc = [[W::zero(); D]; D];
        for (t, f) in self.rows.chunks_exact(D * b).enumerate() {
            // (Not `array::from_fn`: not always inlined, and a call spills every sum.)
            let mut fs = [W::zero(); D];
            for (alpha, lanes) in fs.iter_mut().enumerate() {
                *lanes = W::load(&f[alpha * b..]);
            }
            for (d, acc_d) in acc.iter_mut().enumerate() {
                let v = W::splat(at[t * D + d]);
                for alpha in 0..D - 1 {
                    acc_d[alpha] = acc_d[alpha].plus_product(v, fs[alpha]);
                }
                let v_prime = W::splat(at_prime[t * D + d]);
                acc_d[D - 1] = acc_d[D - 1].plus_product(v_prime, fs[D - 1]);
            }
        }
        let w = W::load(self.weight);
        for (d, acc_d) in acc.iter().enumerate() {
            for (alpha, sums) in acc_d.iter().enumerate() {
                let out = &mut modes[d * stride + alpha * m + self.first..];
                if self.len == W::WIDTH {
                    w.mul(*sums).store(out);
                } else {
                    w.mul(*sums).store_first(out, self.len);
                }
            }
        }
    }
}

/// Where one or two blocks of base nodes of [`ExtrudedFactors::transpose`] at line point
/// j go: C and C′ of node t0 + i (component d) at `c[at + d nbp + i]`, the tables' rows
/// `block` lanes wide.
struct NodeBlocks {
    block: usize,
    qb: usize,
    nbp: usize,
    at: usize,
}

impl NodeBlocks {
    /// C and C′ of the block of `rows` on registers W and, when TWO, of the next block
    /// (`next`) on registers X, from the modes V_d[α][(·, j)]: the base directions' sums
    /// first, then the line's, so that the sums and rows of both blocks fit in registers.
    #[inline(always)]
    fn pair<W: Lanes, X: Lanes<Real = W::Real>, const D: usize, const TWO: bool>(
        &self,
        rows: &[W::Real],
        next: &[W::Real],
        v: &[[&[W::Real]; D]; D],
        c: &mut [W::Real],
        c_prime: &mut [W::Real],
    ) {
        let (b, row) = (self.block, D * self.block);
        let (mut s, mut s_next) = ([W::zero(); D], [X::zero(); D]);
        for q in 0..self.qb {
            for alpha in 0..D - 1 {
                let f = W::load(&rows[q * row + alpha * b..]);
                let f_next = if TWO {
                    X::load(&next[q * row + alpha * b..])
                } else {
                    X::zero()
                };
                for d in 0..D {
                    let mode = v[d][alpha][q];
                    s[d] = s[d].plus_product(W::splat(mode), f);
                    if TWO {
                        s_next[d] = s_next[d].plus_product(X::splat(mode), f_next);
                    }
                }
            }
        }
        self.store::<W, X, D, TWO>(s, s_next, c);
        let (mut s, mut s_next) = ([W::zero(); D], [X::zero(); D]);
        let last = (D - 1) * b;
        for q in 0..self.qb {
            let f = W::load(&rows[q * row + last..]);
            let f_next = if TWO {
                X::load(&next[q * row + last..])
            } else {
                X::zero()
            };
            for d in 0..D {
                let mode = v[d][D - 1][q];
                s[d] = s[d].plus_product(W::splat(mode), f);
                if TWO {
                    s_next[d] = s_next[d].plus_product(X::splat(mode), f_next);
                }
            }
        }
        self.store::<W, X, D, TWO>(s, s_next, c_prime);
    }

    #[inline(always)]
    fn store<W: Lanes, X: Lanes<Real = W::Real>, const D: usize, const TWO: bool>(
        &self,
        s: [W; D],
        s_next: [X; D],
        to: &mut [W::Real],
    ) {
        for d in 0..D {
            let at = self.at + d * self.nbp;
            s[d].store(&mut to[at..]);
            if TWO {
                s_next[d].store(&mut to[at + self.block..]);
            }
        }
    }
}

/// Yᵀ[l][k0..k0 + W::WIDTH] of [`ExtrudedFactors::transpose`]: Σ_j ψ_l(ζ_j) C[j] + ψ′_l(ζ_j)
/// C′[j] on those lanes.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn line_block<W: Lanes>(
    tables: &FactorTables<W::Real>,
    ql: usize,
    l: usize,
    c: &[W::Real],
    c_prime: &[W::Real],
    yt: &mut [W::Real],
    span: usize,
    k0: usize,
) {
    let mut s = W::zero();
    for j in 0..ql {
        let f = W::splat(tables.line_value[l * ql + j]);
        let g = W::splat(tables.line_deriv[l * ql + j]);
        let cs = W::load(&c[j * span + k0..]);
        let cps = W::load(&c_prime[j * span + k0..]);
        s = s.add(f.mul(cs).add(g.mul(cps)));
    }
    s.store(&mut yt[l * span + k0..]);
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

impl<T: CellReal> FactorTables<T> {
    /// No tables (while the factors that make them are built).
    fn empty() -> Self {
        FactorTables {
            block: 1,
            qb_padded: 0,
            weight: Vec::new(),
            by_point: Vec::new(),
            by_node: Vec::new(),
            line_value: Vec::new(),
            line_deriv: Vec::new(),
        }
    }
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
    use crate::lanes::Portable;
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
            2 => factors.gradients::<Portable<f64, 4>, 2>(&x, n, &mut modes, stride, &mut scratch),
            _ => factors.gradients::<Portable<f64, 4>, 3>(&x, n, &mut modes, stride, &mut scratch),
        }
        // f32 (blocks of 8) to its round-off.
        let single: Vec<f32> = x.iter().map(|&v| v as f32).collect();
        let mut narrow = vec![0.0_f32; D * stride];
        match dim {
            2 => factors.gradients::<Portable<f32, 8>, 2>(
                &single,
                n,
                &mut narrow,
                stride,
                &mut Default::default(),
            ),
            _ => factors.gradients::<Portable<f32, 8>, 3>(
                &single,
                n,
                &mut narrow,
                stride,
                &mut Default::default(),
            ),
        }
        assert_within_f32_round_off(&modes, &narrow);
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
            2 => factors.transpose::<Portable<f64, 4>, 2>(&v, stride, &mut y, n, &mut scratch),
            _ => factors.transpose::<Portable<f64, 4>, 3>(&v, stride, &mut y, n, &mut scratch),
        }
        let single: Vec<f32> = v.iter().map(|&v| v as f32).collect();
        let mut narrow = vec![0.0_f32; D * n];
        match dim {
            2 => factors.transpose::<Portable<f32, 8>, 2>(
                &single,
                stride,
                &mut narrow,
                n,
                &mut Default::default(),
            ),
            _ => factors.transpose::<Portable<f32, 8>, 3>(
                &single,
                stride,
                &mut narrow,
                n,
                &mut Default::default(),
            ),
        }
        assert_within_f32_round_off(&y, &narrow);
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

    /// `single` (f32 sums) equals `double` to f32 round-off relative to its largest entry.
    fn assert_within_f32_round_off(double: &[f64], single: &[f32]) {
        let largest = double.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let error = double
            .iter()
            .zip(single)
            .fold(0.0_f64, |e, (a, b)| e.max((a - f64::from(*b)).abs()));
        assert!(error <= 1e-5 * largest, "f32: {error:e} of {largest:e}");
    }

    /// Timing of the factored sums alone, one cell's data in cache (run with `--ignored
    /// --nocapture`, release, on a CPU with AVX2): ns per call of the gradients and the
    /// transpose, f64 and f32, prisms and hexahedra p = 2..5. Against
    /// `matrix_free::tests::extruded_action_timings` it tells what share of a cell action
    /// the sums are.
    #[test]
    #[ignore]
    #[cfg(target_arch = "x86_64")]
    fn factored_sum_timings() {
        use crate::lanes::{Avx2Double, Avx2Single};
        assert!(std::arch::is_x86_feature_detected!("avx2"));
        #[target_feature(enable = "avx2")]
        fn time<V: Lanes>(factors: &ExtrudedFactors, n: usize, m: usize, reps: usize) -> [f64; 2] {
            let stride = 3 * m;
            let x: Vec<V::Real> = (0..3 * n)
                .map(|i| V::Real::of(((i * 37 % 101) as f64) / 50.0 - 1.0))
                .collect();
            let (mut modes, mut y) = (
                vec![V::Real::default(); 3 * stride],
                vec![V::Real::default(); 3 * n],
            );
            let mut scratch = ExtrudedScratch::default();
            let start = std::time::Instant::now();
            for _ in 0..reps {
                factors.gradients::<V, 3>(&x, n, &mut modes, stride, &mut scratch);
                std::hint::black_box(&mut modes);
            }
            let gradients = start.elapsed().as_secs_f64();
            let start = std::time::Instant::now();
            for _ in 0..reps {
                factors.transpose::<V, 3>(&modes, stride, &mut y, n, &mut scratch);
                std::hint::black_box(&mut y);
            }
            [gradients, start.elapsed().as_secs_f64()].map(|t| 1e9 * t / reps as f64)
        }
        for order in 2..=5 {
            for shape in [Shape::Prism, Shape::Hex] {
                let reference = ReferenceStiffness::new(shape, order, NodeFamily::Fekete).unwrap();
                let factors = ExtrudedFactors::new(&reference).unwrap();
                let (n, m) = (reference.len, reference.stiffness_rule.len());
                let reps = 200_000 / (order * order);
                // SAFETY: the CPU has AVX2 (asserted above).
                let [g64, t64] = unsafe { time::<Avx2Double>(&factors, n, m, reps) };
                let [g32, t32] = unsafe { time::<Avx2Single>(&factors, n, m, reps) };
                println!(
                    "{shape:?} p = {order}: gradients f64 {g64:.0} f32 {g32:.0} ns, \
                     transpose f64 {t64:.0} f32 {t32:.0} ns"
                );
            }
        }
    }
}
