use super::*;
use crate::test_meshes::single_element;
use hocurve_mesh::Shape;

#[test]
fn stretching_is_longest_over_shortest_edge() {
    // Reference triangle: edges 1, √2, 1.
    let mesh = single_element(Shape::Tri, 2, |x| x);
    assert!((stretching(&mesh).unwrap()[0] - 2f64.sqrt()).abs() < 1e-15);
    // A 1 × 1 × 10 box: 10 (curving the interior nodes does not change it).
    let mesh = single_element(Shape::Hex, 2, |x| {
        [x[0] + 0.1 * x[1] * x[1] * (1.0 - x[1]), x[1], 10.0 * x[2]]
    });
    assert!((stretching(&mesh).unwrap()[0] - 10.0).abs() < 1e-13);
    // Reference tet stretched ×3 in z: edges 1, √2, 1, 3, √10, √10 → √10 / 1.
    let mesh = single_element(Shape::Tet, 1, |x| [x[0], x[1], 3.0 * x[2]]);
    assert!((stretching(&mesh).unwrap()[0] - 10f64.sqrt()).abs() < 1e-14);
}

#[test]
fn coincident_vertices_are_an_error() {
    let mut mesh = single_element(Shape::Quad, 1, |x| x);
    let v = mesh.cells[0].nodes[1] as usize;
    mesh.nodes[v] = mesh.nodes[mesh.cells[0].nodes[0] as usize];
    assert!(matches!(
        stretching(&mesh),
        Err(QualityError::DegenerateEdge { element: 0, .. })
    ));
}
