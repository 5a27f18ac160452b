//! Closed-form near-optimal nodes on the simplex: Warburton's warp & blend construction
//! (T. Warburton, J Eng Math 56 (2006); Hesthaven & Warburton, Nodal DG Methods, Sect. 6.1
//! and 10.1), and the Blyth–Pozrikidis formula (IMA J Appl Math 71 (2006)) from 1D
//! Gauss–Lobatto points.
//!
//! Both start from the equispaced lattice and move each point, so every node keeps its
//! lattice index. Only interior nodes are produced here: edges and faces of an element take
//! the 1D and triangle sets of the same family (see [`crate::ReferenceNodes`]).

use crate::gauss::gauss_lobatto_legendre;

/// The p + 1 Gauss–Lobatto–Legendre points mapped to [0, 1], ascending, exactly symmetric.
pub(crate) fn gll_unit(p: usize) -> Vec<f64> {
    let rule = gauss_lobatto_legendre(p + 1);
    let mut x: Vec<f64> = rule.points.iter().map(|r| 0.5 * (1.0 + r)).collect();
    // Exact symmetry x_i + x_{p−i} = 1 and exact end points.
    for i in 0..=p / 2 {
        let s = 0.5 * (x[i] + 1.0 - x[p - i]);
        x[i] = s;
        x[p - i] = 1.0 - s;
    }
    x[0] = 0.0;
    x[p] = 1.0;
    x
}

/// Warburton's optimised blending exponents α for the triangle, p = 1..=15 (Hesthaven &
/// Warburton, Table 6.1); 5/3 beyond.
const ALPHA_TRI: [f64; 15] = [
    0.0, 0.0, 1.4152, 0.1001, 0.2751, 0.9800, 1.0999, 1.2832, 1.3648, 1.4773, 1.4959, 1.5743,
    1.5770, 1.6223, 1.6258,
];

/// Warburton's optimised α for the tetrahedron, p = 1..=15 (Hesthaven & Warburton,
/// Table 10.1); 1 beyond.
const ALPHA_TET: [f64; 15] = [
    0.0, 0.0, 0.0, 0.1002, 1.1332, 1.5608, 1.3413, 1.2577, 1.1603, 1.10153, 0.6080, 0.4523, 0.8856,
    0.8717, 0.9655,
];

/// The 1D warp w(r) = Σᵢ (gᵢ − eᵢ) ℓᵢ(r) / (1 − r²) on [−1, 1]: the displacement from
/// equispaced points eᵢ to GLL points gᵢ, interpolated, divided by the edge bubble so that
/// the blend can multiply it back (H&W Eq. (6.8)). Zero at r = ±1.
struct Warp {
    equispaced: Vec<f64>,
    displacement: Vec<f64>,
}

impl Warp {
    fn new(p: usize) -> Self {
        let gll = gll_unit(p);
        let equispaced: Vec<f64> = (0..=p).map(|i| -1.0 + 2.0 * i as f64 / p as f64).collect();
        let displacement = (0..=p)
            .map(|i| (2.0 * gll[i] - 1.0) - equispaced[i])
            .collect();
        Warp {
            equispaced,
            displacement,
        }
    }

    fn at(&self, r: f64) -> f64 {
        if r.abs() >= 1.0 - 1e-10 {
            return 0.0;
        }
        let e = &self.equispaced;
        let mut w = 0.0;
        for (i, d) in self.displacement.iter().enumerate() {
            if *d == 0.0 {
                continue;
            }
            let mut l = 1.0;
            for (j, ej) in e.iter().enumerate() {
                if j != i {
                    l *= (r - ej) / (e[i] - ej);
                }
            }
            w += d * l;
        }
        w / (1.0 - r * r)
    }

    /// The 2D warp of a point with barycentric coordinates (l1, l2, l3) in the equilateral
    /// triangle whose vertex 1 is at the top, 2 at the left, 3 at the right (H&W Eq. (6.9)):
    /// the displacement (dx, dy) in that triangle's frame.
    fn triangle_shift(&self, alpha: f64, l: [f64; 3]) -> [f64; 2] {
        let [l1, l2, l3] = l;
        let w1 = 4.0 * l2 * l3 * self.at(l3 - l2) * (1.0 + (alpha * l1).powi(2));
        let w2 = 4.0 * l1 * l3 * self.at(l1 - l3) * (1.0 + (alpha * l2).powi(2));
        let w3 = 4.0 * l1 * l2 * self.at(l2 - l1) * (1.0 + (alpha * l3).powi(2));
        let (c2, s2) = (
            (2.0 * std::f64::consts::PI / 3.0).cos(),
            (2.0 * std::f64::consts::PI / 3.0).sin(),
        );
        let (c3, s3) = (
            (4.0 * std::f64::consts::PI / 3.0).cos(),
            (4.0 * std::f64::consts::PI / 3.0).sin(),
        );
        [w1 + c2 * w2 + c3 * w3, s2 * w2 + s3 * w3]
    }
}

/// Warp & blend position of triangle lattice point (i, j) (ξ = i/p, η = j/p before warping),
/// in our reference triangle.
pub(crate) fn warp_blend_triangle(p: usize, lattice: [i64; 2]) -> [f64; 2] {
    let alpha = ALPHA_TRI
        .get(p.wrapping_sub(1))
        .copied()
        .unwrap_or(5.0 / 3.0);
    let pf = p as f64;
    // Barycentrics of our vertices v0 = (0,0), v1 = (1,0), v2 = (0,1); the equilateral frame
    // puts v2 at the top, v0 left, v1 right.
    let (l1, l2) = (lattice[0] as f64 / pf, lattice[1] as f64 / pf);
    let l0 = 1.0 - l1 - l2;
    let s3 = 3f64.sqrt();
    let x = -l0 + l1;
    let y = (2.0 * l2 - l0 - l1) / s3;
    let [dx, dy] = Warp::new(p).triangle_shift(alpha, [l2, l0, l1]);
    let (x, y) = (x + dx, y + dy);
    // Back to barycentrics (top, left, right) = (v2, v0, v1).
    let top = (s3 * y + 1.0) / 3.0;
    let right = (3.0 * x - s3 * y + 2.0) / 6.0;
    [right, top]
}

