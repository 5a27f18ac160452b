use super::*;
use crate::p_multigrid::tests::levels_of;
use crate::vector_ops::spmv;

fn pseudo_random(n: usize, seed: usize) -> Vec<f64> {
    (0..n)
        .map(|i| (((i + seed).wrapping_mul(2_654_435_761) >> 5) % 1000) as f64 / 500.0 - 1.0)
        .collect()
}

#[test]
fn cell_by_cell_transfer_equals_the_prolongation_matrix_and_its_transpose() {
    for (p, q, slide) in [(2, 1, true), (3, 2, true), (4, 3, false), (4, 2, true)] {
        let (fine, coarse) = levels_of(4, p, q, slide);
        let matrix = crate::p_multigrid::prolongation(&fine, &coarse).unwrap();
        let transfer = CellTransfer::new(
            &fine.mesh,
            &fine.constraints,
            &coarse.mesh,
            &coarse.constraints,
        )
        .unwrap();
        assert_eq!(transfer.coarse_len(), coarse.constraints.len());
        assert!(fine.mesh.cells.len() > 128, "several runs");
        let (nf, nc) = (fine.constraints.len(), coarse.constraints.len());
        let x = pseudo_random(nc, 1);
        let (mut expected, mut found) = (vec![0.0; nf], vec![0.0; nf]);
        spmv(&matrix, &x, &mut expected);
        transfer.prolong(&x, &mut found);
        for (e, f) in expected.iter().zip(&found) {
            assert!((e - f).abs() < 1e-13, "P, p = {p}, q = {q}: {e} vs {f}");
        }
        let r = pseudo_random(nf, 7);
        let (mut expected, mut found) = (vec![0.0; nc], vec![0.0; nc]);
        spmv(&crate::sparse::transpose(&matrix), &r, &mut expected);
        transfer.restrict(&r, &mut found);
        let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (e, f) in expected.iter().zip(&found) {
            assert!(
                (e - f).abs() < 1e-13 * scale,
                "Pᵀ, p = {p}, q = {q}: {e} vs {f}"
            );
        }
    }
}
