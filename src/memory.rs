//! What a curving run will need, before it runs: the node count of the order-p mesh and an
//! estimate of the peak memory, so that an order the machine cannot hold is refused at once
//! rather than after minutes of work.

use hocurve_mesh::{LinearMesh, MeshError};
use rayon::slice::ParallelSliceMut;

#[cfg(doc)]
use hocurve_mesh::Topology;
use hocurve_nodes::Shape;

/// Bytes per unknown per node of an element, measured (release, 2 threads, peak resident
/// memory): 126 and 130 on 97 k and 279 k sphere tetrahedra at p = 3 (1.4 M and 3.9 M
/// unknowns, 20 nodes per element: 3.4 and 10.1 GB), 117 on 19 k boundary-layer tetrahedra
/// at p = 4 (630 k unknowns, 35 nodes: 2.6 GB), 90–93 on the torus and the IGES wing body
/// at p = 4; the stiffness rows grow with the nodes an unknown shares elements with, the
/// p-multigrid levels follow. With a margin of ~15 %.
pub const BYTES_PER_UNKNOWN_AND_ELEMENT_NODE: f64 = 150.0;

/// Bytes per unknown from order 2, where the stiffness and p-multigrid transfers are
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
    /// [`BYTES_PER_UNKNOWN_AND_ELEMENT_NODE`] at order 1, or from order 2 unknowns ×
    /// ([`MATRIX_FREE_BYTES_PER_UNKNOWN`] + nodes per element ×
    /// [`MATRIX_FREE_BYTES_PER_ELEMENT_NODE`]).
    pub peak_bytes: f64,
}

/// The distinct edges, triangular faces and quadrilateral faces of `linear`'s cells (faces
/// only in 3D): each entity as its sorted vertex ids packed in one integer, sorted and
/// deduplicated — the counts of [`Topology`] without its maps, several times faster.
pub fn count_entities(linear: &LinearMesh) -> Result<[u64; 3], MeshError> {
    let mut edges: Vec<u64> = Vec::new();
    let mut triangles: Vec<u128> = Vec::new();
    let mut quadrilaterals: Vec<u128> = Vec::new();
    linear.validate()?;
    for cell in &linear.cells {
        let v = &cell.vertices;
        for &[a, b] in cell.kind.edges() {
            let (a, b) = (v[a].min(v[b]), v[a].max(v[b]));
            edges.push(((a as u64) << 32) | b as u64);
        }
        if linear.dim == 3 {
            for face in cell.kind.faces() {
                let mut ids: Vec<u32> = face.iter().map(|&k| v[k]).collect();
                ids.sort_unstable();
                let key = ids.iter().fold(0u128, |key, &x| (key << 32) | x as u128);
                if ids.len() == 4 {
                    quadrilaterals.push(key);
                } else {
                    triangles.push(key);
                }
            }
        }
    }
    fn distinct<T: Ord + Send>(mut keys: Vec<T>) -> u64 {
        keys.par_sort_unstable();
        keys.dedup();
        keys.len() as u64
    }
    Ok([
        distinct(edges),
        distinct(triangles),
        distinct(quadrilaterals),
    ])
}

/// Counts the nodes of the order-`order` mesh of `linear` from its entities (without
/// building it) and estimates the peak memory of curving it.
pub fn estimate(linear: &LinearMesh, order: usize) -> Result<Estimate, MeshError> {
    let [edges, triangles, quadrilaterals] = count_entities(linear)?;
    let mut nodes = linear.vertices.len() as u64
        + edges * Shape::Line.num_interior_nodes(order) as u64
        + triangles * Shape::Tri.num_interior_nodes(order) as u64
        + quadrilaterals * Shape::Quad.num_interior_nodes(order) as u64;
    let mut largest = 0;
    for cell in &linear.cells {
        let shape = cell.kind;
        nodes += shape.num_interior_nodes(order) as u64;
        largest = largest.max(shape.num_nodes(order) as u64);
    }
    let unknowns = linear.dim as u64 * nodes;
    // Every shape is applied cell by cell from order 2 (hexahedra and prisms by their
    // per-point factors): measured 2.0 and 3.4 kB per unknown on the hybrid fixture at
    // p = 6 and 8 (343 and 729 nodes per hexahedron), within the formula's 2.2 and 4.1.
    let matrix_free = order >= 2;
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

    #[test]
    fn node_counts_equal_those_of_the_built_mesh_on_mixed_and_quadrilateral_meshes() {
        use hocurve_mesh::Shape;
        use hocurve_testmeshes::{unit_cube, unit_square, Fill, Kuhn};
        for (linear, order) in [
            (unit_cube(3, Fill::Tet(Kuhn::Paired), 0.1), 3),
            (unit_cube(2, Fill::HexPrism, 0.0), 4),
            (unit_square(4, Shape::Tri, 0.1), 5),
            (unit_square(3, Shape::Quad, 0.0), 2),
        ] {
            let built = HighOrderMesh::from_linear(&linear, order, NodeFamily::Fekete).unwrap();
            let e = estimate(&linear, order).unwrap();
            assert_eq!(e.nodes, built.nodes.len() as u64);
            assert_eq!(e.unknowns, linear.dim as u64 * e.nodes);
        }
    }

    #[test]
    fn a_cell_naming_a_missing_vertex_is_an_error() {
        use hocurve_testmeshes::{unit_cube, Fill, Kuhn};
        let mut linear = unit_cube(1, Fill::Tet(Kuhn::Paired), 0.0);
        linear.cells[0].vertices[2] = 99;
        assert!(estimate(&linear, 2).is_err());
    }
}
