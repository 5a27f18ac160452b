//! Bernstein coefficients of det J of triangles and tetrahedra computed from the Bézier
//! control points of the element map by exact Bernstein arithmetic (Johnen, Remacle &
//! Geuzaine, JCP 233 (2013)), the simplex counterpart of [`crate::bezier_map`].
//!
//! Sampling det J at the n = C(3(p − 1) + 3, 3) lattice points and converting through the
//! dense inverse costs ~ n² per element (220² at p = 4), most of the certification's time.
//! Here the map's control points come from its nodes (one (p+1)(p+2)(p+3)/6-square
//! matrix per coordinate), the partial derivatives are coefficient differences,
//!
//! ∂/∂ξ_a Σ_α c_α B_α^d = d Σ_{|β| = d − 1} (c_{β + e_a} − c_{β + e_0}) B_β^{d − 1}
//!
//! (barycentric λ_0 = 1 − Σ ξ, λ_a = ξ_a), and products follow
//!
//! B_α^a B_β^b = [Π_i C(α_i + β_i, α_i) / C(a + b, a)] B_{α+β}^{a+b},
//!
//! whose weights are non-negative and sum to one over the pairs meeting at α + β, so a
//! forward error bound is carried along and becomes the certification margin.

use hocurve_nodes::{NodeFamily, ReferenceElement, Shape};
use nalgebra::DMatrix;

use crate::bezier_map::{binomial_table, cofactor_minors, determinant, Bounded};
use crate::{BernsteinSpace, QualityError};

/// The multi-indices (α_1, α_2, α_3) of total degree ≤ … of the simplex lattice of
/// degree `d` in `dim` variables, in the order of [`crate::BernsteinSpace`]: the last
/// variable outermost, α_0 = d − Σ α_i implied.
pub(crate) fn simplex_lattice(dim: usize, d: usize) -> Vec<[usize; 3]> {
    let mut out = Vec::new();
    let top = if dim == 3 { d } else { 0 };
    for k in 0..=top {
        for j in 0..=d - k {
            for i in 0..=d - j - k {
                out.push([i, j, k]);
            }
        }
    }
    out
}

/// Position of each multi-index of [`simplex_lattice`]`(dim, d)`: index (i, j, k) at
/// i + (d + 1)(j + (d + 1) k).
fn lattice_positions(dim: usize, d: usize) -> Vec<u32> {
    let side = d + 1;
    let mut at = vec![u32::MAX; side * side * side];
    for (n, [i, j, k]) in simplex_lattice(dim, d).into_iter().enumerate() {
        at[i + side * (j + side * k)] = n as u32;
    }
    at
}

/// The product of degree-a and degree-b polynomials: for every pair (i in f, j in g), row
/// by row (pair (i, j) at `i * row_len + j`), the index of the product's coefficient and
/// the pair's weight.
#[derive(Debug, Clone)]
pub(crate) struct ProductTable {
    pub(crate) outputs: Vec<u32>,
    pub(crate) weights: Vec<f64>,
    /// Coefficients of g (the pairs in a row).
    pub(crate) row_len: usize,
    pub(crate) len: usize,
    /// Largest number of pairs meeting at one output coefficient.
    pub(crate) most_terms: usize,
}

impl ProductTable {
    pub(crate) fn new(dim: usize, a: usize, b: usize, binomial: &[Vec<f64>]) -> Self {
        let (fa, fb) = (simplex_lattice(dim, a), simplex_lattice(dim, b));
        let out = lattice_positions(dim, a + b);
        let side = a + b + 1;
        let mut count = vec![0usize; simplex_lattice(dim, a + b).len()];
        let mut outputs = Vec::with_capacity(fa.len() * fb.len());
        let mut weights = Vec::with_capacity(fa.len() * fb.len());
        for alpha in &fa {
            let alpha0 = a - alpha.iter().sum::<usize>();
            for beta in &fb {
                let beta0 = b - beta.iter().sum::<usize>();
                let gamma = [alpha[0] + beta[0], alpha[1] + beta[1], alpha[2] + beta[2]];
                let mut w = binomial[alpha0 + beta0][alpha0] / binomial[a + b][a];
                for k in 0..3 {
                    w *= binomial[gamma[k]][alpha[k]];
                }
                let o = out[gamma[0] + side * (gamma[1] + side * gamma[2])];
                count[o as usize] += 1;
                outputs.push(o);
                weights.push(w);
            }
        }
        ProductTable {
            outputs,
            weights,
            row_len: fb.len(),
            len: count.len(),
            most_terms: count.into_iter().max().unwrap_or(0),
        }
    }

    /// Row i of the table: (output index, weight) of the pairs (i, j), j in order.
    pub(crate) fn row(&self, i: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let range = i * self.row_len..(i + 1) * self.row_len;
        self.outputs[range.clone()]
            .iter()
            .copied()
            .zip(self.weights[range].iter().copied())
    }

    /// Number of rows (coefficients of f).
    pub(crate) fn rows(&self) -> usize {
        self.outputs.len() / self.row_len.max(1)
    }

