//! Feature edges: the rim of a cylinder standing on a plane (a circle) and on a slanted plane
//! (an ellipse), placed by arc length along the intersection.

use std::collections::BTreeMap;
use std::f64::consts::PI;

use super::*;
use crate::{
    associate_boundary, place_boundary_nodes_with, AssociationRule, BoundaryNodeStrategy,
    BoundaryTargets, PlacementOptions,
};
use hocurve_mesh::{Element, HighOrderMesh, LinearMesh, PhysicalGroup, Shape};
use hocurve_nodes::{gauss_legendre, NodeFamily};
use hocurve_nurbs::shapes::{circle, cylinder, AnalyticShape};
use hocurve_nurbs::vec3::{norm, sub};
use hocurve_nurbs::{GeometricEntity, NurbsSurface};

/// The plane z = slope · x as a bilinear patch over [−2, 2]².
fn plane(slope: f64) -> NurbsSurface {
    let corner = |x: f64, y: f64| [x, y, slope * x];
    hocurve_nurbs::shapes::bilinear_patch([
        [corner(-2.0, -2.0), corner(-2.0, 2.0)],
        [corner(2.0, -2.0), corner(2.0, 2.0)],
    ])
    .expect("plane")
}

/// The unit cylinder about z between z = −2 and 2, and the plane z = slope · x; with the rim
/// circle as a curve entity when `with_rim` (only meaningful for slope 0).
fn model(slope: f64, with_rim: bool) -> GeometryModel {
    let mut cyl = GeometricEntity::new(
        "cylinder",
        "test",
        EntityGeometry::Surface(
            cylinder([0.0; 3], [0.0, 0.0, 1.0], 1.0, (-2.0, 2.0)).expect("cyl"),
        ),
    );
    cyl.analytic = Some(AnalyticShape::new_cylinder([0.0; 3], [0.0, 0.0, 1.0], 1.0).expect("cyl"));
    let mut entities = vec![
        cyl,
        GeometricEntity::new("plane", "test", EntityGeometry::Surface(plane(slope))),
    ];
    if with_rim {
        let mut rim = GeometricEntity::new(
            "rim",
            "test",
            EntityGeometry::Curve(circle([0.0; 3], [0.0, 0.0, 1.0], 1.0).expect("circle")),
        );
        rim.analytic = Some(AnalyticShape::new_circle([0.0; 3], [0.0, 0.0, 1.0], 1.0).expect("c"));
        entities.push(rim);
    }
    GeometryModel::new(entities, None)
}

/// A can of `n` prisms about the z axis: bottom triangles on the plane z = slope · x
/// ("plane"), side quads on the cylinder ("cylinder"), top at z = 1.5 (left straight).
/// Vertices: 0 bottom centre, 1..=n the rim, n+1..=2n the top ring, 2n+1 the top centre.
fn can(n: usize, slope: f64) -> LinearMesh {
    let mut vertices = vec![[0.0; 3]];
    let angle = |i: usize| 2.0 * PI * i as f64 / n as f64;
    for i in 0..n {
        let (s, c) = angle(i).sin_cos();
        vertices.push([c, s, slope * c]);
    }
    for i in 0..n {
        let (s, c) = angle(i).sin_cos();
        vertices.push([c, s, 1.5]);
    }
    vertices.push([0.0, 0.0, 1.5]);
    let rim = |i: usize| (1 + i % n) as u32;
    let top = |i: usize| (1 + n + i % n) as u32;
    let centre_top = (2 * n + 1) as u32;
    let mut cells = vec![];
    let mut facets = vec![];
    for i in 0..n {
        cells.push(Element {
            kind: Shape::Prism,
            vertices: vec![0, rim(i), rim(i + 1), centre_top, top(i), top(i + 1)],
            entity: 1,
        });
        facets.push(Element {
            kind: Shape::Tri,
            vertices: vec![0, rim(i + 1), rim(i)],
            entity: 1,
        });
        facets.push(Element {
            kind: Shape::Quad,
            vertices: vec![rim(i), rim(i + 1), top(i + 1), top(i)],
            entity: 2,
        });
    }
    let mut entity_physicals = BTreeMap::new();
    entity_physicals.insert((2, 1), vec![1]);
    entity_physicals.insert((2, 2), vec![2]);
    LinearMesh {
        dim: 3,
        vertices,
        cells,
        facets,
        physical_groups: vec![
            PhysicalGroup {
                dim: 2,
                tag: 1,
                name: "plane".into(),
            },
            PhysicalGroup {
                dim: 2,
                tag: 2,
                name: "cylinder".into(),
            },
        ],
        entity_physicals,
        vertex_tags: Vec::new(),
        cell_tags: Vec::new(),
        facet_tags: Vec::new(),
    }
}

