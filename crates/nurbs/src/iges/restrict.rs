//! 126 and 128 rational B-splines restricted to the parameter ranges the file gives them
//! (split at the range's ends), and the 128 surface's control net reordered to
//! [`NurbsSurface`]'s layout.

use super::entities::BSplineSurfaceData;
use crate::{NurbsCurve, NurbsSurface};

/// The curve restricted to `[lo, hi]` when that lies strictly inside its domain (split at the
/// ends); parameters are kept.
pub(crate) fn restrict_curve(c: NurbsCurve, lo: f64, hi: f64) -> Result<NurbsCurve, String> {
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
