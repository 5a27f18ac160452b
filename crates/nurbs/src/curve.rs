//! Rational B-spline (NURBS) curves in 3D (2D curves have z = 0): evaluation, first and
//! second derivatives (Piegl & Tiller A4.1/A4.2), knot insertion (A5.1) and splitting.

use crate::basis::{
    basis_function_derivatives, basis_functions, find_span, validate_knot_vector, validate_weights,
    MAX_ORDER,
};
use crate::vec3;
use crate::NurbsError;

/// A NURBS curve `C(u) = Σ N_{i,p}(u) w_i P_i / Σ N_{i,p}(u) w_i` on `[U_p, U_{n+1}]`.
///
/// The fields are public for readers (IGES, JSON); [`NurbsCurve::new`] validates them, and
/// code that builds a curve field by field should call [`NurbsCurve::validate`].
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsCurve {
    /// Polynomial degree `p ≥ 1`.
    pub degree: usize,
    /// Non-decreasing knots, `control_points.len() + degree + 1` of them.
    pub knots: Vec<f64>,
    /// Control points `P_i` (z = 0 for planar curves).
    pub control_points: Vec<[f64; 3]>,
    /// Weights `w_i > 0`, one per control point.
    pub weights: Vec<f64>,
}

impl NurbsCurve {
    /// A validated NURBS curve.
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        control_points: Vec<[f64; 3]>,
        weights: Vec<f64>,
    ) -> Result<Self, NurbsError> {
        let curve = Self {
            degree,
            knots,
            control_points,
            weights,
        };
        curve.validate()?;
        Ok(curve)
    }

    /// A validated polynomial B-spline curve (all weights 1).
    pub fn non_rational(
        degree: usize,
        knots: Vec<f64>,
        control_points: Vec<[f64; 3]>,
    ) -> Result<Self, NurbsError> {
        let weights = vec![1.0; control_points.len()];
        Self::new(degree, knots, control_points, weights)
    }

    /// Checks degree, knot vector, weights and control points.
    pub fn validate(&self) -> Result<(), NurbsError> {
        validate_knot_vector(self.degree, &self.knots, self.control_points.len())?;
        validate_weights(&self.weights, self.control_points.len())?;
        for (index, p) in self.control_points.iter().enumerate() {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(NurbsError::NonFiniteControlPoint { index });
            }
        }
        Ok(())
    }

    /// Parameter domain `(U_p, U_{n+1})`.
    pub fn domain(&self) -> (f64, f64) {
        (
            self.knots[self.degree],
            self.knots[self.control_points.len()],
        )
    }

    /// Diagonal of the control polygon's bounding box: the model size used for tolerances.
    pub fn size(&self) -> f64 {
        vec3::bounding_box_diagonal(&self.control_points)
    }

    /// Whether the curve ends where it starts (to 1e-12 of its size).
    pub fn is_closed(&self) -> bool {
        let (a, b) = self.domain();
        vec3::distance(self.point(a), self.point(b)) <= 1e-12 * self.size().max(f64::MIN_POSITIVE)
    }

    /// The point `C(u)`; `u` outside the domain is evaluated on the end span (extrapolated).
    pub fn point(&self, u: f64) -> [f64; 3] {
        let p = self.degree;
        let span = find_span(p, &self.knots, u);
        let mut n = [0.0; MAX_ORDER];
        basis_functions(span, u, p, &self.knots, &mut n);
        let mut cw = [0.0; 4];
        for j in 0..=p {
            let i = span - p + j;
            let w = n[j] * self.weights[i];
            for d in 0..3 {
                cw[d] += w * self.control_points[i][d];
            }
            cw[3] += w;
        }
        [cw[0] / cw[3], cw[1] / cw[3], cw[2] / cw[3]]
    }

    /// `[C(u), C'(u), C''(u)]`, computed up to order `order.min(2)`; higher entries are zero.
    /// Rational derivatives by the quotient rule (A4.2).
    pub fn derivatives(&self, u: f64, order: usize) -> [[f64; 3]; 3] {
        let order = order.min(2);
        let p = self.degree;
        let span = find_span(p, &self.knots, u);
        let mut ders = [[0.0; MAX_ORDER]; 3];
        basis_function_derivatives(span, u, p, order, &self.knots, &mut ders);
        // Homogeneous derivatives A^(k) = Σ N^(k) w P and w^(k) = Σ N^(k) w.
        let mut a = [[0.0; 3]; 3];
        let mut w = [0.0; 3];
        for k in 0..=order {
            for j in 0..=p {
                let i = span - p + j;
                let nw = ders[k][j] * self.weights[i];
                for d in 0..3 {
                    a[k][d] += nw * self.control_points[i][d];
                }
                w[k] += nw;
            }
        }
        let mut c = [[0.0; 3]; 3];
        for d in 0..3 {
            c[0][d] = a[0][d] / w[0];
            if order >= 1 {
                c[1][d] = (a[1][d] - w[1] * c[0][d]) / w[0];
            }
            if order >= 2 {
                c[2][d] = (a[2][d] - 2.0 * w[1] * c[1][d] - w[2] * c[0][d]) / w[0];
            }
        }
        c
    }

    /// Multiplicity of the knot value `u` (exact comparison).
    pub fn knot_multiplicity(&self, u: f64) -> usize {
        self.knots.iter().filter(|&&k| k == u).count()
    }

    /// Distinct knot values inside the domain, including both ends, ascending: the breaks
    /// between polynomial pieces.
    pub fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut out: Vec<f64> = vec![a];
        for &k in &self.knots {
            if k > *out.last().unwrap_or(&a) && k < b {
                out.push(k);
            }
        }
        out.push(b);
        out
    }

    /// Interior knots of multiplicity ≥ degree: the parameters where the curve may have a
    /// corner (it is only C⁰ there).
    pub fn c0_parameters(&self) -> Vec<f64> {
        let bp = self.breakpoints();
        bp[1..bp.len() - 1]
            .iter()
            .copied()
            .filter(|&u| self.knot_multiplicity(u) >= self.degree)
            .collect()
    }

    /// The same curve with the knot `u` inserted `times` more times (A5.1). The multiplicity
    /// after insertion may not exceed the degree; `u` must lie strictly inside the domain.
    pub fn insert_knot(&self, u: f64, times: usize) -> Result<NurbsCurve, NurbsError> {
        let (start, end) = self.domain();
        if !(u > start && u < end) {
            return Err(NurbsError::ParameterOutOfDomain {
                param: u,
                start,
                end,
            });
        }
        let p = self.degree;
        let s = self.knot_multiplicity(u);
        let r = times.min(p.saturating_sub(s));
        if r == 0 {
            return Ok(self.clone());
        }
        let np = self.control_points.len() - 1;
        let mp = np + p + 1;
        let k = find_span(p, &self.knots, u);
        let pw: Vec<[f64; 4]> = self
            .control_points
            .iter()
            .zip(&self.weights)
            .map(|(x, &w)| [x[0] * w, x[1] * w, x[2] * w, w])
            .collect();
        let uk = &self.knots;
        let mut knots = Vec::with_capacity(mp + r + 1);
        knots.extend_from_slice(&uk[..=k]);
        knots.extend(std::iter::repeat_n(u, r));
        knots.extend_from_slice(&uk[k + 1..]);
        let mut qw = vec![[0.0; 4]; np + r + 1];
        qw[..=k - p].copy_from_slice(&pw[..=k - p]);
        qw[k - s + r..=np + r].copy_from_slice(&pw[k - s..=np]);
        let mut rw: Vec<[f64; 4]> = (0..=p - s).map(|i| pw[k - p + i]).collect();
        let mut l = k - p;
        for j in 1..=r {
            l = k - p + j;
            for i in 0..=p - j - s {
                let alpha = (u - uk[l + i]) / (uk[i + k + 1] - uk[l + i]);
                for d in 0..4 {
                    rw[i][d] = alpha * rw[i + 1][d] + (1.0 - alpha) * rw[i][d];
                }
            }
            qw[l] = rw[0];
            qw[k + r - j - s] = rw[p - j - s];
        }
        if l + 1 < k - s {
            qw[l + 1..k - s].copy_from_slice(&rw[1..k - s - l]);
        }
        let weights: Vec<f64> = qw.iter().map(|q| q[3]).collect();
        let control_points = qw
            .iter()
            .map(|q| [q[0] / q[3], q[1] / q[3], q[2] / q[3]])
            .collect();
        Ok(NurbsCurve {
            degree: p,
            knots,
            control_points,
            weights,
        })
    }

    /// Splits the curve at the interior parameter `u` into `[a, u]` and `[u, b]`, each keeping
    /// its original parametrisation.
    pub fn split_at(&self, u: f64) -> Result<(NurbsCurve, NurbsCurve), NurbsError> {
        let p = self.degree;
        let full = self.insert_knot(u, p)?;
        // Last index of the knot u (multiplicity p now): the point at u is P_{k-p}.
        let k = full.knots.iter().rposition(|&x| x == u).unwrap_or(p);
        let left = NurbsCurve {
            degree: p,
            knots: full.knots[..=k].iter().copied().chain([u]).collect(),
            control_points: full.control_points[..=k - p].to_vec(),
            weights: full.weights[..=k - p].to_vec(),
        };
        let right = NurbsCurve {
            degree: p,
            knots: std::iter::once(u)
                .chain(full.knots[k - p + 1..].iter().copied())
                .collect(),
            control_points: full.control_points[k - p..].to_vec(),
            weights: full.weights[k - p..].to_vec(),
        };
        Ok((left, right))
    }
}

#[cfg(test)]
#[path = "tests/curve.rs"]
mod tests;
