//! Point inversion (Piegl & Tiller Sect. 6.1, the paper's "point inversion algorithm"): the
//! parameter of the point of a curve or surface closest to a given point. Starts are the best
//! of a few samples per knot span; Newton's method on the squared distance follows, with a
//! backtracking line search, parameters clamped to the domain (wrapped across the seam of a
//! closed curve or surface) and, where ∂S/∂u or ∂S/∂v vanishes (a pole), steps in the
//! non-degenerate direction only. Iterations stop when a step moves the point by less than
//! 1e-12 of the model size.

use crate::shapes::ClosestPoint;
use crate::vec3::{dot, norm, sub};
use crate::{NurbsCurve, NurbsSurface, SurfaceProperties};

/// Relative tolerance (of the model size) on the closest point.
pub const RELATIVE_TOLERANCE: f64 = 1e-12;
/// Below this distance (relative to the model size) a point counts as lying on the surface.
const ON_SURFACE: f64 = 1e-14;
/// Newton starts tried from the best samples.
const STARTS: usize = 3;
/// Newton stops after a step shorter than this (relative to the model size); by quadratic
/// convergence the point is then far more accurate than [`RELATIVE_TOLERANCE`].
const STEP_TOLERANCE: f64 = 1e-3 * RELATIVE_TOLERANCE;
const MAX_ITERATIONS: usize = 100;

/// How a parameter leaves its interval: clamped, or wrapped for a closed direction.
#[derive(Clone, Copy)]
struct Range {
    start: f64,
    end: f64,
    periodic: bool,
}

impl Range {
    fn fit(self, t: f64) -> f64 {
        if self.periodic {
            self.start + (t - self.start).rem_euclid(self.end - self.start)
        } else {
            t.clamp(self.start, self.end)
        }
    }
}

/// `count` samples per knot span, plus the domain end.
fn samples(breakpoints: &[f64], count: usize) -> Vec<f64> {
    let mut out = Vec::new();
    for w in breakpoints.windows(2) {
        for i in 0..count {
            out.push(w[0] + (w[1] - w[0]) * i as f64 / count as f64);
        }
    }
    out.extend(breakpoints.last());
    out
}

/// Whether a trial point is better: a smaller half squared distance `g`, or, where `g` is flat
/// to round-off (the evaluated point carries an absolute error ~ ε · size, so `g` one of
/// ~ ε · size · |r|), a smaller gradient.
fn accept(g_new: f64, g: f64, grad_new: f64, grad: f64, size: f64) -> bool {
    let noise = 16.0 * f64::EPSILON * (g + (2.0 * g).sqrt() * size) + f64::MIN_POSITIVE;
    g_new < g || (g_new <= g + noise && grad_new < grad)
}

/// The backtracking line search of a Newton step: the first of the step fractions
/// λ = 1, 1/2, 1/4, ... (above 1e-12) whose trial point [`accept`] takes over the current one
/// (half squared distance `g`, gradient norm `grad`). `trial(λ)` evaluates the point λ of the
/// way along the step: its state, half squared distance and gradient norm. `None` when no
/// fraction improves on the current point.
fn line_search<T>(g: f64, grad: f64, size: f64, trial: impl Fn(f64) -> (T, f64, f64)) -> Option<T> {
    let mut lambda = 1.0;
    while lambda > 1e-12 {
        let (state, g_new, grad_new) = trial(lambda);
        if accept(g_new, g, grad_new, grad, size) {
            return Some(state);
        }
        lambda *= 0.5;
    }
    None
}

/// The point of `curve` closest to `x`, from sampled starts.
pub fn closest_point_on_curve(curve: &NurbsCurve, x: [f64; 3]) -> ClosestPoint<f64> {
    let starts = samples(&curve.breakpoints(), 2 * curve.degree + 2);
    let mut scored: Vec<(f64, f64)> = starts
        .iter()
        .map(|&u| (norm(sub(curve.point(u), x)), u))
        .collect();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best: Option<ClosestPoint<f64>> = None;
    for &(_, u) in scored.iter().take(STARTS) {
        let candidate = closest_point_on_curve_near(curve, x, u);
        if best.is_none_or(|b| candidate.distance < b.distance) {
            best = Some(candidate);
        }
    }
    best.unwrap_or_else(|| closest_point_on_curve_near(curve, x, curve.domain().0))
}

