//! Edges on a surface-patch boundary in 3D: a mesh edge whose facets lie on two (or more)
//! surfaces runs along their intersection curve (a feature curve: the rim where a cylinder
//! meets a plane, the seam between two CAD faces).
//!
//! The paper's Sect. 4.1 treats these edges like the 2D boundary: "the surface
//! parameterisation is, when restricted to a patch boundary, just a parametric curve in three
//! dimensions", and the nodes are placed at the arc-length fractions of the reference 1D
//! distribution (Eq. (4)). The curve is
//! - the CAD edge between the two surfaces through both vertices, when the model has its
//!   topology (STEP B-reps: [`hocurve_nurbs::ModelEdge`]), or the model's own curve entity
//!   through the edge (IGES boundary curves): exact arc length on that NURBS curve (Eq. (4)
//!   as in 2D), untraced — where two faces meet nearly tangentially their intersection is
//!   ill-conditioned, and the modeller's curve is the edge;
//! - otherwise the intersection curve traced between the two vertices: a polyline refined by
//!   bisection — every chord midpoint moved onto the intersection (its foot point there) —
//!   until its length, with segments measured as circular arcs (fourth-order accurate, exact
//!   on circles), changes by less than a relative tolerance; the nodes are then placed at the
//!   length fractions along it.
//!
//! Either way every point is finally moved onto the intersection of all the surfaces (its
//! foot point there, by Newton's method on the two tangent planes and the curve's normal
//! plane), so it lies on each of them to round-off — except that a point of the modeller's
//! curve stays where it is when that foot is farther from it than the file's uncertainty
//! and the point itself is within the uncertainty of every surface.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use hocurve_nurbs::inversion::closest_point_on_curve;
#[cfg(test)]
use hocurve_nurbs::inversion::closest_point_on_surface;
use hocurve_nurbs::vec3::{add, cross, distance, dot, norm, scale, sub, unit};
use hocurve_nurbs::{EntityGeometry, GeometricEntity, GeometryModel, NurbsCurve};

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
/// At most this many Newton steps onto the intersection of two surfaces: from a point near
/// it they settle in 2–4 where the surfaces cross at an angle; where they are nearly
/// tangent the steps wander (Ventilator.stp's fillets: 50 steps of ~1e-5 of the model size)
/// and the seam solvers that follow do better.
const INTERSECTION_STEPS: usize = 12;
/// At most this many parabola steps across the seam of two tangent surfaces.
const SEAM_ITERATIONS: usize = 40;
/// At most this many alternating projections onto two surfaces from their last parameters.
const ALTERNATIONS: usize = 100;
/// The first, brief alternation: steps, and the gap (relative to the model size) it must
/// close to be taken.
const QUICK_ALTERNATION: (usize, f64) = (8, 1e-13);
/// Alternating projections that settle with the two feet farther apart than this (relative
/// to the model size) are taken to have stalled off the seam.
const SEAM_GAP: f64 = 1e-6;
/// Two surfaces whose gap is within this (relative to the model size) touch: the strict
/// "on the geometry" of the written mesh, where the file states no uncertainty.
const ON_SURFACE: f64 = 1e-10;

/// The curve carrying a feature edge, from its first vertex to its second.
#[derive(Debug, Clone)]
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
    /// The modeller's curve through the edge (a curve entity, or the CAD edge between the
    /// surfaces), if any.
    explicit: Option<CurveArc<'a>>,
    /// The model's size (the scale of round-off in lengths).
    size: f64,
}

/// Feature curves already traced on one model, for reuse: the curving pipeline places
/// boundary nodes several times on one model (with and without the minimum-angle
/// corrections, and again in each round of repair, on a mesh whose edges are mostly the
/// same), and a trace is a pure function of its surfaces, end points and tolerance, so a
/// reused one is the curve that tracing again would give, bit for bit. A curve of another
/// model is never returned (the model is compared by address).
/// Beyond [`KEPT_TRACE_POINTS`] traced points no more curves are kept: memory is not
/// traded for time without bound.
#[derive(Debug, Default)]
pub struct FeatureTraces<'a> {
    kept: Mutex<KeptTraces<'a>>,
}

