//! Geometry input as JSON: a list of named entities (analytic shapes, NACA airfoils, explicit
//! NURBS) turned into a [`GeometryModel`]. Analytic kinds get their exact rational NURBS from
//! [`crate::shapes`] and their closed form as [`AnalyticShape`]; `naca4` gets the interpolating
//! spline of [`Naca4::curve`].
//!
//! # Schema
//!
//! ```json
//! {
//!   "entities": [
//!     {"name": "sphere", "kind": "sphere", "center": [0, 0, 0], "radius": 1},
//!     {"name": "airfoil", "kind": "naca4", "digits": "0012", "chord": 1,
//!      "closed_trailing_edge": true},
//!     {"name": "ring", "kind": "torus", "center": [0, 0, 0], "axis": [0, 0, 1],
//!      "major_radius": 2, "minor_radius": 0.5},
//!     {"name": "pipe", "kind": "cylinder", "point": [0, 0, 0], "axis": [0, 0, 2],
//!      "radius": 0.5},
//!     {"name": "nose", "kind": "cone", "apex": [0, 0, 0], "axis": [1, 0, 0],
//!      "half_angle_degrees": 7, "axial_range": [0, 1]},
//!     {"name": "farfield", "kind": "circle", "center": [0.5, 0], "radius": 10},
//!     {"name": "arc", "kind": "nurbs_curve", "degree": 2, "knots": [0, 0, 0, 1, 1, 1],
//!      "control_points": [[1, 0], [1, 1], [0, 1]], "weights": [1, 0.7071067811865476, 1]},
//!     {"name": "patch", "kind": "nurbs_surface", "degree": [1, 1],
//!      "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
//!      "control_points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1]]]}
//!   ]
//! }
//! ```
//!
//! Rules (every entity is an object with a `"kind"`; lengths in model units):
//!
//! | kind | fields (optional ones with their default) |
//! |---|---|
//! | `sphere` | `center` `[x, y, z]`, `radius` > 0 (NURBS axis z, poles at ±z) |
//! | `torus` | `center`, `axis` `[x, y, z]`, `major_radius` > `minor_radius` > 0 |
//! | `cylinder` | `point` on the axis, `axis` `[x, y, z]`, `radius` > 0, `axial_range` `[t0, t1]` = `[0, ‖axis‖]` |
//! | `cone` | `apex`, `axis` `[x, y, z]` (from the apex into the cone), `half_angle_degrees` in (0, 90), `axial_range` `[h0, h1]` = `[0, ‖axis‖]` with 0 ≤ h0 < h1 |
//! | `circle` | `center` `[x, y]` (z = 0) or `[x, y, z]`, `normal` = `[0, 0, 1]`, `radius` > 0 |
//! | `naca4` | `digits` `"MPTT"` (a string), `chord` = 1, `closed_trailing_edge` = false |
//! | `nurbs_curve` | `degree`, `knots`, `control_points` `[[x, y] or [x, y, z], …]`, `weights` = all 1 |
//! | `nurbs_surface` | `degree` `[du, dv]`, `knots` `[[u…], [v…]]`, `control_points` nested: `[i][j]` = `[x, y, z]` (i along u, j along v), `weights` nested the same way = all 1 |
//!
//! - `name` is optional in every entity; the default is the kind followed by the entity's
//!   index, e.g. `"circle4"`. Names must be non-empty and unique: they are matched against the
//!   mesh's physical group names.
//! - The cylinder is infinite for projection (its closed form); its NURBS patch covers the
//!   axial coordinates `axial_range` measured from `point` along the unit axis, by default from
//!   `point` to `point + axis` (the convention of Gmsh's and OpenCASCADE's cylinders).
//!   The cone is one infinite nappe for projection; its patch covers the heights
//!   `axial_range` above the apex along the unit axis.
//! - The airfoil has its leading edge at the origin and its chord along +x; move the mesh, not
//!   the airfoil.
//! - Unknown fields are errors, as are unknown kinds, bad sizes, inconsistent knot vectors and
//!   duplicate names; errors name the entity's index and name ([`GeometryInputError`]).
//!
//! ```
//! let model = hocurve_nurbs::parse_geometry_json(
//!     r#"{"entities": [{"name": "farfield", "kind": "circle", "center": [0.5, 0], "radius": 10}]}"#,
//! )?;
//! let far = model.entity("farfield").ok_or("no farfield")?;
//! assert!((far.distance([0.5, 3.0, 0.0]) - 7.0).abs() < 1e-14);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::naca::Naca4;
use crate::shapes::{self, AnalyticShape};
use crate::{EntityGeometry, GeometricEntity, GeometryModel, NurbsCurve, NurbsError, NurbsSurface};
use serde::de::DeserializeOwned;
use serde::Deserialize;
use serde_json::{Map, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The entity kinds of the schema, in the order error messages list them.
pub const KINDS: [&str; 8] = [
    "sphere",
    "torus",
    "cylinder",
    "cone",
    "circle",
    "naca4",
    "nurbs_curve",
    "nurbs_surface",
];

/// What was wrong with a JSON geometry description, and where.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GeometryInputError {
    /// The file could not be read.
    #[error("cannot read geometry file {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Not valid JSON, or the top level is not `{"entities": [...]}` (serde_json's message
    /// ends with the line and column).
    #[error("invalid geometry JSON: {source}")]
    Json {
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error.
        column: usize,
        #[source]
        source: serde_json::Error,
    },
    /// An entry of `entities` that is not an object.
    #[error("entity {index}: expected an object {{\"kind\": ..., ...}}")]
    NotAnObject { index: usize },
    /// An entity without `"kind"`.
    #[error("entity {index}: missing \"kind\" (one of {})", KINDS.join(", "))]
    MissingKind { index: usize },
    /// A `"kind"` that is not one of [`KINDS`].
    #[error("entity {index}: unknown kind {kind} (valid kinds: {})", KINDS.join(", "))]
    UnknownKind {
        index: usize,
        /// The kind as written (JSON, with quotes for strings).
        kind: String,
    },
    /// A missing, unknown or ill-typed field.
    #[error("entity {index} (\"{name}\", {kind}): {source}")]
    Field {
        index: usize,
        /// The entity's name as given (empty if none).
        name: String,
        kind: String,
        #[source]
        source: serde_json::Error,
    },
    /// Fields that do not fit together (a ragged control net, an empty name).
    #[error("entity {index} (\"{name}\"): {reason}")]
    Invalid {
        index: usize,
        name: String,
        reason: String,
    },
    /// The fields describe no valid curve or surface (negative radius, wrong knot count, …).
    #[error("entity {index} (\"{name}\"): {source}")]
    Geometry {
        index: usize,
        name: String,
        #[source]
        source: NurbsError,
    },
    /// Two entities with the same name.
    #[error("entity {index}: name \"{name}\" is already used by entity {first}")]
    DuplicateName {
        index: usize,
        first: usize,
        name: String,
    },
}

