//! Geodesics in closed form on the analytic surfaces that have them: great circles on a
//! sphere, helices on a cylinder and straight lines of the unrolled cone (both surfaces
//! develop onto the plane isometrically). Points at a
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
    /// Circular cone: unrolled about its apex into a plane sector (a point at distance s
    /// from the apex and angle θ about the axis goes to polar coordinates (s, θ sin α)),
    /// geodesics are straight segments there.
    Unrolled {
        /// The apex.
        apex: [f64; 3],
        /// Orthonormal frame (e1, e2, axis), the axis into the nappe.
        frame: [[f64; 3]; 3],
        /// Half-angle α.
        half_angle: f64,
    },
}

impl ClosedFormGeodesic {
    /// The closed form of `shape`'s geodesics, if it has one (spheres, cylinders, cones).
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
            AnalyticShape::Cone {
                apex,
                axis,
                half_angle,
            } => Some(Self::Unrolled {
                apex,
                frame: orthonormal_frame(axis).ok()?,
                half_angle,
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
    /// Cone, with distances s from the apex and angles θ about the axis: in the unrolled
    /// plane A = s_a e^{iθ_a sin α}, B = s_b e^{i(θ_a + Δθ) sin α} (Δθ the shorter way round,
    /// so the sector angle |Δθ| sin α < π and the segment misses the apex), the point is
    /// A + f (B − A), rolled back up.
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
                let turn = shorter_turn(theta_b - theta_a);
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
            Self::Unrolled {
                apex,
                frame: [e1, e2, axis],
                half_angle,
            } => {
                let (sin, cos) = half_angle.sin_cos();
                // (θ, s) of the point of the cone nearest x.
                let conical = |x: [f64; 3]| {
                    let d = sub(x, apex);
                    let (t, u, v) = (dot(d, axis), dot(d, e1), dot(d, e2));
                    (v.atan2(u), (u.hypot(v) * sin + t * cos).max(0.0))
                };
                let ((theta_a, s_a), (theta_b, s_b)) = (conical(a), conical(b));
                let turn = shorter_turn(theta_b - theta_a);
                // Unrolled with A on the first axis: B at angle turn · sin α.
                let phi = turn * sin;
                let (x, y) = (s_a + f * (s_b * phi.cos() - s_a), f * s_b * phi.sin());
                let s = x.hypot(y);
                let theta = theta_a + y.atan2(x) / sin;
                add(
                    apex,
                    scale(
                        add(
                            scale(add(scale(e1, theta.cos()), scale(e2, theta.sin())), sin),
                            scale(axis, cos),
                        ),
                        s,
                    ),
                )
            }
        }
    }
}

/// An angle difference (of two angles in (−π, π]) as the shorter turn, in (−π, π].
fn shorter_turn(turn: f64) -> f64 {
    if turn > std::f64::consts::PI {
        turn - std::f64::consts::TAU
    } else if turn <= -std::f64::consts::PI {
        turn + std::f64::consts::TAU
    } else {
        turn
    }
}

#[cfg(test)]
#[path = "tests/closed_form.rs"]
mod tests;
