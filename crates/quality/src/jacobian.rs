//! Jacobian determinants of the isoparametric map and the scaled Jacobian of the paper's
//! Eq. (8).
//!
//! An order-p element with nodes xᵢ maps the reference element by x(ξ) = Σᵢ xᵢ Φᵢ(ξ), so its
//! Jacobian is J(ξ) = Σᵢ xᵢ ⊗ ∇Φᵢ(ξ). The gradients ∇Φᵢ at the sample points depend only on
//! (shape, order, node family): a [`JacobianSampler`] takes them from the shared
//! [`ReferenceElement`], after which each element costs one small matrix product
//! (coordinates × gradients) and a determinant per point, with no allocation. In 2D the determinant is that of the 2×2 map of (x, y).

use std::collections::BTreeMap;
use std::sync::Arc;

use hocurve_mesh::{HighOrderElement, HighOrderMesh};
use hocurve_nodes::{NodeFamily, ReferenceElement, Shape, TabulatedBasis};
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

impl std::str::FromStr for Sampling {
    type Err = String;
    /// "quadrature", "nodes" or "both" (as on the command line).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "quadrature" => Ok(Self::Quadrature),
            "nodes" => Ok(Self::Nodes),
            "both" => Ok(Self::Both),
            _ => Err(format!(
                "unknown sampling \"{s}\" (expected quadrature, nodes or both)"
            )),
        }
    }
}

/// det J of elements of one (shape, order, family) at a fixed set of reference points: the
/// shared [`ReferenceElement`]'s basis tabulated there, with the isoparametric map of
/// [`TabulatedBasis::jacobian`].
#[derive(Debug, Clone)]
pub struct JacobianSampler {
    shape: Shape,
    order: usize,
    family: NodeFamily,
    table: Arc<TabulatedBasis>,
}

