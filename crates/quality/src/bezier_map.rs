//! Bernstein coefficients of det J of quadrilaterals and hexahedra computed from the
//! Bézier control points of the element map, by exact Bernstein arithmetic (Johnen, Remacle
//! & Geuzaine, "Geometrical validity of curvilinear finite elements", JCP 233 (2013)),
//! instead of converting sampled values of det J.
//!
//! Sampled values convert to coefficients through M⁻¹, whose norm grows exponentially with
//! the degree: for det J of a p = 6 hexahedron (degree 17 per variable) ‖M⁻¹‖∞ exceeds
//! 10¹³, so rounding in the samples could move a coefficient by more than det J itself and
//! nothing could be certified. Here only the map's own conversion (degree p per variable)
//! amplifies rounding; derivatives are coefficient differences and products of Bernstein
//! polynomials have non-negative weights summing to one,
//!
//! B_i^a B_j^b = [C(a, i) C(b, j) / C(a + b, i + j)] B_{i+j}^{a+b}  (per variable),
//!
//! so a forward error bound is carried along and becomes the certification margin.

use hocurve_nodes::{NodeFamily, ReferenceElement, Shape};
use nalgebra::DMatrix;

use crate::QualityError;

/// The precomputed data of one (shape, order, family) with tensor-product nodes.
#[derive(Debug, Clone)]
pub(crate) struct TensorJacobian {
    dim: usize,
    order: usize,
    /// Tensor storage position (i₀ + (p+1)(i₁ + (p+1) i₂)) of each node in canonical order.
    tensor_index: Vec<usize>,
    /// Row-major (p+1)×(p+1) map from nodal values along one axis to Bézier coefficients.
    to_bezier: Vec<f64>,
    /// ‖to_bezier‖∞^dim: the amplification of rounding in the conversion.
    conversion_norm: f64,
    /// binomial[n][k] = C(n, k), exact in f64 for n ≤ 60.
    binomial: Vec<Vec<f64>>,
}

/// A Bernstein polynomial and a bound on the absolute error of every coefficient: tensor
/// (storage i₀ + (d₀+1)(i₁ + (d₁+1) i₂), degrees per variable) here, on the simplex (total
/// degree `degree[0]`) in [`crate::bezier_simplex`].
#[derive(Debug, Clone)]
pub(crate) struct Bounded {
    pub(crate) c: Vec<f64>,
    pub(crate) degree: [usize; 3],
    pub(crate) error: f64,
}

impl Bounded {
    pub(crate) fn max_abs(&self) -> f64 {
        self.c.iter().fold(0.0, |m, v| m.max(v.abs()))
    }
}

impl TensorJacobian {
    /// None when the nodes are not a tensor product of one 1D set (never for hocurve's
    /// families, but then the sampled conversion is used instead).
    pub(crate) fn new(
        shape: Shape,
        order: usize,
        family: NodeFamily,
    ) -> Result<Option<Self>, QualityError> {
        let dim = match shape {
            Shape::Quad => 2,
            Shape::Hex => 3,
            _ => return Ok(None),
        };
        let element = ReferenceElement::shared(shape, order, family)?;
        let nodes = element.nodes();
        let mut line: Vec<f64> = nodes.points().iter().map(|x| x[0]).collect();
        line.sort_by(f64::total_cmp);
        // The same 1D coordinate may differ in the last bit between nodes.
        line.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
        if line.len() != order + 1 {
            return Ok(None);
        }
        let side = order + 1;
        let position = |t: f64| line.iter().position(|&u| (u - t).abs() < 1e-12);
        let mut tensor_index = Vec::with_capacity(nodes.len());
        for x in nodes.points() {
            let mut index = 0;
            for k in (0..dim).rev() {
                let Some(i) = position(x[k]) else {
                    return Ok(None);
                };
                index = index * side + i;
            }
            tensor_index.push(index);
        }
        let mut seen = tensor_index.clone();
        seen.sort_unstable();
        seen.dedup();
        if seen.len() != side.pow(dim as u32) || tensor_index.len() != seen.len() {
            return Ok(None);
        }
        let binomial = binomial_table(60);
        // M_{ij} = B_j^p(t_i); the Bézier coefficients of the interpolant are M⁻¹ · values.
        let p = order;
        let m = DMatrix::from_fn(side, side, |i, j| {
            let t = line[i];
            binomial[p][j] * t.powi(j as i32) * (1.0 - t).powi((p - j) as i32)
        });
        let Some(inverse) = m.try_inverse() else {
            return Ok(None);
        };
        let to_bezier: Vec<f64> = (0..side * side)
            .map(|k| inverse[(k / side, k % side)])
            .collect();
        let row_norm = to_bezier
            .chunks(side)
            .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        Ok(Some(TensorJacobian {
            dim,
            order,
            tensor_index,
            to_bezier,
            conversion_norm: row_norm.powi(dim as i32),
            binomial,
        }))
    }

