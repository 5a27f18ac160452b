//! Preconditioned conjugate gradients (Hestenes–Stiefel with a symmetric positive definite
//! preconditioner M ≈ A⁻¹), stopping when the updated residual has fallen by `tolerance`.

use crate::block_matrix::BlockOperator;
use crate::vector_ops::{axpy, dot, norm, spmv, xpby};
use crate::StiffnessMatrix;

/// z ≈ A⁻¹ r, symmetric positive definite.
pub(crate) trait Preconditioner {
    fn apply(&mut self, r: &[f64], z: &mut [f64]);
}

/// y = A x for a symmetric positive definite A.
pub(crate) trait LinearOperator: Sync {
    fn apply(&self, x: &[f64], y: &mut [f64]);

    /// r = b − A x.
    fn residual(&self, b: &[f64], x: &[f64], r: &mut [f64]) {
        self.apply(x, r);
        xmy(b, r);
    }
}

/// y = x − y.
fn xmy(x: &[f64], y: &mut [f64]) {
    use rayon::prelude::*;
    y.par_iter_mut()
        .with_min_len(4096)
        .zip(x)
        .for_each(|(yi, xi)| *yi = xi - *yi);
}

impl<T: LinearOperator + ?Sized> LinearOperator for &T {
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        (**self).apply(x, y);
    }
}

impl LinearOperator for StiffnessMatrix {
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        spmv(self, x, y);
    }
}

impl LinearOperator for BlockOperator {
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        BlockOperator::apply(self, x, y);
    }
}

/// Solves A x = b from the initial guess in `x`; returns the iterations done.
#[cfg(test)]
pub(crate) fn pcg(
    a: &dyn LinearOperator,
    b: &[f64],
    x: &mut [f64],
    preconditioner: &mut dyn Preconditioner,
    tolerance: f64,
    max_iterations: usize,
) -> usize {
    pcg_with_progress(
        a,
        b,
        x,
        preconditioner,
        tolerance,
        max_iterations,
        &mut |_, _| {},
    )
}

/// [`pcg`], calling `progress(iteration, ‖r‖ / ‖b‖)` after each iteration (the updated
/// residual).
pub(crate) fn pcg_with_progress(
    a: &dyn LinearOperator,
    b: &[f64],
    x: &mut [f64],
    preconditioner: &mut dyn Preconditioner,
    tolerance: f64,
    max_iterations: usize,
    progress: &mut dyn FnMut(usize, f64),
) -> usize {
    let n = b.len();
    let b_norm = norm(b);
    if b_norm == 0.0 {
        x.iter_mut().for_each(|v| *v = 0.0);
        return 0;
    }
    let mut r = vec![0.0; n];
    a.residual(b, x, &mut r);
    let mut z = vec![0.0; n];
    preconditioner.apply(&r, &mut z);
    let mut p = z.clone();
    let mut q = vec![0.0; n];
    let mut rz = dot(&r, &z);
    for iteration in 1..=max_iterations {
        let r_norm = norm(&r);
        if iteration > 1 {
            progress(iteration - 1, r_norm / b_norm);
        }
        if r_norm <= tolerance * b_norm {
            return iteration - 1;
        }
        a.apply(&p, &mut q);
        let pq = dot(&p, &q);
        if pq.is_nan() || pq <= 0.0 {
            // A or M is not positive definite along p (or p vanished): stop, the caller
            // checks the true residual.
            return iteration - 1;
        }
        let alpha = rz / pq;
        axpy(alpha, &p, x);
        axpy(-alpha, &q, &mut r);
        preconditioner.apply(&r, &mut z);
        let rz_next = dot(&r, &z);
        xpby(&z, rz_next / rz, &mut p);
        rz = rz_next;
    }
    if max_iterations > 0 {
        progress(max_iterations, norm(&r) / b_norm);
    }
    max_iterations
}

#[cfg(test)]
#[path = "tests/pcg.rs"]
mod tests;