/// Length of the rim z = slope · x on the unit cylinder from angle a to angle b.
fn rim_length(slope: f64, a: f64, b: f64) -> f64 {
    let rule = gauss_legendre(20);
    let pieces = 16;
    let h = (b - a) / pieces as f64;
    let mut sum = 0.0;
    for k in 0..pieces {
        let (lo, hi) = (a + k as f64 * h, a + (k + 1) as f64 * h);
        for (&x, &w) in rule.points.iter().zip(&rule.weights) {
            let t = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
            let ds = (1.0 + (slope * t.sin()).powi(2)).sqrt();
            sum += 0.5 * (hi - lo) * w * ds;
        }
    }
    sum
}

/// For every rim edge: the largest distance of its nodes from the cylinder and the plane,
/// and the largest error of their arc-length fractions against the reference distribution.
fn check_rim(mesh: &HighOrderMesh, t: &BoundaryTargets, n: usize, slope: f64) -> (f64, f64) {
    let p = mesh.order;
    let line: Vec<f64> = mesh
        .family
        .interior_nodes(Shape::Line, p)
        .iter()
        .map(|(x, _)| x[0])
        .collect();
    let (mut off, mut fraction_error): (f64, f64) = (0.0, 0.0);
    for i in 0..n {
        let (u, v) = ((1 + i) as u32, (1 + (i + 1) % n) as u32);
        let (a, b) = (u.min(v), u.max(v));
        let e = mesh.topology().find_edge(a, b).expect("rim edge");
        let first = mesh.layout().edge_first_node(e, p) as u32;
        let angle_of = |x: [f64; 3]| x[1].atan2(x[0]);
        let (ta, mut tb) = (angle_of(t.targets[&a]), angle_of(t.targets[&b]));
        // The short way from a to b.
        if tb - ta > PI {
            tb -= 2.0 * PI;
        } else if ta - tb > PI {
            tb += 2.0 * PI;
        }
        let total = rim_length(slope, ta, tb);
        for (k, &xi) in line.iter().enumerate() {
            let x = t.targets[&(first + k as u32)];
            off = off
                .max(((x[0] * x[0] + x[1] * x[1]).sqrt() - 1.0).abs())
                .max((x[2] - slope * x[0]).abs());
            let mut tx = angle_of(x);
            while tx - ta > PI {
                tx -= 2.0 * PI;
            }
            while ta - tx > PI {
                tx += 2.0 * PI;
            }
            fraction_error = fraction_error.max((rim_length(slope, ta, tx) / total - xi).abs());
        }
    }
    (off, fraction_error)
}

#[test]
fn rim_nodes_lie_on_both_surfaces_at_the_arc_length_fractions() {
    let n = 8;
    for (slope, with_rim) in [(0.0, false), (0.0, true), (0.5, false)] {
        let linear = can(n, slope);
        let geometry = model(slope, with_rim);
        let assoc = associate_boundary(&linear, &geometry, AssociationRule::NameOnly, Some(1e-9))
            .expect("associates");
        assert_eq!(assoc.unassociated, 0);
        for family in [NodeFamily::GaussLobatto, NodeFamily::Equispaced] {
            for p in [2, 4, 5] {
                let mesh = HighOrderMesh::from_linear(&linear, p, family).expect("mesh");
                let t = place_boundary_nodes_with(
                    &mesh,
                    &geometry,
                    &assoc,
                    &PlacementOptions::new(BoundaryNodeStrategy::Geodesic),
                )
                .expect("placed");
                if with_rim {
                    assert_eq!((t.feature_edges_on_curves, t.feature_edges_traced), (n, 0));
                } else {
                    assert_eq!((t.feature_edges_on_curves, t.feature_edges_traced), (0, n));
                }
                let (off, fraction_error) = check_rim(&mesh, &t, n, slope);
                println!(
                    "slope {slope}, rim curve {with_rim}, {family:?} p = {p}: off {off:.1e}, fractions {fraction_error:.1e}"
                );
                assert!(off < 1e-12, "{off}");
                assert!(fraction_error < 1e-8, "{fraction_error}");
                assert!(t.max_geometry_distance < 1e-12);
                assert_eq!(t.corrected_edges, 0);
            }
        }
    }
}

