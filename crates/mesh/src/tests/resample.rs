use super::*;
use crate::{Element, LinearMesh, Shape};

/// A curved 3D hybrid mesh (hexahedron and prism) of order `p` on `family` nodes.
fn curved(p: usize, family: NodeFamily) -> HighOrderMesh {
    let linear = LinearMesh {
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
            Element {
                kind: Shape::Prism,
                vertices: vec![1, 8, 2, 5, 9, 6],
                entity: 1,
            },
        ],
        ..Default::default()
    };
    let mut mesh = HighOrderMesh::from_linear(&linear, p, family).unwrap();
    for x in &mut mesh.nodes {
        let (a, b, c) = (x[0], x[1], x[2]);
        *x = [
            a + 0.1 * (2.0 * b).sin(),
            b + 0.05 * a * c,
            c + 0.05 * (a + b).cos(),
        ];
    }
    mesh
}

#[test]
fn a_linear_field_stays_exact_after_resampling() {
    let f = |x: [f64; 3]| {
        [
            1.5 + 2.0 * x[0] - 0.5 * x[1] + 0.25 * x[2],
            -x[2] + 3.0 * x[0],
        ]
    };
    for p in 1..=5 {
        let mesh = curved(p, NodeFamily::Fekete);
        let values: Vec<f64> = mesh.nodes.iter().flat_map(|&x| f(x)).collect();
        let target = NodeFamily::Equispaced;
        let resampled = mesh.resampled(target).unwrap();
        let moved = mesh.resampled_point_values(target, 2, &values).unwrap();
        assert_eq!(moved.len(), values.len());
        for (i, x) in resampled.nodes.iter().enumerate() {
            let want = f(*x);
            for k in 0..2 {
                assert!((moved[2 * i + k] - want[k]).abs() < 1e-12, "p={p} node {i}");
            }
        }
    }
}

#[test]
fn coordinates_as_data_resample_bitwise_like_the_mesh() {
    let mesh = curved(4, NodeFamily::WarpBlend);
    let values: Vec<f64> = mesh.nodes.iter().flatten().copied().collect();
    let moved = mesh
        .resampled_point_values(NodeFamily::Equispaced, 3, &values)
        .unwrap();
    let resampled = mesh.resampled(NodeFamily::Equispaced).unwrap();
    let want: Vec<f64> = resampled.nodes.iter().flatten().copied().collect();
    assert_eq!(moved, want);
    // Same family: unchanged.
    assert_eq!(
        mesh.resampled_point_values(NodeFamily::WarpBlend, 3, &values)
            .unwrap(),
        values
    );
}

#[test]
fn wrong_data_length_is_an_error() {
    let mesh = curved(2, NodeFamily::Equispaced);
    let err = mesh
        .resampled_point_values(NodeFamily::Fekete, 3, &[0.0; 5])
        .unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::DataLength {
                components: 3,
                found: 5,
                ..
            }
        ),
        "{err}"
    );
    assert!(mesh
        .resampled_point_values(NodeFamily::Fekete, 0, &[])
        .is_err());
}
