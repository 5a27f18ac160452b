use super::*;
use crate::shapes::sphere;
use crate::vec3;

#[test]
fn sphere_entity_projects_exactly_and_inverts_to_its_parameter() {
    let mut e = GeometricEntity::new(
        "ball",
        "test",
        EntityGeometry::Surface(sphere([1.0, 0.0, 0.0], 2.0).unwrap()),
    );
    e.analytic = Some(AnalyticShape::new_sphere([1.0, 0.0, 0.0], 2.0).unwrap());
    let x = [4.0, 1.0, -0.5];
    let cp = e.closest_point(x);
    let d = vec3::sub(cp.point, [1.0, 0.0, 0.0]);
    assert!((vec3::norm(d) - 2.0).abs() < 1e-15);
    assert!(vec3::distance(e.point(cp.param), cp.point) < 1e-12);
    let model = GeometryModel::new(vec![e], None);
    assert_eq!(model.index_of("ball"), Some(0));
    assert_eq!(model.counts(), (0, 1));
    assert!(model.entity("cube").is_none());
}

#[test]
fn a_local_projection_from_a_nearby_parameter_finds_the_global_foot() {
    // A sphere without its closed form (as a B-spline face is) and a circle: from the
    // parameter of a nearby point, the local search lands on the foot the global inversion
    // finds, with a parameter that evaluates to it.
    let ball = GeometricEntity::new(
        "ball",
        "test",
        EntityGeometry::Surface(sphere([1.0, 0.0, 0.0], 2.0).unwrap()),
    );
    let ring = GeometricEntity::new(
        "ring",
        "test",
        EntityGeometry::Curve(crate::shapes::circle([0.0; 3], [0.0, 0.0, 1.0], 1.5).unwrap()),
    );
    for e in [&ball, &ring] {
        let (x, nearby) = ([3.5, 1.0, -0.5], [3.45, 1.1, -0.45]);
        let guess = e.closest_point(nearby).param;
        let (foot, param) = e.nearest_point_near(x, guess);
        let global = e.closest_point(x);
        assert!(vec3::distance(foot, global.point) < 1e-12, "{}", e.name);
        assert!(vec3::distance(e.point(param), foot) < 1e-12, "{}", e.name);
    }
}

#[test]
fn span_hulls_prove_far_points_and_are_rebuilt_for_a_replaced_patch() {
    let mut e = GeometricEntity::new(
        "ball",
        "test",
        EntityGeometry::Surface(sphere([0.0; 3], 1.0).unwrap()),
    );
    let x = [10.0, 0.0, 0.0];
    assert!(e.patch_is_farther_than(x, 8.5));
    assert!(!e.patch_is_farther_than(x, 9.0 + 1e-9));
    // The same net size moved onto x: the hulls built for the first sphere would still say
    // "far".
    e.geometry = EntityGeometry::Surface(sphere([9.0, 0.0, 0.0], 1.0).unwrap());
    assert!(!e.patch_is_farther_than(x, 1e-9));
    // Curves too.
    let c = GeometricEntity::new(
        "ring",
        "test",
        EntityGeometry::Curve(crate::shapes::circle([0.0; 3], [0.0, 0.0, 1.0], 1.0).unwrap()),
    );
    assert!(c.patch_is_farther_than([0.0, 0.0, 5.0], 4.5));
    assert!(!c.patch_is_farther_than([1.0, 0.0, 0.0], 1e-12));
}
