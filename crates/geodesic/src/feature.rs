//! Edges on a surface-patch boundary in 3D: a mesh edge whose facets lie on two (or more)
//! surfaces runs along their intersection curve (a feature curve: the rim where a cylinder
//! meets a plane, the seam between two CAD faces).
//!
//! The paper's Sect. 4.1 treats these edges like the 2D boundary: "the surface
//! parameterisation is, when restricted to a patch boundary, just a parametric curve in three
//! dimensions", and the nodes are placed at the arc-length fractions of the reference 1D
//! distribution (Eq. (4)). The curve is
//! - the model's own curve entity through the edge, when it has one (IGES boundary curves):
//!   exact arc length on that NURBS curve (Eq. (4) as in 2D);
//! - otherwise the intersection curve traced between the two vertices: a polyline refined by
//!   bisection — every chord midpoint moved onto the intersection (its foot point there) —
//!   until its length, with segments measured as circular arcs (fourth-order accurate, exact
//!   on circles), changes by less than a relative tolerance; the nodes are then placed at the
//!   length fractions along it.
//!
//! Either way every point is finally moved onto the intersection of all the surfaces (its
//! foot point there, by Newton's method on the two tangent planes and the curve's normal
//! plane), so it lies on each of them to round-off.

use hocurve_nurbs::inversion::closest_point_on_curve;
#[cfg(test)]
use hocurve_nurbs::inversion::closest_point_on_surface;
use hocurve_nurbs::vec3::{add, cross, distance, dot, scale};
use hocurve_nurbs::{EntityGeometry, GeometricEntity, GeometryModel};

use crate::association::snap_onto;
use crate::chart::SurfaceChart;
use crate::curve_arc::CurveArc;
use crate::frame::{end_tangent, SurfaceFrame};
use crate::path::{chord_point_at_fraction, cumulative_lengths};

/// At least this many segments in a traced intersection curve.
const MIN_SEGMENTS: usize = 8;
/// At most this many segments in a traced intersection curve.
const MAX_SEGMENTS: usize = 1024;
/// A model curve carries a feature edge if both vertices and the traced curve's midpoint lie
/// within this distance (relative to the model size) of it.
const CURVE_MATCH_TOLERANCE: f64 = 1e-9;

/// The curve carrying a feature edge, from its first vertex to its second.
pub(crate) struct FeatureCurve<'a> {
    geometry: &'a GeometryModel,
    surfaces: Vec<usize>,
    /// The charts of the surfaces.
    charts: Vec<SurfaceChart<'a>>,
    /// The traced intersection: points on all surfaces, first and last at the vertices.
    pub(crate) points: Vec<[f64; 3]>,
    /// The points' parameters on each surface (unrolled along the curve).
    params: Vec<Vec<[f64; 2]>>,
    /// Cumulative lengths along `points`.
    lengths: Vec<f64>,
    /// The model's curve entity through the edge, if any, and its index.
    explicit: Option<(usize, CurveArc<'a>)>,
}

impl<'a> FeatureCurve<'a> {
    /// The intersection curve of `surfaces` from `from` to `to` (both on all of them), traced
    /// until its length changes by less than `tolerance` (relative); the model's curve entity
    /// through the edge is used for the placement when there is one.
    pub(crate) fn between(
        geometry: &'a GeometryModel,
        surfaces: &[usize],
        from: [f64; 3],
        to: [f64; 3],
        tolerance: f64,
    ) -> Self {
        let charts = charts_of(geometry, surfaces);
        let (points, params) = trace_intersection(geometry, &charts, surfaces, from, to, tolerance);
        let lengths = cumulative_lengths(&points);
        let explicit = explicit_curve(geometry, &points);
        Self {
            geometry,
            surfaces: surfaces.to_vec(),
            charts,
            points,
            params,
            lengths,
            explicit,
        }
    }

    /// Length of the edge along the curve.
    #[cfg(test)]
    pub(crate) fn length(&self) -> f64 {
        match &self.explicit {
            Some((_, arc)) => arc.length,
            None => self.lengths.last().copied().unwrap_or(0.0),
        }
    }

    /// Index of the model's curve entity used, if any.
    pub(crate) fn curve_entity(&self) -> Option<usize> {
        self.explicit.as_ref().map(|(e, _)| *e)
    }

