//! High-order linear elasticity (the paper's Sect. 2, 3.2): spreads the boundary displacement
//! of curved walls into the domain so that elements next to them stay valid.
//!
//! Not yet implemented: this crate is filled in by issue [5/7].