    /// The Bernstein coefficients of det J (degree 2p − 1 per variable on the
    /// quadrilateral, 3p − 1 on the hexahedron, in [`crate::BernsteinSpace`] order) of the
    /// element with node coordinates `coords` (canonical order, relative to a nearby
    /// point), and a bound on their absolute rounding error.
    pub(crate) fn coefficients(&self, coords: &[[f64; 3]]) -> (Vec<f64>, f64) {
        let (dim, p) = (self.dim, self.order);
        let side = p + 1;
        let count = side.pow(dim as u32);
        let degree = [p, p, if dim == 3 { p } else { 0 }];
        let largest = coords
            .iter()
            .flat_map(|x| x[..dim].iter())
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let conversion_error =
            self.conversion_norm * (coords.len() + 8) as f64 * f64::EPSILON * largest;
        // Control points of each coordinate, then ∂x_d/∂ξ_a for every (d, a).
        let mut partials: Vec<Vec<Bounded>> = Vec::with_capacity(dim);
        for d in 0..dim {
            let mut c = vec![0.0; count];
            for (node, &index) in self.tensor_index.iter().enumerate() {
                c[index] = coords[node][d];
            }
            let mut tmp = Vec::new();
            for axis in 0..dim {
                crate::bernstein::apply_along_axis(
                    &self.to_bezier,
                    [
                        side,
                        if dim > 1 { side } else { 1 },
                        if dim > 2 { side } else { 1 },
                    ],
                    axis,
                    &mut c,
                    &mut tmp,
                );
            }
            let control = Bounded {
                c,
                degree,
                error: conversion_error,
            };
            partials.push((0..dim).map(|a| derivative(&control, a)).collect());
        }
        let product = |f: &Bounded, g: &Bounded| self.product(f, g);
        let det = determinant(dim, &partials, product, product);
        (det.c, det.error)
    }

    /// f · g with the per-variable product rule of Bernstein polynomials.
    fn product(&self, f: &Bounded, g: &Bounded) -> Bounded {
        let degree = [
            f.degree[0] + g.degree[0],
            f.degree[1] + g.degree[1],
            f.degree[2] + g.degree[2],
        ];
        let dims = degree.map(|d| d + 1);
        let fd = f.degree.map(|d| d + 1);
        let gd = g.degree.map(|d| d + 1);
        let mut c = vec![0.0; dims[0] * dims[1] * dims[2]];
        // w[axis][i][j] = C(a, i) C(b, j) / C(a + b, i + j).
        let weights: Vec<Vec<Vec<f64>>> = (0..3)
            .map(|k| {
                let (a, b) = (f.degree[k], g.degree[k]);
                (0..=a)
                    .map(|i| {
                        (0..=b)
                            .map(|j| {
                                self.binomial[a][i] * self.binomial[b][j]
                                    / self.binomial[a + b][i + j]
                            })
                            .collect()
                    })
                    .collect()
            })
            .collect();
        for fk in 0..fd[2] {
            for fj in 0..fd[1] {
                for fi in 0..fd[0] {
                    let fv = f.c[fi + fd[0] * (fj + fd[1] * fk)];
                    if fv == 0.0 {
                        continue;
                    }
                    for gk in 0..gd[2] {
                        let wk = fv * weights[2][fk][gk];
                        for gj in 0..gd[1] {
                            let wjk = wk * weights[1][fj][gj];
                            let out = dims[0] * ((fj + gj) + dims[1] * (fk + gk)) + fi;
                            let row = &g.c[gd[0] * (gj + gd[1] * gk)..][..gd[0]];
                            for (gi, gv) in row.iter().enumerate() {
                                c[out + gi] += wjk * weights[0][fi][gi] * gv;
                            }
                        }
                    }
                }
            }
        }
        let (mf, mg) = (f.max_abs(), g.max_abs());
        // Each output is a convex combination of ≤ K products; each weight and product
        // rounds with a few ε.
        let terms = fd.iter().zip(&gd).map(|(a, b)| a.min(b)).product::<usize>() as f64;
        Bounded {
            c,
            degree,
            error: f.error * mg
                + g.error * mf
                + f.error * g.error
                + (terms + 6.0) * f64::EPSILON * mf * mg,
        }
    }
}

