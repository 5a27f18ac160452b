//! The error type of the file formats.

use std::path::PathBuf;

/// Where in a file something went wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// 1-based line number (ASCII files).
    Line(usize),
    /// 0-based byte offset (binary files and sections).
    Byte(u64),
    /// End of the file.
    EndOfFile,
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Location::Line(l) => write!(f, "line {l}"),
            Location::Byte(b) => write!(f, "byte {b}"),
            Location::EndOfFile => f.write_str("end of file"),
        }
    }
}

/// Errors reading or writing mesh files. Messages name the file and the place.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// The operating system refused a read or write.
    #[error("{}: {source}", path.display())]
    Os {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The file's content is not what the format requires.
    #[error("{}: {location}: {message}", path.display())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// Where.
        location: Location,
        /// What was expected and what was found.
        message: String,
    },
    /// The file is well formed but describes a mesh hocurve cannot use.
    #[error("{}: {source}", path.display())]
    Mesh {
        /// The file.
        path: PathBuf,
        /// What is wrong with the mesh.
        #[source]
        source: hocurve_mesh::MeshError,
    },
    /// The requested output format is not known.
    #[error("{}: unknown output format (expected a .vtu or .msh file name)", path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The input format is not known.
    #[error("{}: unknown mesh format (expected a .msh or .vtu file name)", path.display())]
    UnknownInputFormat {
        /// The file.
        path: PathBuf,
    },
    /// Something hocurve cannot write (e.g. an order beyond a format's element types).
    #[error("{}: {message}", path.display())]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What.
        message: String,
    },
}
