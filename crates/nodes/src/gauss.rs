//! One-dimensional Gauss rules on [-1, 1] and the Jacobi polynomials they are built from.
//!
//! Nodes come from the Golub–Welsch eigenproblem of the (symmetric tridiagonal) Jacobi matrix
//! of the orthonormal Jacobi polynomials, are polished by Newton's method on p̃ₙ, and the
//! weights are the Christoffel numbers wᵢ = 1 / Σₖ₍ₖ₌₀..ₙ₋₁₎ p̃ₖ(xᵢ)², which stay accurate to
//! a few ulps even for the small weights next to ±1. Rules with α = β are symmetrised
//! exactly (xᵢ = −xₙ₋₁₋ᵢ).

use nalgebra::{DMatrix, SymmetricEigen};

/// A quadrature rule on [-1, 1]: Σᵢ wᵢ f(xᵢ) ≈ ∫ w(x) f(x) dx, points ascending.
#[derive(Debug, Clone, PartialEq)]
pub struct Rule1D {
    /// Nodes xᵢ in [-1, 1], ascending.
    pub points: Vec<f64>,
    /// Weights wᵢ.
    pub weights: Vec<f64>,
}

impl Rule1D {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True for the empty rule (n = 0).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Σᵢ wᵢ f(xᵢ).
    pub fn integrate(&self, f: impl Fn(f64) -> f64) -> f64 {
        self.points
            .iter()
            .zip(&self.weights)
            .map(|(&x, &w)| w * f(x))
            .sum()
    }
}

/// Gauss–Legendre rule with `n` points: exact for polynomials of degree ≤ 2n − 1 on [-1, 1].
pub fn gauss_legendre(n: usize) -> Rule1D {
    gauss_jacobi(n, 0.0, 0.0)
}

/// Gauss–Lobatto–Legendre rule with `n ≥ 2` points, including ±1: exact for polynomials of
/// degree ≤ 2n − 3. The interior points are the zeros of P′ₙ₋₁, i.e. the Gauss–Jacobi
/// points with α = β = 1, and wᵢ = 2 / (n(n − 1) Pₙ₋₁(xᵢ)²).
///
/// # Panics
/// If `n < 2`.
pub fn gauss_lobatto_legendre(n: usize) -> Rule1D {
    assert!(
        n >= 2,
        "a Gauss–Lobatto rule needs at least 2 points, got {n}"
    );
    let interior = gauss_jacobi(n - 2, 1.0, 1.0);
    let scale = 2.0 / (n * (n - 1)) as f64;
    let mut points = Vec::with_capacity(n);
    let mut weights = Vec::with_capacity(n);
    points.push(-1.0);
    weights.push(scale);
    for &x in &interior.points {
        let p = jacobi(n - 1, 0.0, 0.0, x);
        points.push(x);
        weights.push(scale / (p * p));
    }
    points.push(1.0);
    weights.push(scale);
    let mut rule = Rule1D { points, weights };
    symmetrise(&mut rule);
    rule
}

/// Gauss–Jacobi rule with `n` points for the weight (1 − x)^α (1 + x)^β on [-1, 1]
/// (α, β > −1): exact for p(x)·(1 − x)^α (1 + x)^β with p of degree ≤ 2n − 1.
///
/// Accurate to a few ulps for n up to a few hundred; tested to n = 40.
///
/// # Panics
/// If α ≤ −1 or β ≤ −1.
pub fn gauss_jacobi(n: usize, alpha: f64, beta: f64) -> Rule1D {
    assert!(
        alpha > -1.0 && beta > -1.0,
        "Jacobi weight needs alpha, beta > -1 (got {alpha}, {beta})"
    );
    if n == 0 {
        return Rule1D {
            points: Vec::new(),
            weights: Vec::new(),
        };
    }
    let rec = JacobiRecurrence::new(n, alpha, beta);
    let mut jacobi_matrix = DMatrix::<f64>::zeros(n, n);
    for k in 0..n {
        jacobi_matrix[(k, k)] = rec.a[k];
        if k + 1 < n {
            jacobi_matrix[(k, k + 1)] = rec.b[k + 1];
            jacobi_matrix[(k + 1, k)] = rec.b[k + 1];
        }
    }
    let mut points: Vec<f64> = SymmetricEigen::new(jacobi_matrix)
        .eigenvalues
        .iter()
        .copied()
        .collect();
    points.sort_by(f64::total_cmp);
    let mut weights = Vec::with_capacity(n);
    for x in &mut points {
        // Newton on p̃ₙ; the eigenvalues are already within a few ulps, so a step larger
        // than 1e-8 can only mean a numerically flat p̃ₙ and is refused.
        for _ in 0..4 {
            let (p, dp, _) = rec.eval_top(*x);
            let dx = p / dp;
            if !dx.is_finite() || dx.abs() > 1e-8 {
                break;
            }
            *x = (*x - dx).clamp(-1.0, 1.0);
            if dx.abs() <= 1e-17 {
                break;
            }
        }
        let (_, _, christoffel) = rec.eval_top(*x);
        weights.push(1.0 / christoffel);
    }
    let mut rule = Rule1D { points, weights };
    if alpha == beta {
        symmetrise(&mut rule);
    }
    rule
}

