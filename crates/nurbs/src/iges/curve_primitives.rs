//! The IGES curve primitives as exact NURBS: the 100 circular and 104 elliptic arcs, on the
//! rational quadratic arc of [`crate::conics`] (the 110 line segment is its `line_segment`).

use std::f64::consts::TAU;

use super::tolerance::RECOGNITION_TOLERANCE;
use crate::conics::rational_arc;
use crate::NurbsCurve;

/// A full turn when `span` is 2π to [`RECOGNITION_TOLERANCE`] (exactly `TAU` then).
pub(crate) fn snap_full_turn(span: f64) -> f64 {
    if (span - TAU).abs() <= RECOGNITION_TOLERANCE * TAU {
        TAU
    } else {
        span
    }
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
