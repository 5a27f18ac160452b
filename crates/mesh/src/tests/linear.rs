use super::*;

fn one_cell(dim: usize, kind: Shape, vertices: Vec<[f64; 3]>) -> LinearMesh {
    LinearMesh {
        dim,
        cells: vec![Element {
            kind,
            vertices: (0..vertices.len() as u32).collect(),
            entity: 1,
        }],
        vertices,
        ..Default::default()
    }
}

#[test]
fn corner_jacobians_are_volumes_of_unit_cells() {
    use hocurve_nodes::Shape;
    for shape in [
        Shape::Tri,
        Shape::Quad,
        Shape::Tet,
        Shape::Hex,
        Shape::Prism,
    ] {
        // The reference element scaled by 2 in every direction: det J = 2^dim.
        let x: Vec<[f64; 3]> = shape
            .vertices()
            .iter()
            .map(|v| v.map(|c| 2.0 * c))
            .collect();
        for j in corner_jacobians(shape, &x) {
            assert_eq!(j, (1 << shape.dim()) as f64, "{shape:?}");
        }
    }
}

#[test]
fn inverted_tet_and_hex_are_rejected() {
    let tet = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    assert!(one_cell(3, Shape::Tet, tet.clone())
        .check_orientation()
        .is_ok());
    let mut inverted = tet;
    inverted.swap(1, 2);
    let err = one_cell(3, Shape::Tet, inverted)
        .check_orientation()
        .unwrap_err();
    assert!(err.to_string().contains("inverted"), "{err}");
    // A hex with one top corner pushed below the bottom face.
    let mut hex: Vec<[f64; 3]> = hocurve_nodes::Shape::Hex.vertices().to_vec();
    hex[6] = [1.0, 1.0, -0.5];
    let err = one_cell(3, Shape::Hex, hex)
        .check_orientation()
        .unwrap_err();
    assert!(
        matches!(err, MeshError::InvertedCell { index: 0, .. }),
        "{err}"
    );
}

#[test]
fn two_d_meshes_must_be_consistently_oriented() {
    let mut mesh = one_cell(
        2,
        Shape::Tri,
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ],
    );
    mesh.cells.push(Element {
        kind: Shape::Tri,
        vertices: vec![1, 3, 2],
        entity: 1,
    });
    assert!(mesh.check_orientation().is_ok());
    // Clockwise throughout is fine too.
    for c in &mut mesh.cells {
        c.vertices.swap(1, 2);
    }
    assert!(mesh.check_orientation().is_ok());
    // One cell the other way round: named as such, not as inverted.
    mesh.cells[1].vertices.swap(1, 2);
    let err = mesh.check_orientation().unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::MixedOrientation {
                index: 1,
                this: "counter-clockwise",
                first: "clockwise",
                ..
            }
        ),
        "{err}"
    );
    // A quadrilateral folded over itself (its corners turning both ways) is inverted.
    let mut quads = one_cell(
        2,
        Shape::Quad,
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
    );
    quads.vertices.extend([[2.0, 0.0, 0.0], [2.0, 1.0, 0.0]]);
    quads.cells.push(Element {
        kind: Shape::Quad,
        vertices: vec![1, 4, 2, 5],
        entity: 1,
    });
    let err = quads.check_orientation().unwrap_err();
    assert!(
        matches!(err, MeshError::InvertedCell { index: 1, .. }),
        "{err}"
    );
}

