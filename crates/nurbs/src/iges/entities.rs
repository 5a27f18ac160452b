//! Typed IGES entity records (plain data as written in the Parameter Data section; nothing is
//! evaluated or converted here).

use super::params::Param;

/// The parameters of one entity, by type. Pointers are DE sequence numbers (odd).
#[derive(Debug, Clone, PartialEq)]
pub enum EntityData {
    /// 100: circular arc in the plane z = `zt` of its definition space, counter-clockwise
    /// from `start` to `end` about `center` (start = end: full circle).
    CircularArc {
        zt: f64,
        center: [f64; 2],
        start: [f64; 2],
        end: [f64; 2],
    },
    /// 102: composite curve, the listed curves end to end.
    CompositeCurve { curves: Vec<u32> },
    /// 104: conic arc `A x² + B x y + C y² + D x + E y + F = 0` in the plane z = `zt`.
    ConicArc {
        coefficients: [f64; 6],
        zt: f64,
        start: [f64; 2],
        end: [f64; 2],
    },
    /// 108: plane `A x + B y + C z = D`, optionally bounded by a closed curve; `point` and
    /// `size` locate the display symbol.
    Plane {
        coefficients: [f64; 4],
        boundary: Option<u32>,
        point: [f64; 3],
        size: f64,
    },
    /// 110: line (segment for form 0, ray for form 1, line for form 2) through two points.
    Line { start: [f64; 3], end: [f64; 3] },
    /// 120: surface of revolution of the curve `generatrix` about the line `axis`
    /// (a 110 entity), from `start_angle` to `end_angle` (radians).
    SurfaceOfRevolution {
        axis: u32,
        generatrix: u32,
        start_angle: f64,
        end_angle: f64,
    },
    /// 122: tabulated cylinder: the curve `directrix` swept along the vector from its start
    /// point to `end`.
    TabulatedCylinder { directrix: u32, end: [f64; 3] },
    /// 124: transformation matrix `x' = R x + T`; rows are `[R_i1, R_i2, R_i3, T_i]`.
    TransformationMatrix { matrix: [[f64; 4]; 3] },
    /// 126: rational B-spline curve.
    BSplineCurve(BSplineCurveData),
    /// 128: rational B-spline surface.
    BSplineSurface(BSplineSurfaceData),
    /// 142: curve on a parametric surface.
    CurveOnSurface {
        /// How the curve was created (0 unspecified, 1 projection, 2 intersection,
        /// 3 isoparametric).
        creation: i64,
        surface: u32,
        /// The curve in the surface's parameter space (`None` when 0).
        parameter_curve: Option<u32>,
        /// The curve in model space (`None` when 0).
        model_curve: Option<u32>,
        /// Preferred representation (0 unspecified, 1 parameter curve, 2 model curve,
        /// 3 either).
        preferred: i64,
    },
    /// 144: trimmed (parametric) surface.
    TrimmedSurface {
        surface: u32,
        /// `false` (N1 = 0): the outer boundary is the boundary of `surface`.
        outer_specified: bool,
        /// Outer boundary (a 142), `None` when not specified.
        outer: Option<u32>,
        /// Inner boundaries (142 entities).
        inner: Vec<u32>,
    },
    /// B-rep entities (186 manifold solid, 502 vertex list, 504 edge list, 510 face,
    /// 514 shell): kept as raw parameters (after the type number), not interpreted.
    Brep {
        type_number: i32,
        params: Vec<Param>,
    },
    /// Entities that a conversion ignores, having no curve or surface a mesh boundary
    /// could lie on: 402 associativity, 406 property, 314 colour, 0 null, 116 point,
    /// 202..=230 annotations, 312 text template, 404 drawing, 410 view.
    Ignored { type_number: i32 },
    /// Any other entity type; a conversion step reports it with its type and line.
    Unsupported { type_number: i32 },
}

