//! NURBS curves and surfaces for hocurve: evaluation, point inversion and arc length
//! (the paper's Sect. 3.1), plus exact representations of analytic shapes.
//!
//! Not yet implemented: this crate is filled in by issue [3/7] (Geometry).
