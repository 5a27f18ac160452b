//! Exact rational NURBS of circles, spheres, cylinders, cones and tori (Piegl & Tiller Ch. 7–8:
//! the nine-point quadratic circle and surfaces of revolution), and the same shapes as
//! [`AnalyticShape`]s with closed-form closest points (the fast path for point projection).
//!
//! Parametrisations of the NURBS: the circle runs once around, counter-clockwise about its
//! normal, for u ∈ [0, 1], starting on the frame's first axis ([`orthonormal_frame`]). Surfaces
//! of revolution have u around the axis (that circle) and v along the profile; the sphere's
//! profile runs from the south pole (v = 0) to the north pole (v = 1), so its edges v = 0 and
//! v = 1 are poles.

use crate::vec3::{self, add, cross, dot, norm, scale, sub};
use crate::{NurbsCurve, NurbsError, NurbsSurface};
use std::f64::consts::{FRAC_1_SQRT_2, PI};

/// Knots of the nine-point full circle.
const CIRCLE_KNOTS: [f64; 12] = [
    0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
];
/// Control points (x, y) of the unit circle: the corners of the square [-1, 1]².
const UNIT_CIRCLE: [[f64; 2]; 9] = [
    [1.0, 0.0],
    [1.0, 1.0],
    [0.0, 1.0],
    [-1.0, 1.0],
    [-1.0, 0.0],
    [-1.0, -1.0],
    [0.0, -1.0],
    [1.0, -1.0],
    [1.0, 0.0],
];

fn circle_weight(i: usize) -> f64 {
    if i.is_multiple_of(2) {
        1.0
    } else {
        FRAC_1_SQRT_2
    }
}

/// A right-handed orthonormal frame `(e1, e2, a)` with `a = axis / |axis|`; for the z axis it
/// is `(x, y, z)`.
pub fn orthonormal_frame(axis: [f64; 3]) -> Result<[[f64; 3]; 3], NurbsError> {
    let length = norm(axis);
    if !(length.is_finite() && length > 0.0) {
        return Err(NurbsError::InvalidShape {
            shape: "axis",
            reason: format!("axis {axis:?} has no direction"),
        });
    }
    let a = scale(axis, 1.0 / length);
    // Helper: the coordinate axis least aligned with a.
    let mut helper = [0.0; 3];
    let mut best = 0;
    for d in 1..3 {
        if a[d].abs() < a[best].abs() {
            best = d;
        }
    }
    helper[best] = 1.0;
    let e1 = sub(helper, scale(a, dot(helper, a)));
    let e1 = scale(e1, 1.0 / norm(e1));
    let e2 = cross(a, e1);
    Ok([e1, e2, a])
}

fn check_radius(shape: &'static str, name: &str, r: f64) -> Result<(), NurbsError> {
    if r.is_finite() && r > 0.0 {
        Ok(())
    } else {
        Err(NurbsError::InvalidShape {
            shape,
            reason: format!("{name} must be finite and > 0, got {r}"),
        })
    }
}

/// The full circle of `radius` about `center` in the plane normal to `normal`: degree 2,
/// nine control points, weights 1 and √2/2.
pub fn circle(center: [f64; 3], normal: [f64; 3], radius: f64) -> Result<NurbsCurve, NurbsError> {
    check_radius("circle", "radius", radius)?;
    let [e1, e2, _] = orthonormal_frame(normal)?;
    let control_points = UNIT_CIRCLE
        .iter()
        .map(|c| add(center, scale(add(scale(e1, c[0]), scale(e2, c[1])), radius)))
        .collect();
    let weights = (0..9).map(circle_weight).collect();
    NurbsCurve::new(2, CIRCLE_KNOTS.to_vec(), control_points, weights)
}

/// Surface of revolution of a profile given in the meridian half-plane as `(ρ, ζ)`
/// (distance from the axis, height along it), with its weights and knots, about the axis
/// through `center` with direction `axis` (A8.1 with a full turn).
fn revolve(
    center: [f64; 3],
    axis: [f64; 3],
    profile_degree: usize,
    profile_knots: &[f64],
    profile: &[[f64; 2]],
    profile_weights: &[f64],
) -> Result<NurbsSurface, NurbsError> {
    let [e1, e2, a] = orthonormal_frame(axis)?;
    let mut control_points = Vec::with_capacity(9 * profile.len());
    let mut weights = Vec::with_capacity(9 * profile.len());
    for (i, c) in UNIT_CIRCLE.iter().enumerate() {
        let radial = add(scale(e1, c[0]), scale(e2, c[1]));
        for (pr, &wp) in profile.iter().zip(profile_weights) {
            control_points.push(add(center, add(scale(radial, pr[0]), scale(a, pr[1]))));
            weights.push(circle_weight(i) * wp);
        }
    }
    NurbsSurface::new(
        2,
        profile_degree,
        CIRCLE_KNOTS.to_vec(),
        profile_knots.to_vec(),
        control_points,
        weights,
    )
}

