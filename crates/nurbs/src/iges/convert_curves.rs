//! Curve entities (100, 102, 104, 110, 126, 142) as exact NURBS: one joined curve where a
//! single one is needed (a generatrix, a directrix, a plane's boundary), or one model entity
//! per member of a composite; full 100 circles keep their closed form.

use super::affine::{
    apply, apply_linear, compose, similarity_scale, transform_curve, transform_shape, Affine,
};
use super::converter::{geometry_error, unsupported, Converted, Converter};
use super::curve_primitives::{circular_arc, elliptic_arc};
use super::entities::EntityData;
use super::error::IgesError;
use super::join::concatenate;
use super::model::IgesEntity;
use super::restrict::restrict_curve;
use super::tolerance::RECOGNITION_TOLERANCE;
use crate::conics::line_segment;
use crate::model::EntityGeometry;
use crate::shapes::AnalyticShape;
use crate::NurbsCurve;

/// A circle or circular arc placed in its parent's space by a similarity.
pub(super) struct PlacedCircle {
    pub(super) center: [f64; 3],
    pub(super) normal: [f64; 3],
    pub(super) radius: f64,
    pub(super) full: bool,
}

impl<'a> Converter<'a> {
    /// A curve entity as one NURBS in its parent's definition space (own transformation
    /// applied). Composite curves are joined.
    pub(super) fn curve(&self, e: &IgesEntity) -> Result<NurbsCurve, IgesError> {
        let fail = |reason: String| geometry_error(e, reason);
        let c = match &e.kind {
            EntityData::CircularArc {
                zt,
                center,
                start,
                end,
            } => circular_arc(*zt, *center, *start, *end).map_err(fail)?,
            EntityData::Line { start, end } => {
                line_segment(*start, *end).map_err(|x| fail(x.to_string()))?
            }
            EntityData::ConicArc {
                coefficients,
                zt,
                start,
                end,
            } => elliptic_arc(*coefficients, *zt, *start, *end)
                .map_err(|reason| unsupported(e, format!(": {reason}")))?,
            EntityData::BSplineCurve(d) => {
                let c = NurbsCurve::new(
                    d.m,
                    d.knots.clone(),
                    d.control_points.clone(),
                    d.weights.clone(),
                )
                .map_err(|x| fail(x.to_string()))?;
                restrict_curve(c, d.v0, d.v1).map_err(fail)?
            }
            EntityData::CompositeCurve { curves } => {
                let parts = curves
                    .iter()
                    .map(|&de| self.curve(self.child(de, e)?))
                    .collect::<Result<Vec<_>, _>>()?;
                let size = parts.iter().map(NurbsCurve::size).fold(0.0, f64::max);
                concatenate(&parts, RECOGNITION_TOLERANCE * size.max(1.0)).map_err(fail)?
            }
            EntityData::CurveOnSurface { model_curve, .. } => match model_curve {
                Some(de) => self.curve(self.child(*de, e)?)?,
                None => {
                    return Err(fail(
                        "curve on surface without a model-space curve (CPTR = 0)".into(),
                    ))
                }
            },
            other => {
                return Err(fail(format!(
                    "expected a curve (entity type 100, 102, 104, 110, 126 or 142), found type {}",
                    other.type_number()
                )))
            }
        };
        transform_curve(c, &self.own_transform(e)).map_err(fail)
    }

    /// A curve entity in model space (`to_model` maps its parent's space there), split into
    /// its members when it is a composite (recursively) or a curve on surface.
    pub(super) fn curve_entities(
        &self,
        e: &'a IgesEntity,
        to_model: &Affine,
        note: &str,
    ) -> Result<Vec<Converted<'a>>, IgesError> {
        let placed = compose(to_model, &self.own_transform(e));
        let mut out = Vec::new();
        match &e.kind {
            EntityData::CompositeCurve { curves } => {
                let note = format!(
                    "{note}, member of entity type 102 (DE {}, line {})",
                    e.de, e.line
                );
                for &de in curves {
                    out.extend(self.curve_entities(self.child(de, e)?, &placed, &note)?);
                }
            }
            EntityData::CurveOnSurface {
                model_curve: Some(de),
                ..
            } => {
                out.extend(self.curve_entities(self.child(*de, e)?, &placed, note)?);
            }
            _ => {
                let c = transform_curve(self.curve(e)?, to_model)
                    .map_err(|reason| geometry_error(e, reason))?;
                let analytic = self
                    .placed_circle(e)
                    .filter(|c| c.full)
                    .and_then(|c| AnalyticShape::new_circle(c.center, c.normal, c.radius).ok())
                    .and_then(|shape| transform_shape(shape, to_model));
                out.push(Converted {
                    entity: e,
                    note: note.to_string(),
                    geometry: EntityGeometry::Curve(c),
                    analytic,
                });
            }
        }
        Ok(out)
    }

    /// A 100 arc in its parent's space when its own transformation is a similarity.
    pub(super) fn placed_circle(&self, e: &IgesEntity) -> Option<PlacedCircle> {
        let EntityData::CircularArc {
            zt,
            center,
            start,
            end,
        } = e.kind
        else {
            return None;
        };
        let t = self.own_transform(e);
        let s = similarity_scale(&t)?;
        let radius = (start[0] - center[0]).hypot(start[1] - center[1]);
        let gap = (start[0] - end[0]).hypot(start[1] - end[1]);
        Some(PlacedCircle {
            center: apply(&t, [center[0], center[1], zt]),
            normal: apply_linear(&t, [0.0, 0.0, 1.0]),
            radius: s * radius,
            full: gap <= RECOGNITION_TOLERANCE * radius,
        })
    }
}