/// The curves kept, and their points in all.
#[derive(Debug, Default)]
struct KeptTraces<'a> {
    curves: HashMap<TraceKey, Arc<FeatureCurve<'a>>>,
    points: usize,
}

/// At most this many traced points are kept by [`FeatureTraces`]: ~100 bytes each on two
/// surfaces (the point, its length, its parameter on each surface in a vector of its own),
/// ~400 MB in all. A STEP assembly of 85 k tets (as1_pe_203) keeps 1.3 M at p = 2.
pub const KEPT_TRACE_POINTS: usize = 1 << 22;

/// Surfaces, the two end points' and the tolerance's bits.
type TraceKey = (Vec<usize>, [u64; 3], [u64; 3], u64);

impl<'a> FeatureTraces<'a> {
    /// [`FeatureCurve::between`], from the traces when it was asked before.
    pub(crate) fn between(
        &self,
        geometry: &'a GeometryModel,
        surfaces: &[usize],
        from: [f64; 3],
        to: [f64; 3],
        tolerance: f64,
    ) -> FeatureCurve<'a> {
        let key = (
            surfaces.to_vec(),
            from.map(f64::to_bits),
            to.map(f64::to_bits),
            tolerance.to_bits(),
        );
        // (A poisoned lock only means another thread panicked: nothing in the lock can
        // leave the map half changed.)
        let known = self
            .kept
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .curves
            .get(&key)
            .filter(|c| std::ptr::eq(c.geometry, geometry))
            .cloned();
        // Copied out of the lock: the other threads' lookups do not wait for it.
        if let Some(curve) = known {
            return FeatureCurve::clone(&curve);
        }
        let curve = FeatureCurve::between(geometry, surfaces, from, to, tolerance);
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        let same_model = kept
            .curves
            .values()
            .next()
            .is_none_or(|c| std::ptr::eq(c.geometry, geometry));
        if same_model && kept.points + curve.points.len() <= KEPT_TRACE_POINTS {
            kept.points += curve.points.len();
            kept.curves.insert(key, Arc::new(curve.clone()));
        }
        curve
    }

    /// How many traces are kept.
    pub fn len(&self) -> usize {
        self.kept
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .curves
            .len()
    }

    /// No trace kept yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
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
        let size = geometry.size().max(f64::MIN_POSITIVE);
        // The CAD edge between the surfaces needs no trace: its samples only guide the
        // projections of the nodes onto the surfaces.
        let (points, params, explicit) = match model_edge_arc(geometry, surfaces, from, to) {
            Some(arc) => {
                let (points, params) = arc_samples(geometry, &charts, surfaces, &arc, from, to);
                (points, params, Some(arc))
            }
            None => {
                let (points, params) =
                    trace_intersection(geometry, &charts, surfaces, from, to, tolerance, size);
                let explicit = explicit_curve(geometry, &points);
                (points, params, explicit)
            }
        };
        let lengths = cumulative_lengths(&points);
        Self {
            geometry,
            surfaces: surfaces.to_vec(),
            charts,
            points,
            params,
            lengths,
            explicit,
            size,
        }
    }

    /// Length of the edge along the curve.
    #[cfg(test)]
    pub(crate) fn length(&self) -> f64 {
        match &self.explicit {
            Some(arc) => arc.length,
            None => self.lengths.last().copied().unwrap_or(0.0),
        }
    }

    /// Whether the nodes are placed on the modeller's curve (not on a traced intersection).
    pub(crate) fn on_model_curve(&self) -> bool {
        self.explicit.is_some()
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
            Some(arc) => arc.at(fraction),
            None => on_chord,
        };
        let guess: Vec<[f64; 2]> = self.params[k]
            .iter()
            .zip(&self.params[k + 1])
            .map(|(a, b)| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])])
            .collect();
        let seam = sub(self.points[k + 1], self.points[k]);
        let y = foot_near(
            self.geometry,
            &self.charts,
            &self.surfaces,
            x,
            &guess,
            Some(seam),
            self.size,
        )
        .0;
        if self.explicit.is_none() {
            return y;
        }
        // On the modeller's curve, the foot is taken where it is the same point to the
        // file's uncertainty; where it is not (faces nearly tangent, whose intersection runs
        // anywhere within their gap), the curve's point is, when it is on every surface to
        // that uncertainty: the modeller's edge, as Gmsh places its nodes.
        let band = self
            .geometry
            .uncertainty
            .unwrap_or(0.0)
            .max(ON_SURFACE * self.size);
        if distance(x, y) <= band {
            return y;
        }
        let on_all = self
            .surfaces
            .iter()
            .all(|&e| self.geometry.entities[e].distance(x) <= band);
        if on_all {
            x
        } else {
            y
        }
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
    size: f64,
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
    let mut last_change = f64::INFINITY;
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
            let seam = sub(points[i + 1], points[i]);
            let (x, uv) = foot_near(geometry, charts, surfaces, mid, &guess, Some(seam), size);
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
        // The length converges at fourth order (the change drops 16-fold per halving of the
        // segments; 4-fold across a curvature jump); when it drops less, the points' own
        // error dominates (faces crossing at a grazing angle whose vertices lie between the
        // two intersections, tangent faces meeting only to the modeller's tolerance) and
        // more segments add nothing.
        let at_noise = segments > MIN_SEGMENTS && change > 0.3 * last_change;
        last_change = change;
        if segments >= MAX_SEGMENTS
            || at_noise
            || (segments >= MIN_SEGMENTS && change <= tolerance * length)
        {
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
    let size = geometry.size().max(f64::MIN_POSITIVE);
    foot_near(geometry, &charts, surfaces, x, &guess, None, size).0
}

