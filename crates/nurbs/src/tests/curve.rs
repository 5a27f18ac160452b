use super::*;

/// A rational cubic with a double knot and uneven weights.
fn wiggly() -> NurbsCurve {
    NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.6, 0.6, 1.0, 1.0, 1.0, 1.0],
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 2.0, 0.5],
            [2.0, -1.0, 1.0],
            [3.0, 0.5, 0.0],
            [4.0, 2.0, -1.0],
            [5.0, 0.0, 0.3],
            [6.0, 1.0, 0.0],
        ],
        vec![1.0, 0.5, 2.0, 1.0, 0.7, 1.5, 1.0],
    )
    .unwrap()
}

#[test]
fn quadratic_bezier_matches_closed_form() {
    let c = NurbsCurve::non_rational(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![[0.0, 0.0, 0.0], [1.0, 2.0, 0.0], [2.0, 0.0, 0.0]],
    )
    .unwrap();
    // C(u) = (2u, 4u(1-u)), C' = (2, 4 - 8u), C'' = (0, -8).
    for &u in &[0.0, 0.25, 0.5, 0.9, 1.0] {
        let d = c.derivatives(u, 2);
        assert!((d[0][0] - 2.0 * u).abs() < 1e-15);
        assert!((d[0][1] - 4.0 * u * (1.0 - u)).abs() < 1e-15);
        assert!((d[1][0] - 2.0).abs() < 1e-14);
        assert!((d[1][1] - (4.0 - 8.0 * u)).abs() < 1e-14);
        assert!((d[2][1] + 8.0).abs() < 1e-13);
    }
    assert!(!c.is_closed());
    assert_eq!(c.domain(), (0.0, 1.0));
}

#[test]
fn rational_derivatives_match_finite_differences() {
    // Fourth-order central differences f' ≈ (f(-2h) - 8 f(-h) + 8 f(h) - f(2h)) / 12h.
    let c = wiggly();
    let h = 1e-4;
    let fd = |f: &dyn Fn(f64) -> [f64; 3], u: f64, k: usize| {
        (f(u - 2.0 * h)[k] - 8.0 * f(u - h)[k] + 8.0 * f(u + h)[k] - f(u + 2.0 * h)[k]) / (12.0 * h)
    };
    let point = |u: f64| c.point(u);
    let tangent = |u: f64| c.derivatives(u, 1)[1];
    for i in 1..100 {
        let u = i as f64 / 100.0;
        if (u - 0.6).abs() < 3.0 * h || (u - 0.3).abs() < 3.0 * h {
            // Differences across a knot see the jump of a higher derivative.
            continue;
        }
        let d = c.derivatives(u, 2);
        for k in 0..3 {
            let (fd1, fd2) = (fd(&point, u, k), fd(&tangent, u, k));
            assert!(
                (d[1][k] - fd1).abs() < 1e-7 * (1.0 + d[1][k].abs()),
                "u={u}"
            );
            assert!(
                (d[2][k] - fd2).abs() < 1e-7 * (1.0 + d[2][k].abs()),
                "u={u}"
            );
            assert_eq!(d[0][k], c.point(u)[k]);
        }
    }
}

#[test]
fn knot_insertion_leaves_the_curve_unchanged() {
    let c = wiggly();
    for &(u, times) in &[(0.1, 1), (0.3, 2), (0.6, 1), (0.45, 3), (0.6, 5)] {
        let refined = c.insert_knot(u, times).unwrap();
        refined.validate().unwrap();
        let expected_added = times.min(3 - c.knot_multiplicity(u));
        assert_eq!(refined.knots.len(), c.knots.len() + expected_added);
        for i in 0..=500 {
            let t = i as f64 / 500.0;
            let (a, b) = (c.point(t), refined.point(t));
            assert!(vec3::distance(a, b) < 1e-13, "u={u} t={t}");
        }
    }
    assert!(c.insert_knot(1.0, 1).is_err());
}

#[test]
fn split_halves_reproduce_the_curve() {
    let c = wiggly();
    for &u in &[0.2, 0.3, 0.6, 0.81] {
        let (left, right) = c.split_at(u).unwrap();
        left.validate().unwrap();
        right.validate().unwrap();
        assert_eq!(left.domain(), (0.0, u));
        assert_eq!(right.domain(), (u, 1.0));
        for i in 0..=200 {
            let t = i as f64 / 200.0;
            let part = if t <= u { &left } else { &right };
            assert!(vec3::distance(c.point(t), part.point(t)) < 1e-13);
        }
    }
}

#[test]
fn c0_parameters_are_knots_of_full_multiplicity() {
    let c = wiggly();
    assert!(c.c0_parameters().is_empty());
    let corner = c.insert_knot(0.6, 1).unwrap();
    assert_eq!(corner.c0_parameters(), vec![0.6]);
    assert_eq!(c.breakpoints(), vec![0.0, 0.3, 0.6, 1.0]);
}

#[test]
fn invalid_curves_are_rejected() {
    let err = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0],
        vec![[0.0; 3]; 3],
        vec![1.0; 3],
    );
    assert!(matches!(err, Err(NurbsError::KnotCount { .. })));
    let err = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![[0.0; 3]; 3],
        vec![1.0, -1.0, 1.0],
    );
    assert!(matches!(
        err,
        Err(NurbsError::NonPositiveWeight { index: 1, .. })
    ));
}
