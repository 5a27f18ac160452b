//! IGES 5.3 input (fixed ASCII form): parsing, and conversion to exact NURBS.
//!
//! [`parse_iges`] splits the file into its 80-column records (section letter in column 73,
//! sequence number in columns 74–80), reads the Global section (delimiters, units, model
//! scale, resolution), the Directory Entry pairs and the free-format Parameter Data of every
//! entity (columns 1–64, back-pointer to the DE in columns 66–72; Hollerith strings `nH...`,
//! reals with `E` or `D` exponents), and returns each entity as a typed record
//! ([`EntityData`]). Nothing is evaluated by the parser. [`geometry_from_iges`] (or
//! [`read_iges_geometry`]) then converts the independent entities to exact rational NURBS
//! curves and surfaces (a [`crate::GeometryModel`]), reporting unsupported entities with their
//! type and line.
//!
//! Every error names the 1-based line of the file and what was expected and found.
//!
//! Layout: `parse` reads the file through `sections` (80-column records), `global`,
//! `directory`, `params` (free-format fields), `param_reader` and `entity_parser` into the
//! `entities` records of a `model`, whose pointers `references` checks. `convert` picks the
//! independent entities and `convert_curves`, `convert_surfaces` and `convert_faces` (trimmed
//! and 2D faces) build them, on the shared `converter` state, from the exact constructions in
//! `affine`, `curve_primitives`, `restrict`, `swept`, `join` and `plane_patch`; `naming` names
//! them.

pub(crate) mod affine;
mod convert;
mod convert_curves;
mod convert_faces;
mod convert_surfaces;
mod converter;
pub(crate) mod curve_primitives;
mod directory;
mod entities;
mod entity_parser;
mod error;
mod global;
mod join;
mod limits;
mod model;
mod model_edges;
mod naming;
mod param_reader;
mod params;
mod parse;
pub(crate) mod plane_patch;
mod references;
pub(crate) mod restrict;
mod sections;
pub(crate) mod swept;
mod tolerance;

pub use convert::{geometry_from_iges, read_iges_geometry};
pub use directory::DirectoryEntry;
pub use entities::{BSplineCurveData, BSplineSurfaceData, EntityData};
pub use error::{IgesError, ReferenceKind};
pub use global::GlobalSection;
pub use limits::{EXPANSION_FACTOR, EXPANSION_MINIMUM, MAX_NESTING};
pub use model::{IgesEntity, IgesModel};
pub use params::{parse_int, parse_real, Param, ParamValue};
pub use parse::{parse_iges, read_iges};
pub use tolerance::RECOGNITION_TOLERANCE;

#[cfg(test)]
#[path = "tests/mod_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "tests/cycles.rs"]
mod cycle_tests;

#[cfg(test)]
#[path = "tests/fuzz.rs"]
mod fuzz_tests;
