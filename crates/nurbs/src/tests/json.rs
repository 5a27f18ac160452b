use super::*;
use crate::vec3::{dot, norm, scale, sub};

/// The module documentation's example.
const EXAMPLE: &str = r#"{
  "entities": [
    {"name": "sphere", "kind": "sphere", "center": [0, 0, 0], "radius": 1},
    {"name": "airfoil", "kind": "naca4", "digits": "0012", "chord": 1,
     "closed_trailing_edge": true},
    {"name": "ring", "kind": "torus", "center": [0, 0, 0], "axis": [0, 0, 1],
     "major_radius": 2, "minor_radius": 0.5},
    {"name": "pipe", "kind": "cylinder", "point": [0, 0, 0], "axis": [0, 0, 2],
     "radius": 0.5},
    {"name": "nose", "kind": "cone", "apex": [0, 0, 0], "axis": [1, 0, 0],
     "half_angle_degrees": 7, "axial_range": [0, 1]},
    {"name": "farfield", "kind": "circle", "center": [0.5, 0], "radius": 10},
    {"name": "arc", "kind": "nurbs_curve", "degree": 2, "knots": [0, 0, 0, 1, 1, 1],
     "control_points": [[1, 0], [1, 1], [0, 1]], "weights": [1, 0.7071067811865476, 1]},
    {"name": "patch", "kind": "nurbs_surface", "degree": [1, 1],
     "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
     "control_points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1]]]}
  ]
}"#;

fn surface_points(e: &GeometricEntity) -> Vec<[f64; 3]> {
    let n = 40;
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            out.push(e.point([i as f64 / n as f64, j as f64 / n as f64]));
        }
    }
    out
}

fn fixture(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(path)
}

#[test]
fn every_kind_is_parsed_and_analytic_entities_lie_on_their_surfaces() {
    let model = parse_geometry_json(EXAMPLE).unwrap();
    let names: Vec<&str> = model.entities.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(
        names,
        ["sphere", "airfoil", "ring", "pipe", "nose", "farfield", "arc", "patch"]
    );
    assert_eq!(model.counts(), (3, 5));

    let sphere = model.entity("sphere").unwrap();
    assert!(matches!(
        sphere.analytic,
        Some(AnalyticShape::Sphere { .. })
    ));
    for p in surface_points(sphere) {
        assert!((norm(p) - 1.0).abs() < 1e-14);
    }

    let ring = model.entity("ring").unwrap();
    assert!(ring.analytic.is_some());
    for p in surface_points(ring) {
        let rho = p[0].hypot(p[1]);
        assert!(((rho - 2.0).hypot(p[2]) - 0.5).abs() < 1e-14);
    }

    // Default axial range: from the point to point + axis.
    let pipe = model.entity("pipe").unwrap();
    assert!(pipe.analytic.is_some());
    for p in surface_points(pipe) {
        assert!((p[0].hypot(p[1]) - 0.5).abs() < 1e-14);
        assert!((-1e-15..=2.0 + 1e-15).contains(&p[2]));
    }
    assert!((pipe.point([0.0, 1.0])[2] - 2.0).abs() < 1e-15);

    // The cone opens along +x from the origin at 7°, its patch from the apex to x = 1.
    let nose = model.entity("nose").unwrap();
    let tan = 7f64.to_radians().tan();
    assert!(matches!(nose.analytic, Some(AnalyticShape::Cone { .. })));
    for p in surface_points(nose) {
        assert!((p[1].hypot(p[2]) - p[0] * tan).abs() < 1e-14);
        assert!((-1e-15..=1.0 + 1e-15).contains(&p[0]));
    }
    assert!(
        (nose.distance([0.5, 1.0, 0.0]) - (1.0 - 0.5 * tan) * 7f64.to_radians().cos()).abs()
            < 1e-14
    );

    // A 2D centre is in the plane z = 0, normal +z.
    let far = model.entity("farfield").unwrap();
    assert!(far.is_curve() && far.analytic.is_some());
    for i in 0..=1000 {
        let p = far.point([i as f64 / 1000.0, 0.0]);
        assert!(((p[0] - 0.5).hypot(p[1]) - 10.0).abs() < 1e-14);
        assert_eq!(p[2], 0.0);
    }

    let airfoil = model.entity("airfoil").unwrap();
    let expected = Naca4::from_digits("0012", 1.0, true)
        .unwrap()
        .curve()
        .unwrap();
    assert_eq!(airfoil.geometry, EntityGeometry::Curve(expected));
    assert!(airfoil.analytic.is_none());

    // The quarter circle given as an explicit rational curve.
    let arc = model.entity("arc").unwrap();
    for i in 0..=100 {
        assert!((norm(arc.point([i as f64 / 100.0, 0.0])) - 1.0).abs() < 1e-15);
    }

    // Bilinear patch: S(u, v) = (u, v, u v).
    let patch = model.entity("patch").unwrap();
    let p = patch.point([0.25, 0.5]);
    assert_eq!(p, [0.25, 0.5, 0.125]);
    assert_eq!(patch.origin, "JSON entity 7 (nurbs_surface)");
}

