//! Faces as exact NURBS surfaces with their closed forms: planes as patches around the
//! face's edges, the quadrics and tori of `shapes`, cones as revolved segments, B-spline
//! surfaces, surfaces of revolution and of linear extrusion over the face's extent.

use std::f64::consts::TAU;

use super::convert::{Converter, EDGE_SAMPLES, EXTENT_MARGIN, MAX_DEPTH, SAME};
use super::curves::integer;
use super::error::StepError;
use super::parse::{StepInstance, StepRecord, StepValue};
use super::placements::Placements;
use crate::conics::line_segment;
use crate::iges::affine::IDENTITY;
use crate::iges::affine::{apply, apply_linear};
use crate::iges::plane_patch::plane_patch;
use crate::iges::swept::{extrude_curve, revolve_curve};
use crate::shapes::{self, AnalyticShape};
use crate::vec3::{add, cross, dot, norm, scale, sub};
use crate::NurbsSurface;

impl<'a> Converter<'a> {
    /// Points on the edges bounding `face` (vertices and samples), to size its surface.
    pub(super) fn face_cover(&self, face: &StepInstance) -> Result<Vec<[f64; 3]>, StepError> {
        let mut cover = Vec::new();
        // A VERTEX_LOOP bound (a cone's apex) is a point the face reaches.
        for b in self.params(face, 2)?[1].list().unwrap_or(&[]) {
            let bound = self.get(b, face)?;
            let loop_ = self.get(&self.params(bound, 2)?[1], bound)?;
            if loop_.type_name() == "VERTEX_LOOP" {
                cover.push(self.vertex(&self.params(loop_, 2)?[1], loop_)?);
            }
        }
        for edge in self.face_edges(face)? {
            let c = self.edge_curve(edge, 0)?;
            let (t0, t1) = c.domain();
            for k in 0..=EDGE_SAMPLES {
                cover.push(c.point(t0 + (t1 - t0) * k as f64 / EDGE_SAMPLES as f64));
            }
        }
        Ok(cover)
    }