/// Makes a rule that is symmetric in exact arithmetic symmetric in floating point.
fn symmetrise(rule: &mut Rule1D) {
    let n = rule.points.len();
    for i in 0..n / 2 {
        let j = n - 1 - i;
        let x = 0.5 * (rule.points[j] - rule.points[i]);
        let w = 0.5 * (rule.weights[i] + rule.weights[j]);
        rule.points[i] = -x;
        rule.points[j] = x;
        rule.weights[i] = w;
        rule.weights[j] = w;
    }
    if n % 2 == 1 {
        rule.points[n / 2] = 0.0;
    }
}

/// The Jacobi polynomial P⁽ᵅ·ᵝ⁾ₙ(x) in the classical normalisation
/// (Pₙ(1) = binom(n + α, n)), by the three-term recurrence.
pub fn jacobi(n: usize, alpha: f64, beta: f64, x: f64) -> f64 {
    let (a, b) = (alpha, beta);
    let mut p_prev = 1.0;
    if n == 0 {
        return p_prev;
    }
    let mut p = 0.5 * (a - b + (a + b + 2.0) * x);
    for k in 2..=n {
        let k = k as f64;
        let c = 2.0 * k + a + b;
        let a1 = 2.0 * k * (k + a + b) * (c - 2.0);
        let a2 = (c - 1.0) * (c * (c - 2.0) * x + a * a - b * b);
        let a3 = 2.0 * (k + a - 1.0) * (k + b - 1.0) * c;
        let next = (a2 * p - a3 * p_prev) / a1;
        p_prev = p;
        p = next;
    }
    p
}

/// d/dx P⁽ᵅ·ᵝ⁾ₙ(x) = (n + α + β + 1)/2 · P⁽ᵅ⁺¹·ᵝ⁺¹⁾ₙ₋₁(x).
pub fn jacobi_derivative(n: usize, alpha: f64, beta: f64, x: f64) -> f64 {
    if n == 0 {
        return 0.0;
    }
    0.5 * (n as f64 + alpha + beta + 1.0) * jacobi(n - 1, alpha + 1.0, beta + 1.0, x)
}

/// ∫₋₁¹ (1 − x)^α (1 + x)^β dx = 2^(α+β+1) B(α + 1, β + 1).
pub fn jacobi_weight_integral(alpha: f64, beta: f64) -> f64 {
    (alpha + beta + 1.0).exp2() * beta_function(alpha + 1.0, beta + 1.0)
}

/// Three-term recurrence of the Jacobi polynomials p̃ₖ that are orthonormal for the weight
/// (1 − x)^α (1 + x)^β on [-1, 1]:
/// x p̃ₖ = bₖ₊₁ p̃ₖ₊₁ + aₖ p̃ₖ + bₖ p̃ₖ₋₁, p̃₀ = 1/√μ₀.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JacobiRecurrence {
    /// aₖ, k = 0..n.
    pub(crate) a: Vec<f64>,
    /// bₖ, k = 0..=n (b₀ = 0 is unused).
    pub(crate) b: Vec<f64>,
    /// p̃₀ = 1/√μ₀.
    pub(crate) p0: f64,
}

impl JacobiRecurrence {
    /// Coefficients for the polynomials p̃₀ … p̃ₙ.
    pub(crate) fn new(n: usize, alpha: f64, beta: f64) -> Self {
        let (al, be) = (alpha, beta);
        let s = al + be;
        let mut a = Vec::with_capacity(n + 1);
        let mut b = Vec::with_capacity(n + 1);
        b.push(0.0);
        for k in 0..=n {
            let kf = k as f64;
            let c = 2.0 * kf + s;
            a.push(if k == 0 {
                (be - al) / (s + 2.0)
            } else {
                (be * be - al * al) / (c * (c + 2.0))
            });
            if k >= 1 {
                // k = 1 in the form with (α + β + 1) cancelled, valid for α + β = −1 too.
                let b2 = if k == 1 {
                    4.0 * (1.0 + al) * (1.0 + be) / ((2.0 + s) * (2.0 + s) * (3.0 + s))
                } else {
                    4.0 * kf * (kf + al) * (kf + be) * (kf + s) / (c * c * (c + 1.0) * (c - 1.0))
                };
                b.push(b2.sqrt());
            }
        }
        let p0 = 1.0 / jacobi_weight_integral(alpha, beta).sqrt();
        JacobiRecurrence { a, b, p0 }
    }

