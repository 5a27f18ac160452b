//! hocurve: curved high-order meshes of arbitrary order from straight-sided meshes.
//!
//! This facade re-exports the workspace crates so that one dependency gives them all:
//! reference elements ([`nodes`]), the mesh model ([`mesh`]), file formats ([`io`]),
//! geometry ([`nurbs`]), boundary nodes ([`geodesic`]), elasticity ([`elastic`]) and
//! quality ([`quality`]).

pub mod interpolation;

pub use hocurve_elastic as elastic;
pub use hocurve_geodesic as geodesic;
pub use hocurve_io as io;
pub use hocurve_mesh as mesh;
pub use hocurve_nodes as nodes;
pub use hocurve_nurbs as nurbs;
pub use hocurve_quality as quality;
