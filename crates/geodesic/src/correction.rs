//! The minimum-angle correction of curved surface edges (the paper's Sect. 4.1, Fig. 4).
//!
//! "For each edge on a curved boundary, e.g. the edge connecting vertices x₁ and x₂ in
//! Fig. 4a, the angles αᵢ, i = 1, …, 4, between this edge and its neighbouring edges are
//! measured. If any angle αᵢ is less than the specified lower limit, a new edge connecting the
//! vertices x₁ and x₂ is defined, in such a way that the four angles αᵢ are acceptable. For
//! instance, if p = 3 is considered, the new edge is defined by a cubic curve, that contains
//! the two vertices x₁ and x₂, with the derivative at the initial and final vertices imposed
//! in such a way that the minimum angle between edges is not less than the specified limit
//! (Fig. 4b). For p = 4, the curvature on one edge vertex is also imposed and, for p = 5, the
//! curvature at both edge vertices is included."
//!
//! Here, for an edge x₁x₂ inside one surface S (its approximate geodesic, Eq. (5)):
//! - **Angles.** At each vertex the edge's tangent t and the tangents dⱼ of its neighbouring
//!   edges — the other edge at that vertex of each curved boundary face holding the edge (two
//!   faces, so four angles in all, as in Fig. 4a) — are projected onto the tangent plane of S.
//!   αⱼ is the angle from t to dⱼ measured towards face j's side of the edge (negative if the
//!   curved edge has crossed its neighbour).
//! - **New tangent directions.** If some αⱼ < α_min, t is turned in the tangent plane by the
//!   smallest angle ψ that gives every αⱼ ≥ α_min: the admissible turns form an interval
//!   [max over faces on one side of (φⱼ + mⱼ), min over faces on the other side of (φⱼ − mⱼ)],
//!   φⱼ the signed angle of dⱼ; ψ is the point of the interval nearest 0, or the bisector of
//!   the two nearest neighbours when the interval is empty (the best the vertex allows). When
//!   the neighbour is itself a surface edge that the correction can turn, the two edges share
//!   the deficit (mⱼ = (α_min + αⱼ)/2: each turns half-way, together they reach α_min);
//!   otherwise mⱼ = α_min. Neighbours' tangents are those of their uncorrected geodesics, so
//!   the correction of every edge is independent of the order of the edges.
//! - **The new edge** (Fig. 4b) is the polynomial C(t), t ∈ [0, 1], of Hermite type with
//!   C(0) = x₁, C(1) = x₂, C′(0) = L t₁′, C′(1) = −L t₂′ (tᵢ′ the turned unit directions
//!   pointing into the edge, L the geodesic's length, so that t is close to arc length);
//!   p = 3: the cubic of these four conditions;
//!   p = 4: the quartic with also C″ imposed at the vertex with the smaller angle (at the
//!   lower-numbered vertex on a tie);
//!   p = 5: the quintic with C″ imposed at both vertices.
//!   The paper does not say which curvature; we impose that of the surface along the new
//!   direction with no tangential acceleration, C″(0) = L² κₙ(t₁′) n₁ — the second derivative
//!   of a unit-speed surface curve without geodesic curvature — so that the new edge
//!   osculates S at the vertex, as the geodesic it replaces did, and the projection back onto
//!   S moves its nodes near the vertex as little as possible.
//! - **Nodes.** xₖ = Π_S(C(ξₖ)) for the reference 1D distribution ξₖ: at these parameters the
//!   degree-p interpolant of the (unprojected) nodes is C itself, so the imposed end
//!   derivatives are those of the discrete edge; the projection only moves the nodes along
//!   the surface normal, by O(L²κ). Other points of the edge (used by the face-interior
//!   construction of Eqs. (6)–(7)) are Π_S(C(f)) for the fraction f.
//!
//! - **Where it applies.** At every end where S has a tangent plane, a vertex on a feature
//!   curve or a corner included: the edge and its neighbours in the faces on S all lie in S,
//!   so their angles are S's even where another entity meets S there. (A fillet's facet with
//!   two vertices on the fillet's boundary circle is the common case: the curved boundary
//!   edge can cross the facet's other edge at such a vertex.) The curving pipeline keeps a
//!   correction only if it lifts the worst element on the edge.
//!
//! Orders the paper leaves open: p = 2 — a quadratic through two points has a single free
//! vector, so it takes the turned tangent at one end only: the end with the smaller angle
//! (the lower-numbered vertex on a tie), C(t) = x₁ + C′(0) t + (x₂ − x₁ − C′(0)) t²; the other
//! end's tangent follows, 2(x₂ − x₁) − C′(0), turned the other way, so the quadratic is
//! taken only if the smallest angle at the two ends is larger with it than before. Its
//! neighbours do not count on it to share a deficit (it may turn at its other end). p ≥ 6 — the quintic of p = 5 ("extra conditions
//! can be devised … but these are not considered here"); the degree-p interpolant
//! reproduces it exactly. Edges on a curve (2D boundaries, 3D feature edges) are fixed by
//! the geometry and are not corrected.

