use super::*;
use crate::arc_length::arc_length;

fn naca0012() -> Naca4 {
    Naca4::from_digits("0012", 1.0, true).unwrap()
}

/// The spline parameter of the angle s.
fn u_of(s: f64) -> f64 {
    (s + PI) / (2.0 * PI)
}

fn xy(p: [f64; 3]) -> [f64; 2] {
    [p[0], p[1]]
}

/// Distance from `x` to the closed-form contour on the piece containing `s0`, by a secant
/// iteration on f(s) = C'(s)·(C(s) − x) from s0 (the spline point's own angle, already
/// within ~1e-10 of the foot point).
fn distance_to_contour(airfoil: &Naca4, x: [f64; 2], s0: f64, fore: bool) -> f64 {
    let f = |s: f64| {
        let c = airfoil.contour(s, fore);
        let r = [c.point[0] - x[0], c.point[1] - x[1]];
        (c.tangent[0] * r[0] + c.tangent[1] * r[1], r[0].hypot(r[1]))
    };
    let (mut s_prev, mut s) = (s0, s0 + 1e-7);
    let (mut f_prev, _) = f(s_prev);
    let mut best = f(s0).1;
    for _ in 0..30 {
        let (fs, dist) = f(s);
        best = best.min(dist);
        if fs == f_prev {
            break;
        }
        let next = s - fs * (s - s_prev) / (fs - f_prev);
        (s_prev, f_prev, s) = (s, fs, next);
    }
    best
}

/// Max parametric and geometric deviation of the spline from the closed form, sampling
/// `per_span` points in each knot span.
fn deviation(airfoil: &Naca4, curve: &NurbsCurve, per_span: usize) -> (f64, f64) {
    let (mut parametric, mut geometric) = (0.0f64, 0.0f64);
    let breaks = curve.breakpoints();
    let sp = if airfoil.is_cambered() {
        (1.0 - 2.0 * airfoil.camber_position).acos()
    } else {
        f64::INFINITY
    };
    for w in breaks.windows(2) {
        if w[0] >= 1.0 {
            continue; // the straight base of a blunt trailing edge
        }
        for j in 0..per_span {
            let u = w[0] + (w[1] - w[0]) * (j as f64 + 0.5) / per_span as f64;
            let s = 2.0 * PI * u - PI;
            let fore = s.abs() < sp;
            let spline = xy(curve.point(u));
            let exact = airfoil.contour(s, fore).point;
            parametric = parametric.max(distance2(spline, exact));
            geometric = geometric.max(distance_to_contour(airfoil, spline, s, fore));
        }
    }
    (parametric, geometric)
}

#[test]
fn digits_are_parsed_and_checked() {
    let a = Naca4::from_digits("2412", 2.0, false).unwrap();
    assert_eq!(
        (a.max_camber, a.camber_position, a.max_thickness, a.chord),
        (0.02, 0.4, 0.12, 2.0)
    );
    for bad in ["012", "00120", "00a2", "0000", "2012", "", "٠٠١٢"] {
        assert!(
            matches!(
                Naca4::from_digits(bad, 1.0, true),
                Err(NurbsError::InvalidShape { shape: "naca4", .. })
            ),
            "{bad}"
        );
    }
    assert!(Naca4::from_digits("0012", 0.0, true).is_err());
    assert!(Naca4::from_digits("0012", f64::NAN, true).is_err());
}

