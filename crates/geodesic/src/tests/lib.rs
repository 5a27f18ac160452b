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
    GeometryModel::new(vec![e], None)
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
    let mut mesh = fixture("sphere/sphere.msh");
    // Tags unlike positions, so that the message shows which it used.
    mesh.vertex_tags = (0..mesh.vertices.len() as u64).map(|v| 9000 + v).collect();
    let err = associate_boundary(
        &mesh,
        &sphere_model("sphere", 1.01),
        AssociationRule::NameOnly,
        None,
    )
    .expect_err("vertices are 0.01 off");
    match &err {
        GeodesicError::VertexOffGeometry {
            entity,
            distance,
            vertex,
            tag,
            ..
        } => {
            assert_eq!(entity, "sphere");
            assert!((distance - 0.01).abs() < 1e-6);
            assert_eq!(*tag, 9000 + u64::from(*vertex));
            assert!(
                err.to_string().contains(&format!("node tag {tag} ")),
                "{err}"
            );
        }
        other => panic!("{other:?}"),
    }
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

/// A boundary layer of first height h below the tolerance: the wall's facet is on the
/// circle, the layer's side facet that only touches it (one vertex on it, one h off, h its
/// length) is not, though both its vertices are within the tolerance.
#[test]
fn proximity_leaves_out_a_facet_that_only_touches_the_curve() {
    use hocurve_mesh::{Element, Shape};
    use hocurve_nurbs::shapes::circle;
    use std::collections::BTreeMap;
    let h = 1e-4;
    let on = |t: f64| [t.cos(), t.sin(), 0.0];
    let segment = |a: u32, b: u32| Element {
        kind: Shape::Line,
        vertices: vec![a, b],
        entity: 1,
    };
    let mesh = LinearMesh {
        dim: 2,
        vertices: vec![on(0.0), on(0.05), [1.0 + h, 0.0, 0.0], [-1.0, -1.0, 0.0]],
        cells: Vec::new(),
        facets: vec![segment(0, 1), segment(0, 2)],
        physical_groups: Vec::new(),
        entity_physicals: BTreeMap::new(),
        vertex_tags: Vec::new(),
        cell_tags: Vec::new(),
        facet_tags: Vec::new(),
    };
    let model = GeometryModel::new(
        vec![GeometricEntity::new(
            "wall",
            "test",
            EntityGeometry::Curve(circle([0.0; 3], [0.0, 0.0, 1.0], 1.0).expect("circle")),
        )],
        None,
    );
    let tolerance = 1e-4 * bounding_box_diagonal(&mesh.vertices);
    assert!(h < tolerance, "the case needs h within the tolerance");
    let a = associate_boundary(&mesh, &model, AssociationRule::NameThenNearest, None).expect("ok");
    assert_eq!(a.facet_entity, [Some(0), None]);
    assert_eq!(a.by_proximity, 1);
    assert!(!a.vertex_targets.contains_key(&2));
    // A facet along the curve whose vertices are off it by a CAD–mesh mismatch (1e-6, far
    // below a tenth of its length) is taken, and its vertices are moved onto the circle.
    let mut close = mesh.clone();
    close.vertices[0] = [1.0 + 1e-6, 0.0, 0.0];
    let b = associate_boundary(&close, &model, AssociationRule::NameThenNearest, None).expect("ok");
    assert_eq!(b.facet_entity, [Some(0), None]);
    assert!((b.max_vertex_move - 1e-6).abs() < 1e-12);
}

#[test]
fn a_surface_for_a_2d_mesh_is_an_error() {
    let mut mesh = fixture("naca0012/naca0012.msh");
    mesh.facet_tags = (0..mesh.facets.len() as u64).map(|f| 7000 + f).collect();
    let err = associate_boundary(
        &mesh,
        &sphere_model("airfoil", 1.0),
        AssociationRule::NameOnly,
        None,
    )
    .expect_err("a 2D boundary needs curves");
    assert!(
        matches!(err, GeodesicError::EntityDimension { facet_tag, .. } if facet_tag >= 7000),
        "{err}"
    );
    assert!(
        err.to_string().contains("facet with element tag 70"),
        "{err}"
    );
}