use hocurve_nurbs::vec3::{add, cross, dot, reject, scale, sub, unit};
use hocurve_nurbs::GeometryModel;

use crate::chart::SurfaceChart;
use crate::frame::SurfaceFrame;
use crate::path::GeodesicPath;

/// A polynomial curve of degree 3–5 given by Hermite data at t = 0 and t = 1 (Fig. 4b),
/// stored by its monomial coefficients; `reversed` curves are evaluated at 1 − t.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct HermiteCurve {
    coefficients: Vec<[f64; 3]>,
    reversed: bool,
}

/// Hermite data of an edge: end points, end first derivatives, and optionally end second
/// derivatives.
#[derive(Debug, Clone, Copy)]
pub(crate) struct HermiteData {
    pub(crate) start: [f64; 3],
    pub(crate) end: [f64; 3],
    pub(crate) start_derivative: [f64; 3],
    pub(crate) end_derivative: [f64; 3],
    pub(crate) start_second: Option<[f64; 3]>,
    pub(crate) end_second: Option<[f64; 3]>,
}

impl HermiteCurve {
    /// The polynomial of lowest degree matching the data: cubic (two points, two first
    /// derivatives), quartic (plus one second derivative), quintic (plus both).
    pub(crate) fn new(data: HermiteData) -> Self {
        match (data.start_second, data.end_second) {
            (None, Some(a1)) => {
                // The quartic with the second derivative at its start, run backwards.
                let mut c = Self::forward(HermiteData {
                    start: data.end,
                    end: data.start,
                    start_derivative: scale(data.end_derivative, -1.0),
                    end_derivative: scale(data.start_derivative, -1.0),
                    start_second: Some(a1),
                    end_second: None,
                });
                c.reversed = true;
                c
            }
            _ => Self::forward(data),
        }
    }

    /// The quadratic through `start` and `end` with first derivative `start_derivative` at
    /// `start` (p = 2): C(t) = P₀ + D₀ t + (P₁ − P₀ − D₀) t².
    pub(crate) fn quadratic(start: [f64; 3], end: [f64; 3], start_derivative: [f64; 3]) -> Self {
        Self {
            coefficients: vec![
                start,
                start_derivative,
                sub(sub(end, start), start_derivative),
            ],
            reversed: false,
        }
    }

    fn forward(data: HermiteData) -> Self {
        let (p0, p1, d0, d1) = (
            data.start,
            data.end,
            data.start_derivative,
            data.end_derivative,
        );
        let coefficients = match (data.start_second, data.end_second) {
            (Some(a0), Some(a1)) => {
                // C = P0 + D0 t + A0/2 t² + a t³ + b t⁴ + c t⁵ with
                // a + b + c = R, 3a + 4b + 5c = S, 6a + 12b + 20c = U.
                let r = sub(sub(sub(p1, p0), d0), scale(a0, 0.5));
                let s = sub(sub(d1, d0), a0);
                let u = sub(a1, a0);
                let a = add(sub(scale(r, 10.0), scale(s, 4.0)), scale(u, 0.5));
                let b = sub(add(scale(r, -15.0), scale(s, 7.0)), u);
                let c = add(sub(scale(r, 6.0), scale(s, 3.0)), scale(u, 0.5));
                vec![p0, d0, scale(a0, 0.5), a, b, c]
            }
            (Some(a0), None) => {
                // C = P0 + D0 t + A0/2 t² + a t³ + b t⁴ with a + b = R, 3a + 4b = S.
                let r = sub(sub(sub(p1, p0), d0), scale(a0, 0.5));
                let s = sub(sub(d1, d0), a0);
                let b = sub(s, scale(r, 3.0));
                let a = sub(scale(r, 4.0), s);
                vec![p0, d0, scale(a0, 0.5), a, b]
            }
            _ => {
                // C = P0 + D0 t + a t² + b t³ with a + b = R, 2a + 3b = S.
                let r = sub(sub(p1, p0), d0);
                let s = sub(d1, d0);
                let b = sub(s, scale(r, 2.0));
                let a = sub(scale(r, 3.0), s);
                vec![p0, d0, a, b]
            }
        };
        Self {
            coefficients,
            reversed: false,
        }
    }

    /// Degree of the polynomial.
    #[cfg(test)]
    pub(crate) fn degree(&self) -> usize {
        self.coefficients.len() - 1
    }

    /// C(t).
    pub(crate) fn point(&self, t: f64) -> [f64; 3] {
        let s = if self.reversed { 1.0 - t } else { t };
        let mut x = [0.0; 3];
        for c in self.coefficients.iter().rev() {
            x = add(scale(x, s), *c);
        }
        x
    }

