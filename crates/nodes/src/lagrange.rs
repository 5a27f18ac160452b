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
#[path = "tests/lagrange.rs"]
mod tests;
