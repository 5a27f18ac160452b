//! Rational B-spline (NURBS) surfaces: evaluation and partial derivatives up to second order
//! (Piegl & Tiller A3.6/A4.4). Degenerate edges (poles, where a whole row of control points
//! coincides) are allowed: there ∂S/∂u or ∂S/∂v vanishes, the point is still well defined.

use crate::basis::{
    basis_function_derivatives_into, basis_functions, find_span, validate_knot_vector,
    validate_weights, MAX_ORDER, SMALL_ORDER,
};
use crate::vec3;
use crate::NurbsError;

/// A NURBS surface `S(u, v)` on `[U_p, U_{n_u}] × [V_q, V_{n_v}]`.
///
/// Control points and weights are stored row-major: the point `P_{i,j}` (i along u, j along v)
/// is `control_points[i * n_v + j]`.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface {
    /// Degree in u.
    pub degree_u: usize,
    /// Degree in v.
    pub degree_v: usize,
    /// Knots in u, `n_u + degree_u + 1` of them.
    pub knots_u: Vec<f64>,
    /// Knots in v, `n_v + degree_v + 1` of them.
    pub knots_v: Vec<f64>,
    /// `n_u × n_v` control points, row-major (index `i * n_v + j`).
    pub control_points: Vec<[f64; 3]>,
    /// One weight `> 0` per control point, same order.
    pub weights: Vec<f64>,
}

/// What point inversion and charts need to know of a surface's shape as a whole, computed
/// once ([`NurbsSurface::properties`]): each is a pass over the control net, which costs more
/// than a Newton step on a large B-spline surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceProperties {
    /// [`NurbsSurface::is_closed_u`] and [`NurbsSurface::is_closed_v`].
    pub closed: [bool; 2],
    /// [`NurbsSurface::degenerate_edges`].
    pub degenerate_edges: [bool; 4],
    /// [`NurbsSurface::size`].
    pub size: f64,
}

/// A surface point and its partial derivatives up to second order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceDerivatives {
    /// `S(u, v)`.
    pub point: [f64; 3],
    /// `∂S/∂u`.
    pub du: [f64; 3],
    /// `∂S/∂v`.
    pub dv: [f64; 3],
    /// `∂²S/∂u²`.
    pub duu: [f64; 3],
    /// `∂²S/∂u∂v`.
    pub duv: [f64; 3],
    /// `∂²S/∂v²`.
    pub dvv: [f64; 3],
}

impl NurbsSurface {
    /// A validated NURBS surface.
    pub fn new(
        degree_u: usize,
        degree_v: usize,
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        control_points: Vec<[f64; 3]>,
        weights: Vec<f64>,
    ) -> Result<Self, NurbsError> {
        let surface = Self {
            degree_u,
            degree_v,
            knots_u,
            knots_v,
            control_points,
            weights,
        };
        surface.validate()?;
        Ok(surface)
    }

    /// Number of control points along u (`n_u`).
    pub fn n_u(&self) -> usize {
        self.knots_u.len().saturating_sub(self.degree_u + 1)
    }

    /// Number of control points along v (`n_v`).
    pub fn n_v(&self) -> usize {
        self.knots_v.len().saturating_sub(self.degree_v + 1)
    }

