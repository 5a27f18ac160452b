//! B-spline basis functions on a knot vector: knot span search and the values and
//! derivatives of the non-zero basis functions (Piegl & Tiller, *The NURBS Book*,
//! algorithms A2.1–A2.3), plus validation of knot vectors and weights.
//!
//! Conventions: degree `p`, control points `P_0 … P_n`, knots `U_0 … U_{n+p+1}`, parameter
//! domain `[U_p, U_{n+1}]`. Evaluation allocates nothing (scratch lives on the stack, hence
//! [`MAX_DEGREE`]).

use crate::NurbsError;

/// Highest supported degree.
pub const MAX_DEGREE: usize = 24;
/// `MAX_DEGREE + 1`: the length of the basis buffers.
pub const MAX_ORDER: usize = MAX_DEGREE + 1;

/// Checks a knot vector for `n_control` control points of degree `degree`: degree in
/// `1..=MAX_DEGREE`, at least `degree + 1` control points, `n_control + degree + 1` finite,
/// non-decreasing knots and a domain of positive length.
pub fn validate_knot_vector(
    degree: usize,
    knots: &[f64],
    n_control: usize,
) -> Result<(), NurbsError> {
    if degree == 0 || degree > MAX_DEGREE {
        return Err(NurbsError::Degree {
            degree,
            max: MAX_DEGREE,
        });
    }
    if n_control < degree + 1 {
        return Err(NurbsError::TooFewControlPoints {
            degree,
            found: n_control,
            needed: degree + 1,
        });
    }
    let expected = n_control + degree + 1;
    if knots.len() != expected {
        return Err(NurbsError::KnotCount {
            expected,
            found: knots.len(),
            control_points: n_control,
            degree,
        });
    }
    for (index, &value) in knots.iter().enumerate() {
        if !value.is_finite() {
            return Err(NurbsError::NonFiniteKnot { index, value });
        }
    }
    for index in 1..knots.len() {
        if knots[index] < knots[index - 1] {
            return Err(NurbsError::DecreasingKnots {
                index,
                previous: knots[index - 1],
                value: knots[index],
            });
        }
    }
    let (start, end) = (knots[degree], knots[n_control]);
    if start >= end {
        return Err(NurbsError::EmptyDomain { start, end });
    }
    Ok(())
}

/// Checks that there is one finite, strictly positive weight per control point.
pub fn validate_weights(weights: &[f64], n_control: usize) -> Result<(), NurbsError> {
    if weights.len() != n_control {
        return Err(NurbsError::WeightCount {
            expected: n_control,
            found: weights.len(),
        });
    }
    for (index, &value) in weights.iter().enumerate() {
        if !(value.is_finite() && value > 0.0) {
            return Err(NurbsError::NonPositiveWeight { index, value });
        }
    }
    Ok(())
}

/// Knot span index `i` with `U_i ≤ u < U_{i+1}` and `U_i < U_{i+1}` (A2.1), for a valid knot
/// vector of degree `degree`. Parameters outside the domain are clamped to its ends; at the end
/// knot `u = U_{n+1}` the last non-empty span is returned, so repeated knots never yield a
/// zero-length span.
pub fn find_span(degree: usize, knots: &[f64], u: f64) -> usize {
    let n = knots.len() - degree - 2;
    if u >= knots[n + 1] {
        let mut span = n;
        while span > degree && knots[span] >= knots[span + 1] {
            span -= 1;
        }
        return span;
    }
    if u <= knots[degree] {
        let mut span = degree;
        while span < n && knots[span + 1] <= knots[span] {
            span += 1;
        }
        return span;
    }
    let (mut low, mut high) = (degree, n + 1);
    let mut mid = (low + high) / 2;
    while u < knots[mid] || u >= knots[mid + 1] {
        if u < knots[mid] {
            high = mid;
        } else {
            low = mid;
        }
        mid = (low + high) / 2;
    }
    mid
}

/// The `degree + 1` non-zero basis functions `N_{span-p}(u) … N_{span}(u)` (A2.2), written to
/// `out[..=degree]`.
pub fn basis_functions(span: usize, u: f64, degree: usize, knots: &[f64], out: &mut [f64]) {
    let mut left = [0.0; MAX_ORDER];
    let mut right = [0.0; MAX_ORDER];
    out[0] = 1.0;
    for j in 1..=degree {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = out[r] / (right[r + 1] + left[j - r]);
            out[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        out[j] = saved;
    }
}

/// The non-zero basis functions and their derivatives up to order `n_derivs` (A2.3):
/// `ders[k][j]` is the k-th derivative of `N_{span-p+j}` at `u`. Derivatives above the degree
/// are zero. `ders` needs at least `n_derivs + 1` rows.
pub fn basis_function_derivatives(
    span: usize,
    u: f64,
    degree: usize,
    n_derivs: usize,
    knots: &[f64],
    ders: &mut [[f64; MAX_ORDER]],
) {
    // The table is (p+1)²: small work buffers for the usual low degrees, because zeroing
    // the MAX_ORDER² table dominated the cost of a surface evaluation.
    basis_function_derivatives_into(span, u, degree, n_derivs, knots, ders)
}

/// Buffer length for degrees below it (cubic and quintic NURBS, conics).
pub(crate) const SMALL_ORDER: usize = 8;

/// [`basis_function_derivatives`] into rows of length `M` (> degree): surfaces of low degree
/// keep their tables on the stack without zeroing [`MAX_ORDER`]-long rows.
pub(crate) fn basis_function_derivatives_into<const M: usize>(
    span: usize,
    u: f64,
    degree: usize,
    n_derivs: usize,
    knots: &[f64],
    ders: &mut [[f64; M]],
) {
    if degree < SMALL_ORDER {
        derivatives_table::<SMALL_ORDER, M>(span, u, degree, n_derivs, knots, ders)
    } else {
        derivatives_table::<MAX_ORDER, M>(span, u, degree, n_derivs, knots, ders)
    }
}

/// A2.3 with work buffers of length `N` (> degree), rows of `ders` of length `M` (> degree).
fn derivatives_table<const N: usize, const M: usize>(
    span: usize,
    u: f64,
    degree: usize,
    n_derivs: usize,
    knots: &[f64],
    ders: &mut [[f64; M]],
) {
    let p = degree;
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    let mut ndu = [[0.0; N]; N];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // Lower triangle: knot differences; upper triangle: basis functions.
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    for row in ders.iter_mut().take(n_derivs + 1) {
        row[..=p].iter_mut().for_each(|d| *d = 0.0);
    }
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let n = n_derivs.min(p);
    let mut a = [[0.0; N]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0, 1);
        a[0][0] = 1.0;
        for k in 1..=n {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                let rk = rk as usize;
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
                d = a[s2][0] * ndu[rk][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if r as isize - 1 <= pk as isize {
                k - 1
            } else {
                p - r
            };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for k in 1..=n {
        for j in 0..=p {
            ders[k][j] *= factor;
        }
        factor *= (p - k) as f64;
    }
}

#[cfg(test)]
#[path = "tests/basis.rs"]
mod tests;
