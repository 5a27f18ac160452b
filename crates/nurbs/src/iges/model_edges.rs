//! The boundary curves of IGES faces, from which the CAD edges between them are found
//! ([`crate::face_edges`]): IGES 144 faces carry no shared topology, but each face's
//! boundary (its 142 curves on surface) holds model-space copies of its edges.

use super::converter::Converter;
use super::entities::EntityData;
use super::model::IgesEntity;
use crate::model::EntityGeometry;
use crate::NurbsCurve;

impl<'a> Converter<'a> {
    /// The model-space curves of face `e`'s boundary: for a 144 trimmed surface, the model
    /// curves of its outer and inner 142 entities, one per CAD edge (the members of a 102).
    /// Boundaries given only in parameter space, and any that do not convert, are left out
    /// (the seams along them are then traced, as for a model without edges).
    pub(super) fn face_edge_curves(&self, e: &'a IgesEntity) -> Vec<(String, NurbsCurve)> {
        let EntityData::TrimmedSurface { outer, inner, .. } = &e.kind else {
            return Vec::new();
        };
        let placed = self.own_transform(e);
        let mut out = Vec::new();
        for &de in outer.iter().chain(inner) {
            let Ok(boundary) = self.child(de, e) else {
                continue;
            };
            if let EntityData::CurveOnSurface {
                model_curve: None, ..
            } = boundary.kind
            {
                continue;
            }
            let Ok(curves) = self.curve_entities(boundary, &placed, "") else {
                continue;
            };
            for (k, c) in curves.into_iter().enumerate() {
                if let EntityGeometry::Curve(curve) = c.geometry {
                    let origin = format!(
                        "IGES boundary curve {} of entity 142 (DE {}, line {}) of entity 144 (DE {})",
                        k + 1,
                        boundary.de,
                        boundary.line,
                        e.de
                    );
                    out.push((origin, curve));
                }
            }
        }
        out
    }
}
