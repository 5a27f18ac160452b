//! Reference shapes: vertex coordinates and the local numbering of edges and faces.
//!
//! The vertex numbering of each shape is the one shared by Gmsh and VTK for linear
//! elements, and the edge and face lists follow Gmsh's, so linear meshes need no
//! reordering. Faces are listed with outward normals by the right-hand rule.

/// A reference element shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Shape {
    /// Segment [0, 1].
    Line,
    /// Triangle (0,0), (1,0), (0,1).
    Tri,
    /// Quadrilateral [0, 1]², vertices counter-clockwise from the origin.
    Quad,
    /// Tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1).
    Tet,
    /// Hexahedron [0, 1]³: bottom face counter-clockwise, then the top face above it.
    Hex,
    /// Prism (wedge): the reference triangle × [0, 1]; bottom triangle, then the top one.
    Prism,
}

impl std::fmt::Display for Shape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

const LINE_VERTICES: [[f64; 3]; 2] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
const TRI_VERTICES: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
const QUAD_VERTICES: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
];
const TET_VERTICES: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];
const HEX_VERTICES: [[f64; 3]; 8] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [0.0, 1.0, 1.0],
];
const PRISM_VERTICES: [[f64; 3]; 6] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
];

const LINE_EDGES: [[usize; 2]; 1] = [[0, 1]];
const TRI_EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];
const QUAD_EDGES: [[usize; 2]; 4] = [[0, 1], [1, 2], [2, 3], [3, 0]];
const TET_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]];
const HEX_EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [0, 3],
    [0, 4],
    [1, 2],
    [1, 5],
    [2, 3],
    [2, 6],
    [3, 7],
    [4, 5],
    [4, 7],
    [5, 6],
    [6, 7],
];
const PRISM_EDGES: [[usize; 2]; 9] = [
    [0, 1],
    [0, 2],
    [0, 3],
    [1, 2],
    [1, 4],
    [2, 5],
    [3, 4],
    [3, 5],
    [4, 5],
];

const TET_FACES: [&[usize]; 4] = [&[0, 2, 1], &[0, 1, 3], &[0, 3, 2], &[3, 1, 2]];
const HEX_FACES: [&[usize]; 6] = [
    &[0, 3, 2, 1],
    &[0, 1, 5, 4],
    &[0, 4, 7, 3],
    &[1, 2, 6, 5],
    &[2, 3, 7, 6],
    &[4, 5, 6, 7],
];
const PRISM_FACES: [&[usize]; 5] = [
    &[0, 2, 1],
    &[3, 4, 5],
    &[0, 1, 4, 3],
    &[0, 3, 5, 2],
    &[1, 2, 5, 4],
];

impl Shape {
    /// All shapes, lowest dimension first.
    pub const ALL: [Shape; 6] = [
        Shape::Line,
        Shape::Tri,
        Shape::Quad,
        Shape::Tet,
        Shape::Hex,
        Shape::Prism,
    ];

    /// Topological dimension.
    pub fn dim(self) -> usize {
        match self {
            Shape::Line => 1,
            Shape::Tri | Shape::Quad => 2,
            Shape::Tet | Shape::Hex | Shape::Prism => 3,
        }
    }

