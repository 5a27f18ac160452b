//! Span hulls: boxes that provably hold a curve or surface, knot span by knot span, so that a
//! point can be found far from a patch without a point inversion.
//!
//! Over a knot span only p + 1 basis functions per direction are nonzero (local support,
//! Piegl & Tiller P2.2), they sum to one and, with positive weights, the rational ones are
//! nonnegative too (P4.1–P4.2): the piece of the curve or surface over the span is a convex
//! combination of those (p + 1) (or (p + 1)(q + 1)) control points, so it lies in their box
//! (the strong convex hull property, P4.3/P4.10). The distance from a point to the nearest
//! span box is therefore a lower bound on its distance to the patch; for a large B-spline
//! face whose whole control net boxes a part of a model, the span boxes are tight.

use crate::{NurbsCurve, NurbsSurface};

/// An axis-aligned box `[lo, hi]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Box3 {
    /// The lower corner.
    pub lo: [f64; 3],
    /// The upper corner.
    pub hi: [f64; 3],
}

impl Box3 {
    /// The box of `points` (empty: inverted, infinitely far from everything).
    pub fn of(points: impl IntoIterator<Item = [f64; 3]>) -> Self {
        let mut b = Box3 {
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
        };
        for p in points {
            for d in 0..3 {
                b.lo[d] = b.lo[d].min(p[d]);
                b.hi[d] = b.hi[d].max(p[d]);
            }
        }
        b
    }

    /// The squared distance from `x` to the box (0 inside; infinite for an empty box).
    pub fn squared_distance(&self, x: [f64; 3]) -> f64 {
        if self.lo[0] > self.hi[0] {
            return f64::INFINITY;
        }
        (0..3)
            .map(|d| (self.lo[d] - x[d]).max(x[d] - self.hi[d]).max(0.0).powi(2))
            .sum()
    }
}

/// The box of a whole patch and the boxes of its knot spans (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct SpanHulls {
    whole: Box3,
    spans: Vec<Box3>,
}

impl SpanHulls {
    /// The span hulls of a curve; `None` when a weight is not positive (no hull property).
    pub fn of_curve(curve: &NurbsCurve) -> Option<Self> {
        if !positive(&curve.weights) || curve.control_points.is_empty() {
            return None;
        }
        let p = curve.degree;
        let spans = nonempty_spans(&curve.knots, p, curve.control_points.len())
            .into_iter()
            .map(|i| Box3::of(curve.control_points[i - p..=i].iter().copied()))
            .collect();
        Some(Self {
            whole: Box3::of(curve.control_points.iter().copied()),
            spans,
        })
    }

    /// The span hulls of a surface; `None` when a weight is not positive.
    pub fn of_surface(surface: &NurbsSurface) -> Option<Self> {
        if !positive(&surface.weights) || surface.control_points.is_empty() {
            return None;
        }
        let (p, q) = (surface.degree_u, surface.degree_v);
        let (n_u, n_v) = (surface.n_u(), surface.n_v());
        let spans_u = nonempty_spans(&surface.knots_u, p, n_u);
        let spans_v = nonempty_spans(&surface.knots_v, q, n_v);
        let mut spans = Vec::with_capacity(spans_u.len() * spans_v.len());
        for &i in &spans_u {
            for &j in &spans_v {
                spans.push(Box3::of((i - p..=i).flat_map(|r| {
                    (j - q..=j).map(move |s| surface.control_points[r * n_v + s])
                })));
            }
        }
        Some(Self {
            whole: Box3::of(surface.control_points.iter().copied()),
            spans,
        })
    }

    /// Whether every point of the patch is farther than `r` from `x` (a `false` proves
    /// nothing).
    pub fn is_farther_than(&self, x: [f64; 3], r: f64) -> bool {
        let r2 = r * r;
        self.whole.squared_distance(x) > r2
            || (!self.spans.is_empty() && self.spans.iter().all(|b| b.squared_distance(x) > r2))
    }

    /// A lower bound on the distance from `x` to the patch: the distance to the nearest span
    /// box (each lies in the whole box, so this is at least the distance to that).
    pub fn distance_bound(&self, x: [f64; 3]) -> f64 {
        if self.spans.is_empty() {
            return self.whole.squared_distance(x).sqrt();
        }
        self.spans
            .iter()
            .map(|b| b.squared_distance(x))
            .fold(f64::INFINITY, f64::min)
            .sqrt()
    }
}

/// Whether every weight is positive (and none is NaN).
fn positive(weights: &[f64]) -> bool {
    weights.iter().all(|w| *w > 0.0)
}

/// The indices `i` (p ≤ i < n) of the knot spans `[u_i, u_{i+1})` of positive length inside
/// the domain `[u_p, u_n]`; the functions `N_{i-p} … N_i` act on span `i`.
fn nonempty_spans(knots: &[f64], degree: usize, count: usize) -> Vec<usize> {
    (degree..count.min(knots.len().saturating_sub(1)))
        .filter(|&i| knots[i + 1] > knots[i])
        .collect()
}

#[cfg(test)]
#[path = "tests/hull.rs"]
mod tests;
