//! NACA 4-digit airfoils: the closed-form section (thickness applied perpendicular to the
//! camber line) and one closed interpolating cubic B-spline of its contour, the geometry of
//! the paper's 2D example (NACA0012, Sect. 5).
//!
//! With the chord fraction ξ = x / c, maximum camber m, its position p and thickness t
//! (digits "MPTT": m = M/100, p = P/10, t = TT/100):
//!
//! - half thickness `y_t = 5t (0.2969 √ξ − 0.1260 ξ − 0.3516 ξ² + 0.2843 ξ³ − a₄ ξ⁴)` with
//!   a₄ = 0.1015 (standard, blunt trailing edge) or 0.1036 (closed trailing edge);
//! - camber `y_c = m/p² (2pξ − ξ²)` for ξ < p and `m/(1−p)² (1 − 2p + 2pξ − ξ²)` for ξ ≥ p;
//! - surfaces `(ξ ∓ y_t sin θ, y_c ± y_t cos θ)` (upper/lower), θ = atan(dy_c/dξ), all times c.
//!
//! The airfoil's leading edge is at the origin and its chord along +x.
//!
//! **Parametrisation.** The contour is parametrised by the angle s ∈ [−π, π] of cosine
//! spacing, ξ = (1 − cos s)/2, with s < 0 on the lower and s > 0 on the upper surface. Then
//! √ξ = sin(|s|/2), so the leading edge's square root disappears and each surface is an
//! analytic function of s; uniform steps in s are the classic cosine clustering toward both
//! edges. The spline parameter is `u = (s + π) / (2π)`: the curve runs from the trailing edge
//! (u = 0) along the lower surface to the leading edge (u = ½) and back along the upper
//! surface to the trailing edge (u = 1), i.e. clockwise, with the airfoil on its right
//! (a flow domain outside the airfoil is on its left).
//!
//! **Spline.** Between break points (trailing edge, leading edge, and for cambered airfoils
//! x = p·c on each side, where the camber's second derivative jumps and the perpendicular
//! thickness leaves a slope discontinuity of order 10⁻⁴ rad) each smooth piece is interpolated
//! by a clamped cubic with knots at the data parameters and the exact end derivatives dC/ds
//! (complete cubic spline interpolation, error O(h⁴) in the parametric distance). Pieces meet
//! at C⁰ knots (multiplicity 3), except at the leading edge where dC/ds is continuous and one
//! knot is removed (multiplicity 2, C¹ in u: the contour is curvature-continuous there, but
//! its s-parametrisation has a jump in d²C/ds²). The ends are clamped at the trailing edge,
//! which is therefore a C⁰ corner (the only one of a symmetric closed-trailing-edge airfoil).
//! Measured distance from the closed form (NACA0012, chord 1): 5.4·10⁻¹⁰ with 128 and
//! 3.4·10⁻¹¹ with [`DEFAULT_INTERVALS_PER_SIDE`] = 256 intervals per side (fourth order);
//! the arc length agrees with the closed form's to 1.3·10⁻¹¹ relative. The speed |C'(u)|
//! vanishes at the trailing edge, as dx/ds of cosine spacing does.
//!
//! **Blunt trailing edge.** With `closed_trailing_edge = false` the two surfaces end 2·y_t(1)
//! apart (0.252 % of the chord for NACA0012); the curve is closed by the straight base from the
//! upper to the lower trailing-edge point, a linear cubic piece on u ∈ [1, 1 + δ] (δ = base
//! length / polyline perimeter, so the speed matches the airfoil's average) joined by C⁰ knots.
//! Either way the result is one closed curve.

use crate::basis::{basis_functions, find_span};
use crate::{NurbsCurve, NurbsError};
use std::f64::consts::PI;

/// Number of spline intervals per surface (lower, upper) used by [`Naca4::curve`].
pub const DEFAULT_INTERVALS_PER_SIDE: usize = 256;

/// Thickness coefficients of √ξ, ξ, ξ², ξ³ (the ξ⁴ one depends on the trailing edge).
const THICKNESS_COEFFICIENTS: [f64; 4] = [0.2969, -0.1260, -0.3516, 0.2843];
/// ξ⁴ coefficient of the standard (blunt trailing edge) section.
const QUARTIC_OPEN: f64 = -0.1015;
/// ξ⁴ coefficient that closes the trailing edge (the coefficients then sum to zero).
const QUARTIC_CLOSED: f64 = -0.1036;

/// A NACA 4-digit airfoil section. Fields are fractions of the chord (m, p, t) and the chord
/// length; [`Naca4::from_digits`] builds and checks one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Naca4 {
    /// Maximum camber m (first digit / 100).
    pub max_camber: f64,
    /// Chordwise position p of the maximum camber (second digit / 10).
    pub camber_position: f64,
    /// Maximum thickness t (last two digits / 100).
    pub max_thickness: f64,
    /// Chord length c; the leading edge is at the origin, the chord along +x.
    pub chord: f64,
    /// Use −0.1036 ξ⁴ (zero thickness at the trailing edge) instead of −0.1015 ξ⁴.
    pub closed_trailing_edge: bool,
}

