//! The condensed stiffness operator Tᵀ K T applied cell by cell, never assembled.
//!
//! The elastic solve runs on the straight-sided mesh, whose simplices are affine: with
//! J⁻¹ = ∂ξ/∂x constant, the element matrix is a fixed combination of the reference
//! matrices S_αβ = ∫ ∂_αΦ ∂_βΦᵀ dξ (see [`crate::element_matrix`]). Every ∂Φ_b/∂ξ_α lies in
//! P_(p−1), of dimension m < n, so the stacked matrix [S_αβ] has rank m and factors as
//! S_αβ = R_αᵀ R_β with R_α of size m × n ([`ReferenceGradients`]). The action y_e = K_e x_e
//! of a cell with nodal displacements X (n × dim) is then
//!
//! U_α = R_α X (the gradient modes),  ∇u_k = Σ_α U_α[k] ⊗ J⁻¹_α,
//! σ_k = |det J| (λ tr(∇u_k) I + μ (∇u_k + ∇u_kᵀ)),  Y = Σ_α R_αᵀ (σ_k J⁻¹_α)_k,
//!
//! 4 dim² m n flops and nothing stored per cell but J⁻¹ and |det J| — where the assembled
//! matrix keeps about (n dim)²/2 numbers per cell (at p = 3, 1 800 against 10; at p = 8,
//! 120 000). Cells are visited in the coloured runs of [`crate::cell_runs`]: the result does
//! not depend on the number of threads.
//!
//! The same factors give the diagonal blocks of Tᵀ K T that the block-Jacobi smoother
//! inverts ([`MatrixFreeStiffness::block_jacobi`]). The smoothers apply the operator with
//! f32 cell products ([`SinglePrecision`]: eight lanes per AVX2 register instead of four;
//! p = 6 sphere, 1 236 tets: CG iterations 0.88 → 0.62 s), CG itself in f64. The stresses
//! of a register of modes are computed side by side ([`stress_modes`]), their J⁻¹ stored
//! component by component ([`ShapePart::point_geometry`]) where they vary by point.

use std::sync::atomic::AtomicU64;
use std::sync::Arc;

use faer::{Mat, Side};
use hocurve_mesh::{HighOrderMesh, Shape};
use rayon::prelude::*;

use crate::block_jacobi::{block_offsets, packed_index, BlockJacobi};
use crate::cell_runs::{add_to, prefetch, CellRuns, ReducedNodes, SharedSum};
use crate::condensation::Constraints;
use crate::element_matrix::invert_jacobian;
use crate::extruded_factors::{ExtrudedFactors, ExtrudedScratch, FactorTables};
#[cfg(target_arch = "x86_64")]
use crate::lanes::{Avx2Double, Avx2Single};
use crate::lanes::{Lanes, Portable};
use crate::pcg::LinearOperator;
use crate::reference_element::ReferenceStiffness;
use crate::{ElasticError, Material};

/// Eigenvalues of [S_αβ] below this fraction of the largest are round-off (the exact ones
/// are zero beyond rank m; the smallest kept one is above 1e-3 of the largest up to p = 10).
const RANK_TOLERANCE: f64 = 1e-10;
/// Order from which prisms, hexahedra and quadrilaterals are applied by sum factorisation
/// ([`ExtrudedFactors`]) instead of the dense factors. Measured on hexahedra + prisms
/// (`fixtures/cad/cylinder_layers`, `--elastic-layers`, 2 cores): CG iterations 11.1 s
/// against 15.7 s at p = 4, 20.9 s against 40.8 s at p = 5; on 31 k prisms at p = 3
/// (issue 21's cylinder) 28.6 s against 25.6 s: below p = 4 the dense products, fewer flops
/// saved and register-blocked, are as fast. Both in f32 in the smoothers and the factored
/// sums lane-parallel over nodes and points (session 22; the layered sphere shell of
/// `bench --layers`, 12 k curved prisms, ns per unknown and CG iteration): p = 2 64
/// factorised against 44 dense, p = 3 200 against 168–174, p = 4 331–366 against 378–386.
/// With every component's sums side by side and the tables in the order the sums read them
/// (session 23; `extruded_action_timings`, perturbed cubes, ns per unknown of one action,
/// f64 / f32): prisms at p = 3 30.5 / 22.6 against 42.3 / 23.8 dense, hexahedra 26.0 /
/// 17.8 against 42.2 / 23.4; at p = 2 still 44.0 / 35.6 against 36.7 / 24.8.
const FACTORISED_FROM_ORDER: usize = 3;
/// The same for prisms with one Jacobian (extruded, affine), whose dense factors have rank
/// dim ∇P rather than a row per point: at p = 3 31.0 / 19.0 dense against 31.1 / 24.5, at
/// p = 4 41.3 / 23.3 against 26.6 / 17.1.
const AFFINE_FACTORISED_FROM_ORDER: usize = 4;
/// How many of a run's nodes ahead the gathers and scatters prefetch.
const PREFETCH_AHEAD: usize = 12;
/// Outputs accumulated together in the cell action's two products: two AVX2 registers of
/// f64 (CG's operator) or of f32 (the smoothers').
const LANES: usize = 8;
const SINGLE_LANES: usize = 16;

/// The floating-point type of a cell action: f64 for CG's operator, f32 for the smoothers'
/// mat-vecs (twice the products per instruction; the sums over cells stay in f64).
pub(crate) trait CellReal:
    Copy
    + Default
    + Send
    + Sync
    + std::ops::Add<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::AddAssign
    + 'static
{
    /// One register of this precision on any CPU, and with AVX2.
    type Portable: Lanes<Real = Self>;
    type Avx2: Lanes<Real = Self>;
    fn of(v: f64) -> Self;
    fn wide(self) -> f64;
    /// The reference factors in this precision.
    fn lane_factors(reference: &ReferenceGradients) -> &LaneFactors<Self>;
    /// J⁻¹ and |det J| in this precision (see [`ShapePart::geometry`]).
    fn geometry(part: &ShapePart) -> &[[Self; 10]];
    /// The same per point (see [`ShapePart::point_geometry`]).
    fn point_geometry(part: &ShapePart) -> &[Self];
    /// The sum-factorisation tables in this precision.
    fn extruded_tables(factors: &ExtrudedFactors) -> &FactorTables<Self>;
}

