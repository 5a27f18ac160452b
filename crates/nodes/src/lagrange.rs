//! Lagrange (nodal) bases on any nodal set, through the generalised Vandermonde matrix.
//!
//! With ψ the [`OrthonormalBasis`] of the shape and V the Vandermonde matrix
//! Vᵢⱼ = ψⱼ(xᵢ) at the nodes xᵢ, the Lagrange functions are Φ = V⁻ᵀ ψ, i.e.
//! Φᵢ(ξ) = Σⱼ (V⁻¹)ⱼᵢ ψⱼ(ξ), so Φᵢ(xₖ) = (V V⁻¹)ₖᵢ = δᵢₖ. Building on an orthonormal basis
//! keeps V as well conditioned as the node set allows (Hesthaven & Warburton §6.1); its
//! 2-norm condition number is kept as a measure of the quality of the node set.

use nalgebra::DMatrix;

use crate::{NodeFamily, NodesError, OrthonormalBasis, ReferenceNodes, Shape};

/// The Lagrange basis {Φᵢ} of a nodal set, Φᵢ(xⱼ) = δᵢⱼ, in the set's node order.
#[derive(Debug, Clone, PartialEq)]
pub struct LagrangeBasis {
    family: NodeFamily,
    basis: OrthonormalBasis,
    nodes: Vec<[f64; 3]>,
    /// V⁻¹; column i holds the coefficients of Φᵢ in the orthonormal basis.
    coefficients: DMatrix<f64>,
    condition_number: f64,
}

impl LagrangeBasis {
    /// The Lagrange basis on `nodes`; an error if their Vandermonde matrix is singular
    /// (relative to machine precision).
    pub fn new(nodes: &ReferenceNodes) -> Result<Self, NodesError> {
        Self::from_points(nodes.shape(), nodes.order(), nodes.family(), nodes.points())
    }

    fn from_points(
        shape: Shape,
        order: usize,
        family: NodeFamily,
        points: &[[f64; 3]],
    ) -> Result<Self, NodesError> {
        let singular = NodesError::SingularVandermonde {
            shape,
            order,
            family,
        };
        let basis = OrthonormalBasis::new(shape, order);
        assert_eq!(
            points.len(),
            basis.len(),
            "node count ≠ dimension of the space"
        );
        let vandermonde = basis.vandermonde(points);
        let sigma = vandermonde.singular_values();
        let (max, min) = (sigma.max(), sigma.min());
        let condition_number = max / min;
        let tolerance = points.len() as f64 * f64::EPSILON;
        if !condition_number.is_finite() || min <= tolerance * max {
            return Err(singular);
        }
        let coefficients = vandermonde.lu().try_inverse().ok_or(singular)?;
        Ok(LagrangeBasis {
            family,
            basis,
            nodes: points.to_vec(),
            coefficients,
            condition_number,
        })
    }

    /// The shape.
    pub fn shape(&self) -> Shape {
        self.basis.shape()
    }

    /// The polynomial order p.
    pub fn order(&self) -> usize {
        self.basis.order()
    }

    /// The node family the basis was built on.
    pub fn family(&self) -> NodeFamily {
        self.family
    }

    /// Number of Lagrange functions (= nodes).
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Always false.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The nodes xᵢ (reference coordinates), in the order of the functions.
    pub fn nodes(&self) -> &[[f64; 3]] {
        &self.nodes
    }

    /// The underlying orthonormal (modal) basis ψ.
    pub fn orthonormal_basis(&self) -> &OrthonormalBasis {
        &self.basis
    }

    /// V⁻¹: column i holds the coefficients of Φᵢ in the orthonormal basis ψ.
    pub fn inverse_vandermonde(&self) -> &DMatrix<f64> {
        &self.coefficients
    }

    /// 2-norm condition number of the Vandermonde matrix Vᵢⱼ = ψⱼ(xᵢ) (σ_max / σ_min).
    pub fn condition_number(&self) -> f64 {
        self.condition_number
    }

    /// Values Φᵢ(ξ) into `out[..len()]`, using `scratch[..len()]` for the ψ values; allocates
    /// nothing.
    pub fn eval_with(&self, xi: [f64; 3], scratch: &mut [f64], out: &mut [f64]) {
        let n = self.len();
        let psi = &mut scratch[..n];
        self.basis.eval(xi, psi);
        let c = self.coefficients.as_slice();
        for (i, o) in out[..n].iter_mut().enumerate() {
            *o = dot(&c[i * n..(i + 1) * n], psi);
        }
    }

    /// Values Φᵢ(ξ) into `out[..len()]` (allocates a scratch vector; see
    /// [`LagrangeBasis::eval_with`] for hot loops).
    pub fn eval(&self, xi: [f64; 3], out: &mut [f64]) {
        let mut scratch = vec![0.0; self.len()];
        self.eval_with(xi, &mut scratch, out);
    }

