//! Bernstein coefficients of det J of prisms computed from the Bézier control points of the
//! element map by exact Bernstein arithmetic, the prism counterpart of
//! [`crate::bezier_simplex`] (triangles, tetrahedra) and [`crate::bezier_map`] (boxes).
//!
//! Sampled det J converts to coefficients through the inverse of the lattice matrix, whose
//! triangle factor at degree 3p − 2 has a norm growing exponentially with p: above p ≈ 5
//! rounding in the samples swamps det J, nothing is certified, and every element is split
//! to the full depth (minutes per mesh). Here the prism's space P_p(ξ, η) ⊗ P_p(ζ) is
//! written in the product Bernstein basis B_α^p(λ) B_k^p(ζ), the partial derivatives are
//! coefficient differences (∂/∂ξ_a lowers the triangle degree, ∂/∂ζ the line degree), and a
//! product multiplies the triangle factors by [`ProductTable`] and the line factors by
//!
//! B_i^a B_j^b = [C(a, i) C(b, j) / C(a + b, i + j)] B_{i+j}^{a+b},
//!
//! all weights non-negative and summing to one, so a forward error bound is carried along
//! and becomes the certification margin. The columns ∂x/∂ξ, ∂x/∂η have degree (p − 1, p),
//! ∂x/∂ζ (p, p − 1); det J has (3p − 2, 3p − 1) ([`crate::jacobian_degree`]).

use std::collections::BTreeMap;

use hocurve_nodes::{NodeFamily, ReferenceElement, Shape};
use nalgebra::DMatrix;

use crate::bezier_map::{binomial_table, determinant, Bounded};
use crate::bezier_simplex::{control_conversion, simplex_lattice, ProductTable};
use crate::QualityError;

/// The precomputed data of order-p prisms with one node family.
#[derive(Debug, Clone)]
pub(crate) struct PrismJacobian {
    order: usize,
    /// Row-major: the map's control values (prism lattice order: triangle index fastest,
    /// then ζ) from its nodal values (canonical order).
    to_bezier: Vec<f64>,
    /// ‖to_bezier‖∞: the amplification of rounding in the conversion.
    conversion_norm: f64,
    /// Triangle products by (degree of f, degree of g).
    triangle_products: BTreeMap<(usize, usize), ProductTable>,
    binomial: Vec<Vec<f64>>,
}

/// Number of triangle Bernstein polynomials of degree d.
fn triangle_len(d: usize) -> usize {
    (d + 1) * (d + 2) / 2
}

impl PrismJacobian {
    /// None for other shapes or p < 1 (or, never for hocurve's families, a node set that
    /// is not unisolvent).
    pub(crate) fn new(
        shape: Shape,
        order: usize,
        family: NodeFamily,
    ) -> Result<Option<Self>, QualityError> {
        if shape != Shape::Prism || order == 0 {
            return Ok(None);
        }
        let p = order;
        let binomial = binomial_table(3 * p + 2);
        let element = ReferenceElement::shared(shape, order, family)?;
        let points = element.nodes().points();
        let triangle = simplex_lattice(2, p);
        let n = triangle.len() * (p + 1);
        if points.len() != n {
            return Ok(None);
        }
        // V_{n, (α, k)} = B_α^p(ξ_n, η_n) B_k^p(ζ_n).
        let basis = |x: &[f64; 3], column: usize| {
            let (alpha, k) = (triangle[column % triangle.len()], column / triangle.len());
            let (i, j) = (alpha[0], alpha[1]);
            let l0 = 1.0 - x[0] - x[1];
            let tri = binomial[p][i]
                * binomial[p - i][j]
                * x[0].powi(i as i32)
                * x[1].powi(j as i32)
                * l0.powi((p - i - j) as i32);
            let line = binomial[p][k] * x[2].powi(k as i32) * (1.0 - x[2]).powi((p - k) as i32);
            tri * line
        };
        let v = DMatrix::from_fn(n, n, |r, c| basis(&points[r], c));
        let Some((to_bezier, conversion_norm)) = control_conversion(v) else {
            return Ok(None);
        };
        let q = p - 1;
        let mut triangle_products = BTreeMap::new();
        for pair in [(q, p), (q, q), (q, 2 * q + 1), (p, 2 * q)] {
            triangle_products
                .entry(pair)
                .or_insert_with(|| ProductTable::new(2, pair.0, pair.1, &binomial));
        }
        Ok(Some(PrismJacobian {
            order,
            to_bezier,
            conversion_norm,
            triangle_products,
            binomial,
        }))
    }

