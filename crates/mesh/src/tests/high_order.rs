use super::*;
use crate::Element;
use hocurve_nodes::ReferenceNodes;
use std::collections::HashSet;

/// Deterministic pseudo-random permutation of 0..n (a tiny LCG; no dependency needed).
fn permutation(n: usize, seed: u64) -> Vec<u32> {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut v: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let j = (state >> 33) as usize % (i + 1);
        v.swap(i, j);
    }
    v
}

/// Builds the mesh under `relabelings` renumberings of its vertices and checks, for every
/// p: the node count formula, that every local node sits where the cell's own straight
/// map puts it, and that no two global nodes coincide (no duplicated shared nodes).
/// Returns the face orientations seen (as permutations local → canonical).
fn check_sharing(
    dim: usize,
    vertices: &[[f64; 3]],
    cells: &[(Shape, Vec<u32>)],
    relabelings: u64,
) -> HashSet<Vec<usize>> {
    let mut orientations = HashSet::new();
    for seed in 0..relabelings {
        let perm = permutation(vertices.len(), seed);
        let mut relabeled = vec![[0.0; 3]; vertices.len()];
        for (old, &new) in perm.iter().enumerate() {
            relabeled[new as usize] = vertices[old];
        }
        let mesh = LinearMesh {
            dim,
            vertices: relabeled,
            cells: cells
                .iter()
                .map(|(kind, v)| Element {
                    kind: *kind,
                    vertices: v.iter().map(|&i| perm[i as usize]).collect(),
                    entity: 1,
                })
                .collect(),
            ..Default::default()
        };
        for p in 1..=6 {
            let ho = HighOrderMesh::from_linear(&mesh, p, NodeFamily::Equispaced).unwrap();
            assert_eq!(ho.nodes.len(), ho.expected_node_count());
            for (cell, lin) in ho.cells.iter().zip(&mesh.cells) {
                let shape = cell.kind;
                let reference = ReferenceNodes::new(shape, p, NodeFamily::Equispaced);
                let corners: Vec<[f64; 3]> = lin
                    .vertices
                    .iter()
                    .map(|&v| mesh.vertices[v as usize])
                    .collect();
                for (xi, &id) in reference.points().iter().zip(&cell.nodes) {
                    let want = straight_map(shape, &corners, *xi);
                    let got = ho.nodes[id as usize];
                    for d in 0..3 {
                        assert!((want[d] - got[d]).abs() < 1e-13, "{shape:?} p={p}");
                    }
                }
            }
            // No two nodes at the same place: shared nodes were not duplicated.
            let mut seen = HashSet::new();
            for x in &ho.nodes {
                let key = x.map(|c| (c * 1e9).round() as i64);
                assert!(seen.insert(key), "duplicate node at {x:?} (p={p})");
            }
            if p == 2 {
                for (c, lin) in mesh.cells.iter().enumerate() {
                    let shape = lin.kind;
                    for (f, face) in shape.faces().iter().enumerate() {
                        let g = ho.topology.cell_faces.row(c)[f] as usize;
                        if ho.topology.facet_cells[g][1] == crate::NO_CELL {
                            continue;
                        }
                        let canon = ho.topology.faces.row(g);
                        let sigma = face
                            .iter()
                            .map(|&i| canon.iter().position(|&v| v == lin.vertices[i]).unwrap())
                            .collect();
                        orientations.insert(sigma);
                    }
                }
            }
        }
    }
    orientations
}

#[test]
fn two_tets_share_face_nodes_in_all_six_orientations() {
    let vertices = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.2, 0.3, 1.0],
        [0.4, 0.3, -0.9],
    ];
    let cells = vec![
        (Shape::Tet, vec![0, 1, 2, 3]),
        (Shape::Tet, vec![0, 2, 1, 4]),
    ];
    let seen = check_sharing(3, &vertices, &cells, 60);
    assert_eq!(seen.len(), 6, "orientations seen: {seen:?}");
}

