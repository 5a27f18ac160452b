//! Poles of a chart, decided in 3D, and what paths and tangent frames make of them.

use super::*;
use crate::frame::SurfaceFrame;
use crate::path::GeodesicPath;
use crate::tests::sphere_model;
use hocurve_nurbs::vec3::{cross, distance, dot, norm};
use hocurve_nurbs::EntityGeometry;

fn unit_sphere() -> hocurve_nurbs::GeometryModel {
    sphere_model("sphere", 1.0)
}

fn surface(model: &hocurve_nurbs::GeometryModel) -> &NurbsSurface {
    match &model.entities[0].geometry {
        EntityGeometry::Surface(s) => s,
        EntityGeometry::Curve(_) => panic!("the sphere is a surface"),
    }
}

/// The parameter of a point at height z on the sphere's chart, by inversion.
fn param_of(chart: &SurfaceChart, x: [f64; 3]) -> [f64; 2] {
    chart.project_near(x, [0.3, 0.5]).0
}

#[test]
fn a_point_a_hair_off_a_pole_is_at_the_pole() {
    let model = unit_sphere();
    let chart = SurfaceChart::new(surface(&model));
    let ((_, _), (v0, v1)) = chart.surface.domain();
    for (v, pole) in [(v0, v0), (v1, v1)] {
        for u in [0.0, 0.17, 0.6, 0.93] {
            // Exactly on the degenerate edge, and 1e-9 of the range off it (what point
            // inversion returns for a vertex snapped to the pole).
            let off = v + 1e-9 * (v1 - v0) * if v == v0 { 1.0 } else { -1.0 };
            for w in [v, off] {
                assert_eq!(
                    chart.free_direction_at([u, w]),
                    Some((0, pole)),
                    "u {u} v {w}"
                );
            }
        }
    }
    // A point 1e-3 of the range away is not at the pole.
    assert_eq!(chart.free_direction_at([0.2, v1 - 1e-3 * (v1 - v0)]), None);
    assert_eq!(chart.free_direction_at([0.2, 0.5 * (v0 + v1)]), None);
}

#[test]
fn the_normal_at_a_pole_is_the_surface_normal_whatever_the_parameter() {
    let model = unit_sphere();
    let chart = SurfaceChart::new(surface(&model));
    let ((u0, u1), (v0, v1)) = chart.surface.domain();
    for v in [v0, v1] {
        for k in 0..16 {
            let u = u0 + (u1 - u0) * k as f64 / 16.0;
            let frame = SurfaceFrame::at(&chart, [u, v]).expect("a frame at the pole");
            let x = chart.point([u, v]);
            // On the unit sphere the normal is ±x; |x · n| = 1 to the step's 1e-7.
            assert!(
                (dot(frame.normal, x).abs() - 1.0).abs() < 1e-6,
                "u {u} v {v}: normal {:?} at {x:?}",
                frame.normal
            );
        }
    }
}

#[test]
fn a_path_from_a_pole_leaves_along_the_meridian_of_its_other_end() {
    let model = unit_sphere();
    let chart = SurfaceChart::new(surface(&model));
    let target = {
        let (theta, phi) = (0.4_f64, 2.2_f64);
        [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ]
    };
    let b = param_of(&chart, target);
    for pole in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]] {
        // Inversion at a pole gives an arbitrary u and a v a little off the pole.
        let a = param_of(&chart, pole);
        let path = GeodesicPath::between(&chart, a, b, 1e-10);
        let exact = dot(pole, target).clamp(-1.0, 1.0).acos();
        assert!(
            (path.length() - exact).abs() < 1e-6,
            "length {} vs great circle {exact}",
            path.length()
        );
        let t = path.end_tangent(false).expect("a tangent");
        // The meridian through the target: horizontal, towards the target's azimuth.
        let h = [target[0], target[1], 0.0];
        let cosine = dot(t, h) / norm(h);
        assert!(cosine > 1.0 - 1e-6, "tangent {t:?} vs meridian {h:?}");
    }
}

