//! Target positions of every high-order node on a curved boundary (the paper's Sect. 3.1,
//! 4.1, 4.2): vertices snapped onto the geometry, edge nodes by arc length along the boundary
//! curve (2D, Eq. (4)), along the intersection curve of the surfaces that meet at a feature
//! edge (3D patch boundaries, [`crate::feature`]) or along the approximate geodesic (3D, Eq.
//! (5)) — with the minimum-angle correction of Fig. 4 ([`crate::correction`]) — and
//! face-interior nodes by the geodesic constructions of Eq. (6) (triangles) and Eq. (7)
//! (quadrilaterals); or, as the baseline the paper improves on, by closest-point projection of
//! the straight nodes.
//!
//! Every edge's nodes are computed once, from one carrier built in the edge's canonical
//! orientation (lower vertex id first), so the facets on either side of it see the very same
//! points.
//!
//! One step of the method a file: `options` says how nodes are placed, `boundary` places
//! every boundary node (the driver), `edge_carriers` builds the carrier of each mesh edge,
//! `small_angle` checks an edge for the minimum-angle correction, `face_interior` places
//! the face-interior nodes, and `geometry_distance` measures and removes the distance of
//! nodes from their entities.

mod boundary;
mod edge_carriers;
mod face_interior;
mod geometry_distance;
mod options;
mod small_angle;

pub use boundary::{
    place_boundary_nodes, place_boundary_nodes_reusing, place_boundary_nodes_with, BoundaryTargets,
};
pub use geometry_distance::{
    max_distance_from_geometry, project_nodes_onto_geometry, GeometryDistance,
};
pub use options::{BoundaryNodeStrategy, PlacementOptions};

#[cfg(test)]
#[path = "../tests/placement.rs"]
mod tests;
