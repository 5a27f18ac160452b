//! Approximate geodesics on a surface by the paper's perpendicular-bisector refinement in
//! parameter space (Sect. 4.1, Eq. (5), Fig. 3).
//!
//! Between parameters λ₁ and λ₂ the new point is
//! λ₃ = argmin over the perpendicular bisector r₁₂ of λ₁λ₂ of |x₁ − S(λ)| + |S(λ) − x₂|;
//! every segment is refined this way, then each interior point is corrected by the same
//! minimisation on the bisector of its two neighbours, until the polyline's length is within a
//! relative tolerance of its limit (estimated from the last two changes, see
//! [`GeodesicPath::between`]). Points along the path are placed by arc length of the
//! polyline, with the parameter interpolated linearly inside a segment and the point
//! evaluated on the surface — so every point returned lies on the surface exactly.

use hocurve_nurbs::vec3::{add, cross, distance, dot, norm, scale, sub};

use crate::chart::SurfaceChart;

/// Default relative tolerance on the polyline length's estimated distance to its limit.
pub const DEFAULT_LENGTH_TOLERANCE: f64 = 1e-10;
/// At least this many segments.
const MIN_SEGMENTS: usize = 4;
/// A relative length change this small is round-off: the path is exact.
const ROUND_OFF: f64 = 1e-13;
/// At most this many segments.
const MAX_SEGMENTS: usize = 256;

/// A polyline on a surface approximating the geodesic between its ends.
#[derive(Debug, Clone, PartialEq)]
pub struct GeodesicPath {
    /// Parameters of the polyline's points (unrolled across seams: fold before evaluating).
    pub params: Vec<[f64; 2]>,
    /// The points S(params).
    pub points: Vec<[f64; 3]>,
    /// Cumulative chord lengths: `lengths[0] = 0`, `lengths.last()` = the path length.
    pub lengths: Vec<f64>,
}

impl GeodesicPath {
    /// The approximate geodesic from parameter `a` to parameter `b` on the chart's surface,
    /// refined until the length is within `tolerance` (relative) of its limit.
    ///
    /// The length error after a refinement is estimated from the change δₖ it made and the
    /// ratio ρ = δₖ₋₁/δₖ of the last two changes: for a sequence converging like hᵐ the
    /// remaining error is δₖ/(ρ − 1) (ρ ≈ 2ᵐ; the circular-arc lengths make m = 4, ρ ≈ 16,
    /// see `segment_arc`). The estimate is used only when the sequence looks asymptotic:
    /// from 8 segments on, with 4 < ρ < 64; otherwise the change itself must be below the
    /// tolerance. Below 8 segments only a change at round-off stops the refinement (exact
    /// paths: planes, great circles, helices): a coarse polyline's change can be small by
    /// cancellation (seen on a torus: 4e-7 from 2 to 4 segments, then 5e-6 from 4 to 8).
    pub fn between(chart: &SurfaceChart, a: [f64; 2], b: [f64; 2], tolerance: f64) -> Self {
        let (a, b) = chart.path_ends(a, b);
        let mut params = vec![a, b];
        let mut points = vec![chart.point(a), chart.point(b)];
        if distance(points[0], points[1]) == 0.0 {
            return Self::from_polyline(params, points);
        }
        let mut length = polyline_length(&points);
        let mut last_change = f64::INFINITY;
        loop {
            // Refine every segment at its bisector minimum.
            let mut fine_params = Vec::with_capacity(2 * params.len());
            let mut fine_points = Vec::with_capacity(2 * params.len());
            for i in 0..params.len() - 1 {
                fine_params.push(params[i]);
                fine_points.push(points[i]);
                let (m, x) =
                    bisector_minimum(chart, params[i], params[i + 1], points[i], points[i + 1]);
                fine_params.push(m);
                fine_points.push(x);
            }
            fine_params.extend(params.last());
            fine_points.extend(points.last());
            params = fine_params;
            points = fine_points;
            // Correct the old interior points (even indices) from their new neighbours (Fig. 3c).
            for i in (2..params.len() - 1).step_by(2) {
                let (m, x) = bisector_minimum(
                    chart,
                    params[i - 1],
                    params[i + 1],
                    points[i - 1],
                    points[i + 1],
                );
                params[i] = m;
                points[i] = x;
            }
            let new_length = polyline_length(&points);
            let segments = params.len() - 1;
            let change = (new_length - length).abs();
            length = new_length;
            let ratio = last_change / change;
            let error = if change <= ROUND_OFF * length {
                // Converged exactly (a plane, a sphere's great circle, a cylinder's helix).
                0.0
            } else if segments < 2 * MIN_SEGMENTS {
                // Too coarse to judge: a change can be small by cancellation.
                f64::INFINITY
            } else if ratio > 4.0 && ratio < 64.0 {
                change / (ratio - 1.0)
            } else {
                change
            };
            last_change = change;
            if segments >= MAX_SEGMENTS || (segments >= MIN_SEGMENTS && error <= tolerance * length)
            {
                break;
            }
        }
        Self::from_polyline(params, points)
    }