impl CellReal for f64 {
    type Portable = Portable<f64, 4>;
    #[cfg(target_arch = "x86_64")]
    type Avx2 = Avx2Double;
    #[cfg(not(target_arch = "x86_64"))]
    type Avx2 = Portable<f64, 4>;
    #[inline(always)]
    fn of(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn wide(self) -> f64 {
        self
    }
    #[inline(always)]
    fn lane_factors(reference: &ReferenceGradients) -> &LaneFactors<Self> {
        &reference.double
    }
    #[inline(always)]
    fn geometry(part: &ShapePart) -> &[[Self; 10]] {
        &part.geometry
    }
    #[inline(always)]
    fn point_geometry(part: &ShapePart) -> &[Self] {
        &part.point_geometry
    }
    #[inline(always)]
    fn extruded_tables(factors: &ExtrudedFactors) -> &FactorTables<Self> {
        factors.double()
    }
}

impl CellReal for f32 {
    type Portable = Portable<f32, 8>;
    #[cfg(target_arch = "x86_64")]
    type Avx2 = Avx2Single;
    #[cfg(not(target_arch = "x86_64"))]
    type Avx2 = Portable<f32, 8>;
    #[inline(always)]
    fn of(v: f64) -> Self {
        v as f32
    }
    #[inline(always)]
    fn wide(self) -> f64 {
        f64::from(self)
    }
    #[inline(always)]
    fn lane_factors(reference: &ReferenceGradients) -> &LaneFactors<Self> {
        &reference.single
    }
    #[inline(always)]
    fn geometry(part: &ShapePart) -> &[[Self; 10]] {
        &part.single_geometry
    }
    #[inline(always)]
    fn point_geometry(part: &ShapePart) -> &[Self] {
        &part.single_point_geometry
    }
    #[inline(always)]
    fn extruded_tables(factors: &ExtrudedFactors) -> &FactorTables<Self> {
        factors.single()
    }
}

/// The matrices of a cell action's two products in one precision, padded to whole lanes.
#[derive(Debug, Clone)]
pub(crate) struct LaneFactors<T> {
    /// dim m rounded up to the lanes, and n likewise.
    rows_padded: usize,
    n_padded: usize,
    /// R_α[k][b] at `(α m + k) n_padded + b`, zero beyond n.
    factors: Vec<T>,
    /// The same transposed: R_α[k][b] at `b rows_padded + α m + k`, zero beyond dim m. Both
    /// orders let the two products of the action accumulate a lane block of outputs in
    /// registers along unit-stride rows.
    transposed: Vec<T>,
}

impl<T: CellReal> LaneFactors<T> {
    /// From R_α[k][b] at `(α m + k) n + b` (`rows` = dim m rows), padded to `lanes`.
    fn new(rows: usize, n: usize, factors: &[f64], lanes: usize) -> Self {
        let rows_padded = rows.div_ceil(lanes) * lanes;
        let n_padded = n.div_ceil(lanes) * lanes;
        let mut transposed = vec![T::default(); rows_padded * n];
        let mut padded = vec![T::default(); rows * n_padded];
        for i in 0..rows {
            for b in 0..n {
                transposed[b * rows_padded + i] = T::of(factors[i * n + b]);
                padded[i * n_padded + b] = T::of(factors[i * n + b]);
            }
        }
        LaneFactors {
            rows_padded,
            n_padded,
            factors: padded,
            transposed,
        }
    }
}

/// The factors R_α of one simplex's reference stiffness matrices: S_αβ = R_αᵀ R_β.
#[derive(Debug, Clone)]
pub(crate) struct ReferenceGradients {
    /// Nodes n.
    n: usize,
    /// Rank m (the dimension of P_(p−1)).
    m: usize,
    /// R_α in f64 ([`LANES`]) and in f32 ([`SINGLE_LANES`]).
    double: LaneFactors<f64>,
    single: LaneFactors<f32>,
    /// S_αβ[a][b] at `(α dim + β) n² + a n + b` (for the diagonal blocks; simplices).
    stiffness: Vec<Vec<f64>>,
    /// The modes k are quadrature points with their own J⁻¹ and |det J| (non-affine
    /// shapes), rather than one J⁻¹ for the cell.
    per_point: bool,
}

impl ReferenceGradients {
    /// From the reference matrices of `reference` (a simplex), by the eigen-decomposition of
    /// the stacked matrix [S_αβ] (size dim·n): R = Λ^½ Vᵀ over the eigenvalues above round-off.
    pub fn new(reference: &ReferenceStiffness) -> Result<Self, ElasticError> {
        let (dim, n) = (reference.dim, reference.len);
        let matrices = reference
            .simplex_stiffness
            .as_ref()
            .or(reference.prism_stiffness.as_ref());
        let Some(s) = matrices else {
            return Err(ElasticError::Factorization {
                what: "reference stiffness",
                message: format!("{} has no reference matrices", reference.shape.name()),
            });
        };
        let size = dim * n;
        let stacked = Mat::from_fn(size, size, |i, j| {
            let (alpha, a) = (i / n, i % n);
            let (beta, b) = (j / n, j % n);
            s[alpha * dim + beta][a * n + b]
        });
        let eigen =
            stacked
                .self_adjoint_eigen(Side::Lower)
                .map_err(|e| ElasticError::Factorization {
                    what: "reference stiffness",
                    message: format!("eigen-decomposition: {e:?}"),
                })?;
        let values = eigen.S().column_vector();
        let vectors = eigen.U();
        let largest = (0..size).map(|i| values[i]).fold(0.0f64, f64::max);
        let kept: Vec<usize> = (0..size)
            .filter(|&i| values[i] > RANK_TOLERANCE * largest)
            .collect();
        let m = kept.len();
        let mut factors = vec![0.0; dim * m * n];
        for (k, &i) in kept.iter().enumerate() {
            let root = values[i].sqrt();
            for alpha in 0..dim {
                for b in 0..n {
                    factors[(alpha * m + k) * n + b] = root * vectors[(alpha * n + b, i)];
                }
            }
        }
        Ok(Self::packed(dim, n, m, &factors, s.clone(), false))
    }

