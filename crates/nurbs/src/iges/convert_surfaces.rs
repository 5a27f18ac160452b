//! Surface entities as exact NURBS in model space: 108 plane patches, 120 surfaces of
//! revolution and 122 tabulated cylinders (with their closed forms: sphere, torus, cylinder),
//! 128 B-spline surfaces on their parameter ranges, and 144 trimmed surfaces as their
//! underlying surface.

use std::f64::consts::TAU;

use super::affine::{apply, compose, transform_curve, transform_shape, transform_surface, Affine};
use super::converter::{geometry_error, Converter};
use super::curve_primitives::snap_full_turn;
use super::entities::EntityData;
use super::error::IgesError;
use super::model::IgesEntity;
use super::plane_patch::plane_patch;
use super::restrict::bspline_surface;
use super::swept::{extrude_curve, revolve_curve};
use super::tolerance::RECOGNITION_TOLERANCE;
use crate::shapes::AnalyticShape;
use crate::vec3::{add, cross, distance, dot, norm, scale, sub};
use crate::NurbsSurface;

impl<'a> Converter<'a> {
    /// A surface entity in model space (`to_model` maps its parent's space there) with its
    /// closed form when it has one. `cover`: model-space points a plane patch must cover
    /// besides its own boundary.
    pub(super) fn surface(
        &self,
        e: &IgesEntity,
        to_model: &Affine,
        cover: &[[f64; 3]],
    ) -> Result<(NurbsSurface, Option<AnalyticShape>), IgesError> {
        let placed = compose(to_model, &self.own_transform(e));
        let fail = |reason: String| geometry_error(e, reason);
        let (s, analytic) = match &e.kind {
            EntityData::TrimmedSurface {
                surface,
                outer,
                inner,
                ..
            } => {
                let carrier = self.child(*surface, e)?;
                let boundaries = outer.iter().chain(inner).copied();
                let cover = self.trimmed_cover(e, carrier, boundaries, &placed, cover)?;
                return self.surface(carrier, &placed, &cover);
            }
            EntityData::Plane {
                coefficients,
                boundary,
                ..
            } => {
                let mut cover = cover.to_vec();
                if let Some(de) = boundary {
                    let c =
                        transform_curve(self.curve(self.child(*de, e)?)?, &placed).map_err(fail)?;
                    cover.extend_from_slice(&c.control_points);
                }
                if cover.is_empty() {
                    return Err(IgesError::UnboundedPlane {
                        line: e.line,
                        de: e.de,
                    });
                }
                return Ok((
                    plane_patch(*coefficients, &placed, &cover).map_err(fail)?,
                    None,
                ));
            }
            EntityData::SurfaceOfRevolution {
                axis,
                generatrix,
                start_angle,
                end_angle,
            } => self.revolution(e, *axis, *generatrix, *start_angle, *end_angle)?,
            EntityData::TabulatedCylinder { directrix, end } => {
                self.tabulated_cylinder(e, *directrix, *end)?
            }
            EntityData::BSplineSurface(d) => (bspline_surface(d).map_err(fail)?, None),
            other => {
                return Err(fail(format!(
                    "expected a surface (entity type 108, 120, 122, 128 or 144), found type {}",
                    other.type_number()
                )))
            }
        };
        Ok((
            transform_surface(s, &placed).map_err(fail)?,
            analytic.and_then(|a| transform_shape(a, &placed)),
        ))
    }

    /// A 120 surface of revolution in its definition space, and its closed form when it is a
    /// whole sphere (a semicircle centred on the axis, revolved 360°), a whole torus (a full
    /// circle in a plane through the axis, off it) or a cylinder (a line parallel to the axis).
    fn revolution(
        &self,
        e: &IgesEntity,
        axis: u32,
        generatrix: u32,
        start_angle: f64,
        end_angle: f64,
    ) -> Result<(NurbsSurface, Option<AnalyticShape>), IgesError> {
        let fail = |reason: String| geometry_error(e, reason);
        let axis_entity = self.child(axis, e)?;
        let EntityData::Line { start, end } = axis_entity.kind else {
            return Err(fail(format!(
                "the axis (DE {axis}) must be a 110 line, found entity type {}",
                axis_entity.type_number()
            )));
        };
        let t = self.own_transform(axis_entity);
        let origin = apply(&t, start);
        let direction = sub(apply(&t, end), origin);
        let length = norm(direction);
        if !(length > 0.0 && length.is_finite()) {
            return Err(fail(format!("the axis (DE {axis}) has zero length")));
        }
        let a = scale(direction, 1.0 / length);
        let span = snap_full_turn(end_angle - start_angle);
        if !(span > 0.0 && span <= TAU) {
            return Err(fail(format!(
                "angles {start_angle} to {end_angle}: need 0 < end − start ≤ 2π"
            )));
        }
        let generatrix_entity = self.child(generatrix, e)?;
        let g = self.curve(generatrix_entity)?;
        let s = revolve_curve(&g, origin, a, start_angle, span).map_err(|x| fail(x.to_string()))?;
        // The closed form whatever the span (a face a quarter of the way round is on the
        // same torus as a whole one, as STEP states it).
        let analytic = self.revolved_shape(generatrix_entity, origin, a);
        Ok((s, analytic))
    }

