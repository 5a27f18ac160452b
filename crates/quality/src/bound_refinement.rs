//! Narrowing the certified interval of an element's scaled Jacobian by best-first
//! subdivision of det J's Bernstein form.
//!
//! The validity check stops refining as soon as every coefficient is positive, so the bound
//! it certifies, min c / max c over its regions, can sit far below the true
//! Ĩ = min det J / max det J of a stretched element (for example 0.016 against 0.39 sampled on
//! a boundary-layer tetrahedron). Subdividing converges to the truth — the coefficients of a
//! region of size h differ from the polynomial's values by O(h²) — so here the region holding
//! the smallest coefficient (or the largest, whichever end of the interval is further from
//! the sampled values) is split, repeatedly, until the certified ratio reaches a target or a
//! budget of regions is spent. Boxes and prisms split by [`crate::BernsteinSubdivision`];
//! triangles and tetrahedra by [`SimplexBisection`] of the region's longest edge, exact de
//! Casteljau steps on the coefficients (no re-sampling of det J).

use crate::bernstein::BernsteinSpace;
use crate::jacobian::min_max;

/// Exact bisection of a simplex's Bernstein form across one edge.
///
/// Splitting the edge (vᵢ, vⱼ) at its midpoint m gives child A (vⱼ replaced by m) and child
/// B (vᵢ replaced by m). Along every line of multi-indices with the other exponents fixed and
/// αᵢ + αⱼ = s, the coefficients (ordered by αⱼ = 0..s) are a degree-s Bernstein polynomial in
/// t = λⱼ/(λᵢ + λⱼ), and A and B are its halves t ∈ [0, ½] and [½, 1]: one de Casteljau
/// triangle at ½ per line gives both (A_k = b⁽ᵏ⁾₀, B_k = b⁽ˢ⁻ᵏ⁾_k). Each step averages, so a
/// bisection adds at most s ε max|c| of rounding.
#[derive(Debug, Clone)]
pub(crate) struct SimplexBisection {
    degree: usize,
    /// Barycentric exponents (α₀, …, α_d) of each coefficient, in storage order.
    exponents: Vec<[usize; 4]>,
    /// Storage position of (α₁, α₂, α₃) at α₁ + (n + 1)(α₂ + (n + 1) α₃).
    position: Vec<u32>,
    /// Storage positions of the vertex coefficients, vertex 0 first.
    vertices: Vec<usize>,
    /// Number of vertices (d + 1).
    corners: usize,
}

impl SimplexBisection {
    /// The bisection of `space`, a triangle or tetrahedron space (None for other shapes).
    pub(crate) fn new(space: &BernsteinSpace) -> Option<SimplexBisection> {
        let corners = match space.shape() {
            hocurve_nodes::Shape::Tri => 3,
            hocurve_nodes::Shape::Tet => 4,
            _ => return None,
        };
        let n = space.degree();
        let side = n + 1;
        let exponents: Vec<[usize; 4]> = space
            .exponents()
            .iter()
            .map(|e| [e[0] as usize, e[1] as usize, e[2] as usize, e[3] as usize])
            .collect();
        let mut position = vec![u32::MAX; side * side * side];
        for (at, e) in exponents.iter().enumerate() {
            position[e[1] + side * (e[2] + side * e[3])] = at as u32;
        }
        let vertices = (0..corners)
            .map(|v| exponents.iter().position(|e| e[v] == n))
            .collect::<Option<Vec<usize>>>()?;
        Some(SimplexBisection {
            degree: n,
            exponents,
            position,
            vertices,
            corners,
        })
    }

    /// Storage position of the multi-index `alpha`.
    fn index(&self, alpha: &[usize; 4]) -> usize {
        let side = self.degree + 1;
        self.position[alpha[1] + side * (alpha[2] + side * alpha[3])] as usize
    }

    /// Storage positions of the vertex coefficients.
    pub(crate) fn vertices(&self) -> &[usize] {
        &self.vertices
    }

    /// Number of vertices of the simplex.
    pub(crate) fn corners(&self) -> usize {
        self.corners
    }

    /// The degree.
    pub(crate) fn degree(&self) -> usize {
        self.degree
    }

    /// The coefficients of children A and B of the bisection of edge (`i`, `j`).
    pub(crate) fn bisect(
        &self,
        c: &[f64],
        (i, j): (usize, usize),
        a: &mut Vec<f64>,
        b: &mut Vec<f64>,
        line: &mut Vec<f64>,
    ) {
        a.clear();
        a.resize(c.len(), 0.0);
        b.clear();
        b.resize(c.len(), 0.0);
        for start in self.exponents.iter().filter(|e| e[j] == 0) {
            let s = start[i];
            let at = |k: usize| {
                let mut alpha = *start;
                alpha[i] = s - k;
                alpha[j] = k;
                self.index(&alpha)
            };
            line.clear();
            line.extend((0..=s).map(|k| c[at(k)]));
            a[at(0)] = line[0];
            b[at(s)] = line[s];
            for r in 1..=s {
                for k in 0..=s - r {
                    line[k] = 0.5 * (line[k] + line[k + 1]);
                }
                a[at(r)] = line[0];
                b[at(s - r)] = line[s - r];
            }
        }
    }
}

/// One region of the refinement: its coefficients, their extremes, the rounding bound the
/// subdivisions added, and (simplices) its vertices in reference coordinates.
#[derive(Debug, Clone)]
pub(crate) struct Region {
    pub(crate) c: Vec<f64>,
    pub(crate) min: f64,
    pub(crate) max: f64,
    pub(crate) error: f64,
    pub(crate) corners: [[f64; 3]; 4],
}

impl Region {
    pub(crate) fn new(c: Vec<f64>, error: f64, corners: [[f64; 3]; 4]) -> Region {
        let (min, max) = min_max(&c);
        Region {
            c,
            min,
            max,
            error,
            corners,
        }
    }

    /// The longest edge of a simplex region with `n` corners (lowest pair on ties).
    pub(crate) fn longest_edge(&self, n: usize) -> (usize, usize) {
        let mut best = (0, 1);
        let mut longest = -1.0;
        for i in 0..n {
            for j in i + 1..n {
                let d: f64 = (0..3)
                    .map(|k| (self.corners[i][k] - self.corners[j][k]).powi(2))
                    .sum();
                if d > longest {
                    longest = d;
                    best = (i, j);
                }
            }
        }
        best
    }
}

/// The certified interval [lower, upper] of det J over `regions` (each widened by its
/// rounding), and the positions of the regions holding the ends.
pub(crate) fn extremes(regions: &[Region]) -> ((f64, usize), (f64, usize)) {
    let mut lower = (f64::INFINITY, 0);
    let mut upper = (f64::NEG_INFINITY, 0);
    for (r, region) in regions.iter().enumerate() {
        if region.min - region.error < lower.0 {
            lower = (region.min - region.error, r);
        }
        if region.max + region.error > upper.0 {
            upper = (region.max + region.error, r);
        }
    }
    (lower, upper)
}

#[cfg(test)]
#[path = "tests/bound_refinement.rs"]
mod tests;