    /// [`ReferenceGradients::new`] of `reference`, computed once per reference element
    /// (an eigen-decomposition of size dim n: 0.1 s for the tetrahedron at p = 10).
    pub fn shared(reference: &ReferenceStiffness) -> Result<Arc<Self>, ElasticError> {
        if let Some(factors) = reference.gradient_factors.get() {
            return Ok(Arc::clone(factors));
        }
        let factors = Arc::new(Self::new(reference)?);
        Ok(Arc::clone(
            reference.gradient_factors.get_or_init(|| factors),
        ))
    }

    /// The factors of a shape whose cells are not affine (quadrilaterals, hexahedra,
    /// prisms): R_α[q][b] = √w_q ∂Φ_b/∂ξ_α(ξ_q) at the points of the degree-2p rule that
    /// assembly integrates with, so that Σ_q R_α[q]ᵀ c_q R_β[q] is that rule's sum; J⁻¹ and
    /// |det J| then vary with q (`per_point`).
    /// The points are taken in the order `points` (rule indices; all of them), or the
    /// rule's own when it is empty.
    pub fn at_quadrature(reference: &ReferenceStiffness, points: &[u32]) -> Self {
        let (dim, n) = (reference.dim, reference.len);
        let rule = &reference.stiffness_rule;
        let m = rule.len();
        let mut factors = vec![0.0; dim * m * n];
        for q in 0..m {
            let k = points.get(q).map_or(q, |&k| k as usize);
            let root = rule.weights()[k].sqrt();
            for (b, g) in rule.gradients(k).iter().enumerate() {
                for alpha in 0..dim {
                    factors[(alpha * m + q) * n + b] = root * g[alpha];
                }
            }
        }
        Self::packed(dim, n, m, &factors, Vec::new(), true)
    }

    /// The padded and transposed copies of `factors` (R_α[k][b] at `(α m + k) n + b`).
    fn packed(
        dim: usize,
        n: usize,
        m: usize,
        factors: &[f64],
        stiffness: Vec<Vec<f64>>,
        per_point: bool,
    ) -> Self {
        ReferenceGradients {
            n,
            m,
            double: LaneFactors::new(dim * m, n, factors, LANES),
            single: LaneFactors::new(dim * m, n, factors, SINGLE_LANES),
            stiffness,
            per_point,
        }
    }

    /// R_α[k][b].
    #[inline]
    fn factor_at(&self, alpha: usize, k: usize, b: usize) -> f64 {
        self.double.factors[(alpha * self.m + k) * self.double.n_padded + b]
    }

    /// The rank m.
    #[cfg(test)]
    pub fn rank(&self) -> usize {
        self.m
    }

    /// R_α[k][b].
    #[cfg(test)]
    pub fn factor(&self, alpha: usize, k: usize, b: usize) -> f64 {
        self.factor_at(alpha, k, b)
    }
}

/// The cells of one shape: their factors, runs and geometry.
pub(crate) struct ShapePart {
    reference: Arc<ReferenceGradients>,
    /// The part's cells in coloured runs; `geometry` follows their order.
    runs: CellRuns,
    /// Per cell (affine cells; empty with `reference.per_point`): J⁻¹ (`inv[α][c]` at
    /// 3α + c) and |det J| times the cell's stiffening.
    geometry: Vec<[f64; 10]>,
    /// The same in f32, for the smoothers' action.
    single_geometry: Vec<[f32; 10]>,
    /// Per cell and quadrature point (`reference.per_point`; else empty), component j of
    /// the above at point q at `(cell · 10 + j) m + q`: a component of consecutive points
    /// side by side, for the cell action's lanes.
    point_geometry: Vec<f64>,
    /// The same in f32.
    single_point_geometry: Vec<f32>,
    /// The [`ReducedNodes::slot`] of each of [`CellRuns::run_nodes`].
    slots: Vec<u32>,
    /// Sum factorisation of the action (prisms, hexahedra, quadrilaterals with tensor
    /// nodes); None: the dense factors.
    extruded: Option<ExtrudedFactors>,
}

/// Tᵀ K T of a mesh of straight-sided cells, applied cell by cell: affine simplices from
/// their reference factors, other shapes (quadrilaterals, hexahedra, prisms) from the
/// gradients at their quadrature points.
pub(crate) struct MatrixFreeStiffness {
    dim: usize,
    /// One per shape present, in shape order.
    parts: Vec<ShapePart>,
    lambda: f64,
    mu: f64,
    nodes: ReducedNodes,
    /// Whether the CPU has AVX2 (for [`MatrixFreeStiffness::cell_action`]).
    avx2: bool,
    sums: SharedSum,
}

impl MatrixFreeStiffness {
    /// Whether [`MatrixFreeStiffness::new`] takes `mesh`: cells of the mesh's dimension,
    /// with the right node counts, every simplex straight-sided (affine); quadrilaterals,
    /// hexahedra and prisms of any straight or curved shape.
    pub fn applies(mesh: &HighOrderMesh) -> bool {
        if mesh.cells.is_empty() || !matches!(mesh.dim, 2 | 3) {
            return false;
        }
        let Ok(references) = ReferenceStiffness::for_mesh(mesh) else {
            return false;
        };
        mesh.cells.par_iter().all(|cell| {
            let reference = &references[&cell.kind];
            reference.simplex_stiffness.is_none() || {
                let coords: Vec<[f64; 3]> =
                    cell.nodes.iter().map(|&n| mesh.nodes[n as usize]).collect();
                reference.is_affine_simplex(&coords)
            }
        })
    }

