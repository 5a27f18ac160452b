//! Local differential geometry: the frame of a surface at a point (derivatives, unit normal,
//! normal curvature) and the unit tangent at either end of a polyline that samples a curve.

use hocurve_nurbs::vec3::{cross, dot, norm, scale, sub, unit};
use hocurve_nurbs::SurfaceDerivatives;

use crate::chart::SurfaceChart;

/// First and second derivatives of a surface at a regular parameter near `uv`, with the unit
/// normal. At a degenerate point (a pole, where ∂S/∂u or ∂S/∂v vanishes) the frame is taken a
/// hair (1e-7 of the parameter range) towards the middle of the domain, where the surface is
/// regular; the normal and curvatures are continuous there, so the error is ~1e-7.
pub(crate) struct SurfaceFrame {
    pub(crate) derivatives: SurfaceDerivatives,
    pub(crate) normal: [f64; 3],
}

impl SurfaceFrame {
    pub(crate) fn at(chart: &SurfaceChart, uv: [f64; 2]) -> Option<Self> {
        let [u, v] = chart.fold(uv);
        let ((u0, u1), (v0, v1)) = chart.surface.domain();
        let (um, vm) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
        for step in [0.0, 1e-7, 1e-5] {
            let (uu, vv) = (
                u + step * (um - u).signum() * (u1 - u0),
                v + step * (vm - v).signum() * (v1 - v0),
            );
            let d = chart.surface.derivatives(uu, vv);
            let n = cross(d.du, d.dv);
            // Relative to the larger derivative: at a pole the vanishing one is round-off
            // (~1e-16) in any direction, and a test relative to |∂S/∂u| |∂S/∂v| would take
            // the cross product of that noise for the normal.
            let scale = norm(d.du).max(norm(d.dv));
            if norm(n) > 1e-8 * scale * scale && norm(n) > 0.0 {
                if let Some(normal) = unit(n) {
                    return Some(Self {
                        derivatives: d,
                        normal,
                    });
                }
            }
        }
        None
    }

    /// Normal curvature κₙ of the surface in the tangent direction `t` (any length):
    /// II(w, w) / I(w, w) with w the parameter direction whose image is `t` (Euler).
    pub(crate) fn normal_curvature(&self, t: [f64; 3]) -> f64 {
        let d = &self.derivatives;
        let (e, f, g) = (dot(d.du, d.du), dot(d.du, d.dv), dot(d.dv, d.dv));
        let (bu, bv) = (dot(d.du, t), dot(d.dv, t));
        let det = e * g - f * f;
        if det.abs() <= 0.0 {
            return 0.0;
        }
        let w = [(g * bu - f * bv) / det, (e * bv - f * bu) / det];
        let n = self.normal;
        let (l, m, nn) = (dot(n, d.duu), dot(n, d.duv), dot(n, d.dvv));
        let second = l * w[0] * w[0] + 2.0 * m * w[0] * w[1] + nn * w[1] * w[1];
        let first = e * w[0] * w[0] + 2.0 * f * w[0] * w[1] + g * w[1] * w[1];
        if first > 0.0 {
            second / first
        } else {
            0.0
        }
    }
}

/// Unit tangent at the first point of a polyline that samples a smooth curve, pointing along
/// it: the chords to the next two points, d(s₁) and d(s₂), are t + (s/2)κ + O(s²), so the
/// extrapolation (s₂ d(s₁) − s₁ d(s₂)) / (s₂ − s₁) is second-order accurate.
pub(crate) fn start_tangent(points: &[[f64; 3]]) -> Option<[f64; 3]> {
    let p0 = *points.first()?;
    let c1 = sub(*points.get(1)?, p0);
    let d1 = unit(c1)?;
    let Some(p2) = points.get(2) else {
        return Some(d1);
    };
    let c2 = sub(*p2, p0);
    let (s1, s2) = (norm(c1), norm(c2));
    match unit(c2) {
        Some(d2) if s2 > s1 => unit(sub(scale(d1, s2), scale(d2, s1))),
        _ => Some(d1),
    }
}

/// Unit tangent of a polyline at its first point (`at_end = false`) or its last, pointing
/// into the polyline.
pub(crate) fn end_tangent(points: &[[f64; 3]], at_end: bool) -> Option<[f64; 3]> {
    if at_end {
        let reversed: Vec<[f64; 3]> = points.iter().rev().copied().collect();
        start_tangent(&reversed)
    } else {
        start_tangent(points)
    }
}
