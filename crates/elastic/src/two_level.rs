//! The two-level preconditioner of the PCG solver: a Chebyshev-accelerated entity-block
//! Jacobi smoother on the order-p problem and an exact coarse solve of the p = 1 problem
//! on the mesh vertices.
//!
//! Coarse space: vertex displacements, prolongated to every node by the vertex (linear,
//! bilinear, …) shape functions of a cell containing it, P; the coarse matrix is the
//! Galerkin product A_c = Pᵀ A P on the reduced (free) dofs, factorised once by sparse
//! Cholesky. One application (a symmetric V-cycle, so that PCG stays valid):
//!
//! z = S r;  t = r − A z;  e = A_c⁻¹ Pᵀ t;  z ← z + P e;  t ← t − (A P) e;  z ← z + S t,
//!
//! where S = q(B A) B is the Chebyshev polynomial smoother on [λ_max/ratio, λ_max] of the
//! block-Jacobi-preconditioned operator (B = the inverses of the diagonal blocks of A over
//! the dofs of each vertex, edge, face and cell interior, see [`crate::block_jacobi`];
//! λ_max estimated by power iteration and enlarged by 10 %). S is symmetric and
//! ‖I − S A‖_A < 1 when λ_max is an upper bound, so the preconditioner is SPD. The
//! smoother's mat-vecs may use a cheaper (f32) copy of A: S stays a fixed SPD operator.
//! A P, kept from the Galerkin product, updates the residual after the coarse correction
//! at a fraction of a mat-vec.

use hocurve_mesh::HighOrderMesh;
use rayon::prelude::*;

use crate::block_jacobi::{dof_cuts, entity_node_cuts, BlockJacobi};
use crate::condensation::Constraints;
use crate::pcg::{LinearOperator, Preconditioner};
use crate::reference_element::ReferenceElement;
use crate::sparse::{from_rows, product, transpose, Cholesky};
use crate::sparsity::Adjacency;
use crate::vector_ops::{axpy, dot, spmv, xpby};
use crate::{ElasticError, StiffnessMatrix};
use hocurve_nodes::Shape;
use std::collections::BTreeMap;
use std::time::Instant;

/// Lower end of the smoothed spectrum: λ_max / SMOOTHING_RATIO (30 halved the solve time
/// of 15 at equal iterations on a 4³-cube tet mesh, p = 2..5).
const SMOOTHING_RATIO: f64 = 30.0;
/// Lanczos steps for the estimate of λ_max(B A).
const LANCZOS_STEPS: usize = 12;

pub(crate) struct TwoLevel<'a> {
    /// A for the smoother's mat-vecs.
    a: &'a dyn LinearOperator,
    smoother: BlockJacobi,
    prolongation: StiffnessMatrix,
    restriction: StiffnessMatrix,
    /// A P (fine × coarse).
    ap: StiffnessMatrix,
    coarse: Option<Cholesky>,
    /// Chebyshev interval [low, high] and degree.
    low: f64,
    high: f64,
    degree: usize,
    scratch: [Vec<f64>; 5],
    coarse_rhs: Vec<f64>,
    /// Seconds spent on the coarse space (prolongation, Galerkin product, factorisation)
    /// and on the smoother (block inverses, spectrum estimate).
    pub coarse_seconds: f64,
    pub smoother_seconds: f64,
}

impl<'a> TwoLevel<'a> {
    /// The preconditioner of `matrix`; the smoother's mat-vecs go through `a`, an
    /// operator equal (or close) to `matrix`.
    pub fn new(
        matrix: &StiffnessMatrix,
        a: &'a dyn LinearOperator,
        constraints: &'a Constraints,
        mesh: &HighOrderMesh,
        cells_of_node: &Adjacency,
        references: &BTreeMap<Shape, ReferenceElement>,
        degree: usize,
    ) -> Result<Self, ElasticError> {
        let nodes = constraints.count.len();
        let first = &constraints.first;
        let size = constraints.len();
        let start = Instant::now();
        let smoother = BlockJacobi::new(matrix, &dof_cuts(&entity_node_cuts(mesh), first));
        let smoother_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        // Prolongation from the vertices' reduced dofs (nodes 0..V come first, so their
        // reduced dofs are 0..first[V]) to all reduced dofs.
        let vertices = mesh.layout.num_vertices.min(nodes);
        let coarse_size = first[vertices];
        let rows: Vec<Vec<(u32, f64)>> = (0..nodes)
            .into_par_iter()
            .flat_map_iter(|n| {
                let kn = constraints.count[n] as usize;
                let mut entries = Vec::new();
                if let Some(&c) = cells_of_node.row(n).first() {
                    let cell = &mesh.cells[c as usize];
                    // Assembly has checked every cell's shape: the lookups cannot fail.
                    let reference = cell.kind.shape().ok().and_then(|s| references.get(&s));
                    let local = cell.nodes.iter().position(|&x| x as usize == n);
                    if let (Some(reference), Some(local)) = (reference, local) {
                        let weights = &reference.vertex_weights[local];
                        for v in 0..reference.shape.num_vertices() {
                            let vertex = cell.nodes[v] as usize;
                            let w = weights[v];
                            if w.abs() < 1e-14 || vertex >= vertices {
                                continue;
                            }
                            entries.push((vertex, w));
                        }
                    }
                }
                entries.sort_by_key(|e| e.0);
                let dim = constraints.dim;
                (0..kn).map(move |i| {
                    let qn = &constraints.directions[n];
                    let mut row = Vec::new();
                    for &(v, w) in &entries {
                        let qv = &constraints.directions[v];
                        for j in 0..constraints.count[v] as usize {
                            let q: f64 = (0..dim).map(|c| qn[i][c] * qv[j][c]).sum();
                            if q != 0.0 {
                                row.push(((first[v] + j) as u32, w * q));
                            }
                        }
                    }
                    row
                })
            })
            .collect();
        let prolongation = from_rows(coarse_size, rows);
        let restriction = transpose(&prolongation);
        let ap = product(matrix, &prolongation);
        let coarse = if coarse_size > 0 {
            let coarse_matrix = product(&restriction, &ap);
            Some(Cholesky::new(&coarse_matrix, "coarse matrix")?)
        } else {
            None
        };
        let coarse_seconds = start.elapsed().as_secs_f64();

        let mut two_level = TwoLevel {
            a,
            smoother,
            prolongation,
            restriction,
            ap,
            coarse,
            low: 0.0,
            high: 0.0,
            degree: degree.max(1),
            scratch: std::array::from_fn(|_| vec![0.0; size]),
            coarse_rhs: vec![0.0; coarse_size],
            coarse_seconds,
            smoother_seconds,
        };
        let start = Instant::now();
        let lambda_max = two_level.estimate_lambda_max();
        two_level.high = 1.1 * lambda_max;
        two_level.low = two_level.high / SMOOTHING_RATIO;
        two_level.smoother_seconds += start.elapsed().as_secs_f64();
        Ok(two_level)
    }

