//! High-order linear elasticity (the paper's Sect. 2, 3.2): spreads the boundary displacement
//! of curved walls into the domain so that the elements next to them stay valid.
//!
//! The unknown is the displacement of every node of a [`HighOrderMesh`](hocurve_mesh::HighOrderMesh), discretised with
//! continuous isoparametric Lagrange elements of the mesh's order on every element type
//! ([`assemble_stiffness`]). Boundary nodes are prescribed or slide along a wall
//! ([`BoundaryConditions`]). On meshes of straight simplices (what the curving solves on) the
//! CG solver never assembles the stiffness: it applies it cell by cell from factors of the
//! reference matrices (`matrix_free`; [`SolverOptions::matrix_free`]), with no matrix in
//! memory. The condensed system is solved by conjugate gradients preconditioned
//! with a p-multigrid V-cycle (orders p, p − 1, …, 1 on the same mesh, a Chebyshev smoother
//! with block Jacobi over the dofs of each vertex, edge, face and cell interior, and an exact
//! p = 1 solve), whose iteration count stays nearly flat in p, or by a sparse Cholesky factorisation ([`SolverKind`]). Results do not depend on the
//! number of threads, bit for bit.
//!
//! # Example
//!
//! ```
//! use std::collections::BTreeMap;
//! use hocurve_elastic::{solve_displacement, BoundaryConditions, Material, SolverOptions};
//! use hocurve_mesh::{Element, Shape, HighOrderMesh, LinearMesh};
//! use hocurve_nodes::NodeFamily;
//! // The unit square as two triangles; stretch it by 1 % in x.
//! let square = LinearMesh {
//!     dim: 2,
//!     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
//!     cells: vec![
//!         Element { kind: Shape::Tri, vertices: vec![0, 1, 2], entity: 1 },
//!         Element { kind: Shape::Tri, vertices: vec![0, 2, 3], entity: 1 },
//!     ],
//!     ..Default::default()
//! };
//! let mesh = HighOrderMesh::from_linear(&square, 2, NodeFamily::Equispaced)?;
//! let mut bc = BoundaryConditions::default();
//! for node in hocurve_elastic::boundary_nodes(&mesh)? {
//!     let x = mesh.nodes[node as usize];
//!     bc.prescribed.insert(node, [0.01 * x[0], 0.0, 0.0]);
//! }
//! let solution =
//!     solve_displacement(&mesh, &Material::default(), &bc, &SolverOptions::default())?;
//! // The only interior node, the middle of the diagonal, moves with the linear field.
//! let centre = mesh.nodes.iter().position(|x| x[0] == 0.5 && x[1] == 0.5);
//! assert!(centre.is_some_and(|c| (solution.displacement[c][0] - 0.005).abs() < 1e-12));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod aggregation;
mod assembly;
mod block_jacobi;
mod block_matrix;
mod boundary;
mod cell_runs;
mod condensation;
mod element_matrix;
mod error_norm;
mod extruded_factors;
mod lanes;
mod material;
mod matrix_free;
mod p_multigrid;
mod pcg;
mod reference_element;
mod smoother;
mod solve;
mod sparse;
mod sparsity;
mod transfer;
mod vector_ops;

pub use assembly::{assemble_load, assemble_stiffness, BodyForce, StiffnessMatrix};
pub use boundary::{boundary_nodes, BoundaryConditions};
pub use error_norm::displacement_l2_error;
pub use material::Material;
pub use solve::{
    solve_displacement, solve_displacement_from, solve_displacement_stiffened,
    solve_displacement_with_load, solve_displacement_with_progress, ElasticSolution, SolveProgress,
    SolverKind, SolverOptions, Timings,
};

use hocurve_mesh::MeshError;
use hocurve_nodes::NodesError;

/// Errors of the elasticity step.
#[derive(Debug, thiserror::Error)]
pub enum ElasticError {
    /// Per-cell stiffening factors that are not one finite positive number per cell.
    #[error("invalid stiffening: {reason}")]
    InvalidStiffening {
        /// What is wrong.
        reason: String,
    },
    /// Young's modulus or Poisson's ratio outside the physical range.
    #[error("invalid material: E = {young}, ν = {poisson} (need E > 0 and −1 < ν < 0.5)")]
    InvalidMaterial {
        /// Young's modulus E.
        young: f64,
        /// Poisson's ratio ν.
        poisson: f64,
    },
    /// Nothing is prescribed: the displacement is defined only up to a rigid motion.
    #[error("no prescribed or sliding node: the elasticity problem is singular (rigid motions are free)")]
    NoDirichlet,
    /// A boundary condition names a node the mesh does not have.
    #[error("boundary condition on node {node}, but the mesh has {count} nodes")]
    NodeOutOfRange {
        /// The node id.
        node: u32,
        /// Number of nodes of the mesh.
        count: usize,
    },
    /// A prescribed displacement or a sliding normal is NaN or infinite, or a normal is zero.
    #[error("invalid boundary value at node {node}: {what}")]
    InvalidBoundaryValue {
        /// The node id.
        node: u32,
        /// What is wrong.
        what: &'static str,
    },
    /// The element map is singular (or not finite) at a quadrature point.
    #[error("cell {cell} is degenerate: Jacobian determinant {jacobian:e}")]
    DegenerateCell {
        /// Cell index.
        cell: usize,
        /// The determinant found.
        jacobian: f64,
    },
    /// A cell whose node count does not match its type and the mesh order.
    #[error("cell {cell} has {found} nodes, expected {expected}")]
    WrongNodeCount {
        /// Cell index.
        cell: usize,
        /// Nodes given.
        found: usize,
        /// Nodes of the complete order-p element.
        expected: usize,
    },
    /// A cell whose dimension differs from the mesh's.
    #[error("cell {cell} is a {kind} in a {dim}D mesh")]
    WrongCellDimension {
        /// Cell index.
        cell: usize,
        /// Its type name.
        kind: &'static str,
        /// Mesh dimension.
        dim: usize,
    },
    /// The sparse Cholesky factorisation failed (matrix not positive definite, or memory).
    #[error("sparse Cholesky factorisation of the {what} failed: {message}")]
    Factorization {
        /// Which matrix ("condensed system", "coarse matrix").
        what: &'static str,
        /// faer's message.
        message: String,
    },
    /// The solve ended with a true relative residual above the acceptable level.
    #[error("the {solver} solver stopped after {iterations} iterations with relative residual {residual:e} (> {limit:e})")]
    NotConverged {
        /// "direct" or "cg".
        solver: &'static str,
        /// Iterations done (0 for the direct solver).
        iterations: usize,
        /// ‖b − A x‖ / ‖b‖.
        residual: f64,
        /// The limit that was not met.
        limit: f64,
    },
    /// An initial guess that is not one finite displacement per node.
    #[error("invalid initial displacement: {reason}")]
    InvalidInitialGuess {
        /// What is wrong.
        reason: String,
    },
    /// A body force value is NaN or infinite.
    #[error("the body force is not finite at a quadrature point of cell {cell}")]
    NonFiniteLoad {
        /// Cell index.
        cell: usize,
    },
    /// The mesh (element types, node sets) could not be handled.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A reference element could not be built.
    #[error(transparent)]
    Nodes(#[from] NodesError),
}