    /// Checks degrees, knot vectors (their lengths fix `n_u`, `n_v`), net size and weights.
    pub fn validate(&self) -> Result<(), NurbsError> {
        let (n_u, n_v) = (self.n_u(), self.n_v());
        if self.control_points.len() != n_u * n_v {
            return Err(NurbsError::ControlNetSize {
                n_u,
                n_v,
                found: self.control_points.len(),
            });
        }
        validate_knot_vector(self.degree_u, &self.knots_u, n_u)?;
        validate_knot_vector(self.degree_v, &self.knots_v, n_v)?;
        validate_weights(&self.weights, self.control_points.len())?;
        for (index, p) in self.control_points.iter().enumerate() {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(NurbsError::NonFiniteControlPoint { index });
            }
        }
        Ok(())
    }

    /// Parameter domain `((u_start, u_end), (v_start, v_end))`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        (
            (self.knots_u[self.degree_u], self.knots_u[self.n_u()]),
            (self.knots_v[self.degree_v], self.knots_v[self.n_v()]),
        )
    }

    /// Diagonal of the control net's bounding box: the model size used for tolerances.
    pub fn size(&self) -> f64 {
        vec3::bounding_box_diagonal(&self.control_points)
    }

    /// The plane the surface lies in — a point of it and its unit normal — when every
    /// control point is on it to 1e-12 of the surface's size (a NURBS surface lies in the
    /// span of its control points, whatever the weights); None for a surface that bends.
    pub fn plane(&self) -> Option<([f64; 3], [f64; 3])> {
        let points = &self.control_points;
        let origin = *points.first()?;
        let size = self.size();
        // The point farthest from the first, then the one farthest off that line.
        let far = points
            .iter()
            .map(|&p| vec3::sub(p, origin))
            .max_by(|a, b| vec3::norm(*a).total_cmp(&vec3::norm(*b)))?;
        let normal = points
            .iter()
            .map(|&p| vec3::cross(far, vec3::sub(p, origin)))
            .max_by(|a, b| vec3::norm(*a).total_cmp(&vec3::norm(*b)))?;
        let length = vec3::norm(normal);
        if !(length > 0.0 && size > 0.0) {
            return None;
        }
        let normal = vec3::scale(normal, 1.0 / length);
        points
            .iter()
            .all(|&p| vec3::dot(vec3::sub(p, origin), normal).abs() <= 1e-12 * size)
            .then_some((origin, normal))
    }

    /// Closedness, poles and size, for reuse across many evaluations.
    pub fn properties(&self) -> SurfaceProperties {
        SurfaceProperties {
            closed: [self.is_closed_u(), self.is_closed_v()],
            degenerate_edges: self.degenerate_edges(),
            size: self.size(),
        }
    }

    /// Control point `P_{i,j}`.
    pub fn control_point(&self, i: usize, j: usize) -> [f64; 3] {
        self.control_points[i * self.n_v() + j]
    }

    /// The point `S(u, v)`.
    pub fn point(&self, u: f64, v: f64) -> [f64; 3] {
        let (p, q) = (self.degree_u, self.degree_v);
        let n_v = self.n_v();
        let span_u = find_span(p, &self.knots_u, u);
        let span_v = find_span(q, &self.knots_v, v);
        let mut nu = [0.0; MAX_ORDER];
        let mut nv = [0.0; MAX_ORDER];
        basis_functions(span_u, u, p, &self.knots_u, &mut nu);
        basis_functions(span_v, v, q, &self.knots_v, &mut nv);
        let mut sw = [0.0; 4];
        for k in 0..=p {
            let row = (span_u - p + k) * n_v;
            for l in 0..=q {
                let idx = row + span_v - q + l;
                let w = nu[k] * nv[l] * self.weights[idx];
                for d in 0..3 {
                    sw[d] += w * self.control_points[idx][d];
                }
                sw[3] += w;
            }
        }
        [sw[0] / sw[3], sw[1] / sw[3], sw[2] / sw[3]]
    }

    /// The point and all partial derivatives up to second order (A3.6 on the homogeneous
    /// net, then the rational quotient rule A4.4).
    pub fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        // Conics and cubics (the usual CAD degrees) on small stack tables: zeroing
        // MAX_ORDER-long rows cost as much as the evaluation itself.
        if self.degree_u < SMALL_ORDER && self.degree_v < SMALL_ORDER {
            self.derivatives_with::<SMALL_ORDER>(u, v)
        } else {
            self.derivatives_with::<MAX_ORDER>(u, v)
        }
    }

    /// [`Self::derivatives`] with basis tables of row length `M` (> both degrees).
    fn derivatives_with<const M: usize>(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let (p, q) = (self.degree_u, self.degree_v);
        let n_v = self.n_v();
        let span_u = find_span(p, &self.knots_u, u);
        let span_v = find_span(q, &self.knots_v, v);
        let mut du = [[0.0; M]; 3];
        let mut dv = [[0.0; M]; 3];
        basis_function_derivatives_into(span_u, u, p, 2, &self.knots_u, &mut du);
        basis_function_derivatives_into(span_v, v, q, 2, &self.knots_v, &mut dv);
        // a[k][l], w[k][l]: homogeneous derivatives ∂^{k+l}/∂u^k ∂v^l, k + l ≤ 2.
        let mut a = [[[0.0; 3]; 3]; 3];
        let mut w = [[0.0; 3]; 3];
        for r in 0..=p {
            let row = (span_u - p + r) * n_v;
            for s in 0..=q {
                let idx = row + span_v - q + s;
                let wi = self.weights[idx];
                let x = self.control_points[idx];
                for k in 0..=2 {
                    for l in 0..=2 - k {
                        let c = du[k][r] * dv[l][s] * wi;
                        for d in 0..3 {
                            a[k][l][d] += c * x[d];
                        }
                        w[k][l] += c;
                    }
                }
            }
        }
        const BINOMIAL: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 2.0, 1.0]];
        let mut skl = [[[0.0; 3]; 3]; 3];
        for k in 0..=2 {
            for l in 0..=2 - k {
                let mut v = a[k][l];
                for j in 1..=l {
                    for d in 0..3 {
                        v[d] -= BINOMIAL[l][j] * w[0][j] * skl[k][l - j][d];
                    }
                }
                for i in 1..=k {
                    for d in 0..3 {
                        v[d] -= BINOMIAL[k][i] * w[i][0] * skl[k - i][l][d];
                    }
                    for j in 1..=l {
                        for d in 0..3 {
                            v[d] -=
                                BINOMIAL[k][i] * BINOMIAL[l][j] * w[i][j] * skl[k - i][l - j][d];
                        }
                    }
                }
                skl[k][l] = vec3::scale(v, 1.0 / w[0][0]);
            }
        }
        SurfaceDerivatives {
            point: skl[0][0],
            du: skl[1][0],
            dv: skl[0][1],
            duu: skl[2][0],
            duv: skl[1][1],
            dvv: skl[0][2],
        }
    }

    /// Whether the first and last control columns in u coincide (to 1e-12 of the size), so that
    /// `S(u_start, v) = S(u_end, v)`: the surface is closed across a seam in u.
    pub fn is_closed_u(&self) -> bool {
        let (n_u, n_v) = (self.n_u(), self.n_v());
        // Relative 1e-8: CAD files carry ~10 significant digits (OpenCASCADE's IGES writes
        // 10), so the control points of a pole agree only to about 1e-10 of the model.
        let tol = 1e-8 * self.size().max(f64::MIN_POSITIVE);
        (0..n_v).all(|j| {
            vec3::distance(self.control_point(0, j), self.control_point(n_u - 1, j)) <= tol
                && (self.weights[j] - self.weights[(n_u - 1) * n_v + j]).abs() <= 1e-12
        })
    }

    /// Whether the first and last control rows in v coincide: closed across a seam in v.
    pub fn is_closed_v(&self) -> bool {
        let (n_u, n_v) = (self.n_u(), self.n_v());
        // Relative 1e-8: CAD files carry ~10 significant digits (OpenCASCADE's IGES writes
        // 10), so the control points of a pole agree only to about 1e-10 of the model.
        let tol = 1e-8 * self.size().max(f64::MIN_POSITIVE);
        (0..n_u).all(|i| {
            vec3::distance(self.control_point(i, 0), self.control_point(i, n_v - 1)) <= tol
                && (self.weights[i * n_v] - self.weights[i * n_v + n_v - 1]).abs() <= 1e-12
        })
    }

    /// Degenerate edges `[v = v_start, v = v_end, u = u_start, u = u_end]`: true where all
    /// control points of that boundary row coincide (a pole).
    pub fn degenerate_edges(&self) -> [bool; 4] {
        let (n_u, n_v) = (self.n_u(), self.n_v());
        // Relative 1e-8: CAD files carry ~10 significant digits (OpenCASCADE's IGES writes
        // 10), so the control points of a pole agree only to about 1e-10 of the model.
        let tol = 1e-8 * self.size().max(f64::MIN_POSITIVE);
        let collapsed = |pts: Vec<[f64; 3]>| pts.iter().all(|&p| vec3::distance(p, pts[0]) <= tol);
        [
            collapsed((0..n_u).map(|i| self.control_point(i, 0)).collect()),
            collapsed((0..n_u).map(|i| self.control_point(i, n_v - 1)).collect()),
            collapsed((0..n_v).map(|j| self.control_point(0, j)).collect()),
            collapsed((0..n_v).map(|j| self.control_point(n_u - 1, j)).collect()),
        ]
    }
}

#[cfg(test)]
#[path = "tests/surface.rs"]
mod tests;