/// The foot point of `x` on the intersection of the first two surfaces, by Newton's method
/// from the parameters `guess` (one per chart): the point y is replaced by the solution of
/// n₁·y′ = n₁·q₁, n₂·y′ = n₂·q₂ (the tangent planes at the projections qᵢ of y onto the
/// surfaces) and t·y′ = t·x (the normal plane through x, t = n₁ × n₂), until it settles to
/// round-off; converges quadratically. Two nearly tangent surfaces (where n₁ × n₂ vanishes)
/// are handled by [`foot_on_tangent_seam`] across the seam direction `seam`, further
/// surfaces by alternating projections. Returns the point and its parameters on each chart.
fn foot_near(
    geometry: &GeometryModel,
    charts: &[SurfaceChart],
    surfaces: &[usize],
    x: [f64; 3],
    guess: &[[f64; 2]],
    seam: Option<[f64; 3]>,
    size: f64,
) -> ([f64; 3], Vec<[f64; 2]>) {
    let mut params = guess.to_vec();
    let mut y = x;
    let mut converged = false;
    if charts.len() >= 2 {
        for _ in 0..INTERSECTION_STEPS {
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
            // The tangent planes are known to round-off (~1e-16 of the size), so the point
            // they fix only to that over the sine of their angle (|t|): steps below that are
            // noise (faces meeting at a grazing angle never take a 1e-15 step).
            if step <= 1e-15 * size / det.sqrt().min(1.0) {
                converged = true;
                break;
            }
        }
    }
    // Closed forms are unbounded and cheap: there `snap_onto` projects onto the whole
    // surfaces, where the charts' NURBS patches end at their faces' extent. (Two faces on
    // one infinite cylinder — coaxial holes of stacked plates — "meet" wherever an edge
    // crosses from one to the other; the patches would clamp its nodes to where they end.)
    let closed_forms = surfaces
        .iter()
        .all(|&e| geometry.entities[e].analytic.is_some());
    if !converged && !closed_forms && charts.len() == 2 && surfaces.len() == 2 {
        // First the plain alternation, briefly: where the faces coincide (two faces of one
        // cylinder, coplanar faces) or the seam is both patches' boundary (projections
        // clamp to it), it settles in a few steps; only where it creeps, across the seam.
        let saved = params.clone();
        let found = foot_by_local_alternation(charts, &mut params, x, size, QUICK_ALTERNATION)
            .or_else(|| {
                params.copy_from_slice(&saved);
                seam.and_then(|t| {
                    let band = geometry.uncertainty.unwrap_or(0.0);
                    foot_on_tangent_seam(charts, &mut params, x, t, (size, band))
                })
            })
            .or_else(|| {
                params.copy_from_slice(&saved);
                foot_by_local_alternation(charts, &mut params, x, size, (ALTERNATIONS, SEAM_GAP))
            });
        if let Some(found) = found {
            y = found;
            converged = true;
        }
    }
    if !converged || surfaces.len() > 2 {
        y = snap_onto(geometry, surfaces, if converged { y } else { x });
    }
    (y, params)
}

