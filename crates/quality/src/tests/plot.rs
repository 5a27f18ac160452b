use super::*;
use hocurve_mesh::Shape;

#[test]
fn histograms_are_drawn_as_svg_with_labels() {
    let values = [1.0, 0.97, 0.9, 0.52, -0.1];
    let summary = QualitySummary::new(
        &[Shape::Tri; 5],
        &values,
        &[1.0, 3.0, 300.0, 2.0, 1.2],
        None,
    );
    let svg = scaled_jacobian_histogram_svg(&summary).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..100.min(svg.len())]);
    assert!(svg.contains("Scaled Jacobian") && svg.contains("% of elements"));
    // plotters writes each label on its own line inside <text>.
    assert!(svg.contains("\n0.95\n") && svg.contains("\n≤0\n"));
    let svg = stretching_histogram_svg(&summary).unwrap();
    assert!(svg.contains("Stretching") && svg.contains("200–500"));
}

#[test]
fn invalid_elements_get_a_red_bar_and_counts() {
    // One invalid element among 2000: 0.05 %, too thin to see without its count.
    let mut values = vec![0.9; 1999];
    values.push(-0.2);
    let n = values.len();
    let summary = QualitySummary::new(&vec![Shape::Tet; n], &values, &vec![1.0; n], None);
    let svg = scaled_jacobian_histogram_svg(&summary).unwrap();
    assert!(svg.contains("1 invalid element(s)"), "{svg}");
    assert!(
        svg.contains("#FF0000") || svg.contains("#ff0000"),
        "no red bar"
    );
    assert!(
        svg.contains("\n1999\n") && svg.contains("\n1\n"),
        "counts missing"
    );
    let valid = QualitySummary::new(&[Shape::Tet; 3], &[0.5; 3], &[1.0; 3], None);
    let svg = scaled_jacobian_histogram_svg(&valid).unwrap();
    assert!(svg.contains("no invalid element"));
    assert!(!svg.contains("#FF0000") && !svg.contains("#ff0000"));
}
