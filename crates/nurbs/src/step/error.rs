//! The errors of STEP reading and conversion, each naming the file line (and entity) it is
//! about.

use std::path::PathBuf;

/// Errors of STEP reading. `line` is the 1-based line of the file where the entity starts.
#[derive(Debug, thiserror::Error)]
pub enum StepError {
    #[error("cannot read STEP file {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("STEP line {line}: {message}")]
    Syntax { line: usize, message: String },
    #[error("STEP line {line}: entity #{id} is defined twice")]
    Duplicate { line: usize, id: u64 },
    #[error(
        "STEP entity #{id} ({name}, line {line}) refers to #{reference}, which is not in the file"
    )]
    MissingReference {
        id: u64,
        name: String,
        line: usize,
        reference: u64,
    },
    #[error("STEP entity #{id} ({name}, line {line}) is not supported{context}; supported faces lie on planes, cylinders, cones, spheres, tori, B-spline surfaces, surfaces of revolution and of linear extrusion, bounded by lines, circles, ellipses and B-spline curves")]
    Unsupported {
        id: u64,
        name: String,
        line: usize,
        context: String,
    },
    #[error("STEP entity #{id} ({name}, line {line}): {reason}")]
    Geometry {
        id: u64,
        name: String,
        line: usize,
        reason: String,
    },
    #[error("STEP entity #{id} (line {line}): reference chain deeper than {limit} (a cycle?)")]
    TooDeep { id: u64, line: usize, limit: usize },
    #[error("STEP #{id}: placed in the assembly more than {limit} times")]
    TooManyOccurrences { id: u64, limit: usize },
    #[error("the STEP file has no face (ADVANCED_FACE or FACE_SURFACE) and no edge: nothing to curve onto")]
    Empty,
}