    /// A path through given parameters and points.
    fn from_polyline(params: Vec<[f64; 2]>, points: Vec<[f64; 3]>) -> Self {
        let lengths = cumulative_lengths(&points);
        Self {
            params,
            points,
            lengths,
        }
    }

    /// Length of the path: the polyline's segments measured as circular arcs (see
    /// `segment_arc`).
    pub fn length(&self) -> f64 {
        self.lengths.last().copied().unwrap_or(0.0)
    }

    /// A parameter near the point at `fraction` ∈ [0, 1] of the length (interpolated
    /// linearly between the polyline's parameters, not projected): a starting guess.
    pub fn parameter_near(&self, fraction: f64) -> [f64; 2] {
        let n = self.points.len();
        if n < 2 {
            return self.params.first().copied().unwrap_or([0.0; 2]);
        }
        let (k, t, _) =
            chord_point_at_fraction(&self.points, &self.lengths, fraction.clamp(0.0, 1.0));
        let (a, b) = (self.params[k], self.params[k + 1]);
        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
    }

    /// The parameter and the point at `fraction` ∈ [0, 1] of the length from the start: the
    /// point of the polyline at that length, projected onto the surface (closest point, by
    /// Newton from the linearly interpolated parameter). The projection is exact on a plane
    /// and on a sphere (whose geodesics are radial projections of their chords).
    pub fn at_fraction(&self, chart: &SurfaceChart, fraction: f64) -> ([f64; 2], [f64; 3]) {
        let n = self.points.len();
        let fraction = fraction.clamp(0.0, 1.0);
        if fraction == 0.0 || n < 2 {
            return (self.params[0], self.points[0]);
        }
        if fraction == 1.0 {
            return (self.params[n - 1], self.points[n - 1]);
        }
        let (k, t, on_chord) = chord_point_at_fraction(&self.points, &self.lengths, fraction);
        let (a, b) = (self.params[k], self.params[k + 1]);
        let guess = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
        let (uv, x) = chart.project_near(on_chord, guess);
        (chart.unroll_near(uv, guess), x)
    }
}

/// The point of a polyline (with cumulative arc lengths `lengths`, see `segment_arc`) at
/// `fraction` ∈ (0, 1) of its length, before projection: the segment `k` holding it, the chord
/// parameter `t` ∈ [0, 1] on that segment, and the chord point. Inside a segment the length is
/// that of its circular arc, so `t` is where the ray from the circle's centre through the arc
/// point crosses the chord — exact for a polyline sampling a circle.
pub(crate) fn chord_point_at_fraction(
    points: &[[f64; 3]],
    lengths: &[f64],
    fraction: f64,
) -> (usize, f64, [f64; 3]) {
    let n = points.len();
    let total = lengths.last().copied().unwrap_or(0.0);
    let target = fraction * total;
    // The segment [k, k + 1] holding the target length.
    let k = lengths.partition_point(|&l| l <= target).clamp(1, n - 1) - 1;
    let seg = lengths[k + 1] - lengths[k];
    let tau = if seg > 0.0 {
        (target - lengths[k]) / seg
    } else {
        0.0
    };
    // The point at arc fraction τ of the segment's circular arc seen from the circle's
    // centre crosses the chord at t = ½ (1 + tan((τ − ½)φ) / tan(φ/2)).
    let phi = segment_arc(points, k).1;
    let t = if phi > 1e-6 {
        0.5 * (1.0 + ((tau - 0.5) * phi).tan() / (0.5 * phi).tan())
    } else {
        tau
    };
    let (xa, xb) = (points[k], points[k + 1]);
    let on_chord = add(xa, scale(sub(xb, xa), t));
    (k, t, on_chord)
}

