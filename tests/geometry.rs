//! The geometry pipeline across crates: mesh + JSON/IGES geometry → association → boundary
//! nodes on the true geometry, on the bundled fixtures.

use std::path::PathBuf;

use hocurve::geodesic::{
    associate_boundary, place_boundary_nodes, AssociationRule, BoundaryNodeStrategy,
};
use hocurve::mesh::HighOrderMesh;
use hocurve::nodes::NodeFamily;
use hocurve::nurbs::{iges::read_iges_geometry, read_geometry_json, Naca4};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

#[test]
fn naca_boundary_nodes_from_json_and_from_iges_agree_and_lie_on_the_airfoil() {
    let linear = hocurve::io::read_msh(&fixture("naca0012/naca0012.msh")).unwrap();
    let mesh = HighOrderMesh::from_linear(&linear, 5, NodeFamily::Fekete).unwrap();
    let json = read_geometry_json(&fixture("naca0012/naca0012.json")).unwrap();
    let iges = read_iges_geometry(&fixture("naca0012/naca0012.igs")).unwrap();
    let place = |model, rule| {
        let a = associate_boundary(&linear, model, rule, None).unwrap();
        assert_eq!(a.unassociated, 0);
        place_boundary_nodes(&mesh, model, &a, BoundaryNodeStrategy::Geodesic).unwrap()
    };
    let from_json = place(&json, AssociationRule::NameOnly);
    let from_iges = place(&iges, AssociationRule::NameThenNearest);
    assert_eq!(from_json.targets.len(), from_iges.targets.len());
    assert_eq!(from_json.curved_facets, 90);
    let naca = Naca4::from_digits("0012", 1.0, true).unwrap();
    let mut worst: f64 = 0.0;
    for (n, x) in &from_json.targets {
        let y = from_iges.targets[n];
        worst = worst.max(((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2)).sqrt());
        // Airfoil nodes against the closed form, away from the leading edge where OCC's spline
        // (the IGES) departs from it by ~1e-5.
        if x[0] > 0.01 && x[0] < 1.0 && x[1].abs() < 0.1 {
            let exact = naca.thickness(x[0]);
            assert!((x[1].abs() - exact).abs() < 1e-7, "{x:?}: {}", exact);
        }
    }
    println!("JSON vs IGES boundary nodes differ by at most {worst:.2e}");
    assert!(worst < 1e-3, "{worst}");
}

#[test]
fn sphere_boundary_nodes_from_iges_lie_on_the_unit_sphere() {
    let linear = hocurve::io::read_msh(&fixture("sphere/sphere.msh")).unwrap();
    let mesh = HighOrderMesh::from_linear(&linear, 3, NodeFamily::Fekete).unwrap();
    let iges = read_iges_geometry(&fixture("sphere/sphere.igs")).unwrap();
    let a = associate_boundary(&linear, &iges, AssociationRule::NameThenNearest, None).unwrap();
    assert_eq!(
        a.unassociated, 0,
        "box faces and the sphere are all in the IGES"
    );
    let t = place_boundary_nodes(&mesh, &iges, &a, BoundaryNodeStrategy::Geodesic).unwrap();
    let sphere_group = linear.physical_group("sphere").unwrap().tag;
    let mut on_sphere = 0;
    for (facet, linear_facet) in mesh.facets.iter().zip(&linear.facets) {
        if linear
            .physical_tags(2, linear_facet.entity)
            .contains(&sphere_group)
        {
            for n in &facet.nodes {
                let x = t.targets[n];
                assert!(((x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() - 1.0).abs() < 1e-13);
                on_sphere += 1;
            }
        }
    }
    assert!(on_sphere > 1000);
    assert!(t.max_geometry_distance < 1e-12);
}