/// The sphere of `radius` about `center`, axis z: u ∈ [0, 1] around the axis, v ∈ [0, 1]
/// from the south pole to the north pole (both poles are degenerate edges).
pub fn sphere(center: [f64; 3], radius: f64) -> Result<NurbsSurface, NurbsError> {
    check_radius("sphere", "radius", radius)?;
    let r = radius;
    revolve(
        center,
        [0.0, 0.0, 1.0],
        2,
        &[0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0],
        &[[0.0, -r], [r, -r], [r, 0.0], [r, r], [0.0, r]],
        &[1.0, FRAC_1_SQRT_2, 1.0, FRAC_1_SQRT_2, 1.0],
    )
}

/// The bilinear patch S(u, v) through four corners, `corners[i][j]` at u = i, v = j
/// (a plane's rectangle when they are coplanar and opposite sides parallel).
pub fn bilinear_patch(corners: [[[f64; 3]; 2]; 2]) -> Result<NurbsSurface, NurbsError> {
    NurbsSurface::new(
        1,
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        vec![corners[0][0], corners[0][1], corners[1][0], corners[1][1]],
        vec![1.0; 4],
    )
}

/// The piece `axial_range.0 ≤ t ≤ axial_range.1` of the cylinder of `radius` whose axis passes
/// through `point` with direction `axis`; v ∈ [0, 1] is linear in t.
pub fn cylinder(
    point: [f64; 3],
    axis: [f64; 3],
    radius: f64,
    axial_range: (f64, f64),
) -> Result<NurbsSurface, NurbsError> {
    check_radius("cylinder", "radius", radius)?;
    let (t0, t1) = axial_range;
    if !(t0.is_finite() && t1.is_finite() && t0 < t1) {
        return Err(NurbsError::InvalidShape {
            shape: "cylinder",
            reason: format!("axial range [{t0}, {t1}] is empty"),
        });
    }
    revolve(
        point,
        axis,
        1,
        &[0.0, 0.0, 1.0, 1.0],
        &[[radius, t0], [radius, t1]],
        &[1.0, 1.0],
    )
}

/// Checks a cone's half-angle: in (0, π/2).
fn check_half_angle(half_angle: f64) -> Result<(), NurbsError> {
    if half_angle > 0.0 && half_angle < 0.5 * PI {
        Ok(())
    } else {
        Err(NurbsError::InvalidShape {
            shape: "cone",
            reason: format!("half-angle {half_angle} (radians) must be in (0, π/2)"),
        })
    }
}

/// The piece `axial_range.0 ≤ h ≤ axial_range.1` (0 ≤ h₀ < h₁, heights from the apex along
/// `axis`) of the cone with `apex` opening along `axis` at `half_angle`: radius h tan α at
/// height h; v ∈ [0, 1] is linear in h.
pub fn cone(
    apex: [f64; 3],
    axis: [f64; 3],
    half_angle: f64,
    axial_range: (f64, f64),
) -> Result<NurbsSurface, NurbsError> {
    check_half_angle(half_angle)?;
    let (h0, h1) = axial_range;
    if !(h0.is_finite() && h1.is_finite() && 0.0 <= h0 && h0 < h1) {
        return Err(NurbsError::InvalidShape {
            shape: "cone",
            reason: format!("axial range [{h0}, {h1}] must satisfy 0 ≤ h₀ < h₁"),
        });
    }
    let t = half_angle.tan();
    revolve(
        apex,
        axis,
        1,
        &[0.0, 0.0, 1.0, 1.0],
        &[[h0 * t, h0], [h1 * t, h1]],
        &[1.0, 1.0],
    )
}

/// The torus about `center` and `axis` with distance `major_radius` from the axis to the tube
/// centre and tube radius `minor_radius < major_radius`; v ∈ [0, 1] goes once around the tube,
/// starting on the outer equator.
pub fn torus(
    center: [f64; 3],
    axis: [f64; 3],
    major_radius: f64,
    minor_radius: f64,
) -> Result<NurbsSurface, NurbsError> {
    check_radius("torus", "major_radius", major_radius)?;
    check_radius("torus", "minor_radius", minor_radius)?;
    if minor_radius >= major_radius {
        return Err(NurbsError::InvalidShape {
            shape: "torus",
            reason: format!(
                "minor_radius {minor_radius} must be below major_radius {major_radius}"
            ),
        });
    }
    let profile: Vec<[f64; 2]> = UNIT_CIRCLE
        .iter()
        .map(|c| [major_radius + minor_radius * c[0], minor_radius * c[1]])
        .collect();
    let weights: Vec<f64> = (0..9).map(circle_weight).collect();
    revolve(center, axis, 2, &CIRCLE_KNOTS, &profile, &weights)
}