/// A point of the contour and its derivative with respect to the angle s.
struct ContourPoint {
    point: [f64; 2],
    tangent: [f64; 2],
}

/// Camber line at ξ: height, slope and (piecewise constant) second derivative.
struct Camber {
    height: f64,
    slope: f64,
    curvature: f64,
}

impl Naca4 {
    /// The airfoil "MPTT" (e.g. `"0012"`, `"2412"`) with the given chord. Rejects strings that
    /// are not exactly four ASCII digits, zero thickness, and camber without a position
    /// (M > 0 with P = 0).
    pub fn from_digits(
        digits: &str,
        chord: f64,
        closed_trailing_edge: bool,
    ) -> Result<Self, NurbsError> {
        let bytes = digits.as_bytes();
        if bytes.len() != 4 || !bytes.iter().all(u8::is_ascii_digit) {
            return Err(invalid(format!(
                "digits \"{digits}\" must be exactly four decimal digits, e.g. \"0012\""
            )));
        }
        let digit = |i: usize| f64::from(bytes[i] - b'0');
        let airfoil = Self {
            max_camber: digit(0) / 100.0,
            camber_position: digit(1) / 10.0,
            max_thickness: (10.0 * digit(2) + digit(3)) / 100.0,
            chord,
            closed_trailing_edge,
        };
        airfoil.validate()?;
        Ok(airfoil)
    }

    /// Checks 0 < t, 0 ≤ m, 0 < p < 1 when m > 0, and a finite positive chord.
    pub fn validate(&self) -> Result<(), NurbsError> {
        let (m, p, t) = (self.max_camber, self.camber_position, self.max_thickness);
        if !(self.chord.is_finite() && self.chord > 0.0) {
            return Err(invalid(format!(
                "chord must be finite and > 0, got {}",
                self.chord
            )));
        }
        if !(t.is_finite() && t > 0.0 && t < 1.0) {
            return Err(invalid(format!(
                "thickness must be in (0, 1) of the chord, got {t}"
            )));
        }
        if !(m.is_finite() && (0.0..1.0).contains(&m)) {
            return Err(invalid(format!(
                "maximum camber must be in [0, 1) of the chord, got {m}"
            )));
        }
        if m > 0.0 && !(p > 0.0 && p < 1.0) {
            return Err(invalid(format!(
                "a cambered airfoil needs its camber position in (0, 1), got {p}"
            )));
        }
        Ok(())
    }

    fn is_cambered(&self) -> bool {
        self.max_camber > 0.0
    }

    fn quartic(&self) -> f64 {
        if self.closed_trailing_edge {
            QUARTIC_CLOSED
        } else {
            QUARTIC_OPEN
        }
    }

    /// The polynomial part of y_t / (5t) (without the √ξ term) and its ξ-derivative.
    fn thickness_polynomial(&self, xi: f64) -> (f64, f64) {
        let [_, a1, a2, a3] = THICKNESS_COEFFICIENTS;
        let a4 = self.quartic();
        let value = xi * (a1 + xi * (a2 + xi * (a3 + xi * a4)));
        let slope = a1 + xi * (2.0 * a2 + xi * (3.0 * a3 + xi * 4.0 * a4));
        (value, slope)
    }

    /// Half thickness y_t at abscissa `x` (clamped to [0, c]): the distance from the camber
    /// line to either surface, measured perpendicular to the camber line.
    pub fn thickness(&self, x: f64) -> f64 {
        let xi = (x / self.chord).clamp(0.0, 1.0);
        let (poly, _) = self.thickness_polynomial(xi);
        5.0 * self.max_thickness * (THICKNESS_COEFFICIENTS[0] * xi.sqrt() + poly) * self.chord
    }

    /// Camber at the chord fraction ξ; `fore` selects the branch ξ < p (matters for the
    /// second derivative at ξ = p only).
    fn camber_at(&self, xi: f64, fore: bool) -> Camber {
        let (m, p) = (self.max_camber, self.camber_position);
        if !self.is_cambered() {
            return Camber {
                height: 0.0,
                slope: 0.0,
                curvature: 0.0,
            };
        }
        if fore {
            let k = m / (p * p);
            Camber {
                height: k * (2.0 * p * xi - xi * xi),
                slope: 2.0 * k * (p - xi),
                curvature: -2.0 * k,
            }
        } else {
            let k = m / ((1.0 - p) * (1.0 - p));
            Camber {
                height: k * (1.0 - 2.0 * p + 2.0 * p * xi - xi * xi),
                slope: 2.0 * k * (p - xi),
                curvature: -2.0 * k,
            }
        }
    }