    /// The operator of `mesh` (which [`MatrixFreeStiffness::applies`] to) under
    /// `constraints`, each cell c's Lamé parameters multiplied by `stiffening[c]` when given.
    pub fn new(
        mesh: &HighOrderMesh,
        material: &Material,
        stiffening: Option<&[f64]>,
        constraints: &Constraints,
    ) -> Result<Self, ElasticError> {
        Self::factorised_from(
            mesh,
            material,
            stiffening,
            constraints,
            [FACTORISED_FROM_ORDER, AFFINE_FACTORISED_FROM_ORDER],
        )
    }

    /// [`Self::new`] with sum factorisation from the orders `from` (cells with a Jacobian
    /// per point, affine prisms): tests and timings compare the two paths.
    pub(crate) fn factorised_from(
        mesh: &HighOrderMesh,
        material: &Material,
        stiffening: Option<&[f64]>,
        constraints: &Constraints,
        from: [usize; 2],
    ) -> Result<Self, ElasticError> {
        material.validate()?;
        let dim = mesh.dim;
        let references = ReferenceStiffness::for_mesh(mesh)?;
        let nodes = ReducedNodes::new(constraints);
        if !nodes.slots_fit() {
            return Err(ElasticError::Factorization {
                what: "matrix-free operator",
                message: format!("{} unknowns do not fit 31-bit indices", nodes.len()),
            });
        }
        let mut parts = Vec::new();
        for (&shape, stiffness) in &references {
            // Extruded prisms are affine: like simplices, one Jacobian per cell and the
            // reference factors of rank dim(∇ space) (36 rows at p = 3 against 48 points).
            let affine_prisms = shape == Shape::Prism
                && stiffness.order < from[1]
                && mesh
                    .cells
                    .par_iter()
                    .filter(|c| c.kind == shape)
                    .all(|cell| {
                        let coords: Vec<[f64; 3]> =
                            cell.nodes.iter().map(|&n| mesh.nodes[n as usize]).collect();
                        stiffness.is_affine_prism(&coords)
                    });
            let extruded = (!affine_prisms && stiffness.order >= from[0])
                .then(|| ExtrudedFactors::new(stiffness))
                .flatten();
            // With sum factorisation, the rule's points in the factors' tensor order.
            let points = extruded.as_ref().map_or(&[][..], |f| f.points());
            let reference = match (&stiffness.simplex_stiffness, affine_prisms) {
                (Some(_), _) | (None, true) => ReferenceGradients::shared(stiffness)?,
                (None, false) => Arc::new(ReferenceGradients::at_quadrature(stiffness, points)),
            };
            let runs = CellRuns::of_shape(mesh, shape, stiffness.len);
            let m = reference.m;
            let point_geometry: Vec<f64> = if reference.per_point {
                let rule = &stiffness.stiffness_rule;
                runs.order
                    .par_iter()
                    .map(|&c| {
                        let c = c as usize;
                        let coords: Vec<[f64; 3]> = mesh.cells[c]
                            .nodes
                            .iter()
                            .map(|&v| mesh.nodes[v as usize])
                            .collect();
                        let mut block = vec![0.0; 10 * m];
                        for q in 0..m {
                            let k = points.get(q).map_or(q, |&k| k as usize);
                            let (inv, det) = invert_jacobian(&rule.jacobian(&coords, k), dim);
                            let g = packed_geometry(inv, det, c, stiffening)?;
                            for (j, v) in g.into_iter().enumerate() {
                                block[j * m + q] = v;
                            }
                        }
                        Ok(block)
                    })
                    .collect::<Result<Vec<_>, ElasticError>>()?
                    .concat()
            } else {
                Vec::new()
            };
            let geometry: Vec<[f64; 10]> = if reference.per_point {
                Vec::new()
            } else {
                runs.order
                    .par_iter()
                    .map(|&c| {
                        let c = c as usize;
                        let cell = &mesh.cells[c];
                        let vertex = |v: usize| mesh.nodes[cell.nodes[v] as usize];
                        let mut jac = [[0.0; 3]; 3];
                        for alpha in 0..dim {
                            for d in 0..dim {
                                jac[d][alpha] = vertex(alpha + 1)[d] - vertex(0)[d];
                            }
                        }
                        let (inv, det) = invert_jacobian(&jac, dim);
                        packed_geometry(inv, det, c, stiffening)
                    })
                    .collect::<Result<Vec<_>, _>>()?
            };
            let slots = runs
                .run_nodes()
                .par_iter()
                .map(|&v| nodes.slot(v as usize))
                .collect();
            let single_geometry = geometry.par_iter().map(|g| g.map(|v| v as f32)).collect();
            let single_point_geometry = point_geometry.par_iter().map(|&v| v as f32).collect();
            parts.push(ShapePart {
                reference,
                runs,
                geometry,
                single_geometry,
                point_geometry,
                single_point_geometry,
                slots,
                extruded,
            });
        }
        let (lambda, mu) = material.lame();
        Ok(MatrixFreeStiffness {
            dim,
            parts,
            lambda,
            mu,
            nodes,
            #[cfg(target_arch = "x86_64")]
            avx2: std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(not(target_arch = "x86_64"))]
            avx2: false,
            sums: SharedSum::default(),
        })
    }

