//! Fully symmetric quadrature rules on the triangle: fewer points than the collapsed
//! (Stroud conical) rules of [`crate::QuadratureRule::new`] for the same degree — 3, 6, 12
//! and 16 points for degrees 2, 4, 6 and 8 against 4, 9, 16 and 25 — with positive weights
//! and every point inside.
//!
//! A rule is a union of orbits of the triangle's symmetry group acting on barycentric
//! coordinates: the centroid (1 point, a weight), (a, a, 1 − 2a) (3 points: a and a
//! weight), (a, b, 1 − a − b) (6 points: a, b and a weight). For the orbit structures
//! below, the conditions "exact on every monomial of degree ≤ d" leave as many independent
//! equations as unknowns (one per symmetric invariant p₂ⁱ p₃ʲ with 2i + 3j ≤ d). Their
//! solutions are found by Gauss–Newton from approximate values (those tabulated by
//! D. A. Dunavant, Int. J. Numer. Meth. Eng. 21 (1985) 1129–1148), so the rules here are
//! exact to rounding whatever the digits of the starting values.

use nalgebra::{DMatrix, DVector};

use crate::QuadratureRule;

/// One orbit with its approximate parameters: barycentric coordinates and the weight of
/// each of its points (the weights of a rule sum to 1).
#[derive(Debug, Clone, Copy)]
enum Orbit {
    /// (⅓, ⅓, ⅓).
    Centroid { weight: f64 },
    /// The 3 permutations of (a, a, 1 − 2a).
    Median { a: f64, weight: f64 },
    /// The 6 permutations of (a, b, 1 − a − b).
    General { a: f64, b: f64, weight: f64 },
}

/// Rules by the degree they are exact to, with the orbits' starting values.
const RULES: [(usize, &[Orbit]); 4] = [
    (
        2,
        &[Orbit::Median {
            a: 1.0 / 6.0,
            weight: 1.0 / 3.0,
        }],
    ),
    (
        4,
        &[
            Orbit::Median {
                a: 0.445_948_490_916,
                weight: 0.223_381_589_678,
            },
            Orbit::Median {
                a: 0.091_576_213_510,
                weight: 0.109_951_743_655,
            },
        ],
    ),
    (
        6,
        &[
            Orbit::Median {
                a: 0.249_286_745_171,
                weight: 0.116_786_275_726,
            },
            Orbit::Median {
                a: 0.063_089_014_492,
                weight: 0.050_844_906_370,
            },
            Orbit::General {
                a: 0.053_145_049_845,
                b: 0.310_352_451_034,
                weight: 0.082_851_075_618,
            },
        ],
    ),
    (
        8,
        &[
            Orbit::Centroid {
                weight: 0.144_315_607_678,
            },
            Orbit::Median {
                a: 0.459_292_588_293,
                weight: 0.095_091_634_267,
            },
            Orbit::Median {
                a: 0.170_569_307_752,
                weight: 0.103_217_370_535,
            },
            Orbit::Median {
                a: 0.050_547_228_317,
                weight: 0.032_458_497_623,
            },
            Orbit::General {
                a: 0.008_394_777_410,
                b: 0.263_112_829_635,
                weight: 0.027_230_314_174,
            },
        ],
    ),
];

