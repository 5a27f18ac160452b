use super::*;
use hocurve_nurbs::inversion::closest_point_on_surface;
use hocurve_nurbs::shapes::{cylinder, sphere};
use hocurve_nurbs::NurbsSurface;

fn param_of(s: &NurbsSurface, x: [f64; 3]) -> [f64; 2] {
    closest_point_on_surface(s, x).param
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = norm(v);
    [v[0] / n, v[1] / n, v[2] / n]
}

#[test]
fn on_a_sphere_the_path_is_the_great_circle_arc() {
    let s = sphere([0.0; 3], 2.0).expect("sphere");
    let chart = SurfaceChart::new(&s);
    // Pairs: generic, across the seam (u = 0 is the +x meridian), from the pole.
    let pairs = [
        (unit([1.0, 0.3, 0.2]), unit([0.2, 1.0, -0.4])),
        (unit([0.8, -0.3, 0.1]), unit([0.9, 0.35, -0.2])),
        ([0.0, 0.0, 1.0], unit([0.5, 0.4, 0.6])),
        (unit([-0.3, 0.2, -0.9]), unit([0.4, -0.5, -0.7])),
    ];
    for (a, b) in pairs {
        let (xa, xb) = (
            [2.0 * a[0], 2.0 * a[1], 2.0 * a[2]],
            [2.0 * b[0], 2.0 * b[1], 2.0 * b[2]],
        );
        let path = GeodesicPath::between(
            &chart,
            param_of(&s, xa),
            param_of(&s, xb),
            DEFAULT_LENGTH_TOLERANCE,
        );
        let exact = 2.0 * dot(a, b).clamp(-1.0, 1.0).acos();
        assert!(
            ((path.length() - exact) / exact).abs() < 1e-6,
            "{} vs {exact}",
            path.length()
        );
        let n = unit(cross(a, b));
        for x in &path.points {
            assert!(
                dot(*x, n).abs() < 1e-6 * 2.0,
                "off the great-circle plane: {}",
                dot(*x, n)
            );
            assert!((dot(*x, *x).sqrt() - 2.0).abs() < 1e-13);
        }
        // Ends are the given points.
        assert!(
            distance(path.points[0], xa) < 1e-12
                && distance(*path.points.last().unwrap(), xb) < 1e-12
        );
        // Points at fractions: on the sphere and at the right angle from a.
        for k in 1..10 {
            let f = k as f64 / 10.0;
            let (_, x) = path.at_fraction(&chart, f);
            assert!((dot(x, x).sqrt() - 2.0).abs() < 1e-13);
            let angle = dot(unit(x), a).clamp(-1.0, 1.0).acos();
            assert!(
                (angle * 2.0 / exact - f).abs() < 1e-6,
                "{f}: {}",
                angle * 2.0 / exact
            );
        }
    }
}

#[test]
fn on_a_cylinder_the_path_is_the_helix() {
    let (r, h, theta) = (1.5f64, 2.0f64, 1.2f64);
    let s = cylinder([0.0; 3], [0.0, 0.0, 1.0], r, (-1.0, 3.0)).expect("cylinder");
    let chart = SurfaceChart::new(&s);
    let xa = [r, 0.0, 0.0];
    let xb = [r * theta.cos(), r * theta.sin(), h];
    let path = GeodesicPath::between(
        &chart,
        param_of(&s, xa),
        param_of(&s, xb),
        DEFAULT_LENGTH_TOLERANCE,
    );
    let exact = (r * theta).hypot(h);
    assert!(((path.length() - exact) / exact).abs() < 1e-6);
    for x in &path.points {
        let angle = x[1].atan2(x[0]);
        assert!(
            (x[2] / h - angle / theta).abs() < 1e-6,
            "not on the helix: {x:?}"
        );
        assert!((x[0].hypot(x[1]) - r).abs() < 1e-13);
    }
}

#[test]
fn on_a_plane_the_path_is_the_straight_segment() {
    // A bilinear patch of the plane z = 0.5x + 0.25y with a non-uniform parametrisation.
    let s = NurbsSurface::new(
        1,
        2,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            [0.0, 0.0, 0.0],
            [0.0, 0.2, 0.05],
            [0.0, 2.0, 0.5],
            [3.0, 0.0, 1.5],
            [3.0, 0.5, 1.625],
            [3.0, 2.0, 2.0],
        ],
        vec![1.0; 6],
    )
    .expect("patch");
    let chart = SurfaceChart::new(&s);
    let xa = [0.2, 0.3, 0.175];
    let xb = [2.5, 1.7, 1.675];
    let path = GeodesicPath::between(
        &chart,
        param_of(&s, xa),
        param_of(&s, xb),
        DEFAULT_LENGTH_TOLERANCE,
    );
    let exact = distance(xa, xb);
    assert!(((path.length() - exact) / exact).abs() < 1e-12);
    for k in 0..=8 {
        let f = k as f64 / 8.0;
        let (_, x) = path.at_fraction(&chart, f);
        let straight = [
            xa[0] + f * (xb[0] - xa[0]),
            xa[1] + f * (xb[1] - xa[1]),
            xa[2] + f * (xb[2] - xa[2]),
        ];
        assert!(distance(x, straight) < 1e-9, "{f}: {x:?} vs {straight:?}");
    }
}