    /// Gradients ∇Φᵢ(ξ) (with respect to reference coordinates) into `out[..len()]`, using
    /// `scratch[..len()]` for the ψ gradients; allocates nothing.
    pub fn eval_grad_with(&self, xi: [f64; 3], scratch: &mut [[f64; 3]], out: &mut [[f64; 3]]) {
        let n = self.len();
        let grad_psi = &mut scratch[..n];
        self.basis.eval_grad(xi, grad_psi);
        let c = self.coefficients.as_slice();
        for (i, o) in out[..n].iter_mut().enumerate() {
            let mut g = [0.0; 3];
            for (cj, gj) in c[i * n..(i + 1) * n].iter().zip(grad_psi.iter()) {
                g[0] += cj * gj[0];
                g[1] += cj * gj[1];
                g[2] += cj * gj[2];
            }
            *o = g;
        }
    }

    /// Gradients ∇Φᵢ(ξ) into `out[..len()]` (allocates a scratch vector; see
    /// [`LagrangeBasis::eval_grad_with`] for hot loops).
    pub fn eval_grad(&self, xi: [f64; 3], out: &mut [[f64; 3]]) {
        let mut scratch = vec![[0.0; 3]; self.len()];
        self.eval_grad_with(xi, &mut scratch, out);
    }

    /// The interpolation matrix `M[(k, i)] = Φᵢ(points[k])` (rows = points, columns =
    /// nodes): nodal values u at the nodes give M u at the points.
    pub fn interpolation_matrix(&self, points: &[[f64; 3]]) -> DMatrix<f64> {
        self.basis.vandermonde(points) * &self.coefficients
    }

