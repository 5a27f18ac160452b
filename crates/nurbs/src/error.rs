//! The crate's error type.

/// What was wrong with a NURBS description or a geometry request, and where.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum NurbsError {
    /// Degree 0 or above [`crate::basis::MAX_DEGREE`].
    #[error("degree {degree} is not supported (must be between 1 and {max})")]
    Degree { degree: usize, max: usize },
    /// Fewer control points than `degree + 1`.
    #[error("{found} control points are too few for degree {degree} (need at least {needed})")]
    TooFewControlPoints {
        degree: usize,
        found: usize,
        needed: usize,
    },
    /// The knot vector's length is not `control points + degree + 1`.
    #[error(
        "knot vector has {found} knots, expected {expected} ({control_points} control points + degree {degree} + 1)"
    )]
    KnotCount {
        expected: usize,
        found: usize,
        control_points: usize,
        degree: usize,
    },
    /// A knot is NaN or infinite.
    #[error("knot {index} is not finite ({value})")]
    NonFiniteKnot { index: usize, value: f64 },
    /// The knot vector decreases.
    #[error("knot vector decreases at index {index}: {previous} > {value}")]
    DecreasingKnots {
        index: usize,
        previous: f64,
        value: f64,
    },
    /// The parameter domain `[knots[p], knots[n+1]]` has zero length.
    #[error("empty parameter domain [{start}, {end}]")]
    EmptyDomain { start: f64, end: f64 },
    /// The number of weights differs from the number of control points.
    #[error("{found} weights given for {expected} control points")]
    WeightCount { expected: usize, found: usize },
    /// A weight is not strictly positive (or not finite).
    #[error("weight {index} is {value}; weights must be finite and > 0")]
    NonPositiveWeight { index: usize, value: f64 },
    /// A control point coordinate is NaN or infinite.
    #[error("control point {index} has a non-finite coordinate")]
    NonFiniteControlPoint { index: usize },
    /// A surface's control net does not have `n_u × n_v` points.
    #[error("control net has {found} points, expected {n_u} × {n_v} = {}", n_u * n_v)]
    ControlNetSize {
        n_u: usize,
        n_v: usize,
        found: usize,
    },
    /// A parameter outside the curve's or surface's domain (or not strictly inside, where
    /// that is required).
    #[error("parameter {param} is outside the domain ({start}, {end})")]
    ParameterOutOfDomain { param: f64, start: f64, end: f64 },
    /// An analytic shape with an invalid size or axis.
    #[error("invalid {shape}: {reason}")]
    InvalidShape { shape: &'static str, reason: String },
}
