//! A surface seen through its parameter plane, with the seams of closed directions unrolled
//! and the poles (degenerate edges) recognised, so that paths in parameter space can cross
//! a seam or start at a pole.

use hocurve_nurbs::inversion::closest_point_on_surface_near;
use hocurve_nurbs::NurbsSurface;

/// A NURBS surface with its periodicity and poles.
#[derive(Debug, Clone)]
pub struct SurfaceChart<'a> {
    /// The surface.
    pub surface: &'a NurbsSurface,
    domain: [(f64, f64); 2],
    periodic: [bool; 2],
    /// `[v = v0, v = v1, u = u0, u = u1]` collapsed to a point.
    poles: [bool; 4],
}

impl<'a> SurfaceChart<'a> {
    /// The chart of `surface`.
    pub fn new(surface: &'a NurbsSurface) -> Self {
        let (du, dv) = surface.domain();
        Self {
            surface,
            domain: [du, dv],
            periodic: [surface.is_closed_u(), surface.is_closed_v()],
            poles: surface.degenerate_edges(),
        }
    }

    /// The parameter folded into the domain: wrapped in closed directions, clamped otherwise.
    pub fn fold(&self, uv: [f64; 2]) -> [f64; 2] {
        let mut out = uv;
        for d in 0..2 {
            let (a, b) = self.domain[d];
            out[d] = if self.periodic[d] {
                a + (uv[d] - a).rem_euclid(b - a)
            } else {
                uv[d].clamp(a, b)
            };
        }
        out
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
            if self.periodic[d] {
                let period = self.domain[d].1 - self.domain[d].0;
                out[d] = uv[d] - ((uv[d] - near[d]) / period).round() * period;
            }
        }
        out
    }

    /// Whether `uv` lies on a degenerate edge, and which parameter is then free:
    /// `Some(0)` — u is arbitrary (a pole at v = const), `Some(1)` — v is arbitrary.
    pub fn free_direction_at(&self, uv: [f64; 2]) -> Option<usize> {
        let [u, v] = self.fold(uv);
        let ((u0, u1), (v0, v1)) = (self.domain[0], self.domain[1]);
        let eps_u = 1e-12 * (u1 - u0);
        let eps_v = 1e-12 * (v1 - v0);
        if (self.poles[0] && (v - v0).abs() <= eps_v) || (self.poles[1] && (v1 - v).abs() <= eps_v)
        {
            Some(0)
        } else if (self.poles[2] && (u - u0).abs() <= eps_u)
            || (self.poles[3] && (u1 - u).abs() <= eps_u)
        {
            Some(1)
        } else {
            None
        }
    }

    /// The end parameters of a path from `a` to `b`: `b` unrolled next to `a`, and an end at a
    /// pole given the other end's free coordinate (the path leaves a pole along a meridian).
    pub fn path_ends(&self, a: [f64; 2], b: [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let mut a = a;
        let mut b = self.unroll_near(b, a);
        if let Some(d) = self.free_direction_at(a) {
            a[d] = b[d];
        } else if let Some(d) = self.free_direction_at(b) {
            b[d] = a[d];
        }
        let b = self.unroll_near(b, a);
        (a, b)
    }

    /// Closest point of the surface to `x`, by Newton from the parameter `guess`.
    pub fn project_near(&self, x: [f64; 3], guess: [f64; 2]) -> ([f64; 2], [f64; 3]) {
        let cp = closest_point_on_surface_near(self.surface, x, self.fold(guess));
        (cp.param, cp.point)
    }
}
