use super::*;

/// Deterministic pseudo-random numbers in [0, 1) (a 64-bit LCG).
pub(crate) fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

#[test]
fn circle_points_are_on_the_circle() {
    let (c, r) = ([1.0, -2.0, 0.5], 1.0);
    let n = [1.0, 2.0, 2.0];
    let curve = circle(c, n, r).unwrap();
    let n = scale(n, 1.0 / 3.0);
    assert!(curve.is_closed());
    for i in 0..=5000 {
        let p = curve.point(i as f64 / 5000.0);
        let d = sub(p, c);
        assert!((norm(d) - r).abs() < 1e-14);
        assert!(dot(d, n).abs() < 1e-14);
    }
    // Quarter points are where the frame axes say.
    let [e1, e2, _] = orthonormal_frame(n).unwrap();
    assert!(vec3::distance(curve.point(0.0), add(c, e1)) < 1e-15);
    assert!(vec3::distance(curve.point(0.25), add(c, e2)) < 1e-15);
}

#[test]
fn sphere_satisfies_its_implicit_equation_and_has_poles() {
    let (c, r) = ([0.3, -0.2, 0.1], 1.0);
    let s = sphere(c, r).unwrap();
    let mut seed = 1;
    for _ in 0..5000 {
        let (u, v) = (lcg(&mut seed), lcg(&mut seed));
        let p = s.point(u, v);
        assert!((vec3::distance(p, c) - r).abs() < 1e-14, "{u} {v}");
    }
    assert_eq!(s.degenerate_edges(), [true, true, false, false]);
    assert!(s.is_closed_u() && !s.is_closed_v());
    assert!(vec3::distance(s.point(0.3, 0.0), [0.3, -0.2, -0.9]) < 1e-15);
    assert!(vec3::distance(s.point(0.3, 1.0), [0.3, -0.2, 1.1]) < 1e-15);
    assert!(vec3::distance(s.point(0.0, 0.5), [1.3, -0.2, 0.1]) < 1e-15);
}

#[test]
fn torus_and_cylinder_satisfy_their_implicit_equations() {
    let (c, (big, small)) = ([1.0, 2.0, 3.0], (1.0, 0.25));
    let axis = [0.0, 1.0, 1.0];
    let a = scale(axis, 1.0 / 2f64.sqrt());
    let t = torus(c, axis, big, small).unwrap();
    let cyl = cylinder(c, axis, 0.5, (-1.0, 2.0)).unwrap();
    let mut seed = 7;
    for _ in 0..5000 {
        let (u, v) = (lcg(&mut seed), lcg(&mut seed));
        // (|d_⊥| - R)² + (d·a)² = r²
        let d = sub(t.point(u, v), c);
        let z = dot(d, a);
        let rho = norm(sub(d, scale(a, z)));
        assert!(((rho - big).hypot(z) - small).abs() < 1e-14);
        let d = sub(cyl.point(u, v), c);
        let z = dot(d, a);
        assert!((norm(sub(d, scale(a, z))) - 0.5).abs() < 1e-14);
        assert!((z - (-1.0 + 3.0 * v)).abs() < 1e-14);
    }
    assert!(t.is_closed_u() && t.is_closed_v());
    assert_eq!(t.degenerate_edges(), [false; 4]);
}