    /// Lower-case name, e.g. `"tetrahedron"`; also what `Display` prints.
    pub fn name(self) -> &'static str {
        match self {
            Shape::Line => "line",
            Shape::Tri => "triangle",
            Shape::Quad => "quadrilateral",
            Shape::Tet => "tetrahedron",
            Shape::Hex => "hexahedron",
            Shape::Prism => "prism",
        }
    }

    /// Vertex coordinates of the reference element (unused components are 0).
    pub fn vertices(self) -> &'static [[f64; 3]] {
        match self {
            Shape::Line => &LINE_VERTICES,
            Shape::Tri => &TRI_VERTICES,
            Shape::Quad => &QUAD_VERTICES,
            Shape::Tet => &TET_VERTICES,
            Shape::Hex => &HEX_VERTICES,
            Shape::Prism => &PRISM_VERTICES,
        }
    }

    /// Number of vertices.
    pub fn num_vertices(self) -> usize {
        self.vertices().len()
    }

    /// Local edges as pairs of local vertex indices; interior edge nodes run from the first
    /// vertex to the second.
    pub fn edges(self) -> &'static [[usize; 2]] {
        match self {
            Shape::Line => &LINE_EDGES,
            Shape::Tri => &TRI_EDGES,
            Shape::Quad => &QUAD_EDGES,
            Shape::Tet => &TET_EDGES,
            Shape::Hex => &HEX_EDGES,
            Shape::Prism => &PRISM_EDGES,
        }
    }

    /// Local faces of a 3D shape as lists of local vertex indices (3 for a triangle, 4 for a
    /// quadrilateral, counter-clockwise seen from outside). Empty for 1D and 2D shapes.
    pub fn faces(self) -> &'static [&'static [usize]] {
        match self {
            Shape::Tet => &TET_FACES,
            Shape::Hex => &HEX_FACES,
            Shape::Prism => &PRISM_FACES,
            _ => &[],
        }
    }

    /// The shape of a face with `n` vertices.
    pub fn face_shape(n: usize) -> Shape {
        if n == 3 {
            Shape::Tri
        } else {
            Shape::Quad
        }
    }

    /// Values of the vertex (linear, bilinear, trilinear, prism) shape functions at the
    /// reference point `xi`; entry i belongs to vertex i. The straight-sided map of an element
    /// is x(ξ) = Σᵢ Nᵢ(ξ) xᵢ.
    pub fn vertex_shape_functions(self, xi: [f64; 3]) -> ([f64; 8], usize) {
        let [x, y, z] = xi;
        let mut n = [0.0; 8];
        match self {
            Shape::Line => {
                n[0] = 1.0 - x;
                n[1] = x;
            }
            Shape::Tri => {
                n[0] = 1.0 - x - y;
                n[1] = x;
                n[2] = y;
            }
            Shape::Quad => {
                n[0] = (1.0 - x) * (1.0 - y);
                n[1] = x * (1.0 - y);
                n[2] = x * y;
                n[3] = (1.0 - x) * y;
            }
            Shape::Tet => {
                n[0] = 1.0 - x - y - z;
                n[1] = x;
                n[2] = y;
                n[3] = z;
            }
            Shape::Hex => {
                for (i, v) in HEX_VERTICES.iter().enumerate() {
                    let f = |c: f64, t: f64| if c == 0.0 { 1.0 - t } else { t };
                    n[i] = f(v[0], x) * f(v[1], y) * f(v[2], z);
                }
            }
            Shape::Prism => {
                let tri = [1.0 - x - y, x, y];
                for i in 0..3 {
                    n[i] = tri[i] * (1.0 - z);
                    n[i + 3] = tri[i] * z;
                }
            }
        }
        (n, self.num_vertices())
    }

    /// Number of nodes of the complete order-`p` element.
    pub fn num_nodes(self, p: usize) -> usize {
        match self {
            Shape::Line => p + 1,
            Shape::Tri => (p + 1) * (p + 2) / 2,
            Shape::Quad => (p + 1) * (p + 1),
            Shape::Tet => (p + 1) * (p + 2) * (p + 3) / 6,
            Shape::Hex => (p + 1) * (p + 1) * (p + 1),
            Shape::Prism => (p + 1) * (p + 1) * (p + 2) / 2,
        }
    }

    /// Number of nodes strictly inside the element (not on its boundary) at order `p`.
    pub fn num_interior_nodes(self, p: usize) -> usize {
        let q = p.saturating_sub(1); // interior nodes along an edge
        match self {
            Shape::Line => q,
            Shape::Tri => q * q.saturating_sub(1) / 2,
            Shape::Quad => q * q,
            Shape::Tet => q * q.saturating_sub(1) * q.saturating_sub(2) / 6,
            Shape::Hex => q * q * q,
            Shape::Prism => Shape::Tri.num_interior_nodes(p) * q,
        }
    }
}

#[cfg(test)]
#[path = "tests/reference.rs"]
mod tests;
