//! IGES entities → exact rational NURBS: the [`GeometryModel`] that boundary nodes are placed
//! on (DESIGN.md §4). Every conversion is exact: circular arcs, surfaces of revolution and
//! tabulated cylinders become rational B-splines that reproduce the IGES definition up to
//! rounding, not fits.
//!
//! Which entities become model entities:
//! - Only *independent* entities: those whose Directory Entry subordinate switch is 0 or 2
//!   when the file sets the switch anywhere (OpenCASCADE does), otherwise those that no other
//!   entity references. So the surface of a 144 trimmed surface, the generatrix and axis of a
//!   120, and the members of a 102 never appear alone.
//! - A 144 trimmed surface (and a 142 curve on surface) becomes its *underlying* surface
//!   (curve); trimming curves are not kept.
//! - A 2D model is its curves: when every independent surface is a 108 plane (bare or under a
//!   144) and all lie in one plane, each face is replaced by its model-space boundary curves
//!   (the model curves of its 142 entities), duplicates removed. A 3D model is its faces.
//! - An independent 102 composite curve contributes one entity per member (the members are
//!   the CAD edges, and a joined curve would have corners inside). Where one curve is needed
//!   (a generatrix, a directrix), the members are joined into one NURBS: split into rational
//!   Bézier pieces, degree-elevated to the highest degree, concatenated with C⁰ joins.
//! - 124 transformation matrices are applied to control points (rational B-splines are
//!   invariant under affine maps of their control points), chained from the entity up through
//!   every referencing parent; 402 associativities and 406/314 properties are ignored; every
//!   other type (B-rep entities 186, 5xx included) is an error naming its type and line.
//!
//! Parametrisations: a 100 arc runs over its angle in radians (counter-clockwise about the
//! definition-space z axis); a surface of revolution has u = angle about the axis (radians,
//! start to end angle) and v = the generatrix parameter, as [`crate::shapes`]; a tabulated
//! cylinder has u = directrix parameter, v ∈ [0, 1] along the sweep; a 108 plane is a bilinear
//! patch over the bounding box of its trimming curves (or, with none, of the whole model)
//! widened by 10% on each side, since an IGES plane has no parametrisation of its own.
//!
//! Units: coordinates are kept as written, whatever the Global section's units flag and
//! model scale say. OpenCASCADE (through Gmsh) writes unit flag 2 (millimetres) with scale 1
//! but the numbers are the CAD model's own, the same the mesh of that model uses.

use std::cell::Cell;
use std::collections::BTreeSet;
use std::f64::consts::TAU;
use std::path::Path;

use super::affine::{
    apply, apply_linear, compose, similarity_scale, transform_curve, transform_shape,
    transform_surface, Affine, IDENTITY,
};
use super::curve_primitives::{circular_arc, elliptic_arc, line_segment, snap_full_turn};
use super::join::concatenate;
use super::plane_patch::{model_plane, plane_patch};
use super::restrict::{bspline_surface, restrict_curve};
use super::swept::{extrude_curve, revolve_curve};
use super::tolerance::RECOGNITION_TOLERANCE;
use super::{read_iges, EntityData, IgesEntity, IgesError, IgesModel};
use crate::model::{EntityGeometry, GeometricEntity, GeometryModel};
use crate::shapes::AnalyticShape;
use crate::vec3::{add, cross, distance, dot, norm, scale, sub};
use crate::{NurbsCurve, NurbsSurface};

/// Converts every independent entity of a parsed IGES file into a named exact NURBS curve or
/// surface (see the module documentation for what is kept and how).
pub fn geometry_from_iges(model: &IgesModel) -> Result<GeometryModel, IgesError> {
    // The conversion follows references recursively: bounded once they are acyclic and
    // shallow.
    model.check_references()?;
    Converter {
        model,
        spent: Cell::new(0),
        limit: model.expansion_limit(),
    }
    .convert()
}

/// Reads an IGES file and converts it with [`geometry_from_iges`].
pub fn read_iges_geometry(path: &Path) -> Result<GeometryModel, IgesError> {
    geometry_from_iges(&read_iges(path)?)
}

// ---------------------------------------------------------------------------------------------
// the converter
// ---------------------------------------------------------------------------------------------

/// A circle or circular arc placed in its parent's space by a similarity.
struct PlacedCircle {
    center: [f64; 3],
    normal: [f64; 3],
    radius: f64,
    start: [f64; 3],
    end: [f64; 3],
    full: bool,
}

