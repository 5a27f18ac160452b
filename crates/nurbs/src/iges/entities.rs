//! Typed IGES entity records (plain data as written in the Parameter Data section; nothing is
//! evaluated or converted here).

use super::params::Param;
use super::IgesError;
use crate::basis::MAX_DEGREE;

/// What a degree must be (the text of [`IgesError::Parameter`] is static).
const DEGREE_EXPECTED: &str = "a degree from 0 to 24 (the highest supported)";
// keeps the message above true
const _: () = assert!(MAX_DEGREE == 24);

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
    /// Entities without geometry that a conversion ignores: 402 associativity,
    /// 406 property, 314 colour, 0 null.
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

/// A DE pointer read from a parameter, with its file line (for validation).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reference {
    pub pointer: u32,
    pub line: usize,
    pub index: usize,
    pub name: &'static str,
}

/// Sequential reader of one entity's parameters.
pub(crate) struct Reader<'a> {
    params: &'a [Param],
    next: usize,
    de: u32,
    entity_type: i32,
    end_line: usize,
    pub refs: Vec<Reference>,
}

impl<'a> Reader<'a> {
    pub fn new(params: &'a [Param], de: u32, entity_type: i32, end_line: usize) -> Self {
        Reader {
            params,
            next: 0,
            de,
            entity_type,
            end_line,
            refs: Vec::new(),
        }
    }

    fn error(&self, index: usize, name: &'static str, expected: &'static str) -> IgesError {
        let (line, found) = match self.params.get(index) {
            Some(p) => (p.line, p.describe()),
            None => (self.end_line, "the end of the parameter record".to_string()),
        };
        IgesError::Parameter {
            line,
            de: self.de,
            entity_type: self.entity_type,
            index,
            name,
            expected,
            found,
        }
    }

    fn take(&mut self, name: &'static str, expected: &'static str) -> Result<&'a Param, IgesError> {
        let i = self.next;
        match self.params.get(i) {
            Some(p) => {
                self.next += 1;
                Ok(p)
            }
            None => Err(self.error(i, name, expected)),
        }
    }

    /// The number of parameters not read yet.
    pub fn remaining(&self) -> usize {
        self.params.len().saturating_sub(self.next)
    }

    pub fn rest(&self) -> Vec<Param> {
        self.params[self.next.min(self.params.len())..].to_vec()
    }

    pub fn real(&mut self, name: &'static str) -> Result<f64, IgesError> {
        let i = self.next;
        let p = self.take(name, "a real number")?;
        p.as_real()
            .ok_or_else(|| self.error(i, name, "a real number"))
    }

    pub fn int(&mut self, name: &'static str) -> Result<i64, IgesError> {
        let i = self.next;
        let p = self.take(name, "an integer")?;
        p.as_int().ok_or_else(|| self.error(i, name, "an integer"))
    }

    pub fn flag(&mut self, name: &'static str) -> Result<bool, IgesError> {
        let i = self.next;
        match self.int(name)? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(self.error(i, name, "0 or 1")),
        }
    }

    /// A non-negative count of which `per_item` parameters each must still follow.
    pub fn count(&mut self, name: &'static str, per_item: usize) -> Result<usize, IgesError> {
        let i = self.next;
        let v = self.int(name)?;
        if v < 0 {
            return Err(self.error(i, name, "a non-negative integer"));
        }
        let n = v as usize;
        match n.checked_mul(per_item) {
            Some(t) if t <= self.remaining() => {}
            _ => {
                return Err(self.error(
                    i,
                    name,
                    "a count not larger than the parameters that follow",
                ));
            }
        }
        Ok(n)
    }

    /// An optional DE pointer (0 or defaulted → `None`).
    pub fn opt_ptr(&mut self, name: &'static str) -> Result<Option<u32>, IgesError> {
        let i = self.next;
        let v = self.int(name)?;
        if v == 0 {
            return Ok(None);
        }
        if v < 0 || v > u32::MAX as i64 {
            return Err(self.error(i, name, "a DE pointer (positive odd integer)"));
        }
        self.refs.push(Reference {
            pointer: v as u32,
            line: self.params[i].line,
            index: i,
            name,
        });
        Ok(Some(v as u32))
    }

    /// A required DE pointer.
    pub fn ptr(&mut self, name: &'static str) -> Result<u32, IgesError> {
        let i = self.next;
        self.opt_ptr(name)?
            .ok_or_else(|| self.error(i, name, "a DE pointer (positive odd integer)"))
    }

    pub fn xy(&mut self, nx: &'static str, ny: &'static str) -> Result<[f64; 2], IgesError> {
        Ok([self.real(nx)?, self.real(ny)?])
    }

    pub fn xyz(
        &mut self,
        nx: &'static str,
        ny: &'static str,
        nz: &'static str,
    ) -> Result<[f64; 3], IgesError> {
        Ok([self.real(nx)?, self.real(ny)?, self.real(nz)?])
    }

    fn reals(&mut self, n: usize, name: &'static str) -> Result<Vec<f64>, IgesError> {
        (0..n).map(|_| self.real(name)).collect()
    }

    fn points(&mut self, n: usize) -> Result<Vec<[f64; 3]>, IgesError> {
        (0..n).map(|_| self.xyz("X", "Y", "Z")).collect()
    }

    /// A B-spline degree: at most [`MAX_DEGREE`], which bounds the work of every later
    /// step (degree elevation, knot insertion) whatever the file says.
    fn degree(&mut self, name: &'static str) -> Result<usize, IgesError> {
        let i = self.next;
        let m = self.non_negative(name)?;
        if m > MAX_DEGREE {
            return Err(self.error(i, name, DEGREE_EXPECTED));
        }
        Ok(m)
    }

    fn non_negative(&mut self, name: &'static str) -> Result<usize, IgesError> {
        let i = self.next;
        let v = self.int(name)?;
        if v < 0 || v > self.params.len() as i64 {
            return Err(self.error(
                i,
                name,
                "a non-negative integer not larger than the parameter count",
            ));
        }
        Ok(v as usize)
    }

    /// Checks that `n` more parameters follow (for sizes computed from several fields).
    fn need(&self, n: Option<usize>, name: &'static str, at: usize) -> Result<usize, IgesError> {
        match n {
            Some(n) if n <= self.remaining() => Ok(n),
            _ => Err(self.error(
                at,
                name,
                "array sizes that fit in the parameters that follow",
            )),
        }
    }
}

