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
//! - Placements (`AXIS2_PLACEMENT_3D`) are applied; assemblies whose parts are placed by a
//!   transformation other than the identity are refused (not supported yet).
//! - Units: lengths are converted to millimetres and angles to radians from the file's
//!   `LENGTH_UNIT` and `PLANE_ANGLE_UNIT` (SI prefixes, or conversion-based units such as
//!   inches and degrees), as OpenCASCADE reads STEP, so the geometry is in the numbers of a
//!   mesh Gmsh makes from the same file.
//!
//! Names: a face's (edge's) name when it has a unique non-empty one, else `face#<id>`
//! (`edge#<id>`); origins name the instance, its surface type and its line.

use std::f64::consts::TAU;
use std::path::Path;

use super::error::StepError;
use super::parse::{read_step, StepFile, StepInstance, StepRecord, StepValue};
use crate::iges::affine::IDENTITY;
use crate::iges::curve_primitives::{line_segment, rational_arc, snap_full_turn};
use crate::iges::plane_patch::plane_patch;
use crate::iges::restrict::restrict_curve;
use crate::iges::swept::{extrude_curve, revolve_curve};
use crate::model::{EntityGeometry, GeometricEntity, GeometryModel};
use crate::shapes::{self, AnalyticShape};
use crate::vec3::{add, cross, distance, dot, norm, scale, sub};
use crate::{NurbsCurve, NurbsSurface};

/// How deep references are followed (STEP geometry is a few levels deep; a cycle is not).
const MAX_DEPTH: usize = 64;

/// Relative margin added around a face's extent where the surface is unbounded along it
/// (cylinder and cone axes, extrusions), as for plane patches.
const EXTENT_MARGIN: f64 = 0.1;

/// Points sampled on each edge to size the unbounded surfaces of its faces.
const EDGE_SAMPLES: usize = 16;

