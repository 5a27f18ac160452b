//! IGES 5.3 input (fixed ASCII form): parsing, and conversion to exact NURBS.
//!
//! [`parse_iges`] splits the file into its 80-column records (section letter in column 73,
//! sequence number in columns 74–80), reads the Global section (delimiters, units, model
//! scale, resolution), the Directory Entry pairs and the free-format Parameter Data of every
//! entity (columns 1–64, back-pointer to the DE in columns 66–72; Hollerith strings `nH...`,
//! reals with `E` or `D` exponents), and returns each entity as a typed record
//! ([`EntityData`]). Nothing is evaluated by the parser. [`geometry_from_iges`] (or
//! [`read_iges_geometry`]) then converts the independent entities to exact rational NURBS
//! curves and surfaces (a [`crate::GeometryModel`]), reporting unsupported entities with their
//! type and line.
//!
//! Every error names the 1-based line of the file and what was expected and found.

mod constructions;
mod convert;
mod directory;
mod entities;
mod entity_parser;
mod global;
mod param_reader;
mod params;
mod sections;
mod tolerance;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub use convert::{geometry_from_iges, read_iges_geometry};
pub use directory::DirectoryEntry;
pub use entities::{BSplineCurveData, BSplineSurfaceData, EntityData};
pub use global::GlobalSection;
pub use params::{parse_int, parse_real, Param, ParamValue};
pub use tolerance::RECOGNITION_TOLERANCE;

/// Deepest chain of entity references accepted, and longest chain of 124 transformation
/// matrices (a trimmed surface of a surface of revolution of a composite of curves is 4
/// deep; real files stay far below this).
pub const MAX_NESTING: usize = 64;

/// Conversion visits an entity once per path of references that reaches it; it may visit
/// at most this many times the file's Parameter Data records (plus [`EXPANSION_MINIMUM`]).
/// Real files reference each entity from one or two parents.
pub const EXPANSION_FACTOR: usize = 64;

/// The expansion allowed whatever the file's size (small files may share a lot).
pub const EXPANSION_MINIMUM: usize = 100_000;

/// Errors of IGES reading. `line` is the 1-based line number in the file.
#[derive(Debug, thiserror::Error)]
pub enum IgesError {
    #[error("cannot read IGES file {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("IGES line {line}: expected {expected}, found {found}")]
    Syntax {
        line: usize,
        expected: String,
        found: String,
    },
    #[error(
        "IGES line {line}: bad section letter in column 73: expected {expected}, found {found:?}"
    )]
    Section {
        line: usize,
        expected: String,
        found: char,
    },
    #[error("IGES line {line}: sequence number of the {section} section (columns 74-80): expected {expected}, found {found:?}")]
    Sequence {
        line: usize,
        section: char,
        expected: u32,
        found: String,
    },
    #[error("IGES line {line}: parameter data back-pointer (columns 66-72): expected DE {expected}, found {found:?}")]
    BackPointer {
        line: usize,
        expected: u32,
        found: String,
    },
    #[error("IGES line {line}: entity type {entity_type} (DE {de}), parameter {index} ({name}): expected {expected}, found {found}")]
    Parameter {
        line: usize,
        de: u32,
        entity_type: i32,
        /// 0-based index after the entity type number.
        index: usize,
        name: &'static str,
        expected: &'static str,
        found: String,
    },
    /// An entity type that is not converted (or a form of it, e.g. a hyperbolic 104), as a
    /// model entity or referenced by one; `context` says which or why.
    #[error("IGES line {line}: entity type {entity_type} (DE {de}) is not supported{context}")]
    Unsupported {
        line: usize,
        de: u32,
        entity_type: i32,
        context: String,
    },
    /// An entity whose data do not describe valid geometry (zero radius, gaps between the
    /// members of a composite curve, a non-line axis, ...).
    #[error("IGES line {line}: entity type {entity_type} (DE {de}): {reason}")]
    Geometry {
        line: usize,
        de: u32,
        entity_type: i32,
        reason: String,
    },
    /// A 108 plane with no boundary, in a model with nothing else to size its patch by.
    #[error("IGES line {line}: plane (entity type 108, DE {de}) has no boundary and the model nothing else to bound it")]
    UnboundedPlane { line: usize, de: u32 },
    /// Directory-entry pointers that lead back to where they started (a trimmed surface
    /// whose surface is itself, a composite curve that contains itself, a 124 matrix whose
    /// own transformation leads back to it, ...).
    #[error(
        "IGES line {line}: entity type {entity_type} (DE {de}) refers to itself through DE {cycle} ({via})"
    )]
    ReferenceCycle {
        line: usize,
        de: u32,
        entity_type: i32,
        /// The DE numbers of the cycle, e.g. "7 -> 9 -> 7".
        cycle: String,
        /// Which pointers form the cycle.
        via: ReferenceKind,
    },
    /// References nested deeper than [`MAX_NESTING`] (no CAD system writes that; converting
    /// it would recurse without a useful bound).
    #[error(
        "IGES line {line}: entity type {entity_type} (DE {de}) nests {via} more than {max} deep"
    )]
    NestingTooDeep {
        line: usize,
        de: u32,
        entity_type: i32,
        max: usize,
        via: ReferenceKind,
    },
    /// Entities shared so often through references that converting them (each reference
    /// converts its target again) would take more than [`EXPANSION_FACTOR`] times the
    /// file's size: e.g. 60 nested composites each holding the next one twice, 2^60 curves.
    #[error("IGES line {line}: entity type {entity_type} (DE {de}): converting the references would repeat entities for more than {limit} parameter records (the file has {records})")]
    ExpansionTooLarge {
        line: usize,
        de: u32,
        entity_type: i32,
        limit: usize,
        /// Parameter Data records of the whole file.
        records: usize,
    },
}

