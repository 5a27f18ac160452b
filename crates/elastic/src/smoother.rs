//! The smoother of every p-multigrid level: Chebyshev acceleration of the entity-block
//! Jacobi preconditioner.
//!
//! S = q(B A) B is the degree-k Chebyshev polynomial on [λ_max/ratio, λ_max] of the
//! block-Jacobi-preconditioned operator (B = the inverses of the diagonal blocks of A over
//! the dofs of each vertex, edge, face and cell interior, see [`crate::block_jacobi`]; λ_max
//! estimated by Lanczos and enlarged by 10 %). S is symmetric and ‖I − S A‖_A < 1 when
//! λ_max is an upper bound, so a V-cycle using S before and after the coarse correction is
//! symmetric positive definite. The mat-vecs may use a cheaper (f32) copy of A: S stays a
//! fixed SPD operator.

use rayon::prelude::*;

use crate::block_jacobi::BlockJacobi;
use crate::pcg::LinearOperator;
use crate::vector_ops::{axpy, dot, xpby};
use crate::StiffnessMatrix;

/// Lower end of the smoothed spectrum: λ_max / SMOOTHING_RATIO (30 halved the solve time
/// of 15 at equal iterations on a 4³-cube tet mesh, p = 2..5).
const SMOOTHING_RATIO: f64 = 30.0;
/// Lanczos steps for the estimate of λ_max(B A).
const LANCZOS_STEPS: usize = 12;

/// Scratch vectors of one smoothing step, each of the level's size.
pub(crate) struct SmootherScratch {
    res: Vec<f64>,
    d: Vec<f64>,
    w: Vec<f64>,
}

impl SmootherScratch {
    pub fn new(size: usize) -> Self {
        SmootherScratch {
            res: vec![0.0; size],
            d: vec![0.0; size],
            w: vec![0.0; size],
        }
    }
}

/// Chebyshev-accelerated block Jacobi.
pub(crate) struct ChebyshevSmoother {
    pub block_jacobi: BlockJacobi,
    /// Chebyshev interval [low, high] and degree.
    low: f64,
    high: f64,
    degree: usize,
}

impl ChebyshevSmoother {
    /// The smoother of `matrix` with diagonal blocks over the dof ranges `cuts`; the
    /// spectrum is estimated with mat-vecs by `a`, an operator equal (or close) to `matrix`.
    pub fn new(
        matrix: &StiffnessMatrix,
        a: &dyn LinearOperator,
        cuts: &[usize],
        degree: usize,
    ) -> Self {
        Self::from_block_jacobi(BlockJacobi::new(matrix, cuts), a, degree)
    }

    /// The smoother with the block-Jacobi preconditioner `block_jacobi` of the operator `a`.
    pub fn from_block_jacobi(
        block_jacobi: BlockJacobi,
        a: &dyn LinearOperator,
        degree: usize,
    ) -> Self {
        let mut smoother = ChebyshevSmoother {
            block_jacobi,
            low: 0.0,
            high: 0.0,
            degree: degree.max(1),
        };
        smoother.high = 1.1 * smoother.estimate_lambda_max(a);
        smoother.low = smoother.high / SMOOTHING_RATIO;
        smoother
    }

