//! File formats for hocurve: Gmsh MSH in (4.1 and 2.2, ASCII and binary); high-order Gmsh
//! MSH 4.1 and VTK XML `.vtu` Lagrange cells out.

mod error;
mod msh_read;

pub use error::{IoError, Location};
pub use msh_read::{parse_msh, read_msh};
mod atomic;
mod msh_write;
pub mod ordering;
mod vtu_write;

pub use atomic::write_atomically;
pub use msh_write::write_msh;
pub use vtu_write::{write_vtu, write_vtu_with, DataArray, VtuEncoding};

use std::path::Path;

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::NodeFamily;

/// Writes `mesh` in the format its file name asks for: `.vtu` (VTK Lagrange cells) or `.msh`
/// (Gmsh MSH 4.1). Both formats define high-order elements on equispaced nodes, so a mesh
/// built on another node family is first resampled (same geometry, equispaced nodes).
pub fn write_mesh(path: &Path, mesh: &HighOrderMesh) -> Result<(), IoError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if extension != "vtu" && extension != "msh" {
        return Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
        });
    }
    let resampled;
    let mesh = if mesh.family == NodeFamily::Equispaced {
        mesh
    } else {
        resampled = mesh
            .resampled(NodeFamily::Equispaced)
            .map_err(|source| IoError::Mesh {
                path: path.to_path_buf(),
                source,
            })?;
        &resampled
    };
    if extension == "vtu" {
        write_vtu(path, mesh, &[], &[])
    } else {
        write_msh(path, mesh)
    }
}
