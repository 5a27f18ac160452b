use super::*;

fn dense(a: &StiffnessMatrix) -> Vec<Vec<f64>> {
    let mut out = vec![vec![0.0; a.cols()]; a.rows()];
    for (v, (r, c)) in a.iter() {
        out[r as usize][c as usize] = *v;
    }
    out
}

#[test]
fn transpose_product_and_cholesky_on_small_matrices() {
    // A = [[1, 2, 0], [0, 3, 4]], B = Aᵀ: A Aᵀ = [[5, 6], [6, 25]].
    let a = from_rows(3, vec![vec![(0, 1.0), (1, 2.0)], vec![(1, 3.0), (2, 4.0)]]);
    let at = transpose(&a);
    assert_eq!(
        dense(&at),
        vec![vec![1.0, 0.0], vec![2.0, 3.0], vec![0.0, 4.0]]
    );
    let aat = product(&a, &at);
    assert_eq!(dense(&aat), vec![vec![5.0, 6.0], vec![6.0, 25.0]]);
    // Solve [[5, 6], [6, 25]] x = [17, 56] ⇒ x = (1, 2).
    let chol = Cholesky::new(&aat, "test").unwrap();
    let mut x = vec![17.0, 56.0];
    chol.solve_in_place(&mut x);
    assert!(
        (x[0] - 1.0).abs() < 1e-14 && (x[1] - 2.0).abs() < 1e-14,
        "{x:?}"
    );
    // Indefinite: an error, not a panic.
    let bad = from_rows(2, vec![vec![(0, 1.0), (1, 2.0)], vec![(0, 2.0), (1, 1.0)]]);
    assert!(matches!(
        Cholesky::new(&bad, "test"),
        Err(ElasticError::Factorization { what: "test", .. })
    ));
}
