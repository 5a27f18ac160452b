//! Boundary conditions: prescribed displacements and sliding (u·n = 0) nodes, and the
//! nodes on the boundary of a mesh.

use std::collections::{BTreeMap, BTreeSet};

use hocurve_mesh::HighOrderMesh;

use crate::ElasticError;

/// Dirichlet-type conditions on mesh nodes.
///
/// A node in `prescribed` moves by the given displacement (unused components ignored in
/// 2D). A node in `sliding` keeps its normal displacement zero, u·n = 0, and moves freely
/// in its tangent plane (line in 2D); the normal need not be normalised. A node in
/// `along_line` moves only along the given direction, u ∥ t (where two sliding planes
/// meet). Precedence: prescribed, then along a line, then sliding. All other nodes are
/// free.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BoundaryConditions {
    /// Prescribed displacement per node.
    pub prescribed: BTreeMap<u32, [f64; 3]>,
    /// Wall normal per sliding node.
    pub sliding: BTreeMap<u32, [f64; 3]>,
    /// Direction of motion per node held to a line (3D; need not be normalised).
    pub along_line: BTreeMap<u32, [f64; 3]>,
}

impl BoundaryConditions {
    /// Checks node ids against a mesh of `count` nodes and that values are finite and
    /// normals non-zero.
    pub fn validate(&self, count: usize, dim: usize) -> Result<(), ElasticError> {
        let nodes = self
            .prescribed
            .iter()
            .chain(&self.sliding)
            .chain(&self.along_line);
        for (&node, value) in nodes {
            if node as usize >= count {
                return Err(ElasticError::NodeOutOfRange { node, count });
            }
            if value[..dim].iter().any(|v| !v.is_finite()) {
                return Err(ElasticError::InvalidBoundaryValue {
                    node,
                    what: "not finite",
                });
            }
        }
        for (&node, normal) in &self.sliding {
            if !self.prescribed.contains_key(&node)
                && !self.along_line.contains_key(&node)
                && normal[..dim].iter().all(|&v| v == 0.0)
            {
                return Err(ElasticError::InvalidBoundaryValue {
                    node,
                    what: "zero sliding normal",
                });
            }
        }
        for (&node, direction) in &self.along_line {
            if !self.prescribed.contains_key(&node) && direction[..dim].iter().all(|&v| v == 0.0) {
                return Err(ElasticError::InvalidBoundaryValue {
                    node,
                    what: "zero line direction",
                });
            }
        }
        Ok(())
    }
}

/// The nodes lying on boundary facets of the mesh (faces with one cell in 3D, edges in 2D),
/// sorted. Found from the topology, so it needs no facets declared in the file.
pub fn boundary_nodes(mesh: &HighOrderMesh) -> Result<Vec<u32>, ElasticError> {
    let nodes: BTreeSet<u32> = mesh
        .boundary_facet_nodes()?
        .into_iter()
        .flat_map(|(_, nodes)| nodes)
        .collect();
    Ok(nodes.into_iter().collect())
}