/// A trace asked again comes from the kept ones, bit for bit what tracing gives; another
/// model's curve is never handed out for the same key.
#[test]
fn kept_feature_traces_are_the_traced_curves() {
    let geometry = model(0.0, false);
    let (a, b) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let traces = FeatureTraces::default();
    let fresh = FeatureCurve::between(&geometry, &[0, 1], a, b, 1e-12);
    let first = traces.between(&geometry, &[0, 1], a, b, 1e-12);
    let again = traces.between(&geometry, &[0, 1], a, b, 1e-12);
    assert_eq!(traces.len(), 1);
    for curve in [&first, &again] {
        assert_eq!(curve.points, fresh.points);
        for fraction in [0.0, 0.3, 0.5, 1.0] {
            assert_eq!(curve.at(fraction), fresh.at(fraction));
        }
    }
    // Another end point: a new trace.
    traces.between(&geometry, &[0, 1], a, [-1.0, 0.0, 0.0], 1e-12);
    assert_eq!(traces.len(), 2);
    // The same key on another model (the same surfaces, and the rim as a curve entity):
    // traced on that model, which finds its curve.
    assert!(!first.on_model_curve());
    let other = model(0.0, true);
    let on_other = traces.between(&other, &[0, 1], a, b, 1e-12);
    assert!(on_other.on_model_curve());
    assert_eq!(traces.len(), 2);
}

#[test]
fn a_traced_circle_has_the_exact_length() {
    let geometry = model(0.0, false);
    let (a, b) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let curve = FeatureCurve::between(&geometry, &[0, 1], a, b, 1e-12);
    assert!(
        (curve.length() - 0.5 * PI).abs() < 1e-14,
        "{}",
        curve.length() - 0.5 * PI
    );
    // Tangents at the ends: along the circle.
    let start = curve.end_tangent(false).expect("tangent");
    let end = curve.end_tangent(true).expect("tangent");
    assert!(norm(sub(start, [0.0, 1.0, 0.0])) < 1e-6, "{start:?}");
    assert!(norm(sub(end, [1.0, 0.0, 0.0])) < 1e-6, "{end:?}");
    // The foot point of a point off the rim is the radial one.
    let x = foot_on_intersection(&geometry, &[0, 1], [0.3, 0.4, 0.2]);
    assert!(norm(sub(x, [0.6, 0.8, 0.0])) < 1e-14, "{x:?}");
}

/// A torus (major radius 1, tube 0.5) lying on the plane z = 0, its tube `gap` above it: the
/// two surfaces are tangent along the unit circle and meet only to `gap`, as two tangent
/// B-spline faces of a CAD part meet only to the modeller's tolerance.
fn torus_on_plane(gap: f64) -> GeometryModel {
    let centre = [0.0, 0.0, 0.5 + gap];
    let mut torus = GeometricEntity::new(
        "torus",
        "test",
        EntityGeometry::Surface(
            hocurve_nurbs::shapes::torus(centre, [0.0, 0.0, 1.0], 1.0, 0.5).expect("torus"),
        ),
    );
    torus.analytic =
        Some(AnalyticShape::new_torus(centre, [0.0, 0.0, 1.0], 1.0, 0.5).expect("torus"));
    let plane = GeometricEntity::new("plane", "test", EntityGeometry::Surface(plane(0.0)));
    GeometryModel::new(vec![torus, plane], None)
}

