use super::*;

/// Cubic with a double interior knot at 0.5 and clamped ends.
const KNOTS: [f64; 10] = [0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.5, 1.0, 1.0, 1.0];

// Note: KNOTS has 10 entries with degree 3 → 6 control points, but the end is only
// triple; use the clamped vector below for span tests.
const CLAMPED: [f64; 11] = [0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.5, 1.0, 1.0, 1.0, 1.0];

#[test]
fn validation_reports_what_is_wrong() {
    assert!(validate_knot_vector(3, &CLAMPED, 7).is_ok());
    assert!(matches!(
        validate_knot_vector(3, &KNOTS, 7),
        Err(NurbsError::KnotCount {
            expected: 11,
            found: 10,
            ..
        })
    ));
    let mut bad = CLAMPED;
    bad[5] = 0.1;
    assert!(matches!(
        validate_knot_vector(3, &bad, 7),
        Err(NurbsError::DecreasingKnots { index: 5, .. })
    ));
    assert!(matches!(
        validate_knot_vector(0, &CLAMPED, 10),
        Err(NurbsError::Degree { .. })
    ));
    assert!(matches!(
        validate_knot_vector(3, &[0.0; 8], 4),
        Err(NurbsError::EmptyDomain { .. })
    ));
    assert!(matches!(
        validate_weights(&[1.0, 0.0, 1.0], 3),
        Err(NurbsError::NonPositiveWeight { index: 1, .. })
    ));
    assert!(matches!(
        validate_weights(&[1.0], 3),
        Err(NurbsError::WeightCount {
            expected: 3,
            found: 1
        })
    ));
}

#[test]
fn span_search_handles_ends_and_repeated_knots() {
    let p = 3;
    assert_eq!(find_span(p, &CLAMPED, 0.0), 3);
    assert_eq!(find_span(p, &CLAMPED, -1.0), 3);
    assert_eq!(find_span(p, &CLAMPED, 0.1), 3);
    assert_eq!(find_span(p, &CLAMPED, 0.25), 4);
    assert_eq!(find_span(p, &CLAMPED, 0.4), 4);
    // Double knot at 0.5 (indices 5, 6): the span starting at 0.5 is 6.
    assert_eq!(find_span(p, &CLAMPED, 0.5), 6);
    assert_eq!(find_span(p, &CLAMPED, 0.99), 6);
    // End knot: last non-empty span.
    assert_eq!(find_span(p, &CLAMPED, 1.0), 6);
    assert_eq!(find_span(p, &CLAMPED, 2.0), 6);
}

#[test]
fn bernstein_basis_on_a_single_span() {
    // Knots [0,0,0,0,1,1,1,1]: the cubic Bernstein polynomials.
    let knots = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    for &u in &[0.0, 0.2, 0.5, 0.77, 1.0] {
        let span = find_span(3, &knots, u);
        let mut n = [0.0; 4];
        basis_functions(span, u, 3, &knots, &mut n);
        let t = 1.0 - u;
        let exact = [t * t * t, 3.0 * u * t * t, 3.0 * u * u * t, u * u * u];
        let mut ders = [[0.0; MAX_ORDER]; 4];
        basis_function_derivatives(span, u, 3, 3, &knots, &mut ders);
        let d1 = [
            -3.0 * t * t,
            3.0 * t * t - 6.0 * u * t,
            6.0 * u * t - 3.0 * u * u,
            3.0 * u * u,
        ];
        let d2 = [6.0 * t, -12.0 * t + 6.0 * u, 6.0 * t - 12.0 * u, 6.0 * u];
        let d3 = [-6.0, 18.0, -18.0, 6.0];
        for j in 0..4 {
            assert!((n[j] - exact[j]).abs() < 1e-15);
            assert!((ders[0][j] - exact[j]).abs() < 1e-15);
            assert!((ders[1][j] - d1[j]).abs() < 1e-13);
            assert!((ders[2][j] - d2[j]).abs() < 1e-13);
            assert!((ders[3][j] - d3[j]).abs() < 1e-12);
        }
    }
}

#[test]
fn partition_of_unity_and_derivatives_sum_to_zero() {
    for i in 0..=200 {
        let u = i as f64 / 200.0;
        let span = find_span(3, &CLAMPED, u);
        let mut ders = [[0.0; MAX_ORDER]; 5];
        basis_function_derivatives(span, u, 3, 4, &CLAMPED, &mut ders);
        let sums: Vec<f64> = (0..5).map(|k| ders[k][..4].iter().sum()).collect();
        assert!((sums[0] - 1.0).abs() < 1e-14);
        for k in 1..5 {
            assert!(sums[k].abs() < 1e-9, "k={k} sum={}", sums[k]);
        }
        assert!(ders[4][..4].iter().all(|&d| d == 0.0));
    }
}

#[test]
fn piegl_tiller_example_2_3() {
    // The NURBS Book Ex. 2.3: U = {0,0,0,1,2,3,4,4,5,5,5}, p = 2, u = 5/2:
    // N_{2,2} = 1/8, N_{3,2} = 6/8, N_{4,2} = 1/8.
    let knots = [0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0, 5.0, 5.0, 5.0];
    let span = find_span(2, &knots, 2.5);
    assert_eq!(span, 4);
    let mut n = [0.0; 3];
    basis_functions(span, 2.5, 2, &knots, &mut n);
    assert!((n[0] - 0.125).abs() < 1e-15);
    assert!((n[1] - 0.75).abs() < 1e-15);
    assert!((n[2] - 0.125).abs() < 1e-15);
}
