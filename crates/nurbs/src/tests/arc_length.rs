use super::*;
use crate::shapes::circle;
use std::f64::consts::{FRAC_1_SQRT_2, PI};

#[test]
fn full_circle_is_two_pi_r() {
    for &r in &[1.0, 0.37, 250.0] {
        let c = circle([1.0, 2.0, 3.0], [0.2, -1.0, 0.5], r).unwrap();
        let length = arc_length(&c, 0.0, 1.0);
        assert!((length - 2.0 * PI * r).abs() < 1e-12 * r, "r={r}: {length}");
        assert_eq!(arc_length(&c, 1.0, 0.0), length);
        assert_eq!(arc_length(&c, 0.3, 0.3), 0.0);
    }
}

/// Complete elliptic integral of the second kind E(k) by the arithmetic–geometric mean:
/// E = K (1 - Σ_{n≥0} 2^{n-1} c_n²), K = π / (2 AGM(1, √(1-k²))), c_0 = k,
/// c_{n+1} = (a_n - b_n) / 2.
fn elliptic_e(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    let mut sum = 0.5 * k * k;
    let mut power = 0.5;
    for _ in 0..40 {
        let c = 0.5 * (a - b);
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
        power *= 2.0;
        sum += power * c * c;
        if c.abs() < 1e-18 {
            break;
        }
    }
    PI / (2.0 * a) * (1.0 - sum)
}

#[test]
fn quarter_ellipse_matches_the_elliptic_integral() {
    // The quarter ellipse x = a cos t, y = b sin t as the affine image of the rational
    // quarter circle: control points (a,0), (a,b), (0,b), weights 1, √2/2, 1.
    let (a, b) = (3.0, 1.0);
    let ellipse = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![[a, 0.0, 0.0], [a, b, 0.0], [0.0, b, 0.0]],
        vec![1.0, FRAC_1_SQRT_2, 1.0],
    )
    .unwrap();
    // Quarter perimeter = a E(e), e² = 1 - b²/a².
    let exact = a * elliptic_e((1.0 - b * b / (a * a)).sqrt());
    let length = arc_length(&ellipse, 0.0, 1.0);
    assert!(
        (length - exact).abs() < 1e-12 * exact,
        "{length} vs {exact}"
    );
    // Sanity of the AGM itself: E(0) = π/2, and the power series
    // E(k) = π/2 Σ_n ((2n-1)!! / (2n)!!)² k^{2n} / (1 - 2n) at k = 1/2.
    assert!((elliptic_e(0.0) - PI / 2.0).abs() < 1e-15);
    let (k, mut coefficient, mut series) = (0.5f64, 1.0f64, 0.0);
    for n in 0..60 {
        if n > 0 {
            let ratio = (2 * n - 1) as f64 / (2 * n) as f64;
            coefficient *= ratio * ratio;
        }
        series += coefficient * k.powi(2 * n) / (1.0 - 2.0 * n as f64);
    }
    assert!((elliptic_e(k) - PI / 2.0 * series).abs() < 1e-15);
}

#[test]
fn parameter_at_fraction_on_a_circle_is_at_the_right_angle() {
    // On a circle, the length fraction is the angle fraction.
    let c = circle([0.0; 3], [0.0, 0.0, 1.0], 2.0).unwrap();
    for i in 0..=20 {
        let f = i as f64 / 20.0;
        let u = parameter_at_length_fraction(&c, 0.0, 1.0, f);
        let p = c.point(u);
        let angle = 2.0 * PI * f;
        assert!((p[0] - 2.0 * angle.cos()).abs() < 1e-12, "f={f}");
        assert!((p[1] - 2.0 * angle.sin()).abs() < 1e-12, "f={f}");
        // Backwards from u = 1: clockwise.
        let u = parameter_at_length_fraction(&c, 1.0, 0.0, f);
        let p = c.point(u);
        assert!((p[0] - 2.0 * angle.cos()).abs() < 1e-12);
        assert!((p[1] + 2.0 * angle.sin()).abs() < 1e-12);
    }
    // A sub-arc from 45° to 225°: the midpoint by length is at 135°.
    let (u0, u1) = (0.125, 0.625);
    let p0 = c.point(u0);
    assert!((p0[1].atan2(p0[0]) - PI / 4.0).abs() < 1e-14);
    let p = c.point(parameter_at_length_fraction(&c, u0, u1, 0.5));
    assert!((p[1].atan2(p[0]) - 0.75 * PI).abs() < 1e-12);
}
