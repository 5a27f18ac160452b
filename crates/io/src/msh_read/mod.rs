//! Gmsh MSH reader: MSH 4.1 and 2.2 (2.0–2.2), ASCII and binary, first-order elements
//! ([`read_msh`]) or complete elements of any order ([`read_high_order_msh`]).
//!
//! What the reader produces ([`LinearMesh`](hocurve_mesh::LinearMesh)):
//! - every node of `$Nodes`, in file order; node tags may be sparse and unordered, they are
//!   mapped to 0-based indices in order of appearance;
//! - the elements of the highest dimension present become the cells (which fixes `dim`), the
//!   elements one dimension lower the facets; points and lower-dimensional elements are
//!   dropped;
//! - entity tags: MSH 4.1 element block `entityTag`, MSH 2 second ("elementary") tag;
//! - physical tags per entity: MSH 4.1 `$Entities`, MSH 2 first element tag (elements that
//!   MSH 2 repeats once per physical group are merged);
//! - physical groups: `$PhysicalNames` plus every physical tag used but not named.
//!
//! Errors name the line (ASCII) or byte offset (binary) and say what was expected and found.
//! The reader never panics: counts read from the file are checked against the bytes left
//! before anything is allocated for them.
//!
//! Layout: [`cursor`] reads the file record by record (text lines or binary values, through
//! [`tokens`]); [`parser`] holds what has been read; [`sections`] walks the file and hands
//! each section to its parser ([`mesh_format`], [`physicals`], [`nodes`] with the
//! [`node_index`], [`elements`] with the Gmsh types of [`element_types`], both with the MSH
//! 4.1 [`blocks`]); [`linear`] and [`high_order`] assemble the mesh each reader returns;
//! [`failure`] is what goes wrong before the file's path is attached.

mod blocks;
mod cursor;
mod element_types;
mod elements;
mod failure;
mod high_order;
mod linear;
mod mesh_format;
mod node_index;
mod nodes;
mod parser;
mod physicals;
mod sections;
mod tokens;

pub use high_order::{parse_high_order_msh, read_high_order_msh};
pub use linear::{parse_msh, read_msh};

#[cfg(test)]
#[path = "../tests/msh_read.rs"]
mod tests;

#[cfg(test)]
#[path = "../tests/msh_read_high_order.rs"]
mod high_order_tests;