    /// Number of reduced unknowns.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// The load −Tᵀ K u_p that the prescribed displacements (`constraints.prescribed`, a
    /// full dof vector) put on the reduced unknowns.
    pub fn prescribed_load(&self, constraints: &Constraints) -> Vec<f64> {
        let dim = self.dim;
        let u = &constraints.prescribed;
        let mut out = vec![0.0; self.len()];
        self.accumulate::<f64, LANES>(
            |part, i| {
                let node = part.runs.run_nodes()[i] as usize;
                let mut v = [0.0; 3];
                if self.nodes.is_fixed(node) {
                    (0..dim).for_each(|d| v[d] = u[node * dim + d]);
                }
                v
            },
            &[],
            &mut out,
        );
        out.par_iter_mut().for_each(|v| *v = -*v);
        out
    }

    /// y = Σ over cells of Tᵀ K_e x_e, the displacement of each cell node from
    /// `gather(part, i)`, i its place in the part's [`CellRuns::run_nodes`]; the parts one
    /// after the other. `source` is the vector `gather` reads (for prefetching; empty if
    /// none).
    /// The cell actions run in precision T with L lanes ([`LANES`] for f64,
    /// [`SINGLE_LANES`] for f32).
    fn accumulate<T: CellReal, const L: usize>(
        &self,
        gather: impl Fn(&ShapePart, usize) -> [f64; 3] + Sync,
        source: &[f64],
        y: &mut [f64],
    ) {
        let dim = self.dim;
        self.sums.collect(y, |sums| {
            for part in &self.parts {
                let n = part.reference.n;
                let n_padded = T::lane_factors(&part.reference).n_padded;
                part.runs
                    .for_each_run(CellScratch::default, |scratch, run| {
                        let range = part.runs.run_range(run);
                        let len = range.len();
                        // The run's nodal values (component d of its node j at 3 j + d) and
                        // results.
                        scratch.run_x.resize(3 * len, T::default());
                        scratch.run_y.clear();
                        scratch.run_y.resize(3 * len, T::default());
                        for (j, i) in range.clone().enumerate() {
                            if let Some(&ahead) = part.slots.get(i + PREFETCH_AHEAD) {
                                if let Some(f) = self.nodes.first_of_slot(ahead) {
                                    prefetch(source, f);
                                }
                            }
                            let v = gather(part, i);
                            for d in 0..3 {
                                scratch.run_x[3 * j + d] = T::of(v[d]);
                            }
                        }
                        for c in part.runs.cells_of_run(run) {
                            if dim == 2 {
                                self.cell_in_run::<T, L, 2>(part, c, n, n_padded, scratch);
                            } else {
                                self.cell_in_run::<T, L, 3>(part, c, n, n_padded, scratch);
                            }
                        }
                        for (j, &slot) in part.slots[range.clone()].iter().enumerate() {
                            if let Some(&ahead) = part.slots.get(range.start + j + PREFETCH_AHEAD) {
                                if let Some(f) = self.nodes.first_of_slot(ahead) {
                                    sums.prefetch(f);
                                }
                            }
                            let mut v = [0.0; 3];
                            (0..dim).for_each(|d| v[d] = scratch.run_y[3 * j + d].wide());
                            self.nodes
                                .restrict_slot(slot, v, |i, value| sums.add(i, value));
                        }
                    });
            }
        });
    }

    /// The cell at position c of `part` within its run: its nodes' values from the run's
    /// (`scratch.run_x`, node-major) into the cell's (component-major), the cell action, its
    /// result added to the run's (`scratch.run_y`). D a constant so that the copies unroll.
    #[inline(always)]
    fn cell_in_run<T: CellReal, const L: usize, const D: usize>(
        &self,
        part: &ShapePart,
        c: usize,
        n: usize,
        n_padded: usize,
        scratch: &mut CellScratch<T>,
    ) {
        let local = part.runs.local(c);
        // Every entry is overwritten.
        scratch.x.resize(D * n, T::default());
        {
            let (x, run_x) = (&mut scratch.x[..D * n], &scratch.run_x[..]);
            for (a, &j) in local.iter().enumerate().take(n) {
                let j = 3 * j as usize;
                let v = &run_x[j..j + D];
                for d in 0..D {
                    x[d * n + a] = v[d];
                }
            }
        }
        self.cell_action::<T, L>(part, c, scratch);
        let (y, run_y) = (&scratch.y[..D * n_padded], &mut scratch.run_y[..]);
        for (a, &j) in local.iter().enumerate().take(n) {
            let j = 3 * j as usize;
            let v = &mut run_y[j..j + D];
            for d in 0..D {
                v[d] += y[d * n_padded + a];
            }
        }
    }

    /// scratch.y = K_c scratch.x for the cell at position c of `part` (module
    /// documentation); both hold component d of node b at `d n + b`. With AVX2 where the
    /// CPU has it: the same operations in the same order (no fused multiply-add), so the
    /// same bits, on 4 lanes instead of 2.
    fn cell_action<T: CellReal, const L: usize>(
        &self,
        part: &ShapePart,
        c: usize,
        scratch: &mut CellScratch<T>,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only when the running CPU reports AVX2.
            unsafe { self.cell_action_avx2::<T, L>(part, c, scratch) };
            return;
        }
        self.cell_action_body::<T, L, false>(part, c, scratch);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn cell_action_avx2<T: CellReal, const L: usize>(
        &self,
        part: &ShapePart,
        c: usize,
        scratch: &mut CellScratch<T>,
    ) {
        self.cell_action_body::<T, L, true>(part, c, scratch);
    }