#[test]
fn closed_form_matches_the_standard_formulas() {
    let open = Naca4::from_digits("0012", 1.0, false).unwrap();
    let closed = naca0012();
    // y_t(1) = 0.6 (0.2969 − 0.1260 − 0.3516 + 0.2843 − a₄): 0.6 · 0.0021 or 0.
    assert!((open.thickness(1.0) - 0.6 * 0.0021).abs() < 1e-15);
    assert!(closed.thickness(1.0).abs() < 1e-15);
    // At x = 0.25: 0.6 (0.2969·0.5 − 0.0315 − 0.021975 + 0.0044421875 − 0.000396484375).
    let expected = 0.6 * (0.14845 - 0.0315 - 0.021975 + 0.0044421875 - 0.000396484375);
    assert!((open.thickness(0.25) - expected).abs() < 1e-15);
    // Symmetric: upper and lower mirror each other at the same abscissa.
    let (up, lo) = (closed.upper_surface(0.3), closed.lower_surface(0.3));
    assert_eq!(up, [0.3, closed.thickness(0.3)]);
    assert_eq!(lo, [0.3, -closed.thickness(0.3)]);
    // Chord scaling: the 2 m airfoil is the 1 m one doubled.
    let big = Naca4::from_digits("0012", 2.0, true).unwrap();
    assert!((big.thickness(0.6) - 2.0 * closed.thickness(0.3)).abs() < 1e-15);
    assert_eq!(closed.trailing_edge(), ([1.0, 0.0], [1.0, 0.0]));
    let (u, l) = open.trailing_edge();
    assert!((u[1] - 0.6 * 0.0021).abs() < 1e-15 && (l[1] + 0.6 * 0.0021).abs() < 1e-15);
}

#[test]
fn contour_derivative_matches_finite_differences() {
    // Fourth-order central differences away from the breaks, for 0012 and 2412.
    let h = 1e-3;
    for airfoil in [naca0012(), Naca4::from_digits("2412", 1.5, false).unwrap()] {
        for i in 1..40 {
            let s = -PI + 2.0 * PI * i as f64 / 40.0 + 0.01;
            let xi = 0.5 * (1.0 - s.cos());
            let fore = xi < airfoil.camber_position;
            let p = |t: f64| airfoil.contour(t, fore).point;
            let d = airfoil.contour(s, fore).tangent;
            for k in 0..2 {
                let fd = (p(s - 2.0 * h)[k] - 8.0 * p(s - h)[k] + 8.0 * p(s + h)[k]
                    - p(s + 2.0 * h)[k])
                    / (12.0 * h);
                assert!((fd - d[k]).abs() < 1e-9, "s={s} k={k}: {fd} vs {}", d[k]);
            }
        }
    }
}

#[test]
fn spline_interpolates_the_data_points() {
    let airfoil = naca0012();
    let n = 64;
    let curve = airfoil.curve_with_intervals(n).unwrap();
    for i in 0..=2 * n {
        let s = -PI + PI * i as f64 / n as f64;
        let u = u_of(s);
        let p = xy(curve.point(u));
        let exact = airfoil.contour_point(s);
        assert!(distance2(p, exact) < 1e-13, "s={s}: {p:?} vs {exact:?}");
    }
    // Clamped at the trailing edge, leading edge at u = 1/2.
    assert_eq!(curve.point(0.0), [1.0, 0.0, 0.0]);
    assert_eq!(curve.point(1.0), [1.0, 0.0, 0.0]);
    assert!(curve.is_closed());
    assert!(distance2(xy(curve.point(0.5)), [0.0, 0.0]) < 1e-15);
    // Lower surface first: clockwise.
    assert!(curve.point(0.25)[1] < 0.0 && curve.point(0.75)[1] > 0.0);
}

#[test]
fn knots_mark_the_trailing_edge_and_the_leading_edge() {
    let curve = naca0012().curve().unwrap();
    assert_eq!(curve.domain(), (0.0, 1.0));
    assert_eq!(curve.knot_multiplicity(0.0), 4);
    assert_eq!(curve.knot_multiplicity(1.0), 4);
    assert_eq!(curve.knot_multiplicity(0.5), 2);
    assert!(curve.c0_parameters().is_empty());
    assert_eq!(
        curve.control_points.len(),
        2 * (DEFAULT_INTERVALS_PER_SIDE + 3) - 2
    );
    // C¹ at the leading edge: one-sided derivatives agree.
    let (left, right) = (
        curve.derivatives(0.5 - 1e-15, 1)[1],
        curve.derivatives(0.5, 1)[1],
    );
    assert!((left[0] - right[0]).abs() < 1e-9 && (left[1] - right[1]).abs() < 1e-9);
    // dC/du = 2π dC/ds = 2π (0, 5t · 0.2969 / 2) at the leading edge: a vertical tangent.
    let expected = PI * 0.6 * 0.2969;
    for d in [left, right] {
        assert!(
            d[0].abs() < 1e-12 && (d[1] - expected).abs() < 1e-12,
            "{d:?}"
        );
    }

    // Blunt trailing edge: a straight base joined by C⁰ knots closes the curve.
    let open = Naca4::from_digits("0012", 1.0, false).unwrap();
    let curve = open.curve().unwrap();
    assert!(curve.is_closed());
    assert_eq!(curve.c0_parameters(), vec![1.0]);
    let (_, end) = curve.domain();
    let gap = 2.0 * 0.6 * 0.0021;
    assert!(end > 1.0 && end < 1.0 + gap);
    for i in 0..=10 {
        let p = curve.point(1.0 + (end - 1.0) * i as f64 / 10.0);
        assert!((p[0] - 1.0).abs() < 1e-15);
        assert!((p[1] - gap * (0.5 - i as f64 / 10.0)).abs() < 1e-15);
    }
    let length = arc_length(&curve, 1.0, end);
    assert!((length - gap).abs() < 1e-15);
}

