use super::*;

/// A polynomial of the space, written with monomials, evaluated exactly enough.
fn monomial_test(shape: Shape, degree: usize, degree_z: usize, xi: [f64; 3]) -> f64 {
    let [x, y, z] = xi;
    match shape {
        Shape::Line => (0..=degree)
            .map(|e| x.powi(e as i32) * (e as f64 + 1.0))
            .sum(),
        Shape::Tri => (1.0 + x - 2.0 * y).powi(degree as i32) + 0.5,
        Shape::Tet => (1.0 + x - 2.0 * y + 0.5 * z).powi(degree as i32) - 0.3,
        Shape::Quad => (1.0 + 2.0 * x).powi(degree as i32) * (1.0 - y).powi(degree as i32),
        Shape::Hex => {
            (1.0 + 2.0 * x).powi(degree as i32)
                * (3.0 - y).powi(degree as i32)
                * (z - 2.0).powi(degree as i32)
        }
        Shape::Prism => (1.0 + x + 3.0 * y).powi(degree as i32) * (2.0 - z).powi(degree_z as i32),
    }
}

#[test]
fn coefficients_reproduce_polynomials_of_the_space_everywhere() {
    for shape in Shape::ALL {
        for degree in 0..=6 {
            let degree_z = degree + 1;
            let space = BernsteinSpace::new(shape, degree, degree_z).unwrap();
            let mut c: Vec<f64> = space
                .points()
                .iter()
                .map(|&x| monomial_test(shape, degree, degree_z, x))
                .collect();
            let mut tmp = Vec::new();
            space.values_to_coefficients(&mut c, &mut tmp);
            for k in 0..20 {
                let s = k as f64 / 20.0;
                let xi = match shape.dim() {
                    1 => [s, 0.0, 0.0],
                    2 => [0.7 * s, 0.3 * (1.0 - s), 0.0],
                    _ => [0.5 * s, 0.3 * (1.0 - s), 0.15 + 0.1 * s],
                };
                let want = monomial_test(shape, degree, degree_z, xi);
                let got = space.eval(&c, xi);
                assert!(
                    (want - got).abs() < 1e-9 * want.abs().max(1.0),
                    "{shape:?} n={degree}: {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn basis_is_a_partition_of_unity_and_vertex_coefficients_are_values() {
    let space = BernsteinSpace::new(Shape::Tet, 4, 0).unwrap();
    let mut b = vec![0.0; space.len()];
    space.lattice.basis_values([0.1, 0.2, 0.3], &mut b);
    assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-14);
    assert!(b.iter().all(|&v| v >= 0.0));
    // f = ξ + 2η: coefficient at vertex (0,1,0) is f there = 2, at the origin 0.
    let mut c: Vec<f64> = space.points().iter().map(|x| x[0] + 2.0 * x[1]).collect();
    space.values_to_coefficients(&mut c, &mut Vec::new());
    let at = |p: [f64; 3]| space.points().iter().position(|&x| x == p).unwrap();
    assert!((c[at([0.0, 1.0, 0.0])] - 2.0).abs() < 1e-12);
    assert!(c[at([0.0, 0.0, 0.0])].abs() < 1e-12);
    // Degree elevation of a linear function: coefficients are its values at ξ_α (exact
    // for linear functions), so the minimum coefficient is 0 and the maximum 2.
    let min = c.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(min.abs() < 1e-12);
}

#[test]
fn jacobian_degrees_follow_the_derivation() {
    assert_eq!(jacobian_degree(Shape::Tri, 3), (4, 4));
    assert_eq!(jacobian_degree(Shape::Tet, 3), (6, 6));
    assert_eq!(jacobian_degree(Shape::Quad, 1), (1, 1));
    assert_eq!(jacobian_degree(Shape::Hex, 1), (2, 2));
    assert_eq!(jacobian_degree(Shape::Prism, 1), (1, 2));
    assert_eq!(jacobian_degree(Shape::Prism, 2), (4, 5));
    assert_eq!(multinomial(&[2, 1, 1]), 12.0);
    assert!(matches!(
        BernsteinSpace::for_jacobian(Shape::Tet, 10),
        Err(QualityError::UnsupportedBezierDegree { degree: 27, .. })
    ));
}

/// The children of one refinement as maps η ↦ ξ (boxes: halves per axis; prism: midpoint
/// triangles times ζ halves, in the order of `BernsteinSpace::subdivision`).
fn child_map(shape: Shape, child: usize, eta: [f64; 3]) -> [f64; 3] {
    match shape {
        Shape::Quad | Shape::Hex => {
            let mut xi = [0.0; 3];
            for k in 0..shape.dim() {
                xi[k] = 0.5 * eta[k] + 0.5 * (child >> k & 1) as f64;
            }
            xi
        }
        _ => {
            let (t, half) = (child % 4, child / 4);
            let v = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
            let m = |a: usize, b: usize| [0.5 * (v[a][0] + v[b][0]), 0.5 * (v[a][1] + v[b][1])];
            let w = [
                [v[0], m(0, 1), m(0, 2)],
                [m(0, 1), v[1], m(1, 2)],
                [m(0, 2), m(1, 2), v[2]],
                [m(1, 2), m(0, 2), m(0, 1)],
            ][t];
            let (l1, l2) = (eta[0], eta[1]);
            let l0 = 1.0 - l1 - l2;
            [
                l0 * w[0][0] + l1 * w[1][0] + l2 * w[2][0],
                l0 * w[0][1] + l1 * w[1][1] + l2 * w[2][1],
                0.5 * eta[2] + 0.5 * half as f64,
            ]
        }
    }
}

#[test]
fn subdivision_gives_the_coefficients_of_the_polynomial_on_each_child() {
    for shape in [Shape::Quad, Shape::Hex, Shape::Prism] {
        for degree in [1, 3, 8] {
            let degree_z = degree + 1;
            let space = BernsteinSpace::new(shape, degree, degree_z).unwrap();
            let sub = space.subdivision().expect("product shape");
            assert_eq!(sub.len(), if shape == Shape::Quad { 4 } else { 8 });
            let mut c: Vec<f64> = space
                .points()
                .iter()
                .map(|&x| monomial_test(shape, degree, degree_z, x))
                .collect();
            let mut tmp = Vec::new();
            space.values_to_coefficients(&mut c, &mut tmp);
            let mut d = Vec::new();
            for child in 0..sub.len() {
                sub.child(child, &c, &mut d, &mut tmp);
                for k in 0..15 {
                    let s = k as f64 / 15.0;
                    let eta = [0.6 * s, 0.35 * (1.0 - s), 0.2 + 0.7 * s];
                    let eta = if shape.dim() == 2 {
                        [eta[0], eta[1], 0.0]
                    } else {
                        eta
                    };
                    let exact =
                        monomial_test(shape, degree, degree_z, child_map(shape, child, eta));
                    let got = space.eval(&d, eta);
                    assert!(
                        (got - exact).abs() <= 1e-9 * (1.0 + exact.abs()),
                        "{shape:?} degree {degree} child {child} at {eta:?}: {got} vs {exact}"
                    );
                }
                // Vertex coefficients are the values at the child's vertices.
                for &v in sub.vertices() {
                    let exact = monomial_test(
                        shape,
                        degree,
                        degree_z,
                        child_map(shape, child, space.points()[v]),
                    );
                    assert!((d[v] - exact).abs() <= 1e-9 * (1.0 + exact.abs()));
                }
            }
        }
    }
}

#[test]
fn subdivision_rows_are_convex_combinations() {
    // Non-negative weights summing to one: a subdivision cannot amplify rounding errors.
    for shape in [Shape::Quad, Shape::Hex, Shape::Prism] {
        let space = BernsteinSpace::for_jacobian(shape, 4).unwrap();
        let sub = space.subdivision().expect("product shape");
        let mut tmp = Vec::new();
        let mut d = Vec::new();
        let ones = vec![1.0; space.len()];
        for child in 0..sub.len() {
            sub.child(child, &ones, &mut d, &mut tmp);
            assert!(
                d.iter().all(|&v| (v - 1.0).abs() < 1e-13),
                "{shape:?} child {child}"
            );
        }
        for m in &sub.matrices {
            assert!(m.iter().all(|&v| v >= 0.0), "{shape:?}: negative weight");
        }
    }
    assert!(BernsteinSpace::for_jacobian(Shape::Tet, 2)
        .unwrap()
        .subdivision()
        .is_none());
}

#[test]
fn the_largest_dense_degree_is_the_largest_lattice_that_fits() {
    // C(24, 3) = 2024 Bernstein polynomials: degree 21 on the tetrahedron (det J at p = 8);
    // C(64, 2) = 2016 on the triangle.
    assert_eq!(max_dense_degree(Shape::Tet), 21);
    assert_eq!(max_dense_degree(Shape::Tri), 62);
    for shape in [Shape::Tri, Shape::Tet] {
        let n = max_dense_degree(shape);
        assert!(Lattice::new(shape, n, 0).len() <= MAX_DENSE_COEFFICIENTS);
        assert!(Lattice::new(shape, n + 1, 0).len() > MAX_DENSE_COEFFICIENTS);
    }
}
