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
//! Units: coordinates are converted to millimetres by the Global section's units flag, as
//! OpenCASCADE reads IGES (so the geometry is in the numbers of a mesh Gmsh makes from the
//! same file: an IGES in metres or inches is meshed in millimetres); the model space scale
//! is ignored, as OpenCASCADE does. Flag 3 (units named in the file) and unknown flags keep
//! the numbers as written.

use std::collections::BTreeSet;
use std::path::Path;

use super::affine::{transform_curve, transform_shape, transform_surface, Affine, IDENTITY};
use super::converter::{unsupported, Converted, Converter};
use super::entities::EntityData;
use super::error::IgesError;
use super::model::{IgesEntity, IgesModel};
use super::naming::name_entities;
use super::parse::read_iges;
use super::tolerance::RECOGNITION_TOLERANCE;
use crate::face_edges::FaceBoundaries;
use crate::model::{EntityGeometry, GeometryModel};
use crate::vec3::distance;
use crate::NurbsCurve;

/// Converts every independent entity of a parsed IGES file into a named exact NURBS curve or
/// surface (see the module documentation for what is kept and how).
pub fn geometry_from_iges(model: &IgesModel) -> Result<GeometryModel, IgesError> {
    // The conversion follows references recursively: bounded once they are acyclic and
    // shallow.
    model.check_references()?;
    let (mut geometry, mut boundaries) = Converter::new(model).convert()?;
    let mm = model.global.unit_in_metres().map_or(1.0, |m| 1000.0 * m);
    let resolution = model.global.min_resolution * mm;
    geometry.uncertainty = (resolution > 0.0 && resolution.is_finite()).then_some(resolution);
    if let Some(metres) = model.global.unit_in_metres() {
        let mm = 1000.0 * metres;
        if mm != 1.0 {
            let t: Affine = [
                [mm, 0.0, 0.0, 0.0],
                [0.0, mm, 0.0, 0.0],
                [0.0, 0.0, mm, 0.0],
            ];
            for e in &mut geometry.entities {
                let scaled = match &e.geometry {
                    EntityGeometry::Curve(c) => {
                        transform_curve(c.clone(), &t).map(EntityGeometry::Curve)
                    }
                    EntityGeometry::Surface(s) => {
                        transform_surface(s.clone(), &t).map(EntityGeometry::Surface)
                    }
                };
                e.geometry = scaled.map_err(|reason| IgesError::Units {
                    entity: e.name.clone(),
                    reason,
                })?;
                e.analytic = e.analytic.and_then(|a| transform_shape(a, &t));
            }
            for (_, curves) in &mut boundaries {
                for (origin, curve) in curves {
                    *curve =
                        transform_curve(curve.clone(), &t).map_err(|reason| IgesError::Units {
                            entity: origin.clone(),
                            reason,
                        })?;
                }
            }
        }
    }
    geometry.set_edges_between_faces(boundaries);
    Ok(geometry)
}

/// Reads an IGES file and converts it with [`geometry_from_iges`].
pub fn read_iges_geometry(path: &Path) -> Result<GeometryModel, IgesError> {
    geometry_from_iges(&read_iges(path)?)
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

impl<'a> Converter<'a> {
    /// The model's entities, and each 3D face's boundary curves (entity index, curves).
    fn convert(&self) -> Result<(GeometryModel, FaceBoundaries), IgesError> {
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
        let faces: Vec<(usize, &'a IgesEntity)> = converted
            .iter()
            .enumerate()
            .filter(|(_, c)| matches!(c.geometry, EntityGeometry::Surface(_)) && !two_d)
            .map(|(k, c)| (k, c.entity))
            .collect();
        let boundaries = faces
            .into_iter()
            .map(|(k, e)| (k, self.face_edge_curves(e)))
            .collect();
        Ok((
            GeometryModel::new(name_entities(converted), None),
            boundaries,
        ))
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
}

/// Whether an entity is converted as a surface (or face) rather than a curve.
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

#[cfg(test)]
#[path = "tests/convert.rs"]
mod tests;
