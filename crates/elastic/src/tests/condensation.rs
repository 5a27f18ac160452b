use super::*;

#[test]
fn sliding_frames_are_orthonormal_and_orthogonal_to_the_normal() {
    for normal in [
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -3.0],
        [1.0, 2.0, 2.0],
        [1e-9, 1.0, 1e-9],
    ] {
        let len = normal.iter().map(|v| v * v).sum::<f64>().sqrt();
        let [t1, t2] = tangents(normal, 3);
        let dot = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| a[i] * b[i]).sum::<f64>();
        assert!((dot(t1, t1) - 1.0).abs() < 1e-15);
        assert!((dot(t2, t2) - 1.0).abs() < 1e-15);
        assert!(dot(t1, t2).abs() < 1e-15);
        assert!(dot(t1, normal).abs() < 1e-15 * len);
        assert!(dot(t2, normal).abs() < 1e-15 * len);
    }
    let [t, _] = tangents([3.0, 4.0, 0.0], 2);
    assert_eq!(t, [-0.8, 0.6, 0.0]);
}

#[test]
fn prescribed_wins_over_sliding_and_expansion_inverts_restriction() {
    let mut bc = BoundaryConditions::default();
    bc.prescribed.insert(0, [0.1, 0.2, 0.3]);
    bc.sliding.insert(0, [1.0, 0.0, 0.0]);
    bc.sliding.insert(2, [0.0, 1.0, 1.0]);
    let c = Constraints::new(3, 3, &bc);
    assert_eq!(c.count, vec![0, 3, 2]);
    assert_eq!(c.first, vec![0, 0, 3, 5]);
    // A displacement of node 2 along its wall survives restrict → expand; the normal
    // part is removed.
    let full = [9.0, 9.0, 9.0, 1.0, 2.0, 3.0, 0.5, 0.7, -0.7];
    let u = c.expand(&c.restrict(&full));
    assert_eq!(u[0], [0.1, 0.2, 0.3]);
    assert_eq!(u[1], [1.0, 2.0, 3.0]);
    for d in 0..3 {
        assert!((u[2][d] - [0.5, 0.7, -0.7][d]).abs() < 1e-15);
    }
}
