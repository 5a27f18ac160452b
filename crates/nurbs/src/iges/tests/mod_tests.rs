use std::collections::BTreeMap;
use std::path::Path;

use super::params::{tokenize, Stream};
use super::sections::Record;
use super::*;

pub(super) fn fixture(rel: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

const FIXTURES: [&str; 4] = [
    "sphere/sphere.igs",
    "naca0012/naca0012.igs",
    "formats/torus.igs",
    "formats/cylinder.igs",
];

/// Independent scan: entity type in columns 1–8 of every other D record.
fn scan_histogram(text: &str) -> BTreeMap<i32, usize> {
    let mut h = BTreeMap::new();
    let d: Vec<&str> = text
        .lines()
        .filter(|l| l.len() >= 73 && &l[72..73] == "D")
        .collect();
    for l in d.iter().step_by(2) {
        *h.entry(l[0..8].trim().parse::<i32>().unwrap()).or_insert(0) += 1;
    }
    h
}

fn record(data: &str, letter: char, seq: usize) -> String {
    assert!(data.len() <= 72);
    format!("{data:<72}{letter}{seq:07}\n")
}

/// Entity for the synthetic file builder.
pub(super) struct E<'a> {
    pub ty: i32,
    pub form: i32,
    pub transform: u32,
    pub params: &'a str,
}

pub(super) fn ent(ty: i32, params: &str) -> E<'_> {
    E {
        ty,
        form: 0,
        transform: 0,
        params,
    }
}

pub(super) const GLOBAL: &str = "1H,,1H;,4Htest,8Htest.igs,6Hhocurv,3H1.0,32,308,15,308,15,,1.0,2,2HMM,1,0.01,15H20260101.000000,1E-07,10.,4Hnone,,11,0,15H20260101.000000;";

/// Writes a well-formed fixed-format IGES file.
pub(super) fn build(global: &str, ents: &[E<'_>]) -> String {
    let mut out = record("synthetic test file", 'S', 1);
    let gb = global.as_bytes();
    let mut g = 0;
    for (i, chunk) in gb.chunks(72).enumerate() {
        out += &record(std::str::from_utf8(chunk).unwrap(), 'G', i + 1);
        g += 1;
    }
    let mut d = String::new();
    let mut p = String::new();
    let mut pseq = 1;
    for (i, ent) in ents.iter().enumerate() {
        let de = 2 * i + 1;
        let chunks: Vec<&[u8]> = ent.params.as_bytes().chunks(64).collect();
        d += &record(
            &format!(
                "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}00000000",
                ent.ty, pseq, 0, 0, 0, 0, ent.transform, 0
            ),
            'D',
            de,
        );
        d += &record(
            &format!(
                "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
                ent.ty,
                0,
                0,
                chunks.len(),
                ent.form,
                "",
                "",
                "",
                0
            ),
            'D',
            de + 1,
        );
        for c in chunks {
            let data = format!("{:<64} {:>7}", std::str::from_utf8(c).unwrap(), de);
            p += &record(&data, 'P', pseq);
            pseq += 1;
        }
    }
    out += &d;
    out += &p;
    out += &record(
        &format!("S{:>7}G{:>7}D{:>7}P{:>7}", 1, g, 2 * ents.len(), pseq - 1),
        'T',
        1,
    );
    out
}

/// Replaces columns `from..=to` (1-based) of file line `line` (1-based).
fn patch(text: &str, line: usize, from: usize, new: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let l = &mut lines[line - 1];
    l.replace_range(from - 1..from - 1 + new.len(), new);
    lines.join("\n") + "\n"
}

fn line_of(text: &str, pred: impl Fn(&str) -> bool) -> usize {
    text.lines().position(pred).unwrap() + 1
}

// ---------------------------------------------------------------------------------------------
// fixtures
// ---------------------------------------------------------------------------------------------

#[test]
fn every_fixture_parses_and_histogram_matches_scan() {
    for rel in FIXTURES {
        let text = fixture(rel);
        let model = parse_iges(&text).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert_eq!(model.histogram(), scan_histogram(&text), "{rel}");
        assert!(!model.entities.is_empty());
        for (i, e) in model.entities.iter().enumerate() {
            assert_eq!(e.de as usize, 2 * i + 1);
            assert_eq!(e.kind.type_number(), e.type_number(), "{rel} DE {}", e.de);
            assert_eq!(model.entity(e.de), Some(e));
            assert!(
                !matches!(e.kind, EntityData::Unsupported { .. }),
                "{rel}: unexpected unsupported entity {} at line {}",
                e.type_number(),
                e.line
            );
            for r in e.kind.references() {
                assert!(model.entity(r).is_some());
            }
        }
        let g = &model.global;
        assert_eq!((g.parameter_delimiter, g.record_delimiter), (',', ';'));
        assert_eq!(g.model_space_scale, 1.0);
        assert_eq!(g.units_flag, 2);
        assert_eq!(g.units_name, "MM");
        assert_eq!(g.unit_in_metres(), Some(1e-3));
        assert_eq!(g.min_resolution, 1e-7);
        assert!(g.max_coordinate.unwrap() > 0.0);
        assert_eq!(g.version, 11);
        assert!(g.product_id_sender.starts_with("Open CASCADE"));
        // read_iges gives the same model
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures")
            .join(rel);
        assert_eq!(read_iges(&path).unwrap(), model);
    }
    assert!(matches!(
        read_iges("/nonexistent/x.igs"),
        Err(IgesError::Io { .. })
    ));
}

fn arc_radius(model: &IgesModel, de: u32) -> f64 {
    let EntityData::CircularArc { center, start, .. } = &model.entity(de).unwrap().kind else {
        panic!("DE {de} is not a circular arc");
    };
    ((start[0] - center[0]).powi(2) + (start[1] - center[1]).powi(2)).sqrt()
}

fn apply(m: &[[f64; 4]; 3], p: [f64; 3]) -> [f64; 3] {
    let mut q = [0.0; 3];
    for i in 0..3 {
        q[i] = m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3];
    }
    q
}

