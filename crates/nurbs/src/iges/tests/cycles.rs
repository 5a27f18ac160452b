//! References that lead back to themselves, nest absurdly deep or share entities
//! exponentially often, and absurd sizes: each is a specific error, never a stack overflow,
//! a hang or a huge allocation.

use super::tests::{build, ent, E, GLOBAL};
use super::*;
use crate::iges::geometry_from_iges;

fn convert(text: &str) -> Result<crate::GeometryModel, IgesError> {
    geometry_from_iges(&parse_iges(text)?)
}

#[test]
fn a_composite_curve_that_contains_itself_is_a_clear_error() {
    let text = build(GLOBAL, &[ent(102, "102,1,1;")]);
    match convert(&text) {
        Err(IgesError::ReferenceCycle {
            de: 1,
            entity_type: 102,
            cycle,
            ..
        }) => assert_eq!(cycle, "1 -> 1"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_trimmed_surface_whose_surface_is_itself_is_a_clear_error() {
    let text = build(GLOBAL, &[ent(144, "144,1,0,0,0;")]);
    let err = convert(&text).expect_err("a cycle");
    assert!(
        matches!(err, IgesError::ReferenceCycle { de: 1, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("refers to itself"), "{err}");
}

#[test]
fn a_cycle_through_several_entities_names_them() {
    // 102 (DE 1) holds 102 (DE 3), which holds a line and DE 1 again.
    let text = build(
        GLOBAL,
        &[
            ent(102, "102,1,3;"),
            ent(102, "102,2,5,1;"),
            ent(110, "110,0.,0.,0.,1.,0.,0.;"),
        ],
    );
    match convert(&text) {
        Err(IgesError::ReferenceCycle { cycle, .. }) => assert_eq!(cycle, "1 -> 3 -> 1"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn nesting_deeper_than_the_limit_is_a_clear_error_and_within_it_converts() {
    let chain = |depth: usize| {
        // Composite k holds composite k + 1; the last holds a line.
        let params: Vec<String> = (0..depth)
            .map(|k| format!("102,1,{};", 2 * (k + 1) + 1))
            .chain(std::iter::once("110,0.,0.,0.,1.,0.,0.;".to_string()))
            .collect();
        let ents: Vec<_> = params
            .iter()
            .enumerate()
            .map(|(k, p)| ent(if k < depth { 102 } else { 110 }, p))
            .collect();
        build(GLOBAL, &ents)
    };
    let err = convert(&chain(MAX_NESTING + 5)).expect_err("too deep");
    assert!(matches!(err, IgesError::NestingTooDeep { .. }), "{err}");
    let model = convert(&chain(MAX_NESTING - 2)).expect("a chain within the limit converts");
    assert_eq!(model.entities.len(), 1);
}

fn with_transform(mut e: E<'_>, transform: u32) -> E<'_> {
    e.transform = transform;
    e
}

/// The cycle and the pointers it runs through, or a panic naming what came instead.
fn cycle_of(result: Result<impl std::fmt::Debug, IgesError>) -> (u32, String, ReferenceKind) {
    match result {
        Err(IgesError::ReferenceCycle { de, cycle, via, .. }) => (de, cycle, via),
        other => panic!("expected a reference cycle, got {other:?}"),
    }
}

#[test]
fn a_cycle_error_names_the_line_the_entity_and_the_chain() {
    let text = build(
        GLOBAL,
        &[
            ent(110, "110,0.,0.,0.,1.,0.,0.;"),
            ent(102, "102,1,5;"),
            ent(102, "102,2,1,3;"),
        ],
    );
    let err = convert(&text).expect_err("a cycle");
    // DE 3 is the second Directory Entry pair: file lines 6 and 7 after one S and two G
    assert_eq!(
        err.to_string(),
        "IGES line 6: entity type 102 (DE 3) refers to itself through DE 3 -> 5 -> 3 \
         (parameter pointers)"
    );
}

#[test]
fn a_transformation_matrix_that_transforms_itself_is_a_clear_error() {
    let text = build(
        GLOBAL,
        &[with_transform(
            ent(124, "124,1.,0.,0.,1.,0.,1.,0.,0.,0.,0.,1.,0.;"),
            1,
        )],
    );
    // rejected by the parser already: transform_of() must never meet a cycle
    let (de, cycle, via) = cycle_of(parse_iges(&text));
    assert_eq!(
        (de, cycle.as_str(), via),
        (1, "1 -> 1", ReferenceKind::Transformation)
    );
}

#[test]
fn transformation_matrices_in_a_cycle_are_a_clear_error() {
    // a line under DE 3, which is under DE 5, which is under DE 3 again
    let matrix = "124,1.,0.,0.,1.,0.,1.,0.,0.,0.,0.,1.,0.;";
    let text = build(
        GLOBAL,
        &[
            with_transform(ent(110, "110,0.,0.,0.,1.,0.,0.;"), 3),
            with_transform(ent(124, matrix), 5),
            with_transform(ent(124, matrix), 3),
        ],
    );
    let err = parse_iges(&text).expect_err("a cycle");
    assert!(
        err.to_string().ends_with(
            "refers to itself through DE 3 -> 5 -> 3 (transformation matrix pointers (DE field 7))"
        ),
        "{err}"
    );
    let (de, _, via) = cycle_of(Err::<(), _>(err));
    assert_eq!((de, via), (3, ReferenceKind::Transformation));
}

#[test]
fn a_transformation_chain_longer_than_the_limit_is_a_clear_error_and_within_it_converts() {
    // matrices 0..n, each a translation by +1 in x under the next; the line under the first
    let chain = |n: usize| {
        let matrix = "124,1.,0.,0.,1.,0.,1.,0.,0.,0.,0.,1.,0.;";
        let mut ents = vec![with_transform(ent(110, "110,0.,0.,0.,0.,1.,0.;"), 3)];
        for k in 0..n {
            let next = if k + 1 < n { 2 * (k + 2) + 1 } else { 0 };
            ents.push(with_transform(ent(124, matrix), next as u32));
        }
        build(GLOBAL, &ents)
    };
    match parse_iges(&chain(MAX_NESTING + 1)) {
        Err(IgesError::NestingTooDeep { max, via, .. }) => {
            assert_eq!((max, via), (MAX_NESTING, ReferenceKind::Transformation))
        }
        other => panic!("{other:?}"),
    }
    let model = convert(&chain(MAX_NESTING)).expect("a chain of the limit's length converts");
    let crate::EntityGeometry::Curve(line) = &model.entities[0].geometry else {
        panic!("a line");
    };
    assert_eq!(line.control_points[0], [MAX_NESTING as f64, 0.0, 0.0]);
}

#[test]
fn a_curve_on_surface_on_itself_is_a_clear_error() {
    // SPTR names the 142 itself
    let text = build(GLOBAL, &[ent(142, "142,0,1,0,0,0;")]);
    assert_eq!(cycle_of(convert(&text)).1, "1 -> 1");
    // CPTR (its model-space curve) names it
    let text = build(
        GLOBAL,
        &[
            ent(142, "142,0,3,0,1,2;"),
            ent(128, "128,1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,0.,1.,0.,1.,1.,0.,0.,1.,0.,1.;"),
        ],
    );
    assert_eq!(cycle_of(convert(&text)).1, "1 -> 1");
}

#[test]
fn a_trimmed_surface_bounded_by_a_curve_on_itself_is_a_clear_error() {
    // 144 (DE 1) on the 128 (DE 3), outer boundary the 142 (DE 5) whose surface is DE 1
    let text = build(
        GLOBAL,
        &[
            ent(144, "144,3,1,0,5;"),
            ent(128, "128,1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,0.,1.,0.,1.,1.,0.,0.,1.,0.,1.;"),
            ent(142, "142,0,1,0,7,2;"),
            ent(110, "110,0.,0.,0.,1.,0.,0.;"),
        ],
    );
    assert_eq!(cycle_of(convert(&text)).1, "1 -> 5 -> 1");
}

#[test]
fn a_revolution_whose_generatrix_leads_back_is_a_clear_error() {
    // 120 (DE 1) about the line DE 3, generatrix the composite DE 5 holding DE 1
    let text = build(
        GLOBAL,
        &[
            ent(120, "120,3,5,0.,6.283185307;"),
            ent(110, "110,0.,0.,0.,0.,0.,1.;"),
            ent(102, "102,1,1;"),
        ],
    );
    let (de, cycle, via) = cycle_of(convert(&text));
    assert_eq!(
        (de, cycle.as_str(), via),
        (1, "1 -> 5 -> 1", ReferenceKind::Parameter)
    );
}

#[test]
fn exponentially_shared_references_are_a_clear_error() {
    // composite k holds composite k + 1 twice: 2^60 paths to the line at the bottom, each a
    // curve of the converted model if nothing stopped it
    let depth = 60;
    let params: Vec<String> = (0..depth)
        .map(|k| {
            let next = 2 * (k + 1) + 1;
            format!("102,2,{next},{next};")
        })
        .chain(std::iter::once("110,0.,0.,0.,1.,0.,0.;".to_string()))
        .collect();
    let ents: Vec<_> = params
        .iter()
        .enumerate()
        .map(|(k, p)| ent(if k < depth { 102 } else { 110 }, p))
        .collect();
    let started = std::time::Instant::now();
    match convert(&build(GLOBAL, &ents)) {
        Err(IgesError::ExpansionTooLarge { limit, records, .. }) => {
            assert_eq!(records, depth + 1);
            assert_eq!(limit, EXPANSION_FACTOR * records + EXPANSION_MINIMUM);
        }
        other => panic!("{:?}", other.map(|m| m.entities.len())),
    }
    assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
}

#[test]
fn a_degree_above_the_supported_maximum_is_a_parameter_error() {
    // K = 1, M = 25, then zeros enough for the counts to fit
    let params = format!("126,1,25,0,0,1,0,{}0.;", "0.,".repeat(60));
    let text = build(GLOBAL, &[ent(126, &params)]);
    match parse_iges(&text) {
        Err(IgesError::Parameter {
            name: "M",
            index: 1,
            expected,
            ..
        }) => assert!(expected.contains("from 0 to 24"), "{expected}"),
        other => panic!("{other:?}"),
    }
    // the same for a surface's second degree
    let params = format!("128,1,1,1,25,0,0,1,0,0,{}0.;", "0.,".repeat(80));
    let text = build(GLOBAL, &[ent(128, &params)]);
    assert!(
        matches!(
            parse_iges(&text),
            Err(IgesError::Parameter { name: "M2", .. })
        ),
        "{text}"
    );
}

#[test]
fn counts_larger_than_the_data_are_errors_before_any_allocation() {
    for params in [
        "102,999999999999,1;",
        "144,1,0,4000000000,0;",
        "126,999999999,1,0,0,1,0,0.,1.;",
        "128,99999,99999,1,1,0,0,1,0,0,0.;",
    ] {
        let ty = params[..3].parse().unwrap();
        let text = build(GLOBAL, &[ent(ty, params)]);
        assert!(
            matches!(parse_iges(&text), Err(IgesError::Parameter { .. })),
            "{params}"
        );
    }
}

#[test]
fn the_deepest_accepted_nesting_converts_on_a_small_stack() {
    // A revolution (DE 1) about a line (DE 3) of a generatrix that is a chain of composites
    // ending in a line: MAX_NESTING levels in all, the most check_references accepts. Each
    // level is a few frames of the recursive conversion (surface, curve, join); on a
    // thread of 512 KiB (a quarter of the default) it must not overflow.
    let composites = MAX_NESTING - 2;
    let mut params = vec![
        "120,3,5,0.,6.283185307;".to_string(),
        "110,0.,0.,0.,0.,0.,1.;".to_string(),
    ];
    for k in 0..composites {
        params.push(format!("102,1,{};", 2 * (k + 3) + 1));
    }
    params.push("110,1.,0.,0.,1.,0.,1.;".to_string());
    let ents: Vec<_> = params
        .iter()
        .map(|p| ent(p[..3].parse().unwrap_or(0), p))
        .collect();
    let text = build(GLOBAL, &ents);
    let model = std::thread::Builder::new()
        .stack_size(512 << 10)
        .spawn(move || convert(&text).map(|m| m.entities.len()))
        .expect("a thread")
        .join()
        .expect("no stack overflow (that would abort) and no panic");
    assert_eq!(model.expect("converts"), 1);
    // one level more is refused
    let mut deeper = params.clone();
    let last = deeper.len();
    deeper.insert(last - 1, format!("102,1,{};", 2 * last + 1));
    let ents: Vec<_> = deeper
        .iter()
        .map(|p| ent(p[..3].parse().unwrap_or(0), p))
        .collect();
    assert!(matches!(
        convert(&build(GLOBAL, &ents)),
        Err(IgesError::NestingTooDeep { .. })
    ));
}
