//! The paper's Fig. 12b: interpolating f(x, y) = x cos y + y sin x on a straight-sided
//! mesh of the unit square converges exponentially in p.

use hocurve::interpolation::{interpolation_l2_error, paper_test_function, unit_square_mesh};
use hocurve::mesh::{HighOrderMesh, Shape};
use hocurve::nodes::NodeFamily;

#[test]
fn interpolation_error_falls_exponentially_with_p() {
    // 5 × 5 squares: 50 triangles or 25 quads; 7 × 7 = 49 quads.
    for (kind, n) in [(Shape::Tri, 5), (Shape::Quad, 7)] {
        let mesh = unit_square_mesh(n, kind);
        let mut errors = Vec::new();
        for p in 1..=7 {
            let ho = HighOrderMesh::from_linear(&mesh, p, NodeFamily::Fekete).unwrap();
            let e = interpolation_l2_error(&ho, paper_test_function).unwrap();
            eprintln!(
                "{kind} p={p} sqrt(ndof)={:.2} L2={e:.3e}",
                (ho.nodes.len() as f64).sqrt()
            );
            errors.push(e);
        }
        for p in 1..errors.len() {
            let ratio = errors[p - 1] / errors[p];
            assert!(
                ratio >= 4.0,
                "{kind}: p={} reduces the error only {ratio:.2}×",
                p + 1
            );
        }
        assert!(errors[6] < 1e-9, "{kind}: p=7 error {:.3e}", errors[6]);
    }
}
