//! Fekete points of the triangle and tetrahedron: the interior nodes that maximise
//! |det V|, V the Vandermonde matrix of an orthonormal basis at all the element's nodes
//! (Taylor, Wingate & Vincent, SIAM J Numer Anal 38 (2000)), with the boundary held at the
//! family's edge (GLL) and face (triangle Fekete) sets so that neighbours share nodes.
//!
//! The optimisation keeps the element's full symmetry by moving whole symmetry orbits: a node
//! with barycentric lattice indices b gets barycentric coordinates λ_k = u(b_k), one unknown
//! value u per distinct index value in its orbit (minus the constraint Σλ = 1). It starts
//! from the warp & blend nodes and climbs log|det V| by BFGS with a backtracking line search
//! (gradient: ∂ log|det V| / ∂x_k = Σ_j (V⁻¹)_{jk} ∇ψ_j(x_k)). Results are cached per order.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use nalgebra::{DMatrix, DVector};

use crate::basis::OrthonormalBasis;
use crate::{NodeFamily, ReferenceNodes, Shape};

type Interior = Arc<Vec<([f64; 3], [i64; 3])>>;

/// Interior Fekete nodes of a triangle or tetrahedron of order `p`, in lattice order.
pub(crate) fn fekete_interior(shape: Shape, p: usize) -> Interior {
    static CACHE: OnceLock<Mutex<HashMap<(Shape, usize), Interior>>> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(hit) = cache.lock().ok().and_then(|c| c.get(&(shape, p)).cloned()) {
        return hit;
    }
    let result = Arc::new(optimise(shape, p));
    if let Ok(mut c) = cache.lock() {
        c.entry((shape, p)).or_insert_with(|| result.clone());
    }
    result
}

/// One symmetry orbit of interior nodes: for each member, the node's position in the full
/// set and its barycentric lattice indices; `values` are the distinct index values, the
/// first of which is eliminated by Σλ = 1.
struct Orbit {
    members: Vec<(usize, Vec<i64>)>,
    values: Vec<i64>,
    multiplicity: Vec<f64>,
}