/// The pointers a [`IgesError::ReferenceCycle`] or [`IgesError::NestingTooDeep`] follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReferenceKind {
    /// DE pointers in the parameter data (members, surfaces, boundaries, axes, ...).
    Parameter,
    /// Transformation matrix pointers (Directory Entry field 7).
    Transformation,
}

impl std::fmt::Display for ReferenceKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ReferenceKind::Parameter => "parameter pointers",
            ReferenceKind::Transformation => "transformation matrix pointers (DE field 7)",
        })
    }
}

impl IgesError {
    /// The 1-based file line the error is about (`None` for I/O errors).
    pub fn line(&self) -> Option<usize> {
        match self {
            IgesError::Io { .. } => None,
            IgesError::Syntax { line, .. }
            | IgesError::Section { line, .. }
            | IgesError::Sequence { line, .. }
            | IgesError::BackPointer { line, .. }
            | IgesError::Parameter { line, .. }
            | IgesError::Unsupported { line, .. }
            | IgesError::Geometry { line, .. }
            | IgesError::UnboundedPlane { line, .. }
            | IgesError::ReferenceCycle { line, .. }
            | IgesError::NestingTooDeep { line, .. }
            | IgesError::ExpansionTooLarge { line, .. } => Some(*line),
        }
    }
}

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

    /// Checks that the entities' references (composite members, trimmed surfaces' surfaces
    /// and boundaries, curves on surfaces, revolutions' axis and generatrix, ...) form no
    /// cycle and nest at most [`MAX_NESTING`] deep, so that converting them terminates with
    /// a bounded stack. Depth-first with an explicit stack: a file cannot drive it into a
    /// stack overflow. References to missing DEs are left to the conversion's errors.
    pub fn check_references(&self) -> Result<(), IgesError> {
        const NEW: u8 = 0;
        const OPEN: u8 = 1;
        const DONE: u8 = 2;
        let index = |de: u32| -> Option<usize> { self.entity(de).map(|_| (de as usize - 1) / 2) };
        let children: Vec<Vec<usize>> = self
            .entities
            .iter()
            .map(|e| e.kind.references().into_iter().filter_map(index).collect())
            .collect();
        let mut state = vec![NEW; self.entities.len()];
        let mut depth = vec![0usize; self.entities.len()];
        for root in 0..self.entities.len() {
            if state[root] != NEW {
                continue;
            }
            // (entity, next child to visit)
            let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
            state[root] = OPEN;
            while let Some(top) = stack.last_mut() {
                let node = top.0;
                if let Some(&child) = children[node].get(top.1) {
                    top.1 += 1;
                    match state[child] {
                        NEW => {
                            state[child] = OPEN;
                            stack.push((child, 0));
                        }
                        OPEN => return Err(self.cycle_error(&stack, child)),
                        _ => {}
                    }
                    continue;
                }
                let d = 1 + children[node].iter().map(|&c| depth[c]).max().unwrap_or(0);
                if d > MAX_NESTING {
                    let e = &self.entities[node];
                    return Err(IgesError::NestingTooDeep {
                        line: e.line,
                        de: e.de,
                        entity_type: e.type_number(),
                        max: MAX_NESTING,
                        via: ReferenceKind::Parameter,
                    });
                }
                depth[node] = d;
                state[node] = DONE;
                stack.pop();
            }
        }
        Ok(())
    }

    /// The error for the cycle closed by a reference to `back` from the top of `stack`.
    fn cycle_error(&self, stack: &[(usize, usize)], back: usize) -> IgesError {
        let path: Vec<usize> = stack.iter().map(|&(n, _)| n).collect();
        cycle_error(self, &path, back, ReferenceKind::Parameter)
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

/// `a ∘ b`: apply `b` first, then `a`.
fn compose(a: &[[f64; 4]; 3], b: &[[f64; 4]; 3]) -> [[f64; 4]; 3] {
    let mut c = [[0.0; 4]; 3];
    for i in 0..3 {
        for j in 0..4 {
            let mut s = if j == 3 { a[i][3] } else { 0.0 };
            for k in 0..3 {
                s += a[i][k] * b[k][j];
            }
            c[i][j] = s;
        }
    }
    c
}

/// Reads and parses an IGES file.
pub fn read_iges(path: impl AsRef<Path>) -> Result<IgesModel, IgesError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| IgesError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    // non-ASCII bytes are reported with their line by the parser
    parse_iges(&String::from_utf8_lossy(&bytes))
}

