//! The errors of IGES reading and conversion, each naming the file line it is about.

use std::path::PathBuf;

/// Errors of IGES reading. `line` is the 1-based line number in the file.
#[derive(Debug, thiserror::Error)]
pub enum IgesError {
    #[error("cannot read IGES file {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("IGES entity {entity}: converting to millimetres failed: {reason}")]
    Units { entity: String, reason: String },
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
    /// References nested deeper than [`MAX_NESTING`](crate::iges::MAX_NESTING) (no CAD
    /// system writes that; converting it would recurse without a useful bound).
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
    /// converts its target again) would take more than
    /// [`EXPANSION_FACTOR`](crate::iges::EXPANSION_FACTOR) times the file's size: e.g. 60
    /// nested composites each holding the next one twice, 2^60 curves.
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
            IgesError::Io { .. } | IgesError::Units { .. } => None,
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
