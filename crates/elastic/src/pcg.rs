//! Preconditioned conjugate gradients (Hestenes–Stiefel with a symmetric positive definite
//! preconditioner M ≈ A⁻¹), stopping when the updated residual has fallen by `tolerance`.

use crate::vector_ops::{axpy, dot, norm, spmv, xpby};
use crate::StiffnessMatrix;

/// z ≈ A⁻¹ r, symmetric positive definite.
pub(crate) trait Preconditioner {
    fn apply(&mut self, r: &[f64], z: &mut [f64]);
}

/// Solves A x = b from the initial guess in `x`; returns the iterations done.
pub(crate) fn pcg(
    a: &StiffnessMatrix,
    b: &[f64],
    x: &mut [f64],
    preconditioner: &mut dyn Preconditioner,
    tolerance: f64,
    max_iterations: usize,
) -> usize {
    let n = b.len();
    let b_norm = norm(b);
    if b_norm == 0.0 {
        x.iter_mut().for_each(|v| *v = 0.0);
        return 0;
    }
    let mut r = vec![0.0; n];
    crate::vector_ops::residual(a, b, x, &mut r);
    let mut z = vec![0.0; n];
    preconditioner.apply(&r, &mut z);
    let mut p = z.clone();
    let mut q = vec![0.0; n];
    let mut rz = dot(&r, &z);
    for iteration in 1..=max_iterations {
        if norm(&r) <= tolerance * b_norm {
            return iteration - 1;
        }
        spmv(a, &p, &mut q);
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
    max_iterations
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sparse::from_rows;

    struct Identity;
    impl Preconditioner for Identity {
        fn apply(&mut self, r: &[f64], z: &mut [f64]) {
            z.copy_from_slice(r);
        }
    }

    #[test]
    fn cg_solves_the_1d_laplacian_in_n_steps() {
        // [2 −1; −1 2 −1; …] x = e₀ + e_{n−1} has the solution x = 1.
        let n: usize = 40;
        let rows = (0..n)
            .map(|r| {
                (r.saturating_sub(1)..(r + 2).min(n))
                    .map(|c| (c as u32, if c == r { 2.0 } else { -1.0 }))
                    .collect()
            })
            .collect();
        let a = from_rows(n, rows);
        let mut b = vec![0.0; n];
        b[0] = 1.0;
        b[n - 1] = 1.0;
        let mut x = vec![0.0; n];
        let iterations = pcg(&a, &b, &mut x, &mut Identity, 1e-12, 1000);
        // Exact arithmetic needs at most n/2 steps here (symmetric right-hand side).
        assert!(iterations <= n / 2 + 1, "{iterations}");
        assert!(x.iter().all(|v| (v - 1.0).abs() < 1e-10), "{x:?}");
    }
}