    /// λ_max(B A) from [`LANCZOS_STEPS`] steps of B-preconditioned CG on A x = b (b fixed,
    /// pseudo-random): the largest eigenvalue of the Lanczos matrix of CG's coefficients
    /// (Saad, Sect. 6.7.3), T_jj = 1/α_j + β_(j−1)/α_(j−1), T_(j,j+1) = √β_j / α_j. It
    /// approaches λ_max from below far faster than power iteration.
    pub fn estimate_lambda_max(&self, a: &dyn LinearOperator) -> f64 {
        let n = self.block_jacobi.len();
        if n == 0 {
            return 1.0;
        }
        let mut r: Vec<f64> = (0..n)
            .map(|i| ((i.wrapping_mul(2_654_435_761) >> 7) % 1000) as f64 / 500.0 - 1.0)
            .collect();
        let mut z = vec![0.0; n];
        let mut q = vec![0.0; n];
        self.block_jacobi.apply(&r, &mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let (mut diagonal, mut off_diagonal) = (Vec::new(), Vec::new());
        let (mut alpha_prev, mut beta_prev) = (1.0, 0.0);
        for _ in 0..LANCZOS_STEPS {
            a.apply(&p, &mut q);
            let pq = dot(&p, &q);
            if !(pq > 0.0 && rz > 0.0 && pq.is_finite()) {
                break;
            }
            let alpha = rz / pq;
            diagonal.push(1.0 / alpha + beta_prev / alpha_prev);
            axpy(-alpha, &q, &mut r);
            self.block_jacobi.apply(&r, &mut z);
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            off_diagonal.push(beta.max(0.0).sqrt() / alpha);
            xpby(&z, beta, &mut p);
            (rz, alpha_prev, beta_prev) = (rz_next, alpha, beta);
        }
        off_diagonal.truncate(diagonal.len().saturating_sub(1));
        let lambda = largest_eigenvalue(&diagonal, &off_diagonal);
        if lambda.is_finite() && lambda > 0.0 {
            lambda
        } else {
            1.0
        }
    }

    /// x = S r: `degree` Chebyshev steps for A x = r from x = 0 (Saad, Alg. 12.1, with the
    /// block-Jacobi preconditioner), mat-vecs by `a`.
    pub fn apply(
        &self,
        a: &dyn LinearOperator,
        r: &[f64],
        x: &mut [f64],
        scratch: &mut SmootherScratch,
    ) {
        let SmootherScratch { res, d, w } = scratch;
        let theta = 0.5 * (self.high + self.low);
        let delta = 0.5 * (self.high - self.low);
        let sigma = theta / delta;
        let mut rho = 1.0 / sigma;
        self.block_jacobi.apply(r, d);
        d.par_iter_mut().for_each(|v| *v /= theta);
        x.iter_mut().for_each(|v| *v = 0.0);
        res.copy_from_slice(r);
        for k in 0..self.degree {
            x.par_iter_mut().zip(&*d).for_each(|(xi, di)| *xi += di);
            if k + 1 == self.degree {
                break;
            }
            a.apply(d, w);
            res.par_iter_mut().zip(&*w).for_each(|(ri, wi)| *ri -= wi);
            self.block_jacobi.apply(res, w);
            let rho_next = 1.0 / (2.0 * sigma - rho);
            let (c1, c2) = (rho_next * rho, 2.0 * rho_next / delta);
            d.par_iter_mut()
                .zip(&*w)
                .for_each(|(di, wi)| *di = c1 * *di + c2 * wi);
            rho = rho_next;
        }
    }
}

/// The largest eigenvalue of the symmetric tridiagonal matrix with `diagonal` and
/// `off_diagonal` (one shorter), by bisection on Sturm counts; 0 if empty.
pub(crate) fn largest_eigenvalue(diagonal: &[f64], off_diagonal: &[f64]) -> f64 {
    if diagonal.is_empty() {
        return 0.0;
    }
    let m = diagonal.len();
    let radius = |i: usize| {
        let left = if i > 0 {
            off_diagonal[i - 1].abs()
        } else {
            0.0
        };
        left + off_diagonal.get(i).map_or(0.0, |o| o.abs())
    };
    let mut high = (0..m)
        .map(|i| diagonal[i] + radius(i))
        .fold(f64::MIN, f64::max);
    let mut low = (0..m)
        .map(|i| diagonal[i] - radius(i))
        .fold(f64::MAX, f64::min);
    // Eigenvalues below x: the negative pivots of T − x I.
    let below = |x: f64| {
        let mut count = 0;
        let mut pivot = 1.0;
        for i in 0..m {
            let coupling = if i > 0 {
                off_diagonal[i - 1].powi(2)
            } else {
                0.0
            };
            pivot = diagonal[i] - x - coupling / pivot;
            if pivot == 0.0 {
                pivot = -f64::EPSILON * (x.abs() + 1.0);
            }
            if pivot < 0.0 {
                count += 1;
            }
        }
        count
    };
    for _ in 0..100 {
        let mid = 0.5 * (low + high);
        if mid <= low || mid >= high {
            break;
        }
        if below(mid) == m {
            high = mid;
        } else {
            low = mid;
        }
    }
    high
}