/// Scratch memory for [`JacobianSampler::determinants_with`]; reuse one per thread.
#[derive(Debug, Clone, Default)]
pub struct JacobianWorkspace {
    coords: Vec<[f64; 3]>,
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
        let element = ReferenceElement::shared(shape, order, family)?;
        let table = match sampling {
            Sampling::Quadrature => element.quadrature(2 * order),
            Sampling::Nodes => Arc::new(element.tabulate(element.nodes().points())),
            Sampling::Both => {
                let mut points = element.quadrature(2 * order).points().to_vec();
                points.extend_from_slice(element.nodes().points());
                Arc::new(element.tabulate(&points))
            }
        };
        Ok(JacobianSampler {
            shape,
            order,
            family,
            table,
        })
    }

    /// The sampler at arbitrary reference `points` (e.g. to compare with another code's
    /// Jacobians at its own points).
    pub fn at_points(
        shape: Shape,
        order: usize,
        family: NodeFamily,
        points: &[[f64; 3]],
    ) -> Result<Self, QualityError> {
        let element = ReferenceElement::shared(shape, order, family)?;
        Ok(JacobianSampler {
            shape,
            order,
            family,
            table: Arc::new(element.tabulate(points)),
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
        self.table.points()
    }

    /// Number of nodes of an element (length of the coordinate list it expects).
    pub fn num_nodes(&self) -> usize {
        self.table.num_nodes()
    }

    /// ∇Φ of every node at sample point `point` (entry `node`; only the first `dim`
    /// components are meaningful): the sensitivity of J(ξ_point) to each node's position,
    /// ∂J/∂x_node = e_d ⊗ ∇Φ_node.
    #[inline]
    pub fn point_gradients(&self, point: usize) -> &[[f64; 3]] {
        self.table.gradients(point)
    }

    /// det J(ξ_q) for every sample point q of the element whose node coordinates are
    /// `coords` (canonical local order). Allocates only while `workspace` grows.
    pub fn determinants_with<'w>(
        &self,
        coords: &[[f64; 3]],
        workspace: &'w mut JacobianWorkspace,
    ) -> &'w [f64] {
        self.table.determinants_into(
            &coords[..self.num_nodes().min(coords.len())],
            &mut workspace.determinants,
        );
        &workspace.determinants
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

/// Checks that `cell` (number `element`) has the node count of a complete order-p element
/// and node ids in range.
fn check_nodes(
    mesh: &HighOrderMesh,
    element: usize,
    cell: &HighOrderElement,
) -> Result<(), QualityError> {
    let (shape, count) = (cell.kind, mesh.nodes.len());
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
    match cell.nodes.iter().find(|&&n| n as usize >= count) {
        Some(&node) => Err(QualityError::NodeOutOfRange {
            element,
            node: node as usize,
            count,
        }),
        None => Ok(()),
    }
}

/// Checks every cell of `mesh` (supported shape of the mesh's dimension, node count of a
/// complete order-p element, node ids in range) and returns the set of shapes present.
pub(crate) fn check_cells(mesh: &HighOrderMesh) -> Result<Vec<Shape>, QualityError> {
    let mut shapes = Vec::new();
    for (element, cell) in mesh.cells.iter().enumerate() {
        let shape = cell.kind;
        if shape.dim() != mesh.dim {
            return Err(QualityError::WrongDimension {
                element,
                shape,
                dim: mesh.dim,
            });
        }
        check_nodes(mesh, element, cell)?;
        if !shapes.contains(&shape) {
            shapes.push(shape);
        }
    }
    shapes.sort();
    Ok(shapes)
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
    scaled_jacobian_where(mesh, sampling, None)
}

/// [`scaled_jacobian`], with the cells flagged in `affine` (simplices whose nodes are the
/// straight-sided ones) given Ĩ = ±1 from [`affine_determinant`] without sampling.
pub(crate) fn scaled_jacobian_where(
    mesh: &HighOrderMesh,
    sampling: Sampling,
    affine: Option<&[bool]>,
) -> Result<Vec<f64>, QualityError> {
    let shapes = check_cells(mesh)?;
    let samplers = samplers(mesh, &shapes, sampling)?;
    Ok(mesh
        .cells
        .par_iter()
        .enumerate()
        .map_init(JacobianWorkspace::default, |workspace, (c, cell)| {
            if let Some(det) = affine_determinant(mesh, cell, affine, c) {
                return scaled_ratio(det, det);
            }
            let sampler = &samplers[&cell.kind]; // check_cells saw every shape
            let mut coords = std::mem::take(&mut workspace.coords);
            gather(mesh, cell, &mut coords);
            let value = sampler.scaled_jacobian_with(&coords, workspace);
            workspace.coords = coords;
            value
        })
        .collect())
}

/// det J of a simplex cell flagged in `affine` (at index `c`), whose map is then affine:
/// J = [x₁ − x₀, x₂ − x₀(, x₃ − x₀)] on hocurve's unit reference simplex, the same J as
/// Σᵢ xᵢ ⊗ ∇φᵢ of its nodes. `None` for unflagged cells and other shapes.
pub(crate) fn affine_determinant(
    mesh: &HighOrderMesh,
    cell: &HighOrderElement,
    affine: Option<&[bool]>,
    c: usize,
) -> Option<f64> {
    if !affine
        .and_then(|flags| flags.get(c))
        .copied()
        .unwrap_or(false)
    {
        return None;
    }
    let dim = match cell.kind {
        Shape::Tri => 2,
        Shape::Tet => 3,
        _ => return None,
    };
    let x0 = mesh.nodes[cell.nodes[0] as usize];
    let mut j = [[0.0; 3]; 3];
    for alpha in 0..dim {
        let x = mesh.nodes[cell.nodes[alpha + 1] as usize];
        for (row, (a, b)) in j.iter_mut().zip(x.iter().zip(&x0)) {
            row[alpha] = a - b;
        }
    }
    Some(hocurve_nodes::determinant(&j, dim))
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
    let shape = cell.kind;
    check_nodes(mesh, element, cell)?;
    let sampler = JacobianSampler::at_points(shape, mesh.order, mesh.family, reference_points)?;
    let mut coords = Vec::new();
    gather(mesh, cell, &mut coords);
    Ok(sampler.determinants(&coords))
}

#[cfg(test)]
#[path = "tests/jacobian.rs"]
mod tests;