/// Relative tolerance for "the same point" and "the same plane".
const SAME: f64 = 1e-9;

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
    c.check_assembly_placements()?;
    let faces: Vec<&StepInstance> = file
        .instances
        .values()
        .filter(|i| matches!(i.type_name().as_str(), "ADVANCED_FACE" | "FACE_SURFACE"))
        .collect();
    let mut converted = Vec::new();
    if !faces.is_empty() && !c.is_planar_model(&faces)? {
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
    // The same curve written twice (a model and its copy in another representation).
    let mut unique: Vec<(&StepInstance, String, EntityGeometry, Option<AnalyticShape>)> =
        Vec::new();
    for item in converted {
        let duplicate = unique.iter().any(|u| match (&u.2, &item.2) {
            (EntityGeometry::Curve(a), EntityGeometry::Curve(b)) => a == b,
            _ => false,
        });
        if !duplicate {
            unique.push(item);
        }
    }
    let converted = unique;
    if converted.is_empty() {
        return Err(StepError::Empty);
    }
    Ok(GeometryModel {
        entities: name_entities(converted),
    })
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
    converted
        .into_iter()
        .zip(&labels)
        .map(|((i, kind, geometry, analytic), l)| {
            let what = if matches!(geometry, EntityGeometry::Curve(_)) {
                "edge"
            } else {
                "face"
            };
            let name = match l {
                Some(l) if labels.iter().filter(|x| x.as_ref() == Some(l)).count() == 1 => {
                    l.clone()
                }
                _ => format!("{what}#{}", i.id),
            };
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
struct Frame {
    origin: [f64; 3],
    x: [f64; 3],
    y: [f64; 3],
    z: [f64; 3],
}

struct Converter<'a> {
    file: &'a StepFile,
    /// Millimetres per length unit of the file.
    length: f64,
    /// Radians per plane-angle unit of the file.
    angle: f64,
}

/// SI prefixes as powers of ten.
const SI_PREFIXES: [(&str, i32); 16] = [
    ("EXA", 18),
    ("PETA", 15),
    ("TERA", 12),
    ("GIGA", 9),
    ("MEGA", 6),
    ("KILO", 3),
    ("HECTO", 2),
    ("DECA", 1),
    ("DECI", -1),
    ("CENTI", -2),
    ("MILLI", -3),
    ("MICRO", -6),
    ("NANO", -9),
    ("PICO", -12),
    ("FEMTO", -15),
    ("ATTO", -18),
];

impl<'a> Converter<'a> {
    /// The size of the file's unit of `kind` (`LENGTH_UNIT`: in metres; `PLANE_ANGLE_UNIT`:
    /// in radians) as its representation contexts assign it (`GLOBAL_UNIT_ASSIGNED_CONTEXT`),
    /// None when they assign none. Contexts with different units are refused.
    fn unit_factor(&self, kind: &str) -> Result<Option<f64>, StepError> {
        let mut found: Option<(f64, &StepInstance)> = None;
        let mut assigned = Vec::new();
        for c in self.file.instances.values() {
            if let Some(r) = c.record("GLOBAL_UNIT_ASSIGNED_CONTEXT") {
                for u in r.params.first().and_then(StepValue::list).unwrap_or(&[]) {
                    assigned.push(self.get(u, c)?);
                }
            }
        }
        for i in assigned {
            if i.record(kind).is_none() {
                continue;
            }
            let f = self.unit_size(i, 0)?;
            match found {
                Some((g, first)) if (f - g).abs() > SAME * g.abs() => {
                    return Err(self.unsupported(
                        i,
                        format!(
                            " (a second {kind}, {f} against {g} of #{}: mixed units)",
                            first.id
                        ),
                    ))
                }
                None => found = Some((f, i)),
                _ => {}
            }
        }
        Ok(found.map(|(f, _)| f))
    }

    /// The size of a unit instance in SI base units (metre, radian).
    fn unit_size(&self, i: &StepInstance, depth: usize) -> Result<f64, StepError> {
        if depth > MAX_DEPTH {
            return Err(StepError::TooDeep {
                id: i.id,
                line: i.line,
                limit: MAX_DEPTH,
            });
        }
        if let Some(si) = i.record("SI_UNIT") {
            let prefix = match si.params.first() {
                Some(StepValue::Enumeration(p)) => SI_PREFIXES
                    .iter()
                    .find(|(name, _)| name == p)
                    .map(|&(_, e)| e)
                    .ok_or_else(|| self.unsupported(i, format!(" (SI prefix {p})")))?,
                _ => 0,
            };
            return match si.params.get(1).and_then(StepValue::enumeration) {
                Some("METRE" | "RADIAN") => Ok(10f64.powi(prefix)),
                other => Err(self.unsupported(i, format!(" (SI unit {other:?})"))),
            };
        }
        if let Some(c) = i.record("CONVERSION_BASED_UNIT") {
            let measure = c
                .params
                .get(1)
                .ok_or_else(|| self.fail(i, "a conversion-based unit without its measure"))?;
            let m = self.get(measure, i)?;
            let p = &m.records[0].params;
            let (Some(value), Some(unit)) = (p.first().and_then(StepValue::real), p.get(1)) else {
                return Err(self.fail(m, "expected a value and a unit"));
            };
            let base = self.unit_size(self.get(unit, m)?, depth + 1)?;
            let size = value * base;
            if size.is_nan() || size <= 0.0 {
                return Err(self.fail(i, format!("a unit of size {size}")));
            }
            return Ok(size);
        }
        Err(self.unsupported(i, " (as a unit)"))
    }

    /// A length parameter, in millimetres.
    fn length(&self, v: &StepValue, i: &StepInstance, what: &str) -> Result<f64, StepError> {
        Ok(self.real(v, i, what)? * self.length)
    }

    fn fail(&self, i: &StepInstance, reason: impl Into<String>) -> StepError {
        StepError::Geometry {
            id: i.id,
            name: i.type_name(),
            line: i.line,
            reason: reason.into(),
        }
    }

    fn unsupported(&self, i: &StepInstance, context: impl Into<String>) -> StepError {
        StepError::Unsupported {
            id: i.id,
            name: i.type_name(),
            line: i.line,
            context: context.into(),
        }
    }

    /// The instance `value` refers to (from `parent`).
    fn get(&self, value: &StepValue, parent: &StepInstance) -> Result<&'a StepInstance, StepError> {
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
    fn params<'i>(
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

    fn real(&self, v: &StepValue, i: &StepInstance, what: &str) -> Result<f64, StepError> {
        v.real()
            .filter(|x| x.is_finite())
            .ok_or_else(|| self.fail(i, format!("{what}: expected a number, found {v:?}")))
    }

    fn triple(&self, v: &StepValue, i: &StepInstance, what: &str) -> Result<[f64; 3], StepError> {
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

    fn expect_type(&self, i: &StepInstance, name: &str) -> Result<(), StepError> {
        if i.type_name() == name {
            Ok(())
        } else {
            Err(self.fail(i, format!("expected {name}")))
        }
    }

    fn point(&self, v: &StepValue, parent: &StepInstance) -> Result<[f64; 3], StepError> {
        let i = self.get(v, parent)?;
        self.expect_type(i, "CARTESIAN_POINT")?;
        let x = self.triple(&self.params(i, 2)?[1], i, "coordinates")?;
        Ok(scale(x, self.length))
    }

    fn direction(&self, v: &StepValue, parent: &StepInstance) -> Result<[f64; 3], StepError> {
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
    fn vector(&self, v: &StepValue, parent: &StepInstance) -> Result<[f64; 3], StepError> {
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
    fn placement(&self, v: &StepValue, parent: &StepInstance) -> Result<Frame, StepError> {
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

    /// Assemblies: parts placed by a transformation other than the identity are refused.
    fn check_assembly_placements(&self) -> Result<(), StepError> {
        for i in self.file.instances.values() {
            let Some(r) = i.record("ITEM_DEFINED_TRANSFORMATION") else {
                continue;
            };
            if r.params.len() < 4 {
                return Err(self.fail(i, "ITEM_DEFINED_TRANSFORMATION needs two placements"));
            }
            let a = self.placement(&r.params[2], i)?;
            let b = self.placement(&r.params[3], i)?;
            let size = 1.0 + norm(a.origin).max(norm(b.origin));
            let same = distance(a.origin, b.origin) <= SAME * size
                && distance(a.x, b.x) <= SAME
                && distance(a.z, b.z) <= SAME;
            if !same {
                return Err(self.unsupported(
                    i,
                    " (an assembly part placed by a transformation other than the identity; export the model as one part)",
                ));
            }
        }
        Ok(())
    }

    /// Follows `SURFACE_CURVE`, `SEAM_CURVE` (their 3D curve) and `TRIMMED_CURVE` (its
    /// basis) to the curve that carries an edge.
    fn basis_curve(
        &self,
        v: &StepValue,
        parent: &StepInstance,
        depth: usize,
    ) -> Result<&'a StepInstance, StepError> {
        if depth > MAX_DEPTH {
            return Err(StepError::TooDeep {
                id: parent.id,
                line: parent.line,
                limit: MAX_DEPTH,
            });
        }
        let i = self.get(v, parent)?;
        match i.type_name().as_str() {
            "SURFACE_CURVE" | "SEAM_CURVE" | "TRIMMED_CURVE" => {
                let p = self.params(i, 2)?;
                self.basis_curve(&p[1], i, depth + 1)
            }
            _ => Ok(i),
        }
    }

    /// A vertex's point.
    fn vertex(&self, v: &StepValue, parent: &StepInstance) -> Result<[f64; 3], StepError> {
        let i = self.get(v, parent)?;
        self.expect_type(i, "VERTEX_POINT")?;
        self.point(&self.params(i, 2)?[1], i)
    }

    /// `EDGE_CURVE(name, start, end, curve, same_sense)` as a NURBS curve from its start
    /// vertex to its end vertex (B-spline curves whole).
    fn edge_curve(&self, edge: &StepInstance, depth: usize) -> Result<NurbsCurve, StepError> {
        let p = self.params(edge, 5)?;
        let a = self.vertex(&p[1], edge)?;
        let b = self.vertex(&p[2], edge)?;
        let same_sense = p[4].enumeration() != Some("F");
        let closed = p[1] == p[2];
        let carrier = self.basis_curve(&p[3], edge, depth + 1)?;
        self.bounded_curve(carrier, a, b, same_sense, closed)
    }

    /// The piece of `carrier` from `a` to `b` (its own direction when `same_sense`, else
    /// the reverse), the whole closed curve when `closed`: lines as segments, circles and
    /// ellipses as exact arcs, B-spline curves whole.
    fn bounded_curve(
        &self,
        carrier: &StepInstance,
        a: [f64; 3],
        b: [f64; 3],
        same_sense: bool,
        closed: bool,
    ) -> Result<NurbsCurve, StepError> {
        let closed = closed || distance(a, b) <= SAME * (1.0 + norm(a));
        let fail = |r: String| self.fail(carrier, r);
        match carrier.type_name().as_str() {
            "LINE" => line_segment(a, b).map_err(|e| fail(e.to_string())),
            "CIRCLE" | "ELLIPSE" => {
                let q = self.params(carrier, 3)?;
                let f = self.placement(&q[1], carrier)?;
                let r1 = self.length(&q[2], carrier, "radius")?;
                let r2 = if carrier.type_name() == "ELLIPSE" {
                    self.length(&self.params(carrier, 4)?[3], carrier, "second semi-axis")?
                } else {
                    r1
                };
                if !(r1 > 0.0 && r2 > 0.0) {
                    return Err(fail(format!("semi-axes {r1}, {r2}")));
                }
                let angle = |x: [f64; 3]| {
                    let d = sub(x, f.origin);
                    (dot(d, f.y) / r2).atan2(dot(d, f.x) / r1)
                };
                // The piece runs counter-clockwise about the axis when its sense agrees.
                let (from, to) = if same_sense { (a, b) } else { (b, a) };
                let start = angle(from);
                let span = if closed {
                    TAU
                } else {
                    snap_full_turn((angle(to) - start).rem_euclid(TAU))
                };
                if span.is_nan() || span <= 0.0 {
                    return Err(fail("an arc of zero angle".into()));
                }
                let (knots, points, weights) =
                    rational_arc(f.origin, scale(f.x, r1), scale(f.y, r2), start, span);
                let c =
                    NurbsCurve::new(2, knots, points, weights).map_err(|e| fail(e.to_string()))?;
                Ok(if same_sense { c } else { reversed(c) })
            }
            _ => self.free_curve(carrier),
        }
    }

    /// `TRIMMED_CURVE(name, basis, trim1, trim2, sense, preference)`: a B-spline basis
    /// restricted to its parameter trims, other curves between the trim points (given as
    /// points, or as parameters: distance along a line's vector, angle on a circle).
    fn trimmed_curve(&self, i: &StepInstance) -> Result<NurbsCurve, StepError> {
        let p = self.params(i, 5)?;
        let basis = self.basis_curve(&p[1], i, 0)?;
        let same_sense = p[4].enumeration() != Some("F");
        fn trim(v: &StepValue) -> (Option<&StepValue>, Option<f64>) {
            let items = v.list().unwrap_or(&[]);
            let point = items.iter().find(|x| x.reference().is_some());
            let parameter = items.iter().find_map(|x| match x {
                StepValue::Typed(name, inner) if name == "PARAMETER_VALUE" => {
                    inner.first().and_then(StepValue::real)
                }
                _ => None,
            });
            (point, parameter)
        }
        let ((p1, t1), (p2, t2)) = (trim(&p[2]), trim(&p[3]));
        if basis.record("B_SPLINE_CURVE_WITH_KNOTS").is_some() {
            let c = self.free_curve(basis)?;
            let c = match (t1, t2) {
                (Some(t1), Some(t2)) => {
                    restrict_curve(c, t1.min(t2), t1.max(t2)).map_err(|r| self.fail(i, r))?
                }
                _ => c,
            };
            return Ok(if same_sense { c } else { reversed(c) });
        }
        let end = |point: Option<&StepValue>, t: Option<f64>| -> Result<[f64; 3], StepError> {
            if let Some(v) = point {
                return self.point(v, i);
            }
            let t = t.ok_or_else(|| self.fail(i, "a trim with neither point nor parameter"))?;
            let q = self.params(basis, 3)?;
            match basis.type_name().as_str() {
                "LINE" => Ok(add(
                    self.point(&q[1], basis)?,
                    scale(self.vector(&q[2], basis)?, t),
                )),
                "CIRCLE" => {
                    let f = self.placement(&q[1], basis)?;
                    let r = self.length(&q[2], basis, "radius")?;
                    let t = t * self.angle;
                    Ok(add(
                        f.origin,
                        add(scale(f.x, r * t.cos()), scale(f.y, r * t.sin())),
                    ))
                }
                _ => Err(self.unsupported(basis, " (trimmed by parameter)")),
            }
        };
        let (a, b) = (end(p1, t1)?, end(p2, t2)?);
        self.bounded_curve(basis, a, b, same_sense, false)
    }

    /// A bounded curve on its own (B-spline curves), for edges and swept surfaces.
    fn free_curve(&self, i: &StepInstance) -> Result<NurbsCurve, StepError> {
        let Some(spline) = i.record("B_SPLINE_CURVE_WITH_KNOTS") else {
            return Err(self.unsupported(i, " (as a curve)"));
        };
        // Simple form: name, degree, points, form, closed, self_intersect, mults, knots,
        // spec; complex: B_SPLINE_CURVE(degree, points, …) + …_WITH_KNOTS(mults, knots, spec).
        let (head, tail): (&[StepValue], &[StepValue]) = match i.record("B_SPLINE_CURVE") {
            Some(b) => (&b.params[..], &spline.params[..]),
            None if spline.params.len() >= 9 => (&spline.params[1..6], &spline.params[6..]),
            None => return Err(self.fail(i, "too few parameters for a B-spline curve")),
        };
        if head.len() < 2 || tail.len() < 2 {
            return Err(self.fail(i, "too few parameters for a B-spline curve"));
        }
        let degree = integer(&head[0]).ok_or_else(|| self.fail(i, "degree"))?;
        let points = head[1]
            .list()
            .ok_or_else(|| self.fail(i, "control points"))?
            .iter()
            .map(|v| self.point(v, i))
            .collect::<Result<Vec<_>, _>>()?;
        let knots = self.knots(i, &tail[0], &tail[1])?;
        let weights = match i.record("RATIONAL_B_SPLINE_CURVE") {
            Some(r) => self.reals(i, r, 0, "weights")?,
            None => vec![1.0; points.len()],
        };
        NurbsCurve::new(degree, knots, points, weights).map_err(|e| self.fail(i, e.to_string()))
    }

    /// Knots expanded from (multiplicities, distinct knots).
    fn knots(
        &self,
        i: &StepInstance,
        multiplicities: &StepValue,
        knots: &StepValue,
    ) -> Result<Vec<f64>, StepError> {
        let (Some(m), Some(k)) = (multiplicities.list(), knots.list()) else {
            return Err(self.fail(i, "knot multiplicities and knots must be lists"));
        };
        if m.len() != k.len() {
            return Err(self.fail(
                i,
                format!("{} knot multiplicities for {} knots", m.len(), k.len()),
            ));
        }
        let mut out = Vec::new();
        for (m, k) in m.iter().zip(k) {
            let times = integer(m)
                .filter(|&t| t > 0 && t < 64)
                .ok_or_else(|| self.fail(i, format!("knot multiplicity {m:?}")))?;
            let value = self.real(k, i, "knot")?;
            out.extend(std::iter::repeat_n(value, times));
        }
        Ok(out)
    }

    /// A flat list of reals (or a list of lists, flattened row by row) at `record.params[k]`.
    fn reals(
        &self,
        i: &StepInstance,
        record: &StepRecord,
        k: usize,
        what: &str,
    ) -> Result<Vec<f64>, StepError> {
        let list = record
            .params
            .get(k)
            .and_then(StepValue::list)
            .ok_or_else(|| self.fail(i, format!("{what}: expected a list")))?;
        let mut out = Vec::new();
        for v in list {
            match v.list() {
                Some(row) => {
                    for x in row {
                        out.push(self.real(x, i, what)?);
                    }
                }
                None => out.push(self.real(v, i, what)?),
            }
        }
        Ok(out)
    }

    /// Points on the edges bounding `face` (vertices and samples), to size its surface.
    fn face_cover(&self, face: &StepInstance) -> Result<Vec<[f64; 3]>, StepError> {
        let mut cover = Vec::new();
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
    fn face_edges(&self, face: &StepInstance) -> Result<Vec<&'a StepInstance>, StepError> {
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
    fn face_geometry(&self, face: &StepInstance) -> Result<&'a StepInstance, StepError> {
        let p = self.params(face, 3)?;
        self.get(&p[2], face)
    }

    /// Whether every face lies on a plane and all those planes are one.
    fn is_planar_model(&self, faces: &[&StepInstance]) -> Result<bool, StepError> {
        let mut first: Option<Frame> = None;
        for &face in faces {
            let s = self.face_geometry(face)?;
            if s.type_name() != "PLANE" {
                return Ok(false);
            }
            let f = self.placement(&self.params(s, 2)?[1], s)?;
            match first {
                None => first = Some(f),
                Some(g) => {
                    let size = 1.0 + norm(g.origin).max(norm(f.origin));
                    if norm(cross(f.z, g.z)) > SAME
                        || dot(sub(f.origin, g.origin), g.z).abs() > SAME * size
                    {
                        return Ok(false);
                    }
                }
            }
        }
        Ok(first.is_some())
    }

    /// A face's surface as exact NURBS, its closed form, and its type for messages.
    fn face_surface(
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
                (
                    shapes::torus(f.origin, f.z, major, minor).map_err(|e| fail(e.to_string()))?,
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
                (
                    revolve_curve(&g, f.origin, f.z, 0.0, TAU).map_err(|e| fail(e.to_string()))?,
                    None,
                )
            }
            "SURFACE_OF_REVOLUTION" => {
                let p = self.params(s, 3)?;
                let g = self.free_curve(self.basis_curve(&p[1], s, 0)?)?;
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
                let g = self.free_curve(self.basis_curve(&p[1], s, 0)?)?;
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
    fn extent(
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
    fn bspline_surface(
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

/// An integer parameter as a count.
fn integer(v: &StepValue) -> Option<usize> {
    match *v {
        StepValue::Integer(i) if i >= 0 => usize::try_from(i).ok(),
        _ => None,
    }
}

/// The smallest and largest of `values` (+∞, −∞ when empty).
fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    })
}

/// `[lo, hi]` widened by [`EXTENT_MARGIN`] of its length on each side (of 1 when empty).
fn widen(lo: f64, hi: f64) -> (f64, f64) {
    let margin = EXTENT_MARGIN * (hi - lo).max(SAME * (1.0 + lo.abs().max(hi.abs())));
    (lo - margin, hi + margin)
}

/// The same curve run backwards: reversed control points and weights, knots mirrored.
fn reversed(c: NurbsCurve) -> NurbsCurve {
    let (a, b) = (c.knots[0], c.knots[c.knots.len() - 1]);
    let knots = c.knots.iter().rev().map(|&k| a + b - k).collect();
    let mut points = c.control_points;
    points.reverse();
    let mut weights = c.weights;
    weights.reverse();
    NurbsCurve {
        degree: c.degree,
        knots,
        control_points: points,
        weights,
    }
}

#[cfg(test)]
#[path = "tests/convert.rs"]
mod tests;
