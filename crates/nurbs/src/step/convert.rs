//! STEP faces and edges → exact rational NURBS: the same [`GeometryModel`] the IGES reader
//! builds, so that association and curving do not care which file the geometry came from.
//!
//! - A 3D model is its faces (`ADVANCED_FACE`, `FACE_SURFACE`), each as its underlying
//!   surface (trims are not kept, as for IGES 144), with the closed form where there is one:
//!   `SPHERICAL_SURFACE`, `CYLINDRICAL_SURFACE` and `TOROIDAL_SURFACE` (exact rational
//!   B-splines plus the analytic shape), `PLANE` (a bilinear patch around the face's edges,
//!   as an IGES 108), `CONICAL_SURFACE` (a revolved segment over the face's axial extent),
//!   `B_SPLINE_SURFACE_WITH_KNOTS` (rational or not, and its `QUASI_UNIFORM`/`UNIFORM`/
//!   `BEZIER` forms written with knots), `SURFACE_OF_REVOLUTION` and
//!   `SURFACE_OF_LINEAR_EXTRUSION`.
//! - A 2D model (every face a plane, all in one plane) is its edges (`EDGE_CURVE` on `LINE`,
//!   `CIRCLE`, `ELLIPSE` and B-spline curves, through `SURFACE_CURVE`, `SEAM_CURVE` and
//!   `TRIMMED_CURVE`), each between its vertices, duplicates removed.
//! - A 3D model also keeps its edges ([`crate::ModelEdge`]): the curve of each `EDGE_CURVE`
//!   bounding two of its faces (shared, or copies that coincide where each face is its own
//!   shell), with the faces, so that a feature edge between them lies on the modeller's
//!   curve rather than on a traced intersection.
//! - Placements (`AXIS2_PLACEMENT_3D`) are applied, and the parts of an assembly are put in
//!   place by their representation relationships ([`super::placements`]), once per
//!   occurrence.
//! - Units: lengths are converted to millimetres and angles to radians from the file's
//!   `LENGTH_UNIT` and `PLANE_ANGLE_UNIT` (SI prefixes, or conversion-based units such as
//!   inches and degrees), as OpenCASCADE reads STEP, so the geometry is in the numbers of a
//!   mesh Gmsh makes from the same file.
//!
//! Names: a face's (edge's) name when it has a unique non-empty one, else `face#<id>`
//! (`edge#<id>`); origins name the instance, its surface type and its line.

use std::collections::BTreeMap;
use std::path::Path;

use super::error::StepError;
use super::parse::{read_step, StepFile, StepInstance, StepValue};
use crate::face_edges::FaceBoundaries;
use crate::iges::affine::{transform_curve, transform_shape, transform_surface, Affine, IDENTITY};
use crate::model::{EntityGeometry, GeometricEntity, GeometryModel};
use crate::shapes::AnalyticShape;
use crate::vec3::{cross, dot, norm, scale, sub};
use crate::NurbsCurve;

/// How deep references are followed (STEP geometry is a few levels deep; a cycle is not).
pub(super) const MAX_DEPTH: usize = 64;

/// Relative margin added around a face's extent where the surface is unbounded along it
/// (cylinder and cone axes, extrusions), as for plane patches.
pub(super) const EXTENT_MARGIN: f64 = 0.1;

/// Points sampled on each edge to size the unbounded surfaces of its faces.
pub(super) const EDGE_SAMPLES: usize = 16;

/// Relative tolerance for "the same point" and "the same plane".
pub(super) const SAME: f64 = 1e-9;

/// Reads a STEP file and converts it with [`geometry_from_step`].
pub fn read_step_geometry(path: &Path) -> Result<GeometryModel, StepError> {
    geometry_from_step(&read_step(path)?)
}

