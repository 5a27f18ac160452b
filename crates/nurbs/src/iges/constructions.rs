//! Exact rational B-spline forms of IGES geometry: affine maps (124), circular and elliptic
//! arcs (100, 104), restricted curves and surfaces (126, 128 parameter ranges), surfaces of
//! revolution (120) and tabulated cylinders (122), joined composite curves (102) and plane
//! patches (108). Each is exact: the NURBS reproduces the IGES definition up to rounding.

use std::f64::consts::{FRAC_PI_2, TAU};

use super::tolerance::RECOGNITION_TOLERANCE;
use super::BSplineSurfaceData;
use crate::shapes::{orthonormal_frame, AnalyticShape};
use crate::vec3::{add, cross, distance, dot, norm, scale, sub};
use crate::{NurbsCurve, NurbsError, NurbsSurface};

/// Relative margin added on every side of a plane's patch around what it must cover.
const PLANE_MARGIN: f64 = 0.1;

/// An affine map `x' = R x + T` as rows `[R_i1, R_i2, R_i3, T_i]` (the 124 layout).
pub(super) type Affine = [[f64; 4]; 3];

pub(super) const IDENTITY: Affine = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
];

// ---------------------------------------------------------------------------------------------
// affine maps
// ---------------------------------------------------------------------------------------------

pub(super) fn apply(t: &Affine, x: [f64; 3]) -> [f64; 3] {
    let mut y = [0.0; 3];
    for i in 0..3 {
        y[i] = t[i][0] * x[0] + t[i][1] * x[1] + t[i][2] * x[2] + t[i][3];
    }
    y
}

/// The linear part `R v` (for directions).
pub(super) fn apply_linear(t: &Affine, v: [f64; 3]) -> [f64; 3] {
    let mut y = [0.0; 3];
    for i in 0..3 {
        y[i] = t[i][0] * v[0] + t[i][1] * v[1] + t[i][2] * v[2];
    }
    y
}

/// The factor `s` when `R = s Q` with `Q` orthogonal (to [`RECOGNITION_TOLERANCE`]): the maps
/// that carry spheres, cylinders and tori to spheres, cylinders and tori.
pub(super) fn similarity_scale(t: &Affine) -> Option<f64> {
    let col = |k: usize| [t[0][k], t[1][k], t[2][k]];
    let s2 = dot(col(0), col(0));
    if !(s2.is_finite() && s2 > 0.0) {
        return None;
    }
    for i in 0..3 {
        for j in 0..3 {
            let target = if i == j { s2 } else { 0.0 };
            if (dot(col(i), col(j)) - target).abs() > RECOGNITION_TOLERANCE * s2 {
                return None;
            }
        }
    }
    Some(s2.sqrt())
}

/// The curve with `t` applied to its control points; an error when that leaves the
/// floating-point range (huge matrices or coordinates in the file).
pub(super) fn transform_curve(mut c: NurbsCurve, t: &Affine) -> Result<NurbsCurve, String> {
    if *t != IDENTITY {
        transform_points(&mut c.control_points, t)?;
    }
    Ok(c)
}

/// The surface with `t` applied to its control points (an error as [`transform_curve`]).
pub(super) fn transform_surface(mut s: NurbsSurface, t: &Affine) -> Result<NurbsSurface, String> {
    if *t != IDENTITY {
        transform_points(&mut s.control_points, t)?;
    }
    Ok(s)
}

fn transform_points(points: &mut [[f64; 3]], t: &Affine) -> Result<(), String> {
    for (i, p) in points.iter_mut().enumerate() {
        *p = apply(t, *p);
        if !p.iter().all(|x| x.is_finite()) {
            return Err(format!(
                "the transformation matrices take control point {i} out of the floating-point range"
            ));
        }
    }
    Ok(())
}

