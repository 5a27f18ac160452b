//! Bernstein (Bézier) polynomial spaces on the reference shapes, and the conversion of
//! sampled values to Bernstein coefficients.
//!
//! On a simplex the Bernstein polynomials of degree n are B_α(λ) = n!/(α₀!⋯α_d!) Π λᵢ^αᵢ,
//! |α| = n, with λ the barycentric coordinates; on the box they are tensor products of the 1D
//! B_i^n(t) = C(n, i) tⁱ (1 − t)ⁿ⁻ⁱ; on the prism, triangle × line. They are non-negative and
//! sum to 1, so a polynomial lies between its smallest and largest coefficient (the convex
//! hull property), and the coefficient of a vertex is the polynomial's value there.
//!
//! The coefficients of a polynomial f of the space are found from its values at lattice
//! points ξ_α (unisolvent for the space): c = M⁻¹ f with M_{αβ} = B_β(ξ_α). On simplices the
//! points are the equispaced α / n; in each 1D direction (quadrilateral, hexahedron, the
//! prism's ζ) the Chebyshev–Lobatto points ½ − ½ cos(π i / n), which keep ‖M⁻¹‖∞ — the
//! factor by which rounding in the values can grow in the coefficients — 3 to 6 times smaller
//! per direction than equispaced points at the degrees of p = 2..4 hexahedra (e.g. 184
//! instead of 560 at degree 8). Both include the vertices. M⁻¹ is precomputed; on the box and
//! the prism it is a Kronecker product of 1D (and triangle) inverses and is applied one
//! direction at a time.

use hocurve_nodes::Shape;
use nalgebra::DMatrix;

use crate::bernstein_subdivision::subdivision_matrix;
use crate::{BernsteinSubdivision, QualityError};

/// Largest degree per variable (1D factor) accepted.
pub const MAX_LINE_DEGREE: usize = 40;
/// Largest number of coefficients of a dense (triangle or tetrahedron) factor: 2024 is the
/// degree-21 tetrahedron, i.e. det J of p = 8 tetrahedra (a 33 MB inverse).
pub const MAX_DENSE_COEFFICIENTS: usize = 2024;

/// A Bernstein polynomial space on a reference shape, with its lattice points and the
/// precomputed values-to-coefficients conversion.
#[derive(Debug, Clone)]
pub struct BernsteinSpace {
    lattice: Lattice,
    /// Conversion factors: (storage axis, row-major m×m inverse of the factor's M); None for
    /// a space built without its conversion ([`BernsteinSpace::lattice_only`]).
    factors: Option<Vec<(usize, Vec<f64>)>>,
    /// ‖M⁻¹‖∞ of the whole conversion (product of the factors' norms).
    inverse_norm: f64,
}

/// Multi-indices, lattice points and basis weights of a space, without the conversion.
#[derive(Debug, Clone)]
struct Lattice {
    shape: Shape,
    degree: usize,
    degree_z: usize,
    /// Exponents of the "barycentric" coordinates (see [`Lattice::coordinates`]).
    exponents: Vec<[u8; 6]>,
    /// Multinomial (or binomial product) weight of each basis function.
    weights: Vec<f64>,
    points: Vec<[f64; 3]>,
    /// Storage shape: index = i₀ + dims₀ (i₁ + dims₁ i₂).
    dims: [usize; 3],
}

impl BernsteinSpace {
    /// The space of the Jacobian determinant of order-`order` isoparametric elements of
    /// `shape` (see [`jacobian_degree`]).
    pub fn for_jacobian(shape: Shape, order: usize) -> Result<Self, QualityError> {
        let (degree, degree_z) = jacobian_degree(shape, order);
        Self::new(shape, degree, degree_z).map_err(|_| QualityError::UnsupportedBezierDegree {
            shape,
            order,
            degree: degree.max(degree_z),
            max: match shape {
                Shape::Tri | Shape::Tet => max_dense_degree(shape),
                _ => MAX_LINE_DEGREE,
            },
        })
    }

