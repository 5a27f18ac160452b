//! Affine maps `x' = R x + T` (the 124 transformation matrix): applied to points,
//! directions and control points, composed along a chain of matrices, and recognised as
//! similarities, which carry circles, spheres, cylinders and tori to their like.

use super::tolerance::RECOGNITION_TOLERANCE;
use crate::shapes::AnalyticShape;
use crate::vec3::dot;
use crate::{NurbsCurve, NurbsSurface};

/// An affine map `x' = R x + T` as rows `[R_i1, R_i2, R_i3, T_i]` (the 124 layout).
pub(crate) type Affine = [[f64; 4]; 3];

/// The map of an entity without a 124 transformation matrix.
pub(crate) const IDENTITY: Affine = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
];

/// The map applied to the point `x`.
pub(crate) fn apply(t: &Affine, x: [f64; 3]) -> [f64; 3] {
    let mut y = [0.0; 3];
    for i in 0..3 {
        y[i] = t[i][0] * x[0] + t[i][1] * x[1] + t[i][2] * x[2] + t[i][3];
    }
    y
}

/// The linear part `R v` (for directions).
pub(crate) fn apply_linear(t: &Affine, v: [f64; 3]) -> [f64; 3] {
    let mut y = [0.0; 3];
    for i in 0..3 {
        y[i] = t[i][0] * v[0] + t[i][1] * v[1] + t[i][2] * v[2];
    }
    y
}

/// `a ∘ b`: apply `b` first, then `a`.
pub(crate) fn compose(a: &Affine, b: &Affine) -> Affine {
    let mut c = [[0.0; 4]; 3];
    for i in 0..3 {
        for j in 0..4 {
            let mut s = if j == 3 { a[i][3] } else { 0.0 };
            for k in 0..3 {
                s += a[i][k] * b[k][j];
            }
            c[i][j] = s;
        }
    }
    c
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
pub(crate) fn transform_curve(mut c: NurbsCurve, t: &Affine) -> Result<NurbsCurve, String> {
    if *t != IDENTITY {
        transform_points(&mut c.control_points, t)?;
    }
    Ok(c)
}

/// The surface with `t` applied to its control points (an error as [`transform_curve`]).
pub(crate) fn transform_surface(mut s: NurbsSurface, t: &Affine) -> Result<NurbsSurface, String> {
    if *t != IDENTITY {
        transform_points(&mut s.control_points, t)?;
    }
    Ok(s)
}

/// Applies `t` to every point, in place; an error names the first that leaves the
/// floating-point range.
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
pub(crate) fn transform_shape(shape: AnalyticShape, t: &Affine) -> Option<AnalyticShape> {
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
        AnalyticShape::Cone {
            apex,
            axis,
            half_angle,
        } => AnalyticShape::new_cone(apply(t, apex), apply_linear(t, axis), half_angle),
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
