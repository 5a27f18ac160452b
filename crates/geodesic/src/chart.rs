//! A surface seen through its parameter plane, with the seams of closed directions unrolled
//! and the poles (degenerate edges) recognised, so that paths in parameter space can cross
//! a seam or start at a pole.

use hocurve_nurbs::inversion::closest_point_on_surface_near_with;
use hocurve_nurbs::vec3::{distance, dot, sub};
use hocurve_nurbs::{EntityGeometry, GeometryModel, NurbsSurface, SurfaceProperties};

/// A NURBS surface with its periodicity and poles.
#[derive(Debug, Clone)]
pub struct SurfaceChart<'a> {
    /// The surface.
    pub surface: &'a NurbsSurface,
    domain: [(f64, f64); 2],
    /// Closed directions (`closed`), poles (`degenerate_edges`: `[v = v0, v = v1, u = u0,
    /// u = u1]` collapsed to a point) and size.
    properties: SurfaceProperties,
}

/// A geometry with the chart of each of its surfaces, built once: a chart's closedness and
/// poles take a pass over the control net, which costs more than a geodesic on a large
/// B-spline surface.
#[derive(Debug, Clone)]
pub(crate) struct GeometryCharts<'a> {
    pub geometry: &'a GeometryModel,
    charts: Vec<Option<SurfaceChart<'a>>>,
}

impl<'a> GeometryCharts<'a> {
    pub fn new(geometry: &'a GeometryModel) -> Self {
        let charts = geometry
            .entities
            .iter()
            .map(|e| match &e.geometry {
                EntityGeometry::Surface(s) => Some(SurfaceChart::new(s)),
                EntityGeometry::Curve(_) => None,
            })
            .collect();
        Self { geometry, charts }
    }

    /// The chart of entity `entity`, `None` for a curve or an index out of range.
    pub fn chart(&self, entity: usize) -> Option<&SurfaceChart<'a>> {
        self.charts.get(entity).and_then(Option::as_ref)
    }
}

impl<'a> SurfaceChart<'a> {
    /// The chart of `surface`.
    pub fn new(surface: &'a NurbsSurface) -> Self {
        let (du, dv) = surface.domain();
        Self {
            surface,
            domain: [du, dv],
            properties: surface.properties(),
        }
    }

    /// The parameter folded into the domain: wrapped in closed directions, clamped otherwise.
    pub fn fold(&self, uv: [f64; 2]) -> [f64; 2] {
        let mut out = uv;
        for d in 0..2 {
            let (a, b) = self.domain[d];
            out[d] = if self.properties.closed[d] {
                a + (uv[d] - a).rem_euclid(b - a)
            } else {
                uv[d].clamp(a, b)
            };
        }
        out
    }

    /// The bounding-box diagonal of the surface's control net.
    pub fn size(&self) -> f64 {
        self.properties.size
    }

    /// The range of parameter `d` (0: u, 1: v) when it is not periodic; `None` for a
    /// closed direction, which has no end.
    pub fn bounded_range(&self, d: usize) -> Option<(f64, f64)> {
        (!self.properties.closed[d]).then_some(self.domain[d])
    }

    /// The surface point at an (unrolled) parameter.
    pub fn point(&self, uv: [f64; 2]) -> [f64; 3] {
        let [u, v] = self.fold(uv);
        self.surface.point(u, v)
    }

    /// The copy of `uv` (shifted by whole periods) nearest `near`, so that the straight
    /// parameter segment between them does not run the long way round a seam.
    pub fn unroll_near(&self, uv: [f64; 2], near: [f64; 2]) -> [f64; 2] {
        let mut out = uv;
        for d in 0..2 {
            if self.properties.closed[d] {
                let period = self.domain[d].1 - self.domain[d].0;
                out[d] = uv[d] - ((uv[d] - near[d]) / period).round() * period;
            }
        }
        out
    }

