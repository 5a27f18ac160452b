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

#[test]
fn direct_condensed_assembly_equals_the_condensed_full_matrix() {
    use crate::assembly::{assemble, assemble_condensed};
    use crate::vector_ops::spmv;
    use hocurve_nodes::NodeFamily;
    let linear = crate::p_multigrid::tests::tet_cube(2);
    let mesh = hocurve_mesh::HighOrderMesh::from_linear(&linear, 3, NodeFamily::Fekete).unwrap();
    let material = crate::Material::default();
    // Nodes on x = 0 prescribed (a non-zero field), on z = 0 sliding on a slanted normal, the
    // rest free.
    let mut bc = BoundaryConditions::default();
    for (n, x) in mesh.nodes.iter().enumerate() {
        if x[0] == 0.0 {
            bc.prescribed
                .insert(n as u32, [0.01 * x[1], -0.02 * x[2], 0.03]);
        } else if x[2] == 0.0 {
            bc.sliding.insert(n as u32, [0.2, 0.1, 1.0]);
        }
    }
    let constraints = Constraints::new(mesh.nodes.len(), 3, &bc);
    let full = assemble(&mesh, &material).unwrap();
    let expected = condense_matrix(&full.matrix, &full.graph, &constraints);
    let mut k_up = vec![0.0; mesh.nodes.len() * 3];
    spmv(&full.matrix, &constraints.prescribed, &mut k_up);
    let expected_rhs: Vec<f64> = constraints.restrict(&k_up).iter().map(|v| -v).collect();

    let direct = assemble_condensed(&mesh, &material, None, &constraints, &mut |_| {}).unwrap();
    assert_eq!(direct.matrix.indptr(), expected.indptr());
    assert_eq!(direct.matrix.indices(), expected.indices());
    let scale = expected.data().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(!bc.sliding.is_empty() && !bc.prescribed.is_empty());
    for row in 0..expected.rows() {
        let range = expected.indptr().outer_inds_sz(row);
        for k in range {
            let (a, b) = (direct.matrix.data()[k], expected.data()[k]);
            assert!((a - b).abs() <= 1e-13 * scale, "row {row}: {a} vs {b}");
        }
    }
    // Blocks between free nodes are the element sums in the same order: bitwise equal.
    let free_free = (0..mesh.nodes.len())
        .filter(|&n| constraints.identity[n])
        .all(|n| {
            let r = constraints.first[n];
            let range = expected.indptr().outer_inds_sz(r);
            direct.matrix.indices()[range.clone()]
                .iter()
                .zip(range)
                .filter(|(&col, _)| {
                    let m = constraints.first.partition_point(|&f| f <= col as usize) - 1;
                    constraints.identity[m]
                })
                .all(|(_, k)| direct.matrix.data()[k] == expected.data()[k])
        });
    assert!(free_free);
    let rhs_scale = expected_rhs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(rhs_scale > 0.0);
    for (a, b) in direct.rhs.iter().zip(&expected_rhs) {
        assert!((a - b).abs() <= 1e-13 * rhs_scale, "{a} vs {b}");
    }
}
