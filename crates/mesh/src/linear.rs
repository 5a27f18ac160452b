//! The linear (straight-sided) mesh as read from a file.

use std::collections::BTreeMap;

use crate::{ElementType, MeshError};

/// One element of a linear mesh: a cell or a boundary facet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Element {
    /// Element type.
    pub kind: ElementType,
    /// Vertex ids (0-based indices into [`LinearMesh::vertices`]), in Gmsh/VTK linear order.
    pub vertices: Vec<u32>,
    /// Tag of the geometric entity (Gmsh "elementary" tag) the element was meshed on.
    pub entity: i32,
}

/// A named physical group (Gmsh `$PhysicalNames`); `name` is empty when the file gave none.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct PhysicalGroup {
    /// Dimension of the group's entities.
    pub dim: usize,
    /// Physical tag.
    pub tag: i32,
    /// Name.
    pub name: String,
}

/// A straight-sided mesh: vertices, cells of the mesh dimension, and the facets of the next
/// lower dimension that the file declared (boundary curves in 2D, surfaces in 3D) with their
/// entity and physical tags.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LinearMesh {
    /// Mesh dimension, 2 or 3.
    pub dim: usize,
    /// Vertex coordinates (z = 0 in 2D).
    pub vertices: Vec<[f64; 3]>,
    /// Cells (dimension `dim`).
    pub cells: Vec<Element>,
    /// Facets (dimension `dim − 1`) declared in the file, usually the boundary.
    pub facets: Vec<Element>,
    /// Physical groups, sorted by (dim, tag).
    pub physical_groups: Vec<PhysicalGroup>,
    /// Physical tags of each geometric entity, keyed by (dim, entity tag).
    pub entity_physicals: BTreeMap<(usize, i32), Vec<i32>>,
}

impl LinearMesh {
    /// Physical tags of a cell or facet of dimension `dim` on geometric entity `entity`.
    pub fn physical_tags(&self, dim: usize, entity: i32) -> &[i32] {
        self.entity_physicals
            .get(&(dim, entity))
            .map(Vec::as_slice)
            .unwrap_or(&[])
    }

    /// The physical group with the given name, if any.
    pub fn physical_group(&self, name: &str) -> Option<&PhysicalGroup> {
        self.physical_groups.iter().find(|g| g.name == name)
    }

    /// Checks what the rest of hocurve relies on: a 2D or 3D mesh with cells of its
    /// dimension only, supported element types, vertex ids in range and not repeated within
    /// an element, facets one dimension lower.
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.dim != 2 && self.dim != 3 {
            return Err(MeshError::UnsupportedDimension(self.dim));
        }
        if self.cells.is_empty() {
            return Err(MeshError::NoCells { dim: self.dim });
        }
        let n = self.vertices.len();
        for (what, list, dim) in [
            ("cell", &self.cells, self.dim),
            ("facet", &self.facets, self.dim - 1),
        ] {
            for (i, e) in list.iter().enumerate() {
                e.kind.shape()?;
                if e.kind.dim() != dim {
                    return Err(MeshError::WrongDimension {
                        what,
                        index: i,
                        kind: e.kind,
                        expected: dim,
                    });
                }
                if e.vertices.len() != e.kind.num_vertices() {
                    return Err(MeshError::WrongVertexCount {
                        what,
                        index: i,
                        kind: e.kind,
                        found: e.vertices.len(),
                    });
                }
                for (k, &v) in e.vertices.iter().enumerate() {
                    if v as usize >= n {
                        return Err(MeshError::VertexOutOfRange {
                            what,
                            index: i,
                            vertex: v as usize,
                            count: n,
                        });
                    }
                    if e.vertices[..k].contains(&v) {
                        return Err(MeshError::RepeatedVertex {
                            what,
                            index: i,
                            vertex: v as usize,
                        });
                    }
                }
            }
        }
        for (i, v) in self.vertices.iter().enumerate() {
            if v.iter().any(|c| !c.is_finite()) {
                return Err(MeshError::NonFiniteVertex(i));
            }
        }
        Ok(())
    }
}