    /// The point at `fraction` of the length from the first vertex, on all surfaces.
    pub(crate) fn at(&self, fraction: f64) -> [f64; 3] {
        let n = self.points.len();
        let fraction = fraction.clamp(0.0, 1.0);
        if fraction == 0.0 {
            return self.points[0];
        }
        if fraction == 1.0 {
            return self.points[n - 1];
        }
        let (k, t, on_chord) = chord_point_at_fraction(&self.points, &self.lengths, fraction);
        let x = match &self.explicit {
            Some((_, arc)) => arc.at(fraction),
            None => on_chord,
        };
        let guess: Vec<[f64; 2]> = self.params[k]
            .iter()
            .zip(&self.params[k + 1])
            .map(|(a, b)| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])])
            .collect();
        foot_near(self.geometry, &self.charts, &self.surfaces, x, &guess).0
    }

    /// Unit tangent at the first vertex (`at_end = false`) or the last (`true`), pointing
    /// into the edge.
    pub(crate) fn end_tangent(&self, at_end: bool) -> Option<[f64; 3]> {
        end_tangent(&self.points, at_end)
    }
}

/// The charts of the surface entities among `surfaces`.
fn charts_of<'a>(geometry: &'a GeometryModel, surfaces: &[usize]) -> Vec<SurfaceChart<'a>> {
    surfaces
        .iter()
        .filter_map(|&e| match &geometry.entities.get(e)?.geometry {
            EntityGeometry::Surface(s) => Some(SurfaceChart::new(s)),
            EntityGeometry::Curve(_) => None,
        })
        .collect()
}

/// The intersection of `surfaces` between `from` and `to` as a polyline refined by bisection
/// (chord midpoints moved to their foot points on the intersection) until its length changes
/// by less than `tolerance` (relative), with at least `MIN_SEGMENTS` and at most
/// `MAX_SEGMENTS` segments; with the points' parameters on each surface.
fn trace_intersection(
    geometry: &GeometryModel,
    charts: &[SurfaceChart],
    surfaces: &[usize],
    from: [f64; 3],
    to: [f64; 3],
    tolerance: f64,
) -> (Vec<[f64; 3]>, Vec<Vec<[f64; 2]>>) {
    // The entities of `charts`, whose inversion start grids are kept across calls.
    let entities: Vec<&GeometricEntity> = surfaces
        .iter()
        .filter_map(|&e| geometry.entities.get(e))
        .filter(|e| !e.is_curve())
        .collect();
    let invert = |x: [f64; 3]| -> Vec<[f64; 2]> {
        entities.iter().map(|e| e.closest_point(x).param).collect()
    };
    let start = invert(from);
    let end: Vec<[f64; 2]> = invert(to)
        .iter()
        .zip(charts.iter().zip(&start))
        .map(|(b, (c, a))| c.unroll_near(*b, *a))
        .collect();
    let mut points = vec![from, to];
    let mut params = vec![start, end];
    if distance(from, to) == 0.0 {
        return (points, params);
    }
    let mut length = f64::INFINITY;
    loop {
        let mut fine = Vec::with_capacity(2 * points.len());
        let mut fine_params = Vec::with_capacity(2 * points.len());
        for i in 0..points.len() - 1 {
            fine.push(points[i]);
            fine_params.push(params[i].clone());
            let mid = scale(add(points[i], points[i + 1]), 0.5);
            let guess: Vec<[f64; 2]> = params[i]
                .iter()
                .zip(&params[i + 1])
                .map(|(a, b)| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])])
                .collect();
            let (x, uv) = foot_near(geometry, charts, surfaces, mid, &guess);
            fine.push(x);
            fine_params.push(uv);
        }
        fine.extend(points.last());
        fine_params.extend(params.last().cloned());
        points = fine;
        params = fine_params;
        let new_length = cumulative_lengths(&points).last().copied().unwrap_or(0.0);
        let change = (new_length - length).abs();
        length = new_length;
        let segments = points.len() - 1;
        if segments >= MAX_SEGMENTS || (segments >= MIN_SEGMENTS && change <= tolerance * length) {
            return (points, params);
        }
    }
}

