//! Exact subdivision of a polynomial in Bernstein form into the children of one midpoint
//! refinement (what the validity check of [`crate::JacobianBezier`] recurses with), built by
//! [`crate::BernsteinSpace::subdivision`].

use crate::bernstein::apply_along_axis;

/// Exact subdivision of the Bernstein form on the shapes with a product structure
/// (quadrilateral, hexahedron, prism): the coefficients of f∘A on each child A of one
/// refinement, from those of f, without sampling. Each child's map is a product of one
/// sub-element per factor (a half of [0, 1]; one of the 4 midpoint triangles), so its
/// subdivision matrix is the Kronecker product of one matrix per factor, applied one factor
/// at a time like the conversion. The factor matrices come from the blossom (de Casteljau
/// with the child's vertices as arguments): their entries are non-negative, each row sums
/// to 1, and with midpoint children they are dyadic rationals times binomials, exact in
/// f64 at the degrees allowed here, so a subdivision adds rounding of at most (m ε) · max|c|
/// per factor of length m and never amplifies errors.
#[derive(Debug, Clone)]
pub struct BernsteinSubdivision {
    /// Per child: per factor, (storage axis, row-major m×m matrix index into `matrices`).
    pub(crate) children: Vec<Vec<(usize, usize)>>,
    pub(crate) matrices: Vec<Vec<f64>>,
    pub(crate) dims: [usize; 3],
    /// Storage positions of the coefficients at the vertices (the values there).
    pub(crate) vertices: Vec<usize>,
}

impl BernsteinSubdivision {
    /// Number of children of one refinement.
    pub fn len(&self) -> usize {
        self.children.len()
    }

    /// Never true.
    pub fn is_empty(&self) -> bool {
        self.children.is_empty()
    }

    /// Storage positions of the vertex coefficients (the polynomial's values there).
    pub fn vertices(&self) -> &[usize] {
        &self.vertices
    }

    /// The longest factor (m in the rounding bound m ε max|c| per factor).
    pub fn longest_factor(&self) -> usize {
        self.dims.iter().copied().max().unwrap_or(1)
    }

    /// Number of factors applied per subdivision.
    pub fn factors(&self) -> usize {
        self.children.first().map_or(0, Vec::len)
    }

    /// The coefficients of child `child` into `out`, from the parent's `coefficients`
    /// (`tmp` is scratch memory).
    pub fn child(
        &self,
        child: usize,
        coefficients: &[f64],
        out: &mut Vec<f64>,
        tmp: &mut Vec<f64>,
    ) {
        out.clear();
        out.extend_from_slice(coefficients);
        for &(axis, matrix) in &self.children[child] {
            apply_along_axis(&self.matrices[matrix], self.dims, axis, out, tmp);
        }
    }
}

/// The row-major matrix S with d = S c, where c are the Bernstein coefficients (degree n,
/// multi-indices `exponents` over 2 or 3 barycentric coordinates, the third 0 for a line)
/// of f and d those of f on the sub-simplex with barycentric vertices `w`:
/// d_β = blossom(w₀^β₀, w₁^β₁, w₂^β₂), computed by de Casteljau steps on each unit c.
pub(crate) fn subdivision_matrix(
    exponents: &[Vec<usize>],
    n: usize,
    w: &[[f64; 3]; 3],
) -> Vec<f64> {
    let m = exponents.len();
    let mut s = vec![0.0; m * m];
    // A net of total degree r stored as net[b · (n + 1) + c] (a = r − b − c).
    let side = n + 1;
    let mut net = vec![0.0; side * side];
    let mut next = vec![0.0; side * side];
    for (col, alpha) in exponents.iter().enumerate() {
        for (row, beta) in exponents.iter().enumerate() {
            net.fill(0.0);
            net[alpha[1] * side + alpha[2]] = 1.0;
            let mut r = n;
            for (k, &count) in beta.iter().enumerate() {
                let u = w[k];
                for _ in 0..count {
                    // One de Casteljau step with argument u: degree r → r − 1.
                    for b in 0..r {
                        for c in 0..r - b {
                            next[b * side + c] = u[0] * net[b * side + c]
                                + u[1] * net[(b + 1) * side + c]
                                + u[2] * net[b * side + c + 1];
                        }
                    }
                    std::mem::swap(&mut net, &mut next);
                    r -= 1;
                }
            }
            s[row * m + col] = net[0];
        }
    }
    s
}