#[test]
fn spline_is_within_1e_10_chord_of_the_closed_form_with_fourth_order_convergence() {
    let airfoil = naca0012();
    let curve = airfoil.curve().unwrap();
    let (parametric, geometric) = deviation(&airfoil, &curve, 8);
    assert!(parametric < 1e-10, "parametric deviation {parametric:e}");
    assert!(
        geometric <= parametric + 1e-15,
        "{geometric:e} {parametric:e}"
    );
    // Fourth-order convergence: halving the intervals multiplies the error by ~16.
    let coarse = airfoil
        .curve_with_intervals(DEFAULT_INTERVALS_PER_SIDE / 4)
        .unwrap();
    let (coarse_parametric, _) = deviation(&airfoil, &coarse, 8);
    let rate = (coarse_parametric / parametric).log2() / 2.0;
    assert!((3.7..4.3).contains(&rate), "rate {rate}");
}

#[test]
fn point_inversion_recovers_offsets_along_the_exact_normal() {
    // x = C(s) + d n(s) with n the outward unit normal: its distance to the contour is d
    // (d well below the leading-edge radius 1.1019 t² ≈ 0.016), up to the spline's error.
    let airfoil = naca0012();
    let curve = airfoil.curve().unwrap();
    let d = 1e-3;
    for i in 0..=200 {
        let s = -PI + 2.0 * PI * (i as f64 + 0.5) / 201.0;
        let c = airfoil.contour(s, true);
        let speed = c.tangent[0].hypot(c.tangent[1]);
        // Clockwise contour: the outward normal is the tangent turned left.
        let n = [-c.tangent[1] / speed, c.tangent[0] / speed];
        let x = [c.point[0] + d * n[0], c.point[1] + d * n[1], 0.0];
        let cp = crate::inversion::closest_point_on_curve(&curve, x);
        assert!((cp.distance - d).abs() < 1e-10, "s={s}: {}", cp.distance);
        assert!(
            (cp.param - u_of(s)).abs() < 1e-6,
            "s={s}: {} vs {}",
            cp.param,
            u_of(s)
        );
    }
    // Beyond the trailing edge the corner itself is closest.
    let cp = crate::inversion::closest_point_on_curve(&curve, [1.01, 0.0, 0.0]);
    assert!((cp.distance - 0.01).abs() < 1e-14);
}

/// Length of the polyline through the closed-form contour at `2^level` equal angle steps on
/// each smooth piece.
fn polyline_length(airfoil: &Naca4, level: u32) -> f64 {
    let k = 1usize << level;
    airfoil
        .pieces()
        .iter()
        .map(|&(a, b, fore)| {
            let mut previous = airfoil.contour(a, fore).point;
            let mut length = 0.0;
            for i in 1..=k {
                let p = airfoil
                    .contour(a + (b - a) * i as f64 / k as f64, fore)
                    .point;
                length += distance2(previous, p);
                previous = p;
            }
            length
        })
        .sum()
}