    /// The space of `shape` of degree `degree`: total degree on simplices, degree per
    /// variable on the line, quadrilateral and hexahedron; on the prism total degree
    /// `degree` in (ξ, η) times degree `degree_z` in ζ (`degree_z` is ignored elsewhere).
    pub fn new(shape: Shape, degree: usize, degree_z: usize) -> Result<Self, QualityError> {
        let lattice = Lattice::new(shape, degree, degree_z);
        let too_big = || QualityError::UnsupportedBezierDegree {
            shape,
            order: 0,
            degree,
            max: MAX_LINE_DEGREE,
        };
        let line = |n: usize| -> Result<Vec<f64>, QualityError> {
            if n > MAX_LINE_DEGREE {
                return Err(too_big());
            }
            dense_inverse(&Lattice::new(Shape::Line, n, 0)).ok_or_else(too_big)
        };
        let dense = |space: &Lattice| -> Result<Vec<f64>, QualityError> {
            if space.len() > MAX_DENSE_COEFFICIENTS {
                return Err(too_big());
            }
            dense_inverse(space).ok_or_else(too_big)
        };
        let factors = match shape {
            Shape::Line | Shape::Tri | Shape::Tet => vec![(0, dense(&lattice)?)],
            Shape::Quad => {
                let a = line(degree)?;
                vec![(0, a.clone()), (1, a)]
            }
            Shape::Hex => {
                let a = line(degree)?;
                vec![(0, a.clone()), (1, a.clone()), (2, a)]
            }
            Shape::Prism => vec![
                (0, dense(&Lattice::new(Shape::Tri, degree, 0))?),
                (1, line(degree_z)?),
            ],
        };
        let inverse_norm = factors
            .iter()
            .map(|(axis, m)| infinity_norm(m, lattice.dims[*axis]))
            .product();
        Ok(BernsteinSpace {
            lattice,
            factors: Some(factors),
            inverse_norm,
        })
    }

    /// The space of det J of order-`order` elements of `shape` without the conversion from
    /// sampled values: for triangles and tetrahedra, whose coefficients come exactly from the
    /// map's control points ([`crate::bezier_simplex`]) and whose regions are split by exact
    /// bisection, so the dense inverse (C(3(p − 1) + 3, 3)² numbers: 33 MB and seconds of
    /// factorisation at p = 8, 132 MB at p = 10) is never needed. Its
    /// [`BernsteinSpace::conversion_norm`] is infinite and it does not convert values.
    pub fn lattice_only(shape: Shape, order: usize) -> Result<Self, QualityError> {
        let (degree, degree_z) = jacobian_degree(shape, order);
        if degree.max(degree_z) > MAX_LINE_DEGREE {
            return Err(QualityError::UnsupportedBezierDegree {
                shape,
                order,
                degree: degree.max(degree_z),
                max: MAX_LINE_DEGREE,
            });
        }
        Ok(BernsteinSpace {
            lattice: Lattice::new(shape, degree, degree_z),
            factors: None,
            inverse_norm: f64::INFINITY,
        })
    }
    /// The exponents of every basis polynomial, in coefficient order (the barycentric
    /// groups of [`Lattice::coordinates`], zero-padded).
    pub(crate) fn exponents(&self) -> &[[u8; 6]] {
        &self.lattice.exponents
    }

    /// The shape.
    pub fn shape(&self) -> Shape {
        self.lattice.shape
    }

    /// Degree (total on simplices and the prism's triangle, per variable on boxes).
    pub fn degree(&self) -> usize {
        self.lattice.degree
    }

    /// Degree in ζ of a prism space (equal to [`BernsteinSpace::degree`] for other shapes).
    pub fn degree_z(&self) -> usize {
        if self.lattice.shape == Shape::Prism {
            self.lattice.degree_z
        } else {
            self.lattice.degree
        }
    }

    /// Number of basis functions (= coefficients = lattice points).
    pub fn len(&self) -> usize {
        self.lattice.len()
    }

