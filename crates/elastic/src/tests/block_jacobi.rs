use super::*;
use crate::sparse::from_rows;

#[test]
fn blocks_are_inverted_exactly() {
    // Blocks {0, 1} = [[4, 1], [1, 3]] (inverse [[3, −1], [−1, 4]] / 11) and {2} = [5];
    // the couplings between blocks (−1) are ignored.
    let a = from_rows(
        3,
        vec![
            vec![(0, 4.0), (1, 1.0), (2, -1.0)],
            vec![(0, 1.0), (1, 3.0)],
            vec![(0, -1.0), (2, 5.0)],
        ],
    );
    let b = BlockJacobi::new(&a, &[0, 2, 3]);
    let mut z = vec![0.0; 3];
    b.apply(&[11.0, 0.0, 1.0], &mut z);
    let exact = [3.0, -1.0, 0.2];
    assert!(
        z.iter().zip(exact).all(|(z, e)| (z - e).abs() < 1e-15),
        "{z:?}"
    );
}

#[test]
fn cholesky_inverse_of_a_larger_block() {
    // The 1D Laplacian tridiag(−1, 2, −1) of size k has inverse min(i, j)(k + 1 − max(i, j))/(k + 1)
    // (1-based indices).
    let k: usize = 7;
    let mut m: Vec<f64> = (0..k * k)
        .map(|e| match (e / k).abs_diff(e % k) {
            0 => 2.0,
            1 => -1.0,
            _ => 0.0,
        })
        .collect();
    let mut out = vec![0.0; k * k];
    invert_spd(&mut m, k, &mut out);
    for i in 1..=k {
        for j in 1..=k {
            let exact = (i.min(j) * (k + 1 - i.max(j))) as f64 / (k + 1) as f64;
            assert!((out[(i - 1) * k + j - 1] - exact).abs() < 1e-14);
        }
    }
}

#[test]
fn dof_cuts_drop_empty_ranges_and_split_large_ones() {
    // Nodes 0..4 with 3, 0, 3, 2 dofs; ranges {0}, {1}, {2, 3}.
    let first = [0, 3, 3, 6, 8];
    assert_eq!(dof_cuts(&[0, 1, 2, 4], &first), vec![0, 3, 8]);
    // 40 nodes of 3 dofs in one range: split below MAX_BLOCK at node boundaries.
    let first: Vec<usize> = (0..=40).map(|n| 3 * n).collect();
    let cuts = dof_cuts(&[0, 40], &first);
    assert_eq!(cuts.last(), Some(&120));
    assert!(cuts
        .windows(2)
        .all(|w| w[1] > w[0] && w[1] - w[0] <= MAX_BLOCK && w[1] % 3 == 0));
}
