//! A parsed IGES file: its entities in Directory Entry order, looked up by DE pointer, with
//! their chains of 124 transformation matrices composed.

use std::collections::BTreeMap;

use super::affine::compose;
use super::directory::DirectoryEntry;
use super::entities::EntityData;
use super::global::GlobalSection;
use super::limits::{EXPANSION_FACTOR, EXPANSION_MINIMUM};

/// One entity: its Directory Entry data and its typed parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct IgesEntity {
    /// DE sequence number of the entity's first Directory Entry record (odd); other
    /// entities point to it with this number.
    pub de: u32,
    /// The typed parameter record.
    pub kind: EntityData,
    /// Form number (DE field 15).
    pub form: i32,
    /// DE pointer of the 124 transformation matrix applied to this entity, if any.
    pub transform: Option<u32>,
    /// 1-based file line of the first Directory Entry record.
    pub line: usize,
    /// 1-based file line of the first Parameter Data record.
    pub parameter_line: usize,
    /// All fixed Directory Entry fields.
    pub directory: DirectoryEntry,
}

impl IgesEntity {
    /// The IGES entity type number.
    pub fn type_number(&self) -> i32 {
        self.directory.entity_type
    }

    /// Whether the entity is physically dependent on another (status subordinate switch 1
    /// or 3), e.g. the curves of a trimmed surface.
    pub fn is_subordinate(&self) -> bool {
        matches!(self.directory.status[1], 1 | 3)
    }
}

/// A parsed IGES file.
#[derive(Debug, Clone, PartialEq)]
pub struct IgesModel {
    /// The Start section text (columns 1–72 of each S record, right-trimmed).
    pub start: Vec<String>,
    pub global: GlobalSection,
    /// All entities in Directory Entry order (entity `i` has DE number `2 i + 1`).
    pub entities: Vec<IgesEntity>,
}

impl IgesModel {
    /// The entity with DE sequence number `de`.
    pub fn entity(&self, de: u32) -> Option<&IgesEntity> {
        if de & 1 == 0 {
            return None;
        }
        self.entities
            .get((de as usize).checked_sub(1)? / 2)
            .filter(|e| e.de == de)
    }

    /// The transformation of `entity` as `[R | T]` rows (`x' = R x + T`), composing the
    /// chain of 124 matrices (a 124 may itself point to another 124, applied after it);
    /// `None` when the entity has no transformation.
    pub fn transform_of(&self, entity: &IgesEntity) -> Option<[[f64; 4]; 3]> {
        let mut acc: Option<[[f64; 4]; 3]> = None;
        let mut next = entity.transform;
        let mut steps = 0;
        while let Some(de) = next {
            steps += 1;
            if steps > self.entities.len() {
                break; // the parser rejects cycles; a hand-built model must not loop forever
            }
            let e = self.entity(de)?;
            let EntityData::TransformationMatrix { matrix } = &e.kind else {
                return None;
            };
            acc = Some(match acc {
                None => *matrix,
                Some(a) => compose(matrix, &a),
            });
            next = e.transform;
        }
        acc
    }

    /// Parameter Data records a conversion may visit (see [`EXPANSION_FACTOR`]).
    pub fn expansion_limit(&self) -> usize {
        let records: usize = self.parameter_records();
        records
            .saturating_mul(EXPANSION_FACTOR)
            .saturating_add(EXPANSION_MINIMUM)
    }

    /// Parameter Data records of all entities.
    pub fn parameter_records(&self) -> usize {
        self.entities
            .iter()
            .map(|e| e.directory.parameter_line_count as usize)
            .sum()
    }

    /// Number of entities of each type.
    pub fn histogram(&self) -> BTreeMap<i32, usize> {
        let mut h = BTreeMap::new();
        for e in &self.entities {
            *h.entry(e.type_number()).or_insert(0) += 1;
        }
        h
    }

    /// The entities of one type.
    pub fn entities_of_type(&self, type_number: i32) -> impl Iterator<Item = &IgesEntity> {
        self.entities
            .iter()
            .filter(move |e| e.type_number() == type_number)
    }
}
