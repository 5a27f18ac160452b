use super::*;
use crate::condensation::{condense_matrix, Constraints};
use crate::sparse::from_rows;
use crate::vector_ops::spmv;
use crate::BoundaryConditions;

#[test]
fn block_mat_vec_equals_the_csr_one() {
    // Three nodes in 3D, all coupled, with a dense pseudo-random symmetric K; node 1 slides
    // (2 dofs), node 2 is free, node 0 is prescribed.
    let graph = Adjacency::from_parts(vec![0, 3, 6, 9], vec![0, 1, 2, 0, 1, 2, 0, 1, 2]);
    let value = |r: usize, c: usize| 1.0 + ((r * 7 + c * 7 + r * c) % 11) as f64 / 3.0;
    let k = from_rows(
        9,
        (0..9)
            .map(|r| (0..9).map(|c| (c as u32, value(r, c))).collect())
            .collect(),
    );
    let mut bc = BoundaryConditions::default();
    bc.prescribed.insert(0, [0.1, 0.0, 0.0]);
    bc.sliding.insert(1, [1.0, 2.0, 2.0]);
    let constraints = Constraints::new(3, 3, &bc);
    let a = condense_matrix(&k, &graph, &constraints);
    assert_eq!(a.rows(), 5);
    let pattern = BlockPattern::new(&a, &graph, &constraints).unwrap();
    let x = [0.3, -1.5, 2.25, 0.7, -0.125];
    let mut expected = vec![0.0; 5];
    spmv(&a, &x, &mut expected);
    let mut y = vec![0.0; 5];
    let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    pattern.apply(a.data(), &x, &mut y);
    assert!(y
        .iter()
        .zip(&expected)
        .all(|(a, b)| (a - b).abs() < 1e-14 * scale));
    BlockOperator::single(pattern, &a).apply(&x, &mut y);
    assert!(y
        .iter()
        .zip(&expected)
        .all(|(a, b)| (a - b).abs() < 1e-6 * scale));
}

/// Timing of the three mat-vecs on a p = 4 cube (run with `--ignored --nocapture`, release).
#[test]
#[ignore]
fn mat_vec_timings() {
    use hocurve_nodes::NodeFamily;
    let linear = crate::p_multigrid::tests::tet_cube(6);
    let mesh = hocurve_mesh::HighOrderMesh::from_linear(&linear, 4, NodeFamily::Fekete).unwrap();
    let assembled = crate::assembly::assemble(&mesh, &crate::Material::default()).unwrap();
    let mut bc = BoundaryConditions::default();
    bc.prescribed.insert(0, [0.0; 3]);
    let constraints = Constraints::new(mesh.nodes.len(), 3, &bc);
    let a = condense_matrix(&assembled.matrix, &assembled.graph, &constraints);
    let pattern = BlockPattern::new(&a, &assembled.graph, &constraints).unwrap();
    let single = BlockOperator::single(pattern.clone(), &a);
    let x: Vec<f64> = (0..a.rows()).map(|i| (i % 17) as f64).collect();
    let mut y = vec![0.0; a.rows()];
    let values32: Vec<f32> = a.data().iter().map(|&v| v as f32).collect();
    let csr32 = |x: &[f64], y: &mut [f64]| {
        use rayon::prelude::*;
        let indptr = a.indptr().into_raw_storage();
        let indices = a.indices();
        y.par_iter_mut()
            .with_min_len(256)
            .enumerate()
            .for_each(|(r, yr)| {
                let range = indptr[r]..indptr[r + 1];
                *yr = indices[range.clone()]
                    .iter()
                    .zip(&values32[range])
                    .map(|(&c, &v)| v as f64 * x[c as usize])
                    .sum();
            });
    };
    let mut best = [f64::MAX; 4];
    for _ in 0..20 {
        for (k, best) in best.iter_mut().enumerate() {
            let t = std::time::Instant::now();
            match k {
                0 => spmv(&a, &x, &mut y),
                1 => pattern.apply(a.data(), &x, &mut y),
                2 => single.apply(&x, &mut y),
                _ => csr32(&x, &mut y),
            }
            *best = best.min(t.elapsed().as_secs_f64());
        }
    }
    println!(
        "{} rows, {} nnz: csr {:.1} ms, block f64 {:.1} ms, block f32 {:.1} ms, csr f32 {:.1} ms",
        a.rows(),
        a.nnz(),
        1e3 * best[0],
        1e3 * best[1],
        1e3 * best[2],
        1e3 * best[3]
    );
}