/// The point of the intersection of `surfaces` whose normal plane (the plane through it
/// orthogonal to the curve's tangent) contains `x`: the foot point of `x` on the curve (see
/// `foot_near`), from parameters found by point inversion.
#[cfg(test)]
pub(crate) fn foot_on_intersection(
    geometry: &GeometryModel,
    surfaces: &[usize],
    x: [f64; 3],
) -> [f64; 3] {
    let charts = charts_of(geometry, surfaces);
    let guess: Vec<[f64; 2]> = charts
        .iter()
        .map(|c| closest_point_on_surface(c.surface, x).param)
        .collect();
    foot_near(geometry, &charts, surfaces, x, &guess).0
}

/// The foot point of `x` on the intersection of the first two surfaces, by Newton's method
/// from the parameters `guess` (one per chart): the point y is replaced by the solution of
/// n₁·y′ = n₁·q₁, n₂·y′ = n₂·q₂ (the tangent planes at the projections qᵢ of y onto the
/// surfaces) and t·y′ = t·x (the normal plane through x, t = n₁ × n₂), until it settles to
/// round-off; converges quadratically. Further surfaces, and nearly tangent ones, are handled
/// by alternating projections. Returns the point and its parameters on each chart.
fn foot_near(
    geometry: &GeometryModel,
    charts: &[SurfaceChart],
    surfaces: &[usize],
    x: [f64; 3],
    guess: &[[f64; 2]],
) -> ([f64; 3], Vec<[f64; 2]>) {
    let size = geometry.size().max(f64::MIN_POSITIVE);
    let mut params = guess.to_vec();
    let mut y = x;
    let mut converged = false;
    if charts.len() >= 2 {
        for _ in 0..50 {
            let mut planes = Vec::with_capacity(2);
            for (chart, uv) in charts.iter().zip(params.iter_mut()).take(2) {
                let (new_uv, q) = chart.project_near(y, *uv);
                *uv = chart.unroll_near(new_uv, *uv);
                let Some(frame) = SurfaceFrame::at(chart, *uv) else {
                    break;
                };
                planes.push((frame.normal, q));
            }
            let [(n1, q1), (n2, q2)] = planes[..] else {
                break;
            };
            let t = cross(n1, n2);
            let det = dot(t, t);
            if det < 1e-12 {
                break;
            }
            let (b1, b2, b3) = (dot(n1, q1), dot(n2, q2), dot(t, x));
            let next = scale(
                add(
                    add(scale(cross(n2, t), b1), scale(cross(t, n1), b2)),
                    scale(t, b3),
                ),
                1.0 / det,
            );
            let step = distance(next, y);
            y = next;
            if step <= 1e-15 * size {
                converged = true;
                break;
            }
        }
    }
    if !converged || surfaces.len() > 2 {
        y = snap_onto(geometry, surfaces, if converged { y } else { x });
    }
    (y, params)
}

/// The model's curve entity (with the arc on it from the first point to the last) through the
/// traced polyline's ends and middle, if there is one.
fn explicit_curve<'a>(
    geometry: &'a GeometryModel,
    points: &[[f64; 3]],
) -> Option<(usize, CurveArc<'a>)> {
    let (first, last) = (*points.first()?, *points.last()?);
    let middle = points[points.len() / 2];
    let tolerance = CURVE_MATCH_TOLERANCE * geometry.size().max(f64::MIN_POSITIVE);
    geometry
        .entities
        .iter()
        .enumerate()
        .find_map(|(index, entity)| {
            let EntityGeometry::Curve(curve) = &entity.geometry else {
                return None;
            };
            let near = [first, middle, last]
                .iter()
                .all(|&x| entity.distance(x) <= tolerance);
            if !near {
                return None;
            }
            let (a, b) = (
                closest_point_on_curve(curve, first).param,
                closest_point_on_curve(curve, last).param,
            );
            let arc = CurveArc::new(curve, a, b);
            // A closed curve is taken the short way round: check that this is the traced way.
            let on_arc = distance(arc.at(0.5), middle) <= tolerance + 0.25 * distance(first, last);
            on_arc.then_some((index, arc))
        })
}

#[cfg(test)]
#[path = "tests/feature.rs"]
mod tests;
