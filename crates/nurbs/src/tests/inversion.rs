use super::*;
use crate::shapes::{circle, sphere, torus, AnalyticShape};
use crate::vec3::distance;

fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

#[test]
fn curve_round_trip() {
    let c = NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.6, 1.0, 1.0, 1.0, 1.0],
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 2.0, 0.5],
            [2.0, -1.0, 1.0],
            [3.0, 0.5, 0.0],
            [4.0, 2.0, -1.0],
            [5.0, 0.0, 0.3],
        ],
        vec![1.0, 0.5, 2.0, 1.0, 0.7, 1.0],
    )
    .unwrap();
    for i in 0..=200 {
        let u = i as f64 / 200.0;
        let cp = closest_point_on_curve(&c, c.point(u));
        assert!((cp.param - u).abs() < 1e-12, "u={u}: {}", cp.param);
        assert!(cp.distance < 1e-12);
    }
    // Beyond the end: the end point.
    let cp = closest_point_on_curve(&c, [20.0, 0.0, 0.3]);
    assert_eq!(cp.param, 1.0);
}

#[test]
fn circle_projection_is_radial_and_wraps_the_seam() {
    let c = circle([0.0; 3], [0.0, 0.0, 1.0], 1.0).unwrap();
    let analytic = AnalyticShape::new_circle([0.0; 3], [0.0, 0.0, 1.0], 1.0).unwrap();
    let mut seed = 3;
    for _ in 0..500 {
        let x = [
            4.0 * lcg(&mut seed) - 2.0,
            4.0 * lcg(&mut seed) - 2.0,
            lcg(&mut seed),
        ];
        let cp = closest_point_on_curve(&c, x);
        let exact = analytic.closest_point(x);
        assert!(
            distance(cp.point, exact.point) < 1e-12,
            "{x:?} {cp:?} {exact:?}"
        );
        assert!((cp.distance - exact.distance).abs() < 1e-12);
    }
    // Just below the seam at (1, 0): a start at u = 0.02 must wrap to u ≈ 1.
    let cp = closest_point_on_curve_near(&c, [2.0, -0.01, 0.0], 0.02);
    assert!(distance(cp.point, analytic.closest_point([2.0, -0.01, 0.0]).point) < 1e-12);
    assert!(cp.param > 0.99);
}

#[test]
fn sphere_round_trip_and_exact_projection() {
    let s = sphere([0.5, -1.0, 2.0], 3.0).unwrap();
    let analytic = AnalyticShape::new_sphere([0.5, -1.0, 2.0], 3.0).unwrap();
    let mut seed = 11;
    for _ in 0..500 {
        // Away from poles and seam.
        let (u, v) = (0.02 + 0.96 * lcg(&mut seed), 0.05 + 0.9 * lcg(&mut seed));
        let cp = closest_point_on_surface(&s, s.point(u, v));
        assert!((cp.param[0] - u).abs() < 1e-12 && (cp.param[1] - v).abs() < 1e-12);
        // Off the surface, anywhere (poles and seam included).
        let x = [
            0.5 + 10.0 * lcg(&mut seed) - 5.0,
            -1.0 + 10.0 * lcg(&mut seed) - 5.0,
            2.0 + 10.0 * lcg(&mut seed) - 5.0,
        ];
        let cp = closest_point_on_surface(&s, x);
        let exact = analytic.closest_point(x);
        assert!(
            distance(cp.point, exact.point) < 1e-12 * 3.0,
            "{x:?} {cp:?} {exact:?}"
        );
        assert!((cp.distance - exact.distance).abs() < 1e-12 * 3.0);
    }
    // Right above the north pole.
    let cp = closest_point_on_surface(&s, [0.5, -1.0, 7.0]);
    assert!(distance(cp.point, [0.5, -1.0, 5.0]) < 1e-12);
}

#[test]
fn torus_round_trip_and_exact_projection() {
    let axis = [1.0, 1.0, 0.0];
    let t = torus([0.0, 1.0, 0.0], axis, 2.0, 0.5).unwrap();
    let analytic = AnalyticShape::new_torus([0.0, 1.0, 0.0], axis, 2.0, 0.5).unwrap();
    let mut seed = 5;
    for _ in 0..300 {
        let (u, v) = (0.02 + 0.96 * lcg(&mut seed), 0.02 + 0.96 * lcg(&mut seed));
        let cp = closest_point_on_surface(&t, t.point(u, v));
        assert!((cp.param[0] - u).abs() < 1e-12 && (cp.param[1] - v).abs() < 1e-12);
        // Within the tube's reach (closest point unique), in a box around the torus.
        let x = [
            6.0 * lcg(&mut seed) - 3.0,
            1.0 + 6.0 * lcg(&mut seed) - 3.0,
            6.0 * lcg(&mut seed) - 3.0,
        ];
        let exact = analytic.closest_point(x);
        let cp = closest_point_on_surface(&t, x);
        assert!(
            distance(cp.point, exact.point) < 1e-11,
            "{x:?} {}",
            distance(cp.point, exact.point)
        );
        assert!((cp.distance - exact.distance).abs() < 1e-11);
    }
}

#[test]
fn a_kept_start_grid_gives_exact_closest_points_and_stops_on_the_surface() {
    let s = torus([0.0; 3], [0.0, 0.0, 1.0], 2.0, 0.5).unwrap();
    let samples = SurfaceSamples::new(&s);
    assert!(samples.fits(&s));
    let mut state = 7;
    for _ in 0..200 {
        let x = [
            4.0 * lcg(&mut state) - 2.0,
            4.0 * lcg(&mut state) - 2.0,
            lcg(&mut state) - 0.5,
        ];
        let kept = closest_point_on_surface_sampled(&s, &samples, x);
        // On the surface, the first start that reaches the point is the answer.
        let on = kept.point;
        let again = closest_point_on_surface_sampled(&s, &samples, on);
        assert!(again.distance <= 1e-14 * s.size(), "{}", again.distance);
        let exact = AnalyticShape::new_torus([0.0; 3], [0.0, 0.0, 1.0], 2.0, 0.5)
            .unwrap()
            .closest_point(x);
        assert!((kept.distance - exact.distance).abs() < 1e-12, "{x:?}");
    }
    // A grid made for another control net is not used.
    let other = sphere([0.0; 3], 1.0).unwrap();
    assert!(!samples.fits(&other));
}