/// λ on the bisector of the parameter segment `a`–`b` minimising |xa − S(λ)| + |S(λ) − xb|
/// (Eq. (5)), by Brent's method along the bisector. The bisector is taken through the
/// parameter midpoint in the direction whose image is perpendicular to the chord xa–xb: on a
/// surface with an uneven parametrisation (a sphere's), a parameter-space perpendicular is
/// slanted in space, and the sum of distances — a saddle along the geodesic — would be
/// minimised off it.
fn bisector_minimum(
    chart: &SurfaceChart,
    a: [f64; 2],
    b: [f64; 2],
    xa: [f64; 3],
    xb: [f64; 3],
) -> ([f64; 2], [f64; 3]) {
    // Through the surface point nearest the chord's midpoint (not the parameter midpoint,
    // whose image drifts along the path on an uneven parametrisation): the new point then
    // splits the segment into two equal chords and the polyline's chords stay even.
    let guess = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let chord_mid = scale(add(xa, xb), 0.5);
    // Gauss–Newton from the parameter midpoint (its image is O(h²) off); the projection with
    // a line search is the fallback at poles, domain edges and on long first segments.
    let mid = chart
        .project_by_gauss_newton(chord_mid, guess, 8)
        .unwrap_or_else(|| chart.unroll_near(chart.project_near(chord_mid, guess).0, guess));
    let chord = sub(xb, xa);
    let chord_length = distance(xa, xb);
    let mut direction = [-(b[1] - a[1]), b[0] - a[0]];
    let [u, v] = chart.fold(mid);
    let d = chart.surface.derivatives(u, v);
    let g = [dot(d.du, chord), dot(d.dv, chord)];
    let image = |w: [f64; 2]| norm(add(scale(d.du, w[0]), scale(d.dv, w[1])));
    let perpendicular = [g[1], -g[0]];
    let len = image(perpendicular);
    if len > 1e-12 * chord_length.max(f64::MIN_POSITIVE) && len.is_finite() {
        // Scaled so that t = ±1/2 reaches half a chord length off the midpoint.
        let scale = chord_length / len;
        direction = [perpendicular[0] * scale, perpendicular[1] * scale];
    }
    // The bisector stays inside the domain: clamped onto a bounded edge (a pole), it would
    // reach the segment's own end when that end is the pole, where the sum of distances
    // is the chord itself, and every refinement would collapse onto the pole.
    let (mut lo, mut hi) = (-0.5_f64, 0.5_f64);
    for d in 0..2 {
        if let (Some((p0, p1)), true) = (chart.bounded_range(d), direction[d] != 0.0) {
            let (ta, tb) = ((p0 - mid[d]) / direction[d], (p1 - mid[d]) / direction[d]);
            lo = lo.max(ta.min(tb));
            hi = hi.min(ta.max(tb));
        }
    }
    if lo >= hi {
        (lo, hi) = (0.0, 0.0);
    }
    let at = |t: f64| [mid[0] + t * direction[0], mid[1] + t * direction[1]];
    // The minimum is the root of the cost's derivative f'(t) = (e_a + e_b)·S'(t), e the unit
    // vectors from the foci; f''(t) = (ė_a + ė_b)·S' + (e_a + e_b)·S'' with
    // ė = (S' − (e·S') e)/|x − focus|. One surface evaluation gives both (its second
    // derivatives), so Newton from the bisector's midpoint converges in 2–4 evaluations;
    // Brent's minimum (limited to ~√ε by the flatness of the cost) and the bracketed secant
    // method are the fallback when it does not.
    let slope_and_curvature = |t: f64| {
        let [u, v] = chart.fold(at(t));
        let d = chart.surface.derivatives(u, v);
        let tangent = add(scale(d.du, direction[0]), scale(d.dv, direction[1]));
        let second = add(
            add(
                scale(d.duu, direction[0] * direction[0]),
                scale(d.duv, 2.0 * direction[0] * direction[1]),
            ),
            scale(d.dvv, direction[1] * direction[1]),
        );
        let (mut slope, mut curvature) = (0.0, 0.0);
        for focus in [xa, xb] {
            let offset = sub(d.point, focus);
            let r = norm(offset);
            if r > 0.0 {
                let e = scale(offset, 1.0 / r);
                let along = dot(e, tangent);
                slope += along;
                curvature += (dot(tangent, tangent) - along * along) / r + dot(e, second);
            }
        }
        (slope, curvature)
    };
    let slope = |t: f64| slope_and_curvature(t).0;
    let t = if lo == hi {
        0.0
    } else if let Some(t) = newton_root(slope_and_curvature, lo, hi) {
        t
    } else if slope(lo) < 0.0 && slope(hi) > 0.0 {
        // (Bracketed by the ends themselves: the interval rebuilt from its midpoint and
        // half-width misses an end by round-off, and an end at a patch edge can have a
        // slope of 1e-21 there and −2e-16 a rounding away — the search then found no sign
        // change and took the midpoint, a quarter chord inside the face.)
        root_between(slope, lo, hi).unwrap_or(0.0_f64.clamp(lo, hi))
    } else {
        let cost = |t: f64| {
            let x = chart.point(at(t));
            distance(xa, x) + distance(x, xb)
        };
        let t = brent_minimum(cost, lo, hi, 1e-8);
        polish_root(slope, t, 1e-6).clamp(lo, hi)
    };
    let uv = at(t);
    (uv, chart.point(uv))
}