#[test]
fn sphere_is_a_revolved_unit_arc() {
    let model = parse_iges(&fixture("sphere/sphere.igs")).unwrap();
    let revs: Vec<_> = model.entities_of_type(120).collect();
    assert_eq!(revs.len(), 1);
    let EntityData::SurfaceOfRevolution {
        axis,
        generatrix,
        start_angle,
        end_angle,
    } = revs[0].kind
    else {
        panic!()
    };
    assert_eq!(model.entity(axis).unwrap().type_number(), 110);
    assert!((arc_radius(&model, generatrix) - 1.0).abs() < 1e-9);
    assert!((end_angle - start_angle - 2.0 * std::f64::consts::PI).abs() < 1e-8);
    // the box: 6 planes, all trimmed
    assert_eq!(model.entities_of_type(108).count(), 6);
    assert_eq!(model.entities_of_type(144).count(), 7);
    for t in model.entities_of_type(144) {
        let EntityData::TrimmedSurface { surface, outer, .. } = &t.kind else {
            panic!()
        };
        let s = model.entity(*surface).unwrap().type_number();
        assert!(s == 108 || s == 120, "{s}");
        assert_eq!(model.entity(outer.unwrap()).unwrap().type_number(), 142);
    }
}

#[test]
fn torus_generatrix_is_placed_by_its_transformation() {
    let model = parse_iges(&fixture("formats/torus.igs")).unwrap();
    let rev = model.entities_of_type(120).next().unwrap();
    let EntityData::SurfaceOfRevolution { generatrix, .. } = rev.kind else {
        panic!()
    };
    let arc = model.entity(generatrix).unwrap();
    assert!((arc_radius(&model, generatrix) - 0.5).abs() < 1e-12);
    let EntityData::CircularArc {
        zt, center, start, ..
    } = arc.kind
    else {
        panic!()
    };
    let m = model
        .transform_of(arc)
        .expect("the generatrix has a transformation");
    let c = apply(&m, [center[0], center[1], zt]);
    let s = apply(&m, [start[0], start[1], zt]);
    // the tube centre lies on the circle of radius 2 about the z axis
    assert!(
        ((c[0] * c[0] + c[1] * c[1]).sqrt() - 2.0).abs() < 1e-9,
        "{c:?}"
    );
    assert!(c[2].abs() < 1e-9);
    let d = ((s[0] - c[0]).powi(2) + (s[1] - c[1]).powi(2) + (s[2] - c[2]).powi(2)).sqrt();
    assert!((d - 0.5).abs() < 1e-9);
    // 124 rotations are orthonormal
    for t in model.entities_of_type(124) {
        let EntityData::TransformationMatrix { matrix } = t.kind else {
            panic!()
        };
        for i in 0..3 {
            for j in 0..3 {
                let dot: f64 = (0..3).map(|k| matrix[i][k] * matrix[j][k]).sum();
                assert!((dot - f64::from(u8::from(i == j))).abs() < 1e-8);
            }
        }
    }
    assert_eq!(model.transform_of(rev), None);
}