#[test]
fn two_hexes_share_quad_face_nodes_in_all_eight_orientations() {
    let mut vertices = Vec::new();
    for z in 0..2 {
        for y in 0..2 {
            for x in 0..3 {
                // Slightly distorted so the bilinear faces are not parallelograms.
                let w = 0.1 * (x * y + z) as f64;
                vertices.push([x as f64 + w, y as f64, z as f64 + 0.05 * x as f64]);
            }
        }
    }
    let id = |x: u32, y: u32, z: u32| x + 3 * y + 6 * z;
    let hex = |x0: u32| {
        vec![
            id(x0, 0, 0),
            id(x0 + 1, 0, 0),
            id(x0 + 1, 1, 0),
            id(x0, 1, 0),
            id(x0, 0, 1),
            id(x0 + 1, 0, 1),
            id(x0 + 1, 1, 1),
            id(x0, 1, 1),
        ]
    };
    let cells = vec![(Shape::Hex, hex(0)), (Shape::Hex, hex(1))];
    let seen = check_sharing(3, &vertices, &cells, 80);
    assert_eq!(seen.len(), 8, "orientations seen: {seen:?}");
}

#[test]
fn prisms_share_triangle_and_quad_faces_and_hex_prism_hybrids_agree() {
    // Two prisms stacked (shared triangle), a third beside (shared quad), a hex beside.
    let vertices = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.1],
        [0.0, 1.0, 1.0],
        [0.0, 0.0, 2.0],
        [1.0, 0.0, 2.0],
        [0.0, 1.0, 2.1],
        [1.0, 1.0, 0.0],
        [1.0, 1.0, 1.0],
        [0.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [0.0, -1.0, 1.0],
        [1.0, -1.0, 1.0],
    ];
    let cells = vec![
        (Shape::Prism, vec![0, 1, 2, 3, 4, 5]),
        (Shape::Prism, vec![3, 4, 5, 6, 7, 8]),
        (Shape::Prism, vec![1, 9, 2, 4, 10, 5]),
        (Shape::Hex, vec![11, 12, 1, 0, 13, 14, 4, 3]),
    ];
    let seen = check_sharing(3, &vertices, &cells, 40);
    assert!(seen.iter().any(|s| s.len() == 3) && seen.iter().any(|s| s.len() == 4));
}

#[test]
fn triangles_and_quads_share_edge_nodes_in_2d() {
    let vertices = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.5, 0.0],
    ];
    let cells = vec![(Shape::Quad, vec![0, 1, 2, 3]), (Shape::Tri, vec![1, 4, 2])];
    check_sharing(2, &vertices, &cells, 20);
}

#[test]
fn resampling_between_families_keeps_straight_cells_straight() {
    // A distorted hex and a tet: the straight map is reproduced by every family, so
    // resampling to another family equals building that family directly.
    let mesh = LinearMesh {
        dim: 3,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.2, 0.0, 0.1],
            [1.0, 1.1, 0.0],
            [0.0, 1.0, 0.2],
            [0.1, 0.0, 1.0],
            [1.0, 0.2, 1.1],
            [1.1, 1.0, 1.0],
            [0.0, 1.0, 0.9],
            [0.5, 0.5, -1.0],
        ],
        cells: vec![
            Element {
                kind: Shape::Hex,
                vertices: (0..8).collect(),
                entity: 1,
            },
            Element {
                kind: Shape::Tet,
                vertices: vec![0, 2, 1, 8],
                entity: 1,
            },
        ],
        ..Default::default()
    };
    for p in 1..=5 {
        for from in NodeFamily::ALL {
            let a = HighOrderMesh::from_linear(&mesh, p, from).unwrap();
            for to in NodeFamily::ALL {
                let b = a.resampled(to).unwrap();
                let direct = HighOrderMesh::from_linear(&mesh, p, to).unwrap();
                assert_eq!(b.family, to);
                for (x, y) in b.nodes.iter().zip(&direct.nodes) {
                    assert!(
                        (0..3).all(|d| (x[d] - y[d]).abs() < 1e-12),
                        "{from}->{to} p={p}"
                    );
                }
            }
        }
    }
}

