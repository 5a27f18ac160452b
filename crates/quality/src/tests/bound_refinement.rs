use super::*;
use crate::test_meshes::hash01;
use hocurve_nodes::Shape;

/// Barycentric coordinates (λ₀, …) of reference point ξ of the triangle or tetrahedron.
fn barycentric(xi: [f64; 3], corners: usize) -> [f64; 4] {
    let mut l = [0.0; 4];
    l[1..corners].copy_from_slice(&xi[..corners - 1]);
    l[0] = 1.0 - l[1..].iter().sum::<f64>();
    l
}

#[test]
fn bisected_coefficients_are_the_polynomial_on_each_half() {
    for (shape, degree) in [(Shape::Tri, 4), (Shape::Tet, 6), (Shape::Tet, 1)] {
        let space = BernsteinSpace::new(shape, degree, degree).unwrap();
        let bisection = SimplexBisection::new(&space).unwrap();
        let n = bisection.corners();
        let c: Vec<f64> = (0..space.len())
            .map(|k| hash01(31 * k as u64) - 0.3)
            .collect();
        let vertices = shape.vertices();
        let (mut a, mut b, mut line) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..n {
            for j in i + 1..n {
                bisection.bisect(&c, (i, j), &mut a, &mut b, &mut line);
                let m: Vec<f64> = (0..3)
                    .map(|k| 0.5 * (vertices[i][k] + vertices[j][k]))
                    .collect();
                for (child, replaced) in [(&a, j), (&b, i)] {
                    for s in 0..10 {
                        // A random point of the child, by its barycentric coordinates.
                        let mut eta = [0.0; 3];
                        for e in eta.iter_mut().take(n - 1) {
                            *e = hash01(1000 + 7 * s + *e as u64) / (n as f64);
                        }
                        eta[0] = hash01(500 + s) / n as f64;
                        let mu = barycentric(eta, n);
                        let mut xi = [0.0; 3];
                        for (v, w) in mu.iter().enumerate().take(n) {
                            let corner: Vec<f64> = if v == replaced {
                                m.clone()
                            } else {
                                vertices[v].to_vec()
                            };
                            for k in 0..3 {
                                xi[k] += w * corner[k];
                            }
                        }
                        let (got, want) = (space.eval(child, eta), space.eval(&c, xi));
                        assert!(
                            (got - want).abs() < 1e-13,
                            "{shape} degree {degree} edge ({i}, {j}): {got} vs {want}"
                        );
                    }
                }
                // The vertex coefficients are the polynomial's values at the corners.
                let at_mid = space.eval(&c, [m[0], m[1], m[2]]);
                assert!((a[bisection.vertices()[j]] - at_mid).abs() < 1e-13);
                assert!((b[bisection.vertices()[i]] - at_mid).abs() < 1e-13);
            }
        }
    }
}

#[test]
fn the_longest_edge_is_split_first() {
    let mut corners = [[0.0; 3]; 4];
    corners[1] = [1.0, 0.0, 0.0];
    corners[2] = [0.0, 2.0, 0.0];
    corners[3] = [0.0, 0.0, 1.0];
    let region = Region::new(vec![1.0], 0.0, corners);
    assert_eq!(region.longest_edge(4), (1, 2));
    assert_eq!(region.longest_edge(3), (1, 2));
    assert_eq!(region.longest_edge(2), (0, 1));
}
