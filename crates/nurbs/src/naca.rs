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
#[path = "tests/naca.rs"]
mod tests;