    /// Height of the camber line y_c at abscissa `x` (clamped to [0, c]).
    pub fn camber(&self, x: f64) -> f64 {
        let xi = (x / self.chord).clamp(0.0, 1.0);
        self.camber_at(xi, xi < self.camber_position).height * self.chord
    }

    /// Slope dy_c/dx of the camber line at abscissa `x` (clamped to [0, c]).
    pub fn camber_slope(&self, x: f64) -> f64 {
        let xi = (x / self.chord).clamp(0.0, 1.0);
        self.camber_at(xi, xi < self.camber_position).slope
    }

    /// The surface point `(x_c, y_c) + side · y_t · n` of the camber station `x`, with n the
    /// camber line's unit normal `(−sin θ, cos θ)` and side +1 (upper) or −1 (lower).
    fn surface(&self, x: f64, side: f64) -> [f64; 2] {
        let xi = (x / self.chord).clamp(0.0, 1.0);
        let camber = self.camber_at(xi, xi < self.camber_position);
        let cos = 1.0 / camber.slope.hypot(1.0);
        let sin = camber.slope * cos;
        let yt = self.thickness(x) / self.chord;
        [
            self.chord * (xi - side * yt * sin),
            self.chord * (camber.height + side * yt * cos),
        ]
    }

    /// Upper surface point of the camber station `x` ∈ [0, c]: `(x − y_t sin θ, y_c + y_t cos θ)`.
    /// Its abscissa differs from `x` when the airfoil is cambered.
    pub fn upper_surface(&self, x: f64) -> [f64; 2] {
        self.surface(x, 1.0)
    }

    /// Lower surface point of the camber station `x` ∈ [0, c]: `(x + y_t sin θ, y_c − y_t cos θ)`.
    pub fn lower_surface(&self, x: f64) -> [f64; 2] {
        self.surface(x, -1.0)
    }

    /// The contour point at the cosine-spacing angle `s` ∈ [−π, π] (clamped): lower surface
    /// at the station ξ = (1 − cos s)/2 for s < 0, upper for s > 0. The spline of
    /// [`Naca4::curve`] interpolates this map at `u = (s + π) / (2π)`.
    pub fn contour_point(&self, s: f64) -> [f64; 2] {
        let s = s.clamp(-PI, PI);
        let xi = 0.5 * (1.0 - s.cos());
        self.contour(s, xi < self.camber_position).point
    }

    /// Point and dC/ds at the angle `s`; `fore` selects the camber branch (for one-sided
    /// derivatives at the break ξ = p). The √ξ term is differentiated as sin(|s|/2), so the
    /// derivative is finite at the leading edge.
    fn contour(&self, s: f64, fore: bool) -> ContourPoint {
        let side = if s < 0.0 { -1.0 } else { 1.0 };
        let half = 0.5 * s.abs();
        let xi = 0.5 * (1.0 - s.cos());
        let dxi = 0.5 * s.sin();
        let five_t = 5.0 * self.max_thickness;
        let (poly, dpoly) = self.thickness_polynomial(xi);
        let a0 = THICKNESS_COEFFICIENTS[0];
        let yt = five_t * (a0 * half.sin() + poly);
        // side · dy_t/ds: d sin(|s|/2)/ds = side · cos(|s|/2) / 2.
        let signed_dyt = five_t * (a0 * 0.5 * half.cos() + side * dpoly * dxi);
        let camber = self.camber_at(xi, fore);
        let cos = 1.0 / camber.slope.hypot(1.0);
        let sin = camber.slope * cos;
        // dθ/ds = y_c'' / (1 + y_c'²) · dξ/ds; dn/ds = −dθ/ds (cos θ, sin θ).
        let dtheta = camber.curvature * cos * cos * dxi;
        let c = self.chord;
        let point = [
            c * (xi - side * yt * sin),
            c * (camber.height + side * yt * cos),
        ];
        let tangent = [
            c * (dxi - signed_dyt * sin - side * yt * dtheta * cos),
            c * (camber.slope * dxi + signed_dyt * cos - side * yt * dtheta * sin),
        ];
        ContourPoint { point, tangent }
    }

    /// The trailing-edge points (upper, lower); equal (`(c, 0)`) for a closed trailing edge.
    pub fn trailing_edge(&self) -> ([f64; 2], [f64; 2]) {
        if self.closed_trailing_edge {
            ([self.chord, 0.0], [self.chord, 0.0])
        } else {
            (
                self.contour(PI, false).point,
                self.contour(-PI, false).point,
            )
        }
    }

    /// The break angles of the smooth pieces, ascending from −π to π, and for each piece
    /// whether it lies ahead of the maximum camber.
    fn pieces(&self) -> Vec<(f64, f64, bool)> {
        if self.is_cambered() {
            let sp = (1.0 - 2.0 * self.camber_position).acos();
            vec![
                (-PI, -sp, false),
                (-sp, 0.0, true),
                (0.0, sp, true),
                (sp, PI, false),
            ]
        } else {
            vec![(-PI, 0.0, true), (0.0, PI, true)]
        }
    }

