//! Arc length of NURBS curves by adaptive composite Gauss–Legendre quadrature on each knot
//! span (the integrand |C'(u)| is smooth inside a span), to ≤ 1e-13 relative error, and its
//! inverse: the parameter at a given fraction of the length between two parameters (the
//! paper's Eq. (4), used to place edge nodes).

use crate::vec3::norm;
use crate::NurbsCurve;
use hocurve_nodes::{gauss_legendre, Rule1D};
use std::sync::OnceLock;

/// Relative tolerance of the adaptive quadrature and of the inverse.
const RELATIVE_TOLERANCE: f64 = 1e-14;
/// Maximal bisection depth of the adaptive quadrature per knot span.
const MAX_DEPTH: usize = 40;

fn rule() -> &'static Rule1D {
    static RULE: OnceLock<Rule1D> = OnceLock::new();
    RULE.get_or_init(|| gauss_legendre(10))
}

fn gauss(curve: &NurbsCurve, a: f64, b: f64) -> f64 {
    let rule = rule();
    let (half, mid) = (0.5 * (b - a), 0.5 * (a + b));
    let mut sum = 0.0;
    for (&x, &w) in rule.points.iter().zip(&rule.weights) {
        sum += w * norm(curve.derivatives(mid + half * x, 1)[1]);
    }
    sum * half
}

fn adaptive(curve: &NurbsCurve, a: f64, b: f64, whole: f64, tol: f64, depth: usize) -> f64 {
    let m = 0.5 * (a + b);
    let (left, right) = (gauss(curve, a, m), gauss(curve, m, b));
    if (left + right - whole).abs() <= tol || depth == 0 || m <= a || m >= b {
        left + right
    } else {
        adaptive(curve, a, m, left, tol, depth - 1) + adaptive(curve, m, b, right, tol, depth - 1)
    }
}

/// Length of the curve between the parameters `u0` and `u1` (in either order; parameters are
/// clamped to the domain), ≥ 0.
pub fn arc_length(curve: &NurbsCurve, u0: f64, u1: f64) -> f64 {
    let (start, end) = curve.domain();
    let lo = u0.min(u1).clamp(start, end);
    let hi = u0.max(u1).clamp(start, end);
    if hi <= lo {
        return 0.0;
    }
    let mut cuts = vec![lo];
    cuts.extend(
        curve
            .breakpoints()
            .into_iter()
            .filter(|&k| k > lo && k < hi),
    );
    cuts.push(hi);
    let pieces: Vec<f64> = cuts.windows(2).map(|w| gauss(curve, w[0], w[1])).collect();
    let estimate: f64 = pieces.iter().sum();
    let tol = RELATIVE_TOLERANCE * estimate;
    cuts.windows(2)
        .zip(&pieces)
        .map(|(w, &whole)| adaptive(curve, w[0], w[1], whole, tol, MAX_DEPTH))
        .sum()
}

/// The parameter `u` between `u0` and `u1` whose arc length from `u0` is `fraction` of the
/// length from `u0` to `u1` (`fraction` clamped to [0, 1]); `u1 < u0` is allowed. Safeguarded
/// Newton (the derivative of the length is |C'(u)|) inside a shrinking bisection bracket.
pub fn parameter_at_length_fraction(curve: &NurbsCurve, u0: f64, u1: f64, fraction: f64) -> f64 {
    let fraction = fraction.clamp(0.0, 1.0);
    if fraction == 0.0 || u0 == u1 {
        return u0;
    }
    if fraction == 1.0 {
        return u1;
    }
    let total = arc_length(curve, u0, u1);
    if total <= 0.0 {
        return u0 + fraction * (u1 - u0);
    }
    let target = fraction * total;
    let direction = (u1 - u0).signum();
    // Bracket [behind, ahead] in the direction of travel: length(behind) < target < length(ahead).
    let (mut behind, mut ahead) = (u0, u1);
    let mut u = u0 + fraction * (u1 - u0);
    for _ in 0..200 {
        let residual = arc_length(curve, u0, u) - target;
        if residual.abs() <= 1e-15 * total {
            break;
        }
        if residual < 0.0 {
            behind = u;
        } else {
            ahead = u;
        }
        let speed = norm(curve.derivatives(u, 1)[1]);
        let mut next = u - direction * residual / speed;
        let inside = (next - behind) * direction > 0.0 && (ahead - next) * direction > 0.0;
        if !(speed > 0.0 && inside && next.is_finite()) {
            next = 0.5 * (behind + ahead);
        }
        if next == u || (ahead - behind).abs() <= 4.0 * f64::EPSILON * u.abs().max(1.0) {
            u = next;
            break;
        }
        u = next;
    }
    u
}

#[cfg(test)]
#[path = "tests/arc_length.rs"]
mod tests;
