//! The conversion's shared state and steps: the budget of entity visits (so that shared
//! references cannot expand without bound), following a DE pointer to its entity, an
//! entity's own 124 transformation, and the errors that name the entity.

use std::cell::Cell;

use super::affine::{Affine, IDENTITY};
use super::entities::EntityData;
use super::error::IgesError;
use super::model::{IgesEntity, IgesModel};
use crate::model::EntityGeometry;
use crate::shapes::AnalyticShape;

/// One converted entity before naming: the IGES entity it is named after, a note for its
/// origin, its geometry and closed form.
pub(super) struct Converted<'a> {
    pub(super) entity: &'a IgesEntity,
    pub(super) note: String,
    pub(super) geometry: EntityGeometry,
    pub(super) analytic: Option<AnalyticShape>,
}

/// Converts the entities of one parsed file; the curve, surface and face conversions are
/// its methods.
pub(super) struct Converter<'a> {
    pub(super) model: &'a IgesModel,
    /// Parameter Data records of the entities visited so far (once per visit).
    spent: Cell<usize>,
    /// [`IgesModel::expansion_limit`]: acyclic references may still share entities so
    /// much that visiting each once per path would never end.
    limit: usize,
}

impl<'a> Converter<'a> {
    /// A converter with nothing visited yet and the file's expansion limit.
    pub(super) fn new(model: &'a IgesModel) -> Self {
        Converter {
            model,
            spent: Cell::new(0),
            limit: model.expansion_limit(),
        }
    }

    /// Counts a visit of `e` against the expansion limit.
    pub(super) fn visit(&self, e: &IgesEntity) -> Result<(), IgesError> {
        let records = (e.directory.parameter_line_count as usize).max(1);
        let spent = self.spent.get().saturating_add(records);
        self.spent.set(spent);
        if spent > self.limit {
            return Err(IgesError::ExpansionTooLarge {
                line: e.line,
                de: e.de,
                entity_type: e.type_number(),
                limit: self.limit,
                records: self.model.parameter_records(),
            });
        }
        Ok(())
    }

    /// The entity at DE `de`, referenced by `parent`; unsupported types are an error naming
    /// both. Every reference followed passes here, so the visits are counted here.
    pub(super) fn child(&self, de: u32, parent: &IgesEntity) -> Result<&'a IgesEntity, IgesError> {
        let e = self.model.entity(de).ok_or_else(|| {
            geometry_error(parent, format!("refers to DE {de}, which does not exist"))
        })?;
        self.visit(e)?;
        match e.kind {
            EntityData::Brep { .. } | EntityData::Unsupported { .. } => Err(unsupported(
                e,
                format!(
                    " (referenced by entity type {}, DE {}, line {})",
                    parent.type_number(),
                    parent.de,
                    parent.line
                ),
            )),
            _ => Ok(e),
        }
    }

    /// The entity's own transformation (its 124 chain), identity when it has none.
    pub(super) fn own_transform(&self, e: &IgesEntity) -> Affine {
        self.model.transform_of(e).unwrap_or(IDENTITY)
    }
}

/// The error for an entity of a type (or form) that is not converted; `context` says where
/// it was met.
pub(super) fn unsupported(e: &IgesEntity, context: String) -> IgesError {
    IgesError::Unsupported {
        line: e.line,
        de: e.de,
        entity_type: e.type_number(),
        context,
    }
}

/// The error for an entity whose data describe no valid geometry.
pub(super) fn geometry_error(e: &IgesEntity, reason: String) -> IgesError {
    IgesError::Geometry {
        line: e.line,
        de: e.de,
        entity_type: e.type_number(),
        reason,
    }
}