    /// C′(t).
    #[cfg(test)]
    pub(crate) fn derivative(&self, t: f64) -> [f64; 3] {
        let s = if self.reversed { 1.0 - t } else { t };
        let mut x = [0.0; 3];
        for (k, c) in self.coefficients.iter().enumerate().skip(1).rev() {
            x = add(scale(x, s), scale(*c, k as f64));
        }
        if self.reversed {
            scale(x, -1.0)
        } else {
            x
        }
    }
}

/// A neighbouring edge at a vertex of the edge being checked.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Neighbour {
    /// Unit tangent of the neighbouring edge at the shared vertex, pointing into it.
    pub(crate) tangent: [f64; 3],
    /// The face's vertex beyond the neighbouring edge (its other end): which side of the
    /// checked edge the face lies on.
    pub(crate) far_vertex: [f64; 3],
    /// Whether the neighbouring edge is itself turned by the correction (so the two share the
    /// deficit).
    pub(crate) correctable: bool,
}

/// One end of the edge being checked.
#[derive(Debug, Clone)]
pub(crate) struct EdgeEnd {
    /// Global vertex id (ties of the p = 4 rule go to the lower id).
    pub(crate) vertex: u32,
    /// The vertex position.
    pub(crate) point: [f64; 3],
    /// Its surface parameter.
    pub(crate) param: [f64; 2],
    /// Unit tangent of the edge's geodesic there, pointing into the edge.
    pub(crate) tangent: [f64; 3],
    /// The neighbouring edges there.
    pub(crate) neighbours: Vec<Neighbour>,
}

/// The outcome of checking one edge.
#[derive(Debug, Clone)]
pub(crate) struct AngleCheck {
    /// Smallest angle αⱼ at either end, radians (before correction).
    pub(crate) min_angle: f64,
    /// The new edge, when some angle is below the limit and the order allows a correction.
    pub(crate) curve: Option<HermiteCurve>,
}

/// The turn ψ (radians, positive counter-clockwise about `normal`) that brings every angle
/// between the unit tangent `t` and the neighbours to at least `limit`, and the smallest angle
/// before the turn (see the module doc).
pub(crate) fn vertex_turn(
    t: [f64; 3],
    normal: [f64; 3],
    chord: [f64; 3],
    point: [f64; 3],
    neighbours: &[Neighbour],
    limit: f64,
) -> (f64, f64) {
    let mut min_angle = f64::INFINITY;
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut nearest_negative, mut nearest_positive) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut constrained = false;
    for nb in neighbours {
        let Some(d) = unit(reject(nb.tangent, normal)) else {
            continue;
        };
        let far = reject(sub(nb.far_vertex, point), normal);
        let side = dot(cross(chord, far), normal).signum();
        if side == 0.0 {
            continue;
        }
        let phi = dot(cross(t, d), normal).atan2(dot(t, d));
        let alpha = side * phi;
        min_angle = min_angle.min(alpha);
        let required = if nb.correctable && alpha < limit {
            0.5 * (limit + alpha)
        } else {
            limit
        };
        constrained = true;
        if side > 0.0 {
            hi = hi.min(phi - required);
            nearest_positive = nearest_positive.min(phi);
        } else {
            lo = lo.max(phi + required);
            nearest_negative = nearest_negative.max(phi);
        }
    }
    if !constrained || min_angle >= limit {
        return (min_angle, 0.0);
    }
    let turn = if lo <= hi {
        0.0_f64.max(lo).min(hi)
    } else {
        0.5 * (nearest_negative + nearest_positive)
    };
    (min_angle, turn)
}

/// `t` turned by `psi` about the unit `normal` (t ⟂ normal).
fn rotate(t: [f64; 3], normal: [f64; 3], psi: f64) -> [f64; 3] {
    add(scale(t, psi.cos()), scale(cross(normal, t), psi.sin()))
}