/// The foot point of `x` on the seam where two surfaces meet tangentially (a fillet running
/// into a face, two B-spline faces joined with G1 continuity), from their parameters `params`
/// (updated). There the tangent planes coincide and cannot fix the point, and alternating
/// projections creep (sublinearly, at exact tangency); but across the seam the offset of the
/// second surface from the first, h(s) = n₁ · (P₂(y(s)) − y(s)) with y(s) = P₁(x + s w) and
/// w = n₁ × `seam` the direction across, is a smooth function with a root (surfaces crossing
/// at a grazing angle) or a minimum (surfaces touching only to the modeller's tolerance). It
/// is found by fitting parabolas through three offsets (exact in one step on a quadratic
/// h). The point returned is the midpoint of y and its projection onto the second surface:
/// within half the gap of both. `None` when the parabolas do not settle.
///
/// Where the surfaces touch only to the file's uncertainty `band` (a fillet's B-spline
/// beside the sphere it rounds: OpenCASCADE's wiggles by 2e-6 about the sphere, crossing it
/// twice within 5e-4 of the edge), h has two roots with the whole span between them within
/// `band`: the seam is the parabola's vertex, the middle of that band — either root alone
/// would scatter the traced points across it (by up to 2e-3 there). Only where the feet
/// themselves are within `band` (beyond a patch's end its projection clamps: the feet are
/// apart along the surface while h stays flat).
///
/// Every point returned has its two feet apart by at most `band` (or a hundredth of the
/// `seam` segment) beyond their offset along the normal: h is only that offset, and where the second patch ends at the
/// seam while the first runs on past it (Ventilator.stp's blade faces, B-splines joined
/// with G1 continuity), its projection clamps to its end, h stays flat, and the parabolas
/// settle anywhere on the first surface: a point returned there is on neither surface
/// (there: 0.07 from the seam, 4 edge lengths once the trace built on it). `None` then,
/// and the caller's alternation finds the seam, the second patch's end.
fn foot_on_tangent_seam(
    charts: &[SurfaceChart],
    params: &mut [[f64; 2]],
    x: [f64; 3],
    seam: [f64; 3],
    (size, band): (f64, f64),
) -> Option<[f64; 3]> {
    let [first, second] = charts else {
        return None;
    };
    let (uv1, _) = first.project_near(x, params[0]);
    let normal = SurfaceFrame::at(first, uv1)?.normal;
    let across = unit(cross(normal, seam))?;
    // The feet on both surfaces of the point `s` across the seam from `x`, and the offset.
    let feet = |s: f64, params: &mut [[f64; 2]]| -> Option<(f64, [f64; 3], [f64; 3])> {
        let (uv, y) = first.project_near(add(x, scale(across, s)), params[0]);
        params[0] = first.unroll_near(uv, params[0]);
        let (uv, q) = second.project_near(y, params[1]);
        params[1] = second.unroll_near(uv, params[1]);
        // (At a degenerate point of the chart, the normal where the search started.)
        let n = SurfaceFrame::at(first, params[0]).map_or(normal, |f| f.normal);
        Some((dot(n, sub(q, y)), y, q))
    };
    // Offsets below this are round-off.
    let noise = 1e-14 * size;
    // The midpoint of two feet, unless they are apart along the surfaces (beyond their
    // offset along the normal) by more than the band and a hundredth of the seam segment:
    // a clamped projection (on Ventilator.stp, half the segment; OpenCASCADE's fillet of a
    // sphere, whose patch ends at the seam too, leaves its feet apart by 1e-4 of a length
    // of 0.02-0.06 where its parabola vertex is right).
    let close = band.max(ON_SURFACE * size).max(0.01 * norm(seam));
    let settled = |y: [f64; 3], q: [f64; 3]| {
        let (d, h) = (distance(y, q), dot(normal, sub(q, y)));
        let along = (d * d - h * h).max(0.0).sqrt();
        (along <= close).then(|| scale(add(y, q), 0.5))
    };
    let mut centre = 0.0;
    let mut step = 1e-4 * size;
    for _ in 0..SEAM_ITERATIONS {
        let saved = params.to_vec();
        let (h0, y, q) = feet(centre, params)?;
        let centre_params = params.to_vec();
        let (hm, ..) = feet(centre - step, params)?;
        params.copy_from_slice(&saved);
        let (hp, ..) = feet(centre + step, params)?;
        params.copy_from_slice(&centre_params);
        if h0.abs() <= noise && (hp - h0).abs().max((hm - h0).abs()) <= 100.0 * noise {
            // h is round-off across the stencil: the faces coincide here (two faces of one
            // cylinder, coplanar faces of stacked parts), and a parabola through noise
            // would jump anywhere along them.
            return settled(y, q);
        }
        // h ≈ h0 + b σ + c σ² about the centre.
        let b = (hp - hm) / (2.0 * step);
        let c = (hp - 2.0 * h0 + hm) / (2.0 * step * step);
        let discriminant = b * b - 4.0 * c * h0;
        let mut at_vertex = false;
        let delta = if c.abs() * step <= 1e-3 * b.abs() {
            -h0 / b
        } else if discriminant >= 0.0
            && !(distance(y, q) <= band && (h0 - b * b / (4.0 * c)).abs() <= band)
        {
            // The root nearer the centre.
            let r = discriminant.sqrt();
            let (r1, r2) = ((-b + r) / (2.0 * c), (-b - r) / (2.0 * c));
            if r1.abs() <= r2.abs() {
                r1
            } else {
                r2
            }
        } else {
            at_vertex = true;
            -b / (2.0 * c)
        };
        // The offset at the vertex: the surfaces' gap there.
        let gap = (h0 - b * b / (4.0 * c)).abs();
        if at_vertex
            && delta.abs() <= (noise / c.abs()).sqrt().min(step)
            && gap <= band.max(ON_SURFACE * size)
        {
            // At a minimum of h (surfaces touching, not crossing) its vertex is fixed only
            // to √(round-off / c) across the seam: a step within that, inside the stencil,
            // is the seam (closer steps fit parabolas through noise and wander). Off each
            // surface by about their gap there — taken only where that is within the file's
            // uncertainty, or on them to the strict tolerance (faces farther apart do not
            // meet: the callers' fallbacks decide).
            let (_, y_next, q_next) = feet(centre + delta, params)?;
            return settled(y_next, q_next);
        }
        if !delta.is_finite() {
            // h constant: the faces coincide here (one surface split in two faces), or
            // never meet.
            return if h0.abs() <= noise {
                settled(y, q)
            } else {
                None
            };
        }
        let delta = delta.clamp(-100.0 * step, 100.0 * step);
        if delta.abs() <= noise {
            return settled(y, q);
        }
        if h0.abs() <= noise {
            // On both surfaces to round-off. Where they touch, h is flat to round-off over a
            // band ~√(round-off) wide: the parabola's vertex is the seam if its offset is
            // round-off too, else the fit is noise and the centre is kept.
            let (h, y_next, q_next) = feet(centre + delta, params)?;
            if h.abs() <= noise {
                return settled(y_next, q_next);
            }
            params.copy_from_slice(&centre_params);
            return settled(y, q);
        }
        centre += delta;
        step = (0.5 * delta.abs()).clamp(1e-9 * size, 1e-4 * size);
    }
    None
}

