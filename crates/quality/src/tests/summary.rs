use super::*;

fn check(validity: Validity, lower: f64) -> ValidityCheck {
    ValidityCheck {
        validity,
        min_jacobian_lower_bound: 0.0,
        max_jacobian_upper_bound: 1.0,
        scaled_jacobian_lower_bound: lower,
        scaled_jacobian_upper_bound: 1.0,
        regions: 1,
    }
}

#[test]
fn bins_follow_the_correctly_rounded_edges() {
    assert_eq!(scaled_jacobian_bin(-0.3), 0);
    assert_eq!(scaled_jacobian_bin(0.0), 0);
    assert_eq!(scaled_jacobian_bin(f64::NAN), 0);
    assert_eq!(scaled_jacobian_bin(1e-300), 1);
    assert_eq!(scaled_jacobian_bin(0.05), 1);
    assert_eq!(scaled_jacobian_bin(0.55), 11); // 0.55·20 = 11.000000000000002
    assert_eq!(scaled_jacobian_bin(0.15), 3);
    assert_eq!(scaled_jacobian_bin(0.950_000_000_000_001), 20);
    assert_eq!(scaled_jacobian_bin(0.95), 19);
    assert_eq!(scaled_jacobian_bin(1.0), 20);
    assert_eq!(scaled_jacobian_bin(1.5), 20);
    for k in 1..=20 {
        let edge = k as f64 / 20.0;
        assert_eq!(scaled_jacobian_bin(edge), k);
        assert_eq!(scaled_jacobian_bin(edge + 1e-9), (k + 1).min(20));
    }
}

#[test]
fn summary_of_hand_made_values() {
    use Shape::{Hex, Tet};
    let kinds = [Tet, Tet, Tet, Hex, Tet, Hex, Tet, Tet];
    let scaled = [1.0, 0.96, 0.95, 0.4, -0.2, 0.0, 0.5, 0.97];
    let stretch = [1.0, 1.5, 2.0, 250.0, 199.0, 200.0, 1000.0, 4.0];
    let checks = [
        check(Validity::Valid, 0.9),
        check(Validity::Valid, 0.8),
        check(Validity::Valid, 0.7),
        check(Validity::Undecided, -0.1),
        check(Validity::Invalid, -0.5),
        check(Validity::Invalid, -0.3),
        check(Validity::Valid, 0.4),
        check(Validity::Valid, 0.9),
    ];
    let s = QualitySummary::new(&kinds, &scaled, &stretch, Some(&checks));
    assert_eq!(s.elements, 8);
    assert_eq!(s.elements_by_type["tetrahedron"], 6);
    assert_eq!(s.elements_by_type["hexahedron"], 2);
    assert_eq!(s.min_scaled_jacobian, Some(-0.2));
    assert_eq!(s.invalid_elements, 2); // −0.2 and 0.0
    assert_eq!(s.fraction_above_0_95, 3.0 / 8.0); // 1.0, 0.96, 0.97 (0.95 is not >)
    assert_eq!(s.elements_below_0_5, 3); // 0.4, −0.2, 0.0 (0.5 is not <)
    assert_eq!(s.max_stretching, Some(1000.0));
    assert_eq!(s.elements_stretched_above_200, 2); // 250, 1000 (200 is not >)
    let v = s.validity.unwrap();
    assert_eq!((v.valid, v.invalid, v.undecided), (5, 2, 1));
    assert_eq!(v.min_scaled_jacobian_lower_bound, Some(-0.5));

    let h = &s.scaled_jacobian_histogram;
    assert_eq!(h.bins.len(), 21);
    let counts: Vec<usize> = h.bins.iter().map(|b| b.count).collect();
    let mut want = vec![0; 21];
    want[0] = 2; // −0.2, 0.0
    want[8] = 1; // 0.4 ∈ (0.35, 0.40]
    want[10] = 1; // 0.5 ∈ (0.45, 0.50]
    want[19] = 1; // 0.95 ∈ (0.90, 0.95]
    want[20] = 3; // 0.96, 0.97, 1.0
    assert_eq!(counts, want);
    assert_eq!(h.bins[0].percentage, 25.0);
    assert_eq!(h.bins[20].percentage, 37.5);
    assert_eq!(h.bins[19].label, "(0.90, 0.95]");
    assert!((h.bins.iter().map(|b| b.percentage).sum::<f64>() - 100.0).abs() < 1e-12);

    let st: Vec<usize> = s
        .stretching_histogram
        .bins
        .iter()
        .map(|b| b.count)
        .collect();
    // [1,2): 1, 1.5; [2,5): 2, 4; [100,200): 199; [200,500): 200, 250; ≥1000: 1000.
    assert_eq!(st, vec![2, 2, 0, 0, 0, 0, 1, 2, 0, 1]);

    let json: serde_json::Value = serde_json::from_str(&s.to_json().unwrap()).unwrap();
    assert_eq!(json["invalid_elements"], 2);
    assert_eq!(json["fraction_above_0_95"], 0.375);
    assert_eq!(json["elements_below_0_5"], 3);
    assert_eq!(json["min_scaled_jacobian"], -0.2);
    assert_eq!(json["validity"]["undecided"], 1);
    assert_eq!(json["scaled_jacobian_histogram"]["bins"][20]["count"], 3);

    let table = s.to_string();
    assert!(table.contains("37.5 %"), "{table}");
    assert!(table.contains("5 valid, 2 invalid, 1 undecided"), "{table}");
}

#[test]
fn empty_mesh_summary_has_no_minimum() {
    let s = QualitySummary::new(&[], &[], &[], None);
    assert_eq!(s.min_scaled_jacobian, None);
    assert_eq!(s.fraction_above_0_95, 0.0);
    assert!(s
        .scaled_jacobian_histogram
        .bins
        .iter()
        .all(|b| b.percentage == 0.0));
}