/// Parameters of a 126 rational B-spline curve.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineCurveData {
    /// Upper index of the sum: the curve has `k + 1` control points.
    pub k: usize,
    /// Degree.
    pub m: usize,
    /// PROP1: planar.
    pub planar: bool,
    /// PROP2: closed.
    pub closed: bool,
    /// PROP3: polynomial (all weights equal) rather than rational.
    pub polynomial: bool,
    /// PROP4: periodic.
    pub periodic: bool,
    /// `k + m + 2` knots.
    pub knots: Vec<f64>,
    /// `k + 1` weights.
    pub weights: Vec<f64>,
    /// `k + 1` control points.
    pub control_points: Vec<[f64; 3]>,
    /// Parameter range `[v0, v1]`.
    pub v0: f64,
    pub v1: f64,
    /// Unit normal of the plane for planar curves (when written).
    pub normal: Option<[f64; 3]>,
}

/// Parameters of a 128 rational B-spline surface. Weights and control points are stored with
/// the first (u, "S") index varying fastest: index `i + (k1 + 1) * j`.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineSurfaceData {
    pub k1: usize,
    pub k2: usize,
    /// Degrees in u and v.
    pub m1: usize,
    pub m2: usize,
    /// PROP1, PROP2: closed in u, in v.
    pub closed_u: bool,
    pub closed_v: bool,
    /// PROP3: polynomial.
    pub polynomial: bool,
    /// PROP4, PROP5: periodic in u, in v.
    pub periodic_u: bool,
    pub periodic_v: bool,
    /// `k1 + m1 + 2` knots in u.
    pub knots_u: Vec<f64>,
    /// `k2 + m2 + 2` knots in v.
    pub knots_v: Vec<f64>,
    pub weights: Vec<f64>,
    pub control_points: Vec<[f64; 3]>,
    /// Parameter domain `[u0, u1] × [v0, v1]`.
    pub u0: f64,
    pub u1: f64,
    pub v0: f64,
    pub v1: f64,
}

impl EntityData {
    /// The IGES entity type number of this record.
    pub fn type_number(&self) -> i32 {
        match self {
            EntityData::CircularArc { .. } => 100,
            EntityData::CompositeCurve { .. } => 102,
            EntityData::ConicArc { .. } => 104,
            EntityData::Plane { .. } => 108,
            EntityData::Line { .. } => 110,
            EntityData::SurfaceOfRevolution { .. } => 120,
            EntityData::TabulatedCylinder { .. } => 122,
            EntityData::TransformationMatrix { .. } => 124,
            EntityData::BSplineCurve(_) => 126,
            EntityData::BSplineSurface(_) => 128,
            EntityData::CurveOnSurface { .. } => 142,
            EntityData::TrimmedSurface { .. } => 144,
            EntityData::Brep { type_number, .. }
            | EntityData::Ignored { type_number }
            | EntityData::Unsupported { type_number } => *type_number,
        }
    }

    /// DE pointers to other entities held in the parameters (not transformation matrices).
    pub fn references(&self) -> Vec<u32> {
        match self {
            EntityData::CompositeCurve { curves } => curves.clone(),
            EntityData::Plane { boundary, .. } => boundary.iter().copied().collect(),
            EntityData::SurfaceOfRevolution {
                axis, generatrix, ..
            } => vec![*axis, *generatrix],
            EntityData::TabulatedCylinder { directrix, .. } => vec![*directrix],
            EntityData::CurveOnSurface {
                surface,
                parameter_curve,
                model_curve,
                ..
            } => std::iter::once(*surface)
                .chain(*parameter_curve)
                .chain(*model_curve)
                .collect(),
            EntityData::TrimmedSurface {
                surface,
                outer,
                inner,
                ..
            } => std::iter::once(*surface)
                .chain(*outer)
                .chain(inner.iter().copied())
                .collect(),
            _ => Vec::new(),
        }
    }
}
