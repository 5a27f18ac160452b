//! Reference elements for high-order finite elements: the shapes hocurve meshes are made of
//! ([`Shape`]), their vertices, edges and faces, and the p-th order nodal sets placed on them
//! ([`ReferenceNodes`], families in [`NodeFamily`]).
//!
//! Every reference element lives in the unit box: the simplices have their right-angle
//! vertex at the origin, the quadrilateral and hexahedron are `[0, 1]^d`. Nodes are listed
//! in hocurve's *canonical local order*: vertices, then the interior nodes of each edge, of
//! each face, then of the cell (see [`ReferenceNodes`]).
//!
//! ```
//! use hocurve_nodes::{NodeFamily, ReferenceNodes, Shape};
//! let tet = ReferenceNodes::new(Shape::Tet, 3, NodeFamily::Equispaced);
//! assert_eq!(tet.len(), 20); // (p+1)(p+2)(p+3)/6
//! assert_eq!(tet.points()[1], [1.0, 0.0, 0.0]);
//! ```

mod basis;
mod fekete;
mod gauss;
mod lagrange;
mod nodal_sets;
mod quadrature;
mod reference;
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
