use super::*;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[test]
fn vertex_shape_functions_interpolate_vertices_and_sum_to_one() {
    for shape in Shape::ALL {
        let v = shape.vertices();
        for (i, xi) in v.iter().enumerate() {
            let (n, len) = shape.vertex_shape_functions(*xi);
            assert_eq!(len, v.len());
            for (j, nj) in n[..len].iter().enumerate() {
                assert_eq!(*nj, if i == j { 1.0 } else { 0.0 }, "{shape:?}");
            }
        }
        let (n, len) = shape.vertex_shape_functions([0.21, 0.33, 0.17]);
        assert!((n[..len].iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }
}

#[test]
fn faces_point_outward() {
    for shape in [Shape::Tet, Shape::Hex, Shape::Prism] {
        let v = shape.vertices();
        let n = v.len() as f64;
        let centroid = (0..3).map(|k| v.iter().map(|p| p[k]).sum::<f64>() / n);
        let c: Vec<f64> = centroid.collect();
        for face in shape.faces() {
            let normal = cross(sub(v[face[1]], v[face[0]]), sub(v[face[2]], v[face[0]]));
            let out = sub(v[face[0]], [c[0], c[1], c[2]]);
            assert!(
                dot(normal, out) > 0.0,
                "{shape:?} face {face:?} points inward"
            );
        }
    }
}

#[test]
fn euler_characteristic_and_node_counts() {
    for shape in [Shape::Tet, Shape::Hex, Shape::Prism] {
        let (v, e, f) = (
            shape.num_vertices() as i64,
            shape.edges().len() as i64,
            shape.faces().len() as i64,
        );
        assert_eq!(v - e + f, 2, "{shape:?}");
    }
    for shape in Shape::ALL {
        for p in 1..=8 {
            // total = vertices + edges·(p−1) + Σ faces' interiors + interior
            let mut total = shape.num_vertices() + shape.edges().len() * (p - 1);
            if shape.dim() == 3 {
                for face in shape.faces() {
                    total += Shape::face_shape(face.len()).num_interior_nodes(p);
                }
            }
            if shape.dim() > 1 {
                total += shape.num_interior_nodes(p);
            }
            assert_eq!(total, shape.num_nodes(p), "{shape:?} p={p}");
        }
    }
}
