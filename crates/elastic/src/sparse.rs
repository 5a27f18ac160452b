//! Sparse kernels beyond the mat-vec: transpose, the row-wise product used for the Galerkin
//! coarse matrix, and sparse Cholesky through faer.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::Side;

use crate::{ElasticError, StiffnessMatrix};

fn raw(a: &StiffnessMatrix) -> (&[usize], &[u32], &[f64]) {
    (a.indptr().into_raw_storage(), a.indices(), a.data())
}

/// Builds a CSR matrix from rows of (sorted column, value) pairs.
pub(crate) fn from_rows(ncols: usize, rows: Vec<Vec<(u32, f64)>>) -> StiffnessMatrix {
    let mut indptr = Vec::with_capacity(rows.len() + 1);
    indptr.push(0);
    let nnz: usize = rows.iter().map(Vec::len).sum();
    let mut indices = Vec::with_capacity(nnz);
    let mut data = Vec::with_capacity(nnz);
    let nrows = rows.len();
    for row in rows {
        for (c, v) in row {
            indices.push(c);
            data.push(v);
        }
        indptr.push(indices.len());
    }
    StiffnessMatrix::new((nrows, ncols), indptr, indices, data)
}

/// Aᵀ in CSR (a counting sort: entries keep their row order, so it is deterministic).
pub(crate) fn transpose(a: &StiffnessMatrix) -> StiffnessMatrix {
    let (indptr, indices, data) = raw(a);
    let (nrows, ncols) = a.shape();
    let mut counts = vec![0usize; ncols + 1];
    for &c in indices {
        counts[c as usize + 1] += 1;
    }
    for i in 0..ncols {
        counts[i + 1] += counts[i];
    }
    let out_ptr = counts.clone();
    let mut next = counts;
    let mut out_idx = vec![0u32; indices.len()];
    let mut out_val = vec![0.0; indices.len()];
    for r in 0..nrows {
        for k in indptr[r]..indptr[r + 1] {
            let c = indices[k] as usize;
            out_idx[next[c]] = r as u32;
            out_val[next[c]] = data[k];
            next[c] += 1;
        }
    }
    StiffnessMatrix::new((ncols, nrows), out_ptr, out_idx, out_val)
}

/// A B (the aggregation level's Galerkin product Pᵀ A P), row by row in parallel; each row
/// is accumulated in a fixed order (A's entries in order, then B's), so the result is
/// thread-count independent.
pub(crate) fn product(a: &StiffnessMatrix, b: &StiffnessMatrix) -> StiffnessMatrix {
    use rayon::prelude::*;
    let (a_ptr, a_idx, a_val) = raw(a);
    let (b_ptr, b_idx, b_val) = raw(b);
    let ncols = b.cols();
    let rows: Vec<Vec<(u32, f64)>> = (0..a.rows())
        .into_par_iter()
        .map_init(
            || (vec![0.0f64; ncols], vec![false; ncols], Vec::<u32>::new()),
            |(acc, used, cols), r| {
                cols.clear();
                for k in a_ptr[r]..a_ptr[r + 1] {
                    let (j, v) = (a_idx[k] as usize, a_val[k]);
                    for l in b_ptr[j]..b_ptr[j + 1] {
                        let c = b_idx[l] as usize;
                        if !used[c] {
                            used[c] = true;
                            cols.push(c as u32);
                        }
                        acc[c] += v * b_val[l];
                    }
                }
                cols.sort_unstable();
                cols.iter()
                    .map(|&c| {
                        let c = c as usize;
                        let v = acc[c];
                        acc[c] = 0.0;
                        used[c] = false;
                        (c as u32, v)
                    })
                    .collect()
            },
        )
        .collect();
    from_rows(ncols, rows)
}

/// A sparse Cholesky factorisation L Lᵀ of a symmetric positive definite matrix (faer,
/// fill-reducing AMD ordering, supernodal where it pays).
pub(crate) struct Cholesky {
    factor: faer::sparse::linalg::solvers::Llt<usize, f64>,
    len: usize,
}

impl Cholesky {
    /// Factorises `a`, of which only the lower triangle is read. `what` names the matrix
    /// in errors.
    pub fn new(a: &StiffnessMatrix, what: &'static str) -> Result<Self, ElasticError> {
        let (indptr, indices, data) = raw(a);
        let n = a.rows();
        // CSR of a symmetric matrix read as CSC: same arrays; faer wants one index type.
        let row_idx: Vec<usize> = indices.iter().map(|&c| c as usize).collect();
        let symbolic = SymbolicSparseColMatRef::new_checked(n, n, indptr, None, &row_idx);
        let matrix = SparseColMatRef::new(symbolic, data);
        let factor = matrix
            .sp_cholesky(Side::Lower)
            .map_err(|e| ElasticError::Factorization {
                what,
                message: format!("{e:?}"),
            })?;
        Ok(Cholesky { factor, len: n })
    }

    /// Solves A x = b in place (`rhs` holds b on entry, x on exit).
    pub fn solve_in_place(&self, rhs: &mut [f64]) {
        let column = faer::MatMut::from_column_major_slice_mut(rhs, self.len, 1);
        self.factor.solve_in_place(column);
    }
}

#[cfg(test)]
#[path = "tests/sparse.rs"]
mod tests;
