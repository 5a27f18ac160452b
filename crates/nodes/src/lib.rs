//! Reference elements for high-order finite elements (the paper's Sect. 2): the shapes
//! hocurve meshes are made of ([`Shape`]); p-th order nodal sets on them ([`ReferenceNodes`]:
//! equispaced, Gauss–Lobatto, warp & blend and Fekete, see [`NodeFamily`]); orthonormal
//! bases ([`OrthonormalBasis`]) and Lagrange bases on any nodal set ([`LagrangeBasis`]);
//! Gauss rules in 1D ([`gauss_legendre`], [`gauss_lobatto_legendre`], [`gauss_jacobi`]) and
//! quadrature exact to any degree on every shape ([`QuadratureRule`]).
//!
//! Every reference element lives in the unit box: the simplices have their right-angle
//! vertex at the origin, the quadrilateral and hexahedron are `[0, 1]^d`. Nodes are listed
//! in hocurve's *canonical local order*: vertices, then the interior nodes of each edge, of
//! each face, then of the cell (see [`ReferenceNodes`]). Fekete points are optimised at run
//! time (under 0.5 s for a tetrahedron at p = 10, milliseconds below p = 8) and cached.
//!
//! # Example
//!
//! ```
//! use hocurve_nodes::{LagrangeBasis, NodeFamily, QuadratureRule, ReferenceNodes, Shape};
//! let tet = ReferenceNodes::new(Shape::Tet, 3, NodeFamily::Equispaced);
//! assert_eq!(tet.len(), 20); // (p+1)(p+2)(p+3)/6
//! assert_eq!(tet.points()[1], [1.0, 0.0, 0.0]);
//! // Fekete nodes interpolate; the Lagrange basis is 1 at its own node.
//! let tri = ReferenceNodes::new(Shape::Tri, 6, NodeFamily::Fekete);
//! let basis = LagrangeBasis::new(&tri)?;
//! let mut phi = vec![0.0; basis.len()];
//! basis.eval(tri.points()[20], &mut phi);
//! assert!((phi[20] - 1.0).abs() < 1e-12);
//! // A degree-4 rule integrates x²y² over the triangle exactly: 2!·2!/6! = 1/180.
//! let rule = QuadratureRule::new(Shape::Tri, 4);
//! let integral: f64 = rule.points.iter().zip(&rule.weights).map(|(x, w)| w * x[0] * x[0] * x[1] * x[1]).sum();
//! assert!((integral - 1.0 / 180.0).abs() < 1e-15);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod basis;
mod fekete;
mod gauss;
mod lagrange;
mod nodal_sets;
mod quadrature;
mod reference;
mod reference_element;
mod symmetric_triangle;
mod warp_blend;

pub use basis::{OrthonormalBasis, MAX_BASIS_ORDER};
pub use gauss::{
    gauss_jacobi, gauss_legendre, gauss_lobatto_legendre, jacobi, jacobi_derivative,
    jacobi_weight_integral, Rule1D,
};
pub use lagrange::LagrangeBasis;
pub use nodal_sets::{NodeEntity, NodeFamily, ReferenceNodes};
pub use quadrature::QuadratureRule;
pub use reference::Shape;
pub use reference_element::{
    determinant, isoparametric_jacobian, ReferenceElement, TabulatedBasis,
};

/// Errors of this crate.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum NodesError {
    /// The order is outside what the nodal family supports.
    #[error("order {order} is not supported for {family} nodes (supported: 1..={max})")]
    UnsupportedOrder {
        /// Requested order.
        order: usize,
        /// Family name.
        family: &'static str,
        /// Largest supported order.
        max: usize,
    },
    /// The generalised Vandermonde matrix of a nodal set is (numerically) singular: the nodes
    /// are not unisolvent for the polynomial space, so no Lagrange basis exists on them.
    #[error(
        "the Vandermonde matrix of the order-{order} {family} nodes on the {} is singular",
        .shape.name()
    )]
    SingularVandermonde {
        /// Reference shape.
        shape: Shape,
        /// Polynomial order.
        order: usize,
        /// Node family.
        family: NodeFamily,
    },
}