fn optimise(shape: Shape, p: usize) -> Vec<([f64; 3], [i64; 3])> {
    let start = NodeFamily::WarpBlend.interior_nodes(shape, p);
    if start.is_empty() {
        return start;
    }
    // The full set: Fekete boundary (this family's edges and faces), warp & blend inside.
    let mut set = ReferenceNodes::assemble(shape, p, NodeFamily::Fekete, start.clone());
    let dim = shape.dim();
    let pi = p as i64;
    let first_interior = set.len() - start.len();
    let bary = |l: &[i64; 3]| -> Vec<i64> {
        let rest = pi - l[..dim].iter().sum::<i64>();
        std::iter::once(rest)
            .chain(l[..dim].iter().copied())
            .collect()
    };

    // Group interior nodes into orbits by the multiset of their barycentric indices.
    let mut orbits: Vec<Orbit> = Vec::new();
    let mut orbit_of: HashMap<Vec<i64>, usize> = HashMap::new();
    for k in first_interior..set.len() {
        let b = bary(&set.lattice()[k]);
        let mut key = b.clone();
        key.sort_unstable();
        let o = *orbit_of.entry(key.clone()).or_insert_with(|| {
            let mut values = key.clone();
            values.dedup();
            let multiplicity = values
                .iter()
                .map(|v| key.iter().filter(|&&x| x == *v).count() as f64)
                .collect();
            orbits.push(Orbit {
                members: Vec::new(),
                values,
                multiplicity,
            });
            orbits.len() - 1
        });
        orbits[o].members.push((k, b));
    }

    // Parameters: u for every value but the first of each orbit, started at the
    // warp & blend λ of the orbit's first member.
    let mut params: Vec<f64> = Vec::new();
    let mut offsets = Vec::new();
    for orbit in &orbits {
        offsets.push(params.len());
        let (k, b) = &orbit.members[0];
        let x = set.points[*k];
        let lambda: Vec<f64> = std::iter::once(1.0 - x[..dim].iter().sum::<f64>())
            .chain(x[..dim].iter().copied())
            .collect();
        for v in &orbit.values[1..] {
            let pos = b.iter().position(|bi| bi == v).unwrap_or(0);
            params.push(lambda[pos]);
        }
    }
    let place = |params: &[f64], points: &mut [[f64; 3]]| {
        for (orbit, &off) in orbits.iter().zip(&offsets) {
            let u = &params[off..off + orbit.values.len() - 1];
            let rest: f64 = u
                .iter()
                .zip(&orbit.multiplicity[1..])
                .map(|(u, m)| u * m)
                .sum();
            let u0 = (1.0 - rest) / orbit.multiplicity[0];
            let value = |b: i64| {
                let j = orbit.values.iter().position(|&v| v == b).unwrap_or(0);
                if j == 0 {
                    u0
                } else {
                    u[j - 1]
                }
            };
            for (k, b) in &orbit.members {
                for c in 0..dim {
                    points[*k][c] = value(b[c + 1]);
                }
            }
        }
    };

    let basis = OrthonormalBasis::new(shape, p);
    let n = set.len();
    // log|det V| and its gradient with respect to the parameters; None if V is singular.
    let objective = |params: &[f64], points: &mut Vec<[f64; 3]>| -> Option<(f64, Vec<f64>)> {
        place(params, points);
        // |det V| grows without bound outside the element: keep every node inside.
        let outside = points[first_interior..]
            .iter()
            .any(|x| x[..dim].iter().any(|&c| c <= 0.0) || x[..dim].iter().sum::<f64>() >= 1.0);
        if outside {
            return None;
        }
        let mut v = DMatrix::<f64>::zeros(n, n);
        let mut row = vec![0.0; n];
        for (k, x) in points.iter().enumerate() {
            basis.eval(*x, &mut row);
            for j in 0..n {
                v[(k, j)] = row[j];
            }
        }
        let lu = v.lu();
        // log|det V| as Σ log|U_ii|: |det V| itself overflows f64 for tets at p ≥ 8.
        let log_det: f64 = lu.u().diagonal().iter().map(|u| u.abs().ln()).sum();
        if !log_det.is_finite() {
            return None;
        }
        let inverse = lu.try_inverse()?;
        let mut grads = vec![[0.0; 3]; n];
        let mut grad_x = vec![[0.0; 3]; n];
        for k in first_interior..n {
            basis.eval_grad(points[k], &mut grads);
            let mut g = [0.0; 3];
            for j in 0..n {
                for c in 0..dim {
                    g[c] += inverse[(j, k)] * grads[j][c];
                }
            }
            grad_x[k] = g;
        }
        let mut grad = vec![0.0; params.len()];
        for (orbit, &off) in orbits.iter().zip(&offsets) {
            for (k, b) in &orbit.members {
                for c in 0..dim {
                    let vj = orbit
                        .values
                        .iter()
                        .position(|&v| v == b[c + 1])
                        .unwrap_or(0);
                    if vj == 0 {
                        for (j, m) in orbit.multiplicity.iter().enumerate().skip(1) {
                            grad[off + j - 1] -= grad_x[*k][c] * m / orbit.multiplicity[0];
                        }
                    } else {
                        grad[off + vj - 1] += grad_x[*k][c];
                    }
                }
            }
        }
        Some((log_det, grad))
    };

    let mut points = set.points.clone();
    let Some((mut f, mut g)) = objective(&params, &mut points) else {
        return start;
    };
    let m = params.len();
    let mut h = DMatrix::<f64>::identity(m, m) * 1e-3; // inverse Hessian estimate
    for _ in 0..400 {
        let gv = DVector::from_column_slice(&g);
        if gv.norm() < 1e-11 {
            break;
        }
        let mut dir = &h * &gv;
        if dir.dot(&gv) <= 0.0 {
            h = DMatrix::identity(m, m) * 1e-3;
            dir = &h * &gv;
        }
        let mut step = 1.0;
        let mut accepted = None;
        for _ in 0..40 {
            let trial: Vec<f64> = params
                .iter()
                .zip(dir.iter())
                .map(|(x, d)| x + step * d)
                .collect();
            if let Some((ft, gt)) = objective(&trial, &mut points) {
                if ft >= f + 1e-4 * step * dir.dot(&gv) {
                    accepted = Some((trial, ft, gt));
                    break;
                }
            }
            step *= 0.5;
        }
        let Some((trial, ft, gt)) = accepted else {
            break;
        };
        let s = DVector::from_iterator(m, trial.iter().zip(&params).map(|(a, b)| a - b));
        let y = DVector::from_iterator(m, g.iter().zip(&gt).map(|(a, b)| a - b)); // −Δ∇(−f)
        let sy = s.dot(&y);
        if sy > 1e-300 {
            // BFGS update of the inverse Hessian of −f.
            let rho = 1.0 / sy;
            let i = DMatrix::<f64>::identity(m, m);
            let a = &i - rho * &s * y.transpose();
            let b = &i - rho * &y * s.transpose();
            h = &a * &h * &b + rho * &s * s.transpose();
        }
        let improvement = ft - f;
        params = trial;
        f = ft;
        g = gt;
        if improvement.abs() < 1e-15 * f.abs().max(1.0) {
            break;
        }
    }
    place(&params, &mut set.points);
    (first_interior..n)
        .map(|k| (set.points[k], set.lattice()[k]))
        .collect()
}

#[cfg(test)]
#[path = "tests/fekete.rs"]
mod tests;
