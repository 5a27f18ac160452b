//! NURBS curves and surfaces for hocurve (the paper's Sect. 3.1): B-spline basis functions
//! ([`basis`]), rational curves ([`NurbsCurve`]) and surfaces ([`NurbsSurface`]) with first and
//! second derivatives and knot insertion, exact rational representations of circles, spheres,
//! cylinders and tori with closed-form projections ([`shapes`]), point inversion
//! ([`inversion`]) and arc length with its inverse ([`arc_length`]); NACA 4-digit airfoils as
//! interpolating cubic B-splines ([`naca`]) and the JSON geometry input ([`json`]).
//!
//! # Example
//!
//! ```
//! use hocurve_nurbs::shapes;
//! let circle = shapes::circle([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 2.0)?;
//! let p = circle.point(0.3);
//! assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - 2.0).abs() < 1e-14);
//! let length = hocurve_nurbs::arc_length::arc_length(&circle, 0.0, 1.0);
//! assert!((length - 4.0 * std::f64::consts::PI).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod arc_length;
pub mod basis;
mod conics;
pub mod curve;
mod error;
mod face_edges;
mod groups;
pub mod hull;
pub mod iges;
pub mod inversion;
pub mod json;
pub mod model;
pub mod naca;
pub mod shapes;
pub mod step;
pub mod surface;
mod surface_groups;
pub mod vec3;

pub use curve::NurbsCurve;
pub use error::NurbsError;
pub use json::{parse_geometry_json, read_geometry_json, GeometryInputError};
pub use model::{EntityGeometry, EntityPoint, GeometricEntity, GeometryModel, ModelEdge};
pub use naca::Naca4;
pub use surface::{NurbsSurface, SurfaceDerivatives, SurfaceProperties};