/// The top level of the file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Document {
    entities: Vec<Value>,
}

/// A point `[x, y, z]`; with `XY`, also `[x, y]` (z = 0) for planar input.
#[derive(Deserialize, Clone, Copy)]
#[serde(try_from = "Vec<f64>")]
struct Point<const XY: bool>([f64; 3]);

/// `[x, y, z]`.
type Point3 = Point<false>;

/// `[x, y]` (z = 0) or `[x, y, z]`.
type Point2or3 = Point<true>;

impl<const XY: bool> TryFrom<Vec<f64>> for Point<XY> {
    type Error = String;
    fn try_from(v: Vec<f64>) -> Result<Self, String> {
        let expected = if XY {
            "[x, y] or [x, y, z]"
        } else {
            "[x, y, z]"
        };
        match v[..] {
            [x, y] if XY => Ok(Self([x, y, 0.0])),
            [x, y, z] => Ok(Self([x, y, z])),
            _ => Err(format!("expected {expected}, got {} numbers", v.len())),
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereSpec {
    name: Option<String>,
    center: Point3,
    radius: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TorusSpec {
    name: Option<String>,
    center: Point3,
    axis: Point3,
    major_radius: f64,
    minor_radius: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CylinderSpec {
    name: Option<String>,
    point: Point3,
    axis: Point3,
    radius: f64,
    axial_range: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConeSpec {
    name: Option<String>,
    apex: Point3,
    axis: Point3,
    half_angle_degrees: f64,
    axial_range: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CircleSpec {
    name: Option<String>,
    center: Point2or3,
    normal: Option<Point3>,
    radius: f64,
}

fn unit_chord() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Naca4Spec {
    name: Option<String>,
    digits: String,
    #[serde(default = "unit_chord")]
    chord: f64,
    #[serde(default)]
    closed_trailing_edge: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NurbsCurveSpec {
    name: Option<String>,
    degree: usize,
    knots: Vec<f64>,
    control_points: Vec<Point2or3>,
    weights: Option<Vec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NurbsSurfaceSpec {
    name: Option<String>,
    degree: [usize; 2],
    knots: [Vec<f64>; 2],
    control_points: Vec<Vec<Point3>>,
    weights: Option<Vec<Vec<f64>>>,
}

/// A parsed entity before naming: its optional name, NURBS and closed form.
struct Parsed {
    name: Option<String>,
    geometry: EntityGeometry,
    analytic: Option<AnalyticShape>,
}

/// Why a spec could not become geometry (turned into an error with the entity's index).
enum SpecError {
    Geometry(NurbsError),
    Invalid(String),
}

impl From<NurbsError> for SpecError {
    fn from(e: NurbsError) -> Self {
        Self::Geometry(e)
    }
}

/// Parses a JSON geometry description (schema in the module documentation).
pub fn parse_geometry_json(text: &str) -> Result<GeometryModel, GeometryInputError> {
    let document: Document =
        serde_json::from_str(text).map_err(|source| GeometryInputError::Json {
            line: source.line(),
            column: source.column(),
            source,
        })?;
    let mut entities: Vec<GeometricEntity> = Vec::with_capacity(document.entities.len());
    let mut first_use: BTreeMap<String, usize> = BTreeMap::new();
    for (index, value) in document.entities.into_iter().enumerate() {
        let entity = parse_entity(index, value)?;
        if let Some(&first) = first_use.get(&entity.name) {
            return Err(GeometryInputError::DuplicateName {
                index,
                first,
                name: entity.name,
            });
        }
        first_use.insert(entity.name.clone(), index);
        entities.push(entity);
    }
    Ok(GeometryModel::new(entities, None))
}

/// Reads and parses a JSON geometry file; entity origins name the file.
pub fn read_geometry_json(path: &Path) -> Result<GeometryModel, GeometryInputError> {
    let text = std::fs::read_to_string(path).map_err(|source| GeometryInputError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut model = parse_geometry_json(&text)?;
    for entity in &mut model.entities {
        entity.origin = format!("{}: {}", path.display(), entity.origin);
    }
    Ok(model)
}

fn parse_entity(index: usize, value: Value) -> Result<GeometricEntity, GeometryInputError> {
    let Value::Object(mut fields) = value else {
        return Err(GeometryInputError::NotAnObject { index });
    };
    let kind = match fields.remove("kind") {
        Some(Value::String(kind)) if KINDS.contains(&kind.as_str()) => kind,
        Some(other) => {
            return Err(GeometryInputError::UnknownKind {
                index,
                kind: other.to_string(),
            })
        }
        None => return Err(GeometryInputError::MissingKind { index }),
    };
    let given_name = fields
        .get("name")
        .and_then(Value::as_str)
        .unwrap_or_default()
        .to_owned();
    let parsed = parse_fields(&kind, fields).map_err(|source| GeometryInputError::Field {
        index,
        name: given_name.clone(),
        kind: kind.clone(),
        source,
    })?;
    let parsed = parsed.map_err(|e| match e {
        SpecError::Geometry(source) => GeometryInputError::Geometry {
            index,
            name: given_name.clone(),
            source,
        },
        SpecError::Invalid(reason) => GeometryInputError::Invalid {
            index,
            name: given_name.clone(),
            reason,
        },
    })?;
    let name = parsed.name.unwrap_or_else(|| format!("{kind}{index}"));
    if name.is_empty() {
        return Err(GeometryInputError::Invalid {
            index,
            name,
            reason: "the name is empty".into(),
        });
    }
    Ok(GeometricEntity {
        name,
        origin: format!("JSON entity {index} ({kind})"),
        geometry: parsed.geometry,
        analytic: parsed.analytic,
        samples: Default::default(),
        hulls: Default::default(),
    })
}

fn spec<T: DeserializeOwned>(fields: Map<String, Value>) -> Result<T, serde_json::Error> {
    serde_json::from_value(Value::Object(fields))
}

/// Deserialises the fields of `kind` (outer error) and builds the geometry (inner error).
fn parse_fields(
    kind: &str,
    fields: Map<String, Value>,
) -> Result<Result<Parsed, SpecError>, serde_json::Error> {
    Ok(match kind {
        "sphere" => build_sphere(spec(fields)?),
        "torus" => build_torus(spec(fields)?),
        "cylinder" => build_cylinder(spec(fields)?),
        "cone" => build_cone(spec(fields)?),
        "circle" => build_circle(spec(fields)?),
        "naca4" => build_naca4(spec(fields)?),
        "nurbs_curve" => build_nurbs_curve(spec(fields)?),
        _ => build_nurbs_surface(spec(fields)?),
    })
}

fn build_sphere(s: SphereSpec) -> Result<Parsed, SpecError> {
    Ok(Parsed {
        geometry: EntityGeometry::Surface(shapes::sphere(s.center.0, s.radius)?),
        analytic: Some(AnalyticShape::new_sphere(s.center.0, s.radius)?),
        name: s.name,
    })
}

fn build_torus(s: TorusSpec) -> Result<Parsed, SpecError> {
    let (c, a) = (s.center.0, s.axis.0);
    Ok(Parsed {
        geometry: EntityGeometry::Surface(shapes::torus(c, a, s.major_radius, s.minor_radius)?),
        analytic: Some(AnalyticShape::new_torus(
            c,
            a,
            s.major_radius,
            s.minor_radius,
        )?),
        name: s.name,
    })
}

fn build_cylinder(s: CylinderSpec) -> Result<Parsed, SpecError> {
    let (p, a) = (s.point.0, s.axis.0);
    let length = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    let [t0, t1] = s.axial_range.unwrap_or([0.0, length]);
    Ok(Parsed {
        geometry: EntityGeometry::Surface(shapes::cylinder(p, a, s.radius, (t0, t1))?),
        analytic: Some(AnalyticShape::new_cylinder(p, a, s.radius)?),
        name: s.name,
    })
}

fn build_cone(s: ConeSpec) -> Result<Parsed, SpecError> {
    let (apex, a) = (s.apex.0, s.axis.0);
    let length = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    let [h0, h1] = s.axial_range.unwrap_or([0.0, length]);
    let half_angle = s.half_angle_degrees.to_radians();
    Ok(Parsed {
        geometry: EntityGeometry::Surface(shapes::cone(apex, a, half_angle, (h0, h1))?),
        analytic: Some(AnalyticShape::new_cone(apex, a, half_angle)?),
        name: s.name,
    })
}

fn build_circle(s: CircleSpec) -> Result<Parsed, SpecError> {
    let normal = s.normal.map_or([0.0, 0.0, 1.0], |n| n.0);
    let c = s.center.0;
    Ok(Parsed {
        geometry: EntityGeometry::Curve(shapes::circle(c, normal, s.radius)?),
        analytic: Some(AnalyticShape::new_circle(c, normal, s.radius)?),
        name: s.name,
    })
}

fn build_naca4(s: Naca4Spec) -> Result<Parsed, SpecError> {
    let airfoil = Naca4::from_digits(&s.digits, s.chord, s.closed_trailing_edge)?;
    Ok(Parsed {
        geometry: EntityGeometry::Curve(airfoil.curve()?),
        analytic: None,
        name: s.name,
    })
}

fn build_nurbs_curve(s: NurbsCurveSpec) -> Result<Parsed, SpecError> {
    let points: Vec<[f64; 3]> = s.control_points.iter().map(|p| p.0).collect();
    let weights = s.weights.unwrap_or_else(|| vec![1.0; points.len()]);
    Ok(Parsed {
        geometry: EntityGeometry::Curve(NurbsCurve::new(s.degree, s.knots, points, weights)?),
        analytic: None,
        name: s.name,
    })
}

fn build_nurbs_surface(s: NurbsSurfaceSpec) -> Result<Parsed, SpecError> {
    let [degree_u, degree_v] = s.degree;
    let [knots_u, knots_v] = s.knots;
    let n_u = s.control_points.len();
    let n_v = s.control_points.first().map_or(0, Vec::len);
    if let Some(i) = s.control_points.iter().position(|row| row.len() != n_v) {
        return Err(SpecError::Invalid(format!(
            "control point row {i} has {} points, row 0 has {n_v}",
            s.control_points[i].len()
        )));
    }
    // The nested net fixes n_u and n_v, so a knot vector of the wrong length is reported as
    // such (rather than as a net of the wrong size).
    for (degree, knots, count) in [(degree_u, &knots_u, n_u), (degree_v, &knots_v, n_v)] {
        if knots.len() != count + degree + 1 {
            return Err(NurbsError::KnotCount {
                expected: count + degree + 1,
                found: knots.len(),
                control_points: count,
                degree,
            }
            .into());
        }
    }
    let weights = match s.weights {
        Some(rows) => {
            if rows.len() != n_u || rows.iter().any(|r| r.len() != n_v) {
                return Err(SpecError::Invalid(format!(
                    "weights must be nested like the control points ({n_u} rows of {n_v})"
                )));
            }
            rows.concat()
        }
        None => vec![1.0; n_u * n_v],
    };
    let points = s.control_points.iter().flatten().map(|p| p.0).collect();
    Ok(Parsed {
        geometry: EntityGeometry::Surface(NurbsSurface::new(
            degree_u, degree_v, knots_u, knots_v, points, weights,
        )?),
        analytic: None,
        name: s.name,
    })
}

#[cfg(test)]
#[path = "tests/json.rs"]
mod tests;