#[test]
fn naca_b_spline_curves_have_consistent_sizes() {
    let model = parse_iges(&fixture("naca0012/naca0012.igs")).unwrap();
    let curves: Vec<_> = model.entities_of_type(126).collect();
    assert_eq!(curves.len(), 2);
    for c in curves {
        let EntityData::BSplineCurve(b) = &c.kind else {
            panic!()
        };
        assert_eq!(b.knots.len(), b.k + b.m + 2);
        assert_eq!(b.weights.len(), b.k + 1);
        assert_eq!(b.control_points.len(), b.k + 1);
        assert_eq!(b.m, 3);
        assert!(b.knots.windows(2).all(|w| w[0] <= w[1]));
        assert!(b.weights.iter().all(|&w| w > 0.0));
        assert!(b.planar);
        assert!(!b.closed);
        assert_eq!(b.v0, b.knots[b.m]);
        assert_eq!(b.v1, b.knots[b.k + 1]);
        // interpolating splines from the leading edge (0,0) to the trailing edge (1,0)
        // (either orientation)
        let (mut p0, mut pn) = (b.control_points[0], b.control_points[b.k]);
        if p0[0] > pn[0] {
            std::mem::swap(&mut p0, &mut pn);
        }
        assert!(p0[0].abs() < 1e-9 && p0[1].abs() < 1e-9, "{p0:?}");
        assert!((pn[0] - 1.0).abs() < 1e-9 && pn[1].abs() < 1e-9, "{pn:?}");
        assert!(b.control_points.iter().all(|p| p[2] == 0.0));
    }
    // the far field circle of radius 10 about (0.5, 0)
    let arc = model.entities_of_type(100).next().unwrap();
    assert!((arc_radius(&model, arc.de) - 10.0).abs() < 1e-9);
}

// ---------------------------------------------------------------------------------------------
// synthetic files
// ---------------------------------------------------------------------------------------------