/// Newton from the start parameter `guess` (a local minimum of the distance near it).
pub fn closest_point_on_curve_near(
    curve: &NurbsCurve,
    x: [f64; 3],
    guess: f64,
) -> ClosestPoint<f64> {
    let (start, end) = curve.domain();
    let range = Range {
        start,
        end,
        periodic: curve.is_closed(),
    };
    let size = curve.size().max(f64::MIN_POSITIVE);
    let tol = STEP_TOLERANCE * size;
    let mut u = range.fit(guess);
    let mut d = curve.derivatives(u, 2);
    let mut r = sub(d[0], x);
    let mut g = 0.5 * dot(r, r);
    for _ in 0..MAX_ITERATIONS {
        let f = dot(d[1], r);
        let speed2 = dot(d[1], d[1]);
        let fp = dot(d[2], r) + speed2;
        let step = if fp > 0.0 {
            -f / fp
        } else if speed2 > 0.0 {
            -f / speed2
        } else {
            break;
        };
        let trial = |lambda: f64| {
            let un = range.fit(u + lambda * step);
            let dn = curve.derivatives(un, 2);
            let rn = sub(dn[0], x);
            let gn = 0.5 * dot(rn, rn);
            let grad_n = dot(dn[1], rn).abs();
            ((un, dn, rn, gn), gn, grad_n)
        };
        let Some((un, dn, rn, gn)) = line_search(g, f.abs(), size, trial) else {
            break;
        };
        let movement = norm(sub(dn[0], d[0]));
        (u, d, r, g) = (un, dn, rn, gn);
        let moved = movement > tol;
        if !moved {
            break;
        }
    }
    ClosestPoint {
        param: u,
        point: d[0],
        distance: norm(r),
    }
}

/// The point of `surface` closest to `x`, from sampled starts.
pub fn closest_point_on_surface(surface: &NurbsSurface, x: [f64; 3]) -> ClosestPoint<[f64; 2]> {
    closest_point_on_surface_sampled(surface, &SurfaceSamples::new(surface), x)
}

/// The start grid of global point inversion on one surface — degree + 2 parameters per knot
/// span in each direction, with their points — and the surface's properties: computed once
/// for a surface inverted many times, they make each inversion a scan of stored points and
/// a few Newton steps instead of hundreds of surface evaluations.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSamples {
    params: Vec<[f64; 2]>,
    points: Vec<[f64; 3]>,
    /// Closedness, poles and size of the surface.
    pub properties: SurfaceProperties,
    /// What the grid was made for: the domain and the control net's size.
    domain: ((f64, f64), (f64, f64)),
    net: (usize, usize),
}

impl SurfaceSamples {
    /// The start grid of `surface`.
    pub fn new(surface: &NurbsSurface) -> Self {
        let su = samples(
            &breakpoints(&surface.knots_u, surface.degree_u),
            surface.degree_u + 2,
        );
        let sv = samples(
            &breakpoints(&surface.knots_v, surface.degree_v),
            surface.degree_v + 2,
        );
        let mut params = Vec::with_capacity(su.len() * sv.len());
        for &u in &su {
            for &v in &sv {
                params.push([u, v]);
            }
        }
        let points = params.iter().map(|p| surface.point(p[0], p[1])).collect();
        SurfaceSamples {
            params,
            points,
            properties: surface.properties(),
            domain: surface.domain(),
            net: (surface.n_u(), surface.n_v()),
        }
    }

    /// Whether the grid was made for a surface with `surface`'s domain and control net size
    /// (a cheap guard against a grid kept past a change of the surface).
    pub fn fits(&self, surface: &NurbsSurface) -> bool {
        self.domain == surface.domain() && self.net == (surface.n_u(), surface.n_v())
    }
}

/// [`closest_point_on_surface`] from the precomputed start grid `samples` of `surface`
/// (bitwise the same result).
pub fn closest_point_on_surface_sampled(
    surface: &NurbsSurface,
    samples: &SurfaceSamples,
    x: [f64; 3],
) -> ClosestPoint<[f64; 2]> {
    let mut scored: Vec<(f64, usize)> = samples
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| (norm(sub(*p, x)), i))
        .collect();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    let properties = &samples.properties;
    let mut best: Option<ClosestPoint<[f64; 2]>> = None;
    // Distinct start points only: at a pole a whole row of samples is one point.
    let separation = 1e-9 * properties.size;
    let mut taken: Vec<[f64; 3]> = Vec::new();
    for &(_, i) in &scored {
        if taken.len() > STARTS {
            break;
        }
        let p = samples.points[i];
        if taken.iter().any(|&q| norm(sub(p, q)) <= separation) {
            continue;
        }
        taken.push(p);
        let candidate =
            closest_point_on_surface_near_with(surface, properties, x, samples.params[i]);
        if best.is_none_or(|b| candidate.distance < b.distance) {
            best = Some(candidate);
        }
        // A point on the surface to round-off is its own closest point: no other start can
        // do better than this (the usual case: checking nodes placed on the surface).
        if candidate.distance <= ON_SURFACE * properties.size {
            break;
        }
    }
    let ((u0, _), (v0, _)) = surface.domain();
    best.unwrap_or_else(|| closest_point_on_surface_near_with(surface, properties, x, [u0, v0]))
}