/// Parses the text of an IGES 5.3 file (fixed ASCII form).
pub fn parse_iges(text: &str) -> Result<IgesModel, IgesError> {
    let secs = sections::split_sections(text)?;
    let global = global::parse_global(&secs.global)?;
    let directory = directory::parse_directory(&secs.directory)?;
    let pdelim = global.parameter_delimiter as u8;
    let rdelim = global.record_delimiter as u8;
    let p = &secs.parameter;
    let mut entities = Vec::with_capacity(directory.len());
    let mut references = Vec::new();
    for de in directory {
        let first = de.parameter_pointer as usize;
        let count = de.parameter_line_count as usize;
        let p_end = p.len();
        if first == 0 || count == 0 || first - 1 + count > p_end {
            return Err(IgesError::Syntax {
                line: de.line,
                expected: format!(
                    "entity type {} (DE {}): parameter data records {}..{} (pointer, line count)",
                    de.entity_type,
                    de.de,
                    first,
                    (first + count).saturating_sub(1)
                ),
                found: format!("a Parameter Data section of {p_end} records"),
            });
        }
        let records = &p[first - 1..first - 1 + count];
        for r in records {
            let back = r.cols(66, 72);
            if back.trim().parse::<u32>().ok() != Some(de.de) {
                return Err(IgesError::BackPointer {
                    line: r.line,
                    expected: de.de,
                    found: back.to_string(),
                });
            }
        }
        let stream = params::Stream::from_records(records, 1, 64);
        let what = format!("entity type {} (DE {})", de.entity_type, de.de);
        let params = params::tokenize(&stream, 0, pdelim, rdelim, &what)?;
        let end_line = records[count - 1].line;
        let type_param = &params[0];
        if type_param.as_int() != Some(de.entity_type as i64)
            || type_param.value == ParamValue::Empty
        {
            return Err(IgesError::Parameter {
                line: type_param.line,
                de: de.de,
                entity_type: de.entity_type,
                index: 0,
                name: "entity type number",
                expected: "the entity type of the Directory Entry",
                found: type_param.describe(),
            });
        }
        let mut reader = param_reader::Reader::new(&params[1..], de.de, de.entity_type, end_line);
        let kind = entity_parser::parse_entity(de.entity_type, &mut reader)?;
        references.extend(reader.refs.iter().map(|r| (*r, de.de, de.entity_type)));
        entities.push(IgesEntity {
            de: de.de,
            kind,
            form: de.form,
            transform: (de.transform != 0).then_some(de.transform),
            line: de.line,
            parameter_line: records[0].line,
            directory: de,
        });
    }
    let start = secs
        .start
        .iter()
        .map(|r| r.cols(1, 72).trim_end().to_string())
        .collect();
    let model = IgesModel {
        start,
        global,
        entities,
    };
    validate(&model, &references)?;
    Ok(model)
}

