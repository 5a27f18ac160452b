use super::*;
use crate::Shape;
use hocurve_nodes::ReferenceNodes;

/// A 2D hybrid (two triangles and a quadrilateral) or 3D hybrid (a hexahedron and a prism on
/// top of... beside it) straight mesh with boundary facets, at order `p`, then curved by a
/// smooth map so that every node matters.
fn curved_hybrid(dim: usize, p: usize) -> HighOrderMesh {
    let linear = if dim == 2 {
        LinearMesh {
            dim: 2,
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
                [2.0, 0.5, 0.0],
            ],
            cells: vec![
                Element {
                    kind: Shape::Quad,
                    vertices: vec![0, 1, 2, 3],
                    entity: 1,
                },
                Element {
                    kind: Shape::Tri,
                    vertices: vec![1, 4, 2],
                    entity: 1,
                },
            ],
            facets: vec![
                Element {
                    kind: Shape::Line,
                    vertices: vec![0, 1],
                    entity: 5,
                },
                Element {
                    kind: Shape::Line,
                    vertices: vec![4, 2],
                    entity: 6,
                },
            ],
            ..Default::default()
        }
    } else {
        LinearMesh {
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
            ],
            cells: vec![
                Element {
                    kind: Shape::Hex,
                    vertices: vec![0, 1, 2, 3, 4, 5, 6, 7],
                    entity: 1,
                },
                // Prism with bottom (1, 8, 2) and top (5, 9, 6): shares the face x = 1.
                Element {
                    kind: Shape::Prism,
                    vertices: vec![1, 8, 2, 5, 9, 6],
                    entity: 1,
                },
            ],
            facets: vec![
                Element {
                    kind: Shape::Quad,
                    vertices: vec![0, 3, 2, 1],
                    entity: 5,
                },
                Element {
                    kind: Shape::Tri,
                    vertices: vec![1, 2, 8],
                    entity: 6,
                },
            ],
            ..Default::default()
        }
    };
    let mut mesh = HighOrderMesh::from_linear(&linear, p, NodeFamily::Equispaced).unwrap();
    for x in &mut mesh.nodes {
        let (a, b, c) = (x[0], x[1], x[2]);
        *x = [
            a + 0.05 * (3.0 * b).sin(),
            b + 0.04 * (2.0 * a).cos() * a,
            if dim == 3 {
                c + 0.03 * (a * b).sin()
            } else {
                0.0
            },
        ];
    }
    mesh
}

/// Deterministic pseudo-random permutation of 0..n.
fn shuffle(n: usize, seed: u64) -> Vec<u32> {
    let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
    let mut v: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        v.swap(i, (state >> 33) as usize % (i + 1));
    }
    v
}

fn coords(mesh: &HighOrderMesh, e: &HighOrderElement) -> Vec<[u64; 3]> {
    e.nodes
        .iter()
        .map(|&n| mesh.nodes[n as usize].map(f64::to_bits))
        .collect()
}

#[test]
fn rebuilding_a_mesh_from_its_cells_gives_it_back_in_any_input_numbering() {
    for dim in [2, 3] {
        for p in 1..=4 {
            let mesh = curved_hybrid(dim, p);
            // Same numbering: the very same mesh.
            let same = HighOrderMesh::from_cells(
                dim,
                p,
                mesh.family,
                &mesh.nodes,
                &mesh.cells,
                &mesh.facets,
            )
            .unwrap();
            assert_eq!(
                same.nodes
                    .iter()
                    .map(|x| x.map(f64::to_bits))
                    .collect::<Vec<_>>(),
                mesh.nodes
                    .iter()
                    .map(|x| x.map(f64::to_bits))
                    .collect::<Vec<_>>()
            );
            assert_eq!(same.cells, mesh.cells);
            assert_eq!(same.facets, mesh.facets);
            assert_eq!(same.layout, mesh.layout);
            // Shuffled input nodes, plus an unused node: same per-element coordinates.
            let perm = shuffle(mesh.nodes.len(), p as u64);
            let mut nodes = vec![[0.0; 3]; mesh.nodes.len() + 1];
            nodes[mesh.nodes.len()] = [9.0, 9.0, 9.0];
            for (old, &new) in perm.iter().enumerate() {
                nodes[new as usize] = mesh.nodes[old];
            }
            let relabel = |list: &[HighOrderElement]| -> Vec<HighOrderElement> {
                list.iter()
                    .map(|e| HighOrderElement {
                        kind: e.kind,
                        nodes: e.nodes.iter().map(|&n| perm[n as usize]).collect(),
                        entity: e.entity,
                    })
                    .collect()
            };
            let (rebuilt, source) = HighOrderMesh::from_cells_with_source_nodes(
                dim,
                p,
                mesh.family,
                &nodes,
                &relabel(&mesh.cells),
                &relabel(&mesh.facets),
            )
            .unwrap();
            assert_eq!(rebuilt.nodes.len(), mesh.nodes.len());
            assert_eq!(rebuilt.nodes.len(), rebuilt.expected_node_count());
            for (a, b) in rebuilt.cells.iter().zip(&mesh.cells) {
                assert_eq!(coords(&rebuilt, a), coords(&mesh, b));
            }
            assert_eq!(rebuilt.facets.len(), 2);
            for (a, b) in rebuilt.facets.iter().zip(&mesh.facets) {
                assert_eq!(coords(&rebuilt, a), coords(&mesh, b));
                assert_eq!(a.entity, b.entity);
            }
            for (i, &s) in source.iter().enumerate() {
                assert_eq!(rebuilt.nodes[i], nodes[s as usize]);
            }
            // Vertices first: every cell's corners are nodes 0..V.
            for cell in &rebuilt.cells {
                for &v in &cell.nodes[..cell.kind.num_vertices()] {
                    assert!((v as usize) < rebuilt.layout.num_vertices);
                }
            }
        }
    }
}