mod placement {
    use super::*;
    use crate::{place_boundary_nodes, BoundaryNodeStrategy};
    use hocurve_mesh::{Element, HighOrderMesh, PhysicalGroup, Shape};
    use hocurve_nodes::{NodeFamily, ReferenceNodes};
    use hocurve_nurbs::shapes::circle;
    use hocurve_nurbs::vec3::{distance, dot, norm, sub};
    use std::collections::BTreeMap;

    fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
        let d = dot(a, b) / (norm(a) * norm(b));
        d.clamp(-1.0, 1.0).acos()
    }

    /// For every curved facet edge: the fractions of the edge's interior nodes along it
    /// (measured by `along` from the facet's local vertex i), next to the reference ones.
    fn edge_fractions(
        mesh: &HighOrderMesh,
        curved: &[bool],
        targets: &BTreeMap<u32, [f64; 3]>,
        along: impl Fn([f64; 3], [f64; 3]) -> f64,
    ) -> Vec<(f64, f64)> {
        let mut out = vec![];
        for (facet, &c) in mesh.facets.iter().zip(curved) {
            if !c {
                continue;
            }
            let shape = facet.kind;
            let r = ReferenceNodes::new(shape, mesh.order, mesh.family);
            let edges: Vec<[usize; 2]> = if shape == Shape::Line {
                vec![[0, 1]]
            } else {
                shape.edges().to_vec()
            };
            for (n, (xi, ent)) in facet.nodes.iter().zip(r.points().iter().zip(r.entities())) {
                let (i, j) = match (shape, *ent) {
                    (Shape::Line, hocurve_nodes::NodeEntity::Interior(_)) => (0, 1),
                    (_, hocurve_nodes::NodeEntity::Edge { edge, .. }) => {
                        (edges[edge][0], edges[edge][1])
                    }
                    _ => continue,
                };
                let (vi, vj) = (shape.vertices()[i], shape.vertices()[j]);
                let reference = distance(vi, *xi) / distance(vi, vj);
                let (a, b) = (targets[&facet.nodes[i]], targets[&facet.nodes[j]]);
                out.push((along(a, targets[n]) / along(a, b), reference));
            }
        }
        out
    }

    #[test]
    fn sphere_fixture_nodes_lie_on_the_sphere_at_arc_length_fractions() {
        let linear = fixture("sphere/sphere.msh");
        let model = sphere_model("sphere", 1.0);
        let a = associate_boundary(&linear, &model, AssociationRule::NameOnly, None).unwrap();
        for family in [NodeFamily::Fekete, NodeFamily::Equispaced] {
            let mesh = HighOrderMesh::from_linear(&linear, 4, family).unwrap();
            let t =
                place_boundary_nodes(&mesh, &model, &a, BoundaryNodeStrategy::Geodesic).unwrap();
            assert_eq!(t.curved_facets, a.by_name);
            let curved: Vec<bool> = a.facet_entity.iter().map(|e| e.is_some()).collect();
            let expected: std::collections::BTreeSet<u32> = mesh
                .facets
                .iter()
                .zip(&curved)
                .filter(|(_, &c)| c)
                .flat_map(|(f, _)| f.nodes.iter().copied())
                .collect();
            assert_eq!(t.targets.len(), expected.len());
            for x in t.targets.values() {
                assert!((norm(*x) - 1.0).abs() < 1e-13, "{}", norm(*x) - 1.0);
            }
            assert!(t.max_geometry_distance < 1e-13);
            for (f, r) in edge_fractions(&mesh, &curved, &t.targets, angle) {
                assert!((f - r).abs() < 1e-10, "{f} vs {r}");
            }
        }
    }

    /// Max over edges of (largest / smallest) spacing of consecutive nodes relative to the
    /// reference spacing.
    fn spacing_ratio(
        mesh: &HighOrderMesh,
        curved: &[bool],
        targets: &BTreeMap<u32, [f64; 3]>,
    ) -> f64 {
        let fr = edge_fractions(mesh, curved, targets, angle);
        let p = mesh.order;
        let mut worst: f64 = 1.0;
        for chunk in fr.chunks(p - 1) {
            let mut f: Vec<(f64, f64)> = chunk.to_vec();
            f.sort_by(|a, b| a.1.total_cmp(&b.1));
            f.insert(0, (0.0, 0.0));
            f.push((1.0, 1.0));
            let ratios: Vec<f64> = f
                .windows(2)
                .map(|w| (w[1].0 - w[0].0) / (w[1].1 - w[0].1))
                .collect();
            let max = ratios.iter().cloned().fold(0.0, f64::max);
            let min = ratios.iter().cloned().fold(f64::INFINITY, f64::min);
            worst = worst.max(max / min);
        }
        worst
    }

    #[test]
    fn geodesic_placement_spaces_nodes_more_evenly_than_projection() {
        let linear = fixture("sphere/sphere.msh");
        let model = sphere_model("sphere", 1.0);
        let a = associate_boundary(&linear, &model, AssociationRule::NameOnly, None).unwrap();
        let mesh = HighOrderMesh::from_linear(&linear, 4, NodeFamily::Equispaced).unwrap();
        let curved: Vec<bool> = a.facet_entity.iter().map(|e| e.is_some()).collect();
        let g = place_boundary_nodes(&mesh, &model, &a, BoundaryNodeStrategy::Geodesic).unwrap();
        let p = place_boundary_nodes(&mesh, &model, &a, BoundaryNodeStrategy::Projection).unwrap();
        let (rg, rp) = (
            spacing_ratio(&mesh, &curved, &g.targets),
            spacing_ratio(&mesh, &curved, &p.targets),
        );
        println!("sphere p = 4 spacing ratio max/min: geodesic {rg:.6}, projection {rp:.6}");
        assert!(rg < 1.0 + 1e-8 && rp > rg, "geodesic {rg}, projection {rp}");
        for x in p.targets.values() {
            assert!((norm(*x) - 1.0).abs() < 1e-13);
        }
    }

    #[test]
    fn circle_edges_in_2d_follow_arc_length() {
        let linear = fixture("naca0012/naca0012.msh");
        let mut e = GeometricEntity::new(
            "farfield",
            "test",
            EntityGeometry::Curve(circle([0.5, 0.0, 0.0], [0.0, 0.0, 1.0], 10.0).unwrap()),
        );
        e.analytic =
            Some(AnalyticShape::new_circle([0.5, 0.0, 0.0], [0.0, 0.0, 1.0], 10.0).unwrap());
        let model = GeometryModel::new(vec![e], None);
        let a = associate_boundary(&linear, &model, AssociationRule::NameOnly, None).unwrap();
        assert!(a.by_name > 10);
        let mesh = HighOrderMesh::from_linear(&linear, 5, NodeFamily::Fekete).unwrap();
        let t = place_boundary_nodes(&mesh, &model, &a, BoundaryNodeStrategy::Geodesic).unwrap();
        let c = [0.5, 0.0, 0.0];
        let rel = |x: [f64; 3]| sub(x, c);
        for x in t.targets.values() {
            assert!((norm(rel(*x)) - 10.0).abs() < 1e-13 * 10.0);
        }
        let curved: Vec<bool> = a.facet_entity.iter().map(|e| e.is_some()).collect();
        let fr = edge_fractions(&mesh, &curved, &t.targets, |a, b| angle(rel(a), rel(b)));
        assert_eq!(fr.len(), a.by_name * 4);
        for (f, r) in fr {
            assert!((f - r).abs() < 1e-10, "{f} vs {r}");
        }
    }

    /// One tet whose face (1, 0, 0), (0, 1, 0), (0, 0, 1) lies on the unit sphere's octant.
    fn octant_tet() -> LinearMesh {
        let mut entity_physicals = BTreeMap::new();
        entity_physicals.insert((2, 1), vec![7]);
        LinearMesh {
            dim: 3,
            vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            cells: vec![Element {
                kind: Shape::Tet,
                vertices: vec![0, 1, 2, 3],
                entity: 1,
            }],
            facets: vec![Element {
                kind: Shape::Tri,
                vertices: vec![1, 2, 3],
                entity: 1,
            }],
            physical_groups: vec![PhysicalGroup {
                dim: 2,
                tag: 7,
                name: "sphere".into(),
            }],
            entity_physicals,
            vertex_tags: Vec::new(),
            cell_tags: Vec::new(),
            facet_tags: Vec::new(),
        }
    }

    #[test]
    fn an_equilateral_spherical_triangle_gets_a_symmetric_node_pattern() {
        let linear = octant_tet();
        let model = sphere_model("sphere", 1.0);
        let a = associate_boundary(&linear, &model, AssociationRule::NameOnly, Some(1e-9)).unwrap();
        for family in [
            NodeFamily::Fekete,
            NodeFamily::Equispaced,
            NodeFamily::GaussLobatto,
            NodeFamily::WarpBlend,
        ] {
            for p in [3, 5, 6] {
                let mesh = HighOrderMesh::from_linear(&linear, p, family).unwrap();
                let t = place_boundary_nodes(&mesh, &model, &a, BoundaryNodeStrategy::Geodesic)
                    .unwrap();
                let points: Vec<[f64; 3]> =
                    mesh.facets[0].nodes.iter().map(|n| t.targets[n]).collect();
                assert_eq!(points.len(), Shape::Tri.num_nodes(p));
                for x in &points {
                    assert!((norm(*x) - 1.0).abs() < 1e-13);
                }
                // The rotation (x, y, z) -> (y, z, x) maps the pattern onto itself, and so does the
                // reflection swapping x and y.
                for map in [
                    |x: [f64; 3]| [x[1], x[2], x[0]],
                    |x: [f64; 3]| [x[1], x[0], x[2]],
                ] {
                    for x in &points {
                        let y = map(*x);
                        let nearest = points
                            .iter()
                            .map(|z| distance(*z, y))
                            .fold(f64::INFINITY, f64::min);
                        assert!(nearest < 1e-8, "{family:?} p={p}: {nearest}");
                    }
                }
            }
        }
    }
}

