use super::*;

fn one_cell(dim: usize, kind: ElementType, vertices: Vec<[f64; 3]>) -> LinearMesh {
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
    assert!(one_cell(3, ElementType::Tet, tet.clone())
        .check_orientation()
        .is_ok());
    let mut inverted = tet;
    inverted.swap(1, 2);
    let err = one_cell(3, ElementType::Tet, inverted)
        .check_orientation()
        .unwrap_err();
    assert!(err.to_string().contains("inverted"), "{err}");
    // A hex with one top corner pushed below the bottom face.
    let mut hex: Vec<[f64; 3]> = hocurve_nodes::Shape::Hex.vertices().to_vec();
    hex[6] = [1.0, 1.0, -0.5];
    let err = one_cell(3, ElementType::Hex, hex)
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
        ElementType::Tri,
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ],
    );
    mesh.cells.push(Element {
        kind: ElementType::Tri,
        vertices: vec![1, 3, 2],
        entity: 1,
    });
    assert!(mesh.check_orientation().is_ok());
    // Clockwise throughout is fine too.
    for c in &mut mesh.cells {
        c.vertices.swap(1, 2);
    }
    assert!(mesh.check_orientation().is_ok());
    mesh.cells[1].vertices.swap(1, 2);
    let err = mesh.check_orientation().unwrap_err();
    assert!(
        matches!(err, MeshError::InvertedCell { index: 1, .. }),
        "{err}"
    );
}
