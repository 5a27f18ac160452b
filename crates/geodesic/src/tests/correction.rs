//! The minimum-angle correction: the Hermite curves of Fig. 4b exactly, and a thin pair of
//! spherical triangles where it triggers.

use std::collections::BTreeMap;

use super::*;
use crate::tests::sphere_model;
use crate::{
    associate_boundary, place_boundary_nodes_with, AssociationRule, BoundaryNodeStrategy,
    BoundaryTargets, PlacementOptions,
};
use hocurve_mesh::{Element, HighOrderMesh, LinearMesh, PhysicalGroup, Shape};
use hocurve_nodes::NodeFamily;
use hocurve_nurbs::vec3::{add, cross, norm, reject, scale, sub, unit};

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    norm(sub(a, b)) <= tol
}

fn second_derivative(c: &HermiteCurve, t: f64) -> [f64; 3] {
    // Central difference of the exact first derivative (a polynomial of degree ≤ 4, so the
    // error is h²/6 · C⁗ ≈ 1e-10 here).
    let h = 1e-5;
    let (a, b) = if t < 0.5 { (t, t + h) } else { (t - h, t) };
    let (da, db) = (c.derivative(a), c.derivative(b));
    // One-sided at the ends, corrected to second order with a third sample.
    let dc = c.derivative(if t < 0.5 { t + 2.0 * h } else { t - 2.0 * h });
    if t < 0.5 {
        scale(
            add(add(scale(da, -3.0), scale(db, 4.0)), scale(dc, -1.0)),
            0.5 / h,
        )
    } else {
        scale(add(add(scale(db, 3.0), scale(da, -4.0)), dc), 0.5 / h)
    }
}

#[test]
fn hermite_curves_take_the_imposed_points_derivatives_and_curvatures() {
    let data = HermiteData {
        start: [0.3, -1.0, 2.0],
        end: [1.7, 0.4, 1.1],
        start_derivative: [1.0, 2.0, -0.5],
        end_derivative: [0.2, 1.1, 0.9],
        start_second: Some([0.5, -3.0, 1.0]),
        end_second: Some([-2.0, 0.7, 0.1]),
    };
    let cases = [
        (None, None, 3),
        (data.start_second, None, 4),
        (None, data.end_second, 4),
        (data.start_second, data.end_second, 5),
    ];
    for (a0, a1, degree) in cases {
        let c = HermiteCurve::new(HermiteData {
            start_second: a0,
            end_second: a1,
            ..data
        });
        assert_eq!(c.degree(), degree);
        assert!(close(c.point(0.0), data.start, 1e-14));
        assert!(close(c.point(1.0), data.end, 1e-14));
        assert!(close(c.derivative(0.0), data.start_derivative, 1e-13));
        assert!(close(c.derivative(1.0), data.end_derivative, 1e-13));
        if let Some(a0) = a0 {
            assert!(close(second_derivative(&c, 0.0), a0, 1e-6), "{degree}");
        }
        if let Some(a1) = a1 {
            assert!(close(second_derivative(&c, 1.0), a1, 1e-6), "{degree}");
        }
        // The same data given from the other end is the same curve run backwards.
        let back = HermiteCurve::new(HermiteData {
            start: data.end,
            end: data.start,
            start_derivative: scale(data.end_derivative, -1.0),
            end_derivative: scale(data.start_derivative, -1.0),
            start_second: a1,
            end_second: a0,
        });
        for k in 0..=10 {
            let t = k as f64 / 10.0;
            assert!(close(c.point(t), back.point(1.0 - t), 1e-14));
        }
    }
    // p = 2: the quadratic takes the imposed derivative at its start, and the other end's
    // follows, 2 (P₁ − P₀) − D₀; reversed, the same curve from the other end.
    let q = HermiteCurve::quadratic(data.start, data.end, data.start_derivative);
    assert_eq!(q.degree(), 2);
    assert!(close(q.point(0.0), data.start, 1e-14));
    assert!(close(q.point(1.0), data.end, 1e-14));
    assert!(close(q.derivative(0.0), data.start_derivative, 1e-14));
    let follows = sub(scale(sub(data.end, data.start), 2.0), data.start_derivative);
    assert!(close(q.derivative(1.0), follows, 1e-14));
    let back = HermiteCurve {
        reversed: true,
        ..HermiteCurve::quadratic(data.end, data.start, scale(follows, -1.0))
    };
    for k in 0..=10 {
        let t = k as f64 / 10.0;
        assert!(close(q.point(t), back.point(t), 1e-14));
    }
    // A cubic with the chord as both derivatives is the straight segment, uniformly.
    let chord = sub(data.end, data.start);
    let line = HermiteCurve::new(HermiteData {
        start_derivative: chord,
        end_derivative: chord,
        start_second: None,
        end_second: None,
        ..data
    });
    assert!(close(
        line.point(0.25),
        add(data.start, scale(chord, 0.25)),
        1e-14
    ));
}