/// The foot point of `x` on the seam of the two surface entities `surfaces` where they meet
/// tangentially, with no seam direction known (a single node, not an edge): the direction
/// across the seam is where the offset h of the second surface from the first (see
/// [`foot_on_tangent_seam`]) changes: its gradient in the tangent plane where the surfaces
/// cross, else (touching, h has a minimum along the seam) the principal direction of its
/// Hessian, both from h on a 3 × 3 stencil; from the parameters `guess` of nearby feet.
/// `None` where there is no such seam.
pub(crate) fn foot_on_seam_of(
    geometry: &GeometryModel,
    surfaces: &[usize],
    x: [f64; 3],
    guess: &[[f64; 2]],
) -> Option<[f64; 3]> {
    let charts = charts_of(geometry, surfaces);
    let ([first, second], 2) = (&charts[..], surfaces.len()) else {
        return None;
    };
    let size = geometry.size().max(f64::MIN_POSITIVE);
    let mut params = guess.to_vec();
    let (uv, y) = first.project_near(x, params[0]);
    params[0] = uv;
    let frame = SurfaceFrame::at(first, uv)?;
    let e1 = unit(frame.derivatives.du)?;
    let e2 = unit(cross(frame.normal, e1))?;
    let offset = |a: f64, b: f64| -> f64 {
        let z = add(y, add(scale(e1, a), scale(e2, b)));
        let (_, p) = first.project_near(z, params[0]);
        let (_, q) = second.project_near(p, params[1]);
        dot(frame.normal, sub(q, p))
    };
    let step = 1e-4 * size;
    let h: Vec<Vec<f64>> = (-1..=1)
        .map(|i| {
            (-1..=1)
                .map(|j| offset(i as f64 * step, j as f64 * step))
                .collect()
        })
        .collect();
    let gradient = [
        (h[2][1] - h[0][1]) / (2.0 * step),
        (h[1][2] - h[1][0]) / (2.0 * step),
    ];
    let (haa, hbb) = (
        (h[2][1] - 2.0 * h[1][1] + h[0][1]) / (step * step),
        (h[1][2] - 2.0 * h[1][1] + h[1][0]) / (step * step),
    );
    let hab = (h[2][2] - h[2][0] - h[0][2] + h[0][0]) / (4.0 * step * step);
    let across = if gradient[0].hypot(gradient[1]) > step * haa.abs().max(hbb.abs()) {
        gradient
    } else {
        // The eigenvector of [[haa, hab], [hab, hbb]] of the larger |eigenvalue|.
        let angle = 0.5 * (2.0 * hab).atan2(haa - hbb);
        let (sin, cos) = angle.sin_cos();
        let along = haa * cos * cos + 2.0 * hab * sin * cos + hbb * sin * sin;
        let other = haa * sin * sin - 2.0 * hab * sin * cos + hbb * cos * cos;
        if along.abs() >= other.abs() {
            [cos, sin]
        } else {
            [-sin, cos]
        }
    };
    let across = add(scale(e1, across[0]), scale(e2, across[1]));
    // (A direction, its length the stencil's step: the scale of "apart along the faces".)
    let seam = scale(unit(cross(frame.normal, across))?, step);
    let band = geometry.uncertainty.unwrap_or(0.0);
    foot_on_tangent_seam(&charts, &mut params, x, seam, (size, band))
}