/// Steps of [`newton_root`] before it gives up.
const NEWTON_STEPS: usize = 12;

/// The root of g in [lo, hi] by Newton's method from the midpoint, with g and g' from
/// `g_and_slope`; `None` if an iterate leaves the interval, g' is not positive (not a
/// minimum of the cost) or it has not converged to round-off in [`NEWTON_STEPS`] steps.
fn newton_root(g_and_slope: impl Fn(f64) -> (f64, f64), lo: f64, hi: f64) -> Option<f64> {
    let mut t = 0.5 * (lo + hi);
    let scale = (hi - lo).abs();
    for _ in 0..NEWTON_STEPS {
        let (g, slope) = g_and_slope(t);
        if g == 0.0 {
            return Some(t);
        }
        if !(slope > 0.0 && g.is_finite()) {
            return None;
        }
        let step = g / slope;
        t -= step;
        if !(lo..=hi).contains(&t) {
            return None;
        }
        // Quadratic convergence: once a step is below 1e-9 of the interval, the next error
        // is below round-off, so one more step finishes.
        if step.abs() <= 1e-9 * scale {
            let (g, slope) = g_and_slope(t);
            if slope > 0.0 && g.is_finite() {
                t -= g / slope;
            }
            return (lo..=hi).contains(&t).then_some(t);
        }
    }
    None
}

/// The root of `g` near `t0`, searched in [t0 − h, t0 + h]: bisection with secant steps
/// (regula falsi, Illinois variant). Returns `t0` when `g` does not change sign there.
fn polish_root(g: impl Fn(f64) -> f64, t0: f64, h: f64) -> f64 {
    root_between(g, t0 - h, t0 + h).unwrap_or(t0)
}

/// The root of `g` between `a` and `b`, where it changes sign (else `None`): bisection
/// with secant steps (regula falsi, Illinois variant).
fn root_between(g: impl Fn(f64) -> f64, a: f64, b: f64) -> Option<f64> {
    let (mut a, mut b) = (a, b);
    let (mut ga, mut gb) = (g(a), g(b));
    if ga * gb >= 0.0 || ga.is_nan() || gb.is_nan() {
        return None;
    }
    let mut side = 0;
    for _ in 0..100 {
        let t = (a * gb - b * ga) / (gb - ga);
        let gt = g(t);
        if gt == 0.0 || (b - a).abs() <= 4.0 * f64::EPSILON * t.abs().max(1e-300) {
            return Some(t);
        }
        if gt * gb < 0.0 {
            (a, ga) = (b, gb);
            (b, gb) = (t, gt);
            side = 0;
        } else {
            (b, gb) = (t, gt);
            side += 1;
            if side >= 2 {
                ga *= 0.5;
            }
        }
        if (b - a).abs() <= 2.0 * f64::EPSILON * b.abs().max(1e-300) {
            break;
        }
    }
    Some(b)
}

