//! Small curved meshes of every shape, for the readers' round-trip tests.

use hocurve_mesh::{Element, HighOrderMesh, LinearMesh, Shape};
use hocurve_nodes::NodeFamily;

fn element(kind: Shape, vertices: &[u32]) -> Element {
    Element {
        kind,
        vertices: vertices.to_vec(),
        entity: 1,
    }
}

fn facet(kind: Shape, vertices: &[u32], entity: i32) -> Element {
    Element {
        kind,
        vertices: vertices.to_vec(),
        entity,
    }
}

/// Two cells of `shape` sharing an edge (2D) or a face (3D), with a few boundary facets.
pub(crate) fn two_cells(shape: Shape) -> LinearMesh {
    let grid = |nx: u32, ny: u32, nz: u32| -> Vec<[f64; 3]> {
        let mut v = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    v.push([i as f64, j as f64, k as f64]);
                }
            }
        }
        v
    };
    use Shape::*;
    match shape {
        Shape::Tri => LinearMesh {
            dim: 2,
            vertices: grid(2, 2, 1),
            cells: vec![element(Tri, &[0, 1, 3]), element(Tri, &[0, 3, 2])],
            facets: vec![facet(Line, &[0, 1], 5), facet(Line, &[1, 3], 6)],
            ..Default::default()
        },
        Shape::Quad => LinearMesh {
            dim: 2,
            vertices: grid(3, 2, 1),
            cells: vec![element(Quad, &[0, 1, 4, 3]), element(Quad, &[1, 2, 5, 4])],
            facets: vec![facet(Line, &[0, 1], 5)],
            ..Default::default()
        },
        Shape::Tet => LinearMesh {
            dim: 3,
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 1.0, 1.0],
            ],
            cells: vec![element(Tet, &[0, 1, 2, 3]), element(Tet, &[1, 2, 3, 4])],
            facets: vec![facet(Tri, &[0, 2, 1], 5), facet(Tri, &[1, 4, 2], 6)],
            ..Default::default()
        },
        Shape::Hex => LinearMesh {
            dim: 3,
            vertices: grid(3, 2, 2),
            cells: vec![
                element(Hex, &[0, 1, 4, 3, 6, 7, 10, 9]),
                element(Hex, &[1, 2, 5, 4, 7, 8, 11, 10]),
            ],
            facets: vec![facet(Quad, &[0, 3, 4, 1], 5)],
            ..Default::default()
        },
        Shape::Prism => LinearMesh {
            dim: 3,
            vertices: grid(2, 2, 2),
            cells: vec![
                element(Prism, &[0, 1, 2, 4, 5, 6]),
                element(Prism, &[1, 3, 2, 5, 7, 6]),
            ],
            facets: vec![facet(Tri, &[0, 2, 1], 5), facet(Quad, &[0, 1, 5, 4], 6)],
            ..Default::default()
        },
        Shape::Line => unreachable!("lines are not cells"),
    }
}

/// A quadrilateral and a triangle (2D), or a hexahedron and a prism (3D).
pub(crate) fn hybrid(dim: usize) -> LinearMesh {
    use Shape::*;
    if dim == 2 {
        LinearMesh {
            dim: 2,
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
                [2.0, 0.5, 0.0],
            ],
            cells: vec![element(Quad, &[0, 1, 2, 3]), element(Tri, &[1, 4, 2])],
            facets: vec![facet(Line, &[4, 2], 5)],
            ..Default::default()
        }
    } else {
        let mut vertices = Vec::new();
        for z in [0.0, 1.0] {
            vertices.extend([[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]]);
        }
        vertices.extend([[2.0, 0.0, 0.0], [2.0, 0.0, 1.0]]);
        LinearMesh {
            dim: 3,
            vertices,
            cells: vec![
                element(Hex, &[0, 1, 2, 3, 4, 5, 6, 7]),
                element(Prism, &[1, 8, 2, 5, 9, 6]),
            ],
            facets: vec![facet(Tri, &[1, 2, 8], 5), facet(Quad, &[0, 3, 2, 1], 6)],
            ..Default::default()
        }
    }
}

/// The order-`p` equispaced mesh of `linear`, every node moved by a smooth map (so that
/// a node in the wrong place changes the geometry).
pub(crate) fn curved(linear: &LinearMesh, p: usize) -> HighOrderMesh {
    let mut mesh =
        HighOrderMesh::from_linear(linear, p, NodeFamily::Equispaced).expect("test mesh is valid");
    let dim = linear.dim;
    for x in &mut mesh.nodes {
        let (a, b, c) = (x[0], x[1], x[2]);
        *x = [
            a + 0.05 * (3.0 * b + 0.3).sin(),
            b + 0.04 * (2.0 * a).cos() * a + 0.01 * c,
            if dim == 3 {
                c + 0.03 * (a * b + 0.1).sin()
            } else {
                0.0
            },
        ];
    }
    mesh
}

/// Bit patterns of each cell's node coordinates, canonical order.
pub(crate) fn cell_bits(mesh: &HighOrderMesh) -> Vec<(Shape, Vec<[u64; 3]>)> {
    mesh.cells
        .iter()
        .map(|c| {
            (
                c.kind,
                c.nodes
                    .iter()
                    .map(|&n| mesh.nodes[n as usize].map(f64::to_bits))
                    .collect(),
            )
        })
        .collect()
}

/// Same for the facets.
pub(crate) fn facet_bits(mesh: &HighOrderMesh) -> Vec<(Shape, i32, Vec<[u64; 3]>)> {
    mesh.facets
        .iter()
        .map(|c| {
            (
                c.kind,
                c.entity,
                c.nodes
                    .iter()
                    .map(|&n| mesh.nodes[n as usize].map(f64::to_bits))
                    .collect(),
            )
        })
        .collect()
}

/// Every test mesh: each shape, and the two hybrids, with a name.
pub(crate) fn all_meshes() -> Vec<(String, LinearMesh)> {
    let mut out: Vec<(String, LinearMesh)> = [
        Shape::Tri,
        Shape::Quad,
        Shape::Tet,
        Shape::Hex,
        Shape::Prism,
    ]
    .into_iter()
    .map(|s| (s.name().to_string(), two_cells(s)))
    .collect();
    out.push(("hybrid 2D".into(), hybrid(2)));
    out.push(("hybrid 3D".into(), hybrid(3)));
    out
}