/// The band of the torus of [`torus`] between tube angles `start` and `start + span`
/// (radians from the outer equator towards `axis`, 0 < span ≤ 2π): the part of the tube a
/// face covers (a fillet's quarter), so that paths on the patch stay on the face rather
/// than run over the tube beyond its edge. v is the tube angle.
pub fn torus_band(
    center: [f64; 3],
    axis: [f64; 3],
    major_radius: f64,
    minor_radius: f64,
    start: f64,
    span: f64,
) -> Result<NurbsSurface, NurbsError> {
    check_radius("torus", "major_radius", major_radius)?;
    check_radius("torus", "minor_radius", minor_radius)?;
    if minor_radius >= major_radius || !(span > 0.0 && span <= 2.0 * PI) || !start.is_finite() {
        return Err(NurbsError::InvalidShape {
            shape: "torus band",
            reason: format!(
                "minor_radius {minor_radius} must be below major_radius {major_radius}, \
                 the span {span} in (0, 2π]"
            ),
        });
    }
    let (knots, points, weights) = crate::conics::rational_arc(
        [major_radius, 0.0, 0.0],
        [minor_radius, 0.0, 0.0],
        [0.0, minor_radius, 0.0],
        start,
        span,
    );
    let profile: Vec<[f64; 2]> = points.iter().map(|p| [p[0], p[1]]).collect();
    revolve(center, axis, 2, &knots, &profile, &weights)
}

/// A shape with a closed-form closest point. Axes are stored normalised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnalyticShape {
    /// Circle in the plane through `center` normal to `normal`.
    Circle {
        center: [f64; 3],
        normal: [f64; 3],
        radius: f64,
    },
    /// Sphere.
    Sphere { center: [f64; 3], radius: f64 },
    /// Infinite circular cylinder about the line through `point` along `axis`.
    Cylinder {
        point: [f64; 3],
        axis: [f64; 3],
        radius: f64,
    },
    /// One nappe of an infinite circular cone: the points at height h ≥ 0 above `apex`
    /// along `axis` and radius h tan(`half_angle`) from it.
    Cone {
        apex: [f64; 3],
        axis: [f64; 3],
        half_angle: f64,
    },
    /// Torus: tube of `minor_radius` around the circle of `major_radius` about `axis`.
    Torus {
        center: [f64; 3],
        axis: [f64; 3],
        major_radius: f64,
        minor_radius: f64,
    },
}

/// The result of a closest-point query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint<P> {
    /// Parameter of the closest point.
    pub param: P,
    /// The closest point.
    pub point: [f64; 3],
    /// Distance from the query point to `point`.
    pub distance: f64,
}

impl AnalyticShape {
    /// Validates the sizes and normalises the axis.
    pub fn new_circle(center: [f64; 3], normal: [f64; 3], radius: f64) -> Result<Self, NurbsError> {
        check_radius("circle", "radius", radius)?;
        let normal = orthonormal_frame(normal)?[2];
        Ok(Self::Circle {
            center,
            normal,
            radius,
        })
    }

    /// Validates the radius.
    pub fn new_sphere(center: [f64; 3], radius: f64) -> Result<Self, NurbsError> {
        check_radius("sphere", "radius", radius)?;
        Ok(Self::Sphere { center, radius })
    }

    /// Validates the radius and normalises the axis.
    pub fn new_cylinder(point: [f64; 3], axis: [f64; 3], radius: f64) -> Result<Self, NurbsError> {
        check_radius("cylinder", "radius", radius)?;
        let axis = orthonormal_frame(axis)?[2];
        Ok(Self::Cylinder {
            point,
            axis,
            radius,
        })
    }

    /// Validates the half-angle (in (0, π/2)) and normalises the axis (pointing from the
    /// apex into the nappe).
    pub fn new_cone(apex: [f64; 3], axis: [f64; 3], half_angle: f64) -> Result<Self, NurbsError> {
        check_half_angle(half_angle)?;
        let axis = orthonormal_frame(axis)?[2];
        Ok(Self::Cone {
            apex,
            axis,
            half_angle,
        })
    }

    /// Validates the radii (`0 < minor < major`) and normalises the axis.
    pub fn new_torus(
        center: [f64; 3],
        axis: [f64; 3],
        major_radius: f64,
        minor_radius: f64,
    ) -> Result<Self, NurbsError> {
        torus(center, axis, major_radius, minor_radius)?;
        let axis = orthonormal_frame(axis)?[2];
        Ok(Self::Torus {
            center,
            axis,
            major_radius,
            minor_radius,
        })
    }

