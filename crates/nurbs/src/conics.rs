//! Exact NURBS of lines and circular arcs: what IGES's and STEP's curve entities, their
//! surfaces of revolution and the closed-form shapes' patches are built from.

use std::f64::consts::{FRAC_PI_2, TAU};

use crate::vec3::{add, scale};
use crate::{NurbsCurve, NurbsError};

/// The rational quadratic arc `θ ↦ center + cos θ x_axis + sin θ y_axis` for
/// θ ∈ [start, start + span], 0 < span ≤ 2π, in ⌈span / 90°⌉ pieces (Piegl & Tiller A7.1):
/// knots at the piece angles, middle control points at `1 / cos(Δ/2)` with weight `cos(Δ/2)`.
/// Returns (knots, control points, weights); a full turn ends exactly on its first point.
pub(crate) fn rational_arc(
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

/// The line segment from `start` to `end`, degree 1 on [0, 1].
pub(crate) fn line_segment(start: [f64; 3], end: [f64; 3]) -> Result<NurbsCurve, NurbsError> {
    NurbsCurve::non_rational(1, vec![0.0, 0.0, 1.0, 1.0], vec![start, end])
}
