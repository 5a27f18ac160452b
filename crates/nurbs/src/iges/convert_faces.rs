//! Faces bounded by curves: the boundary that the patch of a 144 trimmed plane must cover
//! (the trimming curves themselves are not kept), and the model-space boundary curves that
//! stand for each planar face of a 2D model.

use super::affine::{compose, Affine};
use super::converter::{geometry_error, Converted, Converter};
use super::entities::EntityData;
use super::error::IgesError;
use super::model::IgesEntity;
use super::plane_patch::model_plane;
use super::tolerance::RECOGNITION_TOLERANCE;
use crate::model::EntityGeometry;
use crate::vec3::{cross, dot, norm, sub};

impl<'a> Converter<'a> {
    /// The model-space points the patch of a 144 trimmed surface's `carrier` must cover:
    /// `cover` and, when the carrier is a plane, the control points of the model-space
    /// curves of its boundaries (`placed` maps the 144's space to model space). Boundaries
    /// only in parameter space have nothing to size the patch by.
    pub(super) fn trimmed_cover(
        &self,
        e: &IgesEntity,
        carrier: &IgesEntity,
        boundaries: impl Iterator<Item = u32>,
        placed: &Affine,
        cover: &[[f64; 3]],
    ) -> Result<Vec<[f64; 3]>, IgesError> {
        let mut cover = cover.to_vec();
        if matches!(carrier.kind, EntityData::Plane { .. }) {
            for de in boundaries {
                let boundary = self.child(de, e)?;
                if let EntityData::CurveOnSurface {
                    model_curve: None, ..
                } = boundary.kind
                {
                    continue; // parameter-space only: nothing to size the patch by
                }
                for c in self.curve_entities(boundary, placed, "")? {
                    if let EntityGeometry::Curve(c) = c.geometry {
                        cover.extend_from_slice(&c.control_points);
                    }
                }
            }
        }
        Ok(cover)
    }

    /// Whether the independent surfaces make a 2D model: there is at least one, each is a
    /// 108 plane (bare or under a 144) and all lie in one plane.
    pub(super) fn is_planar_model(&self, surfaces: &[&'a IgesEntity]) -> Result<bool, IgesError> {
        let mut planes = Vec::new();
        for &e in surfaces {
            let mut placed = self.own_transform(e);
            let mut carrier = e;
            if let EntityData::TrimmedSurface { surface, .. } = carrier.kind {
                carrier = self.child(surface, e)?;
                placed = compose(&placed, &self.own_transform(carrier));
            }
            let EntityData::Plane { coefficients, .. } = carrier.kind else {
                return Ok(false);
            };
            planes
                .push(model_plane(coefficients, &placed).map_err(|r| geometry_error(carrier, r))?);
        }
        let Some(&(o, [_, _, n])) = planes.first() else {
            return Ok(false);
        };
        let size = planes.iter().map(|p| norm(p.0)).fold(1.0, f64::max);
        Ok(planes.iter().all(|&(p, [_, _, m])| {
            norm(cross(n, m)) <= RECOGNITION_TOLERANCE
                && dot(sub(p, o), n).abs() <= RECOGNITION_TOLERANCE * size
        }))
    }

    /// The model-space boundary curves of a planar face (2D models).
    pub(super) fn face_boundary_curves(
        &self,
        e: &'a IgesEntity,
    ) -> Result<Vec<Converted<'a>>, IgesError> {
        let placed = self.own_transform(e);
        let note = format!(
            ", boundary of entity type {} (DE {})",
            e.type_number(),
            e.de
        );
        let mut boundaries = Vec::new();
        let mut plane = e;
        let mut plane_placed = placed;
        if let EntityData::TrimmedSurface {
            surface,
            outer,
            inner,
            ..
        } = &e.kind
        {
            for &de in outer.iter().chain(inner) {
                boundaries.push((self.child(de, e)?, placed));
            }
            plane = self.child(*surface, e)?;
            plane_placed = compose(&placed, &self.own_transform(plane));
        }
        if boundaries.is_empty() {
            if let EntityData::Plane {
                boundary: Some(de), ..
            } = plane.kind
            {
                boundaries.push((self.child(de, plane)?, plane_placed));
            }
        }
        if boundaries.is_empty() {
            return Err(geometry_error(
                e,
                "a planar face of a 2D model has no boundary curve".into(),
            ));
        }
        let mut out = Vec::new();
        for (b, to_model) in boundaries {
            if let EntityData::CurveOnSurface {
                model_curve: None, ..
            } = b.kind
            {
                return Err(geometry_error(
                    b,
                    "boundary of a planar face of a 2D model without a model-space curve (CPTR = 0)"
                        .into(),
                ));
            }
            out.extend(self.curve_entities(b, &to_model, &note)?);
        }
        Ok(out)
    }
}
