use super::*;
use crate::assembly::assemble_condensed;
use crate::BoundaryConditions;
use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::NodeFamily;

/// The p = 1 system of a perturbed tetrahedral cube with one face fixed and one sliding.
fn cube_system() -> (HighOrderMesh, Constraints, crate::assembly::Assembled) {
    let linear = crate::p_multigrid::tests::tet_cube(6);
    let mesh = HighOrderMesh::from_linear(&linear, 1, NodeFamily::Fekete).unwrap();
    let mut bc = BoundaryConditions::default();
    for (n, x) in mesh.nodes.iter().enumerate() {
        if x[0] == 0.0 {
            bc.prescribed.insert(n as u32, [0.0; 3]);
        } else if x[2] == 0.0 {
            bc.sliding.insert(n as u32, [0.0, 0.3, 1.0]);
        }
    }
    let constraints = Constraints::new(mesh.nodes.len(), 3, &bc);
    let assembled = assemble_condensed(
        &mesh,
        &crate::Material::default(),
        None,
        &constraints,
        &mut |_| {},
    )
    .unwrap();
    (mesh, constraints, assembled)
}

#[test]
fn every_free_vertex_is_in_one_aggregate_and_the_modes_are_orthonormal() {
    let (mesh, constraints, assembled) = cube_system();
    let (of, count) = aggregates(&assembled.graph, &constraints);
    for (v, &a) in of.iter().enumerate() {
        assert_eq!(a == u32::MAX, constraints.count[v] == 0, "vertex {v}");
        assert!(a == u32::MAX || (a as usize) < count);
    }
    assert!(
        count > 1 && count < mesh.nodes.len() / 4,
        "{count} aggregates"
    );
    let p = tentative_prolongation(&of, count, &constraints, &mesh.nodes);
    assert_eq!(p.rows(), constraints.len());
    // Pᵀ P = I: the columns of each aggregate are orthonormal, aggregates are disjoint.
    let ptp = product(&transpose(&p), &p);
    for r in 0..ptp.rows() {
        for (c, &v) in ptp.outer_view(r).unwrap().iter() {
            let expected = if c == r { 1.0 } else { 0.0 };
            assert!((v - expected).abs() < 1e-12, "({r}, {c}) = {v}");
        }
    }
}

#[test]
fn rigid_motions_of_free_vertices_lie_in_the_coarse_space_and_have_no_energy() {
    let (mesh, constraints, assembled) = cube_system();
    let (p, coarse) = aggregation_level(
        &assembled.matrix,
        &assembled.graph,
        &constraints,
        &mesh.nodes,
    );
    assert_eq!(coarse.rows(), p.cols());
    // A rotation about the z axis, in the reduced unknowns (sliding vertices keep its
    // tangential part): P Pᵀ reproduces it on every aggregate (the modes span it).
    let rotation: Vec<f64> = (0..mesh.nodes.len())
        .flat_map(|v| {
            let x = mesh.nodes[v];
            let m = [-(x[1] - 0.5), x[0] - 0.5, 0.0];
            (0..constraints.count[v] as usize).map(move |i| (v, i, m))
        })
        .map(|(v, i, m)| {
            if constraints.identity[v] {
                m[i]
            } else {
                (0..3).map(|d| constraints.directions[v][i][d] * m[d]).sum()
            }
        })
        .collect();
    let mut coefficients = vec![0.0; p.cols()];
    crate::vector_ops::spmv(&transpose(&p), &rotation, &mut coefficients);
    let mut back = vec![0.0; p.rows()];
    crate::vector_ops::spmv(&p, &coefficients, &mut back);
    let error = rotation
        .iter()
        .zip(&back)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(error < 1e-12, "{error}");
    // The coarse matrix is symmetric.
    let t = transpose(&coarse);
    let scale = coarse.data().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for r in 0..coarse.rows() {
        for (c, &v) in coarse.outer_view(r).unwrap().iter() {
            let w = t.get(r, c).copied().unwrap_or(0.0);
            assert!((v - w).abs() <= 1e-12 * scale);
        }
    }
}
