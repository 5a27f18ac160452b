//! Errors of the quality crate.

use hocurve_mesh::Shape;

/// What can go wrong when measuring a mesh or writing its plots. Element indices are 0-based
/// positions in [`hocurve_mesh::HighOrderMesh::cells`].
#[derive(Debug, thiserror::Error)]
pub enum QualityError {
    /// The element's shape does not have the mesh's dimension (e.g. a line among 2D cells).
    #[error("element {element} is a {}, not a {dim}D cell", .shape.name())]
    WrongDimension {
        /// Element index.
        element: usize,
        /// Its shape.
        shape: Shape,
        /// Mesh dimension.
        dim: usize,
    },
    /// The element has not the number of nodes of a complete order-p element of its shape.
    #[error("element {element} ({}) has {found} nodes, an order-{order} element has {expected}", .shape.name())]
    WrongNodeCount {
        /// Element index.
        element: usize,
        /// Its shape.
        shape: Shape,
        /// Mesh order.
        order: usize,
        /// Nodes expected.
        expected: usize,
        /// Nodes found.
        found: usize,
    },
    /// A node id outside the node list.
    #[error("element {element} references node {node}, but the mesh has {count} nodes")]
    NodeOutOfRange {
        /// Element index.
        element: usize,
        /// The bad node id.
        node: usize,
        /// Number of nodes.
        count: usize,
    },
    /// An element index outside the cell list.
    #[error("element {element} does not exist (the mesh has {count} elements)")]
    ElementOutOfRange {
        /// Requested index.
        element: usize,
        /// Number of elements.
        count: usize,
    },
    /// Two vertices of an element coincide, so its stretching is infinite.
    #[error("element {element} has an edge of zero length (vertices {a} and {b} coincide)")]
    DegenerateEdge {
        /// Element index.
        element: usize,
        /// Local vertex indices of the edge.
        a: usize,
        /// Second local vertex.
        b: usize,
    },
    /// The Bernstein degree the Jacobian determinant needs is beyond what the conversion
    /// handles accurately.
    #[error("Bézier validity of order-{order} {} elements is not supported (Jacobian degree {degree} > {max})", .shape.name())]
    UnsupportedBezierDegree {
        /// Shape.
        shape: Shape,
        /// Mesh order.
        order: usize,
        /// Bernstein degree needed (per variable for tensor shapes).
        degree: usize,
        /// Largest supported degree.
        max: usize,
    },
    /// The order or node family is not available.
    #[error(transparent)]
    Nodes(#[from] hocurve_nodes::NodesError),
    /// Serialising the summary failed.
    #[error("could not write the summary as JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// Drawing a plot failed.
    #[error("could not draw a histogram: {message}")]
    Plot {
        /// What the plotting library said.
        message: String,
    },
}