    /// The closest point to `x` in closed form. The parameter is in angles, with the frame of
    /// [`orthonormal_frame`] of the axis (normal): circle `[θ, 0]`; sphere `[θ, φ]` (longitude
    /// about z, latitude in [-π/2, π/2]); cylinder `[θ, t]` (t the axial coordinate from
    /// `point`); cone `[θ, s]` (s the distance from the apex along the surface); torus `[θ, φ]`
    /// (φ the angle around the tube, 0 on the outer equator). θ lies in
    /// [0, 2π). Where the closest point is not unique (x on the axis, at the centre), one of
    /// them is returned.
    pub fn closest_point(&self, x: [f64; 3]) -> ClosestPoint<[f64; 2]> {
        match *self {
            Self::Circle {
                center,
                normal,
                radius,
            } => {
                let [e1, e2, n] = frame(normal);
                let d = sub(x, center);
                let radial = sub(d, scale(n, dot(d, n)));
                let (dir, theta) = direction_in_plane(radial, e1, e2);
                let point = add(center, scale(dir, radius));
                closest([theta, 0.0], point, x)
            }
            Self::Sphere { center, radius } => {
                let d = sub(x, center);
                let r = norm(d);
                let dir = if r > 0.0 {
                    scale(d, 1.0 / r)
                } else {
                    [1.0, 0.0, 0.0]
                };
                let point = add(center, scale(dir, radius));
                let theta = wrap_angle(dir[1].atan2(dir[0]));
                let phi = dir[2].clamp(-1.0, 1.0).asin();
                closest([theta, phi], point, x)
            }
            Self::Cylinder {
                point: p0,
                axis,
                radius,
            } => {
                let [e1, e2, a] = frame(axis);
                let d = sub(x, p0);
                let t = dot(d, a);
                let (dir, theta) = direction_in_plane(sub(d, scale(a, t)), e1, e2);
                let point = add(add(p0, scale(a, t)), scale(dir, radius));
                closest([theta, t], point, x)
            }
            Self::Cone {
                apex,
                axis,
                half_angle,
            } => {
                // In the half-plane through the axis and x: the foot on the generator
                // (sin α, cos α) in (radial, axial) coordinates, the apex where that foot
                // would lie beyond it (x inside the cone's polar cone).
                let [e1, e2, a] = frame(axis);
                let d = sub(x, apex);
                let t = dot(d, a);
                let (dir, theta) = direction_in_plane(sub(d, scale(a, t)), e1, e2);
                let rho = dot(d, dir);
                let (sin, cos) = half_angle.sin_cos();
                let along = (rho * sin + t * cos).max(0.0);
                let point = add(apex, scale(add(scale(dir, sin), scale(a, cos)), along));
                closest([theta, along], point, x)
            }
            Self::Torus {
                center,
                axis,
                major_radius,
                minor_radius,
            } => {
                let [e1, e2, a] = frame(axis);
                let d = sub(x, center);
                let t = dot(d, a);
                let radial = sub(d, scale(a, t));
                let (dir, theta) = direction_in_plane(radial, e1, e2);
                // Closest point of the tube's centre circle, then of the tube around it.
                let ring = add(center, scale(dir, major_radius));
                let (rho, z) = (dot(radial, dir) - major_radius, t);
                let len = rho.hypot(z);
                let (c, s) = if len > 0.0 {
                    (rho / len, z / len)
                } else {
                    (1.0, 0.0)
                };
                let point = add(
                    ring,
                    add(scale(dir, minor_radius * c), scale(a, minor_radius * s)),
                );
                closest([theta, wrap_angle(s.atan2(c))], point, x)
            }
        }
    }
}

fn frame(axis: [f64; 3]) -> [[f64; 3]; 3] {
    // Axes were validated on construction; a degenerate one falls back to z.
    orthonormal_frame(axis).unwrap_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
}

/// Unit direction of `v` (in the plane spanned by e1, e2) and its angle from e1.
fn direction_in_plane(v: [f64; 3], e1: [f64; 3], e2: [f64; 3]) -> ([f64; 3], f64) {
    let (x, y) = (dot(v, e1), dot(v, e2));
    let r = x.hypot(y);
    if r > 0.0 {
        let (c, s) = (x / r, y / r);
        (add(scale(e1, c), scale(e2, s)), wrap_angle(s.atan2(c)))
    } else {
        (e1, 0.0)
    }
}

fn wrap_angle(angle: f64) -> f64 {
    if angle < 0.0 {
        angle + 2.0 * PI
    } else {
        angle
    }
}

fn closest<P>(param: P, point: [f64; 3], x: [f64; 3]) -> ClosestPoint<P> {
    ClosestPoint {
        param,
        point,
        distance: vec3::distance(point, x),
    }
}

#[cfg(test)]
#[path = "tests/shapes.rs"]
mod tests;