    /// The closed contour as one cubic B-spline with [`DEFAULT_INTERVALS_PER_SIDE`] intervals
    /// per surface (see the module documentation for parametrisation, knots and trailing edge).
    pub fn curve(&self) -> Result<NurbsCurve, NurbsError> {
        self.curve_with_intervals(DEFAULT_INTERVALS_PER_SIDE)
    }

    /// As [`Naca4::curve`] with `intervals_per_side ≥ 2` spline intervals (data points minus
    /// one) on each surface; for cambered airfoils each surface's intervals are shared between
    /// its two pieces in proportion to their angle ranges (at least one each).
    pub fn curve_with_intervals(
        &self,
        intervals_per_side: usize,
    ) -> Result<NurbsCurve, NurbsError> {
        self.validate()?;
        if intervals_per_side < 2 {
            return Err(invalid(format!(
                "at least 2 intervals per side are needed, got {intervals_per_side}"
            )));
        }
        let pieces = self.pieces();
        let n = intervals_per_side;
        let to_u = |s: f64| (s + PI) / (2.0 * PI);
        // Intervals ahead of the maximum camber, per side (all of them when symmetric).
        let fore_share = if self.is_cambered() {
            let sp = pieces[2].1;
            ((n as f64 * sp / PI).round() as usize).clamp(1, n - 1)
        } else {
            n
        };
        let mut knots: Vec<f64> = vec![0.0; 4];
        let mut points: Vec<[f64; 2]> = Vec::new();
        for (k, &(a, b, fore)) in pieces.iter().enumerate() {
            let share = if fore { fore_share } else { n - fore_share };
            let piece = self.fit_piece(a, b, share, fore);
            if k == 0 {
                points.extend_from_slice(&piece.control_points);
            } else if a == 0.0 {
                // Leading edge: dC/ds is continuous, so the shared control point lies on the
                // line of its neighbours at the ratio of the adjacent spans and one of the
                // three knots can be removed exactly (drop that point).
                points.pop();
                knots.extend([to_u(a); 2]);
                points.extend_from_slice(&piece.control_points[1..]);
            } else {
                knots.extend([to_u(a); 3]);
                points.extend_from_slice(&piece.control_points[1..]);
            }
            knots.extend(piece.interior_knots.iter().map(|&s| to_u(s)));
        }
        let (upper_te, lower_te) = self.trailing_edge();
        let last = points.len() - 1;
        points[0] = lower_te;
        points[last] = upper_te;
        if self.closed_trailing_edge {
            knots.extend([1.0; 4]);
        } else {
            // Straight base from the upper back to the lower trailing-edge point, parametrised
            // at the airfoil's mean speed.
            let perimeter: f64 = points.windows(2).map(|w| distance2(w[0], w[1])).sum();
            let end = 1.0 + distance2(upper_te, lower_te) / perimeter;
            knots.extend([1.0; 3]);
            knots.extend([end; 4]);
            for i in 1..=3 {
                let f = i as f64 / 3.0;
                points.push([
                    upper_te[0] + f * (lower_te[0] - upper_te[0]),
                    upper_te[1] + f * (lower_te[1] - upper_te[1]),
                ]);
            }
            let last = points.len() - 1;
            points[last] = lower_te;
        }
        let control_points = points.iter().map(|p| [p[0], p[1], 0.0]).collect();
        NurbsCurve::non_rational(3, knots, control_points)
    }

    /// Complete cubic spline interpolation of the contour on [a, b] (one smooth piece) at
    /// `intervals + 1` equally spaced angles with the exact end derivatives: clamped knots at
    /// the data angles, control points `P_0 … P_{n+2}`.
    fn fit_piece(&self, a: f64, b: f64, intervals: usize, fore: bool) -> Piece {
        let n = intervals;
        let sites: Vec<f64> = (0..=n)
            .map(|i| {
                if i == n {
                    b
                } else {
                    a + (b - a) * i as f64 / n as f64
                }
            })
            .collect();
        let mut knots = vec![a; 4];
        knots.extend_from_slice(&sites[1..n]);
        knots.extend([b; 4]);
        let start = self.contour(a, fore);
        let end = self.contour(b, fore);
        // Clamped ends: C'(a) = 3 (P_1 − P_0) / (s_1 − s_0), likewise at b.
        let (h0, h1) = (sites[1] - sites[0], sites[n] - sites[n - 1]);
        let mut cp = vec![[0.0; 2]; n + 3];
        cp[0] = start.point;
        cp[1] = add2(start.point, start.tangent, h0 / 3.0);
        cp[n + 2] = end.point;
        cp[n + 1] = add2(end.point, end.tangent, -h1 / 3.0);
        // Interior sites s_i (i = 1 … n−1) are simple knots U_{i+3}, where only N_i, N_{i+1},
        // N_{i+2} are non-zero: a tridiagonal system for the unknowns P_2 … P_n.
        let m = n - 1;
        let mut sub = vec![0.0; m];
        let mut diag = vec![0.0; m];
        let mut sup = vec![0.0; m];
        let mut rhs = vec![[0.0; 2]; m];
        let mut basis = [0.0; 4];
        for i in 1..n {
            let s = sites[i];
            let span = find_span(3, &knots, s);
            basis_functions(span, s, 3, &knots, &mut basis);
            debug_assert_eq!(span, i + 3);
            let row = i - 1;
            let mut target = self.contour(s, fore).point;
            // Column i ↔ unknown i − 2 (P_1 is known for i = 1), column i + 2 (P_{n+1} known
            // for i = n − 1).
            if i == 1 {
                target = add2(target, cp[1], -basis[0]);
            } else {
                sub[row] = basis[0];
            }
            diag[row] = basis[1];
            if i == n - 1 {
                target = add2(target, cp[n + 1], -basis[2]);
            } else {
                sup[row] = basis[2];
            }
            rhs[row] = target;
        }
        let solution = solve_tridiagonal(&sub, &diag, &sup, &rhs);
        cp[2..2 + m].copy_from_slice(&solution);
        Piece {
            interior_knots: sites[1..n].to_vec(),
            control_points: cp,
        }
    }
}