/// A quarter-round split once: a triangle through the arc's two ends and its middle has every
/// vertex on the rim where the plane z = 0 meets the unit cylinder, so on both surfaces; it
/// lies in the plane (its centre a sagitta inside the cylinder). A triangle up the cylinder's
/// side, two vertices on the rim, is on the cylinder. Listing the cylinder first would have
/// won the tie by vertices alone.
#[test]
fn a_facet_with_every_vertex_on_a_rim_goes_to_the_surface_through_its_centre() {
    use hocurve_mesh::{Element, Shape};
    use hocurve_nurbs::shapes::cylinder;
    use std::collections::BTreeMap;
    use std::f64::consts::FRAC_PI_4;
    let rim = |t: f64, z: f64| [t.cos(), t.sin(), z];
    let triangle = |v: [u32; 3]| Element {
        kind: Shape::Tri,
        vertices: v.to_vec(),
        entity: 1,
    };
    let mesh = LinearMesh {
        dim: 3,
        vertices: vec![
            rim(0.0, 0.0),
            rim(FRAC_PI_4, 0.0),
            rim(2.0 * FRAC_PI_4, 0.0),
            rim(0.0, 0.5),
            [-1.5, -1.5, 1.5],
        ],
        cells: Vec::new(),
        facets: vec![triangle([0, 1, 2]), triangle([0, 3, 1])],
        physical_groups: Vec::new(),
        entity_physicals: BTreeMap::new(),
        vertex_tags: Vec::new(),
        cell_tags: Vec::new(),
        facet_tags: Vec::new(),
    };
    let corner = |x: f64, y: f64| [x, y, 0.0];
    let plane = hocurve_nurbs::shapes::bilinear_patch([
        [corner(-2.0, -2.0), corner(-2.0, 2.0)],
        [corner(2.0, -2.0), corner(2.0, 2.0)],
    ])
    .expect("plane");
    let model = GeometryModel::new(
        vec![
            GeometricEntity::new(
                "cylinder",
                "test",
                EntityGeometry::Surface(
                    cylinder([0.0; 3], [0.0, 0.0, 1.0], 1.0, (-2.0, 2.0)).expect("cylinder"),
                ),
            ),
            GeometricEntity::new("plane", "test", EntityGeometry::Surface(plane)),
        ],
        None,
    );
    let a = associate_boundary(&mesh, &model, AssociationRule::NameThenNearest, None).expect("ok");
    assert_eq!(a.facet_entity, [Some(1), Some(0)]);
    assert_eq!(a.vertex_entities[&1], [0, 1], "on the rim: both surfaces");
    assert_eq!(a.vertex_entities[&3], [0]);
}