    fn product(&self, f: &Bounded, g: &Bounded) -> Bounded {
        let mut c = vec![0.0; self.len];
        // Pairs in order (i, then j), each (w f_i) g_j.
        for (i, &fi) in f.c.iter().enumerate().take(self.rows()) {
            for ((o, w), &gj) in self.row(i).zip(&g.c) {
                c[o as usize] += w * fi * gj;
            }
        }
        let (mf, mg) = (f.max_abs(), g.max_abs());
        Bounded {
            c,
            degree: [f.degree[0] + g.degree[0], 0, 0],
            error: f.error * mg
                + g.error * mf
                + f.error * g.error
                + (self.most_terms as f64 + 6.0) * f64::EPSILON * mf * mg,
        }
    }

    /// f₀ g₀ − f₁ g₁ + f₂ g₂ (a cofactor expansion) in one pass over the pairs, each pair
    /// (i, j) adding w (f₀ᵢ g₀ⱼ − f₁ᵢ g₁ⱼ + f₂ᵢ g₂ⱼ) to its coefficient: a third of the
    /// scattered additions of three products and their sums. Error bound: each term is
    /// w S (1 + 4ε) with S = Σ_a |f_aᵢ g_aⱼ|, and K terms meeting at a coefficient add at
    /// most (K − 1) ε their sum; the weights meeting there sum to one, so the rounding is
    /// at most (K + 4) ε Σ_a max|f_a| max|g_a| (K + 8 kept), to which the inputs' own
    /// errors add as in [`ProductTable::product`].
    fn cofactor_sum(&self, f: [&Bounded; 3], g: [&Bounded; 3]) -> Bounded {
        let mut c = vec![0.0; self.len];
        let [f0, f1, f2] = f.map(|f| &f.c);
        let [g0, g1, g2] = g.map(|g| &g.c);
        for i in 0..self.rows().min(f0.len()) {
            let (a, b, d) = (f0[i], f1[i], f2[i]);
            for (j, (o, w)) in self.row(i).enumerate().take(g0.len()) {
                c[o as usize] += w * (a * g0[j] - b * g1[j] + d * g2[j]);
            }
        }
        let mut error = 0.0;
        let mut magnitude = 0.0;
        for (f, g) in f.iter().zip(&g) {
            let (mf, mg) = (f.max_abs(), g.max_abs());
            error += f.error * mg + g.error * mf + f.error * g.error;
            magnitude += mf * mg;
        }
        Bounded {
            c,
            degree: [f[0].degree[0] + g[0].degree[0], 0, 0],
            error: error + (self.most_terms as f64 + 8.0) * f64::EPSILON * magnitude,
        }
    }
}

/// V⁻¹ row-major and its ∞-norm, for V_{nα} = B_α(ξ_n) (Bernstein polynomials at the
/// nodes): the conversion from nodal values to Bézier control values and the factor by
/// which it can amplify rounding. None for a singular V.
pub(crate) fn control_conversion(v: DMatrix<f64>) -> Option<(Vec<f64>, f64)> {
    let n = v.nrows();
    let inverse = v.try_inverse()?;
    let rows: Vec<f64> = (0..n * n).map(|k| inverse[(k / n, k % n)]).collect();
    let norm = rows
        .chunks(n.max(1))
        .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    Some((rows, norm))
}

/// The precomputed data of order-p triangles or tetrahedra with one node family.
#[derive(Debug, Clone)]
pub(crate) struct SimplexJacobian {
    dim: usize,
    order: usize,
    /// Row-major: the map's Bézier control values (degree-p lattice order) from its nodal
    /// values (canonical order).
    to_bezier: Vec<f64>,
    /// ‖to_bezier‖∞: the amplification of rounding in the conversion.
    conversion_norm: f64,
    /// For each axis a, for each degree-(p − 1) index β: the degree-p indices of β + e_a
    /// and of β + e_0.
    derivative: Vec<Vec<(u32, u32)>>,
    /// (p − 1) × (p − 1) → 2(p − 1); in 3D also (p − 1) × 2(p − 1) → 3(p − 1).
    square: ProductTable,
    cube: Option<ProductTable>,
    /// The positions of det J's vertex coefficients (its values at the vertices).
    vertices: Vec<usize>,
}

