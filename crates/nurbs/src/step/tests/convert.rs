use super::*;
use crate::iges::read_iges_geometry;
use crate::step::parse_step;
use crate::vec3::distance;
use crate::NurbsSurface;

fn fixture(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/cad")
        .join(name)
}

/// Points on a surface over a grid of its parameters.
fn samples(s: &NurbsSurface) -> Vec<[f64; 3]> {
    let (u0, u1) = (s.knots_u[0], s.knots_u[s.knots_u.len() - 1]);
    let (v0, v1) = (s.knots_v[0], s.knots_v[s.knots_v.len() - 1]);
    let mut out = Vec::new();
    for i in 0..=12 {
        for j in 0..=12 {
            let u = u0 + (u1 - u0) * i as f64 / 12.0;
            let v = v0 + (v1 - v0) * j as f64 / 12.0;
            out.push(s.point(u, v));
        }
    }
    out
}

/// OpenCASCADE's box, sphere, torus, cylinder and cone: every face converted, the curved
/// ones recognised with their exact sizes, and their NURBS on those shapes to round-off.
#[test]
fn analytic_faces_are_exact() {
    let model = read_step_geometry(&fixture("shapes.step")).unwrap();
    // Box 6 planes, sphere 1, torus 1, cylinder 3, cone 3.
    assert_eq!(model.entities.len(), 14);
    let mut found = (0, 0, 0, 0);
    for e in &model.entities {
        let EntityGeometry::Surface(s) = &e.geometry else {
            panic!("{} is not a surface", e.name)
        };
        assert!(e.origin.starts_with("STEP #"), "{}", e.origin);
        let gap = |f: &dyn Fn([f64; 3]) -> f64| samples(s).into_iter().map(f).fold(0.0, f64::max);
        match e.analytic {
            Some(AnalyticShape::Sphere { center, radius }) => {
                assert_eq!((center, radius), ([0.0; 3], 1.0));
                assert!(gap(&|x| (norm(x) - 1.0).abs()) < 1e-14);
                found.0 += 1;
            }
            Some(AnalyticShape::Torus {
                major_radius,
                minor_radius,
                ..
            }) => {
                assert_eq!((major_radius, minor_radius), (2.0, 0.5));
                let tube = |x: [f64; 3]| {
                    let r = x[0].hypot(x[1]);
                    ((r - 2.0).hypot(x[2]) - 0.5).abs()
                };
                assert!(gap(&tube) < 1e-14);
                found.1 += 1;
            }
            Some(AnalyticShape::Cylinder { radius, axis, .. }) => {
                assert_eq!(radius, 0.3);
                assert!((axis[2] - 1.0).abs() < 1e-15);
                assert!(gap(&|x| (x[0].hypot(x[1]) - 0.3).abs()) < 1e-14);
                // The patch covers the whole side, z ∈ [−2, 2], and a margin.
                let z = samples(s)
                    .iter()
                    .map(|x| x[2])
                    .fold(0.0, |m: f64, z| m.max(z.abs()));
                assert!(z > 2.0 && z < 2.5, "{z}");
                found.2 += 1;
            }
            Some(
                shape @ AnalyticShape::Cone {
                    apex,
                    axis,
                    half_angle,
                },
            ) => {
                // Radius 0.4 at z = 1 down to 0.1 at z = 2, about the axis x = y = 1: the
                // apex where it reaches 0, the nappe opening downwards.
                assert!(e.origin.contains("CONICAL_SURFACE"), "{}", e.origin);
                let slope = 0.291456794478f64.tan();
                assert!(
                    distance(apex, [1.0, 1.0, 1.0 + 0.4 / slope]) < 1e-12,
                    "{apex:?}"
                );
                assert_eq!((axis, half_angle), ([0.0, 0.0, -1.0], 0.291456794478));
                let cone = |x: [f64; 3]| {
                    let r = (x[0] - 1.0).hypot(x[1] - 1.0);
                    (r - (0.4 + (1.0 - x[2]) * slope)).abs()
                };
                assert!(gap(&cone) < 1e-14, "cone gap {:e}", gap(&cone));
                let closed_form = |x: [f64; 3]| shape.closest_point(x).distance;
                assert!(gap(&closed_form) < 1e-14, "{:e}", gap(&closed_form));
                found.3 += 1;
            }
            Some(other) => panic!("unexpected {other:?}"),
            None => assert!(e.origin.contains("PLANE"), "{}", e.origin),
        }
    }
    assert_eq!(found, (1, 1, 1, 1));
}

