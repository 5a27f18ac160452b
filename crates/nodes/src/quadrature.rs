//! Quadrature rules on hocurve's reference elements (all inside the unit box).
//!
//! Lines, quadrilaterals and hexahedra use tensor Gauss–Legendre rules. Triangles and
//! tetrahedra use collapsed (Duffy / Stroud conical) rules: the simplex is the image of the
//! unit square or cube under x = u(1 − y) (triangle), resp. x = u(1 − v)(1 − z), y = v(1 − z)
//! (tetrahedron), whose Jacobian (1 − y), resp. (1 − v)(1 − z)², is absorbed into
//! Gauss–Jacobi weights with α = 1 and α = 2. A prism uses the triangle rule × the line rule.
//!
//! Every rule uses n = ⌈(degree + 1)/2⌉ points per direction, so it is exact for total
//! degree ≤ 2n − 1 ≥ degree on simplices (degree ≤ 2n − 1 in each variable on boxes).

use crate::gauss::{gauss_jacobi, gauss_legendre, Rule1D};
use crate::symmetric_triangle::symmetric_triangle;
use crate::Shape;

/// A quadrature rule on a reference element: ∫ f ≈ Σᵢ wᵢ f(ξᵢ).
#[derive(Debug, Clone, PartialEq)]
pub struct QuadratureRule {
    /// Points ξᵢ in reference coordinates (unused components are 0).
    pub points: Vec<[f64; 3]>,
    /// Weights wᵢ > 0; they sum to the volume of the reference element.
    pub weights: Vec<f64>,
}

impl QuadratureRule {
    /// A rule on the reference `shape` that integrates exactly every polynomial of
    /// total degree ≤ `degree` (Line, Tri, Tet); of degree ≤ `degree` in each variable (Quad,
    /// Hex); of total degree ≤ `degree` in (x, y) times degree ≤ `degree` in z (Prism).
    pub fn new(shape: Shape, degree: usize) -> QuadratureRule {
        let n = degree / 2 + 1;
        let line = unit_interval(&gauss_legendre(n), 1.0);
        match shape {
            Shape::Line => tensor(&[&line]),
            Shape::Quad => tensor(&[&line, &line]),
            Shape::Hex => tensor(&[&line, &line, &line]),
            Shape::Tri => collapsed_triangle(&line, n),
            Shape::Tet => {
                // (u, v, z) ↦ (u(1−v)(1−z), v(1−z), z); Jacobian (1 − v)(1 − z)².
                let v_rule = unit_interval(&gauss_jacobi(n, 1.0, 0.0), 2.0);
                let z_rule = unit_interval(&gauss_jacobi(n, 2.0, 0.0), 4.0);
                let mut rule = QuadratureRule::with_capacity(n * n * n);
                for (&z, &wz) in z_rule.points.iter().zip(&z_rule.weights) {
                    for (&v, &wv) in v_rule.points.iter().zip(&v_rule.weights) {
                        for (&u, &wu) in line.points.iter().zip(&line.weights) {
                            let y = v * (1.0 - z);
                            let x = u * (1.0 - v) * (1.0 - z);
                            rule.points.push([x, y, z]);
                            rule.weights.push(wu * wv * wz);
                        }
                    }
                }
                rule
            }
            Shape::Prism => {
                let tri = collapsed_triangle(&line, n);
                let mut rule = QuadratureRule::with_capacity(tri.len() * n);
                for (&z, &wz) in line.points.iter().zip(&line.weights) {
                    for (p, &w) in tri.points.iter().zip(&tri.weights) {
                        rule.points.push([p[0], p[1], z]);
                        rule.weights.push(w * wz);
                    }
                }
                rule
            }
        }
    }

    /// A rule exact to `degree` like [`QuadratureRule::new`], with fewer points where a
    /// fully symmetric triangle rule is known that has fewer (even degrees 2 to 8: 3, 6,
    /// 12, 16 points against 4, 9, 16, 25): triangles, and prisms as that rule × the Gauss
    /// line rule (at degree 6, 48 points instead of 64). Otherwise `new`'s rule.
    pub fn symmetric(shape: Shape, degree: usize) -> QuadratureRule {
        let collapsed = (degree / 2 + 1).pow(2);
        let symmetric = match shape {
            Shape::Tri | Shape::Prism => {
                symmetric_triangle(degree).filter(|rule| rule.len() < collapsed)
            }
            _ => None,
        };
        let Some(tri) = symmetric else {
            return QuadratureRule::new(shape, degree);
        };
        if shape == Shape::Tri {
            return tri;
        }
        let line = unit_interval(&gauss_legendre(degree / 2 + 1), 1.0);
        let mut rule = QuadratureRule::with_capacity(tri.len() * line.len());
        for (&z, &wz) in line.points.iter().zip(&line.weights) {
            for (p, &w) in tri.points.iter().zip(&tri.weights) {
                rule.points.push([p[0], p[1], z]);
                rule.weights.push(w * wz);
            }
        }
        rule
    }

    fn with_capacity(n: usize) -> QuadratureRule {
        QuadratureRule {
            points: Vec::with_capacity(n),
            weights: Vec::with_capacity(n),
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True if the rule has no points (never for rules built by [`QuadratureRule::new`]).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Σᵢ wᵢ f(ξᵢ).
    pub fn integrate(&self, f: impl Fn([f64; 3]) -> f64) -> f64 {
        self.points
            .iter()
            .zip(&self.weights)
            .map(|(&p, &w)| w * f(p))
            .sum()
    }
}

/// Maps a rule on [-1, 1] to [0, 1] (t = (x + 1)/2); the weights are divided by
/// 2 · `weight_scale`, where `weight_scale` = 2^α accounts for (1 − x)^α = 2^α (1 − t)^α.
fn unit_interval(rule: &Rule1D, weight_scale: f64) -> Rule1D {
    Rule1D {
        points: rule.points.iter().map(|x| 0.5 * (x + 1.0)).collect(),
        weights: rule
            .weights
            .iter()
            .map(|w| 0.5 * w / weight_scale)
            .collect(),
    }
}

/// Tensor product of rules on [0, 1], first factor varying fastest.
fn tensor(factors: &[&Rule1D]) -> QuadratureRule {
    let total: usize = factors.iter().map(|r| r.len()).product();
    let mut rule = QuadratureRule::with_capacity(total);
    for index in 0..total {
        let mut rest = index;
        let mut point = [0.0; 3];
        let mut weight = 1.0;
        for (d, factor) in factors.iter().enumerate() {
            let i = rest % factor.len();
            rest /= factor.len();
            point[d] = factor.points[i];
            weight *= factor.weights[i];
        }
        rule.points.push(point);
        rule.weights.push(weight);
    }
    rule
}

/// (u, y) ↦ (u(1 − y), y) with Jacobian (1 − y) in the Gauss–Jacobi (α = 1) weight.
fn collapsed_triangle(line: &Rule1D, n: usize) -> QuadratureRule {
    let y_rule = unit_interval(&gauss_jacobi(n, 1.0, 0.0), 2.0);
    let mut rule = QuadratureRule::with_capacity(n * n);
    for (&y, &wy) in y_rule.points.iter().zip(&y_rule.weights) {
        for (&u, &wu) in line.points.iter().zip(&line.weights) {
            rule.points.push([u * (1.0 - y), y, 0.0]);
            rule.weights.push(wu * wy);
        }
    }
    rule
}

#[cfg(test)]
#[path = "tests/quadrature.rs"]
mod tests;