    /// The `EDGE_CURVE`s of a face's bounds (through `FACE_BOUND`/`FACE_OUTER_BOUND`,
    /// `EDGE_LOOP` and `ORIENTED_EDGE`).
    pub(super) fn face_edges(
        &self,
        face: &StepInstance,
    ) -> Result<Vec<&'a StepInstance>, StepError> {
        let p = self.params(face, 2)?;
        let bounds = p[1]
            .list()
            .ok_or_else(|| self.fail(face, "bounds: expected a list"))?;
        let mut edges = Vec::new();
        for b in bounds {
            let bound = self.get(b, face)?;
            let loop_ = self.get(&self.params(bound, 2)?[1], bound)?;
            if loop_.type_name() != "EDGE_LOOP" {
                continue; // a VERTEX_LOOP (a cone's apex) bounds nothing
            }
            let list = self.params(loop_, 2)?[1]
                .list()
                .ok_or_else(|| self.fail(loop_, "edges: expected a list"))?;
            for oe in list {
                let oriented = self.get(oe, loop_)?;
                let q = self.params(oriented, 4)?;
                let edge = self.get(&q[3], oriented)?;
                self.expect_type(edge, "EDGE_CURVE")?;
                edges.push(edge);
            }
        }
        Ok(edges)
    }

    /// The surface instance under a face.
    /// Through `RECTANGULAR_TRIMMED_SURFACE`s to their basis surface (the face's own bounds
    /// trim it anyway).
    pub(super) fn face_geometry(&self, face: &StepInstance) -> Result<&'a StepInstance, StepError> {
        let p = self.params(face, 3)?;
        let mut s = self.get(&p[2], face)?;
        for _ in 0..MAX_DEPTH {
            if s.type_name() != "RECTANGULAR_TRIMMED_SURFACE" {
                return Ok(s);
            }
            s = self.get(&self.params(s, 2)?[1], s)?;
        }
        Err(StepError::TooDeep {
            id: s.id,
            line: s.line,
            limit: MAX_DEPTH,
        })
    }

    /// Whether every face lies on a plane and all those planes are one.
    pub(super) fn is_planar_model(
        &self,
        faces: &[&StepInstance],
        placements: &Placements,
    ) -> Result<bool, StepError> {
        let mut first: Option<([f64; 3], [f64; 3])> = None;
        for &face in faces {
            let s = self.face_geometry(face)?;
            if s.type_name() != "PLANE" {
                return Ok(false);
            }
            let f = self.placement(&self.params(s, 2)?[1], s)?;
            for t in placements.of(face.id) {
                let (o, z) = (apply(&t, f.origin), apply_linear(&t, f.z));
                let z = scale(z, 1.0 / norm(z));
                match first {
                    None => first = Some((o, z)),
                    Some((go, gz)) => {
                        let size = 1.0 + norm(go).max(norm(o));
                        if norm(cross(z, gz)) > SAME || dot(sub(o, go), gz).abs() > SAME * size {
                            return Ok(false);
                        }
                    }
                }
            }
        }
        Ok(first.is_some())
    }

    /// A face's surface as exact NURBS, its closed form, and its type for messages.
    pub(super) fn face_surface(
        &self,
        face: &StepInstance,
    ) -> Result<(NurbsSurface, Option<AnalyticShape>, String), StepError> {
        let s = self.face_geometry(face)?;
        let kind = s.type_name();
        let fail = |r: String| self.fail(s, r);
        let (surface, analytic) = match kind.as_str() {
            "PLANE" => {
                let f = self.placement(&self.params(s, 2)?[1], s)?;
                let cover = self.face_cover(face)?;
                let plane = [f.z[0], f.z[1], f.z[2], dot(f.z, f.origin)];
                (plane_patch(plane, &IDENTITY, &cover).map_err(fail)?, None)
            }
            "SPHERICAL_SURFACE" => {
                let p = self.params(s, 3)?;
                let f = self.placement(&p[1], s)?;
                let r = self.length(&p[2], s, "radius")?;
                (
                    shapes::sphere(f.origin, r).map_err(|e| fail(e.to_string()))?,
                    AnalyticShape::new_sphere(f.origin, r).ok(),
                )
            }
            "CYLINDRICAL_SURFACE" => {
                let p = self.params(s, 3)?;
                let f = self.placement(&p[1], s)?;
                let r = self.length(&p[2], s, "radius")?;
                let range = self.extent(face, f.origin, f.z)?;
                (
                    shapes::cylinder(f.origin, f.z, r, range).map_err(|e| fail(e.to_string()))?,
                    AnalyticShape::new_cylinder(f.origin, f.z, r).ok(),
                )
            }
            "TOROIDAL_SURFACE" => {
                let p = self.params(s, 4)?;
                let f = self.placement(&p[1], s)?;
                let major = self.length(&p[2], s, "major radius")?;
                let minor = self.length(&p[3], s, "minor radius")?;
                // The patch covers the part of the tube the face does (a fillet's quarter,
                // as an IGES export writes it): a path on the patch between two points of
                // its edge where the fillet meets a face tangentially then follows that
                // edge, rather than run over the tube into the solid.
                let cover = self.face_cover(face)?;
                let patch = match tube_extent(&cover, f.origin, f.z, major) {
                    Some((start, span)) => {
                        shapes::torus_band(f.origin, f.z, major, minor, start, span)
                    }
                    None => shapes::torus(f.origin, f.z, major, minor),
                };
                (
                    patch.map_err(|e| fail(e.to_string()))?,
                    AnalyticShape::new_torus(f.origin, f.z, major, minor).ok(),
                )
            }
            "CONICAL_SURFACE" => {
                let p = self.params(s, 4)?;
                let f = self.placement(&p[1], s)?;
                let r = self.length(&p[2], s, "radius")?;
                let angle = self.real(&p[3], s, "semi-angle")? * self.angle;
                if !(angle.abs() > 0.0 && angle.abs() < 0.5 * std::f64::consts::PI) {
                    return Err(fail(format!(
                        "semi-angle {angle} (radians) out of (0, π/2)"
                    )));
                }
                let (mut v0, mut v1) = self.extent(face, f.origin, f.z)?;
                // The radius r + v tan(angle) stays ≥ 0: clip the range at the apex.
                let apex = -r / angle.tan();
                if angle > 0.0 {
                    v0 = v0.max(apex);
                } else {
                    v1 = v1.min(apex);
                }
                if v1.is_nan() || v0.is_nan() || v1 <= v0 {
                    return Err(fail("the face lies beyond the cone's apex".into()));
                }
                let at = |v: f64| {
                    add(
                        add(f.origin, scale(f.z, v)),
                        scale(f.x, r + v * angle.tan()),
                    )
                };
                let g = line_segment(at(v0), at(v1)).map_err(|e| fail(e.to_string()))?;
                // The nappe holding the face opens from the apex along ±z with the sign
                // of the angle.
                let axis = if angle > 0.0 { f.z } else { scale(f.z, -1.0) };
                (
                    revolve_curve(&g, f.origin, f.z, 0.0, TAU).map_err(|e| fail(e.to_string()))?,
                    AnalyticShape::new_cone(add(f.origin, scale(f.z, apex)), axis, angle.abs())
                        .ok(),
                )
            }
            "SURFACE_OF_REVOLUTION" => {
                let p = self.params(s, 3)?;
                let g = self.swept_curve(self.basis_curve(&p[1], s, 0)?)?;
                let axis = self.get(&p[2], s)?;
                self.expect_type(axis, "AXIS1_PLACEMENT")?;
                let q = self.params(axis, 2)?;
                let origin = self.point(&q[1], axis)?;
                let direction = match q.get(2) {
                    Some(StepValue::Unset) | None => [0.0, 0.0, 1.0],
                    Some(v) => self.direction(v, axis)?,
                };
                (
                    revolve_curve(&g, origin, direction, 0.0, TAU)
                        .map_err(|e| fail(e.to_string()))?,
                    None,
                )
            }
            "SURFACE_OF_LINEAR_EXTRUSION" => {
                let p = self.params(s, 3)?;
                let g = self.swept_curve(self.basis_curve(&p[1], s, 0)?)?;
                let v = self.vector(&p[2], s)?;
                let length = norm(v);
                if length.is_nan() || length <= 0.0 {
                    return Err(fail("an extrusion vector of length zero".into()));
                }
                let d = scale(v, 1.0 / length);
                // S(u, t) = C(u) + t d over the face's extent along d: exactly that extent
                // when the curve lies in a plane across d (the face is then the surface
                // between two such planes, as an IGES 122 is written), else widened.
                let cover = self.face_cover(face)?;
                let along = |x: &[f64; 3]| dot(*x, d);
                let (lo, hi) = min_max(cover.iter().map(along));
                let (clo, chi) = min_max(g.control_points.iter().map(along));
                let slack = SAME * (1.0 + length + chi.abs().max(clo.abs()));
                let (t0, t1) = if chi - clo <= slack {
                    (lo - chi, hi - clo)
                } else {
                    widen(lo - chi, hi - clo)
                };
                if t1 - t0 <= slack {
                    return Err(fail("the face has no extent along the extrusion".into()));
                }
                let mut start = g.clone();
                for x in &mut start.control_points {
                    *x = add(*x, scale(d, t0));
                }
                (
                    extrude_curve(&start, scale(d, t1 - t0)).map_err(|e| fail(e.to_string()))?,
                    None,
                )
            }
            _ => {
                if let Some(spline) = s.record("B_SPLINE_SURFACE_WITH_KNOTS") {
                    (self.bspline_surface(s, spline)?, None)
                } else {
                    return Err(self.unsupported(
                        s,
                        format!(" (the surface of face #{}, line {})", face.id, face.line),
                    ));
                }
            }
        };
        Ok((surface, analytic, kind))
    }

    /// The range of `(x − origin)·axis` over the face's edges, widened by
    /// [`EXTENT_MARGIN`].
    pub(super) fn extent(
        &self,
        face: &StepInstance,
        origin: [f64; 3],
        axis: [f64; 3],
    ) -> Result<(f64, f64), StepError> {
        let cover = self.face_cover(face)?;
        let (lo, hi) = min_max(cover.iter().map(|x| dot(sub(*x, origin), axis)));
        if hi.is_nan() || lo.is_nan() || hi < lo {
            return Err(self.fail(face, "no bounding edge to size its surface by"));
        }
        Ok(widen(lo, hi))
    }

    /// `B_SPLINE_SURFACE_WITH_KNOTS`, simple or complex (rational), as a NURBS surface.
    pub(super) fn bspline_surface(
        &self,
        i: &StepInstance,
        spline: &StepRecord,
    ) -> Result<NurbsSurface, StepError> {
        // Simple: name, du, dv, points, form, u_closed, v_closed, self_int, umults, vmults,
        // uknots, vknots, spec. Complex: B_SPLINE_SURFACE(du, dv, points, …) +
        // …_WITH_KNOTS(umults, vmults, uknots, vknots, spec).
        let (head, tail): (&[StepValue], &[StepValue]) = match i.record("B_SPLINE_SURFACE") {
            Some(b) => (&b.params[..], &spline.params[..]),
            None if spline.params.len() >= 12 => (&spline.params[1..8], &spline.params[8..]),
            None => return Err(self.fail(i, "too few parameters for a B-spline surface")),
        };
        if head.len() < 3 || tail.len() < 4 {
            return Err(self.fail(i, "too few parameters for a B-spline surface"));
        }
        let du = integer(&head[0]).ok_or_else(|| self.fail(i, "u degree"))?;
        let dv = integer(&head[1]).ok_or_else(|| self.fail(i, "v degree"))?;
        let rows = head[2]
            .list()
            .ok_or_else(|| self.fail(i, "control points: expected a list of lists"))?;
        let mut points = Vec::new();
        let mut columns = None;
        for row in rows {
            let row = row
                .list()
                .ok_or_else(|| self.fail(i, "control points: expected a list of lists"))?;
            if *columns.get_or_insert(row.len()) != row.len() {
                return Err(self.fail(i, "control point rows of different lengths"));
            }
            for v in row {
                points.push(self.point(v, i)?);
            }
        }
        let knots_u = self.knots(i, &tail[0], &tail[2])?;
        let knots_v = self.knots(i, &tail[1], &tail[3])?;
        let weights = match i.record("RATIONAL_B_SPLINE_SURFACE") {
            Some(r) => self.reals(i, r, 0, "weights")?,
            None => vec![1.0; points.len()],
        };
        // STEP lists the points row by row in u, each row along v: the u-major order of
        // NurbsSurface.
        NurbsSurface::new(du, dv, knots_u, knots_v, points, weights)
            .map_err(|e| self.fail(i, e.to_string()))
    }
}