#[test]
fn a_cone_satisfies_its_implicit_equation_and_its_closest_points_are_exact() {
    let (apex, axis, alpha) = ([0.5, -1.0, 2.0], [1.0, 2.0, -2.0], 0.4f64);
    let a = scale(axis, 1.0 / 3.0);
    let nurbs = cone(apex, axis, alpha, (0.25, 1.5)).unwrap();
    let shape = AnalyticShape::new_cone(apex, axis, alpha).unwrap();
    let mut seed = 11;
    for _ in 0..2000 {
        let (u, v) = (lcg(&mut seed), lcg(&mut seed));
        // |d_⊥| = (d·a) tan α, with d·a linear in v from 0.25 to 1.5.
        let d = sub(nurbs.point(u, v), apex);
        let h = dot(d, a);
        let rho = norm(sub(d, scale(a, h)));
        assert!((rho - h * alpha.tan()).abs() < 1e-14, "{u} {v}");
        assert!((h - (0.25 + 1.25 * v)).abs() < 1e-14);
        // A point off the cone along its normal there comes back to it, at the offset.
        let normal = scale(
            sub(
                scale(sub(d, scale(a, h)), alpha.cos() / rho),
                scale(a, alpha.sin()),
            ),
            1.0,
        );
        let p = add(apex, d);
        for offset in [-0.1, 0.05] {
            let cp = shape.closest_point(add(p, scale(normal, offset)));
            assert!(vec3::distance(cp.point, p) < 1e-14, "{u} {v} {offset}");
            assert!((cp.distance - offset.abs()).abs() < 1e-14);
            assert!((cp.param[1] - h / alpha.cos()).abs() < 1e-13);
        }
    }
    // Inside the polar cone behind the apex, the apex is nearest.
    let behind = sub(apex, scale(a, 0.7));
    let cp = shape.closest_point(behind);
    assert!(vec3::distance(cp.point, apex) < 1e-15);
    assert!((cp.distance - 0.7).abs() < 1e-15);
    assert!(AnalyticShape::new_cone(apex, axis, 0.5 * PI).is_err());
    assert!(AnalyticShape::new_cone(apex, axis, 0.0).is_err());
    assert!(cone(apex, axis, alpha, (-1.0, 1.0)).is_err());
    assert!(cone(apex, axis, alpha, (1.0, 1.0)).is_err());
}

#[test]
fn analytic_closest_points() {
    let sphere = AnalyticShape::new_sphere([1.0, 0.0, 0.0], 2.0).unwrap();
    let cp = sphere.closest_point([1.0, 0.0, 5.0]);
    assert!(vec3::distance(cp.point, [1.0, 0.0, 2.0]) < 1e-15);
    assert!((cp.distance - 3.0).abs() < 1e-15);
    assert!((cp.param[1] - PI / 2.0).abs() < 1e-15);

    let torus = AnalyticShape::new_torus([0.0; 3], [0.0, 0.0, 2.0], 3.0, 1.0).unwrap();
    // Above the tube centre circle at (0, 3, 0): closest is the top of the tube.
    let cp = torus.closest_point([0.0, 3.0, 4.0]);
    assert!(vec3::distance(cp.point, [0.0, 3.0, 1.0]) < 1e-15);
    assert!((cp.distance - 3.0).abs() < 1e-15);
    assert!((cp.param[0] - PI / 2.0).abs() < 1e-15);
    assert!((cp.param[1] - PI / 2.0).abs() < 1e-15);
    // Inside the hole, on the plane: inner equator.
    let cp = torus.closest_point([-0.5, 0.0, 0.0]);
    assert!(vec3::distance(cp.point, [-2.0, 0.0, 0.0]) < 1e-15);
    assert!((cp.param[1] - PI).abs() < 1e-15);

    let cyl = AnalyticShape::new_cylinder([0.0; 3], [0.0, 0.0, -1.0], 1.0).unwrap();
    let cp = cyl.closest_point([3.0, 4.0, 7.0]);
    assert!(vec3::distance(cp.point, [0.6, 0.8, 7.0]) < 1e-15);
    assert!((cp.param[1] + 7.0).abs() < 1e-15);
    assert!((cp.distance - 4.0).abs() < 1e-15);

    let circle = AnalyticShape::new_circle([0.0; 3], [0.0, 0.0, 1.0], 2.0).unwrap();
    let cp = circle.closest_point([0.0, -1.0, 1.0]);
    assert!(vec3::distance(cp.point, [0.0, -2.0, 0.0]) < 1e-15);
    assert!((cp.param[0] - 1.5 * PI).abs() < 1e-15);
    assert!((cp.distance - 2f64.sqrt()).abs() < 1e-15);

    assert!(AnalyticShape::new_torus([0.0; 3], [0.0, 0.0, 1.0], 1.0, 2.0).is_err());
    assert!(AnalyticShape::new_sphere([0.0; 3], -1.0).is_err());
    assert!(AnalyticShape::new_cylinder([0.0; 3], [0.0; 3], 1.0).is_err());
}
