//! A high-order mesh from given nodes and complete order-p elements (as read from a file).
//!
//! The mesh is rebuilt in the node numbering of [`HighOrderMesh::from_linear`]: its corner
//! vertices first (ascending input id), then the interior nodes of each edge, each face
//! (3D) and each cell ([`crate::NodeLayout`]), with the [`crate::Topology`] of the corner
//! vertices. So a mesh read from a file has the same structure as one hocurve built, and
//! every consumer of the layout (boundary nodes, elasticity, writers) works on it.

use std::collections::HashSet;

use hocurve_nodes::NodeFamily;

use crate::topology::face_key;
use crate::{Element, HighOrderElement, HighOrderMesh, LinearMesh, MeshError, Topology};

impl HighOrderMesh {
    /// Builds the order-`order` mesh of dimension `dim` (2 or 3) whose elements' `nodes` are
    /// ids into `nodes`, listed in hocurve's canonical local order of their shape for node
    /// family `family` (see [`hocurve_nodes::ReferenceNodes`]; files hold
    /// [`NodeFamily::Equispaced`] nodes).
    ///
    /// Numbering assumptions and what is checked:
    /// - every cell has the dimension `dim` and the node count of the complete element of its
    ///   shape at `order`; node ids are in range; the first nodes of an element (canonical
    ///   order) are its corner vertices, which define the topology;
    /// - neighbouring cells share their edge and face nodes: where two cells (or a facet and
    ///   a cell) have different input nodes at the same place of a shared edge or face, the
    ///   nodes must have identical coordinates (duplicated nodes are merged), else
    ///   [`MeshError::NonConformingNode`];
    /// - `facets` (dimension `dim − 1`) whose corners are not an edge (2D) or face (3D) of
    ///   the cells are dropped, the others are kept in order, with their nodes checked
    ///   against the cells';
    /// - nodes no cell uses are dropped;
    /// - cells are not checked for inversion (a tangled mesh can be read and assessed).
    ///
    /// The result is renumbered (see the module documentation); physical groups are left
    /// empty for the caller to fill. [`HighOrderMesh::from_cells_with_source_nodes`] also
    /// returns which input node each node came from.
    pub fn from_cells(
        dim: usize,
        order: usize,
        family: NodeFamily,
        nodes: &[[f64; 3]],
        cells: &[HighOrderElement],
        facets: &[HighOrderElement],
    ) -> Result<Self, MeshError> {
        Self::from_cells_with_source_nodes(dim, order, family, nodes, cells, facets)
            .map(|(mesh, _)| mesh)
    }