    #[inline(always)]
    fn cell_action_body<T: CellReal, const L: usize, const AVX2: bool>(
        &self,
        part: &ShapePart,
        c: usize,
        scratch: &mut CellScratch<T>,
    ) {
        match (self.dim, part.reference.per_point) {
            (2, false) => self.cell_action_in::<T, L, 2, false, AVX2>(part, c, scratch),
            (2, true) => self.cell_action_in::<T, L, 2, true, AVX2>(part, c, scratch),
            (_, false) => self.cell_action_in::<T, L, 3, false, AVX2>(part, c, scratch),
            (_, true) => self.cell_action_in::<T, L, 3, true, AVX2>(part, c, scratch),
        }
    }

    /// The cell action in dimension D (a constant, so that the accumulators stay in
    /// registers), with one J⁻¹ per mode when PER_POINT, the factored sums and the stresses
    /// on AVX registers when AVX2 (only inside [`Self::cell_action_avx2`]).
    #[inline(always)]
    fn cell_action_in<
        T: CellReal,
        const L: usize,
        const D: usize,
        const PER_POINT: bool,
        const AVX2: bool,
    >(
        &self,
        part: &ShapePart,
        c: usize,
        scratch: &mut CellScratch<T>,
    ) {
        let ReferenceGradients { n, m, .. } = *part.reference;
        let lanes = T::lane_factors(&part.reference);
        let (rows_padded, n_padded) = (lanes.rows_padded, lanes.n_padded);
        let (lambda, mu) = (T::of(self.lambda), T::of(self.mu));
        let rows = D * m;
        let CellScratch {
            x,
            y,
            modes,
            extruded,
            ..
        } = scratch;
        if PER_POINT {
            // The next cell's geometry (kilobytes per cell, read in ten interleaved rows
            // that the hardware prefetcher follows poorly): asked for now, there by then.
            let geometry = T::point_geometry(part);
            let next = (c + 1) * 10 * m;
            for i in (next..next + 10 * m).step_by(64 / size_of::<T>()) {
                prefetch(geometry, i);
            }
        }
        // U_d[α m + k] = Σ_b R_α[k][b] X_d[b], LANES of (α, k) at a time, or sum-factorised.
        modes.resize(D * rows_padded, T::default());
        match &part.extruded {
            // One register of outputs: 8 in f32, 4 in f64.
            Some(factors) if AVX2 => {
                factors.gradients::<T::Avx2, D>(x, n, modes, rows_padded, extruded)
            }
            Some(factors) => {
                factors.gradients::<T::Portable, D>(x, n, modes, rows_padded, extruded)
            }
            None => lane_products::<T, D, L>(&lanes.transposed, x, n, n, modes, rows_padded),
        }
        // Per mode: ∇u[d][c] = ∂u_d/∂x_c, the stress, and back to reference directions.
        let cell = if PER_POINT {
            &T::point_geometry(part)[c * 10 * m..][..10 * m]
        } else {
            &T::geometry(part)[c][..]
        };
        if AVX2 {
            cell_stresses::<T::Avx2, D, PER_POINT>(modes, rows_padded, m, cell, lambda, mu);
        } else {
            cell_stresses::<T::Portable, D, PER_POINT>(modes, rows_padded, m, cell, lambda, mu);
        }
        // Y_d[b] = Σ_(α, k) R_α[k][b] V_d[α m + k], LANES of b at a time.
        y.resize(D * n_padded, T::default());
        match &part.extruded {
            Some(factors) if AVX2 => {
                factors.transpose::<T::Avx2, D>(modes, rows_padded, y, n_padded, extruded)
            }
            Some(factors) => {
                factors.transpose::<T::Portable, D>(modes, rows_padded, y, n_padded, extruded)
            }
            None => lane_products::<T, D, L>(&lanes.factors, modes, rows_padded, rows, y, n_padded),
        }
    }