/// The analytic shape mapped by `t`, when `t` is a similarity (else there is none).
pub(super) fn transform_shape(shape: AnalyticShape, t: &Affine) -> Option<AnalyticShape> {
    let s = similarity_scale(t)?;
    match shape {
        AnalyticShape::Circle {
            center,
            normal,
            radius,
        } => AnalyticShape::new_circle(apply(t, center), apply_linear(t, normal), s * radius),
        AnalyticShape::Sphere { center, radius } => {
            AnalyticShape::new_sphere(apply(t, center), s * radius)
        }
        AnalyticShape::Cylinder {
            point,
            axis,
            radius,
        } => AnalyticShape::new_cylinder(apply(t, point), apply_linear(t, axis), s * radius),
        AnalyticShape::Torus {
            center,
            axis,
            major_radius,
            minor_radius,
        } => AnalyticShape::new_torus(
            apply(t, center),
            apply_linear(t, axis),
            s * major_radius,
            s * minor_radius,
        ),
    }
    .ok()
}

// ---------------------------------------------------------------------------------------------
// exact constructions
// ---------------------------------------------------------------------------------------------

/// A full turn when `span` is 2π to [`RECOGNITION_TOLERANCE`] (exactly `TAU` then).
pub(super) fn snap_full_turn(span: f64) -> f64 {
    if (span - TAU).abs() <= RECOGNITION_TOLERANCE * TAU {
        TAU
    } else {
        span
    }
}

/// The rational quadratic arc `θ ↦ center + cos θ x_axis + sin θ y_axis` for
/// θ ∈ [start, start + span], 0 < span ≤ 2π, in ⌈span / 90°⌉ pieces (Piegl & Tiller A7.1):
/// knots at the piece angles, middle control points at `1 / cos(Δ/2)` with weight `cos(Δ/2)`.
/// Returns (knots, control points, weights); a full turn ends exactly on its first point.
fn rational_arc(
    center: [f64; 3],
    x_axis: [f64; 3],
    y_axis: [f64; 3],
    start: f64,
    span: f64,
) -> (Vec<f64>, Vec<[f64; 3]>, Vec<f64>) {
    // 1e-9: a span of 90° written with rounding stays one piece
    let pieces = ((span / FRAC_PI_2) - 1e-9).ceil().max(1.0) as usize;
    let delta = span / pieces as f64;
    let middle_weight = (0.5 * delta).cos();
    let at = |theta: f64, s: f64| {
        add(
            center,
            add(
                scale(x_axis, s * theta.cos()),
                scale(y_axis, s * theta.sin()),
            ),
        )
    };
    let mut knots = vec![start; 3];
    let mut points = Vec::with_capacity(2 * pieces + 1);
    let mut weights = Vec::with_capacity(2 * pieces + 1);
    for i in 0..2 * pieces + 1 {
        let theta = start + 0.5 * delta * i as f64;
        if i % 2 == 1 {
            points.push(at(theta, 1.0 / middle_weight));
            weights.push(middle_weight);
        } else {
            points.push(at(theta, 1.0));
            weights.push(1.0);
        }
    }
    for k in 1..pieces {
        knots.extend([start + delta * k as f64; 2]);
    }
    knots.extend([start + span; 3]);
    if span == TAU {
        points[2 * pieces] = points[0];
    }
    (knots, points, weights)
}

/// A 100 circular arc in its definition space: centre `(center, zt)`, counter-clockwise about
/// z from `start` to `end`, the full circle when they coincide. Parameter = angle (radians).
pub(super) fn circular_arc(
    zt: f64,
    center: [f64; 2],
    start: [f64; 2],
    end: [f64; 2],
) -> Result<NurbsCurve, String> {
    let (sx, sy) = (start[0] - center[0], start[1] - center[1]);
    let radius = sx.hypot(sy);
    if !(radius.is_finite() && radius > 0.0) {
        return Err(format!("circular arc of radius {radius}"));
    }
    let theta0 = sy.atan2(sx);
    let span = arc_span(
        theta0,
        [end[0] - center[0], end[1] - center[1]],
        start,
        end,
        radius,
    );
    let (knots, points, weights) = rational_arc(
        [center[0], center[1], zt],
        [radius, 0.0, 0.0],
        [0.0, radius, 0.0],
        theta0,
        span,
    );
    NurbsCurve::new(2, knots, points, weights).map_err(|e| e.to_string())
}

/// Counter-clockwise angle from `theta0` to the direction `to`; 2π when the arc's `start`
/// and `end` coincide.
fn arc_span(theta0: f64, to: [f64; 2], start: [f64; 2], end: [f64; 2], size: f64) -> f64 {
    let gap = (start[0] - end[0]).hypot(start[1] - end[1]);
    if gap <= RECOGNITION_TOLERANCE * size {
        return TAU;
    }
    let mut span = to[1].atan2(to[0]) - theta0;
    while span <= 0.0 {
        span += TAU;
    }
    snap_full_turn(span.min(TAU))
}

