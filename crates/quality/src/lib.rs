//! Mesh quality for curved high-order meshes (the paper's Sect. 4.3 and 5): the scaled
//! Jacobian Ĩ = min det J / |max det J| of its Eq. (8) sampled at the degree-2p quadrature
//! points ([`scaled_jacobian`]), a guaranteed validity check from Bézier bounds on det J
//! ([`check_validity`], beyond the paper), stretching ([`stretching`]), and the summary and
//! histograms of its figures ([`QualitySummary`], [`scaled_jacobian_histogram_svg`]).
//!
//! # Example
//!
//! ```
//! use hocurve_mesh::{Element, Shape, HighOrderMesh, LinearMesh};
//! use hocurve_nodes::NodeFamily;
//! use hocurve_quality::{assess, BezierOptions, QualityOptions, Validity};
//! let mesh = LinearMesh {
//!     dim: 2,
//!     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
//!     cells: vec![
//!         Element { kind: Shape::Tri, vertices: vec![0, 1, 2], entity: 1 },
//!         Element { kind: Shape::Tri, vertices: vec![0, 2, 3], entity: 1 },
//!     ],
//!     ..Default::default()
//! };
//! let ho = HighOrderMesh::from_linear(&mesh, 3, NodeFamily::Fekete)?;
//! let options = QualityOptions { bezier: Some(BezierOptions::default()), ..Default::default() };
//! let quality = assess(&ho, &options)?;
//! // Straight triangles have a constant Jacobian: Ĩ = 1.
//! assert!(quality.summary.min_scaled_jacobian.is_some_and(|m| (m - 1.0).abs() < 1e-12));
//! assert_eq!(quality.validity.map(|v| v[0].validity), Some(Validity::Valid));
//! println!("{}", quality.summary); // the text table
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod assessment;
mod bernstein;
mod bernstein_subdivision;
mod bezier_map;
mod bezier_prism;
mod bezier_simplex;
mod bound_refinement;
mod error;
mod jacobian;
mod plot;
mod stretching;
mod summary;
#[cfg(test)]
#[path = "tests/test_meshes.rs"]
mod test_meshes;
mod validity;

pub use assessment::{assess, assess_with_affine, MeshQuality, QualityOptions};
pub use bernstein::{
    bezier_check_supported, jacobian_degree, BernsteinSpace, MAX_DENSE_COEFFICIENTS,
    MAX_LINE_DEGREE,
};
pub use bernstein_subdivision::BernsteinSubdivision;
pub use error::QualityError;
pub use jacobian::{
    jacobian_determinants, scaled_jacobian, scaled_ratio, JacobianSampler, JacobianWorkspace,
    Sampling,
};
pub use plot::{histogram_svg, scaled_jacobian_histogram_svg, stretching_histogram_svg};
pub use stretching::stretching;
pub use summary::{
    scaled_jacobian_bin, Histogram, HistogramBin, QualitySummary, ValidityCounts,
    STRETCHING_BIN_EDGES, STRETCHING_THRESHOLD,
};
pub use validity::{
    check_validity, BezierOptions, BezierWorkspace, JacobianBezier, NarrowingGoal, Validity,
    ValidityCheck,
};