    /// Block Jacobi over the reduced dof ranges `cuts` (each a whole number of nodes): the
    /// diagonal blocks of Tᵀ K T summed cell by cell, from the reference matrices (affine
    /// simplices) or the quadrature points' gradients. Per cell, only the pairs of nodes of
    /// one block are visited (the cell's nodes grouped by block), each unordered pair once.
    pub fn block_jacobi(&self, cuts: &[usize]) -> BlockJacobi {
        let nodes = self.nodes.nodes();
        let first = self.nodes.first();
        let blocks = cuts.len().saturating_sub(1);
        // The block of each node with free directions.
        let mut block_of = vec![u32::MAX; nodes];
        let mut b = 0;
        for node in 0..nodes {
            if first[node + 1] > first[node] {
                while cuts[b + 1] <= first[node] {
                    b += 1;
                }
                block_of[node] = b as u32;
            }
        }
        let offsets = block_offsets(cuts);
        let dense: Vec<AtomicU64> = (0..offsets[blocks])
            .into_par_iter()
            .map(|_| AtomicU64::new(0))
            .collect();
        let add = |slot: usize, value: f64| add_to(&dense[slot], value);
        let (lambda, mu, dim) = (self.lambda, self.mu, self.dim);
        for part in &self.parts {
            let ReferenceGradients { n, m, .. } = *part.reference;
            part.runs
                .for_each_run(BlockScratch::default, |scratch, run| {
                    let distinct = part.runs.nodes_of_run(run);
                    for c in part.runs.cells_of_run(run) {
                        // (block, local index, node) of the cell's nodes with free
                        // directions, grouped by block.
                        let members = &mut scratch.members;
                        members.clear();
                        for (a, &j) in part.runs.local(c).iter().enumerate() {
                            let node = distinct[j as usize];
                            let block = block_of[node as usize];
                            if block != u32::MAX {
                                members.push((block, a as u32, node));
                            }
                        }
                        members.sort_unstable();
                        for group in members.chunk_by(|x, y| x.0 == y.0) {
                            let block = group[0].0 as usize;
                            let start = cuts[block];
                            // Per point: the physical gradients J⁻ᵀ R[k][a] of the group's
                            // nodes, at `(i m + k)`.
                            if part.reference.per_point {
                                scratch.physical.clear();
                                for &(_, a, _) in group {
                                    let cell = &part.point_geometry[c * 10 * m..][..10 * m];
                                    for k in 0..m {
                                        let g = |j: usize| cell[j * m + k];
                                        let mut v = [0.0; 3];
                                        for (cc, vc) in v.iter_mut().enumerate().take(dim) {
                                            for alpha in 0..dim {
                                                *vc += g(3 * alpha + cc)
                                                    * part
                                                        .reference
                                                        .factor_at(alpha, k, a as usize);
                                            }
                                        }
                                        scratch.physical.push(v);
                                    }
                                }
                            }
                            for (ia, &(_, a, na)) in group.iter().enumerate() {
                                let (a, na) = (a as usize, na as usize);
                                for (ib, &(_, bb, nb)) in group.iter().enumerate() {
                                    let (bb, nb) = (bb as usize, nb as usize);
                                    // Node-block (a, b) lies in the lower triangle iff b's
                                    // dofs come first (or a = b: its own lower half).
                                    if first[nb] > first[na] {
                                        continue;
                                    }
                                    // G = Σ_k |det J| (J⁻ᵀ R[k][a]) (J⁻ᵀ R[k][b])ᵀ (per
                                    // point), or |det J| J⁻ᵀ S_αβ[a][b] J⁻¹ (affine).
                                    let mut gm = [[0.0; 3]; 3];
                                    if part.reference.per_point {
                                        let pa = &scratch.physical[ia * m..(ia + 1) * m];
                                        let pb = &scratch.physical[ib * m..(ib + 1) * m];
                                        for (k, (ga, gb)) in pa.iter().zip(pb).enumerate() {
                                            let w = part.point_geometry[(c * 10 + 9) * m + k];
                                            for cc in 0..dim {
                                                for d in 0..dim {
                                                    gm[cc][d] += w * ga[cc] * gb[d];
                                                }
                                            }
                                        }
                                    } else {
                                        let g = &part.geometry[c];
                                        let s = &part.reference.stiffness;
                                        // M = S J⁻¹ (M[α][d] = Σ_β S_αβ J⁻¹[β][d]), G = J⁻ᵀ M.
                                        let mut mm = [[0.0; 3]; 3];
                                        for alpha in 0..dim {
                                            for beta in 0..dim {
                                                let sab = s[alpha * dim + beta][a * n + bb];
                                                for d in 0..dim {
                                                    mm[alpha][d] += sab * g[3 * beta + d];
                                                }
                                            }
                                        }
                                        for cc in 0..dim {
                                            for d in 0..dim {
                                                let mut sum = 0.0;
                                                for alpha in 0..dim {
                                                    sum += g[3 * alpha + cc] * mm[alpha][d];
                                                }
                                                gm[cc][d] = g[9] * sum;
                                            }
                                        }
                                    }
                                    // K_ab = λ G + μ Gᵀ + μ tr G I.
                                    let trace: f64 = (0..dim).map(|d| gm[d][d]).sum();
                                    let mut kab = [[0.0; 3]; 3];
                                    for cc in 0..dim {
                                        for d in 0..dim {
                                            kab[cc][d] = lambda * gm[cc][d] + mu * gm[d][cc];
                                        }
                                        kab[cc][cc] += mu * trace;
                                    }
                                    let (qa, ka) = self.nodes.directions(na);
                                    let (qb, kb) = self.nodes.directions(nb);
                                    let (ra, rb) = (first[na] - start, first[nb] - start);
                                    for (i, qi) in qa[..ka].iter().enumerate() {
                                        for (j, qj) in qb[..kb].iter().enumerate() {
                                            // The lower triangle only (packed).
                                            if rb + j > ra + i {
                                                continue;
                                            }
                                            let v = if ka == dim && kb == dim {
                                                // Free nodes: Q = I.
                                                kab[i][j]
                                            } else {
                                                let mut v = 0.0;
                                                for cc in 0..dim {
                                                    for d in 0..dim {
                                                        v += qi[cc] * kab[cc][d] * qj[d];
                                                    }
                                                }
                                                v
                                            };
                                            add(offsets[block] + packed_index(ra + i, rb + j), v);
                                        }
                                    }
                                }
                            }
                        }
                    }
                });
        }
        let dense: Vec<f64> = dense
            .into_iter()
            .map(|v| f64::from_bits(v.into_inner()))
            .collect();
        BlockJacobi::from_blocks(cuts, offsets, dense)
    }
}

/// J⁻¹ and |det J| times cell c's stiffening, packed; an error for a singular map.
fn packed_geometry(
    inv: [[f64; 3]; 3],
    det: f64,
    c: usize,
    stiffening: Option<&[f64]>,
) -> Result<[f64; 10], ElasticError> {
    if !det.is_finite() || det == 0.0 {
        return Err(ElasticError::DegenerateCell {
            cell: c,
            jacobian: det,
        });
    }
    let mut g = [0.0; 10];
    for alpha in 0..3 {
        g[3 * alpha..3 * alpha + 3].copy_from_slice(&inv[alpha]);
    }
    g[9] = det.abs() * stiffening.map_or(1.0, |s| s[c]);
    Ok(g)
}

impl LinearOperator for MatrixFreeStiffness {
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        self.accumulate::<f64, LANES>(|part, i| self.nodes.expand_slot(part.slots[i], x), x, y);
    }
}

/// A [`MatrixFreeStiffness`] applied with f32 cell actions (f64 vectors and sums over
/// cells): the smoothers' operator, about twice as fast. Its action differs from the f64 one
/// by the f32 round-off of the cell products (relative ~1e-6), which the smoothing and the
/// V-cycle's residuals tolerate; CG's own operator and the convergence check stay f64.
pub(crate) struct SinglePrecision<S>(pub S);

