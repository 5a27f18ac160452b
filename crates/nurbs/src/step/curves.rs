//! Edges and curves as exact NURBS: lines between their vertices, circles and ellipses as
//! rational arcs, B-spline curves (rational or not) whole or restricted to their trims.

use std::f64::consts::TAU;

use super::convert::{Converter, MAX_DEPTH, SAME};
use super::error::StepError;
use super::parse::{StepInstance, StepRecord, StepValue};
use crate::conics::{line_segment, rational_arc};
use crate::iges::curve_primitives::snap_full_turn;
use crate::iges::restrict::restrict_curve;
use crate::vec3::{add, distance, dot, norm, scale, sub};
use crate::NurbsCurve;

impl<'a> Converter<'a> {
    /// Follows `SURFACE_CURVE`, `SEAM_CURVE`, `INTERSECTION_CURVE` (their 3D curve) and `TRIMMED_CURVE` (its
    /// basis) to the curve that carries an edge.
    pub(super) fn basis_curve(
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
            "SURFACE_CURVE" | "SEAM_CURVE" | "INTERSECTION_CURVE" | "TRIMMED_CURVE" => {
                let p = self.params(i, 2)?;
                self.basis_curve(&p[1], i, depth + 1)
            }
            _ => Ok(i),
        }
    }

    /// A vertex's point.
    pub(super) fn vertex(
        &self,
        v: &StepValue,
        parent: &StepInstance,
    ) -> Result<[f64; 3], StepError> {
        let i = self.get(v, parent)?;
        self.expect_type(i, "VERTEX_POINT")?;
        self.point(&self.params(i, 2)?[1], i)
    }

    /// `EDGE_CURVE(name, start, end, curve, same_sense)` as a NURBS curve from its start
    /// vertex to its end vertex (B-spline curves whole).
    pub(super) fn edge_curve(
        &self,
        edge: &StepInstance,
        depth: usize,
    ) -> Result<NurbsCurve, StepError> {
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
    pub(super) fn bounded_curve(
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
    pub(super) fn trimmed_curve(&self, i: &StepInstance) -> Result<NurbsCurve, StepError> {
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

    /// The curve a surface of revolution or of linear extrusion sweeps: a B-spline curve, a
    /// trimmed curve, or a whole circle or ellipse (OpenCASCADE writes the side of an
    /// extruded disk as an ellipse of equal semi-axes swept along its axis), starting
    /// where its placement's x axis points.
    pub(super) fn swept_curve(&self, i: &StepInstance) -> Result<NurbsCurve, StepError> {
        match i.type_name().as_str() {
            "CIRCLE" | "ELLIPSE" => {
                let q = self.params(i, 3)?;
                let f = self.placement(&q[1], i)?;
                let r1 = self.length(&q[2], i, "radius")?;
                let start = add(f.origin, scale(f.x, r1));
                self.bounded_curve(i, start, start, true, true)
            }
            "TRIMMED_CURVE" => self.trimmed_curve(i),
            _ => self.free_curve(i),
        }
    }

    /// A bounded curve on its own (B-spline curves), for edges and swept surfaces.
    pub(super) fn free_curve(&self, i: &StepInstance) -> Result<NurbsCurve, StepError> {
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
    pub(super) fn knots(
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
    pub(super) fn reals(
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
}

/// An integer parameter as a count.
pub(super) fn integer(v: &StepValue) -> Option<usize> {
    match *v {
        StepValue::Integer(i) if i >= 0 => usize::try_from(i).ok(),
        _ => None,
    }
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