#[test]
fn unused_vertices_are_left_out_and_the_rest_renumbered() {
    let mesh = LinearMesh {
        dim: 2,
        vertices: vec![
            [9.0, 9.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [7.0, 7.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        cells: vec![Element {
            kind: Shape::Tri,
            vertices: vec![1, 2, 4],
            entity: 1,
        }],
        facets: vec![
            Element {
                kind: Shape::Line,
                vertices: vec![1, 2],
                entity: 2,
            },
            Element {
                kind: Shape::Line,
                vertices: vec![0, 3],
                entity: 3,
            },
        ],
        vertex_tags: vec![10, 20, 30, 40, 50],
        cell_tags: vec![7],
        facet_tags: vec![8, 9],
        ..Default::default()
    };
    let (pruned, unused) = mesh.without_unused_vertices();
    assert_eq!(unused, vec![10, 40]);
    assert_eq!(pruned.vertices.len(), 3);
    assert_eq!(pruned.vertex_tags, vec![20, 30, 50]);
    assert_eq!(pruned.cell_tags, vec![7]);
    // The facet on the unused vertices goes, with its tag.
    assert_eq!(pruned.facet_tags, vec![8]);
    assert_eq!(pruned.cells[0].vertices, vec![0, 1, 2]);
    assert_eq!(pruned.facets.len(), 1);
    assert_eq!(pruned.facets[0].vertices, vec![0, 1]);
    assert!(pruned.validate().is_ok());
    // Nothing to leave out: the same mesh.
    let (same, none) = pruned.without_unused_vertices();
    assert!(none.is_empty());
    assert_eq!(same, pruned);
}

/// Validation errors name elements and vertices by their tags in the file, not by their
/// positions.
#[test]
fn validation_errors_name_file_tags() {
    let mut mesh = one_cell(
        2,
        Shape::Tri,
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    );
    mesh.vertex_tags = vec![501, 502, 503];
    mesh.cell_tags = vec![1234];
    mesh.cells[0].vertices = vec![0, 1, 1];
    let err = mesh.validate().unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::RepeatedVertex {
                index: 0,
                tag: 1234,
                vertex: 1,
                vertex_tag: 502,
                ..
            }
        ),
        "{err:?}"
    );
    let text = err.to_string();
    assert!(text.contains("element tag 1234"), "{text}");
    assert!(text.contains("node tag 502"), "{text}");

    mesh.cells[0].vertices = vec![0, 1, 2];
    mesh.facets = vec![Element {
        kind: Shape::Tri,
        vertices: vec![0, 1, 2],
        entity: 1,
    }];
    mesh.facet_tags = vec![77];
    let text = mesh.validate().unwrap_err().to_string();
    assert!(text.contains("facet with element tag 77"), "{text}");

    mesh.facets.clear();
    mesh.vertices[2][1] = f64::NAN;
    let text = mesh.validate().unwrap_err().to_string();
    assert!(text.contains("node tag 503"), "{text}");
}

/// A triangle mesh in 3D that is not in one plane z = const (a surface mesh of a CAD part) is
/// refused with the lowest and highest nodes; a 2D mesh in the plane z = 5 is accepted.
#[test]
fn a_2d_mesh_must_lie_in_a_plane_z_const() {
    let mut mesh = one_cell(
        2,
        Shape::Tri,
        vec![[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]],
    );
    mesh.vertex_tags = vec![501, 502, 503];
    assert!(mesh.check_orientation().is_ok());
    mesh.vertices[1][2] = 5.5;
    // A valid mesh to read (its file is what it is), but not one to curve.
    assert!(mesh.validate().is_ok());
    let err = mesh.check_planar().unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::NotPlanar {
                low_tag: 501,
                high_tag: 502,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("not planar"), "{err}");
    assert!(mesh.check_orientation().is_err());
}

/// A split edge's new cells and facets get element tags past the largest of both lists
/// (Gmsh numbers cells and facets together).
#[test]
fn split_elements_get_new_tags_past_cells_and_facets() {
    let mesh = LinearMesh {
        dim: 2,
        vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        cells: vec![Element {
            kind: Shape::Tri,
            vertices: vec![0, 1, 2],
            entity: 1,
        }],
        facets: vec![Element {
            kind: Shape::Line,
            vertices: vec![0, 1],
            entity: 2,
        }],
        vertex_tags: vec![1, 2, 3],
        cell_tags: vec![10],
        facet_tags: vec![20],
        ..Default::default()
    };
    let (split, count) = mesh.split_edges(&[[0, 1]]);
    assert_eq!(count, 1);
    assert_eq!(split.cell_tags, vec![10, 21]);
    assert_eq!(split.facet_tags, vec![20, 22]);
    assert_eq!(split.vertex_tags, vec![1, 2, 3, 4]);
}