/// ∂f/∂ξ_axis in Bernstein form: degree d − 1 in that variable, coefficients
/// d (c_{i+1} − c_i).
fn derivative(f: &Bounded, axis: usize) -> Bounded {
    let dims = f.degree.map(|d| d + 1);
    let d = f.degree[axis];
    let mut degree = f.degree;
    degree[axis] = d - 1;
    let out_dims = degree.map(|d| d + 1);
    let mut c = Vec::with_capacity(out_dims[0] * out_dims[1] * out_dims[2]);
    for k in 0..out_dims[2] {
        for j in 0..out_dims[1] {
            for i in 0..out_dims[0] {
                let mut next = [i, j, k];
                next[axis] += 1;
                let at = |ix: [usize; 3]| f.c[ix[0] + dims[0] * (ix[1] + dims[1] * ix[2])];
                c.push(d as f64 * (at(next) - at([i, j, k])));
            }
        }
    }
    Bounded {
        c,
        degree,
        error: d as f64 * (2.0 * f.error + 2.0 * f64::EPSILON * f.max_abs()),
    }
}

/// binomial[n][k] = C(n, k) for n ≤ `top`, exact in f64 up to n = 60 (rounded products).
pub(crate) fn binomial_table(top: usize) -> Vec<Vec<f64>> {
    (0..=top)
        .map(|n| {
            let mut row = vec![1.0; n + 1];
            for k in 1..n {
                row[k] = (1..=k)
                    .fold(1.0, |c, j| c * (n + 1 - j) as f64 / j as f64)
                    .round();
            }
            row
        })
        .collect()
}

/// det J from the partials `partials[d][α]` = ∂x_d/∂ξ_α in Bernstein form, with its error
/// bound: ∂₀x₀ ∂₁x₁ − ∂₁x₀ ∂₀x₁ in 2D, the cofactor expansion along ∂x₀ in 3D. `square`
/// multiplies two partials, `cube` a partial by a 2 × 2 minor.
pub(crate) fn determinant(
    dim: usize,
    partials: &[Vec<Bounded>],
    square: impl Fn(&Bounded, &Bounded) -> Bounded,
    cube: impl Fn(&Bounded, &Bounded) -> Bounded,
) -> Bounded {
    if dim == 2 {
        let a = square(&partials[0][0], &partials[1][1]);
        let b = square(&partials[0][1], &partials[1][0]);
        return difference(&a, &b);
    }
    let [m0, m1, m2] = cofactor_minors(partials, &square);
    let t0 = cube(&partials[0][0], &m0);
    let t1 = cube(&partials[0][1], &m1);
    let t2 = cube(&partials[0][2], &m2);
    let sum = difference(&t0, &t1);
    let mut total = sum.clone();
    for (out, v) in total.c.iter_mut().zip(&t2.c) {
        *out += v;
    }
    total.error = sum.error + t2.error + 2.0 * f64::EPSILON * (sum.max_abs() + t2.max_abs());
    total
}

/// The 2 × 2 minors of rows 1 and 2 of the 3D partials that multiply ∂x₀/∂ξ₀, ∂x₀/∂ξ₁ and
/// ∂x₀/∂ξ₂ in the cofactor expansion of det J (the middle one with its sign left out):
/// columns (1, 2), (0, 2), (0, 1); `square` multiplies two partials.
pub(crate) fn cofactor_minors(
    partials: &[Vec<Bounded>],
    square: impl Fn(&Bounded, &Bounded) -> Bounded,
) -> [Bounded; 3] {
    let minor = |a: usize, b: usize| {
        let one = square(&partials[1][a], &partials[2][b]);
        let two = square(&partials[1][b], &partials[2][a]);
        difference(&one, &two)
    };
    [minor(1, 2), minor(0, 2), minor(0, 1)]
}

/// f − g (same degrees), with its error bound.
pub(crate) fn difference(f: &Bounded, g: &Bounded) -> Bounded {
    Bounded {
        c: f.c.iter().zip(&g.c).map(|(a, b)| a - b).collect(),
        degree: f.degree,
        error: f.error + g.error + f64::EPSILON * (f.max_abs() + g.max_abs()),
    }
}