    /// Whether `uv` lies on a degenerate edge (a pole), and which parameter is then free:
    /// `Some((0, v))` — u is arbitrary and the pole is at v, `Some((1, u))` — v is arbitrary.
    ///
    /// Decided in 3D: the point S(uv) lies within 1e-7 of the surface's size of the pole.
    /// Point inversion converges only linearly at a pole, so a mesh vertex snapped there
    /// gets a parameter some 1e-8 off the degenerate edge; a test in parameter space would
    /// miss it, and a path from it would spiral away along the wrong meridian.
    pub fn free_direction_at(&self, uv: [f64; 2]) -> Option<(usize, f64)> {
        if !self.properties.degenerate_edges.iter().any(|&p| p) {
            return None;
        }
        let [u, v] = self.fold(uv);
        let ((u0, u1), (v0, v1)) = (self.domain[0], self.domain[1]);
        let x = self.surface.point(u, v);
        let tolerance = 1e-7 * self.properties.size.max(f64::MIN_POSITIVE);
        let near = |p: [f64; 3]| distance(x, p) <= tolerance;
        let candidates = [
            (self.properties.degenerate_edges[0], (0, v0), [u, v0]),
            (self.properties.degenerate_edges[1], (0, v1), [u, v1]),
            (self.properties.degenerate_edges[2], (1, u0), [u0, v]),
            (self.properties.degenerate_edges[3], (1, u1), [u1, v]),
        ];
        candidates
            .into_iter()
            .find(|&(pole, _, at)| pole && near(self.surface.point(at[0], at[1])))
            .map(|(_, free, _)| free)
    }

    /// The end parameters of a path from `a` to `b`: `b` unrolled next to `a`, and an end at a
    /// pole put exactly on it with the other end's free coordinate (the path leaves a pole
    /// along a meridian, as every geodesic from a pole does).
    pub fn path_ends(&self, a: [f64; 2], b: [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let mut a = a;
        let mut b = self.unroll_near(b, a);
        let (pole_a, pole_b) = (self.free_direction_at(a), self.free_direction_at(b));
        if let Some((d, at)) = pole_a {
            a[1 - d] = at;
            if pole_b.is_none() {
                a[d] = b[d];
            }
        }
        if let Some((d, at)) = pole_b {
            b[1 - d] = at;
            if pole_a.is_none() {
                b[d] = a[d];
            }
        }
        let b = self.unroll_near(b, a);
        (a, b)
    }

    /// The parameter near `guess` (unrolled next to it) of the surface point closest to `x`
    /// by Gauss–Newton steps on the first fundamental form, without a line search: one
    /// surface evaluation per step, three or four in all where `x` is near the surface and
    /// the guess near its foot, against twice that for [`Self::project_near`]. `None` where
    /// the form is singular (at a pole), an iterate leaves a bounded direction's range, or
    /// the steps have not shrunk to round-off within `max_steps`.
    pub fn project_by_gauss_newton(
        &self,
        x: [f64; 3],
        guess: [f64; 2],
        max_steps: usize,
    ) -> Option<[f64; 2]> {
        let mut uv = guess;
        let tolerance = 1e-14 * self.properties.size;
        for _ in 0..max_steps {
            let [u, v] = self.fold(uv);
            let d = self.surface.derivatives(u, v);
            let r = sub(x, d.point);
            let (guu, guv, gvv) = (dot(d.du, d.du), dot(d.du, d.dv), dot(d.dv, d.dv));
            let det = guu * gvv - guv * guv;
            if det.is_nan() || det <= 1e-12 * guu.max(gvv).powi(2) {
                return None;
            }
            let (bu, bv) = (dot(d.du, r), dot(d.dv, r));
            let step = [(gvv * bu - guv * bv) / det, (guu * bv - guv * bu) / det];
            uv = [uv[0] + step[0], uv[1] + step[1]];
            for d in 0..2 {
                if let Some((a, b)) = self.bounded_range(d) {
                    if !(a..=b).contains(&uv[d]) {
                        return None;
                    }
                }
            }
            // The step's length on the surface, to first order.
            let moved =
                (guu * step[0] * step[0] + 2.0 * guv * step[0] * step[1] + gvv * step[1] * step[1])
                    .max(0.0)
                    .sqrt();
            if moved <= tolerance {
                return Some(uv);
            }
        }
        None
    }

    /// Closest point of the surface to `x`, by Newton from the parameter `guess`.
    pub fn project_near(&self, x: [f64; 3], guess: [f64; 2]) -> ([f64; 2], [f64; 3]) {
        let cp =
            closest_point_on_surface_near_with(self.surface, &self.properties, x, self.fold(guess));
        (cp.param, cp.point)
    }
}

#[cfg(test)]
#[path = "tests/chart.rs"]
mod tests;