#[test]
fn the_turn_is_the_smallest_that_restores_the_limit_or_splits_the_difference() {
    let n = [0.0, 0.0, 1.0];
    let t = [1.0, 0.0, 0.0];
    let dir = |deg: f64| [deg.to_radians().cos(), deg.to_radians().sin(), 0.0];
    let nb = |deg: f64, correctable| Neighbour {
        tangent: dir(deg),
        far_vertex: dir(deg),
        correctable,
    };
    let limit = 10f64.to_radians();
    let chord = t;
    // A neighbour 4° above (fixed) and one 60° below: turn down by 6°.
    let (min, psi) = vertex_turn(
        t,
        n,
        chord,
        [0.0; 3],
        &[nb(4.0, false), nb(-60.0, false)],
        limit,
    );
    assert!((min.to_degrees() - 4.0).abs() < 1e-12);
    assert!((psi.to_degrees() + 6.0).abs() < 1e-12);
    // The same neighbour but correctable: each turns half the deficit.
    let (_, psi) = vertex_turn(
        t,
        n,
        chord,
        [0.0; 3],
        &[nb(4.0, true), nb(-60.0, false)],
        limit,
    );
    assert!((psi.to_degrees() + 3.0).abs() < 1e-12);
    // Too little room (4° above, 12° below): the bisector.
    let (_, psi) = vertex_turn(
        t,
        n,
        chord,
        [0.0; 3],
        &[nb(4.0, false), nb(-12.0, false)],
        limit,
    );
    assert!((psi.to_degrees() + 4.0).abs() < 1e-12);
    // All angles acceptable: no turn.
    let (min, psi) = vertex_turn(
        t,
        n,
        chord,
        [0.0; 3],
        &[nb(30.0, false), nb(-12.0, false)],
        limit,
    );
    assert_eq!(psi, 0.0);
    assert!((min.to_degrees() - 12.0).abs() < 1e-12);
    // A neighbour crossed by the edge (its face above, its tangent 3° below): angle −3°.
    let crossed = Neighbour {
        tangent: dir(-3.0),
        far_vertex: dir(20.0),
        correctable: false,
    };
    let (min, psi) = vertex_turn(t, n, chord, [0.0; 3], &[crossed], limit);
    assert!((min.to_degrees() + 3.0).abs() < 1e-12);
    assert!((psi.to_degrees() + 13.0).abs() < 1e-12);
}

