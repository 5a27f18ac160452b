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

/// `data` cut into consecutive pieces of the given lengths (for filling them in parallel).
pub(crate) fn split_into<T>(
    mut data: &mut [T],
    lengths: impl IntoIterator<Item = usize>,
) -> Vec<&mut [T]> {
    let mut parts = Vec::new();
    for len in lengths {
        let (head, tail) = std::mem::take(&mut data).split_at_mut(len);
        parts.push(head);
        data = tail;
    }
    parts
}

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
#[path = "tests/vector_ops.rs"]
mod tests;