fn two_triangles_p2() -> (Vec<[f64; 3]>, Vec<HighOrderElement>) {
    // Canonical order: vertices, then edges (0,1), (1,2), (2,0).
    let nodes = vec![
        [0.0, 0.0, 0.0], // 0
        [1.0, 0.0, 0.0], // 1
        [1.0, 1.0, 0.0], // 2
        [0.0, 1.0, 0.0], // 3
        [0.5, 0.0, 0.0], // 4: (0,1)
        [1.0, 0.5, 0.0], // 5: (1,2)
        [0.5, 0.5, 0.0], // 6: (2,0) shared diagonal
        [0.5, 1.0, 0.0], // 7: (2,3)
        [0.0, 0.5, 0.0], // 8: (3,0)
    ];
    let cells = vec![
        HighOrderElement {
            kind: Shape::Tri,
            nodes: vec![0, 1, 2, 4, 5, 6],
            entity: 1,
        },
        HighOrderElement {
            kind: Shape::Tri,
            nodes: vec![0, 2, 3, 6, 7, 8],
            entity: 1,
        },
    ];
    (nodes, cells)
}

#[test]
fn duplicated_shared_nodes_merge_only_when_they_coincide() {
    let (mut nodes, mut cells) = two_triangles_p2();
    HighOrderMesh::from_cells(2, 2, NodeFamily::Equispaced, &nodes, &cells, &[]).unwrap();
    // A copy of the diagonal's midpoint at the same place: merged.
    nodes.push([0.5, 0.5, 0.0]);
    cells[1].nodes[3] = 9;
    let mesh =
        HighOrderMesh::from_cells(2, 2, NodeFamily::Equispaced, &nodes, &cells, &[]).unwrap();
    assert_eq!(mesh.nodes.len(), 9);
    // Elsewhere: not conforming.
    nodes[9] = [0.5, 0.6, 0.0];
    let err =
        HighOrderMesh::from_cells(2, 2, NodeFamily::Equispaced, &nodes, &cells, &[]).unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::NonConformingNode {
                what: "cell",
                index: 1,
                local: 3,
                node: 9,
                other: 6
            }
        ),
        "{err}"
    );
}

#[test]
fn bad_elements_are_errors_and_stray_facets_are_dropped() {
    let (nodes, cells) = two_triangles_p2();
    let mut short = cells.clone();
    short[1].nodes.pop();
    let err =
        HighOrderMesh::from_cells(2, 2, NodeFamily::Equispaced, &nodes, &short, &[]).unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::WrongNodeCount {
                index: 1,
                expected: 6,
                found: 5,
                ..
            }
        ),
        "{err}"
    );
    let mut far = cells.clone();
    far[0].nodes[4] = 99;
    let err =
        HighOrderMesh::from_cells(2, 2, NodeFamily::Equispaced, &nodes, &far, &[]).unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::NodeOutOfRange {
                node: 99,
                count: 9,
                ..
            }
        ),
        "{err}"
    );
    let err =
        HighOrderMesh::from_cells(1, 2, NodeFamily::Equispaced, &nodes, &cells, &[]).unwrap_err();
    assert!(matches!(err, MeshError::UnsupportedDimension(1)));
    // A boundary edge is kept, an edge that is not a cell edge (1-3) is dropped.
    let line = |a, b, m| HighOrderElement {
        kind: Shape::Line,
        nodes: vec![a, b, m],
        entity: 7,
    };
    let facets = [line(1, 2, 5), line(1, 3, 6)];
    let mesh =
        HighOrderMesh::from_cells(2, 2, NodeFamily::Equispaced, &nodes, &cells, &facets).unwrap();
    assert_eq!(mesh.facets.len(), 1);
    assert_eq!(mesh.facets[0].entity, 7);
    let x: Vec<[f64; 3]> = mesh.facets[0]
        .nodes
        .iter()
        .map(|&n| mesh.nodes[n as usize])
        .collect();
    assert_eq!(x, vec![[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.5, 0.0]]);
}

#[test]
fn inverted_cells_are_accepted_for_assessment() {
    let (nodes, mut cells) = two_triangles_p2();
    // Second triangle clockwise: from_linear refuses, from_cells builds it.
    cells[1] = HighOrderElement {
        kind: Shape::Tri,
        nodes: vec![0, 3, 2, 8, 7, 6],
        entity: 1,
    };
    let mesh =
        HighOrderMesh::from_cells(2, 2, NodeFamily::Equispaced, &nodes, &cells, &[]).unwrap();
    let reference = ReferenceNodes::new(hocurve_nodes::Shape::Tri, 2, NodeFamily::Equispaced);
    assert_eq!(mesh.cells[1].nodes.len(), reference.len());
    assert_eq!(mesh.nodes[mesh.cells[1].nodes[1] as usize], [0.0, 1.0, 0.0]);
}