/// A 104 conic arc in standard position. Ellipses `x²/a² + y²/b² = 1` (A x² + C y² + F = 0)
/// are the unit-circle arc scaled by (a, b): exact. Parabolas and hyperbolas are refused.
pub(super) fn elliptic_arc(
    coefficients: [f64; 6],
    zt: f64,
    start: [f64; 2],
    end: [f64; 2],
) -> Result<NurbsCurve, String> {
    let [a, b, c, d, e, f] = coefficients;
    let size = coefficients.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !((a * c).is_finite() && a * c > 0.0) {
        return Err("only elliptic conic arcs (A C > 0) are converted".into());
    }
    if [b, d, e]
        .iter()
        .any(|x| x.abs() > RECOGNITION_TOLERANCE * size)
    {
        return Err("conic arc not in standard position (B, D, E must be 0)".into());
    }
    let (a2, b2) = (-f / a, -f / c);
    if !(a2 > 0.0 && b2 > 0.0) {
        return Err("the conic has no real points".into());
    }
    let (ra, rb) = (a2.sqrt(), b2.sqrt());
    let unit = |p: [f64; 2]| [p[0] / ra, p[1] / rb];
    let (s, t) = (unit(start), unit(end));
    let theta0 = s[1].atan2(s[0]);
    let span = arc_span(theta0, t, s, t, 1.0);
    let (knots, points, weights) =
        rational_arc([0.0, 0.0, zt], [ra, 0.0, 0.0], [0.0, rb, 0.0], theta0, span);
    NurbsCurve::new(2, knots, points, weights).map_err(|e| e.to_string())
}

/// The line segment from `start` to `end`, degree 1 on [0, 1].
pub(super) fn line_segment(start: [f64; 3], end: [f64; 3]) -> Result<NurbsCurve, NurbsError> {
    NurbsCurve::non_rational(1, vec![0.0, 0.0, 1.0, 1.0], vec![start, end])
}

/// The curve restricted to `[lo, hi]` when that lies strictly inside its domain (split at the
/// ends); parameters are kept.
pub(super) fn restrict_curve(c: NurbsCurve, lo: f64, hi: f64) -> Result<NurbsCurve, String> {
    let (a, b) = c.domain();
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(format!("empty parameter range [{lo}, {hi}]"));
    }
    let eps = 1e-12 * (b - a);
    let mut c = c;
    if lo > a + eps && lo < b - eps {
        c = c.split_at(lo).map_err(|e| e.to_string())?.1;
    }
    if hi < b - eps && hi > a + eps {
        c = c.split_at(hi).map_err(|e| e.to_string())?.0;
    }
    Ok(c)
}

/// The surface with u and v exchanged.
fn transpose(s: &NurbsSurface) -> NurbsSurface {
    let (n_u, n_v) = (s.n_u(), s.n_v());
    let mut control_points = Vec::with_capacity(n_u * n_v);
    let mut weights = Vec::with_capacity(n_u * n_v);
    for j in 0..n_v {
        for i in 0..n_u {
            control_points.push(s.control_points[i * n_v + j]);
            weights.push(s.weights[i * n_v + j]);
        }
    }
    NurbsSurface {
        degree_u: s.degree_v,
        degree_v: s.degree_u,
        knots_u: s.knots_v.clone(),
        knots_v: s.knots_u.clone(),
        control_points,
        weights,
    }
}

