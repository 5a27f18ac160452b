//! When a number written in an IGES file stands for an exact value: the one tolerance both
//! the exact constructions and the entity conversion recognise intents with.

/// Relative tolerance with which a value in the file is taken as its exact intent: a full
/// turn, an arc whose end is its start, a centre on an axis, an orthogonal 124 matrix.
/// OpenCASCADE writes 10 significant digits (2π as `6.283185307`, off by 1.8e-10).
pub const RECOGNITION_TOLERANCE: f64 = 1e-8;