#[test]
fn facets_get_the_nodes_of_their_face() {
    let mesh = LinearMesh {
        dim: 3,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        cells: vec![Element {
            kind: Shape::Tet,
            vertices: vec![0, 1, 2, 3],
            entity: 1,
        }],
        facets: vec![Element {
            kind: Shape::Tri,
            vertices: vec![3, 1, 2],
            entity: 7,
        }],
        ..Default::default()
    };
    for p in 1..=5 {
        let ho = HighOrderMesh::from_linear(&mesh, p, NodeFamily::Equispaced).unwrap();
        let facet = &ho.facets[0];
        let reference = ReferenceNodes::new(Shape::Tri, p, NodeFamily::Equispaced);
        let corners = [mesh.vertices[3], mesh.vertices[1], mesh.vertices[2]];
        for (xi, &id) in reference.points().iter().zip(&facet.nodes) {
            let want = straight_map(Shape::Tri, &corners, *xi);
            let got = ho.nodes[id as usize];
            assert!((0..3).all(|d| (want[d] - got[d]).abs() < 1e-14));
        }
    }
    let mut bad = mesh.clone();
    bad.facets[0].vertices = vec![0, 1, 2];
    bad.vertices.push([5.0, 5.0, 5.0]);
    bad.facets[0].vertices[2] = 4;
    let err = HighOrderMesh::from_linear(&bad, 2, NodeFamily::Equispaced).unwrap_err();
    assert!(
        matches!(err, MeshError::FacetNotInMesh { index: 0, .. }),
        "{err}"
    );
}

#[test]
fn bad_vertex_ids_are_clear_errors() {
    let mesh = LinearMesh {
        dim: 3,
        vertices: vec![[0.0; 3]; 5],
        cells: vec![Element {
            kind: Shape::Tet,
            vertices: vec![0, 1, 2, 9],
            entity: 1,
        }],
        ..Default::default()
    };
    let err = HighOrderMesh::from_linear(&mesh, 2, NodeFamily::Equispaced).unwrap_err();
    assert!(err.to_string().contains("vertex 9"), "{err}");
}

#[test]
fn straight_of_order_rebuilds_the_mesh_of_another_order_with_the_same_entities() {
    // A hex, a prism and a tet sharing faces, with a declared boundary facet.
    let mesh = LinearMesh {
        dim: 3,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
            [2.0, 0.0, 0.0],
            [2.0, 0.0, 1.0],
            [0.5, 0.5, 2.0],
        ],
        cells: vec![
            Element {
                kind: Shape::Hex,
                vertices: (0..8).collect(),
                entity: 1,
            },
            Element {
                kind: Shape::Prism,
                vertices: vec![1, 8, 2, 5, 9, 6],
                entity: 1,
            },
            Element {
                kind: Shape::Tet,
                vertices: vec![4, 5, 6, 10],
                entity: 1,
            },
        ],
        facets: vec![Element {
            kind: Shape::Quad,
            vertices: vec![0, 1, 5, 4],
            entity: 7,
        }],
        ..Default::default()
    };
    for family in NodeFamily::ALL {
        let fine = HighOrderMesh::from_linear(&mesh, 5, family).unwrap();
        for q in 1..=6 {
            let direct = HighOrderMesh::from_linear(&mesh, q, family).unwrap();
            let rebuilt = fine.straight_of_order(q).unwrap();
            assert_eq!(rebuilt.order, q);
            assert_eq!(rebuilt.family, family);
            assert_eq!(rebuilt.nodes, direct.nodes, "{family} q = {q}");
            assert_eq!(rebuilt.cells, direct.cells);
            assert_eq!(rebuilt.facets, direct.facets);
            assert_eq!(rebuilt.layout, direct.layout);
            // The positions alone, on moved vertices, as the whole rebuilt mesh has them.
            let moved: Vec<[f64; 3]> = mesh
                .vertices
                .iter()
                .map(|x| [x[0] + 0.1 * x[2], x[1] - 0.05 * x[0], x[2]])
                .collect();
            assert_eq!(
                fine.straight_positions_on(&moved, q, family).unwrap(),
                fine.straight_on(&moved, q, family).unwrap().nodes
            );
        }
        assert!(matches!(
            fine.straight_positions_on(&mesh.vertices[1..], 2, family),
            Err(MeshError::VertexCount { .. })
        ));
    }
}

#[test]
fn the_shortest_edge_is_measured_between_vertices() {
    // A right triangle with legs 3 and 0.5 (hypotenuse √9.25): the shortest edge is 0.5 at
    // any order (edge nodes do not split it).
    let linear = LinearMesh {
        dim: 2,
        vertices: vec![[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 0.5, 0.0]],
        cells: vec![Element {
            kind: Shape::Tri,
            vertices: vec![0, 1, 2],
            entity: 1,
        }],
        ..Default::default()
    };
    for p in 1..=4 {
        let mesh =
            HighOrderMesh::from_linear(&linear, p, hocurve_nodes::NodeFamily::Fekete).unwrap();
        assert_eq!(mesh.shortest_edge(), Some(0.5));
    }
}