/// The surface restricted to `u ∈ [lo, hi]`: every column of control points (fixed v index)
/// is a curve in u restricted alike; all get the same new knot vector.
fn restrict_surface_u(s: NurbsSurface, lo: f64, hi: f64) -> Result<NurbsSurface, String> {
    let ((a, b), _) = s.domain();
    let eps = 1e-12 * (b - a);
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(format!("empty parameter range [{lo}, {hi}]"));
    }
    if lo <= a + eps && hi >= b - eps {
        return Ok(s);
    }
    let (n_u, n_v) = (s.n_u(), s.n_v());
    let mut columns = Vec::with_capacity(n_v);
    for j in 0..n_v {
        let column = NurbsCurve {
            degree: s.degree_u,
            knots: s.knots_u.clone(),
            control_points: (0..n_u).map(|i| s.control_points[i * n_v + j]).collect(),
            weights: (0..n_u).map(|i| s.weights[i * n_v + j]).collect(),
        };
        columns.push(restrict_curve(column, lo, hi)?);
    }
    let n = columns[0].control_points.len();
    let mut control_points = Vec::with_capacity(n * n_v);
    let mut weights = Vec::with_capacity(n * n_v);
    for i in 0..n {
        for column in &columns {
            control_points.push(column.control_points[i]);
            weights.push(column.weights[i]);
        }
    }
    NurbsSurface::new(
        s.degree_u,
        s.degree_v,
        columns[0].knots.clone(),
        s.knots_v,
        control_points,
        weights,
    )
    .map_err(|e| e.to_string())
}

/// A 128 rational B-spline surface on its `[U0, U1] × [V0, V1]` range, knots as given.
pub(super) fn bspline_surface(d: &BSplineSurfaceData) -> Result<NurbsSurface, String> {
    let (n_u, n_v) = (d.k1 + 1, d.k2 + 1);
    // IGES stores the u index fastest; NurbsSurface is row-major in u.
    let mut control_points = Vec::with_capacity(n_u * n_v);
    let mut weights = Vec::with_capacity(n_u * n_v);
    for i in 0..n_u {
        for j in 0..n_v {
            control_points.push(d.control_points[i + n_u * j]);
            weights.push(d.weights[i + n_u * j]);
        }
    }
    let s = NurbsSurface::new(
        d.m1,
        d.m2,
        d.knots_u.clone(),
        d.knots_v.clone(),
        control_points,
        weights,
    )
    .map_err(|e| e.to_string())?;
    let s = restrict_surface_u(s, d.u0, d.u1)?;
    let s = restrict_surface_u(transpose(&s), d.v0, d.v1)?;
    Ok(transpose(&s))
}

/// Revolves `generatrix` about the axis through `origin` with unit direction `axis`
/// (right-handed) from angle `start` through `span` ∈ (0, 2π]: each control point `Q_j` of
/// weight `w_j` sweeps the rational arc about its foot `O_j` on the axis, with `Q_j − O_j`
/// and `axis × (Q_j − O_j)` as its frame; weights multiply (Piegl & Tiller A8.1).
pub(super) fn revolve_curve(
    generatrix: &NurbsCurve,
    origin: [f64; 3],
    axis: [f64; 3],
    start: f64,
    span: f64,
) -> Result<NurbsSurface, NurbsError> {
    let n_v = generatrix.control_points.len();
    let mut columns = Vec::with_capacity(n_v);
    let mut knots_u = Vec::new();
    for &q in &generatrix.control_points {
        let foot = add(origin, scale(axis, dot(sub(q, origin), axis)));
        let radial = sub(q, foot);
        let (knots, points, weights) = rational_arc(foot, radial, cross(axis, radial), start, span);
        knots_u = knots;
        columns.push((points, weights));
    }
    let n_u = knots_u.len() - 3;
    let mut control_points = Vec::with_capacity(n_u * n_v);
    let mut weights = Vec::with_capacity(n_u * n_v);
    for i in 0..n_u {
        for (column, w) in columns.iter().zip(&generatrix.weights) {
            control_points.push(column.0[i]);
            weights.push(column.1[i] * w);
        }
    }
    NurbsSurface::new(
        2,
        generatrix.degree,
        knots_u,
        generatrix.knots.clone(),
        control_points,
        weights,
    )
}

/// Sweeps `directrix` along `sweep`: `S(u, v) = C(u) + v sweep`, v ∈ [0, 1] (degree 1).
pub(super) fn extrude_curve(
    directrix: &NurbsCurve,
    sweep: [f64; 3],
) -> Result<NurbsSurface, NurbsError> {
    let mut control_points = Vec::with_capacity(2 * directrix.control_points.len());
    let mut weights = Vec::with_capacity(2 * directrix.control_points.len());
    for (&p, &w) in directrix.control_points.iter().zip(&directrix.weights) {
        control_points.extend([p, add(p, sweep)]);
        weights.extend([w, w]);
    }
    NurbsSurface::new(
        directrix.degree,
        1,
        directrix.knots.clone(),
        vec![0.0, 0.0, 1.0, 1.0],
        control_points,
        weights,
    )
}

