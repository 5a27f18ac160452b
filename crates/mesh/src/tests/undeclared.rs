use super::*;

fn element(kind: Shape, vertices: &[u32], entity: i32) -> Element {
    Element {
        kind,
        vertices: vertices.to_vec(),
        entity,
    }
}

/// Two tetrahedra on the face 1 2 3, with the face 0 1 2 declared (in another order).
fn two_tets() -> LinearMesh {
    LinearMesh {
        dim: 3,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ],
        cells: vec![
            element(Shape::Tet, &[0, 1, 2, 3], 1),
            element(Shape::Tet, &[1, 2, 3, 4], 1),
        ],
        facets: vec![element(Shape::Tri, &[2, 0, 1], 7)],
        facet_tags: vec![12],
        ..Default::default()
    }
}

#[test]
fn the_faces_of_one_cell_that_the_file_leaves_out_are_found() {
    let mut mesh = two_tets();
    let found = mesh.undeclared_boundary_facets().unwrap();
    // 8 cell faces, 1 shared by both (not boundary), 1 declared: 5 left.
    assert_eq!(found.len(), 5);
    let keys: BTreeSet<Vec<u32>> = found.iter().map(|f| canonical_face(&f.vertices)).collect();
    assert_eq!(keys.len(), 5);
    assert!(!keys.contains(&canonical_face(&[0, 1, 2])));
    assert!(!keys.contains(&canonical_face(&[1, 2, 3])));
    for (k, f) in found.iter().enumerate() {
        assert_eq!(f.kind, Shape::Tri);
        assert_eq!(f.entity, -1 - k as i32);
        assert!(f.is_undeclared_facet());
    }
    assert!(!mesh.facets[0].is_undeclared_facet());
    mesh.add_undeclared_facets(found);
    assert_eq!(mesh.facets.len(), 6);
    assert_eq!(mesh.facet_tags, [12, 0, 0, 0, 0, 0]);
    // Complete now: nothing more to find, and the high-order mesh takes them all.
    assert!(mesh.undeclared_boundary_facets().unwrap().is_empty());
    let mut high =
        crate::HighOrderMesh::from_linear(&mesh, 2, hocurve_nodes::NodeFamily::Equispaced).unwrap();
    assert_eq!(high.facets.len(), 6);
    assert_eq!(high.drop_undeclared_facets(), 5);
    assert_eq!(high.facets.len(), 1);
    assert_eq!(high.facet_ids.len(), 1);
    assert_eq!(high.facets[0].entity, 7);
}

/// Two volumes of the model (two materials) meeting at the face 1 2 3: the file leaves that
/// interface out when its groups are the volumes; it is found once.
#[test]
fn the_face_between_two_volumes_is_found_once() {
    let mut mesh = two_tets();
    mesh.cells[1].entity = 2;
    let found = mesh.undeclared_boundary_facets().unwrap();
    assert_eq!(found.len(), 6);
    let shared = canonical_face(&[1, 2, 3]);
    let copies = found
        .iter()
        .filter(|f| canonical_face(&f.vertices) == shared)
        .count();
    assert_eq!(copies, 1);
}

#[test]
fn a_prisms_uncovered_faces_are_triangles_and_quadrilaterals() {
    let mesh = LinearMesh {
        dim: 3,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
        ],
        cells: vec![element(Shape::Prism, &[0, 1, 2, 3, 4, 5], 1)],
        ..Default::default()
    };
    let found = mesh.undeclared_boundary_facets().unwrap();
    let kinds: Vec<Shape> = found.iter().map(|f| f.kind).collect();
    assert_eq!(kinds.iter().filter(|&&k| k == Shape::Tri).count(), 2);
    assert_eq!(kinds.iter().filter(|&&k| k == Shape::Quad).count(), 3);
}

#[test]
fn a_2d_meshs_uncovered_edges_are_lines_and_negative_entities_stop_the_search() {
    let mut mesh = LinearMesh {
        dim: 2,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        cells: vec![
            element(Shape::Tri, &[0, 1, 2], 1),
            element(Shape::Tri, &[0, 2, 3], 1),
        ],
        facets: vec![element(Shape::Line, &[1, 0], 5)],
        ..Default::default()
    };
    let found = mesh.undeclared_boundary_facets().unwrap();
    assert_eq!(found.len(), 3);
    assert!(found.iter().all(|f| f.kind == Shape::Line));
    // A file whose own tags are negative: ours could not be told from them.
    mesh.facets[0].entity = -3;
    assert!(mesh.undeclared_boundary_facets().unwrap().is_empty());
}

/// Four triangles of the unit square: on entity 1 one counter-clockwise and one clockwise,
/// on entity 2 both clockwise.
fn square_of_two_surfaces() -> LinearMesh {
    LinearMesh {
        dim: 2,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.5, 0.0],
        ],
        cells: vec![
            element(Shape::Tri, &[0, 1, 4], 1),
            element(Shape::Tri, &[1, 4, 2], 1),
            element(Shape::Tri, &[2, 4, 3], 2),
            element(Shape::Tri, &[3, 4, 0], 2),
        ],
        ..Default::default()
    }
}

#[test]
fn surfaces_numbered_clockwise_are_renumbered_and_mixed_ones_refused() {
    let mut mesh = square_of_two_surfaces();
    // Entity 2 turns clockwise throughout: a numbering. Entity 1 is mixed: left alone.
    assert_eq!(mesh.clockwise_cells(), [2, 3]);
    mesh.reverse_numbering(&[2, 3]);
    assert_eq!(mesh.cells[2].vertices, [2, 3, 4]);
    assert!(mesh.clockwise_cells().is_empty());
    assert!(matches!(
        mesh.check_orientation(),
        Err(MeshError::MixedOrientation { index: 1, .. })
    ));
    mesh.cells[1].vertices = vec![1, 2, 4];
    mesh.check_orientation().unwrap();
    // A quadrilateral keeps its first vertex and turns the other way.
    let mut quad = LinearMesh {
        dim: 2,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
        ],
        cells: vec![element(Shape::Quad, &[0, 1, 2, 3], 4)],
        ..Default::default()
    };
    assert_eq!(quad.clockwise_cells(), [0]);
    quad.reverse_numbering(&[0]);
    assert_eq!(quad.cells[0].vertices, [0, 3, 2, 1]);
    quad.check_orientation().unwrap();
    // 3D cells have one orientation: none is "clockwise".
    assert!(two_tets().clockwise_cells().is_empty());
}