/// One converted entity before naming: the IGES entity it is named after, a note for its
/// origin, its geometry and closed form.
struct Converted<'a> {
    entity: &'a IgesEntity,
    note: String,
    geometry: EntityGeometry,
    analytic: Option<AnalyticShape>,
}

/// Whether two curves have the same control points, in the same or the reverse order (the
/// same edge written twice, e.g. once for each of two faces of a 2D model).
fn same_curve(a: &NurbsCurve, b: &NurbsCurve) -> bool {
    let n = a.control_points.len();
    if n != b.control_points.len() || a.degree != b.degree {
        return false;
    }
    let tol = RECOGNITION_TOLERANCE * a.size().max(b.size());
    let forward = (0..n).all(|i| distance(a.control_points[i], b.control_points[i]) <= tol);
    let backward =
        (0..n).all(|i| distance(a.control_points[i], b.control_points[n - 1 - i]) <= tol);
    forward || backward
}

struct Converter<'a> {
    model: &'a IgesModel,
    /// Parameter Data records of the entities visited so far (once per visit).
    spent: Cell<usize>,
    /// [`IgesModel::expansion_limit`]: acyclic references may still share entities so
    /// much that visiting each once per path would never end.
    limit: usize,
}

impl<'a> Converter<'a> {
    fn convert(&self) -> Result<GeometryModel, IgesError> {
        let top = self.independent_entities()?;
        let surfaces: Vec<&IgesEntity> = top.iter().copied().filter(|e| is_surface(e)).collect();
        let two_d = self.is_planar_model(&surfaces)?;
        // slot per top-level entity, filled in order; unbounded planes wait for the model box
        let mut slots: Vec<Vec<Converted<'a>>> = Vec::with_capacity(top.len());
        let mut waiting = Vec::new();
        for (k, &e) in top.iter().enumerate() {
            self.visit(e)?;
            let converted = if is_surface(e) && two_d {
                self.face_boundary_curves(e)
            } else if is_surface(e) {
                match self.surface(e, &IDENTITY, &[]) {
                    Ok((s, analytic)) => Ok(vec![Converted {
                        entity: e,
                        note: String::new(),
                        geometry: EntityGeometry::Surface(s),
                        analytic,
                    }]),
                    Err(IgesError::UnboundedPlane { .. }) => {
                        waiting.push(k);
                        Ok(Vec::new())
                    }
                    Err(err) => Err(err),
                }
            } else {
                self.curve_entities(e, &IDENTITY, "")
            }?;
            slots.push(converted);
        }
        if !waiting.is_empty() {
            let mut cover = Vec::new();
            for c in slots.iter().flatten() {
                match &c.geometry {
                    EntityGeometry::Curve(x) => cover.extend_from_slice(&x.control_points),
                    EntityGeometry::Surface(x) => cover.extend_from_slice(&x.control_points),
                }
            }
            for k in waiting {
                let e = top[k];
                let (s, analytic) = self.surface(e, &IDENTITY, &cover)?;
                slots[k].push(Converted {
                    entity: e,
                    note: String::new(),
                    geometry: EntityGeometry::Surface(s),
                    analytic,
                });
            }
        }
        let mut converted: Vec<Converted<'a>> = Vec::new();
        for c in slots.into_iter().flatten() {
            let duplicate = converted.iter().any(|d| {
                d.entity.de == c.entity.de
                    || matches!((&d.geometry, &c.geometry),
                        (EntityGeometry::Curve(a), EntityGeometry::Curve(b)) if same_curve(a, b))
            });
            if !duplicate {
                converted.push(c);
            }
        }
        Ok(GeometryModel {
            entities: name_entities(converted),
        })
    }

