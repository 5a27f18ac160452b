//! What a curving run will need, before it runs: the node count of the order-p mesh and an
//! estimate of the peak memory, so that an order the machine cannot hold is refused at once
//! rather than after minutes of work.

use hocurve_mesh::{LinearMesh, MeshError, Topology};
use hocurve_nodes::Shape;

/// Bytes per unknown per node of an element, measured (release, 2 threads, peak resident
/// memory): 126 and 130 on 97 k and 279 k sphere tetrahedra at p = 3 (1.4 M and 3.9 M
/// unknowns, 20 nodes per element: 3.4 and 10.1 GB), 117 on 19 k boundary-layer tetrahedra
/// at p = 4 (630 k unknowns, 35 nodes: 2.6 GB), 90–93 on the torus and the IGES wing body
/// at p = 4; the stiffness rows grow with the nodes an unknown shares elements with, the
/// p-multigrid levels follow. With a margin of ~15 %.
pub const BYTES_PER_UNKNOWN_AND_ELEMENT_NODE: f64 = 150.0;

/// Bytes per unknown on meshes of simplices, whose stiffness and p-multigrid transfers are
/// applied cell by cell and never stored (`hocurve_elastic`'s matrix-free operator): this
/// plus [`MATRIX_FREE_BYTES_PER_ELEMENT_NODE`] per node of an element. Measured: 465, 450 and
/// 447 on 97 k, 279 k and 948 k sphere tetrahedra at p = 3 (1.2, 3.6 and 12.5 M unknowns:
/// 0.58, 1.7 and 5.6 GB), 460 on the 5.7 k-tet bundled sphere at p = 4. With a margin of
/// ~20 % at p = 3.
pub const MATRIX_FREE_BYTES_PER_UNKNOWN: f64 = 450.0;
/// See [`MATRIX_FREE_BYTES_PER_UNKNOWN`]: the order-p cells' node lists grow with p.
pub const MATRIX_FREE_BYTES_PER_ELEMENT_NODE: f64 = 5.0;

/// The size of the order-`order` mesh of `linear` and its estimated peak memory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Nodes of the order-p mesh: V + E(p−1) + faces' and cells' interior nodes.
    pub nodes: u64,
    /// Unknowns of the elastic system (dim × nodes, before the boundary is condensed out).
    pub unknowns: u64,
    /// Estimated peak memory in bytes: unknowns × (largest nodes per element) ×
    /// [`BYTES_PER_UNKNOWN_AND_ELEMENT_NODE`], or on simplices of order ≥ 2 unknowns ×
    /// ([`MATRIX_FREE_BYTES_PER_UNKNOWN`] + nodes per element ×
    /// [`MATRIX_FREE_BYTES_PER_ELEMENT_NODE`]).
    pub peak_bytes: f64,
}

/// Counts the nodes of the order-`order` mesh of `linear` from its topology (without
/// building it) and estimates the peak memory of curving it.
pub fn estimate(linear: &LinearMesh, order: usize) -> Result<Estimate, MeshError> {
    let topology = Topology::new(linear)?;
    let mut nodes = linear.vertices.len() as u64
        + topology.edges().len() as u64 * Shape::Line.num_interior_nodes(order) as u64;
    for face in topology.faces() {
        let shape = if face.len() == 4 {
            Shape::Quad
        } else {
            Shape::Tri
        };
        nodes += shape.num_interior_nodes(order) as u64;
    }
    let mut largest = 0;
    for cell in &linear.cells {
        let shape = cell.kind;
        nodes += shape.num_interior_nodes(order) as u64;
        largest = largest.max(shape.num_nodes(order) as u64);
    }
    let unknowns = linear.dim as u64 * nodes;
    let simplex = if linear.dim == 2 {
        Shape::Tri
    } else {
        Shape::Tet
    };
    let matrix_free = order >= 2 && linear.cells.iter().all(|c| c.kind == simplex);
    let per_unknown = if matrix_free {
        MATRIX_FREE_BYTES_PER_UNKNOWN + largest as f64 * MATRIX_FREE_BYTES_PER_ELEMENT_NODE
    } else {
        largest as f64 * BYTES_PER_UNKNOWN_AND_ELEMENT_NODE
    };
    Ok(Estimate {
        nodes,
        unknowns,
        peak_bytes: unknowns as f64 * per_unknown,
    })
}

/// This machine's memory in bytes (`MemTotal` of /proc/meminfo), if it can be read.
pub fn machine_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// This process's peak resident memory in bytes (`VmHWM` of /proc/self/status), if it can
/// be read.
pub fn peak_resident_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_mesh::HighOrderMesh;
    use hocurve_nodes::NodeFamily;

    #[test]
    fn node_counts_equal_those_of_the_built_mesh() {
        let linear = crate::demo::Demo::Sphere
            .mesh()
            .expect("the bundled sphere");
        for p in 1..=5 {
            let built = HighOrderMesh::from_linear(&linear, p, NodeFamily::Equispaced)
                .expect("order-p mesh");
            let e = estimate(&linear, p).expect("estimate");
            assert_eq!(e.nodes, built.nodes.len() as u64, "p = {p}");
            assert_eq!(e.unknowns, 3 * e.nodes);
        }
        let naca = crate::demo::Demo::Naca0012
            .mesh()
            .expect("the bundled airfoil");
        let built = HighOrderMesh::from_linear(&naca, 5, NodeFamily::Equispaced).unwrap();
        // The paper's count for its own mesh is V + E(p−1) + F(p−1)(p−2)/2; ours too.
        assert_eq!(estimate(&naca, 5).unwrap().nodes, built.nodes.len() as u64);
    }
}