#[test]
fn circle_normal_torus_axis_and_default_names() {
    let model = parse_geometry_json(
        r#"{"entities": [
                {"kind": "circle", "center": [1, 2, 3], "normal": [1, 1, 0], "radius": 2},
                {"kind": "torus", "center": [1, 0, 0], "axis": [0, 1, 1],
                 "major_radius": 1, "minor_radius": 0.25},
                {"kind": "cylinder", "point": [0, 0, 1], "axis": [1, 0, 0], "radius": 3,
                 "axial_range": [-2, 5]},
                {"kind": "naca4", "digits": "2412"}
            ]}"#,
    )
    .unwrap();
    let names: Vec<&str> = model.entities.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["circle0", "torus1", "cylinder2", "naca43"]);
    let (c, n) = ([1.0, 2.0, 3.0], [0.5f64.sqrt(), 0.5f64.sqrt(), 0.0]);
    for i in 0..=200 {
        let d = sub(model.entities[0].point([i as f64 / 200.0, 0.0]), c);
        assert!((norm(d) - 2.0).abs() < 1e-14 && dot(d, n).abs() < 1e-14);
    }
    let a = scale([0.0, 1.0, 1.0], 0.5f64.sqrt());
    for p in surface_points(&model.entities[1]) {
        let d = sub(p, [1.0, 0.0, 0.0]);
        let z = dot(d, a);
        let rho = norm(sub(d, scale(a, z)));
        assert!(((rho - 1.0).hypot(z) - 0.25).abs() < 1e-14);
    }
    for p in surface_points(&model.entities[2]) {
        assert!((p[1].hypot(p[2] - 1.0) - 3.0).abs() < 1e-14);
        assert!((-2.0 - 1e-14..=5.0 + 1e-14).contains(&p[0]));
    }
    // Defaults: chord 1, blunt trailing edge (a straight base closes the curve).
    let EntityGeometry::Curve(airfoil) = &model.entities[3].geometry else {
        panic!("naca4 is a curve")
    };
    assert_eq!(airfoil.c0_parameters().len(), 3);
    assert!(airfoil.domain().1 > 1.0);
}

#[test]
fn nurbs_curve_round_trips_against_direct_construction() {
    let model = parse_geometry_json(
        r#"{"entities": [{"name": "c", "kind": "nurbs_curve", "degree": 3,
                "knots": [0, 0, 0, 0, 0.1, 0.6, 0.6, 1, 1, 1, 1],
                "control_points": [[0, 0], [1, 2, 0.5], [2, -1, 1], [3, 0.5],
                                   [4, 2, -1], [5, 0, 0.3], [6, 1]],
                "weights": [1, 0.5, 2, 1, 0.7, 1.5, 1]},
              {"name": "d", "kind": "nurbs_curve", "degree": 1, "knots": [0, 0, 1, 1],
               "control_points": [[0, 0, 0], [1, 1, 1]]}]}"#,
    )
    .unwrap();
    let direct = NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 0.1, 0.6, 0.6, 1.0, 1.0, 1.0, 1.0],
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 2.0, 0.5],
            [2.0, -1.0, 1.0],
            [3.0, 0.5, 0.0],
            [4.0, 2.0, -1.0],
            [5.0, 0.0, 0.3],
            [6.0, 1.0, 0.0],
        ],
        vec![1.0, 0.5, 2.0, 1.0, 0.7, 1.5, 1.0],
    )
    .unwrap();
    assert_eq!(model.entities[0].geometry, EntityGeometry::Curve(direct));
    let line =
        NurbsCurve::non_rational(1, vec![0.0, 0.0, 1.0, 1.0], vec![[0.0; 3], [1.0; 3]]).unwrap();
    assert_eq!(model.entities[1].geometry, EntityGeometry::Curve(line));
}