/// Converts the faces (3D) or edges (2D) of a parsed STEP file into named exact NURBS
/// surfaces or curves (see the module documentation).
pub fn geometry_from_step(file: &StepFile) -> Result<GeometryModel, StepError> {
    let mut c = Converter {
        file,
        length: 1.0,
        angle: 1.0,
    };
    c.length = c
        .unit_factor("LENGTH_UNIT")?
        .map_or(1.0, |metres| 1000.0 * metres);
    c.angle = c.unit_factor("PLANE_ANGLE_UNIT")?.unwrap_or(1.0);
    let placements = c.placements()?;
    let faces: Vec<&StepInstance> = file
        .instances
        .values()
        .filter(|i| matches!(i.type_name().as_str(), "ADVANCED_FACE" | "FACE_SURFACE"))
        .collect();
    let mut converted = Vec::new();
    if !faces.is_empty() && !c.is_planar_model(&faces, &placements)? {
        for face in faces {
            let (surface, analytic, kind) = c.face_surface(face)?;
            converted.push((face, kind, EntityGeometry::Surface(surface), analytic));
        }
    } else {
        // 2D models (or wireframes): the edges, in file order, each once.
        let edges: Vec<&StepInstance> = file
            .instances
            .values()
            .filter(|i| i.type_name() == "EDGE_CURVE")
            .collect();
        for edge in edges {
            let curve = c.edge_curve(edge, 0)?;
            converted.push((
                edge,
                "EDGE_CURVE".to_string(),
                EntityGeometry::Curve(curve),
                None,
            ));
        }
        if converted.is_empty() {
            // Wireframes: the curves of GEOMETRIC_CURVE_SETs (OpenCASCADE's bare edges).
            for set in file.instances.values() {
                if set.type_name() != "GEOMETRIC_CURVE_SET" {
                    continue;
                }
                let items = c.params(set, 2)?[1].list().unwrap_or(&[]);
                for item in items {
                    let curve = c.get(item, set)?;
                    let geometry = match curve.type_name().as_str() {
                        "TRIMMED_CURVE" => c.trimmed_curve(curve)?,
                        "CARTESIAN_POINT" => continue,
                        _ => c.free_curve(curve)?,
                    };
                    let kind = curve.type_name();
                    converted.push((curve, kind, EntityGeometry::Curve(geometry), None));
                }
            }
        }
    }
    // Each item once per occurrence of its part, carried into place.
    let mut placed = Vec::with_capacity(converted.len());
    for (i, kind, geometry, analytic) in converted {
        for t in placements.of(i.id) {
            if t == IDENTITY {
                placed.push((i, kind.clone(), geometry.clone(), analytic, t));
                continue;
            }
            let moved = match &geometry {
                EntityGeometry::Curve(g) => {
                    transform_curve(g.clone(), &t).map(EntityGeometry::Curve)
                }
                EntityGeometry::Surface(g) => {
                    transform_surface(g.clone(), &t).map(EntityGeometry::Surface)
                }
            }
            .map_err(|r| c.fail(i, format!("placing it in its assembly: {r}")))?;
            placed.push((
                i,
                kind.clone(),
                moved,
                analytic.and_then(|a| transform_shape(a, &t)),
                t,
            ));
        }
    }
    // The same curve written twice (a model and its copy in another representation).
    let mut unique: Vec<Placed> = Vec::new();
    for item in placed {
        let duplicate = unique.iter().any(|u| match (&u.2, &item.2) {
            (EntityGeometry::Curve(a), EntityGeometry::Curve(b)) => a == b,
            _ => false,
        });
        if !duplicate {
            unique.push(item);
        }
    }
    if unique.is_empty() {
        return Err(StepError::Empty);
    }
    let boundaries = c.face_boundaries(&unique);
    let mut model = GeometryModel::new(
        name_entities(
            unique
                .into_iter()
                .map(|(i, k, g, a, _)| (i, k, g, a))
                .collect(),
        ),
        c.length_uncertainty()?,
    );
    model.set_edges_between_faces(boundaries);
    Ok(model)
}

/// A converted item in place: its instance, kind, geometry, closed form and placement.
type Placed<'a> = (
    &'a StepInstance,
    String,
    EntityGeometry,
    Option<AnalyticShape>,
    Affine,
);