/// Two spherical triangles A B C (an angle of ~6° at A) and A D B on the unit sphere, each the
/// boundary face of a tet with an inner vertex O, as a 3D mesh.
fn thin_pair() -> (LinearMesh, [u32; 4]) {
    let c = unit([0.6, 0.7, 0.2]).expect("unit");
    let e1 = unit(cross(c, [0.0, 0.0, 1.0])).expect("unit");
    let e2 = cross(c, e1);
    let h = 0.3;
    let on_sphere =
        |s: f64, t: f64| unit(add(c, add(scale(e1, h * s), scale(e2, h * t)))).expect("unit");
    let (a, b, cc, d) = (
        on_sphere(0.0, 0.0),
        on_sphere(1.0, 0.0),
        on_sphere(0.9, 0.1),
        on_sphere(0.5, -0.6),
    );
    let o = scale(on_sphere(0.45, -0.1), 0.6);
    let vertices = vec![a, b, cc, d, o];
    let tet = |mut v: [u32; 4]| {
        let x = |i: u32| vertices[i as usize];
        let vol = dot(
            cross(sub(x(v[1]), x(v[0])), sub(x(v[2]), x(v[0]))),
            sub(x(v[3]), x(v[0])),
        );
        if vol < 0.0 {
            v.swap(1, 2);
        }
        Element {
            kind: Shape::Tet,
            vertices: v.to_vec(),
            entity: 1,
        }
    };
    let cells = vec![tet([4, 0, 1, 2]), tet([4, 0, 3, 1])];
    let tri = |v: [u32; 3]| Element {
        kind: Shape::Tri,
        vertices: v.to_vec(),
        entity: 1,
    };
    let mut entity_physicals = BTreeMap::new();
    entity_physicals.insert((2, 1), vec![7]);
    let mesh = LinearMesh {
        dim: 3,
        vertices: vertices.clone(),
        cells,
        facets: vec![tri([0, 1, 2]), tri([0, 3, 1])],
        physical_groups: vec![PhysicalGroup {
            dim: 2,
            tag: 7,
            name: "sphere".into(),
        }],
        entity_physicals,
        vertex_tags: Vec::new(),
        cell_tags: Vec::new(),
        facet_tags: Vec::new(),
    };
    (mesh, [0, 1, 2, 3])
}

/// Lagrange derivatives at 0 of the 1D nodes `xs`.
fn lagrange_derivatives_at_zero(xs: &[f64]) -> Vec<f64> {
    (0..xs.len())
        .map(|k| {
            let mut sum = 0.0;
            for j in 0..xs.len() {
                if j == k {
                    continue;
                }
                let mut prod = 1.0 / (xs[k] - xs[j]);
                for m in 0..xs.len() {
                    if m != k && m != j {
                        prod *= (0.0 - xs[m]) / (xs[k] - xs[m]);
                    }
                }
                sum += prod;
            }
            sum
        })
        .collect()
}

/// Tangent at vertex `from` of the degree-p interpolant of the edge `from`–`to`'s nodes.
fn discrete_tangent(mesh: &HighOrderMesh, t: &BoundaryTargets, from: u32, to: u32) -> [f64; 3] {
    let p = mesh.order;
    let line: Vec<f64> = mesh
        .family
        .interior_nodes(Shape::Line, p)
        .iter()
        .map(|(x, _)| x[0])
        .collect();
    let e = mesh.topology().find_edge(from, to).expect("edge");
    let first = mesh.layout().edge_first_node(e, p) as u32;
    // Nodes from `from`: fractions from the lower vertex, flipped if `from` is the higher.
    let mut nodes: Vec<(f64, [f64; 3])> = vec![(0.0, t.targets[&from]), (1.0, t.targets[&to])];
    for (k, &f) in line.iter().enumerate() {
        let f = if from < to { f } else { 1.0 - f };
        nodes.push((f, t.targets[&(first + k as u32)]));
    }
    nodes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let xs: Vec<f64> = nodes.iter().map(|n| n.0).collect();
    let w = lagrange_derivatives_at_zero(&xs);
    nodes
        .iter()
        .zip(&w)
        .fold([0.0; 3], |acc, ((_, x), wk)| add(acc, scale(*x, *wk)))
}