/// Checks pointers: parameters point to existing entities, transformation pointers to 124
/// entities without cycles.
fn validate(
    model: &IgesModel,
    references: &[(param_reader::Reference, u32, i32)],
) -> Result<(), IgesError> {
    for (r, de, entity_type) in references {
        if model.entity(r.pointer).is_none() {
            return Err(IgesError::Parameter {
                line: r.line,
                de: *de,
                entity_type: *entity_type,
                index: r.index,
                name: r.name,
                expected: "a pointer to an existing Directory Entry (odd, in range)",
                found: r.pointer.to_string(),
            });
        }
    }
    check_transforms(model)
}

/// Checks the transformation pointers (DE field 7): each leads to a 124 matrix, whose own
/// field 7 leads to another or ends, without a cycle and at most [`MAX_NESTING`] matrices
/// long. Every entity is walked once (chain lengths are remembered), so a file of many long
/// chains costs linear time.
fn check_transforms(model: &IgesModel) -> Result<(), IgesError> {
    let n = model.entities.len();
    // matrices after an entity, `None` until known
    let mut length: Vec<Option<usize>> = vec![None; n];
    let mut on_path = vec![false; n];
    for start in 0..n {
        let mut path: Vec<usize> = Vec::new();
        let mut node = start;
        // walk until an entity whose chain length is known or that has no matrix
        let mut tail = loop {
            if let Some(known) = length[node] {
                break known;
            }
            path.push(node);
            on_path[node] = true;
            let e = &model.entities[node];
            let Some(t) = e.transform else {
                break 0;
            };
            let target = transform_target(model, e, t)?;
            if on_path[target] {
                return Err(cycle_error(
                    model,
                    &path,
                    target,
                    ReferenceKind::Transformation,
                ));
            }
            node = target;
        };
        // the walked entities have the chain below them plus their own matrix pointer
        for &k in path.iter().rev() {
            on_path[k] = false;
            tail += usize::from(model.entities[k].transform.is_some());
            if tail > MAX_NESTING {
                let e = &model.entities[k];
                return Err(IgesError::NestingTooDeep {
                    line: e.line,
                    de: e.de,
                    entity_type: e.type_number(),
                    max: MAX_NESTING,
                    via: ReferenceKind::Transformation,
                });
            }
            length[k] = Some(tail);
        }
    }
    Ok(())
}

/// The index of the 124 entity that `e`'s field 7 (`t`) points to.
fn transform_target(model: &IgesModel, e: &IgesEntity, t: u32) -> Result<usize, IgesError> {
    match model.entity(t) {
        Some(x) if matches!(x.kind, EntityData::TransformationMatrix { .. }) => {
            Ok((t as usize - 1) / 2)
        }
        other => Err(IgesError::Syntax {
            line: e.line,
            expected: format!(
                "DE {} field 7: a pointer to a 124 transformation matrix or 0",
                e.de
            ),
            found: match other {
                Some(x) => format!("DE {t} of entity type {}", x.type_number()),
                None => format!("DE {t}, which does not exist"),
            },
        }),
    }
}

/// The error for a cycle: `path` (entity indices) ends with an entity pointing back to
/// `back`, which is on it. Names the cycle from `back` round to itself.
fn cycle_error(model: &IgesModel, path: &[usize], back: usize, via: ReferenceKind) -> IgesError {
    let start = path.iter().position(|&n| n == back).unwrap_or(0);
    let des: Vec<String> = path[start..]
        .iter()
        .chain(std::iter::once(&back))
        .map(|&n| model.entities[n].de.to_string())
        .collect();
    let e = &model.entities[back];
    IgesError::ReferenceCycle {
        line: e.line,
        de: e.de,
        entity_type: e.type_number(),
        cycle: des.join(" -> "),
        via,
    }
}

#[cfg(test)]
#[path = "tests/mod_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "tests/cycles.rs"]
mod cycle_tests;

#[cfg(test)]
#[path = "tests/fuzz.rs"]
mod fuzz_tests;
