//! Geodesics in closed form on the analytic surfaces that have them: great circles on a
//! sphere, helices on a cylinder (straight lines of the unrolled cylinder). Points at a
//! fraction of the length come from the two end points alone — no chart, so no seam or
//! pole — and lie on the surface to rounding; the paper's bisector refinement (Eq. (5),
//! [`crate::GeodesicPath`]) converges to the same curve and stays the route for every other
//! surface.

use hocurve_nurbs::shapes::{orthonormal_frame, AnalyticShape};
use hocurve_nurbs::vec3::{add, cross, dot, norm, scale, sub};

/// A surface whose geodesics are known in closed form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ClosedFormGeodesic {
    /// Sphere: geodesics are great-circle arcs.
    GreatCircle {
        /// Centre.
        center: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// Circular cylinder: geodesics are helices, straight in (r θ, z).
    Helix {
        /// A point on the axis.
        point: [f64; 3],
        /// Orthonormal frame (e1, e2, axis).
        frame: [[f64; 3]; 3],
        /// Radius.
        radius: f64,
    },
}

impl ClosedFormGeodesic {
    /// The closed form of `shape`'s geodesics, if it has one (spheres and cylinders).
    pub fn of(shape: &AnalyticShape) -> Option<Self> {
        match *shape {
            AnalyticShape::Sphere { center, radius } => Some(Self::GreatCircle { center, radius }),
            AnalyticShape::Cylinder {
                point,
                axis,
                radius,
            } => Some(Self::Helix {
                point,
                frame: orthonormal_frame(axis).ok()?,
                radius,
            }),
            _ => None,
        }
    }

    /// The point at `fraction` ∈ [0, 1] of the length of the shortest geodesic from (the
    /// surface point nearest) `a` to (that nearest) `b`.
    ///
    /// Sphere, with unit directions â, b̂ from the centre at angle ω:
    /// x(f) = c + r (sin((1 − f)ω) â + sin(fω) b̂) / sin ω (the arc length is fωr).
    /// Cylinder, with angles θ about the axis and heights z: θ(f) = θ_a + f Δθ (Δθ the
    /// shorter way round, in (−π, π]) and z(f) = z_a + f Δz, whose length is
    /// f √((rΔθ)² + Δz²).
    pub fn at_fraction(&self, a: [f64; 3], b: [f64; 3], fraction: f64) -> [f64; 3] {
        let f = fraction.clamp(0.0, 1.0);
        match *self {
            Self::GreatCircle { center, radius } => {
                let unit = |x: [f64; 3]| {
                    let d = sub(x, center);
                    let r = norm(d);
                    if r > 0.0 {
                        scale(d, 1.0 / r)
                    } else {
                        [1.0, 0.0, 0.0]
                    }
                };
                let (ua, ub) = (unit(a), unit(b));
                let omega = norm(cross(ua, ub)).atan2(dot(ua, ub));
                let direction = if omega < 1e-8 {
                    // Nearly the same point: the chord's point, radially projected, is the
                    // arc's to O(ω³).
                    let chord = add(scale(ua, 1.0 - f), scale(ub, f));
                    scale(chord, 1.0 / norm(chord))
                } else {
                    let s = omega.sin();
                    add(
                        scale(ua, ((1.0 - f) * omega).sin() / s),
                        scale(ub, (f * omega).sin() / s),
                    )
                };
                add(center, scale(direction, radius))
            }
            Self::Helix {
                point,
                frame: [e1, e2, axis],
                radius,
            } => {
                let cylindrical = |x: [f64; 3]| {
                    let d = sub(x, point);
                    (dot(d, e2).atan2(dot(d, e1)), dot(d, axis))
                };
                let ((theta_a, z_a), (theta_b, z_b)) = (cylindrical(a), cylindrical(b));
                let mut turn = theta_b - theta_a;
                if turn > std::f64::consts::PI {
                    turn -= std::f64::consts::TAU;
                } else if turn <= -std::f64::consts::PI {
                    turn += std::f64::consts::TAU;
                }
                let theta = theta_a + f * turn;
                let z = z_a + f * (z_b - z_a);
                add(
                    add(point, scale(axis, z)),
                    add(
                        scale(e1, radius * theta.cos()),
                        scale(e2, radius * theta.sin()),
                    ),
                )
            }
        }
    }
}

#[cfg(test)]
#[path = "tests/closed_form.rs"]
mod tests;