    /// Derivative matrices `D[d][(k, i)] = ∂Φᵢ/∂ξ_d (points[k])`.
    pub fn gradient_matrices(&self, points: &[[f64; 3]]) -> [DMatrix<f64>; 3] {
        self.basis
            .gradient_vandermonde(points)
            .map(|d| d * &self.coefficients)
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn max_order(shape: Shape) -> usize {
        match shape {
            Shape::Line | Shape::Tri | Shape::Tet => 8,
            _ => 6,
        }
    }

    /// Deterministic pseudo-random points inside the reference element.
    fn random_points(shape: Shape, count: usize, seed: u64) -> Vec<[f64; 3]> {
        let mut state = seed ^ 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut out = Vec::with_capacity(count);
        while out.len() < count {
            let mut p = [next(), next(), next()];
            for c in p.iter_mut().skip(shape.dim()) {
                *c = 0.0;
            }
            let ok = match shape {
                Shape::Tri | Shape::Prism => p[0] + p[1] < 1.0,
                Shape::Tet => p[0] + p[1] + p[2] < 1.0,
                _ => true,
            };
            if ok {
                out.push(p);
            }
        }
        out
    }

    /// Monomial exponents of the order-p space of `shape`.
    fn space_monomials(shape: Shape, p: usize) -> Vec<[usize; 3]> {
        let dim = shape.dim();
        let max = |d: usize| if d < dim { p } else { 0 };
        let mut out = Vec::new();
        for c in 0..=max(2) {
            for b in 0..=max(1) {
                for a in 0..=p {
                    let ok = match shape {
                        Shape::Line | Shape::Quad | Shape::Hex => true,
                        Shape::Tri | Shape::Tet => a + b + c <= p,
                        Shape::Prism => a + b <= p,
                    };
                    if ok {
                        out.push([a, b, c]);
                    }
                }
            }
        }
        out
    }

    fn monomial(x: [f64; 3], e: [usize; 3]) -> f64 {
        (0..3).map(|d| x[d].powi(e[d] as i32)).product()
    }

    fn monomial_grad(x: [f64; 3], e: [usize; 3]) -> [f64; 3] {
        let mut g = [0.0; 3];
        for (d, gd) in g.iter_mut().enumerate() {
            if e[d] > 0 {
                let mut f = e[d] as f64 * x[d].powi(e[d] as i32 - 1);
                for o in (0..3).filter(|&o| o != d) {
                    f *= x[o].powi(e[o] as i32);
                }
                *gd = f;
            }
        }
        g
    }

    fn equispaced_bases() -> impl Iterator<Item = LagrangeBasis> {
        Shape::ALL.into_iter().flat_map(|shape| {
            (1..=max_order(shape)).map(move |p| {
                let nodes = ReferenceNodes::new(shape, p, NodeFamily::Equispaced);
                LagrangeBasis::new(&nodes).expect("equispaced nodes are unisolvent")
            })
        })
    }

    #[test]
    fn lagrange_property_holds_at_the_nodes() {
        for lagrange in equispaced_bases() {
            let m = lagrange.interpolation_matrix(lagrange.nodes());
            let n = lagrange.len();
            for k in 0..n {
                for i in 0..n {
                    let expected = if i == k { 1.0 } else { 0.0 };
                    assert!(
                        (m[(k, i)] - expected).abs() < 1e-10,
                        "{:?} p={}: Φ{i}(x{k}) = {}",
                        lagrange.shape(),
                        lagrange.order(),
                        m[(k, i)]
                    );
                }
            }
        }
    }

    #[test]
    fn partition_of_unity_and_monomial_reproduction_at_random_points() {
        for lagrange in equispaced_bases() {
            let (shape, p, n) = (lagrange.shape(), lagrange.order(), lagrange.len());
            let points = random_points(shape, 4, p as u64);
            let (mut phi, mut grad) = (vec![0.0; n], vec![[0.0; 3]; n]);
            let (mut scratch, mut grad_scratch) = (vec![0.0; n], vec![[0.0; 3]; n]);
            let grad_matrices = lagrange.gradient_matrices(&points);
            for (k, &x) in points.iter().enumerate() {
                lagrange.eval_with(x, &mut scratch, &mut phi);
                lagrange.eval_grad_with(x, &mut grad_scratch, &mut grad);
                let sum: f64 = phi.iter().sum();
                assert!((sum - 1.0).abs() < 1e-11, "{shape:?} p={p}: ΣΦ = {sum}");
                for d in 0..3 {
                    let s: f64 = grad.iter().map(|g| g[d]).sum();
                    assert!(s.abs() < 1e-9, "{shape:?} p={p}: Σ∂{d}Φ = {s}");
                    for i in 0..n {
                        assert!((grad_matrices[d][(k, i)] - grad[i][d]).abs() < 1e-11);
                    }
                }
                for e in space_monomials(shape, p) {
                    let nodal: Vec<f64> =
                        lagrange.nodes().iter().map(|&y| monomial(y, e)).collect();
                    let value: f64 = nodal.iter().zip(&phi).map(|(u, f)| u * f).sum();
                    assert!(
                        (value - monomial(x, e)).abs() < 1e-10,
                        "{shape:?} p={p}: x^{e:?} at {x:?}: {value}"
                    );
                    let exact = monomial_grad(x, e);
                    for d in 0..3 {
                        let g: f64 = nodal.iter().zip(&grad).map(|(u, g)| u * g[d]).sum();
                        assert!(
                            (g - exact[d]).abs() < 1e-8,
                            "{shape:?} p={p}: ∂{d} x^{e:?} at {x:?}: {g} vs {}",
                            exact[d]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn allocating_and_scratch_evaluations_agree() {
        let nodes = ReferenceNodes::new(Shape::Prism, 3, NodeFamily::Equispaced);
        let lagrange = LagrangeBasis::new(&nodes).unwrap();
        let n = lagrange.len();
        let x = [0.2, 0.3, 0.7];
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        lagrange.eval(x, &mut a);
        lagrange.eval_with(x, &mut vec![0.0; n], &mut b);
        assert_eq!(a, b);
        let m = lagrange.interpolation_matrix(&[x]);
        for i in 0..n {
            assert!((m[(0, i)] - a[i]).abs() < 1e-13);
        }
        let (mut ga, mut gb) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        lagrange.eval_grad(x, &mut ga);
        lagrange.eval_grad_with(x, &mut vec![[0.0; 3]; n], &mut gb);
        assert_eq!(ga, gb);
    }

    #[test]
    fn condition_numbers_are_reported_and_bounded() {
        for lagrange in equispaced_bases() {
            let cond = lagrange.condition_number();
            eprintln!(
                "equispaced {:>13} p={}: cond₂(V) = {cond:.3e}",
                lagrange.shape().name(),
                lagrange.order()
            );
            assert!((1.0..1e4).contains(&cond), "{cond}");
        }
        // Line p = 1: V = [[1, −√3], [1, √3]] has orthogonal columns of norms √2 and √6.
        let line = LagrangeBasis::new(&ReferenceNodes::new(Shape::Line, 1, NodeFamily::Equispaced));
        let cond = line.unwrap().condition_number();
        assert!((cond - 3f64.sqrt()).abs() < 1e-14, "{cond}");
    }

    #[test]
    fn singular_node_sets_are_rejected() {
        // Six points on the edge y = 0: y, xy and y² vanish there, so P₂ restricted to them is
        // only 3-dimensional and V has rank 3.
        let points: Vec<[f64; 3]> = (0..6).map(|i| [i as f64 / 5.0, 0.0, 0.0]).collect();
        let err =
            LagrangeBasis::from_points(Shape::Tri, 2, NodeFamily::Equispaced, &points).unwrap_err();
        assert_eq!(
            err,
            NodesError::SingularVandermonde {
                shape: Shape::Tri,
                order: 2,
                family: NodeFamily::Equispaced
            }
        );
        assert!(err.to_string().contains("triangle"));
        // A repeated node.
        let mut points = ReferenceNodes::new(Shape::Quad, 2, NodeFamily::Equispaced)
            .points()
            .to_vec();
        points[8] = points[0];
        assert!(
            LagrangeBasis::from_points(Shape::Quad, 2, NodeFamily::Equispaced, &points).is_err()
        );
    }
}
