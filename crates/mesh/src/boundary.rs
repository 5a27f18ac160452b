//! Which nodes of a high-order mesh lie on each boundary facet.

use std::collections::BTreeMap;

use hocurve_nodes::{NodeEntity, ReferenceElement};

use crate::{HighOrderMesh, MeshError, NO_CELL};

impl HighOrderMesh {
    /// The nodes of every boundary facet of the topology (faces with one cell in 3D, edges
    /// in 2D), as `(topology facet id, nodes)`, facets ascending. Read off the adjacent
    /// cell's reference node entities, so no facet needs to be declared in the file.
    pub fn boundary_facet_nodes(&self) -> Result<Vec<(usize, Vec<u32>)>, MeshError> {
        let topology = &self.topology;
        let mut references = BTreeMap::new();
        let mut out = Vec::new();
        for f in topology.boundary_facets() {
            let c = topology.facet_cells[f][0];
            if c == NO_CELL {
                continue;
            }
            let cell = &self.cells[c as usize];
            let shape = cell.kind;
            if let std::collections::btree_map::Entry::Vacant(slot) = references.entry(shape) {
                slot.insert(ReferenceElement::shared(shape, self.order, self.family)?);
            }
            let row = if self.dim == 2 {
                topology.cell_edges.row(c as usize)
            } else {
                topology.cell_faces.row(c as usize)
            };
            let Some(k) = row.iter().position(|&x| x as usize == f) else {
                continue;
            };
            let on_facet = |e: &NodeEntity| -> bool {
                if self.dim == 2 {
                    let [a, b] = shape.edges()[k];
                    match *e {
                        NodeEntity::Vertex(v) => v == a || v == b,
                        NodeEntity::Edge { edge, .. } => edge == k,
                        _ => false,
                    }
                } else {
                    let face = shape.faces()[k];
                    match *e {
                        NodeEntity::Vertex(v) => face.contains(&v),
                        NodeEntity::Edge { edge, .. } => {
                            let [a, b] = shape.edges()[edge];
                            face.contains(&a) && face.contains(&b)
                        }
                        NodeEntity::Face { face: g, .. } => g == k,
                        NodeEntity::Interior(_) => false,
                    }
                }
            };
            let nodes = references[&shape]
                .nodes()
                .entities()
                .iter()
                .zip(&cell.nodes)
                .filter(|(e, _)| on_facet(e))
                .map(|(_, &n)| n)
                .collect();
            out.push((f, nodes));
        }
        Ok(out)
    }
}
