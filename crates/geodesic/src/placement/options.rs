//! How boundary nodes are placed: the strategy and the placement options (minimum-angle
//! limit, feature tolerance, edges left uncorrected).

use std::collections::BTreeSet;

use crate::GeodesicError;

/// How boundary nodes are placed on the geometry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BoundaryNodeStrategy {
    /// The paper's method: arc length along curves and geodesics, Eqs. (4)–(7).
    #[default]
    Geodesic,
    /// Closest-point projection of the straight-sided nodes (the baseline).
    Projection,
}

impl std::str::FromStr for BoundaryNodeStrategy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "geodesic" => Ok(Self::Geodesic),
            "projection" => Ok(Self::Projection),
            _ => Err(format!(
                "unknown boundary-node strategy \"{s}\" (expected geodesic or projection)"
            )),
        }
    }
}

/// Options of [`place_boundary_nodes_with`](super::place_boundary_nodes_with).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementOptions {
    /// How the nodes are placed: the paper's geodesic method (default) or closest-point
    /// projection of the straight nodes.
    pub strategy: BoundaryNodeStrategy,
    /// The paper's minimum-angle correction (Sect. 4.1, Fig. 4): surface edges making an
    /// angle below this limit (degrees, in [0, 90)) with a neighbouring edge of a curved face
    /// are replaced by a Hermite-type polynomial curve whose end tangents restore the limit
    /// (see [`crate::correction`]). `None` or `Some(0.0)` turns it off; default `Some(10.0)`.
    /// Only used by [`BoundaryNodeStrategy::Geodesic`] in 3D at orders p ≥ 3 (at p = 2 small
    /// angles are counted but not corrected).
    pub min_angle_degrees: Option<f64>,
    /// Relative tolerance on the length of traced intersection curves (feature edges between
    /// two surfaces without a curve entity in the model): the bisection stops when the
    /// polyline's length changes by less than this. Default 1e-10, as for geodesics
    /// ([`crate::path::DEFAULT_LENGTH_TOLERANCE`]): a node's place along the edge to ~1e-10 of
    /// its length (it lies on the surfaces to round-off either way). 1e-12 took 2–4× the
    /// points (a STEP assembly's placement 3× the time) for the same quality summary.
    pub feature_length_tolerance: f64,
    /// Surface edges (global vertex pairs, lower id first) that keep their geodesic even
    /// when an angle there is below the limit: the curving pipeline's repair puts here the
    /// corrected edges of elements that came out invalid, so that a correction is kept only
    /// where it does not hurt.
    pub uncorrected_edges: BTreeSet<[u32; 2]>,
}

impl Default for PlacementOptions {
    fn default() -> Self {
        Self::new(BoundaryNodeStrategy::default())
    }
}

impl PlacementOptions {
    /// The defaults with the given strategy: minimum angle 10°, feature curves traced to a
    /// relative length change of 1e-10.
    pub fn new(strategy: BoundaryNodeStrategy) -> Self {
        Self {
            strategy,
            min_angle_degrees: Some(10.0),
            feature_length_tolerance: crate::path::DEFAULT_LENGTH_TOLERANCE,
            uncorrected_edges: BTreeSet::new(),
        }
    }

    /// The same options with the minimum-angle limit `degrees` (`None`: no correction).
    pub fn with_min_angle(mut self, degrees: Option<f64>) -> Self {
        self.min_angle_degrees = degrees;
        self
    }

    /// The angle limit in radians, `None` when the correction is off; an error for a limit
    /// outside [0, 90) degrees or a tolerance that is not a positive finite number.
    pub(super) fn checked_limit(&self) -> Result<Option<f64>, GeodesicError> {
        let t = self.feature_length_tolerance;
        if !(t.is_finite() && t > 0.0) {
            return Err(GeodesicError::InvalidOption {
                option: "feature_length_tolerance",
                reason: format!("must be a finite number > 0, got {t}"),
            });
        }
        match self.min_angle_degrees {
            None => Ok(None),
            Some(a) if a.is_finite() && (0.0..90.0).contains(&a) => {
                Ok((a > 0.0).then(|| a.to_radians()))
            }
            Some(a) => Err(GeodesicError::InvalidOption {
                option: "min_angle_degrees",
                reason: format!("must be an angle in [0, 90) degrees, got {a}"),
            }),
        }
    }
}
