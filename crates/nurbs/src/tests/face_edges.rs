use super::*;
use crate::conics::line_segment;
use crate::shapes::circle;

fn named(curves: Vec<NurbsCurve>) -> Vec<(String, NurbsCurve)> {
    curves
        .into_iter()
        .enumerate()
        .map(|(k, c)| (format!("copy {k}"), c))
        .collect()
}

/// Copies of one edge on two faces are one edge between them, whichever way each runs;
/// the two halves of a circle (the same end points) are two edges; a seam that bounds one
/// face twice and an edge of one face alone are no edges between faces.
#[test]
fn copies_of_an_edge_on_two_faces_are_one_edge_between_them() {
    let (a, b) = ([0.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
    let circle = circle([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0).unwrap();
    // The circle from (2, 0, 0) round to (0, 0, 0) and on back.
    let (t0, t1) = circle.domain();
    let (upper, lower) = circle.split_at(0.5 * (t0 + t1)).unwrap();
    let seam = line_segment([5.0, 0.0, 0.0], [5.0, 0.0, 1.0]).unwrap();
    let alone = line_segment([7.0, 0.0, 0.0], [8.0, 0.0, 0.0]).unwrap();
    let faces = vec![
        (0, named(vec![line_segment(a, b).unwrap(), upper.clone()])),
        (1, named(vec![line_segment(b, a).unwrap(), lower.clone()])),
        (2, named(vec![upper, seam.clone(), seam, alone])),
        (3, named(vec![lower])),
    ];
    let edges = edges_between_faces(&faces, 1e-9);
    let faces: Vec<&[usize]> = edges.iter().map(|e| e.faces.as_slice()).collect();
    assert_eq!(faces, [&[0, 1][..], &[0, 2], &[1, 3]]);
    // The line between faces 0 and 1 is face 0's copy.
    assert_eq!(edges[0].origin, "copy 0");
    assert_eq!(edges[0].curve.point(edges[0].curve.domain().0), a);
}

/// Copies apart by more than the tolerance are different edges.
#[test]
fn copies_apart_by_more_than_the_tolerance_are_different_edges() {
    let line = |y: f64| line_segment([0.0, y, 0.0], [1.0, y, 0.0]).unwrap();
    for (gap, together) in [(1e-10, true), (1e-6, false)] {
        let faces = vec![(0, named(vec![line(0.0)])), (1, named(vec![line(gap)]))];
        let edges = edges_between_faces(&faces, 1e-9);
        assert_eq!(edges.len(), usize::from(together), "{gap:e}");
    }
}

/// A model whose faces' copies of an edge are 1e-6 apart, the file stating 1e-7: no edge
/// between them; widened to 2e-6 (what the user knows of the model), the copies are
/// matched again into one edge. Widening to less than the file states changes nothing.
#[test]
fn a_wider_uncertainty_matches_the_copies_again() {
    use crate::model::{EntityGeometry, GeometricEntity, GeometryModel};
    use crate::NurbsSurface;
    let line = |y: f64| line_segment([0.0, y, 0.0], [1.0, y, 0.0]).unwrap();
    let plane = |name: &str, z: f64| {
        let surface = NurbsSurface::new(
            1,
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![0.0, 0.0, 1.0, 1.0],
            vec![[0.0, -1.0, z], [0.0, 1.0, z], [1.0, -1.0, z], [1.0, 1.0, z]],
            vec![1.0; 4],
        )
        .unwrap();
        GeometricEntity::new(name, name, EntityGeometry::Surface(surface))
    };
    let mut model = GeometryModel::new(vec![plane("a", 0.0), plane("b", 1e-6)], Some(1e-7));
    model.set_edges_between_faces(vec![
        (0, named(vec![line(0.0)])),
        (1, named(vec![line(1e-6)])),
    ]);
    assert!(model.edges.is_empty());
    model.widen_uncertainty(1e-8);
    assert_eq!(model.uncertainty, Some(1e-7));
    assert!(model.edges.is_empty());
    model.widen_uncertainty(2e-6);
    assert_eq!(model.uncertainty, Some(2e-6));
    let faces: Vec<&[usize]> = model.edges.iter().map(|e| e.faces.as_slice()).collect();
    assert_eq!(faces, [&[0, 1][..]]);
}
