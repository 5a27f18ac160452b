//! Jacobian determinants of the isoparametric map and the scaled Jacobian of the paper's
//! Eq. (8).
//!
//! An order-p element with nodes xᵢ maps the reference element by x(ξ) = Σᵢ xᵢ Φᵢ(ξ), so its
//! Jacobian is J(ξ) = Σᵢ xᵢ ⊗ ∇Φᵢ(ξ). The gradients ∇Φᵢ at the sample points depend only on
//! (shape, order, node family); a [`JacobianSampler`] computes them once, after which each
//! element costs one small matrix product (coordinates × gradients) and a determinant per
//! point, with no allocation. In 2D the determinant is that of the 2×2 map of (x, y).

use std::collections::BTreeMap;

use hocurve_mesh::{HighOrderElement, HighOrderMesh};
use hocurve_nodes::{LagrangeBasis, NodeFamily, QuadratureRule, ReferenceNodes, Shape};
use rayon::prelude::*;

use crate::QualityError;

/// Where det J is sampled to compute the scaled Jacobian.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Sampling {
    /// The points of the degree-2p quadrature rule of the shape (the paper's choice). The
    /// points are interior, so a minimum at a vertex or on an edge is missed.
    #[default]
    Quadrature,
    /// The element's own nodes (vertices, edges, faces, interior).
    Nodes,
    /// Both sets: never larger than either alone.
    Both,
}

/// Gradients of the Lagrange basis of one (shape, order, family) at a fixed set of reference
/// points, laid out so that the Jacobians of an element at all points are one axpy-friendly
/// product.
#[derive(Debug, Clone)]
pub struct JacobianSampler {
    shape: Shape,
    order: usize,
    family: NodeFamily,
    points: Vec<[f64; 3]>,
    num_nodes: usize,
    /// `gradients[i · dim·Q + q · dim + k] = ∂Φᵢ/∂ξₖ (points[q])`: for node i the row of all
    /// points and directions is contiguous, so J accumulates as x_i[d] · row (vectorisable).
    gradients: Vec<f64>,
}

/// Scratch memory for [`JacobianSampler::determinants_with`]; reuse one per thread.
#[derive(Debug, Clone, Default)]
pub struct JacobianWorkspace {
    coords: Vec<[f64; 3]>,
    jacobians: Vec<f64>,
    determinants: Vec<f64>,
}

impl JacobianSampler {
    /// The sampler of `sampling` for order-`order` elements of `shape` whose nodes are the
    /// `family` set.
    pub fn new(
        shape: Shape,
        order: usize,
        family: NodeFamily,
        sampling: Sampling,
    ) -> Result<Self, QualityError> {
        let mut points = Vec::new();
        if matches!(sampling, Sampling::Quadrature | Sampling::Both) {
            points.extend(QuadratureRule::new(shape, 2 * order).points);
        }
        if matches!(sampling, Sampling::Nodes | Sampling::Both) {
            points.extend_from_slice(ReferenceNodes::try_new(shape, order, family)?.points());
        }
        Self::at_points(shape, order, family, &points)
    }

    /// The sampler at arbitrary reference `points` (e.g. to compare with another code's
    /// Jacobians at its own points).
    pub fn at_points(
        shape: Shape,
        order: usize,
        family: NodeFamily,
        points: &[[f64; 3]],
    ) -> Result<Self, QualityError> {
        let basis = LagrangeBasis::new(&ReferenceNodes::try_new(shape, order, family)?)?;
        let derivatives = basis.gradient_matrices(points);
        let (n, q, dim) = (basis.len(), points.len(), shape.dim());
        let mut gradients = vec![0.0; n * dim * q];
        for i in 0..n {
            for p in 0..q {
                for k in 0..dim {
                    gradients[i * dim * q + p * dim + k] = derivatives[k][(p, i)];
                }
            }
        }
        Ok(JacobianSampler {
            shape,
            order,
            family,
            points: points.to_vec(),
            num_nodes: n,
            gradients,
        })
    }

    /// The shape.
    pub fn shape(&self) -> Shape {
        self.shape
    }

    /// The polynomial order p.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The node family.
    pub fn family(&self) -> NodeFamily {
        self.family
    }