/// OpenCASCADE's sphere read from IGES: its poles are the ends of a bounded v range
/// (−π/2, π/2). A bisector clamped onto the pole used to make every refinement of a path
/// from the pole collapse onto the pole, leaving one long chord; the path must instead be
/// the great-circle arc, point for point.
#[test]
fn a_path_from_a_pole_at_the_end_of_a_bounded_range_is_the_great_circle() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model =
        hocurve_nurbs::iges::read_iges_geometry(&root.join("fixtures/cad/sphere_coarse.igs"))
            .expect("the OCC sphere-in-box IGES");
    let sphere = model
        .entities
        .iter()
        .find_map(|e| match &e.geometry {
            EntityGeometry::Surface(s) if s.degenerate_edges().iter().any(|&d| d) => Some(s),
            _ => None,
        })
        .expect("the sphere has poles");
    let chart = SurfaceChart::new(sphere);
    let target = {
        let (theta, phi) = (0.9_f64, 0.7_f64);
        [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ]
    };
    for pole in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]] {
        let a = param_of(&chart, pole);
        let b = param_of(&chart, target);
        let path = GeodesicPath::between(&chart, a, b, 1e-10);
        let exact = dot(pole, target).clamp(-1.0, 1.0).acos();
        // IGES carries 10 digits.
        assert!(
            (path.length() - exact).abs() < 1e-6,
            "{} vs {exact}",
            path.length()
        );
        // Every point on the great circle through the pole and the target.
        let normal = {
            let c = cross(pole, target);
            let n = norm(c);
            [c[0] / n, c[1] / n, c[2] / n]
        };
        for x in &path.points {
            assert!(dot(*x, normal).abs() < 1e-6, "{x:?} off the great circle");
        }
        // No collapse (it was one chord of the whole length). The polyline still
        // clusters towards the pole (longest chord: 25 % of the path), which arc-length
        // placement tolerates on the sphere; evening it out is left to do.
        let longest = path
            .lengths
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(0.0, f64::max);
        assert!(longest < 0.3 * exact, "a chord of {longest} in {exact}");
    }
}

/// The OpenCASCADE ellipsoid of the wing-body fixture (a sphere dilated by (2, 0.5, 0.5),
/// a rational B-spline in IGES, poles at (0, 0, ±0.5) ending the bounded v range): a path
/// from the pole used to collapse onto it (255 of 257 points at the pole, then one chord),
/// placing a p = 3 edge's two nodes both near its middle and inverting its tetrahedra.
#[test]
fn a_path_from_the_pole_of_a_b_spline_ellipsoid_does_not_collapse_onto_the_pole() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model = hocurve_nurbs::iges::read_iges_geometry(&root.join("fixtures/cad/wing_body.igs"))
        .expect("the wing-body IGES");
    let ellipsoid = model
        .entities
        .iter()
        .find_map(|e| match &e.geometry {
            EntityGeometry::Surface(s) if s.degenerate_edges().iter().any(|&d| d) => Some(s),
            _ => None,
        })
        .expect("the ellipsoid has poles");
    let chart = SurfaceChart::new(ellipsoid);
    let (pole, other) = ([0.0, 0.0, 0.5], [0.6749, 0.21414, 0.41914]);
    let path = GeodesicPath::between(
        &chart,
        param_of(&chart, pole),
        param_of(&chart, other),
        1e-10,
    );
    let chord = distance(other, pole);
    let longest = path
        .lengths
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(0.0, f64::max);
    assert!(
        longest < 0.5 * path.length(),
        "a chord of {longest} in {}",
        path.length()
    );
    // Longer than the chord, shorter than the collapsed path's 0.72398.
    assert!(
        path.length() > chord && path.length() < 0.7235,
        "{}",
        path.length()
    );
    // Its points on the surface.
    for x in &path.points {
        let e = x[0] * x[0] / 4.0 + x[1] * x[1] / 0.25 + x[2] * x[2] / 0.25;
        assert!((e - 1.0).abs() < 1e-6, "{x:?}");
    }
}

#[test]
fn gauss_newton_reaches_the_foot_and_declines_at_a_pole() {
    let model = unit_sphere();
    let chart = SurfaceChart::new(surface(&model));
    // A point off the sphere, from a guess a few degrees away: the foot is x/|x|.
    let x = [0.9, 0.6, 0.5];
    let r = norm(x);
    let guess = chart.unroll_near(param_of(&chart, [0.8, 0.6, 0.0]), [0.3, 0.5]);
    let uv = chart
        .project_by_gauss_newton(x, guess, 20)
        .expect("converges away from the poles");
    let foot = chart.point(uv);
    assert!(distance(foot, x.map(|c| c / r)) < 1e-13, "{foot:?}");
    // At a pole the first fundamental form is singular.
    let ((_, _), (v0, _)) = chart.surface.domain();
    assert_eq!(
        chart.project_by_gauss_newton([0.0, 0.0, -2.0], [0.3, v0], 20),
        None
    );
}