/// The same models exported as STEP and as IGES give the same kind of model: as many
/// entities, surfaces on the same shapes (the IGES numbers have 10 significant digits).
#[test]
fn step_and_iges_exports_agree() {
    for name in ["sphere_occ", "naca_layers", "naca_layers_2d", "wing_body"] {
        let step = read_step_geometry(&fixture(&format!("{name}.step"))).unwrap();
        let iges = read_iges_geometry(&fixture(&format!("{name}.igs"))).unwrap();
        assert_eq!(step.entities.len(), iges.entities.len(), "{name}");
        let analytic =
            |m: &GeometryModel| m.entities.iter().filter(|e| e.analytic.is_some()).count();
        assert_eq!(analytic(&step), analytic(&iges), "{name}");
        for a in &step.entities {
            // Plane patches are sized by each file's own cover; the wing body's B-spline
            // faces are untrimmed loft surfaces reaching into the body in STEP (its curved
            // meshes are compared by `cargo xtask cad --full`).
            if a.origin.contains("on PLANE") || name == "wing_body" {
                continue;
            }
            // Points of the STEP entity lie on the IGES model.
            let points = match &a.geometry {
                EntityGeometry::Surface(s) => samples(s),
                EntityGeometry::Curve(c) => {
                    let (t0, t1) = c.domain();
                    (0..=40)
                        .map(|k| c.point(t0 + (t1 - t0) * k as f64 / 40.0))
                        .collect()
                }
            };
            for x in points {
                let d = iges
                    .entities
                    .iter()
                    .map(|b| b.closest_point(x).distance)
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    d < 1e-8,
                    "{name} {}: {x:?} is {d:e} from the IGES entity",
                    a.name
                );
            }
        }
    }
}

fn step_text(data: &str) -> String {
    format!("ISO-10303-21;\nHEADER;\nFILE_NAME('t');\nENDSEC;\nDATA;\n{data}ENDSEC;\nEND-ISO-10303-21;\n")
}

