//! A piece of a NURBS curve between two parameters, with its nodes placed by arc length (the
//! paper's Eq. (4)): the carrier of a 2D boundary edge, and of a 3D feature edge on a model
//! curve entity.

use hocurve_nurbs::arc_length::{arc_length, parameter_at_length_fraction};
use hocurve_nurbs::NurbsCurve;

/// A piece of a NURBS curve from `from` to `to`, the short way round if the curve is closed.
#[derive(Debug, Clone)]
pub(crate) struct CurveArc<'a> {
    curve: &'a NurbsCurve,
    from: f64,
    to: f64,
    /// Crosses the seam of a closed curve.
    wraps: bool,
    /// Length of the arc.
    pub(crate) length: f64,
}

impl<'a> CurveArc<'a> {
    /// The arc of `curve` from parameter `from` to `to`, across the seam when that is the
    /// shorter way round a closed curve.
    pub(crate) fn new(curve: &'a NurbsCurve, from: f64, to: f64) -> Self {
        let direct = arc_length(curve, from, to);
        if curve.is_closed() {
            let (s0, s1) = curve.domain();
            let total = arc_length(curve, s0, s1);
            if total - direct < direct {
                return Self {
                    curve,
                    from,
                    to,
                    wraps: true,
                    length: total - direct,
                };
            }
        }
        Self {
            curve,
            from,
            to,
            wraps: false,
            length: direct,
        }
    }

    /// The point at `fraction` of the arc length from `from` (the paper's Eq. (4)).
    pub(crate) fn at(&self, fraction: f64) -> [f64; 3] {
        let c = self.curve;
        if !self.wraps {
            return c.point(parameter_at_length_fraction(
                c, self.from, self.to, fraction,
            ));
        }
        let (s0, s1) = c.domain();
        // Through the end of the domain (forwards) or through its start (backwards).
        let (seam_out, seam_in) = if self.from > self.to {
            (s1, s0)
        } else {
            (s0, s1)
        };
        let first = arc_length(c, self.from, seam_out);
        let target = fraction * self.length;
        if target <= first && first > 0.0 {
            c.point(parameter_at_length_fraction(
                c,
                self.from,
                seam_out,
                target / first,
            ))
        } else {
            let rest = (self.length - first).max(f64::MIN_POSITIVE);
            c.point(parameter_at_length_fraction(
                c,
                seam_in,
                self.to,
                (target - first) / rest,
            ))
        }
    }
}
