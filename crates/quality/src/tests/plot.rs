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