/// The symmetric rule on the reference triangle (0,0), (1,0), (0,1) exact to `degree`
/// (the one of the smallest degree ≥ `degree` listed), or None above degree 8 or if its
/// equations did not solve to rounding.
pub(crate) fn symmetric_triangle(degree: usize) -> Option<QuadratureRule> {
    let &(exact_to, orbits) = RULES.iter().find(|(d, _)| *d >= degree)?;
    let mut params: Vec<f64> = orbits.iter().flat_map(|o| o.params()).collect();
    let monomials: Vec<(i32, i32)> = (0..=exact_to as i32)
        .flat_map(|s| (0..=s).map(move |i| (i, s - i)))
        .collect();
    // ∫ xⁱ yʲ over the triangle = i! j! / (i + j + 2)!.
    let exact: Vec<f64> = monomials
        .iter()
        .map(|&(i, j)| factorial(i) * factorial(j) / factorial(i + j + 2))
        .collect();
    let residual_of = |params: &[f64]| -> (DVector<f64>, DMatrix<f64>) {
        let mut r = DVector::from_iterator(exact.len(), exact.iter().map(|e| -e));
        let mut jac = DMatrix::zeros(exact.len(), params.len());
        let mut at = 0;
        for orbit in orbits {
            let count = orbit.params().len();
            let p = &params[at..at + count];
            let weight = 0.5 * p[count - 1];
            for (point, dpoint) in orbit.points(p) {
                for (k, &(i, j)) in monomials.iter().enumerate() {
                    let value = point[0].powi(i) * point[1].powi(j);
                    r[k] += weight * value;
                    jac[(k, at + count - 1)] += 0.5 * value;
                    let dx = if i > 0 {
                        f64::from(i) * point[0].powi(i - 1) * point[1].powi(j)
                    } else {
                        0.0
                    };
                    let dy = if j > 0 {
                        f64::from(j) * point[0].powi(i) * point[1].powi(j - 1)
                    } else {
                        0.0
                    };
                    for (c, d) in dpoint.iter().enumerate().take(count - 1) {
                        jac[(k, at + c)] += weight * (dx * d[0] + dy * d[1]);
                    }
                }
            }
            at += count;
        }
        (r, jac)
    };
    for _ in 0..30 {
        let (r, jac) = residual_of(&params);
        // Least squares: the system is consistent (zero residual at the solution), so
        // Gauss–Newton converges quadratically.
        let step = jac.svd(true, true).solve(&r, 1e-14).ok()?;
        for (p, s) in params.iter_mut().zip(step.iter()) {
            *p -= s;
        }
        if step.amax() < 1e-16 {
            break;
        }
    }
    let (r, _) = residual_of(&params);
    if r.amax() > 1e-15 {
        return None;
    }
    let mut rule = QuadratureRule {
        points: Vec::new(),
        weights: Vec::new(),
    };
    let mut at = 0;
    for orbit in orbits {
        let count = orbit.params().len();
        let p = &params[at..at + count];
        for (point, _) in orbit.points(p) {
            rule.points.push([point[0], point[1], 0.0]);
            rule.weights.push(0.5 * p[count - 1]);
        }
        at += count;
    }
    let inside = rule
        .points
        .iter()
        .all(|p| p[0] > 0.0 && p[1] > 0.0 && p[0] + p[1] < 1.0);
    (inside && rule.weights.iter().all(|&w| w > 0.0)).then_some(rule)
}

impl Orbit {
    /// The unknowns: coordinates, then the weight.
    fn params(&self) -> Vec<f64> {
        match *self {
            Orbit::Centroid { weight } => vec![weight],
            Orbit::Median { a, weight } => vec![a, weight],
            Orbit::General { a, b, weight } => vec![a, b, weight],
        }
    }

    /// The orbit's points (x, y) = (λ₁, λ₂) for the parameters `p` (as
    /// [`Orbit::params`]), each with its derivatives ∂(x, y)/∂ of the coordinate parameters.
    fn points(&self, p: &[f64]) -> Vec<([f64; 2], [[f64; 2]; 2])> {
        // Barycentric coordinates and their derivatives in the parameters (a, b).
        let (lambda, d): ([f64; 3], [[f64; 2]; 3]) = match *self {
            Orbit::Centroid { .. } => ([1.0 / 3.0; 3], [[0.0; 2]; 3]),
            Orbit::Median { .. } => (
                [p[0], p[0], 1.0 - 2.0 * p[0]],
                [[1.0, 0.0], [1.0, 0.0], [-2.0, 0.0]],
            ),
            Orbit::General { .. } => (
                [p[0], p[1], 1.0 - p[0] - p[1]],
                [[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]],
            ),
        };
        let permutations: &[[usize; 2]] = match self {
            Orbit::Centroid { .. } => &[[0, 1]],
            Orbit::Median { .. } => &[[0, 1], [0, 2], [2, 0]],
            Orbit::General { .. } => &[[0, 1], [1, 0], [0, 2], [2, 0], [1, 2], [2, 1]],
        };
        permutations
            .iter()
            .map(|&[i, j]| {
                (
                    [lambda[i], lambda[j]],
                    // ∂x/∂a, ∂y/∂a and ∂x/∂b, ∂y/∂b.
                    [[d[i][0], d[j][0]], [d[i][1], d[j][1]]],
                )
            })
            .collect()
    }
}

fn factorial(n: i32) -> f64 {
    (1..=n).map(f64::from).product()
}

#[cfg(test)]
#[path = "tests/symmetric_triangle.rs"]
mod tests;