/// The point on two surfaces nearest `x` by alternating projections, each from the
/// parameters of the last (`params`, updated): where the seam is the common boundary of two
/// patches (B-spline faces joined edge to edge) the projections clamp to it and settle
/// fast, while h of [`foot_on_tangent_seam`] has a kink there. Returns the midpoint of the
/// last two feet once they settle, within `SEAM_GAP` of the model size: real faces meet
/// only to the modeller's tolerance (a CATIA file states 0.005 mm), and the written mesh is
/// then checked against the geometry. `None` if they do not (a global inversion per step, as
/// in `snap_onto`, costs a grid search on each surface).
fn foot_by_local_alternation(
    charts: &[SurfaceChart],
    params: &mut [[f64; 2]],
    x: [f64; 3],
    size: f64,
    (iterations, accepted_gap): (usize, f64),
) -> Option<[f64; 3]> {
    let [first, second] = charts else {
        return None;
    };
    let mut z = x;
    let mut gap = f64::INFINITY;
    for _ in 0..iterations {
        let (uv, a) = first.project_near(z, params[0]);
        params[0] = first.unroll_near(uv, params[0]);
        let (uv, b) = second.project_near(a, params[1]);
        params[1] = second.unroll_near(uv, params[1]);
        let new_gap = distance(a, b);
        let settled = new_gap <= 1e-14 * size || new_gap >= 0.99 * gap;
        gap = new_gap;
        z = b;
        if settled {
            return (gap <= accepted_gap * size).then(|| scale(add(a, b), 0.5));
        }
    }
    (gap <= accepted_gap * size).then(|| scale(add(z, first.project_near(z, params[0]).1), 0.5))
}

