//! Boundary nodes on the true geometry (the paper's Sect. 3.1, 4.1, 4.2): association of
//! boundary facets with CAD entities ([`association`]), edge nodes by arc length (Eq. (4)) on
//! boundary curves and on the intersection curves of surface patches ([`feature`]),
//! approximate geodesics on surfaces (Eq. (5), Fig. 3) with the minimum-angle correction
//! (Fig. 4, [`correction`]) and face-interior nodes (Eqs. (6)–(7)), all driven by
//! [`place_boundary_nodes_with`].
//!
//! # Example
//!
//! ```
//! use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};
//! use hocurve_geodesic::{GeodesicPath, SurfaceChart};
//! // The unit sphere: u turns about the z axis from +x, v runs from the south pole north.
//! let sphere = hocurve_nurbs::shapes::sphere([0.0; 3], 1.0)?;
//! let chart = SurfaceChart::new(&sphere);
//! // From (1, 0, 0) on the equator to (0, 1, 1)/√2, 45° north: a quarter of a great
//! // circle, which no parameter line follows.
//! let path = GeodesicPath::between(&chart, [0.0, 0.5], [0.25, 0.75], 1e-10);
//! assert!((path.length() - FRAC_PI_2).abs() < 1e-6);
//! // Halfway along is the middle of the arc, (1, 1/√2, 1/√2)/√2.
//! let (_, middle) = path.at_fraction(&chart, 0.5);
//! let expected = [FRAC_1_SQRT_2, 0.5, 0.5];
//! assert!((0..3).all(|d| (middle[d] - expected[d]).abs() < 1e-6));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod association;
pub mod chart;
pub mod closed_form;
pub mod correction;
mod curve_arc;
pub mod feature;
pub(crate) mod frame;
pub mod path;
pub mod placement;

pub use association::{
    associate_boundary, associate_boundary_reusing, AssociationRule, BoundaryAssociation,
    ProximityCache,
};
pub use chart::SurfaceChart;
pub use closed_form::ClosedFormGeodesic;
pub use feature::FeatureTraces;
pub use path::GeodesicPath;
pub use placement::{
    max_distance_from_geometry, place_boundary_nodes, place_boundary_nodes_reusing,
    place_boundary_nodes_with, project_nodes_onto_geometry, BoundaryNodeStrategy, BoundaryTargets,
    GeometryDistance, PlacementOptions,
};

/// What went wrong while putting boundary nodes on the geometry.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GeodesicError {
    /// A geometry tolerance that is negative or not finite.
    #[error("geometry tolerance must be a finite length ≥ 0, got {0}")]
    Tolerance(f64),
    /// A vertex of a facet associated with an entity lies too far from it.
    #[error("node tag {tag} at ({:.6}, {:.6}, {:.6}) lies {distance:.3e} from geometry entity \"{entity}\", beyond the tolerance {tolerance:.3e} (is it the right geometry, in the mesh's units?)", position[0], position[1], position[2])]
    VertexOffGeometry {
        /// The vertex (0-based index).
        vertex: u32,
        /// Its tag in the file (Gmsh node tag).
        tag: u64,
        /// Where it is.
        position: [f64; 3],
        entity: String,
        distance: f64,
        tolerance: f64,
    },
    /// A facet was associated by name with an entity of the wrong dimension.
    #[error("entity \"{entity}\" is a {} but the boundary of a {mesh_dim}D mesh needs {} (facet with element tag {facet_tag})", if *mesh_dim == 2 { "surface" } else { "curve" }, if *mesh_dim == 2 { "curves" } else { "surfaces" })]
    EntityDimension {
        entity: String,
        mesh_dim: usize,
        /// The facet's vertices (0-based indices).
        facet_vertices: Vec<u32>,
        /// The facet's tag in the file (Gmsh element tag).
        facet_tag: u64,
    },
    /// An option of [`PlacementOptions`] out of its range.
    #[error("placement option {option}: {reason}")]
    InvalidOption {
        option: &'static str,
        reason: String,
    },
    /// The mesh, the association and the geometry do not belong together.
    #[error("{0}")]
    Mismatch(String),
}

#[cfg(test)]
#[path = "tests/lib.rs"]
mod tests;