    /// The sample points (reference coordinates).
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Number of nodes of an element (length of the coordinate list it expects).
    pub fn num_nodes(&self) -> usize {
        self.num_nodes
    }

    /// det J(ξ_q) for every sample point q of the element whose node coordinates are
    /// `coords` (canonical local order). Allocates only while `workspace` grows.
    pub fn determinants_with<'w>(
        &self,
        coords: &[[f64; 3]],
        workspace: &'w mut JacobianWorkspace,
    ) -> &'w [f64] {
        let dim = self.shape.dim();
        let q = self.points.len();
        let row = dim * q;
        let jac = &mut workspace.jacobians;
        jac.clear();
        jac.resize(dim * row, 0.0);
        // J[d][k] at point p lives at jac[d·row + p·dim + k].
        for (i, x) in coords.iter().enumerate().take(self.num_nodes) {
            let g = &self.gradients[i * row..(i + 1) * row];
            for d in 0..dim {
                let xd = x[d];
                for (j, gj) in jac[d * row..(d + 1) * row].iter_mut().zip(g) {
                    *j += xd * gj;
                }
            }
        }
        let out = &mut workspace.determinants;
        out.clear();
        out.extend((0..q).map(|p| {
            let at = |d: usize, k: usize| jac[d * row + p * dim + k];
            if dim == 2 {
                at(0, 0) * at(1, 1) - at(0, 1) * at(1, 0)
            } else {
                at(0, 0) * (at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1))
                    - at(0, 1) * (at(1, 0) * at(2, 2) - at(1, 2) * at(2, 0))
                    + at(0, 2) * (at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0))
            }
        }));
        out
    }

    /// det J at every sample point (allocating convenience form of
    /// [`JacobianSampler::determinants_with`]).
    pub fn determinants(&self, coords: &[[f64; 3]]) -> Vec<f64> {
        let mut workspace = JacobianWorkspace::default();
        self.determinants_with(coords, &mut workspace).to_vec()
    }

    /// (min, max) of det J over the sample points.
    pub fn min_max_with(
        &self,
        coords: &[[f64; 3]],
        workspace: &mut JacobianWorkspace,
    ) -> (f64, f64) {
        min_max(self.determinants_with(coords, workspace))
    }

    /// The scaled Jacobian Ĩ = min det J / |max det J| over the sample points (see
    /// [`scaled_ratio`]).
    pub fn scaled_jacobian_with(
        &self,
        coords: &[[f64; 3]],
        workspace: &mut JacobianWorkspace,
    ) -> f64 {
        let (min, max) = self.min_max_with(coords, workspace);
        scaled_ratio(min, max)
    }
}

/// (min, max) of a list; NaN entries make both NaN so that they cannot pass as valid.
pub(crate) fn min_max(values: &[f64]) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &v in values {
        if v.is_nan() {
            return (f64::NAN, f64::NAN);
        }
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (lo, hi)
}

