//! Element types as they appear in mesh files.

use hocurve_nodes::Shape;

use crate::MeshError;

/// The type of a linear element read from a mesh file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ElementType {
    /// 2-node segment: a boundary facet of a 2D mesh.
    Line,
    /// 3-node triangle.
    Tri,
    /// 4-node quadrilateral.
    Quad,
    /// 4-node tetrahedron.
    Tet,
    /// 8-node hexahedron.
    Hex,
    /// 6-node prism (wedge).
    Prism,
    /// 5-node pyramid: recognised so that it can be rejected clearly; not supported yet.
    Pyramid,
}

impl ElementType {
    /// Number of vertices.
    pub fn num_vertices(self) -> usize {
        match self {
            ElementType::Line => 2,
            ElementType::Tri => 3,
            ElementType::Quad => 4,
            ElementType::Tet => 4,
            ElementType::Hex => 8,
            ElementType::Prism => 6,
            ElementType::Pyramid => 5,
        }
    }

    /// Topological dimension.
    pub fn dim(self) -> usize {
        match self {
            ElementType::Line => 1,
            ElementType::Tri | ElementType::Quad => 2,
            _ => 3,
        }
    }

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            ElementType::Pyramid => "pyramid",
            other => other.shape().map(Shape::name).unwrap_or("pyramid"),
        }
    }

    /// The reference shape, or an error for element types hocurve cannot curve yet.
    pub fn shape(self) -> Result<Shape, MeshError> {
        Ok(match self {
            ElementType::Line => Shape::Line,
            ElementType::Tri => Shape::Tri,
            ElementType::Quad => Shape::Quad,
            ElementType::Tet => Shape::Tet,
            ElementType::Hex => Shape::Hex,
            ElementType::Prism => Shape::Prism,
            ElementType::Pyramid => return Err(MeshError::UnsupportedElement(self)),
        })
    }

    /// The element type of a supported shape.
    pub fn from_shape(shape: Shape) -> ElementType {
        match shape {
            Shape::Line => ElementType::Line,
            Shape::Tri => ElementType::Tri,
            Shape::Quad => ElementType::Quad,
            Shape::Tet => ElementType::Tet,
            Shape::Hex => ElementType::Hex,
            Shape::Prism => ElementType::Prism,
        }
    }
}

impl std::fmt::Display for ElementType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
