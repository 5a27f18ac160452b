use hocurve_nurbs::shapes::{cone, cylinder, sphere, AnalyticShape};
use hocurve_nurbs::vec3::{distance, dot, norm, scale, sub};

use super::*;
use crate::{GeodesicPath, SurfaceChart};

fn on_sphere(center: [f64; 3], r: f64, lon: f64, lat: f64) -> [f64; 3] {
    [
        center[0] + r * lat.cos() * lon.cos(),
        center[1] + r * lat.cos() * lon.sin(),
        center[2] + r * lat.sin(),
    ]
}

#[test]
fn great_circle_points_lie_on_the_sphere_at_the_fraction_of_the_angle() {
    let (center, r) = ([0.3, -0.2, 1.0], 2.0);
    let shape = AnalyticShape::new_sphere(center, r).unwrap();
    let exact = ClosedFormGeodesic::of(&shape).unwrap();
    // Across the seam of the usual chart (longitude ±π) and next to a pole.
    for (a, b) in [
        (
            on_sphere(center, r, 3.0, 0.2),
            on_sphere(center, r, -3.0, -0.1),
        ),
        (
            on_sphere(center, r, 0.1, 1.55),
            on_sphere(center, r, 2.0, 1.4),
        ),
        (
            on_sphere(center, r, 0.5, 0.5),
            on_sphere(center, r, 0.5 + 1e-10, 0.5),
        ),
    ] {
        let angle = |x: [f64; 3], y: [f64; 3]| {
            let (u, v) = (sub(x, center), sub(y, center));
            (dot(u, v) / (norm(u) * norm(v))).clamp(-1.0, 1.0).acos()
        };
        let omega = angle(a, b);
        for f in [0.0, 0.1, 0.5, 0.9, 1.0] {
            let x = exact.at_fraction(a, b, f);
            assert!((distance(x, center) - r).abs() < 1e-14 * r);
            assert!((angle(a, x) - f * omega).abs() < 1e-7 * omega.max(1e-9));
            assert!((angle(x, b) - (1.0 - f) * omega).abs() < 1e-7 * omega.max(1e-9));
        }
    }
}

#[test]
fn great_circles_are_the_bisector_refinements_limit() {
    let nurbs = sphere([0.0; 3], 1.0).unwrap();
    let chart = SurfaceChart::new(&nurbs);
    let exact = ClosedFormGeodesic::of(&AnalyticShape::new_sphere([0.0; 3], 1.0).unwrap()).unwrap();
    let path = GeodesicPath::between(&chart, [0.05, 0.4], [0.3, 0.8], 1e-12);
    let (a, b) = (path.points[0], path.points[path.points.len() - 1]);
    for f in [0.25, 0.5, 0.8] {
        let numeric = path.at_fraction(&chart, f).1;
        assert!(
            distance(numeric, exact.at_fraction(a, b, f)) < 1e-9,
            "f = {f}"
        );
    }
}

#[test]
fn helices_are_straight_on_the_unrolled_cylinder_and_take_the_short_way_round() {
    let (point, axis, r) = ([1.0, 0.0, -1.0], [0.0, 1.0, 1.0], 0.5);
    let shape = AnalyticShape::new_cylinder(point, axis, r).unwrap();
    let exact = ClosedFormGeodesic::of(&shape).unwrap();
    let ClosedFormGeodesic::Helix {
        frame: [e1, e2, a], ..
    } = exact
    else {
        panic!("a cylinder's geodesics are helices");
    };
    let at = |theta: f64, z: f64| -> [f64; 3] {
        (0..3)
            .map(|d| point[d] + z * a[d] + r * (theta.cos() * e1[d] + theta.sin() * e2[d]))
            .collect::<Vec<_>>()
            .try_into()
            .unwrap()
    };
    // From θ = 3 to θ = −3 the short way is +(2π − 6) across θ = π.
    let (x0, x1) = (at(3.0, 0.2), at(-3.0, 1.0));
    let turn = std::f64::consts::TAU - 6.0;
    for f in [0.0, 0.3, 0.5, 1.0] {
        let x = exact.at_fraction(x0, x1, f);
        let expected = at(3.0 + f * turn, 0.2 + 0.8 * f);
        assert!(distance(x, expected) < 1e-14, "f = {f}");
    }
    // The same curve as the bisector refinement on the NURBS cylinder.
    let nurbs = cylinder(point, axis, r, (0.0, 2.0)).unwrap();
    let chart = SurfaceChart::new(&nurbs);
    let path = GeodesicPath::between(&chart, [0.1, 0.2], [0.3, 0.7], 1e-12);
    let (a0, b0) = (path.points[0], path.points[path.points.len() - 1]);
    for f in [0.25, 0.5, 0.8] {
        let numeric = path.at_fraction(&chart, f).1;
        assert!(
            distance(numeric, exact.at_fraction(a0, b0, f)) < 1e-9,
            "f = {f}"
        );
    }
}

