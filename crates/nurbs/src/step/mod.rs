//! STEP input (ISO 10303-21 files of AP203/AP214/AP242 B-rep models, as OpenCASCADE and
//! CAD systems write them): [`parse`](parse_step) reads the exchange structure into typed
//! instances, nothing interpreted; [`geometry_from_step`] converts the faces (3D) or edges
//! (2D) into the same exact-NURBS [`crate::GeometryModel`] as the IGES reader, so that
//! association and curving do not depend on the format. Every error names the file line
//! and the instance.
//!
//! Written here rather than taken from a crate: `ruststep` (a complete schema-driven
//! parser) and `truck-stepio` (its reader for the truck modeller) bring a code generator or a
//! whole B-rep kernel, and still leave the mapping onto our model to us; what hocurve needs is
//! the geometry of faces and edges, a few hundred lines on top of a small parser.

mod convert;
mod curves;
mod error;
mod parse;
mod placements;
mod surfaces;
mod units;

pub use convert::{geometry_from_step, read_step_geometry};
pub use error::StepError;
pub use parse::{parse_step, read_step, StepFile, StepInstance, StepRecord, StepValue};