    /// The closed form of a revolution of `generatrix` about the axis through `origin` along
    /// the unit `a`: a sphere, torus, cylinder or cone, when the generatrix makes one — an
    /// arc of a circle about a point of the axis (the sphere's zone a face covers, not
    /// only pole to pole), an arc of a circle in a plane through the axis about a point
    /// farther from it than its radius (a fillet's quarter of the tube, not only all of it).
    fn revolved_shape(
        &self,
        generatrix: &IgesEntity,
        origin: [f64; 3],
        a: [f64; 3],
    ) -> Option<AnalyticShape> {
        let foot = |x: [f64; 3]| add(origin, scale(a, dot(sub(x, origin), a)));
        let off_axis = |x: [f64; 3]| distance(x, foot(x));
        match generatrix.kind {
            EntityData::CircularArc { .. } => {
                let c = self.placed_circle(generatrix)?;
                let tol = RECOGNITION_TOLERANCE * (c.radius + norm(sub(c.center, origin)));
                let n = scale(c.normal, 1.0 / norm(c.normal));
                if off_axis(c.center) <= tol {
                    // Every point of a circle about a point of the axis stays at its radius
                    // from that point as it turns.
                    return AnalyticShape::new_sphere(foot(c.center), c.radius).ok();
                }
                let in_axis_plane = dot(n, a).abs() <= RECOGNITION_TOLERANCE
                    && dot(n, sub(c.center, origin)).abs() <= tol;
                let major = off_axis(c.center);
                (in_axis_plane && major > c.radius)
                    .then(|| AnalyticShape::new_torus(foot(c.center), a, major, c.radius))?
                    .ok()
            }
            EntityData::Line { start, end } => {
                let t = self.own_transform(generatrix);
                let (p, q) = (apply(&t, start), apply(&t, end));
                let d = sub(q, p);
                let radius = off_axis(p);
                let tol = RECOGNITION_TOLERANCE * (radius + norm(sub(p, origin)));
                let parallel = norm(cross(d, a)) <= RECOGNITION_TOLERANCE * norm(d);
                if parallel {
                    return (radius > tol && (off_axis(q) - radius).abs() <= tol)
                        .then(|| AnalyticShape::new_cylinder(foot(p), a, radius))?
                        .ok();
                }
                // A cone: the line meets the axis (lies in a plane through it) at the apex,
                // where the radius, linear in the height along the line, reaches zero; the
                // segment on one side of it.
                let height = |x: [f64; 3]| dot(sub(x, origin), a);
                let (hp, hq, rq) = (height(p), height(q), off_axis(q));
                let coplanar = dot(sub(p, origin), cross(d, a)).abs() <= tol * norm(d);
                if !coplanar || (rq - radius).abs() <= tol || (hq - hp).abs() <= tol {
                    return None;
                }
                let slope = (rq - radius) / (hq - hp);
                let apex_height = hp - radius / slope;
                let apex = add(origin, scale(a, apex_height));
                let ahead = |x: [f64; 3]| (height(x) - apex_height) * slope.signum();
                (ahead(p) >= -tol && ahead(q) >= -tol)
                    .then(|| {
                        AnalyticShape::new_cone(apex, scale(a, slope.signum()), slope.abs().atan())
                    })?
                    .ok()
            }
            _ => None,
        }
    }

    /// A 122 tabulated cylinder in its definition space: the directrix swept to `end`; a
    /// cylinder when the directrix is a full circle swept along its normal.
    fn tabulated_cylinder(
        &self,
        e: &IgesEntity,
        directrix: u32,
        end: [f64; 3],
    ) -> Result<(NurbsSurface, Option<AnalyticShape>), IgesError> {
        let directrix_entity = self.child(directrix, e)?;
        let c = self.curve(directrix_entity)?;
        let sweep = sub(end, c.point(c.domain().0));
        if !(norm(sweep).is_finite() && norm(sweep) > 0.0) {
            return Err(geometry_error(
                e,
                "the sweep from the directrix's start to the end point is zero".into(),
            ));
        }
        let s = extrude_curve(&c, sweep).map_err(|x| geometry_error(e, x.to_string()))?;
        let analytic = self
            .placed_circle(directrix_entity)
            .filter(|circle| {
                circle.full
                    && norm(cross(circle.normal, sweep))
                        <= RECOGNITION_TOLERANCE * norm(circle.normal) * norm(sweep)
            })
            .and_then(|circle| {
                AnalyticShape::new_cylinder(circle.center, circle.normal, circle.radius).ok()
            });
        Ok((s, analytic))
    }
}
