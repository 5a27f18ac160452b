//! The mesh data model of hocurve: the straight-sided [`LinearMesh`] read from a file, its
//! [`Topology`] (unique edges and faces, which cells share them, the boundary), and the
//! [`HighOrderMesh`] whose p-th order nodes are shared exactly between neighbouring cells
//! (the node layout of the paper's Sect. 3–4: vertex, edge, face and interior nodes).
//!
//! # Example
//!
//! ```
//! use hocurve_mesh::{Element, Shape, HighOrderMesh, LinearMesh};
//! use hocurve_nodes::NodeFamily;
//! // Two triangles forming the unit square.
//! let mesh = LinearMesh {
//!     dim: 2,
//!     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
//!     cells: vec![
//!         Element { kind: Shape::Tri, vertices: vec![0, 1, 2], entity: 1 },
//!         Element { kind: Shape::Tri, vertices: vec![0, 2, 3], entity: 1 },
//!     ],
//!     ..Default::default()
//! };
//! let ho = HighOrderMesh::from_linear(&mesh, 3, NodeFamily::Equispaced)?;
//! // V + E(p−1) + F(p−1)(p−2)/2 = 4 + 5·2 + 2·1
//! assert_eq!(ho.nodes.len(), 16);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod boundary;

mod from_cells;
mod high_order;
mod jagged;
mod linear;
mod resample;
mod split;
mod topology;
mod undeclared;

pub use high_order::{HighOrderElement, HighOrderMesh, NodeLayout};
pub use hocurve_nodes::Shape;
pub use jagged::Jagged;
pub use linear::{Element, LinearMesh, PhysicalGroup};
pub use topology::{canonical_face, Topology, NO_CELL};