/// Two CAD faces on one infinite cylinder (coaxial holes through two stacked plates): their
/// closed forms are the same surface, so every vertex is on both; the facet goes to the face
/// whose bounded patch holds it, not to the first listed — whose chart would clamp the
/// facet's parameters to its own end.
#[test]
fn a_facet_on_one_of_two_coaxial_faces_goes_to_the_face_that_holds_it() {
    use hocurve_mesh::{Element, Shape};
    use hocurve_nurbs::shapes::{cylinder, AnalyticShape};
    use std::collections::BTreeMap;
    let on = |t: f64, z: f64| [t.cos(), t.sin(), z];
    let mesh = LinearMesh {
        dim: 3,
        vertices: vec![on(0.0, 2.2), on(0.6, 2.2), on(0.3, 2.8)],
        cells: Vec::new(),
        facets: vec![Element {
            kind: Shape::Tri,
            vertices: vec![0, 1, 2],
            entity: 1,
        }],
        physical_groups: Vec::new(),
        entity_physicals: BTreeMap::new(),
        vertex_tags: Vec::new(),
        cell_tags: Vec::new(),
        facet_tags: Vec::new(),
    };
    let face = |name: &str, range: (f64, f64)| {
        let mut e = GeometricEntity::new(
            name,
            "test",
            EntityGeometry::Surface(
                cylinder([0.0; 3], [0.0, 0.0, 1.0], 1.0, range).expect("cylinder"),
            ),
        );
        e.analytic = Some(AnalyticShape::new_cylinder([0.0; 3], [0.0, 0.0, 1.0], 1.0).unwrap());
        e
    };
    let model = GeometryModel::new(
        vec![face("lower", (0.0, 1.0)), face("upper", (2.0, 3.0))],
        None,
    );
    let a = associate_boundary(&mesh, &model, AssociationRule::NameThenNearest, None).expect("ok");
    assert_eq!(a.facet_entity, [Some(1)]);
    assert_eq!(a.vertex_entities[&0], [1]);
}

