//! Procedural meshes for hocurve's tests: the unit square and the unit cube cut into
//! structured grids of every element type, with the interior vertices optionally moved by a
//! deterministic pseudo-random amount so that the cells are general (not affine images of one
//! another). One place for them, so that the crates' tests build the same meshes the same
//! way; the meshes (their vertex and cell order included) are part of what the tests check,
//! so a builder changes only with the tests that use it.
//!
//! # Example
//!
//! ```
//! use hocurve_mesh::Shape;
//! use hocurve_nodes::NodeFamily;
//! use hocurve_testmeshes::{high_order, unit_cube, unit_square, Fill, Kuhn};
//! let square = unit_square(4, Shape::Tri, 0.2);
//! assert_eq!((square.vertices.len(), square.cells.len()), (25, 32));
//! // The boundary stays where it is: only interior vertices move.
//! assert_eq!(square.vertices[4], [1.0, 0.0, 0.0]);
//! let cube = unit_cube(2, Fill::Tet(Kuhn::Paired), 0.0);
//! assert_eq!(cube.cells.len(), 48);
//! let mesh = high_order(&cube, 2, NodeFamily::Equispaced);
//! assert_eq!(mesh.nodes.len(), 125); // the 5 × 5 × 5 lattice of the p = 2 nodes
//! ```

use hocurve_mesh::{Element, HighOrderMesh, LinearMesh, Shape};
use hocurve_nodes::NodeFamily;

/// How each small cube of [`unit_cube`] is filled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fill {
    /// Six tetrahedra (Kuhn's subdivision: conforming between neighbouring cubes), listed
    /// as the [`Kuhn`] variant says.
    Tet(Kuhn),
    /// One hexahedron.
    Hex,
    /// Two prisms, split along the diagonal of the bottom face through the cube's corners
    /// (0, 0) and (1, 1).
    Prism,
    /// Hexahedra where x < 1/2, prisms elsewhere.
    HexPrism,
}

/// How Kuhn's six tetrahedra of a cube are listed. Each is the path from the cube's corner
/// (0, 0, 0) to (1, 1, 1) along one edge in each axis direction, one path per order of the
/// axes. Every listing gives the same tetrahedra; their order and vertex order fix the node
/// numbering of the high-order mesh, which tests that perturb nodes by index rely on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kuhn {
    /// Axis orders xyz, yxz, xzy, zxy, yzx, zyx (each pair of first two axes both ways); a
    /// negatively oriented path has its last two vertices swapped.
    Paired,
    /// Axis orders in lexicographic order, xyz, xzy, yxz, yzx, zxy, zyx; a negatively
    /// oriented path has its last two vertices swapped.
    Lexicographic,
    /// Lexicographic, a negatively oriented path has its two middle vertices swapped.
    LexicographicMiddleSwapped,
}

impl Kuhn {
    /// The first two axes of the six paths (the third is the one left), in listing order.
    fn paths(self) -> [(usize, usize); 6] {
        match self {
            Kuhn::Paired => [(0, 1), (1, 0), (0, 2), (2, 0), (1, 2), (2, 1)],
            Kuhn::Lexicographic | Kuhn::LexicographicMiddleSwapped => {
                [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)]
            }
        }
    }

    /// The two local vertices swapped to turn a negatively oriented path positive.
    fn swap(self) -> (usize, usize) {
        match self {
            Kuhn::Paired | Kuhn::Lexicographic => (2, 3),
            Kuhn::LexicographicMiddleSwapped => (1, 2),
        }
    }
}

/// A deterministic move of the interior vertices of a grid of spacing h: vertex (i, j, k)
/// moves along axis d by `amplitude` · h · s(t), where t = w · (i, j, k, d) with the
/// `weights` w and s(t) = 2 fract(43758.5453 sin t) − 1 (a classic shader hash: cheap, and
/// the same on every platform that rounds `sin` the same). [`f64::fract`] keeps the sign,
/// so s lies in (−3, 1), not [−1, 1]: the moves towards the origin reach three times the
/// amplitude. The tests' meshes were made so; kept for them to stay the same.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Perturbation {
    /// Scale of the moves, as a fraction of the grid spacing: they lie in
    /// (−3, 1) · `amplitude` · h along each axis.
    pub amplitude: f64,
    /// Weights of i, j, k and the axis in the hash's argument.
    pub weights: [f64; 4],
}

impl Perturbation {
    /// The weights of [`Perturbation::new`].
    pub const DEFAULT_WEIGHTS: [f64; 4] = [12.9898, 78.233, 37.719, 4.1];

    /// Moves of scale `amplitude` · h with the default weights.
    pub fn new(amplitude: f64) -> Self {
        Perturbation {
            amplitude,
            weights: Self::DEFAULT_WEIGHTS,
        }
    }

    /// The move of grid vertex `index` along `axis`, in units of the grid spacing `h`.
    fn offset(&self, index: [usize; 3], axis: usize, h: f64) -> f64 {
        let [i, j, k] = index;
        let w = self.weights;
        let t = i as f64 * w[0] + j as f64 * w[1] + k as f64 * w[2] + axis as f64 * w[3];
        self.amplitude * h * ((t.sin() * 43758.5453).fract() * 2.0 - 1.0)
    }
}

impl From<f64> for Perturbation {
    fn from(amplitude: f64) -> Self {
        Perturbation::new(amplitude)
    }
}