/// Homogeneous control points `[w x, w y, w z, w]`.
pub(super) type Homogeneous = [f64; 4];

pub(super) fn to_homogeneous(p: [f64; 3], w: f64) -> Homogeneous {
    [p[0] * w, p[1] * w, p[2] * w, w]
}

pub(super) fn from_homogeneous(h: Homogeneous) -> [f64; 3] {
    [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
}

/// The rational Bézier pieces of a clamped curve, each with its parameter length: every
/// interior knot raised to multiplicity p, all in one pass (Piegl & Tiller A5.6), so that a
/// curve of n control points costs O(n p²), not a knot insertion of O(n) per knot.
fn bezier_pieces(c: &NurbsCurve) -> Result<Vec<(Vec<Homogeneous>, f64)>, String> {
    let p = c.degree;
    let n = c.control_points.len();
    let u = &c.knots;
    let clamped = u[..=p].iter().all(|&k| k == u[0]) && u[n..].iter().all(|&k| k == u[n + p]);
    if !clamped {
        return Err("a member with an unclamped knot vector cannot be joined".into());
    }
    if u[p + 1] == u[p] || u[n - 1] == u[n] {
        // the decomposition below needs ends of multiplicity exactly p + 1
        return Err(
            "a member with an end knot of multiplicity above p + 1 cannot be joined".into(),
        );
    }
    let pw: Vec<Homogeneous> = c
        .control_points
        .iter()
        .zip(&c.weights)
        .map(|(&x, &w)| to_homogeneous(x, w))
        .collect();
    let m = n + p; // index of the last knot
    let (mut a, mut b) = (p, p + 1);
    let mut piece = pw[..=p].to_vec();
    let mut alphas = vec![0.0; p];
    let mut out = Vec::new();
    while b < m {
        let first = b;
        while b < m && u[b + 1] == u[b] {
            b += 1;
        }
        let mult = b - first + 1;
        if b < m && mult > p {
            return Err(
                "a member with a knot of multiplicity above its degree cannot be joined".into(),
            );
        }
        let mut next = vec![[0.0; 4]; p + 1];
        if mult < p {
            // insert u[b] until its multiplicity is p, keeping the control points that
            // begin the next piece
            let numerator = u[b] - u[a];
            for j in (mult + 1..=p).rev() {
                alphas[j - mult - 1] = numerator / (u[a + j] - u[a]);
            }
            let r = p - mult;
            for j in 1..=r {
                let s = mult + j;
                for k in (s..=p).rev() {
                    let alpha = alphas[k - s];
                    for d in 0..4 {
                        piece[k][d] = alpha * piece[k][d] + (1.0 - alpha) * piece[k - 1][d];
                    }
                }
                next[r - j] = piece[p];
            }
        }
        out.push((std::mem::take(&mut piece), u[b] - u[a]));
        if b < m {
            for i in p - mult..=p {
                next[i] = pw[b - p + i];
            }
            piece = next;
            a = b;
            b += 1;
        }
    }
    Ok(out)
}

/// Degree elevation of a rational Bézier piece by one, in homogeneous coordinates:
/// `Q_i = i/(q+1) P_{i−1} + (1 − i/(q+1)) P_i`.
pub(super) fn elevate(piece: &[Homogeneous]) -> Vec<Homogeneous> {
    let q = piece.len() - 1;
    let mut out = Vec::with_capacity(q + 2);
    out.push(piece[0]);
    for i in 1..=q {
        let a = i as f64 / (q + 1) as f64;
        let mut h = [0.0; 4];
        for d in 0..4 {
            h[d] = a * piece[i - 1][d] + (1.0 - a) * piece[i][d];
        }
        out.push(h);
    }
    out.push(piece[q]);
    out
}

/// Joins curves end to start into one NURBS of the highest degree with C⁰ joins. Each member
/// keeps its parameter speed (its domain is shifted to follow the previous one); its weights
/// are rescaled so that the shared control point has one weight. Ends further apart than
/// `gap_tolerance` are an error.
pub(super) fn concatenate(parts: &[NurbsCurve], gap_tolerance: f64) -> Result<NurbsCurve, String> {
    if parts.len() == 1 {
        return Ok(parts[0].clone());
    }
    let p = parts.iter().map(|c| c.degree).max().unwrap_or(1);
    let mut t = parts.first().map_or(0.0, |c| c.domain().0);
    let mut knots = vec![t; p + 1];
    let mut points: Vec<Homogeneous> = Vec::new();
    for (k, part) in parts.iter().enumerate() {
        let mut pieces = bezier_pieces(part)?;
        for piece in &mut pieces {
            while piece.0.len() < p + 1 {
                piece.0 = elevate(&piece.0);
            }
        }
        if let Some(&last) = points.last() {
            let first = pieces[0].0[0];
            let gap = distance(from_homogeneous(last), from_homogeneous(first));
            if gap > gap_tolerance {
                return Err(format!(
                    "member {} starts {gap:e} away from where member {k} ends",
                    k + 1
                ));
            }
            let factor = last[3] / first[3];
            for piece in &mut pieces {
                for h in &mut piece.0 {
                    *h = h.map(|x| x * factor);
                }
            }
        }
        for (piece, length) in pieces {
            if points.is_empty() {
                points.extend_from_slice(&piece);
            } else {
                knots.extend(std::iter::repeat_n(t, p));
                points.extend_from_slice(&piece[1..]);
            }
            t += length;
        }
    }
    knots.extend(std::iter::repeat_n(t, p + 1));
    let weights = points.iter().map(|h| h[3]).collect();
    let control_points = points.into_iter().map(from_homogeneous).collect();
    NurbsCurve::new(p, knots, control_points, weights).map_err(|e| e.to_string())
}

/// A plane patch (degree 1 × 1) in model space. The plane `A x + B y + C z = D` is given in
/// its definition space and `placed` maps it to model space; the patch is the rectangle, in
/// an orthonormal in-plane frame, over the projections of `cover`, widened by
/// [`PLANE_MARGIN`] of its larger side on every side.
pub(super) fn plane_patch(
    coefficients: [f64; 4],
    placed: &Affine,
    cover: &[[f64; 3]],
) -> Result<NurbsSurface, String> {
    let (origin, [g1, g2, _]) = model_plane(coefficients, placed)?;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &x in cover {
        let d = sub(x, origin);
        for (k, g) in [g1, g2].into_iter().enumerate() {
            lo[k] = lo[k].min(dot(d, g));
            hi[k] = hi[k].max(dot(d, g));
        }
    }
    let side = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    if !(side.is_finite() && side > 0.0) {
        return Err("the plane's boundary has no extent".into());
    }
    let margin = PLANE_MARGIN * side;
    let corner = |s: f64, t: f64| add(origin, add(scale(g1, s), scale(g2, t)));
    let (s0, s1) = (lo[0] - margin, hi[0] + margin);
    let (t0, t1) = (lo[1] - margin, hi[1] + margin);
    NurbsSurface::new(
        1,
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        vec![
            corner(s0, t0),
            corner(s0, t1),
            corner(s1, t0),
            corner(s1, t1),
        ],
        vec![1.0; 4],
    )
    .map_err(|e| e.to_string())
}

/// A point of the plane and an orthonormal frame `(g1, g2, n)` of it, in model space.
pub(super) fn model_plane(
    coefficients: [f64; 4],
    placed: &Affine,
) -> Result<([f64; 3], [[f64; 3]; 3]), String> {
    let [a, b, c, d] = coefficients;
    let n = [a, b, c];
    let [e1, e2, _] = orthonormal_frame(n).map_err(|_| format!("plane normal {n:?} is zero"))?;
    let origin = apply(placed, scale(n, d / dot(n, n)));
    let f1 = apply_linear(placed, e1);
    let normal = cross(f1, apply_linear(placed, e2));
    if !(norm(normal) > 0.0 && norm(f1) > 0.0) {
        return Err("the transformation matrix flattens the plane".into());
    }
    let normal = scale(normal, 1.0 / norm(normal));
    let g1 = scale(f1, 1.0 / norm(f1));
    Ok((origin, [g1, cross(normal, g1), normal]))
}