/// Two faces that blend: the cylinder S1 of radius 1 and, inside it, S2 of radius 0.99,
/// tangent to it along the line x = z = 0 (a sharply curved blade face and the fillet it
/// blends into, as in Ventilator.stp). A facet on S1 across the first 0.3 rad has its centre
/// nearer S2 (a sagitta inside S1, less inside S2) but its vertices on S1: the scores tie
/// within `SCORE_TIE`, the vertices decide. A facet whose vertices lie on S2 goes to S2 —
/// unless S1 is the only face within reach of every facet of its mesh entity (Ventilator.stp:
/// a blade face's vertices 3e-6 nearer a face that stays within 1e-5 of it near their edge,
/// but not across the blade: the mesh generator's entity knows the face); where both are
/// within reach of every facet of the entity, all its facets go to the one nearest all their
/// vertices.
#[test]
fn facets_between_faces_that_blend_go_by_their_vertices_then_their_mesh_entity() {
    use hocurve_mesh::{Element, Shape};
    use hocurve_nurbs::shapes::cylinder;
    use std::collections::BTreeMap;
    let d = 0.01;
    // Points on S1 and on S2 at angle t from the tangent line, y along the axes.
    let s1 = |t: f64, y: f64| [t.sin(), y, 1.0 - t.cos()];
    let s2 = |t: f64, y: f64| [(1.0 - d) * t.sin(), y, 1.0 - (1.0 - d) * t.cos() - d];
    let vertices = vec![
        s1(0.0, 0.0),
        s1(0.3, 0.0),
        s1(0.3, 0.4),
        s1(2.0, 0.0),
        s1(2.4, 0.0),
        s1(2.2, 0.4),
        s2(0.3, 1.0),
        s2(0.3, 1.4),
        s2(0.0, 1.2),
        s1(0.0, -1.0),
        s1(0.2, -1.0),
        s1(0.2, -1.3),
    ];
    let triangle = |v: [u32; 3], entity: i32| Element {
        kind: Shape::Tri,
        vertices: v.to_vec(),
        entity,
    };
    let mesh = LinearMesh {
        dim: 3,
        vertices,
        cells: Vec::new(),
        facets: vec![
            triangle([0, 1, 2], 7),
            triangle([3, 4, 5], 8),
            triangle([6, 7, 8], 8),
            triangle([6, 7, 8], 9),
            triangle([9, 10, 11], 9),
        ],
        physical_groups: Vec::new(),
        entity_physicals: BTreeMap::new(),
        vertex_tags: Vec::new(),
        cell_tags: Vec::new(),
        facet_tags: Vec::new(),
    };
    let face = |name: &str, radius: f64| {
        GeometricEntity::new(
            name,
            "test",
            EntityGeometry::Surface(
                cylinder([0.0, 0.0, radius], [0.0, 1.0, 0.0], radius, (-2.0, 2.0))
                    .expect("cylinder"),
            ),
        )
    };
    let model = GeometryModel::new(vec![face("S2", 1.0 - d), face("S1", 1.0)], None);
    // The first facet's centre is nearer S2.
    let centre = [
        (0.3f64.sin()) * 2.0 / 3.0,
        0.4 / 3.0,
        (1.0 - 0.3f64.cos()) * 2.0 / 3.0,
    ];
    let (to_s2, to_s1) = (
        model.entities[0].patch_distance(centre),
        model.entities[1].patch_distance(centre),
    );
    assert!(to_s2 < to_s1 && to_s1 < 2.0 * to_s2, "{to_s2:e} {to_s1:e}");
    let a = associate_boundary(&mesh, &model, AssociationRule::NameThenNearest, Some(0.01))
        .expect("ok");
    // The last facet, on S1 nearer the tangent line, shares its mesh entity with the facet
    // on S2: both faces are within reach of both facets, S2 nearer all their vertices, so
    // both go to S2 (no feature edge between two faces that nearly coincide).
    assert_eq!(
        a.facet_entity,
        [Some(1), Some(1), Some(1), Some(0), Some(0)]
    );
}