/// The unit square as n × n quadrilaterals (`kind` [`Shape::Quad`]) or 2n² triangles
/// (`kind` [`Shape::Tri`]: each square cut along its diagonal from (0, 0) to (1, 1)),
/// counter-clockwise, entity 1, no facets. Vertex (i, j) is number i + (n + 1) j; interior
/// vertices are moved by `perturb` (an amplitude, or a [`Perturbation`]).
///
/// # Panics
///
/// If `kind` is not a triangle or a quadrilateral.
pub fn unit_square(n: usize, kind: Shape, perturb: impl Into<Perturbation>) -> LinearMesh {
    assert!(
        matches!(kind, Shape::Tri | Shape::Quad),
        "the unit square is made of triangles or quadrilaterals, not {kind}"
    );
    let perturb = perturb.into();
    let h = 1.0 / n as f64;
    let id = |i: usize, j: usize| (i + (n + 1) * j) as u32;
    let mut vertices = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let mut x = [i as f64 * h, j as f64 * h, 0.0];
            if i > 0 && i < n && j > 0 && j < n {
                for d in 0..2 {
                    x[d] += perturb.offset([i, j, 0], d, h);
                }
            }
            vertices.push(x);
        }
    }
    let mut cells = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let lists = if kind == Shape::Quad {
                vec![vec![a, b, c, d]]
            } else {
                vec![vec![a, b, c], vec![a, c, d]]
            };
            cells.extend(lists.into_iter().map(|vertices| cell(kind, vertices)));
        }
    }
    LinearMesh {
        dim: 2,
        vertices,
        cells,
        ..Default::default()
    }
}

/// The unit cube as n³ small cubes filled as `fill` says, positively oriented, entity 1, no
/// facets. Vertex (i, j, k) is number i + (n + 1)(j + (n + 1) k); interior vertices are moved
/// by `perturb` (an amplitude, or a [`Perturbation`]) before the tetrahedra are oriented.
pub fn unit_cube(n: usize, fill: Fill, perturb: impl Into<Perturbation>) -> LinearMesh {
    let perturb = perturb.into();
    let h = 1.0 / n as f64;
    let id = |i: usize, j: usize, k: usize| (i + (n + 1) * (j + (n + 1) * k)) as u32;
    let mut vertices = Vec::with_capacity((n + 1).pow(3));
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let mut x = [i as f64 * h, j as f64 * h, k as f64 * h];
                if [i, j, k].iter().all(|&t| t > 0 && t < n) {
                    for d in 0..3 {
                        x[d] += perturb.offset([i, j, k], d, h);
                    }
                }
                vertices.push(x);
            }
        }
    }
    let mut cells = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                // The small cube's corner whose bits are its (x, y, z) offsets.
                let v = |bits: usize| id(i + (bits & 1), j + ((bits >> 1) & 1), k + (bits >> 2));
                let hex = || {
                    cell(
                        Shape::Hex,
                        vec![v(0), v(1), v(3), v(2), v(4), v(5), v(7), v(6)],
                    )
                };
                let prisms = [
                    [v(0), v(1), v(3), v(4), v(5), v(7)],
                    [v(0), v(3), v(2), v(4), v(7), v(6)],
                ];
                match fill {
                    Fill::Tet(kuhn) => {
                        for (a, b) in kuhn.paths() {
                            let (a, b) = (1 << a, 1 << b);
                            let mut tet = vec![v(0), v(a), v(a | b), v(7)];
                            if signed_volume(&vertices, &tet) < 0.0 {
                                let (a, b) = kuhn.swap();
                                tet.swap(a, b);
                            }
                            cells.push(cell(Shape::Tet, tet));
                        }
                    }
                    Fill::Hex => cells.push(hex()),
                    Fill::HexPrism if 2 * i < n => cells.push(hex()),
                    Fill::Prism | Fill::HexPrism => {
                        cells.extend(prisms.iter().map(|p| cell(Shape::Prism, p.to_vec())))
                    }
                }
            }
        }
    }
    LinearMesh {
        dim: 3,
        vertices,
        cells,
        ..Default::default()
    }
}

/// The reference tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) as one cell, no facets
/// declared; vertices are appended and cells pushed by tests that need more.
pub fn unit_tet() -> LinearMesh {
    LinearMesh {
        dim: 3,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        cells: vec![cell(Shape::Tet, vec![0, 1, 2, 3])],
        ..Default::default()
    }
}

/// The straight-sided order-`order` mesh of `mesh` on `family` nodes.
///
/// # Panics
///
/// If `mesh` is not a valid, positively oriented mesh (a bug in the test).
pub fn high_order(mesh: &LinearMesh, order: usize, family: NodeFamily) -> HighOrderMesh {
    match HighOrderMesh::from_linear(mesh, order, family) {
        Ok(mesh) => mesh,
        Err(e) => panic!("the test mesh is not valid: {e}"),
    }
}

fn cell(kind: Shape, vertices: Vec<u32>) -> Element {
    Element {
        kind,
        vertices,
        entity: 1,
    }
}

/// Six times the signed volume of the tetrahedron `tet` (vertex ids into `vertices`).
fn signed_volume(vertices: &[[f64; 3]], tet: &[u32]) -> f64 {
    let p = |k: usize| vertices[tet[k] as usize];
    let e = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let (u, w, z) = (e(p(1), p(0)), e(p(2), p(0)), e(p(3), p(0)));
    u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0])
        + u[2] * (w[0] * z[1] - w[1] * z[0])
}

#[cfg(test)]
mod tests;