/// One interpolated smooth piece: its interior knots (angles) and control points.
struct Piece {
    interior_knots: Vec<f64>,
    control_points: Vec<[f64; 2]>,
}

fn invalid(reason: String) -> NurbsError {
    NurbsError::InvalidShape {
        shape: "naca4",
        reason,
    }
}

fn add2(a: [f64; 2], b: [f64; 2], factor: f64) -> [f64; 2] {
    [a[0] + factor * b[0], a[1] + factor * b[1]]
}

fn distance2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Thomas algorithm for a tridiagonal system with two right-hand sides. The B-spline
/// collocation matrix is totally positive, so elimination without pivoting is stable
/// (de Boor, *A Practical Guide to Splines*, Ch. XIII).
fn solve_tridiagonal(sub: &[f64], diag: &[f64], sup: &[f64], rhs: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let m = diag.len();
    let mut c = vec![0.0; m];
    let mut d = vec![[0.0; 2]; m];
    for i in 0..m {
        let (prev_c, prev_d) = if i == 0 {
            (0.0, [0.0; 2])
        } else {
            (c[i - 1], d[i - 1])
        };
        let pivot = diag[i] - sub[i] * prev_c;
        c[i] = sup[i] / pivot;
        d[i] = [
            (rhs[i][0] - sub[i] * prev_d[0]) / pivot,
            (rhs[i][1] - sub[i] * prev_d[1]) / pivot,
        ];
    }
    for i in (0..m.saturating_sub(1)).rev() {
        let next = d[i + 1];
        d[i] = add2(d[i], next, -c[i]);
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::arc_length::arc_length;

    fn naca0012() -> Naca4 {
        Naca4::from_digits("0012", 1.0, true).unwrap()
    }

    /// The spline parameter of the angle s.
    fn u_of(s: f64) -> f64 {
        (s + PI) / (2.0 * PI)
    }

    fn xy(p: [f64; 3]) -> [f64; 2] {
        [p[0], p[1]]
    }

    /// Distance from `x` to the closed-form contour on the piece containing `s0`, by a secant
    /// iteration on f(s) = C'(s)·(C(s) − x) from s0 (the spline point's own angle, already
    /// within ~1e-10 of the foot point).
    fn distance_to_contour(airfoil: &Naca4, x: [f64; 2], s0: f64, fore: bool) -> f64 {
        let f = |s: f64| {
            let c = airfoil.contour(s, fore);
            let r = [c.point[0] - x[0], c.point[1] - x[1]];
            (c.tangent[0] * r[0] + c.tangent[1] * r[1], r[0].hypot(r[1]))
        };
        let (mut s_prev, mut s) = (s0, s0 + 1e-7);
        let (mut f_prev, _) = f(s_prev);
        let mut best = f(s0).1;
        for _ in 0..30 {
            let (fs, dist) = f(s);
            best = best.min(dist);
            if fs == f_prev {
                break;
            }
            let next = s - fs * (s - s_prev) / (fs - f_prev);
            (s_prev, f_prev, s) = (s, fs, next);
        }
        best
    }

    /// Max parametric and geometric deviation of the spline from the closed form, sampling
    /// `per_span` points in each knot span.
    fn deviation(airfoil: &Naca4, curve: &NurbsCurve, per_span: usize) -> (f64, f64) {
        let (mut parametric, mut geometric) = (0.0f64, 0.0f64);
        let breaks = curve.breakpoints();
        let sp = if airfoil.is_cambered() {
            (1.0 - 2.0 * airfoil.camber_position).acos()
        } else {
            f64::INFINITY
        };
        for w in breaks.windows(2) {
            if w[0] >= 1.0 {
                continue; // the straight base of a blunt trailing edge
            }
            for j in 0..per_span {
                let u = w[0] + (w[1] - w[0]) * (j as f64 + 0.5) / per_span as f64;
                let s = 2.0 * PI * u - PI;
                let fore = s.abs() < sp;
                let spline = xy(curve.point(u));
                let exact = airfoil.contour(s, fore).point;
                parametric = parametric.max(distance2(spline, exact));
                geometric = geometric.max(distance_to_contour(airfoil, spline, s, fore));
            }
        }
        (parametric, geometric)
    }

    #[test]
    fn digits_are_parsed_and_checked() {
        let a = Naca4::from_digits("2412", 2.0, false).unwrap();
        assert_eq!(
            (a.max_camber, a.camber_position, a.max_thickness, a.chord),
            (0.02, 0.4, 0.12, 2.0)
        );
        for bad in ["012", "00120", "00a2", "0000", "2012", "", "٠٠١٢"] {
            assert!(
                matches!(
                    Naca4::from_digits(bad, 1.0, true),
                    Err(NurbsError::InvalidShape { shape: "naca4", .. })
                ),
                "{bad}"
            );
        }
        assert!(Naca4::from_digits("0012", 0.0, true).is_err());
        assert!(Naca4::from_digits("0012", f64::NAN, true).is_err());
    }

    #[test]
    fn closed_form_matches_the_standard_formulas() {
        let open = Naca4::from_digits("0012", 1.0, false).unwrap();
        let closed = naca0012();
        // y_t(1) = 0.6 (0.2969 − 0.1260 − 0.3516 + 0.2843 − a₄): 0.6 · 0.0021 or 0.
        assert!((open.thickness(1.0) - 0.6 * 0.0021).abs() < 1e-15);
        assert!(closed.thickness(1.0).abs() < 1e-15);
        // At x = 0.25: 0.6 (0.2969·0.5 − 0.0315 − 0.021975 + 0.0044421875 − 0.000396484375).
        let expected = 0.6 * (0.14845 - 0.0315 - 0.021975 + 0.0044421875 - 0.000396484375);
        assert!((open.thickness(0.25) - expected).abs() < 1e-15);
        // Symmetric: upper and lower mirror each other at the same abscissa.
        let (up, lo) = (closed.upper_surface(0.3), closed.lower_surface(0.3));
        assert_eq!(up, [0.3, closed.thickness(0.3)]);
        assert_eq!(lo, [0.3, -closed.thickness(0.3)]);
        // Chord scaling: the 2 m airfoil is the 1 m one doubled.
        let big = Naca4::from_digits("0012", 2.0, true).unwrap();
        assert!((big.thickness(0.6) - 2.0 * closed.thickness(0.3)).abs() < 1e-15);
        assert_eq!(closed.trailing_edge(), ([1.0, 0.0], [1.0, 0.0]));
        let (u, l) = open.trailing_edge();
        assert!((u[1] - 0.6 * 0.0021).abs() < 1e-15 && (l[1] + 0.6 * 0.0021).abs() < 1e-15);
    }

    #[test]
    fn contour_derivative_matches_finite_differences() {
        // Fourth-order central differences away from the breaks, for 0012 and 2412.
        let h = 1e-3;
        for airfoil in [naca0012(), Naca4::from_digits("2412", 1.5, false).unwrap()] {
            for i in 1..40 {
                let s = -PI + 2.0 * PI * i as f64 / 40.0 + 0.01;
                let xi = 0.5 * (1.0 - s.cos());
                let fore = xi < airfoil.camber_position;
                let p = |t: f64| airfoil.contour(t, fore).point;
                let d = airfoil.contour(s, fore).tangent;
                for k in 0..2 {
                    let fd = (p(s - 2.0 * h)[k] - 8.0 * p(s - h)[k] + 8.0 * p(s + h)[k]
                        - p(s + 2.0 * h)[k])
                        / (12.0 * h);
                    assert!((fd - d[k]).abs() < 1e-9, "s={s} k={k}: {fd} vs {}", d[k]);
                }
            }
        }
    }

    #[test]
    fn spline_interpolates_the_data_points() {
        let airfoil = naca0012();
        let n = 64;
        let curve = airfoil.curve_with_intervals(n).unwrap();
        for i in 0..=2 * n {
            let s = -PI + PI * i as f64 / n as f64;
            let u = u_of(s);
            let p = xy(curve.point(u));
            let exact = airfoil.contour_point(s);
            assert!(distance2(p, exact) < 1e-13, "s={s}: {p:?} vs {exact:?}");
        }
        // Clamped at the trailing edge, leading edge at u = 1/2.
        assert_eq!(curve.point(0.0), [1.0, 0.0, 0.0]);
        assert_eq!(curve.point(1.0), [1.0, 0.0, 0.0]);
        assert!(curve.is_closed());
        assert!(distance2(xy(curve.point(0.5)), [0.0, 0.0]) < 1e-15);
        // Lower surface first: clockwise.
        assert!(curve.point(0.25)[1] < 0.0 && curve.point(0.75)[1] > 0.0);
    }

    #[test]
    fn knots_mark_the_trailing_edge_and_the_leading_edge() {
        let curve = naca0012().curve().unwrap();
        assert_eq!(curve.domain(), (0.0, 1.0));
        assert_eq!(curve.knot_multiplicity(0.0), 4);
        assert_eq!(curve.knot_multiplicity(1.0), 4);
        assert_eq!(curve.knot_multiplicity(0.5), 2);
        assert!(curve.c0_parameters().is_empty());
        assert_eq!(
            curve.control_points.len(),
            2 * (DEFAULT_INTERVALS_PER_SIDE + 3) - 2
        );
        // C¹ at the leading edge: one-sided derivatives agree.
        let (left, right) = (
            curve.derivatives(0.5 - 1e-15, 1)[1],
            curve.derivatives(0.5, 1)[1],
        );
        assert!((left[0] - right[0]).abs() < 1e-9 && (left[1] - right[1]).abs() < 1e-9);
        // dC/du = 2π dC/ds = 2π (0, 5t · 0.2969 / 2) at the leading edge: a vertical tangent.
        let expected = PI * 0.6 * 0.2969;
        for d in [left, right] {
            assert!(
                d[0].abs() < 1e-12 && (d[1] - expected).abs() < 1e-12,
                "{d:?}"
            );
        }

        // Blunt trailing edge: a straight base joined by C⁰ knots closes the curve.
        let open = Naca4::from_digits("0012", 1.0, false).unwrap();
        let curve = open.curve().unwrap();
        assert!(curve.is_closed());
        assert_eq!(curve.c0_parameters(), vec![1.0]);
        let (_, end) = curve.domain();
        let gap = 2.0 * 0.6 * 0.0021;
        assert!(end > 1.0 && end < 1.0 + gap);
        for i in 0..=10 {
            let p = curve.point(1.0 + (end - 1.0) * i as f64 / 10.0);
            assert!((p[0] - 1.0).abs() < 1e-15);
            assert!((p[1] - gap * (0.5 - i as f64 / 10.0)).abs() < 1e-15);
        }
        let length = arc_length(&curve, 1.0, end);
        assert!((length - gap).abs() < 1e-15);
    }

    #[test]
    fn spline_is_within_1e_10_chord_of_the_closed_form_with_fourth_order_convergence() {
        let airfoil = naca0012();
        let curve = airfoil.curve().unwrap();
        let (parametric, geometric) = deviation(&airfoil, &curve, 8);
        assert!(parametric < 1e-10, "parametric deviation {parametric:e}");
        assert!(
            geometric <= parametric + 1e-15,
            "{geometric:e} {parametric:e}"
        );
        // Fourth-order convergence: halving the intervals multiplies the error by ~16.
        let coarse = airfoil
            .curve_with_intervals(DEFAULT_INTERVALS_PER_SIDE / 4)
            .unwrap();
        let (coarse_parametric, _) = deviation(&airfoil, &coarse, 8);
        let rate = (coarse_parametric / parametric).log2() / 2.0;
        assert!((3.7..4.3).contains(&rate), "rate {rate}");
    }

    #[test]
    fn point_inversion_recovers_offsets_along_the_exact_normal() {
        // x = C(s) + d n(s) with n the outward unit normal: its distance to the contour is d
        // (d well below the leading-edge radius 1.1019 t² ≈ 0.016), up to the spline's error.
        let airfoil = naca0012();
        let curve = airfoil.curve().unwrap();
        let d = 1e-3;
        for i in 0..=200 {
            let s = -PI + 2.0 * PI * (i as f64 + 0.5) / 201.0;
            let c = airfoil.contour(s, true);
            let speed = c.tangent[0].hypot(c.tangent[1]);
            // Clockwise contour: the outward normal is the tangent turned left.
            let n = [-c.tangent[1] / speed, c.tangent[0] / speed];
            let x = [c.point[0] + d * n[0], c.point[1] + d * n[1], 0.0];
            let cp = crate::inversion::closest_point_on_curve(&curve, x);
            assert!((cp.distance - d).abs() < 1e-10, "s={s}: {}", cp.distance);
            assert!(
                (cp.param - u_of(s)).abs() < 1e-6,
                "s={s}: {} vs {}",
                cp.param,
                u_of(s)
            );
        }
        // Beyond the trailing edge the corner itself is closest.
        let cp = crate::inversion::closest_point_on_curve(&curve, [1.01, 0.0, 0.0]);
        assert!((cp.distance - 0.01).abs() < 1e-14);
    }

    /// Length of the polyline through the closed-form contour at `2^level` equal angle steps on
    /// each smooth piece.
    fn polyline_length(airfoil: &Naca4, level: u32) -> f64 {
        let k = 1usize << level;
        airfoil
            .pieces()
            .iter()
            .map(|&(a, b, fore)| {
                let mut previous = airfoil.contour(a, fore).point;
                let mut length = 0.0;
                for i in 1..=k {
                    let p = airfoil
                        .contour(a + (b - a) * i as f64 / k as f64, fore)
                        .point;
                    length += distance2(previous, p);
                    previous = p;
                }
                length
            })
            .sum()
    }

    #[test]
    fn arc_length_matches_the_richardson_limit_of_polylines() {
        let airfoil = naca0012();
        // Inscribed polylines on smooth pieces: L_h = L − c₂h² − c₄h⁴ …; two Richardson steps.
        let levels: Vec<f64> = (10..=13).map(|l| polyline_length(&airfoil, l)).collect();
        let r1: Vec<f64> = levels
            .windows(2)
            .map(|w| (4.0 * w[1] - w[0]) / 3.0)
            .collect();
        let r2: Vec<f64> = r1.windows(2).map(|w| (16.0 * w[1] - w[0]) / 15.0).collect();
        let limit = r2[r2.len() - 1];
        assert!((r2[0] - limit).abs() < 1e-12, "{r2:?}");
        let curve = airfoil.curve().unwrap();
        let spline_length = arc_length(&curve, 0.0, 1.0);
        let relative = (spline_length - limit).abs() / limit;
        assert!(
            relative < 1e-10,
            "length {spline_length} vs {limit}: {relative:e}"
        );
        // A NACA0012 contour is a little over twice the chord.
        assert!((2.03..2.05).contains(&limit), "{limit}");
    }

    #[test]
    fn cambered_2412_has_its_camber_peak_at_p_and_corners_there() {
        let airfoil = Naca4::from_digits("2412", 1.0, true).unwrap();
        let (m, p) = (0.02, 0.4);
        assert!((airfoil.camber(p) - m).abs() < 1e-17);
        assert!(airfoil.camber_slope(p).abs() < 1e-17);
        for i in 0..=100 {
            let x = i as f64 / 100.0;
            if (x - p).abs() > 1e-9 {
                assert!(airfoil.camber(x) < m);
            }
        }
        assert_eq!(airfoil.camber(0.0), 0.0);
        assert!(airfoil.camber(1.0).abs() < 1e-17);
        // Surfaces are offset perpendicular to the camber line: at x = p the normal is vertical.
        let yt = airfoil.thickness(p);
        assert!(distance2(airfoil.upper_surface(p), [p, m + yt]) < 1e-16);
        assert!(distance2(airfoil.lower_surface(p), [p, m - yt]) < 1e-16);
        // Ahead of p the upper surface moves back: x_u = x − y_t sin θ < x.
        assert!(airfoil.upper_surface(0.2)[0] < 0.2 && airfoil.lower_surface(0.2)[0] > 0.2);

        let curve = airfoil.curve().unwrap();
        let sp = (1.0 - 2.0 * p).acos();
        let corners = curve.c0_parameters();
        assert_eq!(corners.len(), 2);
        assert!((corners[0] - u_of(-sp)).abs() < 1e-15);
        assert!((corners[1] - u_of(sp)).abs() < 1e-15);
        // The spline passes through the surface points at x = p, and its highest point on the
        // upper side is near there.
        assert!(distance2(xy(curve.point(corners[1])), airfoil.upper_surface(p)) < 1e-13);
        assert!(distance2(xy(curve.point(corners[0])), airfoil.lower_surface(p)) < 1e-13);
        // One-sided tangents at the corner follow the closed form's (a ~2e-4 rad kink).
        let before = airfoil.contour(sp, true).tangent;
        let after = airfoil.contour(sp, false).tangent;
        let angle = |a: [f64; 2]| a[1].atan2(a[0]);
        let kink = angle(after) - angle(before);
        assert!(kink.abs() > 1e-5 && kink.abs() < 1e-3, "kink {kink}");
        let u = corners[1];
        let spline_before = curve.derivatives(u - 1e-14, 1)[1];
        let spline_after = curve.derivatives(u, 1)[1];
        assert!((angle(xy(spline_before)) - angle(before)).abs() < 1e-9);
        assert!((angle(xy(spline_after)) - angle(after)).abs() < 1e-9);

        let (parametric, geometric) = deviation(&airfoil, &curve, 8);
        assert!(parametric < 1e-10 && geometric <= parametric + 1e-15);
        let length = arc_length(&curve, 0.0, 1.0);
        let reference: f64 = {
            let levels: Vec<f64> = (11..=12).map(|l| polyline_length(&airfoil, l)).collect();
            (4.0 * levels[1] - levels[0]) / 3.0
        };
        assert!((length - reference).abs() / reference < 1e-10);
    }
}