/// Parts of an assembly that touch: a nut's face [4, 6]² lies on a plate's face [0, 10]²
/// (both z = 0). The plate's mesh surface has a facet under the nut, on both faces; the
/// nut's mesh surface lies on both faces too. Which face is nearer is round-off (one file
/// of the model measures the plate 4e-14 off, another the nut) and which comes first is the
/// file's order: neither may decide. The plate's facets go to the plate (the only face
/// within reach of all of them), the nut's to the nut (the smaller of the two that are).
#[test]
fn where_parts_touch_facets_go_to_the_same_faces_whatever_the_round_off_and_order() {
    use hocurve_mesh::{Element, Shape};
    use std::collections::BTreeMap;
    let triangle = |v: [u32; 3], entity: i32| Element {
        kind: Shape::Tri,
        vertices: v.to_vec(),
        entity,
    };
    let at = |x: f64, y: f64| [x, y, 0.0];
    let mesh = LinearMesh {
        dim: 3,
        vertices: vec![
            at(0.0, 0.0),
            at(10.0, 0.0),
            at(0.0, 10.0),
            at(4.5, 4.5),
            at(5.5, 4.5),
            at(5.0, 5.5),
            at(4.2, 4.2),
            at(5.8, 4.2),
            at(5.0, 5.8),
        ],
        cells: Vec::new(),
        facets: vec![
            triangle([0, 1, 2], 1),
            triangle([3, 4, 5], 1),
            triangle([6, 7, 8], 2),
        ],
        physical_groups: Vec::new(),
        entity_physicals: BTreeMap::new(),
        vertex_tags: Vec::new(),
        cell_tags: Vec::new(),
        facet_tags: Vec::new(),
    };
    let face = |name: &str, lo: f64, hi: f64, z: f64| {
        let corner = |x: f64, y: f64| [x, y, z];
        let patch = hocurve_nurbs::shapes::bilinear_patch([
            [corner(lo, lo), corner(lo, hi)],
            [corner(hi, lo), corner(hi, hi)],
        ])
        .expect("plane");
        GeometricEntity::new(name, "test", EntityGeometry::Surface(patch))
    };
    for (plate_z, nut_z) in [(0.0, 0.0), (4e-14, 0.0), (0.0, 4e-14)] {
        let plate = face("plate", 0.0, 10.0, plate_z);
        let nut = face("nut", 4.0, 6.0, nut_z);
        for entities in [vec![plate.clone(), nut.clone()], vec![nut, plate]] {
            let model = GeometryModel::new(entities, None);
            let a = associate_boundary(&mesh, &model, AssociationRule::NameThenNearest, None)
                .expect("associates");
            let names: Vec<&str> = a
                .facet_entity
                .iter()
                .map(|e| e.map_or("none", |e| model.entities[e].name.as_str()))
                .collect();
            assert_eq!(
                names,
                ["plate", "plate", "nut"],
                "plate at z = {plate_z:e}, nut at z = {nut_z:e}, {} first",
                model.entities[0].name
            );
        }
    }
}