    /// Never true.
    pub fn is_empty(&self) -> bool {
        self.lattice.len() == 0
    }

    /// The lattice points ξ_α where values are sampled, in coefficient order.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.lattice.points
    }

    /// ‖M⁻¹‖∞: how much the conversion can amplify errors in the sampled values (infinite
    /// for a space without conversion).
    pub fn conversion_norm(&self) -> f64 {
        self.inverse_norm
    }

    /// Whether [`BernsteinSpace::values_to_coefficients`] is available: true for every
    /// space built by [`BernsteinSpace::new`] and [`BernsteinSpace::for_jacobian`]; false for
    /// the simplex spaces of [`crate::JacobianBezier`], which never sample.
    pub fn converts_values(&self) -> bool {
        self.factors.is_some()
    }

    /// Replaces the values f(ξ_α) at the lattice points in `values` by the Bernstein
    /// coefficients of the interpolating polynomial (`tmp` is scratch memory). Values are
    /// set to NaN when the space has no conversion ([`BernsteinSpace::converts_values`]),
    /// so that nothing is certified from them.
    pub fn values_to_coefficients(&self, values: &mut [f64], tmp: &mut Vec<f64>) {
        let Some(factors) = &self.factors else {
            values.fill(f64::NAN);
            return;
        };
        for (axis, matrix) in factors {
            apply_along_axis(matrix, self.lattice.dims, *axis, values, tmp);
        }
    }

    /// The exact subdivision of this space into the children of one midpoint refinement
    /// (2^d boxes; for the prism the 4 midpoint triangles times the 2 halves in ζ, triangle
    /// children in the order of [`crate::JacobianBezier`]'s refinement), or None for simplices and
    /// the line, whose dense subdivision matrices would be large (the validity check samples
    /// det J on their sub-elements instead).
    pub fn subdivision(&self) -> Option<BernsteinSubdivision> {
        let lattice = &self.lattice;
        let line = |n: usize| -> Vec<Vec<usize>> { (0..=n).map(|i| vec![n - i, i, 0]).collect() };
        let halves = [
            [[1.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.0, 0.0, 1.0]],
            [[0.5, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        ];
        let mut matrices = Vec::new();
        let mut children = Vec::new();
        match lattice.shape {
            Shape::Quad | Shape::Hex => {
                let axes = lattice.shape.dim();
                let exponents = line(lattice.degree);
                for w in &halves {
                    matrices.push(subdivision_matrix(&exponents, lattice.degree, w));
                }
                for c in 0..1usize << axes {
                    children.push((0..axes).map(|k| (k, c >> k & 1)).collect());
                }
            }
            Shape::Prism => {
                let (n, nz) = (lattice.degree, lattice.degree_z);
                let mut triangle = Vec::new();
                for j in 0..=n {
                    for i in 0..=n - j {
                        triangle.push(vec![n - i - j, i, j]);
                    }
                }
                let (v0, v1, v2) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
                let (m01, m12, m02) = ([0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]);
                // The midpoint triangles, as barycentric vertices (same order as the
                // affine refinement of the validity check).
                let quarter = [
                    [v0, m01, m02],
                    [m01, v1, m12],
                    [m02, m12, v2],
                    [m12, m02, m01],
                ];
                for w in &quarter {
                    matrices.push(subdivision_matrix(&triangle, n, w));
                }
                let z = line(nz);
                for w in &halves {
                    matrices.push(subdivision_matrix(&z, nz, w));
                }
                for half in 0..2 {
                    for t in 0..4 {
                        children.push(vec![(0, t), (1, 4 + half)]);
                    }
                }
            }
            Shape::Line | Shape::Tri | Shape::Tet => return None,
        }
        // A coefficient sits at a vertex when, in every group of coordinates, one
        // exponent carries the whole degree.
        let groups: &[(usize, usize)] = match lattice.shape {
            Shape::Quad => &[(0, 2), (2, 4)],
            Shape::Hex => &[(0, 2), (2, 4), (4, 6)],
            _ => &[(0, 3), (3, 5)],
        };
        let vertices = lattice
            .exponents
            .iter()
            .enumerate()
            .filter(|(_, ex)| {
                groups.iter().all(|&(a, b)| {
                    let total: usize = ex[a..b].iter().map(|&e| e as usize).sum();
                    ex[a..b].iter().any(|&e| e as usize == total)
                })
            })
            .map(|(i, _)| i)
            .collect();
        Some(BernsteinSubdivision {
            children,
            matrices,
            dims: lattice.dims,
            vertices,
        })
    }

    /// Σ_α c_α B_α(ξ): the polynomial with Bernstein coefficients `coefficients` at ξ.
    pub fn eval(&self, coefficients: &[f64], xi: [f64; 3]) -> f64 {
        let mut basis = vec![0.0; self.len()];
        self.lattice.basis_values(xi, &mut basis);
        basis.iter().zip(coefficients).map(|(b, c)| b * c).sum()
    }
}

/// Degree of det J for order-p isoparametric elements, as (degree, degree_z):
/// - triangle (2D): each column ∂x/∂ξₖ has total degree p − 1, so det J has 2(p − 1);
/// - tetrahedron: 3(p − 1);
/// - quadrilateral (Q_p: degree ≤ p in each variable): ∂x/∂ξ has degree p − 1 in ξ and p in
///   η, ∂x/∂η the reverse, so each term of x_ξ y_η − x_η y_ξ has degree 2p − 1 per variable;
/// - hexahedron: each of the three factors of a term of det J has degree p − 1 in one
///   variable and p in the others, so 3p − 1 per variable;
/// - prism (P_p(ξ, η) ⊗ P_p(ζ)): ∂/∂ξ and ∂/∂η lower the triangle degree to p − 1, ∂/∂ζ the ζ
///   degree to p − 1, so a term has triangle degree 2(p − 1) + p = 3p − 2 and ζ degree
///   2p + (p − 1) = 3p − 1.
///
/// `degree_z` equals `degree` except for the prism.
pub fn jacobian_degree(shape: Shape, order: usize) -> (usize, usize) {
    let p = order;
    let d = match shape {
        Shape::Line => p.saturating_sub(1),
        Shape::Tri => 2 * p.saturating_sub(1),
        Shape::Tet => 3 * p.saturating_sub(1),
        Shape::Quad => (2 * p).saturating_sub(1),
        Shape::Hex => (3 * p).saturating_sub(1),
        Shape::Prism => return ((3 * p).saturating_sub(2), (3 * p).saturating_sub(1)),
    };
    (d, d)
}

/// Whether the Bézier validity check supports order-`order` elements of `shape`: det J's
/// degree per variable within [`MAX_LINE_DEGREE`] (its coefficients are computed exactly from
/// the map's control points, without a conversion matrix): tetrahedra up to p = 14,
/// hexahedra and prisms up to p = 13, triangles up to p = 21.
pub fn bezier_check_supported(shape: Shape, order: usize) -> bool {
    let (degree, degree_z) = jacobian_degree(shape, order);
    degree.max(degree_z) <= MAX_LINE_DEGREE
}

/// Largest total degree n whose dense factor fits [`MAX_DENSE_COEFFICIENTS`]: the simplex
/// of dimension d has C(n + d, d) Bernstein polynomials of degree n.
fn max_dense_degree(shape: Shape) -> usize {
    let count = |n: usize| match shape {
        Shape::Tet => (n + 1) * (n + 2) * (n + 3) / 6,
        Shape::Tri => (n + 1) * (n + 2) / 2,
        _ => n + 1,
    };
    (0..)
        .take_while(|&n| count(n) <= MAX_DENSE_COEFFICIENTS)
        .last()
        .unwrap_or(0)
}

impl Lattice {
    fn new(shape: Shape, degree: usize, degree_z: usize) -> Lattice {
        let n = degree;
        let nz = if shape == Shape::Prism { degree_z } else { n };
        let mut lattice = Lattice {
            shape,
            degree: n,
            degree_z: nz,
            exponents: Vec::new(),
            weights: Vec::new(),
            points: Vec::new(),
            dims: [1; 3],
        };
        // Simplex lattice coordinate i/n, and the 1D Chebyshev–Lobatto point (any point when
        // n = 0: the space is the constants). The cosine is symmetrised so that the points
        // are exactly mirror images and the middle one (even n) is exactly ½.
        let t = |i: usize, n: usize| if n == 0 { 0.0 } else { i as f64 / n as f64 };
        let c = |i: usize, n: usize| {
            if n == 0 {
                0.0
            } else if 2 * i <= n {
                0.5 - 0.5 * (std::f64::consts::PI * i as f64 / n as f64).cos()
            } else {
                0.5 + 0.5 * (std::f64::consts::PI * (n - i) as f64 / n as f64).cos()
            }
        };
        match shape {
            Shape::Line => {
                for i in 0..=n {
                    lattice.push([n - i, i, 0, 0, 0, 0], [c(i, n), 0.0, 0.0]);
                }
                lattice.dims = [n + 1, 1, 1];
            }
            Shape::Tri => {
                for j in 0..=n {
                    for i in 0..=n - j {
                        lattice.push([n - i - j, i, j, 0, 0, 0], [t(i, n), t(j, n), 0.0]);
                    }
                }
                lattice.dims = [lattice.len(), 1, 1];
            }
            Shape::Tet => {
                for k in 0..=n {
                    for j in 0..=n - k {
                        for i in 0..=n - j - k {
                            lattice
                                .push([n - i - j - k, i, j, k, 0, 0], [t(i, n), t(j, n), t(k, n)]);
                        }
                    }
                }
                lattice.dims = [lattice.len(), 1, 1];
            }
            Shape::Quad => {
                for j in 0..=n {
                    for i in 0..=n {
                        lattice.push([n - i, i, n - j, j, 0, 0], [c(i, n), c(j, n), 0.0]);
                    }
                }
                lattice.dims = [n + 1, n + 1, 1];
            }
            Shape::Hex => {
                for k in 0..=n {
                    for j in 0..=n {
                        for i in 0..=n {
                            lattice
                                .push([n - i, i, n - j, j, n - k, k], [c(i, n), c(j, n), c(k, n)]);
                        }
                    }
                }
                lattice.dims = [n + 1, n + 1, n + 1];
            }
            Shape::Prism => {
                for k in 0..=nz {
                    for j in 0..=n {
                        for i in 0..=n - j {
                            lattice.push(
                                [n - i - j, i, j, nz - k, k, 0],
                                [t(i, n), t(j, n), c(k, nz)],
                            );
                        }
                    }
                }
                let triangle = (n + 1) * (n + 2) / 2;
                lattice.dims = [triangle, nz + 1, 1];
            }
        }
        lattice
    }

    fn push(&mut self, exponents: [usize; 6], point: [f64; 3]) {
        // Groups of coordinates summing to 1: simplex = one group, box = one per axis.
        let groups: &[(usize, usize)] = match self.shape {
            Shape::Line => &[(0, 2)],
            Shape::Tri => &[(0, 3)],
            Shape::Tet => &[(0, 4)],
            Shape::Quad => &[(0, 2), (2, 4)],
            Shape::Hex => &[(0, 2), (2, 4), (4, 6)],
            Shape::Prism => &[(0, 3), (3, 5)],
        };
        let weight = groups
            .iter()
            .map(|&(a, b)| multinomial(&exponents[a..b]))
            .product();
        // Degrees are at most MAX_LINE_DEGREE (< 256): the cast is exact.
        self.exponents.push(exponents.map(|e| e as u8));
        self.weights.push(weight);
        self.points.push(point);
    }

    fn len(&self) -> usize {
        self.points.len()
    }

    /// The "barycentric" coordinates whose powers make the basis: (1−ξ−η, ξ, η) for the
    /// triangle, (1−ξ, ξ, 1−η, η, 1−ζ, ζ) for the hexahedron, and so on.
    fn coordinates(&self, xi: [f64; 3]) -> [f64; 6] {
        let [x, y, z] = xi;
        match self.shape {
            Shape::Line => [1.0 - x, x, 0.0, 0.0, 0.0, 0.0],
            Shape::Tri => [1.0 - x - y, x, y, 0.0, 0.0, 0.0],
            Shape::Tet => [1.0 - x - y - z, x, y, z, 0.0, 0.0],
            Shape::Quad => [1.0 - x, x, 1.0 - y, y, 0.0, 0.0],
            Shape::Hex => [1.0 - x, x, 1.0 - y, y, 1.0 - z, z],
            Shape::Prism => [1.0 - x - y, x, y, 1.0 - z, z, 0.0],
        }
    }

    /// B_α(ξ) for every α, into `out`.
    fn basis_values(&self, xi: [f64; 3], out: &mut [f64]) {
        let c = self.coordinates(xi);
        let top = self.degree.max(self.degree_z);
        // powers[a][e] = c_a^e
        let mut powers = vec![[1.0; 6]; top + 1];
        for e in 1..=top {
            for a in 0..6 {
                powers[e][a] = powers[e - 1][a] * c[a];
            }
        }
        for ((o, ex), w) in out.iter_mut().zip(&self.exponents).zip(&self.weights) {
            let mut v = *w;
            for a in 0..6 {
                v *= powers[ex[a] as usize][a];
            }
            *o = v;
        }
    }
}

/// (Σ kᵢ)! / Π kᵢ!, computed as a product of binomials to stay exact in f64 as long as
/// possible.
fn multinomial(k: &[usize]) -> f64 {
    let mut total = 0;
    let mut value = 1.0;
    for &ki in k {
        for j in 1..=ki {
            total += 1;
            value = value * total as f64 / j as f64;
        }
    }
    value
}

/// Row-major inverse of M_{αβ} = B_β(ξ_α) on the lattice, or None if singular.
fn dense_inverse(lattice: &Lattice) -> Option<Vec<f64>> {
    let n = lattice.len();
    let mut m = DMatrix::zeros(n, n);
    let mut row = vec![0.0; n];
    for (a, &x) in lattice.points.iter().enumerate() {
        lattice.basis_values(x, &mut row);
        for b in 0..n {
            m[(a, b)] = row[b];
        }
    }
    let inverse = m.lu().try_inverse()?;
    // nalgebra is column-major: the transpose's storage is the row-major inverse.
    Some(inverse.transpose().as_slice().to_vec())
}

/// Maximum absolute row sum of a row-major m×m matrix.
fn infinity_norm(matrix: &[f64], m: usize) -> f64 {
    matrix
        .chunks(m)
        .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Replaces every fiber of `values` along storage axis `axis` by its image under the
/// row-major m×m `matrix` (m = dims[axis]).
pub(crate) fn apply_along_axis(
    matrix: &[f64],
    dims: [usize; 3],
    axis: usize,
    values: &mut [f64],
    tmp: &mut Vec<f64>,
) {
    let m = dims[axis];
    let stride: usize = dims[..axis].iter().product();
    let outer = values.len() / (m * stride);
    tmp.clear();
    tmp.resize(2 * m, 0.0);
    let (fiber, image) = tmp.split_at_mut(m);
    for o in 0..outer {
        for s in 0..stride {
            let base = o * m * stride + s;
            for r in 0..m {
                fiber[r] = values[base + r * stride];
            }
            for (r, out) in image.iter_mut().enumerate() {
                let row = &matrix[r * m..(r + 1) * m];
                *out = row.iter().zip(fiber.iter()).map(|(a, b)| a * b).sum();
            }
            for r in 0..m {
                values[base + r * stride] = image[r];
            }
        }
    }
}

#[cfg(test)]
#[path = "tests/bernstein.rs"]
mod tests;