    /// [`HighOrderMesh::from_cells`], also returning for each node of the mesh the id of the
    /// input node it was taken from (to carry nodal data over).
    pub fn from_cells_with_source_nodes(
        dim: usize,
        order: usize,
        family: NodeFamily,
        nodes: &[[f64; 3]],
        cells: &[HighOrderElement],
        facets: &[HighOrderElement],
    ) -> Result<(Self, Vec<u32>), MeshError> {
        if dim != 2 && dim != 3 {
            return Err(MeshError::UnsupportedDimension(dim));
        }
        if cells.is_empty() {
            return Err(MeshError::NoCells { dim });
        }
        family.check_order(order)?;
        check_elements("cell", cells, dim, order, nodes.len())?;
        check_elements("facet", facets, dim - 1, order, nodes.len())?;

        // Corner vertices, numbered by ascending input id.
        let mut vertex_of = vec![u32::MAX; nodes.len()];
        for cell in cells {
            for &v in &cell.nodes[..cell.kind.num_vertices()] {
                vertex_of[v as usize] = 0;
            }
        }
        let mut vertices = Vec::new();
        for (i, slot) in vertex_of.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = vertices.len() as u32;
                vertices.push(nodes[i]);
            }
        }
        let corners = |e: &HighOrderElement| -> Vec<u32> {
            e.nodes[..e.kind.num_vertices()]
                .iter()
                .map(|&v| vertex_of[v as usize])
                .collect()
        };
        let mut linear = LinearMesh {
            dim,
            vertices,
            cells: cells
                .iter()
                .map(|c| Element {
                    kind: c.kind,
                    vertices: corners(c),
                    entity: c.entity,
                })
                .collect(),
            ..Default::default()
        };
        linear.validate()?;

        // Facets that are edges (2D) or faces (3D) of the cells.
        let topology = Topology::new(&linear)?;
        let known: HashSet<[u32; 4]> = if dim == 2 {
            topology
                .edges
                .iter()
                .map(|&[a, b]| face_key(&[a, b]))
                .collect()
        } else {
            topology.faces.rows().map(face_key).collect()
        };
        let mut kept = Vec::new();
        for facet in facets {
            let v = &facet.nodes[..facet.kind.num_vertices()];
            if v.iter().any(|&i| vertex_of[i as usize] == u32::MAX) {
                continue;
            }
            let c = corners(facet);
            let mut distinct = c.clone();
            distinct.sort_unstable();
            distinct.dedup();
            if distinct.len() == c.len() && known.contains(&face_key(&c)) {
                linear.facets.push(Element {
                    kind: facet.kind,
                    vertices: c,
                    entity: facet.entity,
                });
                kept.push(facet);
            }
        }

        // The from_linear layout, then the input coordinates put in place.
        let mut mesh = Self::straight_sided(&linear, order, family)?;
        let mut source = vec![u32::MAX; mesh.nodes.len()];
        let mut place = |what: &'static str,
                         index: usize,
                         ours: &HighOrderElement,
                         given: &HighOrderElement|
         -> Result<(), MeshError> {
            for (local, (&id, &node)) in ours.nodes.iter().zip(&given.nodes).enumerate() {
                let slot = &mut source[id as usize];
                if *slot == u32::MAX {
                    *slot = node;
                    mesh.nodes[id as usize] = nodes[node as usize];
                } else if *slot != node
                    && nodes[*slot as usize].map(f64::to_bits)
                        != nodes[node as usize].map(f64::to_bits)
                {
                    return Err(MeshError::NonConformingNode {
                        what,
                        index,
                        local,
                        node: node as usize,
                        other: *slot as usize,
                    });
                }
            }
            Ok(())
        };
        let ours = std::mem::take(&mut mesh.cells);
        for (c, (cell, given)) in ours.iter().zip(cells).enumerate() {
            place("cell", c, cell, given)?;
        }
        let our_facets = std::mem::take(&mut mesh.facets);
        for (k, (facet, given)) in our_facets.iter().zip(&kept).enumerate() {
            place("facet", k, facet, given)?;
        }
        mesh.cells = ours;
        mesh.facets = our_facets;
        Ok((mesh, source))
    }
}

/// Shape, dimension, node count and node range of every element of a list.
fn check_elements(
    what: &'static str,
    elements: &[HighOrderElement],
    dim: usize,
    order: usize,
    count: usize,
) -> Result<(), MeshError> {
    for (index, e) in elements.iter().enumerate() {
        let shape = e.kind;
        if shape.dim() != dim {
            // Elements built in memory have no file tags: their 1-based position.
            return Err(MeshError::WrongDimension {
                what,
                index,
                tag: index as u64 + 1,
                kind: e.kind,
                expected: dim,
            });
        }
        let expected = shape.num_nodes(order);
        if e.nodes.len() != expected {
            return Err(MeshError::WrongNodeCount {
                what,
                index,
                kind: e.kind,
                order,
                expected,
                found: e.nodes.len(),
            });
        }
        if let Some(&node) = e.nodes.iter().find(|&&n| n as usize >= count) {
            return Err(MeshError::NodeOutOfRange {
                what,
                index,
                node: node as usize,
                count,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
#[path = "tests/from_cells.rs"]
mod tests;