#[test]
fn synthetic_file_round_trip() {
    let ents = [
        ent(110, "110,0.,0.,0.,1.0D0,2.5d-1,-3.E2;"),
        E {
            ty: 100,
            form: 0,
            transform: 5,
            params: "100,1.,0.,0.,2.,0.,2.,0.;",
        },
        E {
            ty: 124,
            form: 0,
            transform: 7,
            params: "124,0.,-1.,0.,1.,1.,0.,0.,0.,0.,0.,1.,0.;",
        },
        ent(124, "124,2.,0.,0.,0.,0.,2.,0.,0.,0.,0.,2.,5.;"),
        ent(102, "102,2,1,3;"),
        ent(406, "406,2,1,8HPROPERTY,7HX,Y;Z H;"),
        ent(999, "999,1,2,3;"),
        ent(
            126,
            "126,2,2,1,0,1,0,0.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,0.5,1.,0.,1.,0.,0.,0.,1.,0.,0.,1.;",
        ),
        ent(
            128,
            "128,1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,0.,1.,0.,1.,1.,0.,0.,1.,0.,1.;",
        ),
        ent(144, "144,17,0,0,0;"),
        ent(142, "142,0,17,0,15,2;"),
    ];
    let text = build(GLOBAL, &ents);
    let m = parse_iges(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(m.entities.len(), ents.len());
    assert_eq!(m.histogram(), scan_histogram(&text));
    assert_eq!(m.global.author, "none");
    assert_eq!(m.global.max_coordinate, Some(10.0));
    assert_eq!(m.start, vec!["synthetic test file".to_string()]);
    let EntityData::Line { start, end } = m.entity(1).unwrap().kind else {
        panic!()
    };
    assert_eq!(start, [0.0; 3]);
    assert_eq!(end, [1.0, 0.25, -300.0]);
    // chained transformations: DE 3 -> 124 at DE 5 (rotation + shift) -> 124 at DE 7 (scale 2,
    // shift z by 5); the arc centre (1, 0, 0) goes to (1, 1, 0) then to (2, 2, 5).
    let arc = m.entity(3).unwrap();
    assert_eq!(arc.transform, Some(5));
    let t = m.transform_of(arc).unwrap();
    assert_eq!(apply(&t, [1.0, 0.0, 0.0]), [2.0, 2.0, 5.0]);
    assert_eq!(apply(&t, [0.0, 0.0, 1.0]), [2.0, 0.0, 7.0]);
    // the transformation *of* the 124 at DE 5 is the one it points to
    assert_eq!(
        m.transform_of(m.entity(5).unwrap()).unwrap(),
        [[2., 0., 0., 0.], [0., 2., 0., 0.], [0., 0., 2., 5.]]
    );
    assert_eq!(m.transform_of(m.entity(1).unwrap()), None);
    assert_eq!(
        m.entity(9).unwrap().kind,
        EntityData::CompositeCurve { curves: vec![1, 3] }
    );
    assert_eq!(
        m.entity(11).unwrap().kind,
        EntityData::Ignored { type_number: 406 }
    );
    let u = m.entity(13).unwrap();
    assert_eq!(u.kind, EntityData::Unsupported { type_number: 999 });
    assert_eq!(u.line, line_of(&text, |l| l.starts_with("     999")));
    let EntityData::BSplineCurve(c) = &m.entity(15).unwrap().kind else {
        panic!()
    };
    assert_eq!((c.k, c.m), (2, 2));
    assert_eq!(c.knots, vec![0., 0., 0., 1., 1., 1.]);
    assert_eq!(c.control_points[1], [0.5, 1.0, 0.0]);
    assert_eq!(c.normal, Some([0., 0., 1.]));
    let EntityData::BSplineSurface(s) = &m.entity(17).unwrap().kind else {
        panic!()
    };
    assert_eq!(s.knots_u.len(), s.k1 + s.m1 + 2);
    assert_eq!(s.weights.len(), 4);
    assert_eq!(s.control_points[3], [1.0, 1.0, 0.0]);
    assert_eq!((s.u0, s.u1, s.v0, s.v1), (0., 1., 0., 1.));
    assert!(s.polynomial && !s.closed_u);
    assert_eq!(
        m.entity(19).unwrap().kind,
        EntityData::TrimmedSurface {
            surface: 17,
            outer_specified: false,
            outer: None,
            inner: vec![]
        }
    );
    assert!(m.entity(2).is_none() && m.entity(23).is_none() && m.entity(0).is_none());
}

#[test]
fn hollerith_strings_and_custom_delimiters() {
    // strings holding delimiters, spaces and an `H`; a string spanning two records
    let long = "x".repeat(60);
    let params = format!("406,3,1,3HABC,7HX,Y;Z H,60H{long};");
    let text = build(GLOBAL, &[ent(406, &params)]);
    parse_iges(&text).unwrap();
    let recs: Vec<Record<'_>> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| &l[72..73] == "P")
        .map(|(i, l)| Record {
            line: i + 1,
            text: l,
        })
        .collect();
    assert_eq!(recs.len(), 2);
    let s = Stream::from_records(&recs, 1, 64);
    let p = tokenize(&s, 0, b',', b';', "test").unwrap();
    let values: Vec<_> = p.iter().map(|p| p.value.clone()).collect();
    assert_eq!(
        values,
        vec![
            ParamValue::Token("406".into()),
            ParamValue::Token("3".into()),
            ParamValue::Token("1".into()),
            ParamValue::Str("ABC".into()),
            ParamValue::Str("X,Y;Z H".into()),
            ParamValue::Str(long.clone()),
        ]
    );
    assert_eq!(p[0].line, recs[0].line);
    assert_eq!(p[5].line, recs[0].line);

    // Global section with its own delimiters: '/' between parameters, '#' ends the record
    let g = "1H//1H#/4Htest/8Htest.igs/6Hhocurv/3H1.0/32/308/15/308/15//2.5/6/1HM/1/0.01/15H20260101.000000/1D-6/1.0D1/5Ha/b#c//11/0/15H20260101.000000#";
    let text = build(g, &[ent(110, "110/1.0D0/2/3/4/5/6.5#")]);
    let m = parse_iges(&text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.global.parameter_delimiter, '/');
    assert_eq!(m.global.record_delimiter, '#');
    assert_eq!(m.global.model_space_scale, 2.5);
    assert_eq!(m.global.units_flag, 6);
    assert_eq!(m.global.unit_in_metres(), Some(1.0));
    assert_eq!(m.global.min_resolution, 1e-6);
    assert_eq!(m.global.max_coordinate, Some(10.0));
    assert_eq!(m.global.author, "a/b#c");
    assert_eq!(
        m.entities[0].kind,
        EntityData::Line {
            start: [1., 2., 3.],
            end: [4., 5., 6.5]
        }
    );

    // defaulted delimiters and a short (old-style) Global section
    let text = build(",,4Htest;", &[ent(110, "110,1,2,3,4,5,6;")]);
    let m = parse_iges(&text).unwrap();
    assert_eq!(m.global.product_id_sender, "test");
    assert_eq!(m.global.model_space_scale, 1.0);
    assert_eq!(m.global.max_coordinate, None);
}

#[test]
fn numbers() {
    assert_eq!(parse_real("1.0D0"), Some(1.0));
    assert_eq!(parse_real("-2.5d-3"), Some(-2.5e-3));
    assert_eq!(parse_real("1.5D+2"), Some(150.0));
    assert_eq!(parse_real("1."), Some(1.0));
    assert_eq!(parse_real(".5"), Some(0.5));
    assert_eq!(parse_real("-0."), Some(0.0));
    assert_eq!(parse_real("1E-07"), Some(1e-7));
    assert_eq!(parse_real("7"), Some(7.0));
    for bad in [
        "", ".", "E5", "D1", "abc", "inf", "nan", "1.0X", "1..0", "--1", "1e999",
    ] {
        assert_eq!(parse_real(bad), None, "{bad}");
    }
    assert_eq!(parse_int("42"), Some(42));
    assert_eq!(parse_int("-7"), Some(-7));
    assert_eq!(parse_int("+3"), Some(3));
    for bad in ["", "-", "1.", "1E2", "x", "99999999999999999999999"] {
        assert_eq!(parse_int(bad), None, "{bad}");
    }
}

// ---------------------------------------------------------------------------------------------
// malformed input
// ---------------------------------------------------------------------------------------------

fn err(text: &str) -> IgesError {
    match parse_iges(text) {
        Ok(_) => panic!("expected an error for\n{text}"),
        Err(e) => e,
    }
}

#[test]
fn bad_section_letter_names_the_line() {
    let text = fixture("formats/torus.igs");
    let bad = patch(&text, 12, 73, "X");
    let e = err(&bad);
    assert!(
        matches!(
            e,
            IgesError::Section {
                line: 12,
                found: 'X',
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("line 12"), "{e}");
    // a P record among the D records
    let bad = patch(&text, 12, 73, "P");
    assert_eq!(err(&bad).line(), Some(12));
    // a D record after the P section started
    let first_p = line_of(&text, |l| &l[72..73] == "P");
    let bad = patch(&text, first_p + 1, 73, "D");
    assert!(matches!(err(&bad), IgesError::Section { line, .. } if line == first_p + 1));
    // binary/compressed flag
    let bad = patch(&text, 1, 73, "C");
    let e = err(&bad);
    assert!(e.to_string().contains("compressed"), "{e}");
}

#[test]
fn sequence_gap_names_the_line() {
    let text = fixture("formats/torus.igs");
    let bad = patch(&text, 20, 74, "0000099");
    let e = err(&bad);
    assert!(
        matches!(
            e,
            IgesError::Sequence {
                line: 20,
                section: 'D',
                expected: 15,
                ..
            }
        ),
        "{e}"
    );
    // removing a record
    let mut lines: Vec<&str> = text.lines().collect();
    lines.remove(10);
    let e = err(&(lines.join("\n") + "\n"));
    assert_eq!(e.line(), Some(11), "{e}");
    // a short record
    let bad = text.replacen("144,3,1,0,11;", "144,3,1,0,11; ", 1);
    assert!(matches!(err(&bad), IgesError::Syntax { .. }));
}

#[test]
fn truncated_parameter_data_names_the_directory_entry() {
    let text = build(
        GLOBAL,
        &[ent(110, "110,0,0,0,1,1,1;"), ent(110, "110,0,0,0,2,2,2;")],
    );
    parse_iges(&text).unwrap();
    // DE 3 points to P record 9 of 2
    let de3 = line_of(&text, |l| &l[72..80] == "D0000003");
    let bad = patch(&text, de3, 9, "       9");
    let e = err(&bad);
    assert!(
        matches!(e, IgesError::Syntax { line, .. } if line == de3),
        "{e}"
    );
    assert!(e.to_string().contains("parameter data records 9..9"), "{e}");
    // line count 3
    let bad = patch(&text, de3 + 1, 25, "       3");
    assert_eq!(err(&bad).line(), Some(de3 + 1 - 1));
    // the parameters stop early (record delimiter after 4 coordinates)
    let text2 = build(GLOBAL, &[ent(110, "110,0,0,0,1;")]);
    let e = err(&text2);
    let pline = line_of(&text2, |l| &l[72..73] == "P");
    assert!(
        matches!(e, IgesError::Parameter { line, index: 4, name: "Y2", .. } if line == pline),
        "{e}"
    );
    // no record delimiter at all
    let text3 = build(GLOBAL, &[ent(110, "110,0,0,0,1,1,1")]);
    let e = err(&text3);
    assert!(e.to_string().contains("record delimiter"), "{e}");
    // a count running past the end of the parameters
    let text4 = build(
        GLOBAL,
        &[ent(110, "110,0,0,0,1,1,1;"), ent(102, "102,5,1;")],
    );
    let e = err(&text4);
    assert!(matches!(e, IgesError::Parameter { name: "N", .. }), "{e}");
    let text5 = build(GLOBAL, &[ent(126, "126,1000000000,3,0,0,1,0,0.;")]);
    assert!(matches!(err(&text5), IgesError::Parameter { .. }));
}

#[test]
fn non_numeric_parameter_names_the_line() {
    let text = build(
        GLOBAL,
        &[ent(
            110,
            "110,0.,0.,0.,1.,1.,                                             abc;",
        )],
    );
    let p2 = line_of(&text, |l| &l[72..80] == "P0000002");
    let e = err(&text);
    assert!(
        matches!(&e, IgesError::Parameter { line, entity_type: 110, de: 1, name: "Z2", found, .. }
            if *line == p2 && found.contains("abc")),
        "{e}"
    );
    assert!(e.to_string().contains(&format!("line {p2}")), "{e}");
    // a string where a number is expected
    let e = err(&build(GLOBAL, &[ent(100, "100,3HABC,0,0,1,0,1,0;")]));
    assert!(matches!(e, IgesError::Parameter { name: "ZT", .. }), "{e}");
    // a real where an integer pointer is expected
    let e = err(&build(
        GLOBAL,
        &[ent(110, "110,0,0,0,1,1,1;"), ent(102, "102,1,1.5;")],
    ));
    assert!(
        matches!(e, IgesError::Parameter { name: "DE(i)", .. }),
        "{e}"
    );
    // a pointer to nothing
    let e = err(&build(GLOBAL, &[ent(102, "102,1,7;")]));
    assert!(e.to_string().contains("existing Directory Entry"), "{e}");
    // the entity type number in the parameters differs from the DE
    let e = err(&build(GLOBAL, &[ent(110, "100,0,0,0,1,1,1;")]));
    assert!(matches!(e, IgesError::Parameter { index: 0, .. }), "{e}");
    // a bad Global field
    let g = GLOBAL.replacen(",1.0,2,", ",x1.0,2,", 1);
    let e = err(&build(&g, &[ent(110, "110,0,0,0,1,1,1;")]));
    assert!(e.to_string().contains("model space scale"), "{e}");
    assert_eq!(e.line(), Some(2));
    // a bad DE field
    let text = build(GLOBAL, &[ent(110, "110,0,0,0,1,1,1;")]);
    let de1 = line_of(&text, |l| &l[72..80] == "D0000001");
    let e = err(&patch(&text, de1, 9, "     1x "));
    assert!(
        matches!(e, IgesError::Syntax { line, .. } if line == de1),
        "{e}"
    );
    // transformation pointer to a non-124
    let e = err(&build(
        GLOBAL,
        &[E {
            ty: 110,
            form: 0,
            transform: 1,
            params: "110,0,0,0,1,1,1;",
        }],
    ));
    assert!(e.to_string().contains("transformation"), "{e}");
    // a cycle of transformations
    let m = "124,1,0,0,0,0,1,0,0,0,0,1,0;";
    let cyc = [
        E {
            ty: 124,
            form: 0,
            transform: 3,
            params: m,
        },
        E {
            ty: 124,
            form: 0,
            transform: 1,
            params: m,
        },
    ];
    assert!(matches!(
        err(&build(GLOBAL, &cyc)),
        IgesError::ReferenceCycle {
            via: ReferenceKind::Transformation,
            ..
        }
    ));
}

#[test]
fn back_pointer_mismatch_names_the_line() {
    let text = fixture("formats/torus.igs");
    let p3 = line_of(&text, |l| &l[72..80] == "P0000003");
    let bad = patch(&text, p3, 66, "0000007");
    let e = err(&bad);
    assert!(
        matches!(&e, IgesError::BackPointer { line, expected: 5, .. } if *line == p3),
        "{e}"
    );
}

#[test]
fn truncations_never_panic_and_always_fail() {
    for rel in ["formats/torus.igs", "naca0012/naca0012.igs"] {
        let text = fixture(rel);
        let full_lines = text.lines().count();
        let n = text.len();
        let mut lengths: Vec<usize> = (0..100).map(|i| i * n / 100).collect();
        // whole-line truncations too
        let mut acc = 0;
        for (i, l) in text.lines().enumerate() {
            acc += l.len() + 1;
            if i % 7 == 0 && acc < n {
                lengths.push(acc);
            }
        }
        for len in lengths {
            let e = match parse_iges(&text[..len]) {
                Ok(_) => panic!("{rel}: truncation at {len} of {n} parsed"),
                Err(e) => e,
            };
            let line = e.line().unwrap();
            assert!(line >= 1 && line <= full_lines + 1, "{rel} at {len}: {e}");
        }
    }
}

#[test]
fn single_character_corruptions_never_panic() {
    let text = fixture("formats/torus.igs");
    let bytes = text.as_bytes();
    for (k, pos) in (0..bytes.len()).step_by(13).enumerate() {
        for c in [b'9', b',', b';', b'H', b' ', b'-', b'X'] {
            if bytes[pos] == b'\n' {
                continue;
            }
            let mut b = bytes.to_vec();
            b[pos] = c;
            let t = String::from_utf8(b).unwrap();
            if let Err(e) = parse_iges(&t) {
                assert!(e.line().is_some(), "{k}: {e}");
            }
        }
    }
    // empty and non-ASCII input
    assert_eq!(err("").line(), Some(1));
    assert_eq!(err("\n\n").line(), Some(1));
    let na = text.replacen("144,3,1", "144,3,\u{e9}", 1);
    assert!(matches!(err(&na), IgesError::Syntax { .. }));
}