#[test]
fn an_arc_edge_runs_between_its_vertices_in_either_sense() {
    // A quarter circle of radius 2 about z from (2, 0, 0) to (0, 2, 0); written with the
    // edge against the circle's sense, it runs from (0, 2, 0) back to (2, 0, 0) the short way.
    for (sense, from, to) in [
        (".T.", [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
        (".F.", [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]),
    ] {
        let (a, b) = if sense == ".T." { (1, 2) } else { (2, 1) };
        let text = step_text(&format!(
            "#1 = CARTESIAN_POINT('',(2.,0.,0.));
#2 = CARTESIAN_POINT('',(0.,2.,0.));
#3 = VERTEX_POINT('',#1);
#4 = VERTEX_POINT('',#2);
#5 = CARTESIAN_POINT('',(0.,0.,0.));
#6 = DIRECTION('',(0.,0.,1.));
#7 = DIRECTION('',(1.,0.,0.));
#8 = AXIS2_PLACEMENT_3D('',#5,#6,#7);
#9 = CIRCLE('',#8,2.);
#10 = EDGE_CURVE('',#{},#{},#9,{sense});
",
            a + 2,
            b + 2
        ));
        let model = geometry_from_step(&parse_step(text.as_bytes()).unwrap()).unwrap();
        let EntityGeometry::Curve(c) = &model.entities[0].geometry else {
            panic!()
        };
        let (t0, t1) = c.domain();
        for (x, y) in [(c.point(t0), from), (c.point(t1), to)] {
            assert!(distance(x, y) < 1e-15, "{sense}: {x:?} != {y:?}");
        }
        let mid = c.point(0.5 * (t0 + t1));
        assert!((norm(mid) - 2.0).abs() < 1e-15 && mid[0] > 1.0 && mid[1] > 1.0);
    }
}

#[test]
fn bad_models_are_refused_with_the_instance_and_line() {
    for (data, what) in [
        ("#1 = ADVANCED_FACE('',(),#2,.T.);\n#2 = OFFSET_SURFACE('',#3,1.,.F.);\n", "#2 (OFFSET_SURFACE, line 7) is not supported"),
        ("#1 = ADVANCED_FACE('',(),#9,.T.);\n", "refers to #9, which is not in the file"),
        ("#1 = CARTESIAN_POINT('',(0.,0.,0.));\n", "nothing to curve onto"),
        (
            "#1 = ADVANCED_FACE('',(),#2,.T.);\n#2 = PLANE('',#3);\n#3 = AXIS2_PLACEMENT_3D('',#4,$,$);\n#4 = CARTESIAN_POINT('',(0.,0.,0.));\n#5 = SHAPE_REPRESENTATION('',(#6),$);\n#6 = MAPPED_ITEM('',#7,#3);\n",
            "a mapped item",
        ),
        (
            // Two representations each placed in the other: a cycle, not a stack overflow.
            "#1 = ADVANCED_FACE('',(),#2,.T.);\n#2 = PLANE('',#3);\n#3 = AXIS2_PLACEMENT_3D('',#4,$,$);\n#4 = CARTESIAN_POINT('',(0.,0.,0.));\n#10 = SHAPE_REPRESENTATION('',(#1),$);\n#11 = SHAPE_REPRESENTATION('',(#3),$);\n#20 = ( REPRESENTATION_RELATIONSHIP('','',#10,#11) REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#22) SHAPE_REPRESENTATION_RELATIONSHIP() );\n#21 = ( REPRESENTATION_RELATIONSHIP('','',#11,#10) REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#22) SHAPE_REPRESENTATION_RELATIONSHIP() );\n#22 = ITEM_DEFINED_TRANSFORMATION('','',#3,#3);\n",
            "deeper than 64",
        ),
        (
            "#1 = ADVANCED_FACE('',(),#2,.T.);\n#2 = SPHERICAL_SURFACE('',#3,-1.);\n#3 = AXIS2_PLACEMENT_3D('',#4,$,$);\n#4 = CARTESIAN_POINT('',(0.,0.,0.));\n",
            "radius",
        ),
    ] {
        let err = geometry_from_step(&parse_step(step_text(data).as_bytes()).unwrap()).unwrap_err();
        let message = err.to_string();
        assert!(message.contains(what), "{message}");
    }
}

/// Lengths in the file's unit become millimetres, as OpenCASCADE (and so Gmsh) reads them:
/// the sphere fixture written in metres and in inches is 1000 and 25.4 times larger.
#[test]
fn lengths_are_read_in_millimetres() {
    let text = std::fs::read_to_string(fixture("sphere_occ.step")).unwrap();
    assert!(text.contains("SI_UNIT(.MILLI.,.METRE.)"));
    let radius = |text: &str| {
        let model = geometry_from_step(&parse_step(text.as_bytes()).unwrap()).unwrap();
        model
            .entities
            .iter()
            .find_map(|e| match e.analytic {
                Some(AnalyticShape::Sphere { radius, .. }) => Some(radius),
                _ => None,
            })
            .unwrap()
    };
    assert_eq!(radius(&text), 1.0);
    assert_eq!(
        radius(&text.replace("SI_UNIT(.MILLI.,.METRE.)", "SI_UNIT($,.METRE.)")),
        1000.0
    );
    // An inch: a conversion-based unit of 25.4 mm (OpenCASCADE's form).
    let inch = text
        .replace(
            "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )",
            "( CONVERSION_BASED_UNIT('INCH',#900001) LENGTH_UNIT() NAMED_UNIT(#900002) )",
        )
        .replace(
            "ENDSEC;\nEND-ISO-10303-21;",
            "#900001 = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#900003);\n#900002 = DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.);\n#900003 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\nENDSEC;\nEND-ISO-10303-21;",
        );
    assert!((radius(&inch) - 25.4).abs() < 1e-12);
}

/// An assembly part placed by a transformation is carried into place as OpenCASCADE reads
/// it (its frame `item_1` onto `item_2`), and a part placed twice gives its faces twice.
#[test]
fn assembly_parts_are_put_in_place() {
    check_the_cone_placed_twice("#622", "#10", "-5.", "");
}

/// A placement is read in the units of its own representation's context, which may differ
/// from the geometry's (Inventor writes a part's placement in inches around its B-rep in
/// millimetres): here the second cone's parent is in centimetres, −0.5 cm = −5 mm.
#[test]
fn a_placement_in_other_units_than_the_geometry_is_converted() {
    check_the_cone_placed_twice(
        "#622",
        "#900022",
        "-0.5",
        "#900020 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.CENTI.,.METRE.) );
#900021 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((#900020)) REPRESENTATION_CONTEXT('','') );
#900022 = SHAPE_REPRESENTATION('',(#900003),#900021);
",
    );
}

/// The same when the placed representation is a part's own shape representation linked to
/// its B-rep by a shape representation relationship written on its own (Pro/E, CATIA and
/// Inventor link parts this way; the AS1 assembly of the CAx-IF's test models). A
/// representation outside the assembly that holds the same B-rep (Pro/E's shape aspects)
/// adds no occurrence.
#[test]
fn a_part_linked_to_its_brep_by_a_simple_relationship_is_put_in_place() {
    check_the_cone_placed_twice(
        "#900010",
        "#10",
        "-5.",
        "#900010 = SHAPE_REPRESENTATION('',(#11),#721);
#900011 = SHAPE_REPRESENTATION_RELATIONSHIP('','',#900010,#622);
#900012 = SHAPE_REPRESENTATION('',(#623),#721);
",
    );
}

/// `shapes.step` with its cone moved and a second occurrence of representation `child`
/// placed in representation `parent` (either may be defined by `extra`) at x = `x` in the
/// parent's units, −5 mm.
fn check_the_cone_placed_twice(child: &str, parent: &str, x: &str, extra: &str) {
    let text = std::fs::read_to_string(fixture("shapes.step")).unwrap();
    // The cone (part 5) moved to x = 5 with its axis along x (Gmsh/OpenCASCADE put it in
    // [6, 7] × [0.6, 1.4]²), and placed a second time, turned the other way at x = −5.
    let moved = text
        .replace("#32 = CARTESIAN_POINT('',(0.,0.,0.));", "#32 = CARTESIAN_POINT('',(5.,0.,0.));")
        .replace("#33 = DIRECTION('',(0.,0.,1.));", "#33 = DIRECTION('',(1.,0.,0.));")
        .replace("#34 = DIRECTION('',(1.,0.,-0.));", "#34 = DIRECTION('',(0.,1.,0.));")
        .replace(
            "ENDSEC;\nEND-ISO-10303-21;",
            &format!(
                "{extra}#900001 = ( REPRESENTATION_RELATIONSHIP('','',{child},{parent}) REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#900002) SHAPE_REPRESENTATION_RELATIONSHIP() );
#900002 = ITEM_DEFINED_TRANSFORMATION('','',#11,#900003);
#900003 = AXIS2_PLACEMENT_3D('',#900004,#900005,#900006);
#900004 = CARTESIAN_POINT('',({x},0.,0.));
#900005 = DIRECTION('',(-1.,0.,0.));
#900006 = DIRECTION('',(0.,1.,0.));
ENDSEC;\nEND-ISO-10303-21;"
            ),
        );
    let model = geometry_from_step(&parse_step(moved.as_bytes()).unwrap()).unwrap();
    // Box 6, sphere, torus, cylinder 3, cone 3 twice.
    assert_eq!(model.entities.len(), 17);
    let tan = 0.291456794478f64.tan();
    let cones: Vec<_> = model
        .entities
        .iter()
        .filter(|e| e.origin.contains("CONICAL"))
        .collect();
    assert_eq!(cones.len(), 2);
    assert!(cones[1].name.ends_with(".2"), "{}", cones[1].name);
    for (cone, sign) in cones.iter().zip([1.0, -1.0]) {
        let EntityGeometry::Surface(s) = &cone.geometry else {
            panic!()
        };
        for x in samples(s) {
            // Local height z = sign (X − 5 sign); axis Y = 1, Z = 1 ... carried: the local
            // axis x = y = 1 becomes Y = 1 (local x → Y) and Z = ±1 (local y → ±Z).
            let z = sign * (x[0] - 5.0 * sign);
            let r = (x[1] - 1.0).hypot(x[2] - sign);
            assert!((r - (0.4 + (1.0 - z) * tan)).abs() < 1e-12, "{:?}", x);
            assert!(z > 0.85 && z < 2.15, "{z}");
        }
    }
    // The box is where it was.
    let planes = model
        .entities
        .iter()
        .filter(|e| e.origin.contains("on PLANE"))
        .count();
    assert_eq!(planes, 6 + 2 + 2 * 2);
    // The cone's edges are carried with it: each lies on the faces it bounds.
    check_edges_on_their_faces(&model, "shapes.step with a cone placed twice");
}

/// Every model edge lies on each face it bounds, along its whole curve, to the file's
/// uncertainty (or 1e-9 of the model).
fn check_edges_on_their_faces(model: &GeometryModel, what: &str) {
    let tolerance = model.edge_copy_tolerance();
    for edge in &model.edges {
        assert!(edge.faces.len() >= 2, "{what}: {}", edge.origin);
        let (t0, t1) = edge.curve.domain();
        for k in 0..=16 {
            let x = edge.curve.point(t0 + (t1 - t0) * k as f64 / 16.0);
            for &f in &edge.faces {
                let d = model.entities[f].distance(x);
                assert!(
                    d <= tolerance,
                    "{what}: {} at {x:?} is {d:e} from {}",
                    edge.origin,
                    model.entities[f].name
                );
            }
        }
    }
}

/// A 3D model keeps its CAD edges between faces (the carriers of the feature edges between
/// them): every edge between two faces, on both, and none of a face alone.
#[test]
fn the_edges_between_faces_are_kept_on_their_faces() {
    // (file, its EDGE_CURVEs less those on a SEAM_CURVE, which bound one face twice)
    for (name, between) in [
        ("cone_plate.step", 19 - 3),
        ("filleted_boss.step", 19 - 3),
        ("sphere_on_block.step", 16 - 2),
        ("tee_pipes.step", 8 - 3),
        ("twisted_loft.step", 3 - 1),
        ("wing_body.step", 12),
    ] {
        let model = read_step_geometry(&fixture(name)).unwrap();
        assert_eq!(model.edges.len(), between, "{name}");
        check_edges_on_their_faces(&model, name);
    }
    // A 2D model's edges are its entities, not model edges.
    let flat = read_step_geometry(&fixture("naca_layers_2d.step")).unwrap();
    assert!(flat.edges.is_empty());
}

/// A face on a `RECTANGULAR_TRIMMED_SURFACE` lies on its basis surface (here the sphere,
/// still recognised as one).
#[test]
fn rectangular_trimmed_surfaces_are_their_basis() {
    let text = std::fs::read_to_string(fixture("sphere_occ.step")).unwrap();
    let old = "#347 = ADVANCED_FACE('',(#348),#352,.T.);";
    assert!(text.contains(old));
    let trimmed = text.replace(old, "#347 = ADVANCED_FACE('',(#348),#900001,.T.);").replace(
        "ENDSEC;\nEND-ISO-10303-21;",
        "#900001 = RECTANGULAR_TRIMMED_SURFACE('',#352,0.,6.283185307,-1.570796327,1.570796327,.T.,.T.);\nENDSEC;\nEND-ISO-10303-21;",
    );
    let model = geometry_from_step(&parse_step(trimmed.as_bytes()).unwrap()).unwrap();
    let spheres = model
        .entities
        .iter()
        .filter(
            |e| matches!(e.analytic, Some(AnalyticShape::Sphere { radius, .. }) if radius == 1.0),
        )
        .count();
    assert_eq!(spheres, 1);
}

/// OpenCASCADE writes the side of an extruded disk as a surface of linear extrusion whose
/// swept curve is a whole ELLIPSE with equal semi-axes: converted, it is the cylinder
/// r = 1 between z = 0 and z = 1, closed around.
#[test]
fn an_extrusion_of_a_whole_ellipse_is_the_cylinder() {
    let text = std::fs::read_to_string(fixture("extruded_disk.step")).unwrap();
    assert!(text.contains("ELLIPSE('',#34,1.,1.)"));
    let model = geometry_from_step(&parse_step(text.as_bytes()).unwrap()).unwrap();
    let mut sides = 0;
    for e in &model.entities {
        let EntityGeometry::Surface(s) = &e.geometry else {
            continue;
        };
        let points = samples(s);
        if points
            .iter()
            .all(|p| p[2].abs() < 1e-12 || (p[2] - 1.0).abs() < 1e-12)
        {
            continue; // a cap
        }
        sides += 1;
        for p in &points {
            assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-14, "{p:?}");
            assert!(p[2] > -1e-12 && p[2] < 1.0 + 1e-12, "{p:?}");
        }
        // All the way round: points near (±1, 0) and (0, ±1).
        for axis in [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]] {
            assert!(
                points
                    .iter()
                    .any(|p| p[0] * axis[0] + p[1] * axis[1] > 0.99),
                "{axis:?}"
            );
        }
    }
    assert_eq!(sides, 1);
}