/// The smallest and largest of `values` (+∞, −∞ when empty).
fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    })
}

/// The tube angles a face on a torus covers (start, span; from the outer equator towards
/// the axis), from points of its edges `cover`: all but the widest gap between them, when
/// that gap is wider than sampling leaves (an eighth of a turn: 16 samples per edge step
/// at most 1/16 of a turn); `None` when the face goes all round the tube.
fn tube_extent(
    cover: &[[f64; 3]],
    center: [f64; 3],
    axis: [f64; 3],
    major: f64,
) -> Option<(f64, f64)> {
    let mut angles: Vec<f64> = cover
        .iter()
        .map(|x| {
            let d = sub(*x, center);
            let along = dot(d, axis);
            let rho = norm(sub(d, scale(axis, along)));
            along.atan2(rho - major)
        })
        .filter(|t| t.is_finite())
        .collect();
    angles.sort_by(f64::total_cmp);
    let (&first, &last) = (angles.first()?, angles.last()?);
    // The gap after each angle (the last one's wraps round to the first).
    let (gap, after) = angles
        .windows(2)
        .map(|w| (w[1] - w[0], w[1]))
        .chain(std::iter::once((first + TAU - last, first)))
        .max_by(|a, b| a.0.total_cmp(&b.0))?;
    (gap > TAU / 8.0).then_some((after, TAU - gap))
}

/// `[lo, hi]` widened by [`EXTENT_MARGIN`] of its length on each side (of 1 when empty).
fn widen(lo: f64, hi: f64) -> (f64, f64) {
    let margin = EXTENT_MARGIN * (hi - lo).max(SAME * (1.0 + lo.abs().max(hi.abs())));
    (lo - margin, hi + margin)
}