#[test]
fn the_seam_of_two_tangent_faces_is_traced_on_the_seam_whether_they_touch_cross_or_leave_a_gap() {
    // Touching exactly, crossing at a grazing angle (two circles 1.4e-5 apart), and meeting
    // only to a gap of 1e-10 (tangent B-spline faces of a CAD part).
    for gap in [0.0, -1e-10, 1e-10] {
        let geometry = torus_on_plane(gap);
        let (a, b) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let curve = FeatureCurve::between(&geometry, &[0, 1], a, b, 1e-12);
        // Alternating projections creep along such a seam (sublinearly where the faces touch),
        // leaving the feet of chord midpoints scattered across it: the length never settled
        // and the trace ran to `MAX_SEGMENTS` foot points (minutes on real B-spline faces).
        let segments = curve.points.len() - 1;
        assert!(segments < 128, "gap {gap}: {segments} segments");
        // Crossing, the faces meet on two circles of radii 1 ± √(2 · 0.5 · |gap|); touching,
        // the seam is fixed only to √(round-off of the offset, 1e-14 of the model size).
        let across = (gap.abs() + 1e-14 * geometry.size()).sqrt();
        assert!(
            (curve.length() - 0.5 * PI).abs() < 0.5 * PI * across,
            "gap {gap}: {}",
            curve.length() - 0.5 * PI
        );
        // Every point, and the nodes placed along it, within the gap of both surfaces.
        let fractions = [0.1, 0.25, 0.5, 0.9];
        let nodes = fractions.iter().map(|&f| curve.at(f));
        for x in curve.points.iter().copied().chain(nodes) {
            let radius = (x[0] * x[0] + x[1] * x[1]).sqrt();
            assert!((radius - 1.0).abs() <= across, "gap {gap}: {x:?}");
            for e in &geometry.entities {
                let d = e.distance(x);
                assert!(
                    d <= gap.abs() + 1e-14,
                    "gap {gap}: {x:?} {d:e} from {}",
                    e.name
                );
            }
        }
    }
}

#[test]
fn a_node_snapped_onto_a_tangent_seam_lands_on_both_faces() {
    // Written nodes interpolated between placed ones are snapped back onto their entities;
    // on the seam where a fillet meets a face tangentially, alternating projections crept
    // (sublinearly) and left such nodes 1e-8 of the model off the faces.
    let geometry = torus_on_plane(0.0);
    let size = geometry.size();
    for x in [[0.9, 0.3, 0.02], [0.1, -1.02, 0.001], [-0.7, -0.69, 0.0]] {
        let y = crate::association::snap_onto(&geometry, &[0, 1], x);
        for e in &geometry.entities {
            let d = e.distance(y);
            assert!(d <= 1e-13 * size, "{x:?} -> {y:?}: {d:e} from {}", e.name);
        }
        let radius = (y[0] * y[0] + y[1] * y[1]).sqrt();
        assert!((radius - 1.0).abs() < 1e-6, "{y:?}");
    }
}

#[test]
fn an_edge_across_two_faces_of_one_cylinder_follows_the_cylinder() {
    // Coaxial holes of stacked plates: two faces on one infinite cylinder, their patches
    // meeting at z = 1. An edge from one to the other "lies on both" everywhere along the
    // cylinder; its nodes must follow the cylinder (the helix through the vertices), not
    // be clamped to where the patches end.
    let face = |name: &str, heights: (f64, f64)| {
        let mut e = GeometricEntity::new(
            name,
            "test",
            EntityGeometry::Surface(cylinder([0.0; 3], [0.0, 0.0, 1.0], 1.0, heights).expect("c")),
        );
        e.analytic =
            Some(AnalyticShape::new_cylinder([0.0; 3], [0.0, 0.0, 1.0], 1.0).expect("cyl"));
        e
    };
    let geometry = GeometryModel::new(
        vec![face("lower", (0.0, 1.0)), face("upper", (1.0, 2.0))],
        None,
    );
    let (a, b) = ([1.0, 0.0, 0.2], [0.0, 1.0, 1.5]);
    let curve = FeatureCurve::between(&geometry, &[0, 1], a, b, 1e-12);
    let middle = curve.at(0.5);
    let radius = (middle[0] * middle[0] + middle[1] * middle[1]).sqrt();
    assert!((radius - 1.0).abs() < 1e-12, "{middle:?}");
    assert!((middle[2] - 0.85).abs() < 1e-3, "{middle:?}");
}