#[test]
fn syntax_errors_report_their_line() {
    let text =
        "{\"entities\": [\n  {\"kind\": \"sphere\", \"center\": [0, 0, 0]\n  \"radius\": 1}\n]}";
    let err = parse_geometry_json(text).unwrap_err();
    assert!(
        matches!(err, GeometryInputError::Json { line: 3, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("line 3"), "{err}");
    let err = parse_geometry_json(r#"{"entity": []}"#).unwrap_err();
    assert!(matches!(err, GeometryInputError::Json { line: 1, .. }));
}

#[test]
fn unknown_kinds_and_fields_are_errors() {
    let err = parse_geometry_json(
        r#"{"entities": [{"kind": "sphere", "center": [0,0,0], "radius": 1},
                             {"kind": "cube", "size": 1}]}"#,
    )
    .unwrap_err();
    assert!(
        matches!(&err, GeometryInputError::UnknownKind { index: 1, kind } if kind == "\"cube\"")
    );
    let message = err.to_string();
    assert!(message.contains("entity 1") && message.contains("nurbs_surface"));
    assert!(matches!(
        parse_geometry_json(r#"{"entities": [{"radius": 1}]}"#),
        Err(GeometryInputError::MissingKind { index: 0 })
    ));
    assert!(matches!(
        parse_geometry_json(r#"{"entities": [3]}"#),
        Err(GeometryInputError::NotAnObject { index: 0 })
    ));
    let err = parse_geometry_json(
        r#"{"entities": [{"name": "ball", "kind": "sphere", "center": [0,0,0], "radius": 1,
                              "colour": "red"}]}"#,
    )
    .unwrap_err();
    assert!(
        matches!(&err, GeometryInputError::Field { index: 0, name, .. } if name == "ball"),
        "{err}"
    );
    assert!(err.to_string().contains("colour"), "{err}");
    // Wrong point dimension, missing field.
    assert!(matches!(
        parse_geometry_json(r#"{"entities": [{"kind": "sphere", "center": [0, 0], "radius": 1}]}"#),
        Err(GeometryInputError::Field { .. })
    ));
    assert!(matches!(
        parse_geometry_json(r#"{"entities": [{"kind": "circle", "center": [0, 0]}]}"#),
        Err(GeometryInputError::Field { .. })
    ));
}

#[test]
fn invalid_geometry_is_reported_with_the_entity() {
    let err = parse_geometry_json(
        r#"{"entities": [{"kind": "sphere", "center": [0,0,0], "radius": 1},
                             {"name": "hole", "kind": "circle", "center": [0,0], "radius": -1}]}"#,
    )
    .unwrap_err();
    assert!(
        matches!(
            &err,
            GeometryInputError::Geometry { index: 1, name, source: NurbsError::InvalidShape { .. } }
                if name == "hole"
        ),
        "{err}"
    );
    let err = parse_geometry_json(
        r#"{"entities": [{"kind": "nurbs_curve", "degree": 2, "knots": [0, 0, 0, 1, 1],
                              "control_points": [[0, 0], [1, 1], [2, 0]]}]}"#,
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            GeometryInputError::Geometry {
                index: 0,
                source: NurbsError::KnotCount {
                    expected: 6,
                    found: 5,
                    ..
                },
                ..
            }
        ),
        "{err}"
    );
    let err = parse_geometry_json(
        r#"{"entities": [{"kind": "nurbs_surface", "degree": [1, 1],
                "knots": [[0, 0, 1, 1], [0, 0, 0.5, 1, 1]],
                "control_points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1]]]}]}"#,
    )
    .unwrap_err();
    assert!(matches!(
        err,
        GeometryInputError::Geometry {
            source: NurbsError::KnotCount {
                expected: 4,
                found: 5,
                ..
            },
            ..
        }
    ));
    let err = parse_geometry_json(
        r#"{"entities": [{"kind": "nurbs_surface", "degree": [1, 1],
                "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
                "control_points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0]]]}]}"#,
    )
    .unwrap_err();
    assert!(matches!(err, GeometryInputError::Invalid { index: 0, .. }));
    assert!(matches!(
        parse_geometry_json(r#"{"entities": [{"kind": "naca4", "digits": "12", "chord": 1}]}"#),
        Err(GeometryInputError::Geometry { .. })
    ));
    assert!(matches!(
        parse_geometry_json(
            r#"{"entities": [{"kind": "torus", "center": [0,0,0], "axis": [0,0,1],
                                  "major_radius": 1, "minor_radius": 2}]}"#
        ),
        Err(GeometryInputError::Geometry { .. })
    ));
    for bad in [
        r#""half_angle_degrees": 90"#,
        r#""half_angle_degrees": 10, "axial_range": [-1, 1]"#,
    ] {
        let text = format!(
            r#"{{"entities": [{{"kind": "cone", "apex": [0,0,0], "axis": [0,0,1], {bad}}}]}}"#
        );
        assert!(
            matches!(
                parse_geometry_json(&text),
                Err(GeometryInputError::Geometry { .. })
            ),
            "{bad}"
        );
    }
}

