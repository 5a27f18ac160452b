//! Poles of a chart, decided in 3D, and what paths and tangent frames make of them.

use super::*;
use crate::path::GeodesicPath;
use crate::tests::sphere_model;
use crate::vector::{dot, norm, SurfaceFrame};
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
