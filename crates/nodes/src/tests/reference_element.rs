use std::sync::Arc;

use super::*;

#[test]
fn shared_elements_are_built_once_per_shape_order_and_family() {
    let a = ReferenceElement::shared(Shape::Tet, 3, NodeFamily::Fekete).unwrap();
    let b = ReferenceElement::shared(Shape::Tet, 3, NodeFamily::Fekete).unwrap();
    let c = ReferenceElement::shared(Shape::Tet, 3, NodeFamily::Equispaced).unwrap();
    assert!(Arc::ptr_eq(&a, &b));
    assert!(!Arc::ptr_eq(&a, &c));
    assert_eq!(
        (a.shape(), a.order(), a.family(), a.len()),
        (Shape::Tet, 3, NodeFamily::Fekete, 20)
    );
    assert!(Arc::ptr_eq(&a.quadrature(6), &b.quadrature(6)));
    assert!(ReferenceElement::shared(Shape::Tri, 0, NodeFamily::Equispaced).is_err());
}

#[test]
fn quadrature_tables_hold_a_partition_of_unity_and_exact_weights() {
    for (shape, volume) in [
        (Shape::Tri, 0.5),
        (Shape::Quad, 1.0),
        (Shape::Tet, 1.0 / 6.0),
        (Shape::Hex, 1.0),
        (Shape::Prism, 0.5),
    ] {
        let element = ReferenceElement::shared(shape, 3, NodeFamily::GaussLobatto).unwrap();
        let table = element.quadrature(6);
        assert_eq!(table.num_nodes(), element.len());
        assert!(
            (table.weights().iter().sum::<f64>() - volume).abs() < 1e-14,
            "{shape}"
        );
        for q in 0..table.len() {
            assert!(
                (table.values(q).iter().sum::<f64>() - 1.0).abs() < 1e-12,
                "{shape}"
            );
            for d in 0..3 {
                let g: f64 = table.gradients(q).iter().map(|g| g[d]).sum();
                assert!(g.abs() < 1e-10, "{shape}: Σ∇Φ = {g}");
            }
        }
    }
}

#[test]
fn the_isoparametric_map_of_an_affine_element_has_its_matrix_as_jacobian() {
    // x = A ξ + b at every node: J = A and det J = det A at every point, for every shape.
    let a = [[2.0, 0.5, -0.25], [0.1, 1.5, 0.3], [-0.2, 0.4, 3.0]];
    let b = [10.0, -4.0, 7.0];
    for shape in [
        Shape::Tri,
        Shape::Quad,
        Shape::Tet,
        Shape::Hex,
        Shape::Prism,
    ] {
        let dim = shape.dim();
        let element = ReferenceElement::shared(shape, 4, NodeFamily::Fekete).unwrap();
        let coords: Vec<[f64; 3]> = element
            .nodes()
            .points()
            .iter()
            .map(|xi| {
                let mut x = [0.0; 3];
                for c in 0..dim {
                    x[c] = b[c] + (0..dim).map(|k| a[c][k] * xi[k]).sum::<f64>();
                }
                x
            })
            .collect();
        let table = element.tabulate(&[[0.2, 0.1, 0.3], [0.05, 0.6, 0.1]]);
        assert!(table.weights().is_empty());
        let expected = determinant(&a, dim);
        let mut dets = Vec::new();
        table.determinants_into(&coords, &mut dets);
        for q in 0..table.len() {
            let j = table.jacobian(&coords, q);
            for c in 0..dim {
                for k in 0..dim {
                    assert!(
                        (j[c][k] - a[c][k]).abs() < 1e-11,
                        "{shape}: J[{c}][{k}] = {}",
                        j[c][k]
                    );
                }
            }
            assert!(
                (dets[q] - expected).abs() < 1e-10 * expected.abs(),
                "{shape}"
            );
        }
    }
}

#[test]
fn determinants_by_cofactors() {
    let j = [[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]];
    assert_eq!(determinant(&j, 1), 2.0);
    assert_eq!(determinant(&j, 2), 5.0);
    assert_eq!(determinant(&j, 3), 18.0); // 2·11 − 1·4 + 0
}

/// The determinants of a curved element at points in lane blocks (a partial last block
/// included) have the bits of the point-by-point Jacobians'.
#[test]
fn determinants_in_lane_blocks_have_the_bits_of_point_by_point_jacobians() {
    for shape in Shape::ALL {
        let element = ReferenceElement::shared(shape, 3, NodeFamily::Fekete).unwrap();
        // A curved element: the reference nodes moved by a smooth, non-polynomial field.
        let coords: Vec<[f64; 3]> = element
            .nodes()
            .points()
            .iter()
            .map(|xi| {
                [
                    xi[0] + 0.1 * (3.0 * xi[1]).sin(),
                    xi[1] + 0.1 * (2.0 * xi[2] + xi[0]).cos(),
                    xi[2] + 0.05 * (xi[0] * xi[1]).exp(),
                ]
            })
            .collect();
        let points: Vec<[f64; 3]> = (0..11)
            .map(|k| {
                let t = (k as f64 + 0.5) / 11.0;
                [0.3 * t, 0.5 * (1.0 - t), 0.2 * t * t]
            })
            .collect();
        let table = element.tabulate(&points);
        let mut dets = Vec::new();
        table.determinants_into(&coords, &mut dets);
        assert_eq!(dets.len(), points.len());
        for (q, det) in dets.iter().enumerate() {
            let expected = determinant(&table.jacobian(&coords, q), shape.dim());
            assert_eq!(det.to_bits(), expected.to_bits(), "{shape} point {q}");
            assert!(*det != 0.0, "{shape} point {q}");
        }
    }
}
