use super::*;

#[test]
fn dot_and_spmv_are_exact_on_integers_and_thread_independent() {
    let n = 3 * CHUNK + 17;
    let a: Vec<f64> = (0..n).map(|i| (i % 7) as f64).collect();
    let b: Vec<f64> = (0..n).map(|i| ((i * 3) % 5) as f64 - 2.0).collect();
    let exact: f64 = (0..n)
        .map(|i| ((i % 7) as i64 * (((i * 3) % 5) as i64 - 2)) as f64)
        .sum();
    assert_eq!(dot(&a, &b), exact);
    // Irrational values: same bits with 1 and 2 threads.
    let c: Vec<f64> = (0..n).map(|i| (i as f64).sqrt().sin()).collect();
    let runs: Vec<u64> = [1, 2]
        .iter()
        .map(|&t| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .unwrap()
                .install(|| dot(&c, &c).to_bits())
        })
        .collect();
    assert_eq!(runs[0], runs[1]);
    // Tridiagonal [−1 2 −1] times i² gives −2 inside.
    let m: usize = 50;
    let mut indptr = vec![0];
    let (mut indices, mut data) = (Vec::new(), Vec::new());
    for r in 0..m {
        for c in r.saturating_sub(1)..(r + 2).min(m) {
            indices.push(c as u32);
            data.push(if c == r { 2.0 } else { -1.0 });
        }
        indptr.push(indices.len());
    }
    let a = StiffnessMatrix::new((m, m), indptr, indices, data);
    let x: Vec<f64> = (0..m).map(|i| (i * i) as f64).collect();
    let mut y = vec![0.0; m];
    spmv(&a, &x, &mut y);
    for r in 1..m - 1 {
        assert_eq!(y[r], -2.0);
    }
    assert_eq!(y[0], -1.0);
    let mut r = vec![0.0; m];
    crate::pcg::LinearOperator::residual(&a, &y, &x, &mut r);
    assert!(r.iter().all(|&v| v == 0.0));
}