impl SimplexJacobian {
    /// None for other shapes, p < 1, or when `space` (det J's) does not order its
    /// coefficients as [`simplex_lattice`] does.
    pub(crate) fn new(
        shape: Shape,
        order: usize,
        family: NodeFamily,
        space: &BernsteinSpace,
    ) -> Result<Option<Self>, QualityError> {
        let dim = match shape {
            Shape::Tri => 2,
            Shape::Tet => 3,
            _ => return Ok(None),
        };
        if order == 0 {
            return Ok(None);
        }
        let p = order;
        let det_degree = dim * (p - 1);
        let det_lattice = simplex_lattice(dim, det_degree);
        let same_order = space.len() == det_lattice.len()
            && space
                .exponents()
                .iter()
                .zip(&det_lattice)
                .all(|(e, m)| (0..dim).all(|k| e[k + 1] as usize == m[k]));
        if !same_order {
            return Ok(None);
        }
        let binomial = binomial_table(det_degree.max(p));
        let element = ReferenceElement::shared(shape, order, family)?;
        let points = element.nodes().points();
        let control = simplex_lattice(dim, p);
        if points.len() != control.len() {
            return Ok(None);
        }
        // V_{nα} = B_α^p(ξ_n); the control values are V⁻¹ · nodal values.
        let basis = |xi: &[f64; 3], alpha: &[usize; 3]| {
            let lambda = [
                1.0 - xi[..dim].iter().sum::<f64>(),
                xi[0],
                xi[1],
                if dim == 3 { xi[2] } else { 0.0 },
            ];
            let alpha0 = p - alpha.iter().sum::<usize>();
            let mut v = lambda[0].powi(alpha0 as i32);
            let mut rest = p;
            let mut weight = 1.0;
            // Multinomial p! / (α_0! α_1! α_2! α_3!) as a product of binomials.
            for (k, &a) in [alpha0, alpha[0], alpha[1], alpha[2]].iter().enumerate() {
                weight *= binomial[rest][a];
                rest -= a;
                if k > 0 {
                    v *= lambda[k].powi(a as i32);
                }
            }
            weight * v
        };
        let n = control.len();
        let v = DMatrix::from_fn(n, n, |i, j| basis(&points[i], &control[j]));
        let Some((to_bezier, conversion_norm)) = control_conversion(v) else {
            return Ok(None);
        };
        let at = lattice_positions(dim, p);
        let side = p + 1;
        let index = |m: [usize; 3]| at[m[0] + side * (m[1] + side * m[2])];
        let derivative = (0..dim)
            .map(|a| {
                simplex_lattice(dim, p - 1)
                    .into_iter()
                    .map(|beta| {
                        let mut up = beta;
                        up[a] += 1;
                        (index(up), index(beta))
                    })
                    .collect()
            })
            .collect();
        let square = ProductTable::new(dim, p - 1, p - 1, &binomial);
        let cube = (dim == 3).then(|| ProductTable::new(dim, p - 1, 2 * (p - 1), &binomial));
        let det_at = lattice_positions(dim, det_degree);
        let dside = det_degree + 1;
        let mut vertices = vec![det_at[0] as usize];
        for a in 0..dim {
            let mut m = [0; 3];
            m[a] = det_degree;
            vertices.push(det_at[m[0] + dside * (m[1] + dside * m[2])] as usize);
        }
        Ok(Some(SimplexJacobian {
            dim,
            order,
            to_bezier,
            conversion_norm,
            derivative,
            square,
            cube,
            vertices,
        }))
    }

    /// The positions of det J's vertex coefficients (its exact values at the vertices).
    pub(crate) fn vertices(&self) -> &[usize] {
        &self.vertices
    }

    /// The Bernstein coefficients of det J (total degree d(p − 1), in
    /// [`crate::BernsteinSpace`] order) of the element with node coordinates `coords`
    /// (canonical order, relative to a nearby point), and a bound on their absolute
    /// rounding error.
    pub(crate) fn coefficients(&self, coords: &[[f64; 3]]) -> (Vec<f64>, f64) {
        let (dim, p) = (self.dim, self.order);
        let n = coords.len();
        let largest = coords
            .iter()
            .flat_map(|x| x[..dim].iter())
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let conversion_error = self.conversion_norm * (n + 8) as f64 * f64::EPSILON * largest;
        // ∂x_d/∂ξ_a for every (d, a).
        let mut partials: Vec<Vec<Bounded>> = Vec::with_capacity(dim);
        for d in 0..dim {
            let control: Vec<f64> = self
                .to_bezier
                .chunks(n)
                .map(|row| row.iter().zip(coords).map(|(m, x)| m * x[d]).sum())
                .collect();
            let max_control = control.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            partials.push(
                self.derivative
                    .iter()
                    .map(|pairs| Bounded {
                        degree: [p - 1, 0, 0],
                        c: pairs
                            .iter()
                            .map(|&(up, base)| {
                                p as f64 * (control[up as usize] - control[base as usize])
                            })
                            .collect(),
                        error: p as f64
                            * (2.0 * conversion_error + 2.0 * f64::EPSILON * max_control),
                    })
                    .collect(),
            );
        }
        let square = |f: &Bounded, g: &Bounded| self.square.product(f, g);
        let det = match &self.cube {
            // The cofactor expansion along ∂x₀ (as `determinant` orders it), its three
            // products summed in one pass.
            Some(cube) => {
                let minors = cofactor_minors(&partials, square);
                let row = &partials[0];
                cube.cofactor_sum(
                    [&row[0], &row[1], &row[2]],
                    [&minors[0], &minors[1], &minors[2]],
                )
            }
            None => determinant(dim, &partials, square, square),
        };
        (det.c, det.error)
    }
}

#[cfg(test)]
#[path = "tests/bezier_simplex.rs"]
mod tests;
