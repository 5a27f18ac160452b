//! File formats for hocurve: Gmsh MSH in (4.1 and 2.2, ASCII and binary; linear meshes to
//! curve, and complete high-order meshes to assess) and VTK XML `.vtu` in (linear,
//! quadratic and Lagrange cells, as hocurve or VTK write them); high-order Gmsh MSH (4.1 or
//! 2.2, ASCII or binary) and `.vtu` Lagrange cells (ASCII, base64 or zlib-compressed) out,
//! with point and cell data.
//!
//! # Example
//!
//! ```
//! use std::path::Path;
//! use hocurve_mesh::HighOrderMesh;
//! use hocurve_nodes::NodeFamily;
//! // Two triangles forming the unit square, as Gmsh 2.2 writes them.
//! let msh = "\
//! $MeshFormat
//! 2.2 0 8
//! $EndMeshFormat
//! $Nodes
//! 4
//! 1 0 0 0
//! 2 1 0 0
//! 3 1 1 0
//! 4 0 1 0
//! $EndNodes
//! $Elements
//! 2
//! 1 2 2 0 1 1 2 3
//! 2 2 2 0 1 1 3 4
//! $EndElements
//! ";
//! let linear = hocurve_io::parse_msh(msh.as_bytes(), Path::new("square.msh"))?;
//! assert_eq!((linear.vertices.len(), linear.cells.len()), (4, 2));
//! // Written at order 3 and read back: the same 16 nodes, bit for bit.
//! let cubic = HighOrderMesh::from_linear(&linear, 3, NodeFamily::Equispaced)?;
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("square.msh");
//! hocurve_io::write_mesh(&path, &cubic)?;
//! let back = hocurve_io::read_high_order_mesh(&path)?;
//! assert_eq!(back.nodes.len(), 16);
//! assert_eq!(back.nodes, cubic.nodes);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod error;
mod msh_read;

pub use error::{IoError, Location};
pub use msh_read::{parse_high_order_msh, parse_msh, read_high_order_msh, read_msh};
mod atomic;
mod msh_write;
pub mod ordering;
mod vtu_read;
mod vtu_write;
mod xml;

#[cfg(test)]
#[path = "tests/meshes.rs"]
mod test_meshes;

pub use atomic::{
    check_writable, exit_removing_temporary_files, remove_temporary_files, write_atomically,
    StagedOutputs, SyncedFile,
};
pub use msh_write::{write_msh, write_msh_as, write_msh_with, MshFormat, MshVersion};
pub use vtu_read::{parse_vtu, read_vtu};
pub use vtu_write::{write_vtu, write_vtu_with, DataArray, VtuEncoding};

use std::path::Path;

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::NodeFamily;

/// The lower-case extension of `path`, if it is one of `known`.
fn extension_of(path: &Path, known: &[&'static str]) -> Option<&'static str> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    known.iter().copied().find(|k| *k == extension)
}

/// Writes `mesh` in the format its file name asks for: `.vtu` (VTK Lagrange cells) or `.msh`
/// (Gmsh MSH 4.1). Both formats define high-order elements on equispaced nodes, so a mesh
/// built on another node family is first resampled (same geometry, equispaced nodes).
pub fn write_mesh(path: &Path, mesh: &HighOrderMesh) -> Result<(), IoError> {
    write_mesh_with(path, mesh, &[], &[])
}

/// [`write_mesh`] with point data (given per node of `mesh`) and cell data: `.vtu` arrays
/// (base64) or `.msh` `$NodeData` / `$ElementData` views (scalars and 3-vectors). When the
/// mesh is resampled to equispaced nodes, its point data is resampled the same way
/// ([`HighOrderMesh::resampled_point_values`]: each cell's Lagrange interpolant evaluated at
/// the new nodes, like the coordinates); cell data is written as given.
pub fn write_mesh_with(
    path: &Path,
    mesh: &HighOrderMesh,
    point_data: &[DataArray],
    cell_data: &[DataArray],
) -> Result<(), IoError> {
    write_mesh_as(path, mesh, point_data, cell_data, OutputFormat::default())
}

/// How [`write_mesh_as`] encodes each format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OutputFormat {
    /// For `.msh`: version and ASCII or binary.
    pub msh: MshFormat,
    /// For `.vtu`: ASCII, base64 or zlib-compressed base64.
    pub vtu: VtuEncoding,
}

/// [`write_mesh_with`] with the encoding of each format chosen by `format`.
pub fn write_mesh_as(
    path: &Path,
    mesh: &HighOrderMesh,
    point_data: &[DataArray],
    cell_data: &[DataArray],
    format: OutputFormat,
) -> Result<(), IoError> {
    let Some(extension) = extension_of(path, &["vtu", "msh"]) else {
        return Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
        });
    };
    let as_mesh_error = |source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    };
    let resampled;
    let resampled_values: Vec<Vec<f64>>;
    let resampled_arrays: Vec<DataArray>;
    let (mesh, point_data) = if mesh.family == NodeFamily::Equispaced {
        (mesh, point_data)
    } else {
        resampled = mesh
            .resampled(NodeFamily::Equispaced)
            .map_err(as_mesh_error)?;
        resampled_values = point_data
            .iter()
            .map(|a| {
                mesh.resampled_point_values(NodeFamily::Equispaced, a.components, a.values)
                    .map_err(|source| IoError::Unsupported {
                        path: path.to_path_buf(),
                        message: format!("point data '{}': {source}", a.name),
                    })
            })
            .collect::<Result<_, _>>()?;
        resampled_arrays = point_data
            .iter()
            .zip(&resampled_values)
            .map(|(a, values)| DataArray {
                name: a.name,
                components: a.components,
                values,
            })
            .collect();
        (&resampled, resampled_arrays.as_slice())
    };
    if extension == "vtu" {
        write_vtu_with(path, mesh, point_data, cell_data, format.vtu)
    } else {
        write_msh_as(path, mesh, point_data, cell_data, format.msh)
    }
}

/// Reads a high-order mesh for quality assessment, in the format its extension names:
/// `.msh` ([`read_high_order_msh`]) or `.vtu` ([`read_vtu`]).
pub fn read_high_order_mesh(path: &Path) -> Result<HighOrderMesh, IoError> {
    match extension_of(path, &["vtu", "msh"]) {
        Some("msh") => read_high_order_msh(path),
        Some(_) => read_vtu(path),
        None => Err(IoError::UnknownInputFormat {
            path: path.to_path_buf(),
        }),
    }
}
