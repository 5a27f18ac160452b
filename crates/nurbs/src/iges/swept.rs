//! Swept surfaces as exact NURBS: a curve revolved about an axis (120 surface of revolution)
//! or translated along a vector (122 tabulated cylinder).

use crate::conics::rational_arc;
use crate::vec3::{add, cross, dot, scale, sub};
use crate::{NurbsCurve, NurbsError, NurbsSurface};

/// Revolves `generatrix` about the axis through `origin` with unit direction `axis`
/// (right-handed) from angle `start` through `span` ∈ (0, 2π]: each control point `Q_j` of
/// weight `w_j` sweeps the rational arc about its foot `O_j` on the axis, with `Q_j − O_j`
/// and `axis × (Q_j − O_j)` as its frame; weights multiply (Piegl & Tiller A8.1).
pub(crate) fn revolve_curve(
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
pub(crate) fn extrude_curve(
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
