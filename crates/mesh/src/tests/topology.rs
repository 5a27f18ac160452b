use super::*;

#[test]
fn canonical_quad_face_is_independent_of_rotation_and_direction() {
    let cycle = [7u32, 3, 9, 5];
    let expect = canonical_face(&cycle);
    assert_eq!(expect, vec![3, 7, 5, 9]);
    for start in 0..4 {
        let rotated: Vec<u32> = (0..4).map(|k| cycle[(start + k) % 4]).collect();
        let reversed: Vec<u32> = (0..4).map(|k| cycle[(start + 4 - k) % 4]).collect();
        assert_eq!(canonical_face(&rotated), expect);
        assert_eq!(canonical_face(&reversed), expect);
    }
    assert_eq!(canonical_face(&[9, 2, 4]), vec![2, 4, 9]);
}

#[test]
fn two_tetrahedra_sharing_a_face_through_the_accessors() {
    // Tets (0,1,2,3) and (1,2,3,4) share the face {1,2,3}: 9 edges, 7 faces, 6 of them
    // on the boundary.
    let mesh = LinearMesh {
        dim: 3,
        vertices: vec![[0.0; 3]; 5],
        cells: vec![
            crate::Element {
                kind: crate::Shape::Tet,
                vertices: vec![0, 1, 2, 3],
                entity: 1,
            },
            crate::Element {
                kind: crate::Shape::Tet,
                vertices: vec![1, 2, 3, 4],
                entity: 1,
            },
        ],
        ..Default::default()
    };
    let topology = Topology::new(&mesh).unwrap();
    assert_eq!(topology.edges().len(), 9);
    assert!(topology.edges().iter().all(|e| e[0] < e[1]));
    assert_eq!((topology.num_faces(), topology.faces().count()), (7, 7));
    assert_eq!(topology.boundary_facets().count(), 6);
    let shared = (0..7)
        .find(|&f| topology.face(f) == [1, 2, 3])
        .expect("shared face");
    assert_eq!(topology.facet_cells(shared), [0, 1]);
    for c in 0..2 {
        assert_eq!(topology.cell_edges(c).len(), 6);
        assert!(topology.cell_faces(c).contains(&(shared as u32)));
    }
    assert_eq!(
        topology.find_edge(3, 1),
        topology.edges().iter().position(|&e| e == [1, 3])
    );
}