/// A cone standing tangent on a torus (major radius 1, tube 0.25, axis z) along the circle
/// where the tube's normal is at 60° above the equator: radius 1.125, height √3/8; the cone
/// shifted `gap` off the torus along that normal, as OpenCASCADE writes a fillet's torus
/// beside the cone it rounds (apart by 7e-13 in a part's STEP file). The cone is its NURBS
/// alone unless `closed_form`; the file states an uncertainty of 1e-7, as OCC writes.
fn cone_on_torus(gap: f64, closed_form: bool) -> GeometryModel {
    let (sin, cos) = (PI / 3.0).sin_cos();
    // The generator through the tube point (1 + 0.25 cos 60°, 0.25 sin 60°) along its
    // tangent (−sin 60°, cos 60°) meets the axis at the apex; moved up by gap / sin 60°.
    let seam = [1.0 + 0.25 * cos, 0.25 * sin];
    let apex = [0.0, 0.0, seam[1] + seam[0] * cos / sin + gap / sin];
    let (axis, half_angle) = ([0.0, 0.0, -1.0], PI / 3.0);
    let cone_height = apex[2] - seam[1];
    let nurbs = hocurve_nurbs::shapes::cone(apex, axis, half_angle, (0.5 * cone_height, apex[2]))
        .expect("cone");
    let mut cone = GeometricEntity::new("cone", "test", EntityGeometry::Surface(nurbs));
    if closed_form {
        cone.analytic = Some(AnalyticShape::new_cone(apex, axis, half_angle).expect("cone"));
    }
    let mut torus = GeometricEntity::new(
        "torus",
        "test",
        EntityGeometry::Surface(
            hocurve_nurbs::shapes::torus([0.0; 3], [0.0, 0.0, 1.0], 1.0, 0.25).expect("torus"),
        ),
    );
    torus.analytic =
        Some(AnalyticShape::new_torus([0.0; 3], [0.0, 0.0, 1.0], 1.0, 0.25).expect("torus"));
    GeometryModel::new(vec![cone, torus], Some(1e-7))
}

#[test]
fn a_seam_where_a_cone_touches_a_torus_to_round_off_is_traced_on_both() {
    // The offset across such a seam has a minimum of ~gap, above round-off: its vertex is
    // the seam, fixed only to √(round-off / curvature) across it. The parabola steps found
    // it but never stopped (waiting for a step below round-off), so the nodes fell back on
    // alternating projections, which crept: 3.5e-3 up the torus, 7.5e-5 off the cone.
    let (radius, height) = (1.0 + 0.25 * (PI / 3.0).cos(), 0.25 * (PI / 3.0).sin());
    for closed_form in [false, true] {
        for gap in [0.0, 7e-13] {
            let geometry = cone_on_torus(gap, closed_form);
            let (a, b) = ([radius, 0.0, height], [0.0, radius, height]);
            let curve = FeatureCurve::between(&geometry, &[0, 1], a, b, 1e-12);
            let nodes: Vec<[f64; 3]> = [0.1, 0.25, 0.5, 0.9].iter().map(|&f| curve.at(f)).collect();
            for x in curve.points.iter().chain(&nodes) {
                for e in &geometry.entities {
                    let d = e.distance(*x);
                    assert!(
                        d <= gap + 1e-13,
                        "closed form {closed_form}, gap {gap}: {x:?} {d:e} from {}",
                        e.name
                    );
                }
                // On the seam circle, to √(1e-14 of the model / the offset's curvature).
                let off = ((x[0].hypot(x[1]) - radius).hypot(x[2] - height)).abs();
                assert!(
                    off < 1e-6,
                    "closed form {closed_form}, gap {gap}: {x:?} {off:e}"
                );
            }
            // Equal fractions of the quarter circle, to the trace's resolution: its length
            // stops converging at the points' own scatter along the seam (~1e-7), after a
            // few halvings, and nodes between its points follow its chords.
            let angle = |x: [f64; 3]| x[1].atan2(x[0]);
            for (f, x) in [0.1, 0.25, 0.5, 0.9].iter().zip(&nodes) {
                assert!((angle(*x) - f * 0.5 * PI).abs() < 1e-3, "{f}: {x:?}");
            }
        }
    }
}