/// Ĩ = min / |max| (the paper's Eq. (8) in its signed form: negative means inverted
/// somewhere). When the ratio is not finite — max det J = 0, or non-finite coordinates — the
/// element is degenerate and the result is −1 if some det J is negative, else 0, so that it
/// always counts as invalid (Ĩ ≤ 0) and stays a finite number in reports.
pub fn scaled_ratio(min: f64, max: f64) -> f64 {
    let ratio = min / max.abs();
    if ratio.is_finite() {
        ratio
    } else if min < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Checks every cell of `mesh` (supported shape of the mesh's dimension, node count of a
/// complete order-p element, node ids in range) and returns the set of shapes present.
pub(crate) fn check_cells(mesh: &HighOrderMesh) -> Result<Vec<Shape>, QualityError> {
    let mut shapes = Vec::new();
    let count = mesh.nodes.len();
    for (element, cell) in mesh.cells.iter().enumerate() {
        let shape = cell_shape(element, cell)?;
        if shape.dim() != mesh.dim {
            return Err(QualityError::WrongDimension {
                element,
                shape,
                dim: mesh.dim,
            });
        }
        let expected = shape.num_nodes(mesh.order);
        if cell.nodes.len() != expected {
            return Err(QualityError::WrongNodeCount {
                element,
                shape,
                order: mesh.order,
                expected,
                found: cell.nodes.len(),
            });
        }
        if let Some(&node) = cell.nodes.iter().find(|&&n| n as usize >= count) {
            return Err(QualityError::NodeOutOfRange {
                element,
                node: node as usize,
                count,
            });
        }
        if !shapes.contains(&shape) {
            shapes.push(shape);
        }
    }
    shapes.sort();
    Ok(shapes)
}

/// The reference shape of a cell, or a clear error for pyramids.
pub(crate) fn cell_shape(element: usize, cell: &HighOrderElement) -> Result<Shape, QualityError> {
    cell.kind
        .shape()
        .map_err(|_| QualityError::UnsupportedElement {
            element,
            kind: cell.kind,
        })
}

/// Copies the node coordinates of `cell` into `coords` (canonical local order), relative to
/// its first node: J is unchanged (Σᵢ ∇Φᵢ = 0) and the sums lose no digits to a mesh far from
/// the origin.
pub(crate) fn gather(mesh: &HighOrderMesh, cell: &HighOrderElement, coords: &mut Vec<[f64; 3]>) {
    coords.clear();
    let Some(&first) = cell.nodes.first() else {
        return;
    };
    let o = mesh.nodes[first as usize];
    coords.extend(cell.nodes.iter().map(|&n| {
        let x = mesh.nodes[n as usize];
        [x[0] - o[0], x[1] - o[1], x[2] - o[2]]
    }));
}

/// One sampler per shape present in a mesh.
pub(crate) fn samplers(
    mesh: &HighOrderMesh,
    shapes: &[Shape],
    sampling: Sampling,
) -> Result<BTreeMap<Shape, JacobianSampler>, QualityError> {
    shapes
        .iter()
        .map(|&s| {
            Ok((
                s,
                JacobianSampler::new(s, mesh.order, mesh.family, sampling)?,
            ))
        })
        .collect()
}

/// The scaled Jacobian Ĩ = min det J / |max det J| of every cell (Vec indexed like
/// `mesh.cells`), det J sampled at the points chosen by `sampling` — the paper's Eq. (8)
/// with the degree-2p quadrature points for [`Sampling::Quadrature`]. Ĩ = 1 for affine
/// elements, Ĩ ≤ 0 means inverted. Computed in parallel; each element's value is computed
/// sequentially, so the result does not depend on the number of threads.
pub fn scaled_jacobian(mesh: &HighOrderMesh, sampling: Sampling) -> Result<Vec<f64>, QualityError> {
    let shapes = check_cells(mesh)?;
    let samplers = samplers(mesh, &shapes, sampling)?;
    Ok(mesh
        .cells
        .par_iter()
        .map_init(JacobianWorkspace::default, |workspace, cell| {
            let Some(sampler) = cell.kind.shape().ok().and_then(|s| samplers.get(&s)) else {
                return f64::NAN; // unreachable: every cell was checked above
            };
            let mut coords = std::mem::take(&mut workspace.coords);
            gather(mesh, cell, &mut coords);
            let value = sampler.scaled_jacobian_with(&coords, workspace);
            workspace.coords = coords;
            value
        })
        .collect())
}

/// det J of cell `element` at the given reference points (hocurve's reference elements), for
/// comparison with other codes. Gmsh's `getJacobians` uses the same unit triangle and
/// tetrahedron, but [−1, 1]^d for quadrilaterals and hexahedra and [−1, 1] for the prism's
/// third direction: pass ξ = (u + 1)/2 in those directions and compare with Gmsh's
/// determinant times 2 per such direction (∂x/∂u = ½ ∂x/∂ξ).
pub fn jacobian_determinants(
    mesh: &HighOrderMesh,
    element: usize,
    reference_points: &[[f64; 3]],
) -> Result<Vec<f64>, QualityError> {
    let cell = mesh
        .cells
        .get(element)
        .ok_or(QualityError::ElementOutOfRange {
            element,
            count: mesh.cells.len(),
        })?;
    let shape = cell_shape(element, cell)?;
    let expected = shape.num_nodes(mesh.order);
    if cell.nodes.len() != expected {
        return Err(QualityError::WrongNodeCount {
            element,
            shape,
            order: mesh.order,
            expected,
            found: cell.nodes.len(),
        });
    }
    if let Some(&node) = cell.nodes.iter().find(|&&n| n as usize >= mesh.nodes.len()) {
        return Err(QualityError::NodeOutOfRange {
            element,
            node: node as usize,
            count: mesh.nodes.len(),
        });
    }
    let sampler = JacobianSampler::at_points(shape, mesh.order, mesh.family, reference_points)?;
    let mut coords = Vec::new();
    gather(mesh, cell, &mut coords);
    Ok(sampler.determinants(&coords))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_meshes::{box_tets, hash01, single_element, single_element_of_family};
    use hocurve_mesh::ElementType;

    const ALL_TYPES: [ElementType; 5] = [
        ElementType::Tri,
        ElementType::Quad,
        ElementType::Tet,
        ElementType::Hex,
        ElementType::Prism,
    ];
    const ALL_SAMPLINGS: [Sampling; 3] = [Sampling::Quadrature, Sampling::Nodes, Sampling::Both];

    /// A dense set of reference points of `shape` including its vertices: the equispaced
    /// order-10 lattice.
    fn dense_points(shape: Shape) -> Vec<[f64; 3]> {
        ReferenceNodes::new(shape, 10, NodeFamily::Equispaced)
            .points()
            .to_vec()
    }

    #[test]
    fn affine_elements_of_every_type_have_unit_scaled_jacobian() {
        // A general affine map with det A = 2.57 > 0: J = A everywhere, so Ĩ = 1.
        let affine = |x: [f64; 3]| {
            [
                1.3 * x[0] + 0.4 * x[1] - 0.2 * x[2] + 5.0,
                -0.3 * x[0] + 1.1 * x[1] + 0.1 * x[2] - 2.0,
                0.2 * x[0] + 0.1 * x[1] + 1.7 * x[2] + 1e3,
            ]
        };
        for kind in ALL_TYPES {
            for family in NodeFamily::ALL {
                for p in 1..=4 {
                    let mesh = single_element_of_family(kind, p, family, |x| {
                        let y = affine(x);
                        if kind.dim() == 2 {
                            [y[0], y[1], 0.0]
                        } else {
                            y
                        }
                    });
                    for sampling in ALL_SAMPLINGS {
                        let q = scaled_jacobian(&mesh, sampling).unwrap()[0];
                        // Not bit-exact: the basis gradients carry the rounding of the
                        // Vandermonde inverse (cond ~ 10² at p = 4).
                        assert!((q - 1.0).abs() < 1e-11, "{kind} {family} p={p}: {q}");
                    }
                }
            }
        }
    }

    #[test]
    fn bilinear_quad_matches_the_hand_derivation() {
        // Corners (0,0), (1,0), (c,d), (0,1): x = ξ(1 + (c−1)η), y = η(1 + (d−1)ξ), so
        // x_ξ y_η − x_η y_ξ = (1+(c−1)η)(1+(d−1)ξ) − (c−1)ξ (d−1)η = 1 + (d−1)ξ + (c−1)η:
        // linear, extreme at the corners: values 1, d, c, c+d−1 → with c = 1.5, d = 1.2,
        // Ĩ = 1 / 1.7. At the interior Gauss points g₀ < … < g_last of the quadrature rule
        // it is (1 + 0.7 g₀) / (1 + 0.7 g_last).
        let (c, d) = (1.5, 1.2);
        let bilinear = |x: [f64; 3]| {
            [
                x[0] * (1.0 + (c - 1.0) * x[1]),
                x[1] * (1.0 + (d - 1.0) * x[0]),
                0.0,
            ]
        };
        for p in 1..=3 {
            let mesh = single_element(ElementType::Quad, p, bilinear);
            let exact = 1.0 / 1.7;
            for sampling in [Sampling::Nodes, Sampling::Both] {
                let q = scaled_jacobian(&mesh, sampling).unwrap()[0];
                assert!((q - exact).abs() < 1e-13, "p={p}: {q}");
            }
            let gauss = hocurve_nodes::gauss_legendre(p + 1).points;
            let (g0, g1) = (0.5 * (gauss[0] + 1.0), 0.5 * (gauss[p] + 1.0));
            let at_quadrature = (1.0 + 0.7 * g0) / (1.0 + 0.7 * g1);
            let q = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0];
            assert!(
                (q - at_quadrature).abs() < 1e-13,
                "p={p}: {q} vs {at_quadrature}"
            );
            assert!(q > exact);
        }
    }

    #[test]
    fn trilinear_hex_matches_the_hand_derivation() {
        // x = ξ(1 + αη), y = η, z = ζ(1 + βξ) (vertices (1,1,·) and (1,·,1) moved):
        // J = [[1+αη, αξ, 0], [0, 1, 0], [βζ, 0, 1+βξ]], det J = (1+αη)(1+βξ) by expansion
        // along the second row. Extremes at (0,0,·) and (1,1,·): Ĩ = 1/((1+α)(1+β)).
        let (alpha, beta) = (0.5, 0.3);
        let map = |x: [f64; 3]| {
            [
                x[0] * (1.0 + alpha * x[1]),
                x[1],
                x[2] * (1.0 + beta * x[0]),
            ]
        };
        for p in 1..=3 {
            let mesh = single_element(ElementType::Hex, p, map);
            let exact = 1.0 / ((1.0 + alpha) * (1.0 + beta));
            let q = scaled_jacobian(&mesh, Sampling::Both).unwrap()[0];
            assert!((q - exact).abs() < 1e-13, "p={p}: {q}");
            let gauss = hocurve_nodes::gauss_legendre(p + 1).points;
            let (g0, g1) = (0.5 * (gauss[0] + 1.0), 0.5 * (gauss[p] + 1.0));
            let at_quadrature =
                (1.0 + alpha * g0) * (1.0 + beta * g0) / ((1.0 + alpha * g1) * (1.0 + beta * g1));
            let q = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0];
            assert!((q - at_quadrature).abs() < 1e-13, "p={p}: {q}");
        }
    }

    #[test]
    fn curved_elements_match_the_analytic_jacobian() {
        // x ↦ x + εx² (p ≥ 2) or x + εx³ (p ≥ 3) in the first coordinate: det J = 1 + 2εξ or
        // 1 + 3εξ², from 1 at ξ = 0 to 1 + 2ε or 1 + 3ε at ξ = 1 (every shape spans
        // ξ ∈ [0, 1]), so Ĩ = 1/(1 + 2ε) or 1/(1 + 3ε).
        let eps = 0.4;
        type Case = (usize, fn(f64) -> f64, fn(f64) -> f64, f64);
        let cases: [Case; 2] = [
            (
                2,
                |x| x + 0.4 * x * x,
                |x| 1.0 + 0.8 * x,
                1.0 / (1.0 + 2.0 * eps),
            ),
            (
                3,
                |x| x + 0.4 * x * x * x,
                |x| 1.0 + 1.2 * x * x,
                1.0 / (1.0 + 3.0 * eps),
            ),
        ];
        for kind in ALL_TYPES {
            let shape = kind.shape().unwrap();
            for (min_order, map, det, exact) in cases {
                for p in min_order..=4 {
                    let mesh = single_element(kind, p, |x| [map(x[0]), x[1], x[2]]);
                    let dense = dense_points(shape);
                    let dets = jacobian_determinants(&mesh, 0, &dense).unwrap();
                    for (x, d) in dense.iter().zip(&dets) {
                        assert!((d - det(x[0])).abs() < 1e-10, "{kind} p={p} at {x:?}");
                    }
                    let (lo, hi) = min_max(&dets);
                    assert!((scaled_ratio(lo, hi) - exact).abs() < 1e-10);
                    // The paper's quadrature sampling sees a value ≥ the true minimum, and
                    // exactly the analytic value at its own points.
                    let rule = QuadratureRule::new(shape, 2 * p);
                    let (xmin, xmax) =
                        min_max(&rule.points.iter().map(|x| x[0]).collect::<Vec<_>>());
                    let q = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0];
                    assert!(q >= exact, "{kind} p={p}: {q} < {exact}");
                    assert!((q - det(xmin) / det(xmax)).abs() < 1e-10, "{kind} p={p}");
                    let q = scaled_jacobian(&mesh, Sampling::Nodes).unwrap()[0];
                    assert!((q - exact).abs() < 1e-10, "{kind} p={p}");
                }
            }
        }
    }

    #[test]
    fn results_do_not_depend_on_the_thread_count() {
        let linear = box_tets(3);
        let mut mesh = HighOrderMesh::from_linear(&linear, 3, NodeFamily::Fekete).unwrap();
        for (i, x) in mesh.nodes.iter_mut().enumerate() {
            for d in 0..3 {
                x[d] += 0.005 * (hash01(3 * i as u64 + d as u64) - 0.5);
            }
        }
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| scaled_jacobian(&mesh, Sampling::Both).unwrap())
        };
        let one = run(1);
        assert_eq!(one.len(), 162);
        let (lo, hi) = min_max(&one);
        assert!(lo > 0.0 && hi < 1.0, "{lo} {hi}");
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&one), bits(&run(2)));
        assert_eq!(bits(&one), bits(&run(3)));
    }

    #[test]
    fn inverted_and_degenerate_elements_score_at_most_zero() {
        // Mirrored triangle: det J = −1 everywhere → Ĩ = −1/1 = −1.
        let mesh = single_element(ElementType::Tri, 2, |x| [x[1], x[0], 0.0]);
        let q = scaled_jacobian(&mesh, Sampling::Both).unwrap()[0];
        assert!((q + 1.0).abs() < 1e-13, "{q}");
        // Flattened tet: det J ≡ 0 → 0.
        let mesh = single_element(ElementType::Tet, 2, |x| [x[0], x[1], 0.0]);
        assert_eq!(
            scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0],
            0.0
        );
        // NaN coordinates → counted as invalid (0), never NaN.
        let mesh = single_element(ElementType::Quad, 1, |x| [x[0], f64::NAN, 0.0]);
        assert_eq!(
            scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0],
            0.0
        );
    }

    #[test]
    fn bad_input_is_reported_with_the_element() {
        let mut mesh = single_element(ElementType::Tet, 2, |x| x);
        assert!(matches!(
            jacobian_determinants(&mesh, 3, &[[0.1; 3]]),
            Err(QualityError::ElementOutOfRange {
                element: 3,
                count: 1
            })
        ));
        mesh.cells[0].nodes[4] = 999;
        let err = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap_err();
        assert!(matches!(
            err,
            QualityError::NodeOutOfRange {
                element: 0,
                node: 999,
                ..
            }
        ));
        mesh.cells[0].nodes.pop();
        let err = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap_err();
        assert!(err.to_string().contains("has 9 nodes"), "{err}");
        mesh.cells[0].kind = ElementType::Pyramid;
        let err = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap_err();
        assert!(err.to_string().contains("pyramid"), "{err}");
    }

    /// Throughput on ~1 M order-3 tetrahedra (not a timed assertion; run with
    /// `cargo test -p hocurve-quality --release -- --ignored --nocapture throughput`).
    #[test]
    #[ignore]
    fn throughput_one_million_p3_tets() {
        let t = std::time::Instant::now();
        let linear = box_tets(55);
        let mesh = HighOrderMesh::from_linear(&linear, 3, NodeFamily::Fekete).unwrap();
        println!(
            "{} tets, {} nodes, built in {:.2?}",
            mesh.cells.len(),
            mesh.nodes.len(),
            t.elapsed()
        );
        for sampling in ALL_SAMPLINGS {
            let t = std::time::Instant::now();
            let q = scaled_jacobian(&mesh, sampling).unwrap();
            println!("scaled_jacobian {sampling:?}: {:.2?}", t.elapsed());
            assert!(q.iter().all(|&v| (v - 1.0).abs() < 1e-10));
        }
        let t = std::time::Instant::now();
        let checks = crate::check_validity(&mesh, &crate::BezierOptions::default()).unwrap();
        println!("check_validity: {:.2?}", t.elapsed());
        assert!(checks.iter().all(|c| c.validity == crate::Validity::Valid));
        let t = std::time::Instant::now();
        let quality = crate::assess(&mesh, &crate::QualityOptions::default()).unwrap();
        println!("assess (quadrature, no Bézier): {:.2?}", t.elapsed());
        println!("{}", quality.summary);
        for shape in [
            Shape::Tri,
            Shape::Quad,
            Shape::Tet,
            Shape::Hex,
            Shape::Prism,
        ] {
            for p in 1..=4 {
                let space = crate::BernsteinSpace::for_jacobian(shape, p).unwrap();
                println!(
                    "{shape:?} p={p}: {} coefficients, conversion norm {:.3e}",
                    space.len(),
                    space.conversion_norm()
                );
            }
        }
    }
}