impl<S: std::ops::Deref<Target = MatrixFreeStiffness> + Sync> LinearOperator
    for SinglePrecision<S>
{
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        let a = &*self.0;
        a.accumulate::<f32, SINGLE_LANES>(|part, i| a.nodes.expand_slot(part.slots[i], x), x, y);
    }
}

/// One thread's buffers for [`MatrixFreeStiffness::block_jacobi`].
#[derive(Default)]
struct BlockScratch {
    members: Vec<(u32, u32, u32)>,
    physical: Vec<[f64; 3]>,
}

/// One thread's buffers for [`MatrixFreeStiffness::cell_action`].
#[derive(Default)]
struct CellScratch<T> {
    run_x: Vec<T>,
    run_y: Vec<T>,
    x: Vec<T>,
    y: Vec<T>,
    modes: Vec<T>,
    extruded: ExtrudedScratch<T>,
}

/// The stresses of every mode of a cell (see [`stress_modes`]): a register of modes at a
/// time, then the rest one by one. `cell` holds the cell's J⁻¹ and |det J|: per point
/// (component j of mode k at `j m + k`) when PER_POINT, else once (`[j]`).
#[inline(always)]
fn cell_stresses<V: Lanes, const D: usize, const PER_POINT: bool>(
    modes: &mut [V::Real],
    rows_padded: usize,
    m: usize,
    cell: &[V::Real],
    lambda: V::Real,
    mu: V::Real,
) {
    let whole = m / V::WIDTH * V::WIDTH;
    for k0 in (0..whole).step_by(V::WIDTH) {
        stress_modes::<V, D, PER_POINT>(modes, rows_padded, m, k0, cell, lambda, mu);
    }
    for k in whole..m {
        stress_modes::<Portable<V::Real, 1>, D, PER_POINT>(
            modes,
            rows_padded,
            m,
            k,
            cell,
            lambda,
            mu,
        );
    }
}

/// Modes k0..k0 + V::WIDTH of a cell action (module documentation), in place: from the
/// reference gradients U_d[α m + k] (`modes[d rows_padded + α m + k]`) to ∇u = Σ_α U_α ⊗
/// J⁻¹_α, the stress σ = |det J| (λ tr(∇u) I + μ (∇u + ∇uᵀ)), and σ J⁻ᵀ; `cell` as in
/// [`cell_stresses`]. The same operations on each lane as on one mode at a time, so the
/// same bits whatever the register.
#[inline(always)]
fn stress_modes<V: Lanes, const D: usize, const PER_POINT: bool>(
    modes: &mut [V::Real],
    rows_padded: usize,
    m: usize,
    k0: usize,
    cell: &[V::Real],
    lambda: V::Real,
    mu: V::Real,
) {
    // Component j of J⁻¹ (j = 3 α + c) and |det J| (j = 9), read where used rather than
    // copied: ten registers more would not fit beside the sums.
    let g = |j: usize| {
        if PER_POINT {
            V::load(&cell[j * m + k0..])
        } else {
            V::splat(cell[j])
        }
    };
    let mut grad = [[V::zero(); 3]; 3];
    for alpha in 0..D {
        for (d, grad_d) in grad.iter_mut().enumerate().take(D) {
            let u = V::load(&modes[d * rows_padded + alpha * m + k0..]);
            for (cc, sums) in grad_d.iter_mut().enumerate().take(D) {
                *sums = sums.plus_product(u, g(3 * alpha + cc));
            }
        }
    }
    let mut trace = grad[0][0];
    for (d, row) in grad.iter().enumerate().take(D).skip(1) {
        trace = trace.add(row[d]);
    }
    let w = g(9);
    let (w_mu, w_lambda) = (w.mul(V::splat(mu)), w.mul(V::splat(lambda)));
    let mut stress = [[V::zero(); 3]; 3];
    for d in 0..D {
        for cc in 0..D {
            stress[d][cc] = w_mu.mul(grad[d][cc].add(grad[cc][d]));
        }
        stress[d][d] = stress[d][d].plus_product(w_lambda, trace);
    }
    for alpha in 0..D {
        for (d, stress_d) in stress.iter().enumerate().take(D) {
            let mut v = stress_d[0].mul(g(3 * alpha));
            for (cc, s) in stress_d.iter().enumerate().take(D).skip(1) {
                v = v.plus_product(*s, g(3 * alpha + cc));
            }
            v.store(&mut modes[d * rows_padded + alpha * m + k0..]);
        }
    }
}

/// out_d[j] = Σ_(i < inner) input_d[i] · matrix[i][j] for every component d < D, the
/// rows of `matrix` and of `out` being `width` long (a multiple of L), `input`'s
/// `input_stride`: both of the cell action's products (R X and Rᵀ V). L outputs per
/// component accumulate in registers, the sums in the order of i.
#[inline(always)]
fn lane_products<T: CellReal, const D: usize, const L: usize>(
    matrix: &[T],
    input: &[T],
    input_stride: usize,
    inner: usize,
    out: &mut [T],
    width: usize,
) {
    for j0 in (0..width).step_by(L) {
        let mut acc = [[T::default(); L]; D];
        for i in 0..inner {
            let row = &matrix[i * width + j0..i * width + j0 + L];
            for d in 0..D {
                let v = input[d * input_stride + i];
                for k in 0..L {
                    acc[d][k] += v * row[k];
                }
            }
        }
        for d in 0..D {
            out[d * width + j0..d * width + j0 + L].copy_from_slice(&acc[d]);
        }
    }
}

#[cfg(test)]
#[path = "tests/matrix_free.rs"]
mod tests;