impl Converter<'_> {
    /// The curves of the edges bounding each face among `entities` (entity index, its
    /// edges' curves, once per placement), from which the edges between faces are found
    /// ([`edges_between_faces`]: faces sewn share `EDGE_CURVE`s, faces each in its own
    /// shell hold copies). An edge whose curve cannot be converted is left out: its seam is
    /// then traced as the faces' intersection, as for a model without edges.
    fn face_boundaries(&self, entities: &[Placed]) -> FaceBoundaries {
        let mut curves: BTreeMap<u64, Option<NurbsCurve>> = BTreeMap::new();
        let mut out = Vec::new();
        for (k, (face, _, geometry, _, t)) in entities.iter().enumerate() {
            if !matches!(geometry, EntityGeometry::Surface(_)) {
                continue;
            }
            let mut list = Vec::new();
            for edge in self.face_edges(face).unwrap_or_default() {
                let curve = curves
                    .entry(edge.id)
                    .or_insert_with(|| self.edge_curve(edge, 0).ok())
                    .clone();
                if let Some(Ok(curve)) = curve.map(|c| transform_curve(c, t)) {
                    let origin = format!("STEP #{} EDGE_CURVE (line {})", edge.id, edge.line);
                    list.push((origin, curve));
                }
            }
            out.push((k, list));
        }
        out
    }
}

/// Names and origins (see the module documentation).
fn name_entities(
    converted: Vec<(&StepInstance, String, EntityGeometry, Option<AnalyticShape>)>,
) -> Vec<GeometricEntity> {
    let label = |i: &StepInstance| match i.records[0].params.first() {
        Some(StepValue::String(s)) if !s.trim().is_empty() => Some(s.trim().to_string()),
        _ => None,
    };
    let labels: Vec<Option<String>> = converted.iter().map(|(i, ..)| label(i)).collect();
    let mut seen: std::collections::BTreeMap<u64, usize> = std::collections::BTreeMap::new();
    converted
        .into_iter()
        .zip(&labels)
        .map(|((i, kind, geometry, analytic), l)| {
            let occurrence = {
                let n = seen.entry(i.id).or_insert(0);
                *n += 1;
                *n
            };
            let what = if matches!(geometry, EntityGeometry::Curve(_)) {
                "edge"
            } else {
                "face"
            };
            let mut name = match l {
                Some(l) if labels.iter().filter(|x| x.as_ref() == Some(l)).count() == 1 => {
                    l.clone()
                }
                _ => format!("{what}#{}", i.id),
            };
            if occurrence > 1 {
                name = format!("{name}.{occurrence}");
            }
            let mut entity = GeometricEntity::new(
                name,
                format!(
                    "STEP #{} {} on {kind} (line {})",
                    i.id,
                    i.type_name(),
                    i.line
                ),
                geometry,
            );
            entity.analytic = analytic;
            entity
        })
        .collect()
}

/// An orthonormal frame: origin and axes x, y, z.
#[derive(Debug, Clone, Copy)]
pub(super) struct Frame {
    pub(super) origin: [f64; 3],
    pub(super) x: [f64; 3],
    pub(super) y: [f64; 3],
    pub(super) z: [f64; 3],
}

pub(super) struct Converter<'a> {
    pub(super) file: &'a StepFile,
    /// Millimetres per length unit of the file.
    pub(super) length: f64,
    /// Radians per plane-angle unit of the file.
    pub(super) angle: f64,
}

impl<'a> Converter<'a> {
    pub(super) fn fail(&self, i: &StepInstance, reason: impl Into<String>) -> StepError {
        StepError::Geometry {
            id: i.id,
            name: i.type_name(),
            line: i.line,
            reason: reason.into(),
        }
    }

    pub(super) fn unsupported(&self, i: &StepInstance, context: impl Into<String>) -> StepError {
        StepError::Unsupported {
            id: i.id,
            name: i.type_name(),
            line: i.line,
            context: context.into(),
        }
    }

