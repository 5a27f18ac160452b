//! hocurve: curved high-order meshes of arbitrary order from straight-sided meshes.
//!
//! This facade re-exports the workspace crates so that one dependency gives them all:
//! reference elements ([`nodes`]), the mesh model ([`mesh`]), file formats ([`io`]),
//! geometry ([`nurbs`]), boundary nodes ([`geodesic`]), elasticity ([`elastic`]) and
//! quality ([`quality`]). [`pipeline::curve_mesh`] runs the whole method on a mesh and a
//! geometry; [`demo::Demo`] holds the bundled example cases.
//!
//! # Example
//!
//! ```
//! use std::collections::BTreeMap;
//! use std::f64::consts::{PI, TAU};
//! use hocurve::geodesic::AssociationRule;
//! use hocurve::mesh::{Element, Shape, LinearMesh, PhysicalGroup};
//! use hocurve::pipeline::{curve_mesh, CurveOptions, Geometry};
//! // A regular octagon of eight triangles about its centre, its sides in the group "circle".
//! let ring = |k: usize| 1 + (k % 8) as u32;
//! let element = |kind, vertices| Element { kind, vertices, entity: 1 };
//! let mut vertices = vec![[0.0; 3]];
//! vertices.extend((0..8).map(|k| TAU * k as f64 / 8.0).map(|t| [t.cos(), t.sin(), 0.0]));
//! let octagon = LinearMesh {
//!     dim: 2,
//!     vertices,
//!     cells: (0..8).map(|k| element(Shape::Tri, vec![0, ring(k), ring(k + 1)])).collect(),
//!     facets: (0..8).map(|k| element(Shape::Line, vec![ring(k), ring(k + 1)])).collect(),
//!     physical_groups: vec![PhysicalGroup { dim: 1, tag: 1, name: "circle".into() }],
//!     entity_physicals: BTreeMap::from([((1, 1), vec![1])]),
//!     ..Default::default()
//! };
//! let model = hocurve::nurbs::parse_geometry_json(
//!     r#"{"entities": [{"name": "circle", "kind": "circle", "center": [0, 0], "radius": 1}]}"#,
//! )?;
//! let geometry = Geometry { model: &model, rule: AssociationRule::NameOnly };
//! // Curved at p = 4: the sides become arcs of the unit circle, every element certified valid.
//! let curved = curve_mesh(&octagon, Some(geometry), &CurveOptions::new(4), &mut |_| {})?;
//! assert_eq!(curved.report.certified_valid_elements, Some(8));
//! let area = hocurve::interpolation::domain_measure(&curved.mesh)?;
//! assert!((area - PI).abs() < 1e-5); // the straight octagon: 2√2 ≈ 2.83
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod active_region;
mod attempt;
mod boundary_conditions;
mod certification;
mod correction_choice;
pub mod demo;
pub mod interpolation;
pub mod job;
pub mod layer_columns;
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
