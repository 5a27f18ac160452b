//! The 108 plane as a bilinear patch in model space: an IGES plane has no parametrisation of
//! its own, so the patch is a rectangle of an orthonormal in-plane frame around what it must
//! cover.

use super::affine::{apply, apply_linear, Affine};
use crate::shapes::orthonormal_frame;
use crate::vec3::{add, cross, dot, norm, scale, sub};
use crate::NurbsSurface;

/// Relative margin added on every side of a plane's patch around what it must cover.
const PLANE_MARGIN: f64 = 0.1;

/// A plane patch (degree 1 × 1) in model space. The plane `A x + B y + C z = D` is given in
/// its definition space and `placed` maps it to model space; the patch is the rectangle, in
/// an orthonormal in-plane frame, over the projections of `cover`, widened by
/// [`PLANE_MARGIN`] of its larger side on every side.
pub(crate) fn plane_patch(
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