#[test]
fn a_vertex_on_faces_that_stay_close_is_not_slid_along_them() {
    // Ventilator.stp: a vertex 1.5e-7 from a face that blends into its neighbour with a gap
    // of ~1e-7 for millimetres; the seam solver slid it 1.85 mm (seven edge lengths) to
    // where the gap was 1.3e-7. Here: the plane z = 0 and a face above it whose gap is a
    // parabola in x, least at x = 1.4: 1.1e-7 (the file's uncertainty 1e-5 covers it), or
    // touching (no uncertainty stated: the faces meet exactly there, but so nearly parallel
    // that a point 1e-8 off is as good as on the seam).
    let lifted = |z: [f64; 3]| {
        let mut points = Vec::new();
        for (x, z) in [-2.0, 0.0, 2.0].into_iter().zip(z) {
            for y in [-2.0, 2.0] {
                points.push([x, y, z]);
            }
        }
        let knots_u = vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        NurbsSurface::new(
            2,
            1,
            knots_u,
            vec![0.0, 0.0, 1.0, 1.0],
            points,
            vec![1.0; 6],
        )
        .expect("lifted")
    };
    // The third: gap 1.1e-7 + 1e-3 (x − 1.4)², a point 1e-3 from its least gap, within
    // reach (1e4 × 1.11e-7): only the uncertainty rule keeps it where it is.
    let far = [[0.5, 0.2, 0.0], [-0.5, 1.5, 0.0], [-1.9, -0.3, 0.0]];
    let near = [[1.401, 0.2, 0.0], [1.3992, -1.0, 0.0], [1.4009, 1.7, 0.0]];
    let cases = [
        (Some(1e-5), [4e-7, 0.6e-7, 1.2e-7], far),
        (None, [1.156e-7, -0.204e-7, 0.036e-7], far),
        (Some(1e-5), [0.01156011, -0.00203989, 0.00036011], near),
    ];
    for (uncertainty, z, points) in cases {
        let geometry = GeometryModel::new(
            vec![
                GeometricEntity::new("plane", "test", EntityGeometry::Surface(plane(0.0))),
                GeometricEntity::new("lifted", "test", EntityGeometry::Surface(lifted(z))),
            ],
            uncertainty,
        );
        for x in points {
            let y = crate::association::snap_onto(&geometry, &[0, 1], x);
            let moved = norm(sub(y, x));
            // Within the file's uncertainty of both, the point moves at most onto the other
            // face; without one, at most 1e4 times its distance from them.
            let off = geometry.entities[1].distance(x);
            let reach = if uncertainty.is_some() {
                1.01 * off
            } else {
                1e4 * off
            };
            assert!(
                moved <= reach,
                "{uncertainty:?}: {x:?} -> {y:?}, moved {moved:e}"
            );
        }
    }
}

#[test]
fn a_feature_edge_on_a_cad_edge_between_nearly_tangent_faces_lies_on_that_edge() {
    // Ventilator.stp: a blade's B-spline face beside a linear extrusion, ~1e-5 apart and
    // nearly tangent along their common edge; their "intersection" runs anywhere within the
    // gap, and the nodes traced on it were placed edge lengths away from the CAD edge. Here:
    // the plane z = 0 and a face above it with gap 1.1e-7 + 1e-3 (x − 1.4)² (uncertainty
    // 1e-5), their CAD edge the line x = 1.41, where the gap is 2.1e-7; the least gap, where
    // a trace goes, is 0.01 away.
    let points: Vec<[f64; 3]> = [-2.0, 0.0, 2.0]
        .into_iter()
        .zip([0.01156011, -0.00203989, 0.00036011])
        .flat_map(|(x, z)| [[x, -2.0, z], [x, 2.0, z]])
        .collect();
    let lifted = NurbsSurface::new(
        2,
        1,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        points,
        vec![1.0; 6],
    )
    .expect("lifted");
    let line = |x: f64| {
        hocurve_nurbs::NurbsCurve::new(
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![[x, -1.5, 0.0], [x, 1.5, 0.0]],
            vec![1.0; 2],
        )
        .expect("line")
    };
    let mut geometry = GeometryModel::new(
        vec![
            GeometricEntity::new("plane", "test", EntityGeometry::Surface(plane(0.0))),
            GeometricEntity::new("lifted", "test", EntityGeometry::Surface(lifted)),
        ],
        Some(1e-5),
    );
    let edge = |x: f64| hocurve_nurbs::ModelEdge {
        origin: "test".into(),
        curve: line(x),
        faces: vec![0, 1],
    };
    // An edge of the same faces elsewhere is not this one's carrier.
    geometry.edges = vec![edge(1.5), edge(1.41)];
    let (a, b) = ([1.41, -1.0, 0.0], [1.41, 1.0, 0.0]);
    let curve = FeatureCurve::between(&geometry, &[0, 1], a, b, 1e-12);
    assert!(curve.on_model_curve());
    for f in [0.1, 0.25, 0.5, 0.9] {
        let x = curve.at(f);
        let expected = [1.41, -1.0 + 2.0 * f, 0.0];
        assert!(norm(sub(x, expected)) <= 1e-5, "{f}: {x:?}");
        for e in &geometry.entities {
            assert!(e.distance(x) <= 1e-5, "{f}: {x:?} {:e}", e.distance(x));
        }
    }
    // Without it, the edge is traced (no model edge through its vertices).
    geometry.edges = vec![edge(1.5)];
    let traced = FeatureCurve::between(&geometry, &[0, 1], a, b, 1e-12);
    assert!(!traced.on_model_curve());
}