fn breakpoints(knots: &[f64], degree: usize) -> Vec<f64> {
    let n = knots.len() - degree - 1;
    let (a, b) = (knots[degree], knots[n]);
    let mut out = vec![a];
    for &k in knots {
        if k > *out.last().unwrap_or(&a) && k < b {
            out.push(k);
        }
    }
    out.push(b);
    out
}

/// Newton from the start parameters `guess` (a local minimum of the distance near it).
pub fn closest_point_on_surface_near(
    surface: &NurbsSurface,
    x: [f64; 3],
    guess: [f64; 2],
) -> ClosestPoint<[f64; 2]> {
    closest_point_on_surface_near_with(surface, &surface.properties(), x, guess)
}

/// [`closest_point_on_surface_near`] with the surface's `properties` computed beforehand.
pub fn closest_point_on_surface_near_with(
    surface: &NurbsSurface,
    properties: &SurfaceProperties,
    x: [f64; 3],
    guess: [f64; 2],
) -> ClosestPoint<[f64; 2]> {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let range_u = Range {
        start: u0,
        end: u1,
        periodic: properties.closed[0],
    };
    let range_v = Range {
        start: v0,
        end: v1,
        periodic: properties.closed[1],
    };
    let size = properties.size.max(f64::MIN_POSITIVE);
    let tol = STEP_TOLERANCE * size;
    let mut uv = [range_u.fit(guess[0]), range_v.fit(guess[1])];
    let mut d = surface.derivatives(uv[0], uv[1]);
    let mut r = sub(d.point, x);
    let mut g = 0.5 * dot(r, r);
    for _ in 0..MAX_ITERATIONS {
        let grad = [dot(d.du, r), dot(d.dv, r)];
        let (guu, guv, gvv) = (dot(d.du, d.du), dot(d.du, d.dv), dot(d.dv, d.dv));
        let h = [
            [guu + dot(d.duu, r), guv + dot(d.duv, r)],
            [guv + dot(d.duv, r), gvv + dot(d.dvv, r)],
        ];
        let scale_h = guu.max(gvv);
        let step = solve_pd(h, grad, scale_h)
            // Not convex here: Gauss–Newton (first fundamental form).
            .or_else(|| solve_pd([[guu, guv], [guv, gvv]], grad, scale_h))
            // A pole: move in the non-degenerate direction only.
            .or_else(|| {
                if gvv > guu && gvv > 0.0 {
                    Some([0.0, -grad[1] / gvv])
                } else if guu > 0.0 {
                    Some([-grad[0] / guu, 0.0])
                } else {
                    None
                }
            });
        let Some(step) = step else { break };
        let grad_norm = grad[0].hypot(grad[1]);
        let trial = |lambda: f64| {
            let un = [
                range_u.fit(uv[0] + lambda * step[0]),
                range_v.fit(uv[1] + lambda * step[1]),
            ];
            let dn = surface.derivatives(un[0], un[1]);
            let rn = sub(dn.point, x);
            let gn = 0.5 * dot(rn, rn);
            let grad_n = dot(dn.du, rn).hypot(dot(dn.dv, rn));
            ((un, dn, rn, gn), gn, grad_n)
        };
        let Some((un, dn, rn, gn)) = line_search(g, grad_norm, size, trial) else {
            break;
        };
        let movement = norm(sub(dn.point, d.point));
        (uv, d, r, g) = (un, dn, rn, gn);
        let moved = movement > tol;
        if !moved {
            break;
        }
    }
    ClosestPoint {
        param: uv,
        point: d.point,
        distance: norm(r),
    }
}

/// Solves `h s = -grad` if `h` is safely positive definite.
fn solve_pd(h: [[f64; 2]; 2], grad: [f64; 2], scale: f64) -> Option<[f64; 2]> {
    let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
    if h[0][0] > 0.0 && h[1][1] > 0.0 && det > 1e-12 * scale * scale {
        Some([
            -(h[1][1] * grad[0] - h[0][1] * grad[1]) / det,
            -(h[0][0] * grad[1] - h[1][0] * grad[0]) / det,
        ])
    } else {
        None
    }
}

#[cfg(test)]
#[path = "tests/inversion.rs"]
mod tests;
