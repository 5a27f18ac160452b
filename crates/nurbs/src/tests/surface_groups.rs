use super::*;
use crate::shapes::{bilinear_patch, circle, cylinder};

/// Faces on one surface are found whatever their patches: two faces of one infinite
/// cylinder (different extents, the closed form's axis turned, as a cone or cylinder
/// written once per face with its seam turned) and two copies of one B-spline are each one
/// surface; a cylinder of another radius, another B-spline and a curve are not.
#[test]
fn faces_on_one_surface_are_grouped_whatever_their_patches() {
    let on_cylinder = |radius: f64, range: (f64, f64)| {
        let mut e = GeometricEntity::new(
            "",
            "",
            EntityGeometry::Surface(cylinder([0.0; 3], [0.0, 0.0, 1.0], radius, range).unwrap()),
        );
        e.analytic =
            Some(AnalyticShape::new_cylinder([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], radius).unwrap());
        e
    };
    let patch = |z: f64| {
        let c = |x: f64, y: f64| [x, y, z * x * y];
        GeometricEntity::new(
            "",
            "",
            EntityGeometry::Surface(
                bilinear_patch([[c(0.0, 0.0), c(0.0, 1.0)], [c(1.0, 0.0), c(1.0, 1.0)]]).unwrap(),
            ),
        )
    };
    let curve = GeometricEntity::new(
        "",
        "",
        EntityGeometry::Curve(circle([0.0; 3], [0.0, 0.0, 1.0], 1.0).unwrap()),
    );
    let entities = vec![
        on_cylinder(1.0, (0.0, 1.0)),
        patch(1.0),
        on_cylinder(1.0, (2.0, 3.0)),
        on_cylinder(1.1, (0.0, 1.0)),
        patch(1.0),
        curve,
        patch(2.0),
    ];
    let twins = same_surfaces(&entities);
    assert_eq!(
        twins,
        [
            vec![0, 2],
            vec![1, 4],
            vec![0, 2],
            vec![3],
            vec![1, 4],
            vec![],
            vec![6]
        ]
    );
}
