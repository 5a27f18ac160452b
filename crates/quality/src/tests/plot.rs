use super::*;
use hocurve_mesh::ElementType;

#[test]
fn histograms_are_written_as_svg_with_labels() {
    let values = [1.0, 0.97, 0.9, 0.52, -0.1];
    let summary = QualitySummary::new(
        &[ElementType::Tri; 5],
        &values,
        &[1.0, 3.0, 300.0, 2.0, 1.2],
        None,
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("hist.svg");
    write_histogram_svg(&path, &summary).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..100.min(svg.len())]);
    assert!(svg.contains("Scaled Jacobian") && svg.contains("% of elements"));
    // plotters writes each label on its own line inside <text>.
    assert!(svg.contains("\n0.95\n") && svg.contains("\n≤0\n"));
    // Bars: one <rect> per non-empty bin besides the background.
    let stretch = dir.path().join("stretch.svg");
    write_stretching_histogram_svg(&stretch, &summary).unwrap();
    let svg = std::fs::read_to_string(&stretch).unwrap();
    assert!(svg.contains("Stretching") && svg.contains("200–500"));
    // No temporary file is left behind.
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 2);
}

#[test]
fn unwritable_path_is_an_io_error() {
    let summary = QualitySummary::new(&[], &[], &[], None);
    let err = write_histogram_svg(Path::new("/nonexistent-dir/x/h.svg"), &summary).unwrap_err();
    assert!(matches!(err, QualityError::Io { .. }), "{err}");
}