#[test]
fn names_must_be_unique_and_non_empty() {
    let err = parse_geometry_json(
        r#"{"entities": [{"name": "wall", "kind": "sphere", "center": [0,0,0], "radius": 1},
                             {"kind": "sphere", "center": [0,0,0], "radius": 2},
                             {"name": "wall", "kind": "circle", "center": [0,0], "radius": 1}]}"#,
    )
    .unwrap_err();
    assert!(
        matches!(&err, GeometryInputError::DuplicateName { index: 2, first: 0, name } if name == "wall"),
        "{err}"
    );
    // A default name can collide with an explicit one too.
    assert!(matches!(
        parse_geometry_json(
            r#"{"entities": [{"name": "sphere1", "kind": "sphere", "center": [0,0,0], "radius": 1},
                                 {"kind": "sphere", "center": [0,0,0], "radius": 2}]}"#
        ),
        Err(GeometryInputError::DuplicateName { index: 1, .. })
    ));
    assert!(matches!(
        parse_geometry_json(
            r#"{"entities": [{"name": "", "kind": "sphere", "center": [0,0,0], "radius": 1}]}"#
        ),
        Err(GeometryInputError::Invalid { .. })
    ));
}

#[test]
fn bundled_fixtures_parse() {
    let sphere = read_geometry_json(&fixture("sphere/sphere.json")).unwrap();
    assert_eq!(sphere.entities.len(), 1);
    let ball = sphere.entity("sphere").unwrap();
    assert_eq!(
        ball.analytic,
        Some(AnalyticShape::Sphere {
            center: [0.0; 3],
            radius: 1.0
        })
    );
    assert!(ball.origin.ends_with("sphere.json: JSON entity 0 (sphere)"));

    let naca = read_geometry_json(&fixture("naca0012/naca0012.json")).unwrap();
    let names: Vec<&str> = naca.entities.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["airfoil", "farfield"]);
    let airfoil = naca.entity("airfoil").unwrap();
    // Leading and trailing edge of the chord-1 airfoil at the origin.
    assert!(airfoil.distance([0.0; 3]) < 1e-15);
    assert!(airfoil.distance([1.0, 0.0, 0.0]) < 1e-15);
    let far = naca.entity("farfield").unwrap();
    assert_eq!(
        far.analytic,
        Some(AnalyticShape::Circle {
            center: [0.5, 0.0, 0.0],
            normal: [0.0, 0.0, 1.0],
            radius: 10.0
        })
    );
    assert!(matches!(
        read_geometry_json(&fixture("missing.json")),
        Err(GeometryInputError::Io { .. })
    ));
}