/// Warp & blend position of tetrahedron lattice point (i, j, k), interior points only
/// (H&W Sect. 10.1: each face's 2D warp, blended into the volume).
pub(crate) fn warp_blend_tet(p: usize, lattice: [i64; 3]) -> [f64; 3] {
    let alpha = ALPHA_TET.get(p.wrapping_sub(1)).copied().unwrap_or(1.0);
    let pf = p as f64;
    let l = [
        1.0 - (lattice[0] + lattice[1] + lattice[2]) as f64 / pf,
        lattice[0] as f64 / pf,
        lattice[1] as f64 / pf,
        lattice[2] as f64 / pf,
    ];
    let (s3, s6) = (3f64.sqrt(), 6f64.sqrt());
    let v = [
        [-1.0, -1.0 / s3, -1.0 / s6],
        [1.0, -1.0 / s3, -1.0 / s6],
        [0.0, 2.0 / s3, -1.0 / s6],
        [0.0, 0.0, 3.0 / s6],
    ];
    let mut x = [0.0; 3];
    for k in 0..4 {
        for d in 0..3 {
            x[d] += l[k] * v[k][d];
        }
    }
    let warp = Warp::new(p);
    for a in 0..4 {
        // The face opposite vertex a, with its own equilateral frame: vertex b on top,
        // c left, d right.
        let [b, c, d] = match a {
            0 => [3, 1, 2],
            1 => [3, 0, 2],
            2 => [3, 0, 1],
            _ => [2, 0, 1],
        };
        let unit = |w: [f64; 3]| {
            let n = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            [w[0] / n, w[1] / n, w[2] / n]
        };
        let t1 = unit([v[d][0] - v[c][0], v[d][1] - v[c][1], v[d][2] - v[c][2]]);
        let t2 = unit([
            v[b][0] - 0.5 * (v[c][0] + v[d][0]),
            v[b][1] - 0.5 * (v[c][1] + v[d][1]),
            v[b][2] - 0.5 * (v[c][2] + v[d][2]),
        ]);
        let [w1, w2] = warp.triangle_shift(alpha, [l[b], l[c], l[d]]);
        let la = l[a];
        let denom = (l[b] + 0.5 * la) * (l[c] + 0.5 * la) * (l[d] + 0.5 * la);
        let blend = if denom > 1e-10 {
            (1.0 + (alpha * la).powi(2)) * l[b] * l[c] * l[d] / denom
        } else {
            l[b] * l[c] * l[d]
        };
        for k in 0..3 {
            x[k] += blend * (w1 * t1[k] + w2 * t2[k]);
        }
    }
    // Back to barycentrics: solve x − v0 = Σ_{k≥1} μ_k (v_k − v0).
    let m = [
        [v[1][0] - v[0][0], v[2][0] - v[0][0], v[3][0] - v[0][0]],
        [v[1][1] - v[0][1], v[2][1] - v[0][1], v[3][1] - v[0][1]],
        [v[1][2] - v[0][2], v[2][2] - v[0][2], v[3][2] - v[0][2]],
    ];
    let rhs = [x[0] - v[0][0], x[1] - v[0][1], x[2] - v[0][2]];
    solve3(m, rhs)
}

/// Blyth–Pozrikidis triangle node: barycentric λ_a = (1 + 2v_a − v_b − v_c)/3 from the 1D
/// GLL points v on [0, 1] indexed by the lattice's barycentric indices.
pub(crate) fn blyth_pozrikidis_triangle(p: usize, lattice: [i64; 2]) -> [f64; 2] {
    let v = gll_unit(p);
    let idx = [p as i64 - lattice[0] - lattice[1], lattice[0], lattice[1]];
    let g = idx.map(|i| v[i as usize]);
    let lam = |a: usize, b: usize, c: usize| (1.0 + 2.0 * g[a] - g[b] - g[c]) / 3.0;
    [lam(1, 2, 0), lam(2, 0, 1)]
}

/// The tetrahedral analogue λ_a = (1 + 3v_a − Σ_{b≠a} v_b)/4, used for interior nodes only
/// (faces take the triangle formula).
pub(crate) fn blyth_pozrikidis_tet(p: usize, lattice: [i64; 3]) -> [f64; 3] {
    let v = gll_unit(p);
    let idx = [
        p as i64 - lattice[0] - lattice[1] - lattice[2],
        lattice[0],
        lattice[1],
        lattice[2],
    ];
    let g = idx.map(|i| v[i as usize]);
    let total: f64 = g.iter().sum();
    let lam = |a: usize| (1.0 + 4.0 * g[a] - total) / 4.0;
    [lam(1), lam(2), lam(3)]
}

/// Solves a 3×3 system by Cramer's rule (well conditioned here: an equilateral tet).
fn solve3(m: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(m);
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        let mut mk = m;
        for r in 0..3 {
            mk[r][k] = b[r];
        }
        *o = det(mk) / d;
    }
    out
}

#[cfg(test)]
#[path = "tests/warp_blend.rs"]
mod tests;
