//! Names and origins of the converted entities: the Directory Entry label when it is
//! unique, made unique with the DE number otherwise.

use super::converter::Converted;
use super::model::IgesEntity;
use crate::model::GeometricEntity;

/// The DE label (with `.subscript` when the subscript is not 0), if any.
fn label_of(e: &IgesEntity) -> Option<String> {
    let label = e.directory.label.trim();
    match (label.is_empty(), e.directory.subscript) {
        (true, _) => None,
        (false, 0) => Some(label.to_string()),
        (false, s) => Some(format!("{label}.{s}")),
    }
}

/// Names: the label when it is unique in the model, `label#DE` when several entities share
/// it, `type#DE` without a label. Origins: `IGES entity <type> (DE <n>, line <l>)`.
pub(super) fn name_entities(converted: Vec<Converted<'_>>) -> Vec<GeometricEntity> {
    let labels: Vec<Option<String>> = converted.iter().map(|c| label_of(c.entity)).collect();
    converted
        .into_iter()
        .zip(&labels)
        .map(|(c, label)| {
            let e = c.entity;
            let name = match label {
                Some(l) if labels.iter().filter(|x| x.as_ref() == Some(l)).count() == 1 => {
                    l.clone()
                }
                Some(l) => format!("{l}#{}", e.de),
                None => format!("{}#{}", e.type_number(), e.de),
            };
            GeometricEntity {
                name,
                origin: format!(
                    "IGES entity {} (DE {}, line {}){}",
                    e.type_number(),
                    e.de,
                    e.line,
                    c.note
                ),
                geometry: c.geometry,
                analytic: c.analytic,
                samples: Default::default(),
                hulls: Default::default(),
            }
        })
        .collect()
}