    /// Highest degree available.
    pub(crate) fn degree(&self) -> usize {
        self.b.len() - 1
    }

    /// (p̃ₙ(x), p̃′ₙ(x), Σₖ₌₀ⁿ⁻¹ p̃ₖ(x)²) with n = `self.degree()`.
    fn eval_top(&self, x: f64) -> (f64, f64, f64) {
        let n = self.degree();
        let (mut p_prev, mut dp_prev) = (0.0, 0.0);
        let (mut p, mut dp) = (self.p0, 0.0);
        let mut sum = 0.0;
        for k in 0..n {
            sum += p * p;
            let t = x - self.a[k];
            let next = (t * p - self.b[k] * p_prev) / self.b[k + 1];
            let dnext = (t * dp + p - self.b[k] * dp_prev) / self.b[k + 1];
            (p_prev, dp_prev, p, dp) = (p, dp, next, dnext);
        }
        (p, dp, sum)
    }

    /// Homogenised orthonormal polynomials Qₖ(s, w) = p̃ₖ((2s − w)/w) · wᵏ for k = 0..=n
    /// (n = `values.len() - 1` ≤ `self.degree()`), with ∂Qₖ/∂s and ∂Qₖ/∂w.
    ///
    /// Qₖ is a polynomial in (s, w), evaluated by the recurrence
    /// Qₖ₊₁ = ((2s − (1 + aₖ) w) Qₖ − bₖ w² Qₖ₋₁) / bₖ₊₁ with no division by w, so it is
    /// exact at w = 0 (the collapsed vertex of a simplex). With w = 1 it is p̃ₖ(2s − 1),
    /// the orthonormal polynomial mapped to [0, 1].
    pub(crate) fn eval_homogeneous(
        &self,
        s: f64,
        w: f64,
        values: &mut [f64],
        d_s: &mut [f64],
        d_w: &mut [f64],
    ) {
        let n = values.len();
        debug_assert!(n >= 1 && n <= self.degree() + 1);
        debug_assert!(d_s.len() >= n && d_w.len() >= n);
        values[0] = self.p0;
        d_s[0] = 0.0;
        d_w[0] = 0.0;
        let w2 = w * w;
        for k in 0..n - 1 {
            let t = 2.0 * s - (1.0 + self.a[k]) * w;
            let inv = 1.0 / self.b[k + 1];
            let (q, qs, qw) = (values[k], d_s[k], d_w[k]);
            let (qm, qms, qmw) = if k == 0 {
                (0.0, 0.0, 0.0)
            } else {
                (values[k - 1], d_s[k - 1], d_w[k - 1])
            };
            let bk = self.b[k];
            values[k + 1] = (t * q - bk * w2 * qm) * inv;
            d_s[k + 1] = (2.0 * q + t * qs - bk * w2 * qms) * inv;
            d_w[k + 1] = (-(1.0 + self.a[k]) * q + t * qw - bk * (2.0 * w * qm + w2 * qmw)) * inv;
        }
    }
}

/// The Beta function B(a, b) = Γ(a)Γ(b)/Γ(a + b) for a, b > 0, without overflow: both
/// arguments are first brought into (0, 2] by B(a + 1, b) = a/(a + b) · B(a, b).
fn beta_function(mut a: f64, mut b: f64) -> f64 {
    let mut factor = 1.0;
    while a > 2.0 {
        a -= 1.0;
        factor *= a / (a + b);
    }
    while b > 2.0 {
        b -= 1.0;
        factor *= b / (a + b);
    }
    factor * gamma(a) * gamma(b) / gamma(a + b)
}

/// Γ(x) for 0 < x ≤ ~170: exact products for integers and half-integers, Lanczos (g = 7,
/// 9 terms, relative error ≈ 1e-15) otherwise.
fn gamma(x: f64) -> f64 {
    debug_assert!(x > 0.0);
    if x.fract() == 0.0 || x.fract() == 0.5 {
        let (mut g, mut t) = if x.fract() == 0.0 {
            (1.0, 1.0)
        } else {
            (std::f64::consts::PI.sqrt(), 0.5)
        };
        while t < x {
            g *= t;
            t += 1.0;
        }
        return g;
    }
    if x < 0.5 {
        return std::f64::consts::PI / ((std::f64::consts::PI * x).sin() * gamma(1.0 - x));
    }
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let mut sum = C[0];
    for (i, c) in C.iter().enumerate().skip(1) {
        sum += c / (x + i as f64);
    }
    let t = x + G + 0.5;
    (2.0 * std::f64::consts::PI).sqrt() * t.powf(x + 0.5) * (-t).exp() * sum
}

#[cfg(test)]
#[path = "tests/gauss.rs"]
mod tests;