/// The arc from the first point to the last on the model's curve entity through the traced
/// polyline's ends and middle, if there is one.
fn explicit_curve<'a>(geometry: &'a GeometryModel, points: &[[f64; 3]]) -> Option<CurveArc<'a>> {
    let (first, last) = (*points.first()?, *points.last()?);
    let middle = points[points.len() / 2];
    let tolerance = CURVE_MATCH_TOLERANCE * geometry.size().max(f64::MIN_POSITIVE);
    geometry.entities.iter().find_map(|entity| {
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
        on_arc.then_some(arc)
    })
}

/// The point at `fraction` of the arc length from `from` to `to` along the CAD edge between
/// `surfaces` through both (see [`model_edge_arc`]), if the model has one: where a mesh
/// edge on that CAD edge is split, so that the new vertex lies on the edge as the placed
/// nodes do (faces that meet tangentially have no intersection a projection could find
/// to better than ~1e-4 of their size).
pub fn point_on_model_edge(
    geometry: &GeometryModel,
    surfaces: &[usize],
    from: [f64; 3],
    to: [f64; 3],
    fraction: f64,
) -> Option<[f64; 3]> {
    model_edge_arc(geometry, surfaces, from, to).map(|arc| arc.at(fraction))
}

/// The arc from `from` to `to` on the CAD edge between `surfaces` (the model's
/// [`hocurve_nurbs::ModelEdge`]s) through both points, to the file's uncertainty (or
/// [`CURVE_MATCH_TOLERANCE`] of the model where that is larger), the nearest such edge when
/// several bound the same surfaces.
fn model_edge_arc<'a>(
    geometry: &'a GeometryModel,
    surfaces: &[usize],
    from: [f64; 3],
    to: [f64; 3],
) -> Option<CurveArc<'a>> {
    if geometry.edges.is_empty() || surfaces.len() < 2 {
        return None;
    }
    let mut faces = surfaces.to_vec();
    faces.sort_unstable();
    let reach = (CURVE_MATCH_TOLERANCE * geometry.size().max(f64::MIN_POSITIVE))
        .max(geometry.uncertainty.unwrap_or(0.0));
    let mut best: Option<(f64, f64, f64, &NurbsCurve)> = None;
    for edge in geometry.edges_between(&faces) {
        let (a, b) = (
            closest_point_on_curve(&edge.curve, from),
            closest_point_on_curve(&edge.curve, to),
        );
        let off = distance(a.point, from).max(distance(b.point, to));
        if off <= reach && best.is_none_or(|(d, ..)| off < d) {
            best = Some((off, a.param, b.param, &edge.curve));
        }
    }
    let (_, a, b, curve) = best?;
    Some(CurveArc::new(curve, a, b))
}

/// Points along `arc` at equal fractions of its length, its ends replaced by `from` and
/// `to`, with their parameters on each of `surfaces` (unrolled along the arc): the guides of
/// the projections of the nodes placed on it.
fn arc_samples(
    geometry: &GeometryModel,
    charts: &[SurfaceChart],
    surfaces: &[usize],
    arc: &CurveArc,
    from: [f64; 3],
    to: [f64; 3],
) -> (Vec<[f64; 3]>, Vec<Vec<[f64; 2]>>) {
    let entities: Vec<&GeometricEntity> = surfaces
        .iter()
        .filter_map(|&e| geometry.entities.get(e))
        .filter(|e| !e.is_curve())
        .collect();
    let points: Vec<[f64; 3]> = (0..=MIN_SEGMENTS)
        .map(|k| match k {
            0 => from,
            k if k == MIN_SEGMENTS => to,
            k => arc.at(k as f64 / MIN_SEGMENTS as f64),
        })
        .collect();
    let mut params: Vec<Vec<[f64; 2]>> = Vec::with_capacity(points.len());
    for x in &points {
        let mut uv: Vec<[f64; 2]> = entities.iter().map(|e| e.closest_point(*x).param).collect();
        if let Some(last) = params.last() {
            for ((p, c), q) in uv.iter_mut().zip(charts).zip(last) {
                *p = c.unroll_near(*p, *q);
            }
        }
        params.push(uv);
    }
    (points, params)
}

#[cfg(test)]
#[path = "tests/feature.rs"]
mod tests;
