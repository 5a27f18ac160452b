use super::*;
use hocurve_mesh::{Element, ElementType, LinearMesh, PhysicalGroup};
use hocurve_nodes::NodeFamily;

fn square() -> LinearMesh {
    let mut mesh = LinearMesh {
        dim: 2,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.7, 0.1, 0.0],
        ],
        cells: vec![
            Element {
                kind: ElementType::Tri,
                vertices: vec![0, 1, 4],
                entity: 1,
            },
            Element {
                kind: ElementType::Tri,
                vertices: vec![1, 2, 4],
                entity: 1,
            },
            Element {
                kind: ElementType::Quad,
                vertices: vec![0, 4, 2, 3],
                entity: 2,
            },
        ],
        facets: vec![
            Element {
                kind: ElementType::Line,
                vertices: vec![0, 1],
                entity: 5,
            },
            Element {
                kind: ElementType::Line,
                vertices: vec![2, 3],
                entity: 6,
            },
        ],
        physical_groups: vec![
            PhysicalGroup {
                dim: 1,
                tag: 10,
                name: "bottom".into(),
            },
            PhysicalGroup {
                dim: 2,
                tag: 1,
                name: "domain".into(),
            },
        ],
        ..Default::default()
    };
    mesh.entity_physicals.insert((1, 5), vec![10]);
    mesh.entity_physicals.insert((2, 1), vec![1]);
    mesh.entity_physicals.insert((2, 2), vec![1]);
    mesh
}

#[test]
fn linear_mesh_is_written_as_expected() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.msh");
    let ho = HighOrderMesh::from_linear(&square(), 1, NodeFamily::Equispaced).unwrap();
    write_msh(&path, &ho).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let expected = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
1 10 \"bottom\"
2 1 \"domain\"
$EndPhysicalNames
$Entities
0 2 2 0
5 0.0 0.0 0.0 1.0 0.0 0.0 1 10 0
6 0.0 1.0 0.0 1.0 1.0 0.0 0 0
1 0.0 0.0 0.0 1.0 1.0 0.0 1 1 0
2 0.0 0.0 0.0 1.0 1.0 0.0 1 1 0
$EndEntities
$Nodes
3 5 1 5
1 5 0 2
1
2
0.0 0.0 0.0
1.0 0.0 0.0
1 6 0 2
3
4
1.0 1.0 0.0
0.0 1.0 0.0
2 1 0 1
5
0.7 0.1 0.0
$EndNodes
$Elements
4 5 1 5
1 5 1 1
1 1 2
1 6 1 1
2 3 4
2 1 2 2
3 1 2 5
4 2 3 5
2 2 3 1
5 1 5 3 4
$EndElements
";
    assert_eq!(text, expected);
}

#[test]
fn orders_without_a_gmsh_type_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.msh");
    let ho = HighOrderMesh::from_linear(&square(), 11, NodeFamily::Equispaced).unwrap();
    let err = write_msh(&path, &ho).unwrap_err().to_string();
    assert!(err.contains("Gmsh has no order-11"), "{err}");
    assert!(!path.exists());
}

#[test]
fn high_order_elements_use_gmsh_types_and_order() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.msh");
    let ho = HighOrderMesh::from_linear(&square(), 3, NodeFamily::Equispaced).unwrap();
    write_msh(&path, &ho).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    // Line 4 (26) facets, triangle 10 (21) and quadrilateral 16 (36) cells.
    assert!(text.contains("\n1 5 26 1\n"), "{text}");
    assert!(text.contains("\n2 1 21 2\n"), "{text}");
    assert!(text.contains("\n2 2 36 1\n"), "{text}");
    // Every element's node list, mapped back through the permutation, is the cell's.
    let perm = gmsh_permutation(Shape::Tri, 3);
    let first = &ho.cells[0];
    let line: Vec<String> = std::iter::once("3".to_string())
        .chain(perm.iter().map(|&k| (first.nodes[k] + 1).to_string()))
        .collect();
    assert!(text.contains(&format!("\n{}\n", line.join(" "))), "{text}");
}