/// Minimum of a unimodal `f` on [lo, hi] by Brent's method (golden section with parabolic
/// steps), to an absolute tolerance `tol` in the argument.
pub(crate) fn brent_minimum(f: impl Fn(f64) -> f64, lo: f64, hi: f64, tol: f64) -> f64 {
    const GOLDEN: f64 = 0.381_966_011_250_105_1;
    let (mut a, mut b) = (lo, hi);
    let mut x = 0.5 * (a + b);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e): (f64, f64) = (0.0, 0.0);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        let tol1 = tol + 1e-12 * x.abs();
        let tol2 = 2.0 * tol1;
        if (x - m).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            // Parabola through x, w, v.
            let r = (x - w) * (fx - fv);
            let q0 = (x - v) * (fx - fw);
            let mut p = (x - v) * q0 - (x - w) * r;
            let mut q = 2.0 * (q0 - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            if p.abs() < (0.5 * q * e).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if x < m { tol1 } else { -tol1 };
                }
                golden = false;
            }
        }
        if golden {
            e = if x < m { b - x } else { a - x };
            d = GOLDEN * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else if d > 0.0 {
            x + tol1
        } else {
            x - tol1
        };
        let fu = f(u);
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    x
}

/// Cumulative lengths of a polyline's segments measured as circular arcs (`segment_arc`):
/// `[0, l₀, l₀ + l₁, …]`.
pub(crate) fn cumulative_lengths(points: &[[f64; 3]]) -> Vec<f64> {
    let mut lengths = Vec::with_capacity(points.len());
    let mut total = 0.0;
    lengths.push(0.0);
    for i in 0..points.len().saturating_sub(1) {
        total += segment_arc(points, i).0;
        lengths.push(total);
    }
    lengths
}

pub(crate) fn polyline_length(points: &[[f64; 3]]) -> f64 {
    (0..points.len().saturating_sub(1))
        .map(|i| segment_arc(points, i).0)
        .sum()
}

/// Length of segment `i` of a polyline seen as an arc of the circle through it and its
/// neighbours (mean curvature of the circles through (i−1, i, i+1) and (i, i+1, i+2)), and the
/// angle φ it subtends. Exact for a circle — a great circle on a sphere — and fourth-order
/// accurate for a smooth curve, where the chord alone is only second-order.
pub(crate) fn segment_arc(points: &[[f64; 3]], i: usize) -> (f64, f64) {
    let c = distance(points[i], points[i + 1]);
    let mut curvature = 0.0;
    let mut count = 0.0;
    if i > 0 {
        curvature += circle_curvature(points[i - 1], points[i], points[i + 1]);
        count += 1.0;
    }
    if i + 2 < points.len() {
        curvature += circle_curvature(points[i], points[i + 1], points[i + 2]);
        count += 1.0;
    }
    if count == 0.0 {
        return (c, 0.0);
    }
    let kappa = curvature / count;
    // Chord c of a circle of radius 1/κ subtends φ = 2 asin(κc/2); the arc is φ/κ.
    let half = (0.5 * kappa * c).min(1.0);
    if half < 1e-8 {
        return (c * (1.0 + half * half / 6.0), 2.0 * half);
    }
    let phi = 2.0 * half.asin();
    (phi / kappa, phi)
}

/// Curvature 1/R of the circle through three points: 4·area / (|ab| |bc| |ca|).
fn circle_curvature(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let (ab, bc, ca) = (distance(a, b), distance(b, c), distance(c, a));
    let twice_area = norm(cross(sub(b, a), sub(c, a)));
    let denom = ab * bc * ca;
    if denom > 0.0 {
        2.0 * twice_area / denom
    } else {
        0.0
    }
}

#[cfg(test)]
#[path = "tests/path.rs"]
mod tests;
