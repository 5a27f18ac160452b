//! What a Gmsh file may leave out of a mesh that curving needs, recovered from its cells:
//! the boundary facets it did not declare (a file whose only physical group is the volume
//! holds no facets at all, one with a group on some walls only those, one whose groups are
//! two volumes not the surface between them), and the
//! counter-clockwise numbering of 2D cells (Gmsh numbers a surface's cells by the surface's
//! normal, which points along −z for a face built from a clockwise loop).

use std::collections::BTreeSet;

use crate::linear::corner_jacobians;
use crate::topology::canonical_face;
use crate::{Element, LinearMesh, MeshError, Shape, Topology, NO_CELL};

/// Whether a facet on entity `entity` was found from the cells rather than read from the
/// file ([`LinearMesh::undeclared_boundary_facets`]): such facets carry negative entity
/// tags, which Gmsh never writes, and are curved but not written.
pub(crate) fn is_undeclared_entity(entity: i32) -> bool {
    entity < 0
}

impl Element {
    /// Whether this facet was found from the cells ([`is_undeclared_entity`]).
    pub fn is_undeclared_facet(&self) -> bool {
        is_undeclared_entity(self.entity)
    }
}

impl LinearMesh {
    /// The facets of the cells — faces in 3D, edges in 2D — on the boundary of a model
    /// entity that the file does not declare: those of one cell, and those between cells of
    /// two entities (the interface of two volumes, two materials, whose CAD face the file
    /// leaves out when its groups are the volumes), vertices in the first cell's local
    /// order. Facet k gets
    /// the entity tag −1 − k: each is its own mesh entity (nothing says which surface of
    /// the model it was meshed on), and [`Element::is_undeclared_facet`] tells them apart.
    /// None when some declared element already has a negative entity tag.
    pub fn undeclared_boundary_facets(&self) -> Result<Vec<Element>, MeshError> {
        self.validate()?;
        if self
            .cells
            .iter()
            .chain(&self.facets)
            .any(Element::is_undeclared_facet)
        {
            return Ok(Vec::new());
        }
        let declared: BTreeSet<Vec<u32>> = self
            .facets
            .iter()
            .map(|f| canonical_face(&f.vertices))
            .collect();
        let topology = Topology::new(self)?;
        let mut found = Vec::new();
        for (c, cell) in self.cells.iter().enumerate() {
            let local: Vec<(u32, Vec<usize>)> = if self.dim == 2 {
                topology
                    .cell_edges(c)
                    .iter()
                    .zip(cell.kind.edges())
                    .map(|(&id, e)| (id, e.to_vec()))
                    .collect()
            } else {
                topology
                    .cell_faces(c)
                    .iter()
                    .zip(cell.kind.faces())
                    .map(|(&id, f)| (id, f.to_vec()))
                    .collect()
            };
            for (id, corners) in local {
                let [first, second] = topology.facet_cells(id as usize);
                // Each facet once: from its first cell, on the boundary or where two
                // volumes (surfaces in 2D) of the model meet.
                let between = second != NO_CELL
                    && self.cells.get(second as usize).map(|e| e.entity) != Some(cell.entity);
                if first as usize != c || (second != NO_CELL && !between) {
                    continue;
                }
                let vertices: Vec<u32> = corners.iter().map(|&k| cell.vertices[k]).collect();
                if declared.contains(&canonical_face(&vertices)) {
                    continue;
                }
                let kind = if self.dim == 2 {
                    Shape::Line
                } else {
                    Shape::face_shape(vertices.len())
                };
                let entity = -1
                    - i32::try_from(found.len()).map_err(|_| MeshError::TooLarge {
                        what: "undeclared boundary facets",
                        count: found.len(),
                    })?;
                found.push(Element {
                    kind,
                    vertices,
                    entity,
                });
            }
        }
        Ok(found)
    }

    /// Appends `found` ([`Self::undeclared_boundary_facets`]) to the facets, with tag 0 in
    /// [`Self::facet_tags`] (a tag the file does not use).
    pub fn add_undeclared_facets(&mut self, found: Vec<Element>) {
        if !self.facet_tags.is_empty() {
            self.facet_tags.extend(std::iter::repeat_n(0, found.len()));
        }
        self.facets.extend(found);
    }

    /// The cells of a 2D mesh numbered clockwise in the xy-plane on entities all of whose
    /// cells are: a mesh generator numbers each surface's cells one way round, by its
    /// normal. A surface with cells both ways round is left to
    /// [`Self::check_orientation`], which refuses it (a fold, not a numbering).
    pub fn clockwise_cells(&self) -> Vec<usize> {
        if self.dim != 2 {
            return Vec::new();
        }
        let clockwise: Vec<bool> = self
            .cells
            .iter()
            .map(|cell| {
                let x: Vec<[f64; 3]> = cell
                    .vertices
                    .iter()
                    .map(|&v| self.vertices.get(v as usize).copied().unwrap_or([0.0; 3]))
                    .collect();
                corner_jacobians(cell.kind, &x).iter().all(|&j| j < 0.0)
            })
            .collect();
        let mixed: BTreeSet<i32> = self
            .cells
            .iter()
            .zip(&clockwise)
            .filter(|(_, &cw)| !cw)
            .map(|(c, _)| c.entity)
            .collect();
        (0..self.cells.len())
            .filter(|&c| clockwise[c] && !mixed.contains(&self.cells[c].entity))
            .collect()
    }

    /// Numbers `cells` the other way round: the first vertex kept, the others in reverse
    /// order (Gmsh's `mesh.reverse`), which turns [`Self::clockwise_cells`]
    /// counter-clockwise.
    pub fn reverse_numbering(&mut self, cells: &[usize]) {
        for &c in cells {
            if let Some(cell) = self.cells.get_mut(c) {
                cell.vertices[1..].reverse();
            }
        }
    }
}

#[cfg(test)]
#[path = "tests/undeclared.rs"]
mod tests;
