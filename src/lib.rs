//! hocurve: curved high-order meshes of arbitrary order from straight-sided meshes.
//!
//! This facade re-exports the workspace crates so that one dependency gives them all:
//! reference elements ([`nodes`]), the mesh model ([`mesh`]), file formats ([`io`]),
//! geometry ([`nurbs`]), boundary nodes ([`geodesic`]), elasticity ([`elastic`]) and
//! quality ([`quality`]). [`pipeline::curve_mesh`] runs the whole method on a mesh and a
//! geometry; [`demo::Demo`] holds the bundled example cases.

mod attempt;
mod boundary_conditions;
mod certification;
mod correction_choice;
pub mod demo;
pub mod interpolation;
pub mod job;
pub mod memory;
pub mod pipeline;
mod precurving;
pub mod progress;
pub mod repair;
pub mod report;
pub mod summary;
pub mod verdict;
pub mod written;

pub use hocurve_elastic as elastic;
pub use hocurve_geodesic as geodesic;
pub use hocurve_io as io;
pub use hocurve_mesh as mesh;
pub use hocurve_nodes as nodes;
pub use hocurve_nurbs as nurbs;
pub use hocurve_quality as quality;
pub use hocurve_untangle as untangle;