#[test]
fn brent_finds_the_minimum_of_a_parabola_and_of_a_skewed_function() {
    let t = brent_minimum(|t| (t - 0.123).powi(2) + 1.0, -0.5, 0.5, 1e-12);
    assert!((t - 0.123).abs() < 1e-9);
    let t = brent_minimum(
        |t| (t + 0.3).cosh() + 0.1 * (t + 0.3).powi(4),
        -0.5,
        0.5,
        1e-12,
    );
    assert!((t + 0.3).abs() < 1e-6);
}

#[test]
fn newton_finds_a_root_to_round_off_and_refuses_what_it_cannot_bracket() {
    // g(t) = t³ + t − c has the single root 0.2 for c = 0.208.
    let g = |t: f64| (t * t * t + t - 0.208, 3.0 * t * t + 1.0);
    let t = newton_root(g, -0.5, 0.5).expect("converges");
    assert!((t - 0.2).abs() <= 4.0 * f64::EPSILON, "{t}");
    // The root 0.7 lies outside [−0.5, 0.5]: an iterate leaves the interval.
    assert_eq!(newton_root(|t| (t - 0.7, 1.0), -0.5, 0.5), None);
    // A maximum of the cost (g' < 0) is not taken.
    assert_eq!(newton_root(|t| (-t + 0.1, -1.0), -0.5, 0.5), None);
}

#[test]
fn on_a_torus_the_path_length_is_within_its_tolerance_of_the_limit() {
    // A geodesic on a torus has no closed form: compare with the same path refined to the
    // segment cap, whose length is converged to ~1e-14 (fourth order from 256 segments), on a
    // mesh-edge-like path crossing the tube's parameter lines obliquely.
    let torus = hocurve_nurbs::shapes::torus([0.0; 3], [0.0, 0.0, 1.0], 2.0, 0.5).unwrap();
    let chart = SurfaceChart::new(&torus);
    let (a, b) = (
        param_of(&torus, [2.5, 0.0, 0.0]),
        param_of(&torus, [2.3, 0.45, 0.35]),
    );
    let limit = GeodesicPath::between(&chart, a, b, 0.0).length();
    for tolerance in [1e-6, 1e-8, 1e-10] {
        let path = GeodesicPath::between(&chart, a, b, tolerance);
        let error = (path.length() - limit).abs() / limit;
        assert!(
            error <= tolerance,
            "tolerance {tolerance}: error {error:.2e}"
        );
        assert!(path.points.len() < 257, "stopped before the cap");
    }
}

/// A path between two points of a patch's straight edge runs along that edge, whichever
/// end of the parameter range the edge is at (the IGES export of wing_body has the
/// trailing edge at u = 0, the STEP one at u = u_max). Found: from vertex parameters a
/// rounding off u = 0, the bisector search saw the sign of its slope change between its
/// ends but not between the ends it rebuilt from its midpoint, took the midpoint, and the
/// path ran a quarter chord inside the wing (face nodes beside it 7e-3 off).
#[test]
fn a_path_between_two_points_of_a_straight_patch_edge_runs_along_it() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/cad");
    let iges = hocurve_nurbs::iges::read_iges_geometry(&root.join("wing_body.igs")).unwrap();
    let step = hocurve_nurbs::step::read_step_geometry(&root.join("wing_body.step")).unwrap();
    // The trailing edge from the tip (0.5, −1.6, 0) to (0.5308, −1.1071, 0), on the
    // upper surface (entity 1 of either file).
    let (tip, inboard) = (
        [0.5, -1.6, 0.0],
        [0.530806140575889, -1.107101750785777, 0.0],
    );
    let straight = distance(tip, inboard);
    for (what, model) in [("IGES", &iges), ("STEP", &step)] {
        let e = &model.entities[1];
        let hocurve_nurbs::EntityGeometry::Surface(s) = &e.geometry else {
            panic!("{what}: not a surface");
        };
        let chart = SurfaceChart::new(s);
        let (a, b) = (e.closest_point(tip).param, e.closest_point(inboard).param);
        // The parameters as found, and a rounding either way off the edge's u.
        for nudge in [0.0_f64, 1e-19, -1e-19, 1e-17] {
            let ends = [[a[0] + nudge.abs(), a[1]], [(b[0] + nudge).max(0.0), b[1]]];
            let path = GeodesicPath::between(&chart, ends[0], ends[1], 1e-6);
            assert!((path.length() - straight).abs() < 1e-9 * straight, "{what}");
            for f in [0.25, 0.5, 0.75] {
                let x = path.at_fraction(&chart, f).1;
                let on_edge = [
                    tip[0] + f * (inboard[0] - tip[0]),
                    tip[1] + f * (inboard[1] - tip[1]),
                    0.0,
                ];
                let off = distance(x, on_edge);
                assert!(
                    off < 1e-8,
                    "{what} {nudge:e} at {f}: {x:?} is {off:e} off the edge"
                );
            }
        }
    }
}
