//! The Parameter Data layout of each supported entity type: which fields, in which order,
//! make its typed record.

use super::entities::{BSplineCurveData, BSplineSurfaceData, EntityData};
use super::error::IgesError;
use super::param_reader::Reader;

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
        // Null, colour, associativity, property; points (OpenCASCADE writes the free
        // vertices of a model as 116: nothing a mesh boundary lies on); annotations
        // (dimensions, notes, labels, 202..=230), text templates, drawings and views.
        0 | 116 | 202..=230 | 312 | 314 | 402 | 404 | 406 | 410 => EntityData::Ignored {
            type_number: entity_type,
        },
        t => EntityData::Unsupported { type_number: t },
    })
}