/// The distance to which the file's faces meet, in millimetres: OpenCASCADE writes its
/// largest tolerance as the context's `UNCERTAINTY_MEASURE_WITH_UNIT` (1e-7 mm for exact
/// shapes, 2e-6 for the wing body's approximated surfaces); a context in metres scales it;
/// IGES states it as the Global section's minimum resolution.
#[test]
fn the_files_stated_uncertainty_is_read_in_millimetres() {
    let shapes = read_step_geometry(&fixture("shapes.step")).unwrap();
    assert_eq!(shapes.uncertainty, Some(1e-7));
    let wing = read_step_geometry(&fixture("wing_body.step")).unwrap();
    assert_eq!(wing.uncertainty, Some(2e-6));
    let iges = read_iges_geometry(&fixture("plate_holes.igs")).unwrap();
    assert_eq!(iges.uncertainty, Some(1e-7));
    // The same file in metres: 1e-7 m is 1e-4 mm.
    let text = std::fs::read_to_string(fixture("shapes.step")).unwrap();
    let metres = text.replace("SI_UNIT(.MILLI.,.METRE.)", "SI_UNIT($,.METRE.)");
    assert_ne!(metres, text);
    let model = geometry_from_step(&parse_step(metres.as_bytes()).unwrap()).unwrap();
    let u = model.uncertainty.unwrap();
    assert!((u - 1e-4).abs() < 1e-16, "{u:e}");
    // None stated, none assumed.
    let bare = text.replace("UNCERTAINTY_MEASURE_WITH_UNIT", "UNKNOWN_MEASURE_WITH_UNIT");
    let model = geometry_from_step(&parse_step(bare.as_bytes()).unwrap()).unwrap();
    assert_eq!(model.uncertainty, None);
}