    /// Entities that stand alone: by the subordinate switch when the file sets it anywhere,
    /// by the reference graph otherwise. Transformation matrices and ignorable entities are
    /// left out; unsupported ones are an error.
    fn independent_entities(&self) -> Result<Vec<&'a IgesEntity>, IgesError> {
        let entities = &self.model.entities;
        let by_status = entities.iter().any(|e| e.is_subordinate());
        let referenced: BTreeSet<u32> = entities.iter().flat_map(|e| e.kind.references()).collect();
        let mut out = Vec::new();
        for e in entities {
            let independent = if by_status {
                !e.is_subordinate()
            } else {
                !referenced.contains(&e.de)
            };
            if !independent {
                continue;
            }
            match e.kind {
                EntityData::TransformationMatrix { .. } | EntityData::Ignored { .. } => {}
                EntityData::Brep { .. } | EntityData::Unsupported { .. } => {
                    return Err(unsupported(e, String::new()))
                }
                _ => out.push(e),
            }
        }
        Ok(out)
    }

    /// Counts a visit of `e` against the expansion limit.
    fn visit(&self, e: &IgesEntity) -> Result<(), IgesError> {
        let records = (e.directory.parameter_line_count as usize).max(1);
        let spent = self.spent.get().saturating_add(records);
        self.spent.set(spent);
        if spent > self.limit {
            return Err(IgesError::ExpansionTooLarge {
                line: e.line,
                de: e.de,
                entity_type: e.type_number(),
                limit: self.limit,
                records: self.model.parameter_records(),
            });
        }
        Ok(())
    }

    /// The entity at DE `de`, referenced by `parent`; unsupported types are an error naming
    /// both. Every reference followed passes here, so the visits are counted here.
    fn child(&self, de: u32, parent: &IgesEntity) -> Result<&'a IgesEntity, IgesError> {
        let e = self.model.entity(de).ok_or_else(|| {
            geometry_error(parent, format!("refers to DE {de}, which does not exist"))
        })?;
        self.visit(e)?;
        match e.kind {
            EntityData::Brep { .. } | EntityData::Unsupported { .. } => Err(unsupported(
                e,
                format!(
                    " (referenced by entity type {}, DE {}, line {})",
                    parent.type_number(),
                    parent.de,
                    parent.line
                ),
            )),
            _ => Ok(e),
        }
    }

    /// The entity's own transformation (its 124 chain), identity when it has none.
    fn own_transform(&self, e: &IgesEntity) -> Affine {
        self.model.transform_of(e).unwrap_or(IDENTITY)
    }

    /// A curve entity as one NURBS in its parent's definition space (own transformation
    /// applied). Composite curves are joined.
    fn curve(&self, e: &IgesEntity) -> Result<NurbsCurve, IgesError> {
        let fail = |reason: String| geometry_error(e, reason);
        let c = match &e.kind {
            EntityData::CircularArc {
                zt,
                center,
                start,
                end,
            } => circular_arc(*zt, *center, *start, *end).map_err(fail)?,
            EntityData::Line { start, end } => {
                line_segment(*start, *end).map_err(|x| fail(x.to_string()))?
            }
            EntityData::ConicArc {
                coefficients,
                zt,
                start,
                end,
            } => elliptic_arc(*coefficients, *zt, *start, *end)
                .map_err(|reason| unsupported(e, format!(": {reason}")))?,
            EntityData::BSplineCurve(d) => {
                let c = NurbsCurve::new(
                    d.m,
                    d.knots.clone(),
                    d.control_points.clone(),
                    d.weights.clone(),
                )
                .map_err(|x| fail(x.to_string()))?;
                restrict_curve(c, d.v0, d.v1).map_err(fail)?
            }
            EntityData::CompositeCurve { curves } => {
                let parts = curves
                    .iter()
                    .map(|&de| self.curve(self.child(de, e)?))
                    .collect::<Result<Vec<_>, _>>()?;
                let size = parts.iter().map(NurbsCurve::size).fold(0.0, f64::max);
                concatenate(&parts, RECOGNITION_TOLERANCE * size.max(1.0)).map_err(fail)?
            }
            EntityData::CurveOnSurface { model_curve, .. } => match model_curve {
                Some(de) => self.curve(self.child(*de, e)?)?,
                None => {
                    return Err(fail(
                        "curve on surface without a model-space curve (CPTR = 0)".into(),
                    ))
                }
            },
            other => {
                return Err(fail(format!(
                    "expected a curve (entity type 100, 102, 104, 110, 126 or 142), found type {}",
                    other.type_number()
                )))
            }
        };
        transform_curve(c, &self.own_transform(e)).map_err(fail)
    }

    /// A curve entity in model space (`to_model` maps its parent's space there), split into
    /// its members when it is a composite (recursively) or a curve on surface.
    fn curve_entities(
        &self,
        e: &'a IgesEntity,
        to_model: &Affine,
        note: &str,
    ) -> Result<Vec<Converted<'a>>, IgesError> {
        let placed = compose(to_model, &self.own_transform(e));
        let mut out = Vec::new();
        match &e.kind {
            EntityData::CompositeCurve { curves } => {
                let note = format!(
                    "{note}, member of entity type 102 (DE {}, line {})",
                    e.de, e.line
                );
                for &de in curves {
                    out.extend(self.curve_entities(self.child(de, e)?, &placed, &note)?);
                }
            }
            EntityData::CurveOnSurface {
                model_curve: Some(de),
                ..
            } => {
                out.extend(self.curve_entities(self.child(*de, e)?, &placed, note)?);
            }
            _ => {
                let c = transform_curve(self.curve(e)?, to_model)
                    .map_err(|reason| geometry_error(e, reason))?;
                let analytic = self
                    .placed_circle(e)
                    .filter(|c| c.full)
                    .and_then(|c| AnalyticShape::new_circle(c.center, c.normal, c.radius).ok())
                    .and_then(|shape| transform_shape(shape, to_model));
                out.push(Converted {
                    entity: e,
                    note: note.to_string(),
                    geometry: EntityGeometry::Curve(c),
                    analytic,
                });
            }
        }
        Ok(out)
    }

    /// A 100 arc in its parent's space when its own transformation is a similarity.
    fn placed_circle(&self, e: &IgesEntity) -> Option<PlacedCircle> {
        let EntityData::CircularArc {
            zt,
            center,
            start,
            end,
        } = e.kind
        else {
            return None;
        };
        let t = self.own_transform(e);
        let s = similarity_scale(&t)?;
        let radius = (start[0] - center[0]).hypot(start[1] - center[1]);
        let gap = (start[0] - end[0]).hypot(start[1] - end[1]);
        Some(PlacedCircle {
            center: apply(&t, [center[0], center[1], zt]),
            normal: apply_linear(&t, [0.0, 0.0, 1.0]),
            radius: s * radius,
            start: apply(&t, [start[0], start[1], zt]),
            end: apply(&t, [end[0], end[1], zt]),
            full: gap <= RECOGNITION_TOLERANCE * radius,
        })
    }

    /// A surface entity in model space (`to_model` maps its parent's space there) with its
    /// closed form when it has one. `cover`: model-space points a plane patch must cover
    /// besides its own boundary.
    fn surface(
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
                let mut cover = cover.to_vec();
                if matches!(carrier.kind, EntityData::Plane { .. }) {
                    for &de in outer.iter().chain(inner) {
                        let boundary = self.child(de, e)?;
                        if let EntityData::CurveOnSurface {
                            model_curve: None, ..
                        } = boundary.kind
                        {
                            continue; // parameter-space only: nothing to size the patch by
                        }
                        for c in self.curve_entities(boundary, &placed, "")? {
                            if let EntityGeometry::Curve(c) = c.geometry {
                                cover.extend_from_slice(&c.control_points);
                            }
                        }
                    }
                }
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
        let analytic = if span == TAU {
            self.revolved_shape(generatrix_entity, origin, a)
        } else {
            None
        };
        Ok((s, analytic))
    }

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
                if c.full {
                    let in_axis_plane = dot(n, a).abs() <= RECOGNITION_TOLERANCE
                        && dot(n, sub(c.center, origin)).abs() <= tol;
                    let major = off_axis(c.center);
                    (in_axis_plane && major > c.radius)
                        .then(|| AnalyticShape::new_torus(foot(c.center), a, major, c.radius))?
                        .ok()
                } else {
                    let semicircle = off_axis(c.center) <= tol
                        && off_axis(c.start) <= tol
                        && off_axis(c.end) <= tol;
                    semicircle
                        .then(|| AnalyticShape::new_sphere(foot(c.center), c.radius))?
                        .ok()
                }
            }
            EntityData::Line { start, end } => {
                let t = self.own_transform(generatrix);
                let (p, q) = (apply(&t, start), apply(&t, end));
                let d = sub(q, p);
                let radius = off_axis(p);
                let tol = RECOGNITION_TOLERANCE * (radius + norm(sub(p, origin)));
                let parallel = norm(cross(d, a)) <= RECOGNITION_TOLERANCE * norm(d);
                (parallel && radius > tol && (off_axis(q) - radius).abs() <= tol)
                    .then(|| AnalyticShape::new_cylinder(foot(p), a, radius))?
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

    /// Whether the independent surfaces make a 2D model: there is at least one, each is a
    /// 108 plane (bare or under a 144) and all lie in one plane.
    fn is_planar_model(&self, surfaces: &[&'a IgesEntity]) -> Result<bool, IgesError> {
        let mut planes = Vec::new();
        for &e in surfaces {
            let mut placed = self.own_transform(e);
            let mut carrier = e;
            if let EntityData::TrimmedSurface { surface, .. } = carrier.kind {
                carrier = self.child(surface, e)?;
                placed = compose(&placed, &self.own_transform(carrier));
            }
            let EntityData::Plane { coefficients, .. } = carrier.kind else {
                return Ok(false);
            };
            planes
                .push(model_plane(coefficients, &placed).map_err(|r| geometry_error(carrier, r))?);
        }
        let Some(&(o, [_, _, n])) = planes.first() else {
            return Ok(false);
        };
        let size = planes.iter().map(|p| norm(p.0)).fold(1.0, f64::max);
        Ok(planes.iter().all(|&(p, [_, _, m])| {
            norm(cross(n, m)) <= RECOGNITION_TOLERANCE
                && dot(sub(p, o), n).abs() <= RECOGNITION_TOLERANCE * size
        }))
    }

    /// The model-space boundary curves of a planar face (2D models).
    fn face_boundary_curves(&self, e: &'a IgesEntity) -> Result<Vec<Converted<'a>>, IgesError> {
        let placed = self.own_transform(e);
        let note = format!(
            ", boundary of entity type {} (DE {})",
            e.type_number(),
            e.de
        );
        let mut boundaries = Vec::new();
        let mut plane = e;
        let mut plane_placed = placed;
        if let EntityData::TrimmedSurface {
            surface,
            outer,
            inner,
            ..
        } = &e.kind
        {
            for &de in outer.iter().chain(inner) {
                boundaries.push((self.child(de, e)?, placed));
            }
            plane = self.child(*surface, e)?;
            plane_placed = compose(&placed, &self.own_transform(plane));
        }
        if boundaries.is_empty() {
            if let EntityData::Plane {
                boundary: Some(de), ..
            } = plane.kind
            {
                boundaries.push((self.child(de, plane)?, plane_placed));
            }
        }
        if boundaries.is_empty() {
            return Err(geometry_error(
                e,
                "a planar face of a 2D model has no boundary curve".into(),
            ));
        }
        let mut out = Vec::new();
        for (b, to_model) in boundaries {
            if let EntityData::CurveOnSurface {
                model_curve: None, ..
            } = b.kind
            {
                return Err(geometry_error(
                    b,
                    "boundary of a planar face of a 2D model without a model-space curve (CPTR = 0)"
                        .into(),
                ));
            }
            out.extend(self.curve_entities(b, &to_model, &note)?);
        }
        Ok(out)
    }
}

fn is_surface(e: &IgesEntity) -> bool {
    matches!(
        e.kind,
        EntityData::Plane { .. }
            | EntityData::SurfaceOfRevolution { .. }
            | EntityData::TabulatedCylinder { .. }
            | EntityData::BSplineSurface(_)
            | EntityData::TrimmedSurface { .. }
    )
}

fn unsupported(e: &IgesEntity, context: String) -> IgesError {
    IgesError::Unsupported {
        line: e.line,
        de: e.de,
        entity_type: e.type_number(),
        context,
    }
}

fn geometry_error(e: &IgesEntity, reason: String) -> IgesError {
    IgesError::Geometry {
        line: e.line,
        de: e.de,
        entity_type: e.type_number(),
        reason,
    }
}

/// The DE label (with `.subscript` when the subscript is not 0), if any.
fn label_of(e: &IgesEntity) -> Option<String> {
    let label = e.directory.label.trim();
    match (label.is_empty(), e.directory.subscript) {
        (true, _) => None,
        (false, 0) => Some(label.to_string()),
        (false, s) => Some(format!("{label}.{s}")),
    }
}

/// Names: the label when it is unique in the model, `label#DE` when several entities share
/// it, `type#DE` without a label. Origins: "IGES entity <type> (DE <n>, line <l>)".
fn name_entities(converted: Vec<Converted<'_>>) -> Vec<GeometricEntity> {
    let labels: Vec<Option<String>> = converted.iter().map(|c| label_of(c.entity)).collect();
    converted
        .into_iter()
        .zip(&labels)
        .map(|(c, label)| {
            let e = c.entity;
            let name = match label {
                Some(l) if labels.iter().filter(|x| x.as_ref() == Some(l)).count() == 1 => {
                    l.clone()
                }
                Some(l) => format!("{l}#{}", e.de),
                None => format!("{}#{}", e.type_number(), e.de),
            };
            GeometricEntity {
                name,
                origin: format!(
                    "IGES entity {} (DE {}, line {}){}",
                    e.type_number(),
                    e.de,
                    e.line,
                    c.note
                ),
                geometry: c.geometry,
                analytic: c.analytic,
            }
        })
        .collect()
}

#[cfg(test)]
#[path = "tests/convert.rs"]
mod tests;