#[test]
fn arc_length_matches_the_richardson_limit_of_polylines() {
    let airfoil = naca0012();
    // Inscribed polylines on smooth pieces: L_h = L − c₂h² − c₄h⁴ …; two Richardson steps.
    let levels: Vec<f64> = (10..=13).map(|l| polyline_length(&airfoil, l)).collect();
    let r1: Vec<f64> = levels
        .windows(2)
        .map(|w| (4.0 * w[1] - w[0]) / 3.0)
        .collect();
    let r2: Vec<f64> = r1.windows(2).map(|w| (16.0 * w[1] - w[0]) / 15.0).collect();
    let limit = r2[r2.len() - 1];
    assert!((r2[0] - limit).abs() < 1e-12, "{r2:?}");
    let curve = airfoil.curve().unwrap();
    let spline_length = arc_length(&curve, 0.0, 1.0);
    let relative = (spline_length - limit).abs() / limit;
    assert!(
        relative < 1e-10,
        "length {spline_length} vs {limit}: {relative:e}"
    );
    // A NACA0012 contour is a little over twice the chord.
    assert!((2.03..2.05).contains(&limit), "{limit}");
}

#[test]
fn cambered_2412_has_its_camber_peak_at_p_and_corners_there() {
    let airfoil = Naca4::from_digits("2412", 1.0, true).unwrap();
    let (m, p) = (0.02, 0.4);
    assert!((airfoil.camber(p) - m).abs() < 1e-17);
    assert!(airfoil.camber_slope(p).abs() < 1e-17);
    for i in 0..=100 {
        let x = i as f64 / 100.0;
        if (x - p).abs() > 1e-9 {
            assert!(airfoil.camber(x) < m);
        }
    }
    assert_eq!(airfoil.camber(0.0), 0.0);
    assert!(airfoil.camber(1.0).abs() < 1e-17);
    // Surfaces are offset perpendicular to the camber line: at x = p the normal is vertical.
    let yt = airfoil.thickness(p);
    assert!(distance2(airfoil.upper_surface(p), [p, m + yt]) < 1e-16);
    assert!(distance2(airfoil.lower_surface(p), [p, m - yt]) < 1e-16);
    // Ahead of p the upper surface moves back: x_u = x − y_t sin θ < x.
    assert!(airfoil.upper_surface(0.2)[0] < 0.2 && airfoil.lower_surface(0.2)[0] > 0.2);

    let curve = airfoil.curve().unwrap();
    let sp = (1.0 - 2.0 * p).acos();
    let corners = curve.c0_parameters();
    assert_eq!(corners.len(), 2);
    assert!((corners[0] - u_of(-sp)).abs() < 1e-15);
    assert!((corners[1] - u_of(sp)).abs() < 1e-15);
    // The spline passes through the surface points at x = p, and its highest point on the
    // upper side is near there.
    assert!(distance2(xy(curve.point(corners[1])), airfoil.upper_surface(p)) < 1e-13);
    assert!(distance2(xy(curve.point(corners[0])), airfoil.lower_surface(p)) < 1e-13);
    // One-sided tangents at the corner follow the closed form's (a ~2e-4 rad kink).
    let before = airfoil.contour(sp, true).tangent;
    let after = airfoil.contour(sp, false).tangent;
    let angle = |a: [f64; 2]| a[1].atan2(a[0]);
    let kink = angle(after) - angle(before);
    assert!(kink.abs() > 1e-5 && kink.abs() < 1e-3, "kink {kink}");
    let u = corners[1];
    let spline_before = curve.derivatives(u - 1e-14, 1)[1];
    let spline_after = curve.derivatives(u, 1)[1];
    assert!((angle(xy(spline_before)) - angle(before)).abs() < 1e-9);
    assert!((angle(xy(spline_after)) - angle(after)).abs() < 1e-9);

    let (parametric, geometric) = deviation(&airfoil, &curve, 8);
    assert!(parametric < 1e-10 && geometric <= parametric + 1e-15);
    let length = arc_length(&curve, 0.0, 1.0);
    let reference: f64 = {
        let levels: Vec<f64> = (11..=12).map(|l| polyline_length(&airfoil, l)).collect();
        (4.0 * levels[1] - levels[0]) / 3.0
    };
    assert!((length - reference).abs() / reference < 1e-10);
}
