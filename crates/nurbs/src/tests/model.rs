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
    let model = GeometryModel { entities: vec![e] };
    assert_eq!(model.index_of("ball"), Some(0));
    assert_eq!(model.counts(), (0, 1));
    assert!(model.entity("cube").is_none());
}
