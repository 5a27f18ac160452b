use super::*;
use crate::inversion::{closest_point_on_curve, closest_point_on_surface};
use crate::shapes::{circle, sphere, torus};

fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// A bicubic patch over [0, 10]² on a 10 × 10 net, flat (z = 0) but for a bump of height 3
/// at the corner (0, 0), with uneven weights and a double knot in u.
fn bumped_patch() -> NurbsSurface {
    let n = 10;
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let z = if i < 2 && j < 2 { 3.0 } else { 0.0 };
            points.push([i as f64 * 10.0 / 9.0, j as f64 * 10.0 / 9.0, z]);
            weights.push(1.0 + 0.1 * ((i * 7 + j * 3) % 5) as f64);
        }
    }
    let mut knots_u = vec![0.0; 4];
    knots_u.extend([0.2, 0.4, 0.4, 0.7, 0.9, 0.95]);
    knots_u.extend([1.0; 4]);
    let mut knots_v = vec![0.0; 4];
    knots_v.extend([0.1, 0.3, 0.5, 0.6, 0.8, 0.9]);
    knots_v.extend([1.0; 4]);
    NurbsSurface::new(3, 3, knots_u, knots_v, points, weights).unwrap()
}

fn surfaces() -> Vec<NurbsSurface> {
    vec![
        bumped_patch(),
        sphere([0.5, -1.0, 2.0], 1.5).unwrap(),
        torus([0.0; 3], [0.3, 0.4, 0.866], 2.0, 0.5).unwrap(),
    ]
}

#[test]
fn every_surface_point_lies_in_a_span_box() {
    let mut seed = 5;
    for s in surfaces() {
        let hulls = SpanHulls::of_surface(&s).unwrap();
        let ((u0, u1), (v0, v1)) = s.domain();
        for _ in 0..2000 {
            let (u, v) = (
                u0 + (u1 - u0) * lcg(&mut seed),
                v0 + (v1 - v0) * lcg(&mut seed),
            );
            let x = s.point(u, v);
            assert!(hulls.distance_bound(x) <= 1e-13 * s.size(), "{x:?}");
            assert!(!hulls.is_farther_than(x, 1e-13 * s.size()));
        }
    }
}

#[test]
fn the_span_bound_never_exceeds_the_distance_and_proves_farness() {
    let mut seed = 11;
    for s in surfaces() {
        let hulls = SpanHulls::of_surface(&s).unwrap();
        let size = s.size();
        let mut pruned = 0;
        for _ in 0..400 {
            let x = [0, 1, 2].map(|_| (lcg(&mut seed) - 0.3) * size);
            let d = closest_point_on_surface(&s, x).distance;
            let bound = hulls.distance_bound(x);
            assert!(
                bound <= d * (1.0 + 1e-12) + 1e-12 * size,
                "{bound} > {d} at {x:?}"
            );
            for r in [0.1 * d, 0.5 * d, 0.99 * d] {
                if hulls.is_farther_than(x, r) {
                    pruned += 1;
                    assert!(d > r);
                }
            }
            assert!(!hulls.is_farther_than(x, d * (1.0 + 1e-9) + 1e-12 * size));
        }
        assert!(pruned > 100, "the bound proves little: {pruned}");
    }
}

#[test]
fn span_boxes_see_past_the_whole_box() {
    // Above the flat part, inside the box of the whole net (its z reaches 3 at the bump): the
    // span boxes there are flat, so the bound is the true height.
    let s = bumped_patch();
    let hulls = SpanHulls::of_surface(&s).unwrap();
    let x = [8.0, 8.0, 2.0];
    assert!((hulls.distance_bound(x) - 2.0).abs() < 1e-12);
    assert!(hulls.is_farther_than(x, 1.9));
    assert!((closest_point_on_surface(&s, x).distance - 2.0).abs() < 1e-9);
}

#[test]
fn curve_points_lie_in_span_boxes_and_the_bound_is_below_the_distance() {
    let c = circle([1.0, 2.0, 0.0], [0.0, 0.6, 0.8], 3.0).unwrap();
    let hulls = SpanHulls::of_curve(&c).unwrap();
    let mut seed = 3;
    for _ in 0..500 {
        let u = lcg(&mut seed);
        assert!(hulls.distance_bound(c.point(u)) <= 1e-13);
        let x = [0, 1, 2].map(|_| (lcg(&mut seed) - 0.5) * 12.0);
        let d = closest_point_on_curve(&c, x).distance;
        assert!(hulls.distance_bound(x) <= d + 1e-12);
    }
}

#[test]
fn no_hulls_without_positive_weights() {
    let mut s = bumped_patch();
    s.weights[17] = -0.5;
    assert!(SpanHulls::of_surface(&s).is_none());
    s.weights[17] = f64::NAN;
    assert!(SpanHulls::of_surface(&s).is_none());
}