/// Errors of the mesh model. Indices are 0-based positions in the mesh's lists; messages
/// name elements and vertices by their tags in the file ([`LinearMesh::cell_tag`],
/// [`LinearMesh::facet_tag`], [`LinearMesh::vertex_tag`]: Gmsh element and node tags, or
/// 1-based positions for meshes that have none).
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// Only 2D and 3D meshes are meshes hocurve can curve.
    #[error("mesh dimension {0} is not supported (expected 2 or 3)")]
    UnsupportedDimension(usize),
    /// The mesh has no cells of its dimension.
    #[error("the mesh has no {dim}D cells")]
    NoCells {
        /// Mesh dimension.
        dim: usize,
    },
    /// An element of the wrong dimension in a list.
    #[error(
        "{what} with element tag {tag} is a {kind}, expected an element of dimension {expected}"
    )]
    WrongDimension {
        /// "cell" or "facet".
        what: &'static str,
        /// Element index.
        index: usize,
        /// Its tag in the file (Gmsh element tag).
        tag: u64,
        /// Its type.
        kind: Shape,
        /// Expected dimension.
        expected: usize,
    },
    /// Vertex count does not match the element type.
    #[error("{what} with element tag {tag} is a {kind} with {found} vertices")]
    WrongVertexCount {
        /// "cell" or "facet".
        what: &'static str,
        /// Element index.
        index: usize,
        /// Its tag in the file (Gmsh element tag).
        tag: u64,
        /// Its type.
        kind: Shape,
        /// Vertices given.
        found: usize,
    },
    /// A vertex id outside the vertex list.
    #[error("{what} with element tag {tag} references vertex {vertex} (0-based), but the mesh has {count} vertices")]
    VertexOutOfRange {
        /// "cell" or "facet".
        what: &'static str,
        /// Element index.
        index: usize,
        /// Its tag in the file (Gmsh element tag).
        tag: u64,
        /// The bad vertex id.
        vertex: usize,
        /// Number of vertices.
        count: usize,
    },
    /// The same vertex twice in one element (a collapsed element).
    #[error("{what} with element tag {tag} uses node tag {vertex_tag} twice (collapsed element)")]
    RepeatedVertex {
        /// "cell" or "facet".
        what: &'static str,
        /// Element index.
        index: usize,
        /// Its tag in the file (Gmsh element tag).
        tag: u64,
        /// The repeated vertex.
        vertex: usize,
        /// Its tag in the file (Gmsh node tag).
        vertex_tag: u64,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("node tag {tag} has a non-finite coordinate")]
    NonFiniteVertex {
        /// Vertex index.
        index: usize,
        /// Its tag in the file (Gmsh node tag).
        tag: u64,
    },
    /// The cells of a 2D mesh do not lie in one plane z = const: a surface mesh in 3D.
    #[error(
        "the mesh is 2D (triangles/quadrilaterals) but not planar: node tag {low_tag} is at z = {low}, node tag {high_tag} at z = {high}; hocurve curves volume meshes and 2D meshes in a plane z = const (mesh the volume in 3D, or the section in the xy-plane)"
    )]
    NotPlanar {
        /// Lowest z and its node's tag.
        low: f64,
        low_tag: u64,
        /// Highest z and its node's tag.
        high: f64,
        high_tag: u64,
    },
    /// More than two cells share a face (or, in 2D, an edge).
    #[error(
        "non-manifold mesh: more than two cells share the facet with node tags {vertex_tags:?}"
    )]
    NonManifold {
        /// The facet's vertices.
        vertices: Vec<u32>,
        /// Their tags in the file (Gmsh node tags).
        vertex_tags: Vec<u64>,
    },
    /// A facet of the file is not a face of any cell.
    #[error("facet with element tag {tag} (node tags {vertex_tags:?}) is not a face of any cell")]
    FacetNotInMesh {
        /// Facet index.
        index: usize,
        /// Its tag in the file (Gmsh element tag).
        tag: u64,
        /// Its vertices.
        vertices: Vec<u32>,
        /// Their tags in the file (Gmsh node tags).
        vertex_tags: Vec<u64>,
    },
    /// A cell with non-positive volume (or, in 2D, orientation opposite to the others).
    #[error(
        "input element tag {tag} is inverted or degenerate (signed Jacobian {jacobian:e} at its vertex {vertex}, node tag {vertex_tag})"
    )]
    InvertedCell {
        /// Cell index.
        index: usize,
        /// The cell's tag in the file (Gmsh element tag).
        tag: u64,
        /// The vertex's tag in the file (Gmsh node tag).
        vertex_tag: u64,
        /// Local vertex where the Jacobian was measured.
        vertex: usize,
        /// Signed Jacobian determinant there.
        jacobian: f64,
    },
    /// A 2D cell numbered the other way round from the mesh's first cell (clockwise against
    /// counter-clockwise in the xy-plane): each is valid, but a mesh must use one orientation.
    #[error(
        "input element tag {tag} is numbered {this} in the xy-plane, the first cell (element tag {first_tag}) {first}: a surface whose cells all turn clockwise is renumbered, but one that numbers its cells both ways round is folded or edited (in Gmsh: gmsh.model.mesh.reverse on its cells, or ReverseMesh Surface{{…}})"
    )]
    MixedOrientation {
        /// Cell index.
        index: usize,
        /// The cell's tag in the file (Gmsh element tag).
        tag: u64,
        /// The first cell's tag.
        first_tag: u64,
        /// "clockwise" or "counter-clockwise".
        this: &'static str,
        /// The first cell's orientation.
        first: &'static str,
    },
    /// The nodal set could not be built.
    #[error(transparent)]
    Nodes(#[from] hocurve_nodes::NodesError),
    /// A high-order element whose node count is not that of the complete element of its
    /// shape at the mesh's order.
    #[error("{what} {index} is a {kind} with {found} nodes, expected {expected} (complete order-{order} element)")]
    WrongNodeCount {
        /// "cell" or "facet".
        what: &'static str,
        /// Element index.
        index: usize,
        /// Its type.
        kind: Shape,
        /// Mesh order.
        order: usize,
        /// Nodes of the complete element.
        expected: usize,
        /// Nodes given.
        found: usize,
    },
    /// A node id outside the node list.
    #[error("{what} {index} references node {node}, but the mesh has {count} nodes")]
    NodeOutOfRange {
        /// "cell" or "facet".
        what: &'static str,
        /// Element index.
        index: usize,
        /// The bad node id.
        node: usize,
        /// Number of nodes.
        count: usize,
    },
    /// Two elements put different nodes (at different coordinates) at the same place of a
    /// shared edge or face: the mesh is not conforming.
    #[error("{what} {index} has node {node} (local node {local}) where a neighbouring cell has node {other} at a different position: the elements do not share their edge or face nodes")]
    NonConformingNode {
        /// "cell" or "facet".
        what: &'static str,
        /// Element index.
        index: usize,
        /// Local (canonical) node index in that element.
        local: usize,
        /// The element's node id.
        node: usize,
        /// The node id the neighbour uses there.
        other: usize,
    },
    /// A nodal data array whose length is not a multiple of the node count.
    #[error("nodal data has {found} values, expected {expected} ({components} components × {nodes} nodes)")]
    DataLength {
        /// Values per node.
        components: usize,
        /// Number of nodes.
        nodes: usize,
        /// components × nodes.
        expected: usize,
        /// Values given.
        found: usize,
    },
    /// Vertex positions given for a mesh with a different number of vertices.
    /// A face of a cell or facet whose vertices are not those of the mesh face it shares
    /// with a neighbour in any orientation (a quadrilateral's vertices in another cyclic
    /// order): the cells are not conforming.
    #[error(
        "{what} {index} has a face whose vertices are ordered inconsistently with its neighbour's"
    )]
    MismatchedFace {
        /// "cell" or "facet".
        what: &'static str,
        /// Its index.
        index: usize,
    },
    /// More of something than 32-bit ids can number.
    #[error("the mesh has {count} {what}: more than 32-bit ids can number")]
    TooLarge {
        /// What was counted.
        what: &'static str,
        /// How many.
        count: usize,
    },
    #[error("{found} vertex positions given for a mesh of {expected} vertices")]
    VertexCount {
        /// The mesh's vertices.
        expected: usize,
        /// Positions given.
        found: usize,
    },
}
