//! Minimisation of a patch's distortion energy: nonlinear conjugate gradients
//! (Polak–Ribière⁺) with Armijo backtracking, in rounds of fixed regularisation δ, then
//! Newton's method ([`crate::newton`]) once the patch is untangled.

use crate::energy::DistortionEnergy;
use crate::NodeConstraint;

/// det T below which the regularisation stays on: δ² = ε (ε − min det T) (Escobar et al.
/// 2003), so that δ shrinks as the patch untangles and is 0 once every point has
/// det T ≥ ε.
const EPSILON: f64 = 1e-2;
/// Conjugate-gradient iterations per round of fixed δ.
const ROUND_ITERATIONS: usize = 60;
/// A round ends when an iteration lowers the energy by less than this fraction.
const RELATIVE_DECREASE: f64 = 1e-9;

/// What the minimisation reached.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Outcome {
    /// Smallest det T at the sample points at the end.
    pub min_ratio: f64,
    /// Conjugate-gradient iterations done.
    pub iterations: usize,
}

/// Moves `x` (the free nodes) towards a minimum of `energy`, at most `max_iterations`
/// iterations in all. `length` is the patch's edge length, the scale of the first step.
/// `constraints` (per node; empty: none) keep sliding nodes in their plane or on their
/// line: every gradient is projected onto the directions they may move in, so the search
/// directions, combinations of projected gradients, never leave them.
pub(crate) fn minimise(
    energy: &DistortionEnergy<'_>,
    x: &mut [[f64; 3]],
    length: f64,
    max_iterations: usize,
    constraints: &[Option<NodeConstraint>],
) -> Outcome {
    let project = |grad: &mut [[f64; 3]]| {
        for (g, c) in grad.iter_mut().zip(constraints) {
            if let Some(c) = c {
                *g = c.project(*g);
            }
        }
    };
    let dim = energy.dim;
    let n = x.len();
    let mut iterations = 0;
    let mut grad = vec![[0.0; 3]; n];
    let mut trial = vec![[0.0; 3]; n];
    let mut step = 0.1 * length;
    let mut last_delta = f64::NAN;
    while iterations < max_iterations {
        let min_ratio = energy.evaluate(x, 0.0, None).min_ratio;
        let delta = if min_ratio < EPSILON {
            (EPSILON * (EPSILON - min_ratio)).sqrt()
        } else {
            0.0
        };
        // δ as in the round before (to 0.1 %): that round converged and did not move the
        // worst point, so another round would find the same minimum.
        if delta == last_delta || (delta - last_delta).abs() <= 1e-3 * last_delta {
            break;
        }
        last_delta = delta;
        let mut current = energy.evaluate(x, delta, Some(&mut grad));
        project(&mut grad);
        if !current.energy.is_finite() {
            break;
        }
        let mut direction: Vec<[f64; 3]> = grad.iter().map(neg).collect();
        let mut previous_grad = grad.clone();
        let mut round = 0;
        while round < ROUND_ITERATIONS && iterations < max_iterations {
            round += 1;
            iterations += 1;
            let mut slope = dot(&grad, &direction, dim);
            if slope >= 0.0 {
                direction = grad.iter().map(neg).collect();
                slope = dot(&grad, &direction, dim);
            }
            if slope == 0.0 {
                break;
            }
            let longest = direction
                .iter()
                .map(|d| norm(d, dim))
                .fold(0.0f64, f64::max);
            // Start from twice the last accepted move, never more than 10% of the length.
            let mut alpha = (2.0 * step).min(0.1 * length) / longest;
            let mut accepted = None;
            for _ in 0..50 {
                moved(&mut trial, x, &direction, alpha, dim);
                let e = energy.evaluate(&trial, delta, None);
                if e.energy.is_finite() && e.energy <= current.energy + 1e-4 * alpha * slope {
                    accepted = Some(e);
                    break;
                }
                alpha *= 0.5;
            }
            let Some(_) = accepted else { break };
            step = alpha * longest;
            x.copy_from_slice(&trial);
            previous_grad.copy_from_slice(&grad);
            let next = energy.evaluate(x, delta, Some(&mut grad));
            project(&mut grad);
            let decrease = current.energy - next.energy;
            current = next;
            // Polak–Ribière⁺: β = max(0, gᵀ(g − g_prev) / g_prevᵀ g_prev).
            let mut num = 0.0;
            let mut den = 0.0;
            for (g, gp) in grad.iter().zip(&previous_grad) {
                for k in 0..dim {
                    num += g[k] * (g[k] - gp[k]);
                    den += gp[k] * gp[k];
                }
            }
            let beta = if den > 0.0 { (num / den).max(0.0) } else { 0.0 };
            for (d, g) in direction.iter_mut().zip(&grad) {
                for k in 0..dim {
                    d[k] = -g[k] + beta * d[k];
                }
            }
            if decrease <= RELATIVE_DECREASE * current.energy.abs() {
                break;
            }
        }
    }
    // Where every det T is positive, Newton's method converges to the minimum itself
    // (the iterations above stop at a point that depends on their path).
    if energy.evaluate(x, 0.0, None).energy.is_finite() {
        iterations += crate::newton::converge(energy, x, length, constraints);
    }
    Outcome {
        min_ratio: energy.evaluate(x, 0.0, None).min_ratio,
        iterations,
    }
}

/// `trial` = `x` + α `direction` in the first `dim` coordinates (the rest kept).
pub(crate) fn moved(
    trial: &mut [[f64; 3]],
    x: &[[f64; 3]],
    direction: &[[f64; 3]],
    alpha: f64,
    dim: usize,
) {
    for ((t, xi), d) in trial.iter_mut().zip(x).zip(direction) {
        for k in 0..dim {
            t[k] = xi[k] + alpha * d[k];
        }
        t[dim..].copy_from_slice(&xi[dim..]);
    }
}

pub(crate) fn neg(g: &[f64; 3]) -> [f64; 3] {
    [-g[0], -g[1], -g[2]]
}

pub(crate) fn dot(a: &[[f64; 3]], b: &[[f64; 3]], dim: usize) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (0..dim).map(|k| a[k] * b[k]).sum::<f64>())
        .sum()
}

pub(crate) fn norm(a: &[f64; 3], dim: usize) -> f64 {
    (0..dim).map(|k| a[k] * a[k]).sum::<f64>().sqrt()
}
