//! Repair of curved elements that are not valid (beyond the paper, whose elastic analogy
//! does not guarantee det J > 0): the nodes around them that lie on no boundary are moved
//! to minimise a Jacobian-barrier distortion energy, the boundary nodes staying where they
//! are (on the geometry).
//!
//! For each sample point ξ_q of an element, T = J(ξ_q) W_q⁻¹ compares the curved map's
//! Jacobian J with that of the straight-sided element W (the shape the element should
//! keep). Its distortion in d dimensions is the inverse mean ratio
//!
//! f(T) = |T|²_F / (d · h(det T)^{2/d}),  h(τ) = (τ + √(τ² + 4δ²)) / 2,
//!
//! which is 1 for a similarity and grows without bound as det T → 0⁺ when δ = 0 (a
//! barrier). With δ > 0, h is positive for every τ, so the energy is finite on tangled
//! elements and its minimum drags det T up through zero (Escobar et al., "Simultaneous
//! untangling and smoothing of tetrahedral meshes", CMAME 192 (2003) 2775–2787). δ is
//! chosen from the smallest det T and set to 0 once every sample point is positive, so
//! that the barrier then keeps them positive while the shape improves.
//!
//! The energy is minimised by nonlinear conjugate gradients while it is regularised (they
//! take the mesh through the tangle), then, once every det T is positive, by Newton's
//! method to its minimum itself: where conjugate gradients stop depends on the path they
//! took, so one patch with its fixed nodes moved by round-off (the same model read from
//! STEP and from IGES) would end 1e-3 of an element apart.
//!
//! The patch of an element is the element and the rings of cells sharing a vertex with it;
//! its free nodes are the non-boundary nodes whose cells all lie in the patch, so cells
//! outside it are untouched. Patches that share free nodes are optimised together; separate
//! ones in parallel, each sequentially, so the result does not depend on the thread count.
//!
//! # Example
//!
//! ```
//! use hocurve_mesh::{Element, Shape, HighOrderMesh, LinearMesh};
//! use hocurve_nodes::NodeFamily;
//! use hocurve_quality::{check_validity, BezierOptions, Validity};
//! use hocurve_untangle::{untangle, UntangleOptions};
//! // The unit square as four triangles about its centre, at order 2.
//! let tri = |a, b| Element { kind: Shape::Tri, vertices: vec![a, b, 4], entity: 1 };
//! let square = LinearMesh {
//!     dim: 2,
//!     vertices: vec![
//!         [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 0.0],
//!     ],
//!     cells: vec![tri(0, 1), tri(1, 2), tri(2, 3), tri(3, 0)],
//!     ..Default::default()
//! };
//! let mut mesh = HighOrderMesh::from_linear(&square, 2, NodeFamily::Equispaced)?;
//! let straight = mesh.nodes.clone();
//! // Drag the centre out through the right side: the triangles on it fold over.
//! mesh.nodes[4] = [1.2, 0.5, 0.0];
//! let not_valid = |mesh: &HighOrderMesh| -> Result<Vec<usize>, hocurve_quality::QualityError> {
//!     let checks = check_validity(mesh, &BezierOptions::default())?;
//!     Ok((0..checks.len()).filter(|&e| checks[e].validity != Validity::Valid).collect())
//! };
//! let bad = not_valid(&mesh)?;
//! assert!(!bad.is_empty());
//! // The corners and the nodes on the sides are fixed: the centre and the four edge
//! // midpoints next to it move, back to the straight shapes (which minimise the energy).
//! let fixed: Vec<u32> = (0..mesh.nodes.len() as u32).filter(|&n| {
//!     let x = straight[n as usize];
//!     x[0] * (1.0 - x[0]) * x[1] * (1.0 - x[1]) == 0.0
//! }).collect();
//! let report = untangle(&mut mesh, &straight, &bad, &fixed, &UntangleOptions::default())?;
//! assert!(report.min_ratio > 0.0);
//! assert!(not_valid(&mesh)?.is_empty());
//! let centre = mesh.nodes[4];
//! assert!((centre[0] - 0.5).abs() < 1e-3 && (centre[1] - 0.5).abs() < 1e-3);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod energy;
mod newton;
mod optimise;
mod patch;
#[cfg(test)]
mod tests;

pub use energy::{inverse_mean_ratio, DistortionEnergy};
pub use patch::{untangle, untangle_sliding, UntangleOptions, UntangleReport};

/// How a boundary node that is not fixed may move while its patch is optimised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NodeConstraint {
    /// In the plane through it with this unit normal (a sliding symmetry or end plane).
    Plane([f64; 3]),
    /// Along the line through it with this unit direction (where two sliding planes meet).
    Line([f64; 3]),
}

impl NodeConstraint {
    /// The part of a motion `g` this constraint allows: g − (g·n) n, or (g·d) d.
    pub fn project(&self, g: [f64; 3]) -> [f64; 3] {
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        match *self {
            NodeConstraint::Plane(n) => {
                let t = dot(g, n);
                [g[0] - t * n[0], g[1] - t * n[1], g[2] - t * n[2]]
            }
            NodeConstraint::Line(d) => {
                let t = dot(g, d);
                [t * d[0], t * d[1], t * d[2]]
            }
        }
    }
}

/// Errors of this crate. Element and node indices are 0-based positions in the mesh.
#[derive(Debug, thiserror::Error)]
pub enum UntangleError {
    /// Measuring the elements failed (unsupported shape, wrong node count...).
    #[error(transparent)]
    Quality(#[from] hocurve_quality::QualityError),
    /// The straight-sided positions do not match the mesh.
    #[error("{found} straight-sided node positions given for a mesh of {expected} nodes")]
    StraightNodes {
        /// Nodes of the mesh.
        expected: usize,
        /// Positions given.
        found: usize,
    },
    /// An element asked for does not exist.
    #[error("element {element} does not exist (the mesh has {count} cells)")]
    NoSuchElement {
        /// The index asked for.
        element: usize,
        /// Number of cells.
        count: usize,
    },
}