/// IGES has no shared topology, but its faces' boundary curves give the same CAD edges:
/// an IGES export of each model has as many edges between faces as the STEP export, each
/// on its faces and on a STEP edge along its whole length. (The NACA section's STEP file
/// has each face in its own shell: its edges are copies, found as IGES's are.)
#[test]
fn an_iges_export_has_the_same_edges_between_faces_as_the_step_export() {
    for name in [
        "cone_plate",
        "filleted_boss",
        "sphere_on_block",
        "tee_pipes",
        "twisted_loft",
        "wing_body",
        "naca_layers_tets",
    ] {
        let step = read_step_geometry(&fixture(&format!("{name}.step"))).unwrap();
        let iges = read_iges_geometry(&fixture(&format!("{name}.igs"))).unwrap();
        assert!(!step.edges.is_empty(), "{name}");
        assert_eq!(iges.edges.len(), step.edges.len(), "{name}");
        check_edges_on_their_faces(&iges, name);
        let tolerance = step.edge_copy_tolerance();
        for edge in &iges.edges {
            let (t0, t1) = edge.curve.domain();
            let on_a_step_edge = step.edges.iter().any(|s| {
                (0..=8).all(|k| {
                    let x = edge.curve.point(t0 + (t1 - t0) * k as f64 / 8.0);
                    crate::inversion::closest_point_on_curve(&s.curve, x).distance <= tolerance
                })
            });
            assert!(on_a_step_edge, "{name}: {}", edge.origin);
        }
    }
    let flat = read_iges_geometry(&fixture("naca_layers_2d.igs")).unwrap();
    assert!(flat.edges.is_empty());
}