#[test]
fn cone_geodesics_are_straight_when_unrolled_and_shorter_than_the_bisector_refinement() {
    let (apex, axis, alpha) = ([0.2, 0.1, -0.5], [0.0, 1.0, 1.0], 0.6f64);
    let unit_axis = scale(axis, 1.0 / norm(axis));
    let exact =
        ClosedFormGeodesic::of(&AnalyticShape::new_cone(apex, axis, alpha).unwrap()).unwrap();
    let nurbs = cone(apex, axis, alpha, (0.3, 2.0)).unwrap();
    let chart = SurfaceChart::new(&nurbs);
    // (height along the axis, radius) of x.
    let cylindrical = |x: [f64; 3]| {
        let d = sub(x, apex);
        let h = dot(d, unit_axis);
        (h, norm(sub(d, scale(unit_axis, h))))
    };
    let polyline =
        |points: &[[f64; 3]]| -> f64 { points.windows(2).map(|w| distance(w[0], w[1])).sum() };
    // Within the chart, and across its seam u = 0 ≡ 1 (the short way round).
    for (pa, pb) in [([0.1, 0.2], [0.35, 0.9]), ([0.9, 0.1], [0.15, 0.6])] {
        let path = GeodesicPath::between(&chart, pa, pb, 1e-12);
        let (a, b) = (path.points[0], path.points[path.points.len() - 1]);
        // The geodesic's length: the unrolled chord, by the law of cosines from the apex
        // distances and the angle about the axis between a and b (times sin α).
        let along = |x: [f64; 3]| {
            let (h, _) = cylindrical(x);
            h / alpha.cos()
        };
        let radial = |x: [f64; 3]| {
            let d = sub(x, apex);
            let h = dot(d, unit_axis);
            let r = sub(d, scale(unit_axis, h));
            scale(r, 1.0 / norm(r))
        };
        let turn = dot(radial(a), radial(b)).clamp(-1.0, 1.0).acos() * alpha.sin();
        let (sa, sb) = (along(a), along(b));
        let length = (sa * sa + sb * sb - 2.0 * sa * sb * turn.cos()).sqrt();
        let n = 4000;
        let points: Vec<[f64; 3]> = (0..=n)
            .map(|i| exact.at_fraction(a, b, i as f64 / n as f64))
            .collect();
        for (i, &x) in points.iter().enumerate() {
            let (h, rho) = cylindrical(x);
            assert!((rho - h * alpha.tan()).abs() < 1e-14, "{i}: off the cone");
            // At the fraction i/n of the length (polyline of 4000 chords: error ~1e-8).
            let so_far = polyline(&points[..=i]);
            assert!((so_far - length * i as f64 / n as f64).abs() < 1e-7, "{i}");
        }
        // The paper's refinement (chord midpoints projected) approximates geodesics: on a
        // cone its limit is a longer curve, which the closed form replaces.
        let refined = polyline(&path.points);
        assert!(
            (polyline(&points) - length).abs() < 1e-7 && length < refined,
            "{pa:?} {pb:?}: {length} vs refined {refined}"
        );
    }
}

#[test]
fn tori_have_no_closed_form_here() {
    let torus = AnalyticShape::new_torus([0.0; 3], [0.0, 0.0, 1.0], 2.0, 0.5).unwrap();
    assert_eq!(ClosedFormGeodesic::of(&torus), None);
}
