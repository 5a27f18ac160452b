//! Mesh quality for curved high-order meshes: the scaled Jacobian of the paper's Eq. (8),
//! stretching and histograms.
//!
//! Not yet implemented: this crate is filled in by issue [6/7].