    /// The Bernstein coefficients of det J (degrees (3p − 2, 3p − 1), in
    /// [`crate::BernsteinSpace`] order) of the prism with node coordinates `coords`
    /// (canonical order, relative to a nearby point), and a bound on their absolute
    /// rounding error.
    pub(crate) fn coefficients(&self, coords: &[[f64; 3]]) -> (Vec<f64>, f64) {
        let p = self.order;
        let n = coords.len();
        let largest = coords
            .iter()
            .flat_map(|x| x.iter())
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let conversion_error = self.conversion_norm * (n + 8) as f64 * f64::EPSILON * largest;
        let mut partials: Vec<Vec<Bounded>> = Vec::with_capacity(3);
        for d in 0..3 {
            let c: Vec<f64> = self
                .to_bezier
                .chunks(n)
                .map(|row| row.iter().zip(coords).map(|(m, x)| m * x[d]).sum())
                .collect();
            let control = Bounded {
                c,
                degree: [p, p, 0],
                error: conversion_error,
            };
            partials.push(vec![
                triangle_derivative(&control, 0),
                triangle_derivative(&control, 1),
                line_derivative(&control),
            ]);
        }
        let product = |f: &Bounded, g: &Bounded| self.product(f, g);
        let det = determinant(3, &partials, product, product);
        (det.c, det.error)
    }

    /// f · g: triangle factors by the product table of their degrees, line factors by the
    /// 1D rule.
    fn product(&self, f: &Bounded, g: &Bounded) -> Bounded {
        let (a, az) = (f.degree[0], f.degree[1]);
        let (b, bz) = (g.degree[0], g.degree[1]);
        let (ft, gt, out_t) = (triangle_len(a), triangle_len(b), triangle_len(a + b));
        let mut c = vec![0.0; out_t * (az + bz + 1)];
        // The determinant's products are (p − 1, p)·(p, p − 1)-type pairs in either order:
        // swap to the stored (smaller degree first) table.
        let (f, g, a, b, az, bz, ft, gt) = if self.triangle_products.contains_key(&(a, b)) {
            (f, g, a, b, az, bz, ft, gt)
        } else {
            (g, f, b, a, bz, az, gt, ft)
        };
        let Some(table) = self.triangle_products.get(&(a, b)) else {
            // Not a product of this prism's determinant: nothing is certified from it.
            return Bounded {
                c: vec![f64::NAN; c.len()],
                degree: [a + b, az + bz, 0],
                error: f64::INFINITY,
            };
        };
        let weight = |i: usize, j: usize| {
            self.binomial[az][i] * self.binomial[bz][j] / self.binomial[az + bz][i + j]
        };
        for fk in 0..=az {
            for gk in 0..=bz {
                let w = weight(fk, gk);
                let (fs, gs) = (&f.c[fk * ft..(fk + 1) * ft], &g.c[gk * gt..(gk + 1) * gt]);
                let out = &mut c[(fk + gk) * out_t..(fk + gk + 1) * out_t];
                for (i, &fi) in fs.iter().enumerate().take(table.rows()) {
                    for ((o, t), &gj) in table.row(i).zip(gs) {
                        out[o as usize] += w * t * fi * gj;
                    }
                }
            }
        }
        let (mf, mg) = (f.max_abs(), g.max_abs());
        let terms = (table.most_terms * (az.min(bz) + 1)) as f64;
        Bounded {
            c,
            degree: [a + b, az + bz, 0],
            error: f.error * mg
                + g.error * mf
                + f.error * g.error
                + (terms + 8.0) * f64::EPSILON * mf * mg,
        }
    }
}

/// ∂f/∂ξ_axis (axis 0 or 1, barycentric λ_0 = 1 − ξ − η) of a prism polynomial: triangle
/// degree d − 1, coefficients d (c_{β + e_axis} − c_β) on every ζ level.
fn triangle_derivative(f: &Bounded, axis: usize) -> Bounded {
    let (d, dz) = (f.degree[0], f.degree[1]);
    let (from, to) = (triangle_len(d), triangle_len(d - 1));
    // Position of (i, j) in simplex_lattice(2, d) order: j outer, i inner (i ≤ d − j).
    let at = |i: usize, j: usize| j * (d + 1) - j * j.saturating_sub(1) / 2 + i;
    let mut c = Vec::with_capacity(to * (dz + 1));
    for k in 0..=dz {
        let level = &f.c[k * from..(k + 1) * from];
        for beta in simplex_lattice(2, d - 1) {
            let (i, j) = (beta[0], beta[1]);
            let up = if axis == 0 {
                at(i + 1, j)
            } else {
                at(i, j + 1)
            };
            c.push(d as f64 * (level[up] - level[at(i, j)]));
        }
    }
    Bounded {
        c,
        degree: [d - 1, dz, 0],
        error: d as f64 * (2.0 * f.error + 2.0 * f64::EPSILON * f.max_abs()),
    }
}

/// ∂f/∂ζ of a prism polynomial: line degree dz − 1, coefficients dz (c_{k+1} − c_k).
fn line_derivative(f: &Bounded) -> Bounded {
    let (d, dz) = (f.degree[0], f.degree[1]);
    let t = triangle_len(d);
    let c = (0..dz)
        .flat_map(|k| (0..t).map(move |i| (k, i)))
        .map(|(k, i)| dz as f64 * (f.c[(k + 1) * t + i] - f.c[k * t + i]))
        .collect();
    Bounded {
        c,
        degree: [d, dz - 1, 0],
        error: dz as f64 * (2.0 * f.error + 2.0 * f64::EPSILON * f.max_abs()),
    }
}

#[cfg(test)]
#[path = "tests/bezier_prism.rs"]
mod tests;