    /// λ_max(B A) from [`LANCZOS_STEPS`] steps of B-preconditioned CG on A x = b (b fixed,
    /// pseudo-random): the largest eigenvalue of the Lanczos matrix of CG's coefficients
    /// (Saad, Sect. 6.7.3), T_jj = 1/α_j + β_(j−1)/α_(j−1), T_(j,j+1) = √β_j / α_j. It
    /// approaches λ_max from below far faster than power iteration.
    fn estimate_lambda_max(&mut self) -> f64 {
        let n = self.smoother.len();
        if n == 0 {
            return 1.0;
        }
        let mut r: Vec<f64> = (0..n)
            .map(|i| ((i.wrapping_mul(2_654_435_761) >> 7) % 1000) as f64 / 500.0 - 1.0)
            .collect();
        let mut z = vec![0.0; n];
        let mut q = vec![0.0; n];
        self.smoother.apply(&r, &mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let (mut diagonal, mut off_diagonal) = (Vec::new(), Vec::new());
        let (mut alpha_prev, mut beta_prev) = (1.0, 0.0);
        for _ in 0..LANCZOS_STEPS {
            self.a.apply(&p, &mut q);
            let pq = dot(&p, &q);
            if !(pq > 0.0 && rz > 0.0 && pq.is_finite()) {
                break;
            }
            let alpha = rz / pq;
            diagonal.push(1.0 / alpha + beta_prev / alpha_prev);
            axpy(-alpha, &q, &mut r);
            self.smoother.apply(&r, &mut z);
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
    /// block-Jacobi preconditioner).
    fn chebyshev(&self, r: &[f64], x: &mut [f64], res: &mut [f64], d: &mut [f64], w: &mut [f64]) {
        let theta = 0.5 * (self.high + self.low);
        let delta = 0.5 * (self.high - self.low);
        let sigma = theta / delta;
        let mut rho = 1.0 / sigma;
        self.smoother.apply(r, d);
        d.par_iter_mut().for_each(|v| *v /= theta);
        x.iter_mut().for_each(|v| *v = 0.0);
        res.copy_from_slice(r);
        for k in 0..self.degree {
            x.par_iter_mut().zip(&*d).for_each(|(xi, di)| *xi += di);
            if k + 1 == self.degree {
                break;
            }
            self.a.apply(d, w);
            res.par_iter_mut().zip(&*w).for_each(|(ri, wi)| *ri -= wi);
            self.smoother.apply(res, w);
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

impl Preconditioner for TwoLevel<'_> {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        let [mut t, mut res, mut d, mut w, mut s] = std::mem::take(&mut self.scratch);
        // Pre-smoothing from zero.
        self.chebyshev(r, z, &mut res, &mut d, &mut w);
        self.a.residual(r, z, &mut t);
        // Coarse correction on the residual; A P updates the residual.
        if let Some(coarse) = &self.coarse {
            let mut rc = std::mem::take(&mut self.coarse_rhs);
            spmv(&self.restriction, &t, &mut rc);
            coarse.solve_in_place(&mut rc);
            spmv(&self.prolongation, &rc, &mut w);
            z.par_iter_mut().zip(&w).for_each(|(zi, wi)| *zi += wi);
            spmv(&self.ap, &rc, &mut w);
            t.par_iter_mut().zip(&w).for_each(|(ti, wi)| *ti -= wi);
            self.coarse_rhs = rc;
        }
        // Post-smoothing: the same S on the new residual.
        self.chebyshev(&t, &mut s, &mut res, &mut d, &mut w);
        z.par_iter_mut().zip(&s).for_each(|(zi, si)| *zi += si);
        self.scratch = [t, res, d, w, s];
    }
}

#[cfg(test)]
#[path = "tests/two_level.rs"]
pub(crate) mod tests;
