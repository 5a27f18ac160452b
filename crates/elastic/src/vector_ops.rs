//! Parallel vector and matrix-vector operations whose results do not depend on the number
//! of threads: mat-vec rows are independent, and reductions add fixed-size chunks in a
//! fixed order.

use rayon::prelude::*;

use crate::StiffnessMatrix;

/// Elements per partial sum of a reduction: the chunking, not the thread count, fixes the
/// order of additions.
const CHUNK: usize = 4096;
/// Rows per parallel task in a mat-vec.
const ROWS_PER_TASK: usize = 256;

/// y = A x.
pub(crate) fn spmv(a: &StiffnessMatrix, x: &[f64], y: &mut [f64]) {
    let indptr = a.indptr().into_raw_storage();
    let (indices, data) = (a.indices(), a.data());
    y.par_iter_mut()
        .with_min_len(ROWS_PER_TASK)
        .enumerate()
        .for_each(|(r, yr)| {
            let range = indptr[r]..indptr[r + 1];
            *yr = indices[range.clone()]
                .iter()
                .zip(&data[range])
                .map(|(&c, v)| v * x[c as usize])
                .sum();
        });
}

/// r = b − A x.
pub(crate) fn residual(a: &StiffnessMatrix, b: &[f64], x: &[f64], r: &mut [f64]) {
    spmv(a, x, r);
    r.par_iter_mut()
        .with_min_len(CHUNK)
        .zip(b)
        .for_each(|(ri, bi)| *ri = bi - *ri);
}

/// Σ aᵢ bᵢ, summed per chunk, chunks in order.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let partial: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(x, y)| x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>())
        .collect();
    partial.iter().sum()
}

/// ‖a‖₂.
pub(crate) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// y += α x.
pub(crate) fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    y.par_iter_mut()
        .with_min_len(CHUNK)
        .zip(x)
        .for_each(|(yi, xi)| *yi += alpha * xi);
}

/// y = x + β y.
pub(crate) fn xpby(x: &[f64], beta: f64, y: &mut [f64]) {
    y.par_iter_mut()
        .with_min_len(CHUNK)
        .zip(x)
        .for_each(|(yi, xi)| *yi = xi + beta * *yi);
}

#[cfg(test)]
mod tests {
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
        residual(&a, &y, &x, &mut r);
        assert!(r.iter().all(|&v| v == 0.0));
    }
}