    /// The instance `value` refers to (from `parent`).
    pub(super) fn get(
        &self,
        value: &StepValue,
        parent: &StepInstance,
    ) -> Result<&'a StepInstance, StepError> {
        let Some(id) = value.reference() else {
            return Err(self.fail(parent, format!("expected a reference, found {value:?}")));
        };
        self.file
            .instances
            .get(&id)
            .ok_or_else(|| StepError::MissingReference {
                id: parent.id,
                name: parent.type_name(),
                line: parent.line,
                reference: id,
            })
    }

    /// The parameters of a simple instance (the first record of a complex one).
    pub(super) fn params<'i>(
        &self,
        i: &'i StepInstance,
        at_least: usize,
    ) -> Result<&'i [StepValue], StepError> {
        let p = &i.records[0].params;
        if p.len() < at_least {
            return Err(self.fail(
                i,
                format!("has {} parameters, expected at least {at_least}", p.len()),
            ));
        }
        Ok(p)
    }

    pub(super) fn real(
        &self,
        v: &StepValue,
        i: &StepInstance,
        what: &str,
    ) -> Result<f64, StepError> {
        v.real()
            .filter(|x| x.is_finite())
            .ok_or_else(|| self.fail(i, format!("{what}: expected a number, found {v:?}")))
    }

    pub(super) fn triple(
        &self,
        v: &StepValue,
        i: &StepInstance,
        what: &str,
    ) -> Result<[f64; 3], StepError> {
        let items = v
            .list()
            .ok_or_else(|| self.fail(i, format!("{what}: expected a list")))?;
        if items.len() != 3 {
            return Err(self.fail(
                i,
                format!(
                    "{what}: {} coordinates (only 3D geometry is read)",
                    items.len()
                ),
            ));
        }
        Ok([
            self.real(&items[0], i, what)?,
            self.real(&items[1], i, what)?,
            self.real(&items[2], i, what)?,
        ])
    }

    pub(super) fn expect_type(&self, i: &StepInstance, name: &str) -> Result<(), StepError> {
        if i.type_name() == name {
            Ok(())
        } else {
            Err(self.fail(i, format!("expected {name}")))
        }
    }

    pub(super) fn point(
        &self,
        v: &StepValue,
        parent: &StepInstance,
    ) -> Result<[f64; 3], StepError> {
        let i = self.get(v, parent)?;
        self.expect_type(i, "CARTESIAN_POINT")?;
        let x = self.triple(&self.params(i, 2)?[1], i, "coordinates")?;
        Ok(scale(x, self.length))
    }

    pub(super) fn direction(
        &self,
        v: &StepValue,
        parent: &StepInstance,
    ) -> Result<[f64; 3], StepError> {
        let i = self.get(v, parent)?;
        self.expect_type(i, "DIRECTION")?;
        let d = self.triple(&self.params(i, 2)?[1], i, "direction ratios")?;
        let n = norm(d);
        if !(n > 0.0 && n.is_finite()) {
            return Err(self.fail(i, "a direction of length zero"));
        }
        Ok(scale(d, 1.0 / n))
    }

    /// `VECTOR(name, direction, magnitude)` as direction × magnitude.
    pub(super) fn vector(
        &self,
        v: &StepValue,
        parent: &StepInstance,
    ) -> Result<[f64; 3], StepError> {
        let i = self.get(v, parent)?;
        self.expect_type(i, "VECTOR")?;
        let p = self.params(i, 3)?;
        Ok(scale(
            self.direction(&p[1], i)?,
            self.length(&p[2], i, "magnitude")?,
        ))
    }

    /// `AXIS2_PLACEMENT_3D(name, location, axis, ref_direction)`; axis z and reference x by
    /// default, the reference made orthogonal to the axis.
    pub(super) fn placement(
        &self,
        v: &StepValue,
        parent: &StepInstance,
    ) -> Result<Frame, StepError> {
        let i = self.get(v, parent)?;
        self.expect_type(i, "AXIS2_PLACEMENT_3D")?;
        let p = self.params(i, 2)?;
        let origin = self.point(&p[1], i)?;
        let z = match p.get(2) {
            Some(StepValue::Unset) | None => [0.0, 0.0, 1.0],
            Some(v) => self.direction(v, i)?,
        };
        let reference = match p.get(3) {
            Some(StepValue::Unset) | None => {
                if z[0].abs() < 0.9 {
                    [1.0, 0.0, 0.0]
                } else {
                    [0.0, 1.0, 0.0]
                }
            }
            Some(v) => self.direction(v, i)?,
        };
        let x = sub(reference, scale(z, dot(reference, z)));
        let n = norm(x);
        if n.is_nan() || n <= SAME {
            return Err(self.fail(i, "the reference direction is parallel to the axis"));
        }
        let x = scale(x, 1.0 / n);
        Ok(Frame {
            origin,
            x,
            y: cross(z, x),
            z,
        })
    }
}

#[cfg(test)]
#[path = "tests/convert.rs"]
mod tests;
