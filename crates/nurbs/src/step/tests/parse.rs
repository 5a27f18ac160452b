use super::*;

const SAMPLE: &str = "ISO-10303-21;
HEADER;
FILE_DESCRIPTION(('Open CASCADE Model'),'2;1');
FILE_NAME('a.step','2026-11-26T10:00:00',('Author'),(''),'x','y','DATA;');
ENDSEC;
DATA;
/* a comment */
#1 = CARTESIAN_POINT('',(0.,-1.5E+01,2));
#2 = DIRECTION('it''s',(0.,0.,1.));
#3 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );
#4 = UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#3,
  'distance_accuracy_value','confusion accuracy');
#5 = AXIS2_PLACEMENT_3D('',#1,#2,$);
ENDSEC;
END-ISO-10303-21;
";

#[test]
fn instances_and_values_are_read() {
    let file = parse_step(SAMPLE.as_bytes()).unwrap();
    assert_eq!(file.instances.len(), 5);
    let p = &file.instances[&1];
    assert_eq!((p.line, p.type_name()), (8, "CARTESIAN_POINT".to_string()));
    let coords: Vec<f64> = p.records[0].params[1]
        .list()
        .unwrap()
        .iter()
        .map(|v| v.real().unwrap())
        .collect();
    assert_eq!(coords, vec![0.0, -15.0, 2.0]);
    assert_eq!(
        file.instances[&2].records[0].params[0],
        StepValue::String("it's".into())
    );
    let unit = &file.instances[&3];
    assert_eq!(unit.type_name(), "LENGTH_UNIT+NAMED_UNIT+SI_UNIT");
    assert_eq!(
        unit.record("SI_UNIT").unwrap().params[0].enumeration(),
        Some("MILLI")
    );
    assert_eq!(
        unit.record("NAMED_UNIT").unwrap().params[0],
        StepValue::Derived
    );
    let m = &file.instances[&4];
    assert_eq!(m.line, 11);
    assert_eq!(m.records[0].params[0].real(), Some(1e-7));
    assert_eq!(m.records[0].params[1].reference(), Some(3));
    assert_eq!(file.instances[&5].records[0].params[3], StepValue::Unset);
}

#[test]
fn syntax_errors_name_their_line() {
    for (text, line, what) in [
        (
            "ISO-10303-21;\nDATA;\n#1 = POINT('',(1.,2.);\nENDSEC;\nEND-ISO-10303-21;\n",
            3,
            "expected",
        ),
        (
            "ISO-10303-21;\nDATA;\n#1 = POINT('x);\n",
            3,
            "unterminated string",
        ),
        (
            "ISO-10303-21;\nDATA;\n#1 = A();\n#1 = B();\nENDSEC;\nEND-ISO-10303-21;\n",
            4,
            "twice",
        ),
        (
            "ISO-10303-21;\nDATA;\n#1 = A(1.2.3);\nENDSEC;\n",
            3,
            "not a number",
        ),
        ("ISO-10303-21;\nDATA;\n#1 = A();\n", 4, "ENDSEC"),
        ("HELLO", 1, "ISO-10303-21"),
    ] {
        let err = parse_step(text.as_bytes()).unwrap_err();
        let message = err.to_string();
        assert!(message.contains(&format!("line {line}")), "{message}");
        assert!(message.contains(what), "{message}");
    }
}

#[test]
fn truncated_files_never_panic() {
    for n in 0..SAMPLE.len() {
        let _ = parse_step(&SAMPLE.as_bytes()[..n]);
    }
}

#[test]
fn deeply_nested_lists_are_refused_not_a_stack_overflow() {
    let text = format!(
        "ISO-10303-21;\nDATA;\n#1 = A({}1{});\nENDSEC;\nEND-ISO-10303-21;\n",
        "(".repeat(100_000),
        ")".repeat(100_000)
    );
    let err = parse_step(text.as_bytes()).unwrap_err().to_string();
    assert!(err.contains("nested") && err.contains("line 3"), "{err}");
}