/// Checks the angles of the edge from `ends[0]` to `ends[1]` on the chart's surface (its
/// geodesic has length `length`) and, if one is below `limit` (radians) and `order` ≥ 2,
/// builds the new edge of Fig. 4b. `None` if the surface has no tangent plane at an end.
pub(crate) fn check_edge(
    chart: &SurfaceChart,
    ends: &[EdgeEnd; 2],
    length: f64,
    order: usize,
    limit: f64,
) -> Option<AngleCheck> {
    let mut frames = Vec::with_capacity(2);
    let mut turned = [[0.0; 3]; 2];
    let mut min_angles = [0.0; 2];
    for (i, end) in ends.iter().enumerate() {
        let frame = SurfaceFrame::at(chart, end.param)?;
        let n = frame.normal;
        let t = unit(reject(end.tangent, n))?;
        let chord = reject(sub(ends[1 - i].point, end.point), n);
        let (min_angle, psi) = vertex_turn(t, n, chord, end.point, &end.neighbours, limit);
        turned[i] = rotate(t, n, psi);
        min_angles[i] = min_angle;
        frames.push(frame);
    }
    let min_angle = min_angles[0].min(min_angles[1]);
    if min_angle >= limit || order < 2 {
        return Some(AngleCheck {
            min_angle,
            curve: None,
        });
    }
    // p = 2 and p = 4: the end with the smaller angle (the lower id on a tie) gets the
    // extra condition.
    let first_is_worse = match min_angles[0].total_cmp(&min_angles[1]) {
        std::cmp::Ordering::Less => true,
        std::cmp::Ordering::Greater => false,
        std::cmp::Ordering::Equal => ends[0].vertex < ends[1].vertex,
    };
    if order == 2 {
        return Some(AngleCheck {
            min_angle,
            curve: quadratic_edge(&frames, ends, turned, length, first_is_worse, limit)
                .filter(|(_, new_min)| *new_min > min_angle)
                .map(|(curve, _)| curve),
        });
    }
    let second = |i: usize| {
        let f: &SurfaceFrame = &frames[i];
        scale(f.normal, length * length * f.normal_curvature(turned[i]))
    };
    let (start_second, end_second) = match order {
        3 => (None, None),
        4 if first_is_worse => (Some(second(0)), None),
        4 => (None, Some(second(1))),
        _ => (Some(second(0)), Some(second(1))),
    };
    let curve = HermiteCurve::new(HermiteData {
        start: ends[0].point,
        end: ends[1].point,
        start_derivative: scale(turned[0], length),
        end_derivative: scale(turned[1], -length),
        start_second,
        end_second,
    });
    Some(AngleCheck {
        min_angle,
        curve: Some(curve),
    })
}

/// The quadratic edge (p = 2) with the turned tangent at its worse end (`first_is_worse`),
/// and the smallest angle at either end after it: the other end's tangent is no longer
/// free, so the quadratic is only worth having if that angle beats the edge's before.
fn quadratic_edge(
    frames: &[SurfaceFrame],
    ends: &[EdgeEnd; 2],
    turned: [[f64; 3]; 2],
    length: f64,
    first_is_worse: bool,
    limit: f64,
) -> Option<(HermiteCurve, f64)> {
    let (w, o) = if first_is_worse { (0, 1) } else { (1, 0) };
    let (xw, xo) = (ends[w].point, ends[o].point);
    let curve = HermiteCurve::quadratic(xw, xo, scale(turned[w], length));
    // Into the edge at the other end: −C′(1) = C′(0) − 2 (x_o − x_w).
    let n_o = frames[o].normal;
    let t_o = unit(reject(
        sub(scale(turned[w], length), scale(sub(xo, xw), 2.0)),
        n_o,
    ))?;
    let angle_at = |i: usize, t: [f64; 3]| {
        let n = frames[i].normal;
        let chord = reject(sub(ends[1 - i].point, ends[i].point), n);
        vertex_turn(t, n, chord, ends[i].point, &ends[i].neighbours, limit).0
    };
    let new_min = angle_at(w, turned[w]).min(angle_at(o, t_o));
    let curve = if w == 0 {
        curve
    } else {
        HermiteCurve {
            reversed: true,
            ..curve
        }
    };
    Some((curve, new_min))
}

/// A corrected edge: its Hermite curve, whose points are projected onto the surface.
pub(crate) struct CorrectedEdge<'a> {
    pub(crate) geometry: &'a GeometryModel,
    pub(crate) entity: usize,
    pub(crate) chart: SurfaceChart<'a>,
    pub(crate) curve: HermiteCurve,
    /// The geodesic it replaces, for the start parameters of the projections.
    pub(crate) guide: GeodesicPath,
}

impl CorrectedEdge<'_> {
    /// Π_S(C(fraction)) and its surface parameter.
    pub(crate) fn at(&self, fraction: f64) -> ([f64; 2], [f64; 3]) {
        let n = self.guide.points.len();
        if fraction <= 0.0 {
            return (self.guide.params[0], self.guide.points[0]);
        }
        if fraction >= 1.0 {
            return (self.guide.params[n - 1], self.guide.points[n - 1]);
        }
        let x = self.curve.point(fraction);
        let guess = self.guide.at_fraction(&self.chart, fraction).0;
        let (uv, y) = self.chart.project_near(x, guess);
        let uv = self.chart.unroll_near(uv, guess);
        match &self.geometry.entities[self.entity].analytic {
            Some(shape) => (uv, shape.closest_point(x).point),
            None => (uv, y),
        }
    }
}

#[cfg(test)]
#[path = "tests/correction.rs"]
mod tests;
