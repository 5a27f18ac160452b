//! Tests of the crate on the bundled fixtures and analytic shapes.

use std::path::PathBuf;

use hocurve_mesh::LinearMesh;
use hocurve_nurbs::shapes::{sphere, AnalyticShape};
use hocurve_nurbs::{EntityGeometry, GeometricEntity, GeometryModel};

use crate::association::bounding_box_diagonal;
use crate::{associate_boundary, AssociationRule, GeodesicError};

pub(crate) fn fixture(path: &str) -> LinearMesh {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    hocurve_io::read_msh(&root.join(path)).expect("fixture reads")
}

pub(crate) fn sphere_model(name: &str, radius: f64) -> GeometryModel {
    let mut e = GeometricEntity::new(
        name,
        "test",
        EntityGeometry::Surface(sphere([0.0; 3], radius).expect("sphere")),
    );
    e.analytic = Some(AnalyticShape::new_sphere([0.0; 3], radius).expect("sphere"));
    GeometryModel { entities: vec![e] }
}

fn group_facets(mesh: &LinearMesh, name: &str) -> Vec<bool> {
    let tag = mesh.physical_group(name).expect("group").tag;
    mesh.facets
        .iter()
        .map(|f| mesh.physical_tags(2, f.entity).contains(&tag))
        .collect()
}

#[test]
fn sphere_facets_associate_by_name_and_vertices_land_on_the_sphere() {
    let mesh = fixture("sphere/sphere.msh");
    let on_sphere = group_facets(&mesh, "sphere");
    let a = associate_boundary(
        &mesh,
        &sphere_model("sphere", 1.0),
        AssociationRule::NameOnly,
        None,
    )
    .expect("associates");
    assert_eq!(a.by_name, on_sphere.iter().filter(|&&b| b).count());
    assert_eq!(a.by_proximity, 0);
    assert_eq!(a.unassociated, mesh.facets.len() - a.by_name);
    for (facet, s) in a.facet_entity.iter().zip(&on_sphere) {
        assert_eq!(facet.is_some(), *s);
    }
    assert!((a.tolerance - 1e-4 * bounding_box_diagonal(&mesh.vertices)).abs() < 1e-18);
    for x in a.vertex_targets.values() {
        let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        assert!((r - 1.0).abs() < 1e-15);
    }
    // Gmsh put the vertices on the sphere to its own precision; the move is that small.
    assert!(a.max_vertex_move < 1e-8, "{}", a.max_vertex_move);
}

#[test]
fn without_matching_names_the_nearest_surface_within_the_tolerance_is_taken() {
    let mesh = fixture("sphere/sphere.msh");
    let on_sphere = group_facets(&mesh, "sphere");
    let model = sphere_model("ball", 1.0);
    let none = associate_boundary(&mesh, &model, AssociationRule::NameOnly, None).expect("ok");
    assert_eq!(none.by_name + none.by_proximity, 0);
    let a = associate_boundary(&mesh, &model, AssociationRule::NameThenNearest, None).expect("ok");
    assert_eq!(a.by_name, 0);
    for (facet, s) in a.facet_entity.iter().zip(&on_sphere) {
        assert_eq!(
            facet.is_some(),
            *s,
            "far-field facets are 2 away from the sphere"
        );
    }
    // A sphere slightly larger than the tolerance: nothing is associated.
    let off = sphere_model("ball", 1.0 + 2.0 * a.tolerance);
    let b = associate_boundary(&mesh, &off, AssociationRule::NameThenNearest, None).expect("ok");
    assert_eq!(b.by_proximity, 0);
    assert_eq!(b.unassociated, mesh.facets.len());
}

#[test]
fn a_named_entity_that_misses_the_vertices_is_an_error_naming_the_vertex() {
    let mesh = fixture("sphere/sphere.msh");
    let err = associate_boundary(
        &mesh,
        &sphere_model("sphere", 1.01),
        AssociationRule::NameOnly,
        None,
    )
    .expect_err("vertices are 0.01 off");
    match &err {
        GeodesicError::VertexOffGeometry {
            entity, distance, ..
        } => {
            assert_eq!(entity, "sphere");
            assert!((distance - 0.01).abs() < 1e-6);
        }
        other => panic!("{other:?}"),
    }
    assert!(err.to_string().contains("vertex"));
    // The same with a generous tolerance moves them.
    let a = associate_boundary(
        &mesh,
        &sphere_model("sphere", 1.01),
        AssociationRule::NameOnly,
        Some(0.02),
    )
    .expect("within tolerance");
    assert!((a.max_vertex_move - 0.01).abs() < 1e-6);
    let nan = associate_boundary(
        &mesh,
        &sphere_model("sphere", 1.0),
        AssociationRule::NameOnly,
        Some(f64::NAN),
    );
    assert!(matches!(nan, Err(GeodesicError::Tolerance(t)) if t.is_nan()));
}

#[test]
fn a_surface_for_a_2d_mesh_is_an_error() {
    let mesh = fixture("naca0012/naca0012.msh");
    let err = associate_boundary(
        &mesh,
        &sphere_model("airfoil", 1.0),
        AssociationRule::NameOnly,
        None,
    )
    .expect_err("a 2D boundary needs curves");
    assert!(
        matches!(err, GeodesicError::EntityDimension { .. }),
        "{err}"
    );
}