/// Reads the typed record of an entity from its parameters (the entity type number, the
/// first parameter, already removed).
pub(crate) fn parse_entity(entity_type: i32, r: &mut Reader<'_>) -> Result<EntityData, IgesError> {
    Ok(match entity_type {
        100 => EntityData::CircularArc {
            zt: r.real("ZT")?,
            center: r.xy("X1", "Y1")?,
            start: r.xy("X2", "Y2")?,
            end: r.xy("X3", "Y3")?,
        },
        102 => {
            let n = r.count("N", 1)?;
            let curves = (0..n).map(|_| r.ptr("DE(i)")).collect::<Result<_, _>>()?;
            EntityData::CompositeCurve { curves }
        }
        104 => EntityData::ConicArc {
            coefficients: [
                r.real("A")?,
                r.real("B")?,
                r.real("C")?,
                r.real("D")?,
                r.real("E")?,
                r.real("F")?,
            ],
            zt: r.real("ZT")?,
            start: r.xy("X1", "Y1")?,
            end: r.xy("X2", "Y2")?,
        },
        108 => EntityData::Plane {
            coefficients: [r.real("A")?, r.real("B")?, r.real("C")?, r.real("D")?],
            boundary: r.opt_ptr("PTR")?,
            point: r.xyz("X", "Y", "Z")?,
            size: r.real("SIZE")?,
        },
        110 => EntityData::Line {
            start: r.xyz("X1", "Y1", "Z1")?,
            end: r.xyz("X2", "Y2", "Z2")?,
        },
        120 => EntityData::SurfaceOfRevolution {
            axis: r.ptr("L")?,
            generatrix: r.ptr("C")?,
            start_angle: r.real("SA")?,
            end_angle: r.real("TA")?,
        },
        122 => EntityData::TabulatedCylinder {
            directrix: r.ptr("DE")?,
            end: r.xyz("LX", "LY", "LZ")?,
        },
        124 => {
            let mut matrix = [[0.0; 4]; 3];
            const NAMES: [[&str; 4]; 3] = [
                ["R11", "R12", "R13", "T1"],
                ["R21", "R22", "R23", "T2"],
                ["R31", "R32", "R33", "T3"],
            ];
            for (row, names) in matrix.iter_mut().zip(NAMES) {
                for (v, name) in row.iter_mut().zip(names) {
                    *v = r.real(name)?;
                }
            }
            EntityData::TransformationMatrix { matrix }
        }
        126 => {
            let at = 1;
            let k = r.non_negative("K")?;
            let m = r.degree("M")?;
            let (planar, closed, polynomial, periodic) = (
                r.flag("PROP1")?,
                r.flag("PROP2")?,
                r.flag("PROP3")?,
                r.flag("PROP4")?,
            );
            let nk = k + m + 2;
            r.need(Some(nk + 4 * (k + 1) + 2), "K, M", at)?;
            let knots = r.reals(nk, "T(i) (knot)")?;
            let weights = r.reals(k + 1, "W(i) (weight)")?;
            let control_points = r.points(k + 1)?;
            let v0 = r.real("V(0)")?;
            let v1 = r.real("V(1)")?;
            let normal = if r.remaining() >= 3 {
                Some(r.xyz("XNORM", "YNORM", "ZNORM")?)
            } else {
                None
            };
            EntityData::BSplineCurve(BSplineCurveData {
                k,
                m,
                planar,
                closed,
                polynomial,
                periodic,
                knots,
                weights,
                control_points,
                v0,
                v1,
                normal,
            })
        }
        128 => {
            let at = 1;
            let k1 = r.non_negative("K1")?;
            let k2 = r.non_negative("K2")?;
            let m1 = r.degree("M1")?;
            let m2 = r.degree("M2")?;
            let closed_u = r.flag("PROP1")?;
            let closed_v = r.flag("PROP2")?;
            let polynomial = r.flag("PROP3")?;
            let periodic_u = r.flag("PROP4")?;
            let periodic_v = r.flag("PROP5")?;
            let nu = k1 + m1 + 2;
            let nv = k2 + m2 + 2;
            let np = (k1 + 1).checked_mul(k2 + 1);
            let total = np
                .and_then(|n| n.checked_mul(4))
                .and_then(|n| n.checked_add(nu + nv + 4));
            r.need(total, "K1, K2, M1, M2", at)?;
            let np = np.unwrap_or(0);
            let knots_u = r.reals(nu, "S(i) (u knot)")?;
            let knots_v = r.reals(nv, "T(i) (v knot)")?;
            let weights = r.reals(np, "W(i,j) (weight)")?;
            let control_points = r.points(np)?;
            EntityData::BSplineSurface(BSplineSurfaceData {
                k1,
                k2,
                m1,
                m2,
                closed_u,
                closed_v,
                polynomial,
                periodic_u,
                periodic_v,
                knots_u,
                knots_v,
                weights,
                control_points,
                u0: r.real("U(0)")?,
                u1: r.real("U(1)")?,
                v0: r.real("V(0)")?,
                v1: r.real("V(1)")?,
            })
        }
        142 => EntityData::CurveOnSurface {
            creation: r.int("CRTN")?,
            surface: r.ptr("SPTR")?,
            parameter_curve: r.opt_ptr("BPTR")?,
            model_curve: r.opt_ptr("CPTR")?,
            preferred: r.int("PREF")?,
        },
        144 => {
            let surface = r.ptr("PTS")?;
            let outer_specified = r.flag("N1")?;
            let n2 = r.count("N2", 1)?;
            let outer = r.opt_ptr("PTO")?;
            let inner = (0..n2).map(|_| r.ptr("PTI(i)")).collect::<Result<_, _>>()?;
            EntityData::TrimmedSurface {
                surface,
                outer_specified,
                outer,
                inner,
            }
        }
        186 | 502 | 504 | 508 | 510 | 514 => EntityData::Brep {
            type_number: entity_type,
            params: r.rest(),
        },
        0 | 314 | 402 | 406 => EntityData::Ignored {
            type_number: entity_type,
        },
        t => EntityData::Unsupported { type_number: t },
    })
}