/// The association of a mesh, and of the mesh with edges split, is the same with the
/// distances kept from an earlier association as without; only the vertices and facet
/// centres not seen before are measured, and another tolerance measures them all again.
#[test]
fn associations_reusing_kept_distances_are_the_same_as_without() {
    use crate::{associate_boundary_reusing, ProximityCache};
    let mesh = fixture("cad/bolted_plate.msh");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/cad");
    let model = hocurve_nurbs::step::read_step_geometry(&root.join("bolted_plate.step"))
        .expect("STEP reads");
    let rule = AssociationRule::NameThenNearest;
    let cache = ProximityCache::default();
    let fresh = associate_boundary(&mesh, &model, rule, None).expect("associates");
    let reused = associate_boundary_reusing(&mesh, &model, rule, None, &cache).expect("ok");
    assert_eq!(reused, fresh);
    // Kept by position: where parts touch, two vertices of their two meshes coincide.
    let positions = |mesh: &LinearMesh, a: &crate::BoundaryAssociation| {
        a.vertex_targets
            .keys()
            .map(|&v| mesh.vertices[v as usize].map(f64::to_bits))
            .collect::<std::collections::BTreeSet<_>>()
            .len()
    };
    let on_boundary = positions(&mesh, &fresh);
    assert!(on_boundary < fresh.vertex_targets.len());
    assert_eq!(cache.kept_rows(), on_boundary);
    let centres = cache.kept_centres();
    assert!(centres >= mesh.facets.len() / 2, "{centres}");
    let same = associate_boundary_reusing(&mesh, &model, rule, None, &cache).expect("ok");
    assert_eq!(same, fresh);
    assert_eq!(
        cache.kept_centres(),
        centres,
        "every centre measured before"
    );
    // Cells' first edges split: new vertices inside, every boundary vertex where it was.
    let edges: Vec<[u32; 2]> = mesh.cells[..40]
        .iter()
        .map(|c| {
            [
                c.vertices[0].min(c.vertices[1]),
                c.vertices[0].max(c.vertices[1]),
            ]
        })
        .collect();
    let (split, count) = mesh.split_edges(&edges);
    assert!(count > 0);
    let again = associate_boundary_reusing(&split, &model, rule, None, &cache).expect("ok");
    assert_eq!(
        again,
        associate_boundary(&split, &model, rule, None).expect("ok")
    );
    assert!(
        positions(&split, &again) > on_boundary,
        "boundary edges split too"
    );
    assert_eq!(cache.kept_rows(), positions(&split, &again));
    let other = associate_boundary_reusing(&mesh, &model, rule, Some(1e-3), &cache).expect("ok");
    assert_eq!(
        other,
        associate_boundary(&mesh, &model, rule, Some(1e-3)).expect("ok")
    );
    assert_eq!(
        cache.kept_rows(),
        on_boundary,
        "kept for another tolerance: cleared"
    );
}