/// A face on a torus is a patch over the part of the tube it covers, as an IGES export
/// writes it (a fillet's quarter of the tube revolved), not the whole torus: a path on
/// the patch between two points of the edge where the fillet meets a plane tangentially
/// then follows that edge instead of running over the tube into the solid.
#[test]
fn a_face_on_a_torus_is_the_part_of_the_tube_it_covers() {
    for name in ["cone_plate", "filleted_boss"] {
        let step = read_step_geometry(&fixture(&format!("{name}.step"))).unwrap();
        let iges = read_iges_geometry(&fixture(&format!("{name}.igs"))).unwrap();
        let mut tori = 0;
        for e in &step.entities {
            let Some(AnalyticShape::Torus { .. }) = e.analytic else {
                continue;
            };
            tori += 1;
            let EntityGeometry::Surface(s) = &e.geometry else {
                panic!("{name}: a torus that is not a surface");
            };
            // The IGES face on the same torus, holding this patch's middle point.
            let ((u0, u1), (v0, v1)) = s.domain();
            let middle = s.point(0.5 * (u0 + u1), 0.5 * (v0 + v1));
            let twin = iges
                .entities
                .iter()
                .find(|f| {
                    matches!(f.analytic, Some(AnalyticShape::Torus { .. }))
                        && f.patch_distance(middle) < 1e-9
                })
                .unwrap_or_else(|| panic!("{name}: no IGES face holds {}'s middle", e.name));
            let EntityGeometry::Surface(t) = &twin.geometry else {
                panic!("{name}: {} is not a surface", twin.name);
            };
            // Each patch lies on the other.
            for (a, b) in [(s, twin), (t, e)] {
                for p in samples(a) {
                    let d = b.patch_distance(p);
                    assert!(
                        d < 1e-7,
                        "{name}: {} and {}: {p:?} {d:e}",
                        e.name,
                        twin.name
                    );
                }
            }
        }
        assert!(tori > 0, "{name}");
    }
}