/// Angle at `at` between the discrete edges to `u` and to `v`, in the sphere's tangent plane.
fn discrete_angle(mesh: &HighOrderMesh, t: &BoundaryTargets, at: u32, u: u32, v: u32) -> f64 {
    let n = t.targets[&at];
    let du = reject(discrete_tangent(mesh, t, at, u), n);
    let dv = reject(discrete_tangent(mesh, t, at, v), n);
    (dot(du, dv) / (norm(du) * norm(dv)))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

#[test]
fn a_thin_spherical_triangle_gets_its_small_angle_opened_to_the_limit() {
    let (linear, [a, b, c, d]) = thin_pair();
    let model = sphere_model("sphere", 1.0);
    let assoc = associate_boundary(&linear, &model, AssociationRule::NameOnly, Some(1e-9))
        .expect("associates");
    for p in [2, 3, 4, 5, 6] {
        let mesh = HighOrderMesh::from_linear(&linear, p, NodeFamily::Fekete).expect("mesh");
        let place = |limit| {
            let options =
                PlacementOptions::new(BoundaryNodeStrategy::Geodesic).with_min_angle(limit);
            place_boundary_nodes_with(&mesh, &model, &assoc, &options).expect("placed")
        };
        let (off, zero, on) = (place(None), place(Some(0.0)), place(Some(10.0)));
        // Off and zero are the same thing: no correction, nothing measured.
        assert_eq!(off, zero);
        assert_eq!(off.corrected_edges, 0);
        assert_eq!(off.small_angle_edges, 0);
        // The small angle at A (between AB and AC) is found by both edges.
        let min = on.min_edge_angle_degrees.expect("measured");
        assert!((5.0..8.0).contains(&min), "{min}");
        assert_eq!(on.small_angle_edges, 2, "p = {p}");
        for x in on.targets.values() {
            assert!((norm(*x) - 1.0).abs() < 1e-13);
        }
        assert!(on.max_geometry_distance < 1e-13);
        let before = discrete_angle(&mesh, &off, a, b, c);
        let after = discrete_angle(&mesh, &on, a, b, c);
        println!(
            "p = {p}: corrected {:?}, angle BAC {before:.3}° -> {after:.3}°",
            on.corrected_edge_vertices
        );
        if p == 2 {
            // Each quadratic takes the turned tangent at A, its end with the smaller angle,
            // and turns the whole deficit (a neighbour may not turn at A): together they
            // open BAC beyond the limit, up to 2 × 10° − before.
            assert_eq!(
                on.corrected_edge_vertices,
                vec![[a.min(b), a.max(b)], [a.min(c), a.max(c)]]
            );
            assert!(after > 9.5 && after < 20.5 - before, "{before} -> {after}");
            continue;
        }
        assert_eq!(
            on.corrected_edge_vertices,
            vec![[a.min(b), a.max(b)], [a.min(c), a.max(c)]]
        );
        assert_eq!(on.corrected_edges, 2);
        // The two edges turn half the deficit each: together they reach the limit, up to
        // the projection onto the sphere.
        assert!(
            before < 7.0 && after > 9.5 && after < 10.5,
            "{before} -> {after}"
        );
        // The angle on the other side of AB (in A D B) gives up what BAC gained.
        let other_before = discrete_angle(&mesh, &off, a, d, b);
        let other_after = discrete_angle(&mesh, &on, a, d, b);
        assert!(other_after < other_before && other_after > 10.0);
        // Edges away from the small angle are untouched: the nodes of BC, AD and DB agree.
        for (u, v) in [(b, c), (a, d), (d, b)] {
            let e = mesh.topology().find_edge(u, v).expect("edge");
            let first = mesh.layout().edge_first_node(e, p) as u32;
            for n in first..first + p as u32 - 1 {
                assert_eq!(on.targets[&n], off.targets[&n]);
            }
        }
    }
}

/// An edge end on a feature curve is measured in the edge's own surface, and a neighbour
/// there that the edge has crossed (a curved feature edge bulging past it, as a fillet's rim
/// does past a facet's other edge) gets the edge turned back to the limit at every order:
/// the quadratic at p = 2 takes the turned tangent at that end.
#[test]
fn an_edge_crossed_by_a_curved_neighbour_at_its_end_is_turned_back_at_every_order() {
    let model = sphere_model("sphere", 1.0);
    let hocurve_nurbs::EntityGeometry::Surface(surface) = &model.entities[0].geometry else {
        panic!("the sphere is a surface");
    };
    let chart = crate::chart::SurfaceChart::new(surface);
    let on_sphere = |theta: f64, phi: f64| {
        [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ]
    };
    let (a, b) = (on_sphere(1.2, 0.0), on_sphere(1.2, 0.3));
    let end = |vertex: u32, point: [f64; 3], towards: [f64; 3], neighbours: Vec<Neighbour>| {
        let tangent = unit(reject(sub(towards, point), point)).expect("a tangent");
        EdgeEnd {
            vertex,
            point,
            param: chart.project_near(point, [0.1, 0.5]).0,
            tangent,
            neighbours,
        }
    };
    // At a, a fixed neighbour whose face lies 20° to one side of the edge, but whose
    // (curved) tangent leaves a 3° to the other side: the edge has crossed it, angle −3°.
    let t_a = end(0, a, b, Vec::new()).tangent;
    let n_a = a;
    let turned = |deg: f64| {
        add(
            scale(t_a, deg.to_radians().cos()),
            scale(cross(n_a, t_a), deg.to_radians().sin()),
        )
    };
    let neighbour = Neighbour {
        tangent: turned(-3.0),
        far_vertex: add(a, scale(turned(20.0), 0.3)),
        correctable: false,
    };
    let limit = 10f64.to_radians();
    for order in 2..=6 {
        let ends = [end(0, a, b, vec![neighbour]), end(1, b, a, Vec::new())];
        let check = check_edge(&chart, &ends, 0.3, order, limit).expect("tangent planes");
        assert!((check.min_angle.to_degrees() + 3.0).abs() < 1e-6);
        let curve = check.curve.expect("corrected");
        // The new edge leaves a 10° past the neighbour's tangent: turned by −13° about n.
        let d = unit(reject(curve.derivative(0.0), n_a)).expect("a tangent");
        let angle = dot(cross(turned(-3.0), d), n_a).atan2(dot(turned(-3.0), d));
        assert!(
            (angle.to_degrees() + 10.0).abs() < 1e-9,
            "p = {order}: {}",
            angle.to_degrees()
        );
        assert!(close(curve.point(0.0), a, 1e-15) && close(curve.point(1.0), b, 1e-15));
    }
    // At p = 2 the far end's tangent follows the quadratic (turned by φ at b): a neighbour
    // at b half-way into that turn, on the side it turns to, would be crossed (−φ/2, worse
    // than −3°), so the quadratic is not taken; from p = 3 both tangents are imposed.
    let ends = [end(0, a, b, vec![neighbour]), end(1, b, a, Vec::new())];
    let quadratic = check_edge(&chart, &ends, 0.3, 2, limit)
        .and_then(|c| c.curve)
        .expect("corrected");
    let t_b = ends[1].tangent;
    let d_b = unit(reject(scale(quadratic.derivative(1.0), -1.0), b)).expect("a tangent");
    let phi = dot(cross(t_b, d_b), b).atan2(dot(t_b, d_b));
    assert!(phi.abs().to_degrees() > 8.0, "{}", phi.to_degrees());
    let half = add(
        scale(t_b, (0.5 * phi).cos()),
        scale(cross(b, t_b), (0.5 * phi).sin()),
    );
    let at_b = Neighbour {
        tangent: half,
        far_vertex: add(b, scale(half, 0.3)),
        correctable: false,
    };
    for order in 2..=3 {
        let ends = [end(0, a, b, vec![neighbour]), end(1, b, a, vec![at_b])];
        let check = check_edge(&chart, &ends, 0.3, order, limit).expect("tangent planes");
        assert!((check.min_angle.to_degrees() + 3.0).abs() < 1e-6);
        assert_eq!(check.curve.is_some(), order == 3, "p = {order}");
    }
    // Nothing to correct below the limit's reach: p = 1 has no edge nodes.
    let ends = [end(0, a, b, vec![neighbour]), end(1, b, a, Vec::new())];
    assert!(check_edge(&chart, &ends, 0.3, 1, limit)
        .expect("tangent planes")
        .curve
        .is_none());
}
