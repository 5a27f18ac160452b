//! VTK XML unstructured grid (`.vtu`) reader for high-order meshes.
//!
//! Reads what [`crate::write_vtu_with`] writes (ASCII or inline base64) and what VTK's
//! `vtkXMLUnstructuredGridWriter` writes with any of its settings: `ascii`, inline `binary`
//! or `appended` data (raw or base64), uncompressed or compressed with
//! `vtkZLibDataCompressor` (the block header `[#blocks, block size, last block size,
//! compressed sizes…]`), `UInt32` or `UInt64` header words, little or big endian, several
//! pieces (concatenated). Point and cell data arrays are not read.
//!
//! Cells: `VTK_LINE` 3, `VTK_TRIANGLE` 5, `VTK_QUAD` 9, `VTK_TETRA` 10, `VTK_HEXAHEDRON` 12,
//! `VTK_WEDGE` 13; the Lagrange cells 68–73 of any complete order (from the point count;
//! a `HigherOrderDegrees` cell array, if present, must agree and be isotropic); the fixed
//! quadratic cells that are complete: `VTK_QUADRATIC_EDGE` 21, `VTK_QUADRATIC_TRIANGLE` 22,
//! `VTK_QUADRATIC_TETRA` 24, `VTK_BIQUADRATIC_QUAD` 28, `VTK_TRIQUADRATIC_HEXAHEDRON` 29,
//! `VTK_BIQUADRATIC_QUADRATIC_WEDGE` 32 (their points are ordered like the order-2 Lagrange
//! cells). Lagrange hexahedra of files older than version 2.1 get the old order of their
//! last two vertical edges. Cells of the top dimension (3 if any, else 2) are the mesh;
//! those one dimension lower become facets where they are faces (edges) of the cells; the
//! rest (vertices, lower dimensions, facets elsewhere) is ignored. Incomplete
//! (serendipity) cells, pyramids, Bézier and polyhedral cells are errors.
//!
//! One job a file: [`file`] reads the `<VTKFile>` settings and finds the appended data,
//! [`byte_source`] gives the bytes of binary data (raw or base64), [`blocks`] decodes a
//! data array's header and zlib blocks, [`arrays`] turns data arrays into numbers,
//! [`cell_types`] maps VTK cell types to shapes and point orders, [`cells`] assembles the
//! cells of all pieces; [`failure`] is what goes wrong before the file's path is attached.

mod arrays;
mod blocks;
mod byte_source;
mod cell_types;
mod cells;
mod failure;
mod file;

use std::path::Path;

use hocurve_mesh::{HighOrderMesh, MeshError};
use hocurve_nodes::NodeFamily;

use crate::error::{IoError, Location};
use crate::xml::{line_of, parse_document};

use file::VtkFile;

/// Reads a VTK XML unstructured grid of linear, quadratic or Lagrange cells.
pub fn read_vtu(path: &Path) -> Result<HighOrderMesh, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Os {
        path: path.to_path_buf(),
        source,
    })?;
    parse_vtu(&bytes, path)
}

/// [`read_vtu`] from bytes already in memory; `path` only names the file in errors.
///
/// Nodes are renumbered as by [`HighOrderMesh::from_cells`] (vertices first; points no
/// cell uses are dropped); cells keep their order in the file, their points reordered
/// into hocurve's canonical order on [`NodeFamily::Equispaced`] reference nodes.
pub fn parse_vtu(bytes: &[u8], path: &Path) -> Result<HighOrderMesh, IoError> {
    let malformed = |offset: Option<usize>, message: String| IoError::Malformed {
        path: path.to_path_buf(),
        location: offset.map_or(Location::EndOfFile, |o| Location::Line(line_of(bytes, o))),
        message,
    };
    let root = parse_document(bytes).map_err(|e| malformed(Some(e.offset), e.message))?;
    let file = VtkFile::new(bytes, &root).map_err(|e| malformed(e.offset, e.message))?;
    let cells = file
        .read_cells()
        .map_err(|e| malformed(e.offset, e.message))?;
    let built = HighOrderMesh::from_cells(
        cells.dim,
        cells.order,
        NodeFamily::Equispaced,
        &cells.points,
        &cells.cells,
        &cells.facets,
    );
    built.map_err(|source| match source {
        MeshError::NonConformingNode {
            what: "cell",
            index,
            node,
            other,
            ..
        } => malformed(
            None,
            format!(
                "cell {} has point {node} where a neighbouring cell has point {other} at a \
                 different position: the cells do not share their edge or face points",
                cells.cell_ids.get(index).copied().unwrap_or(index)
            ),
        ),
        source => IoError::Mesh {
            path: path.to_path_buf(),
            source,
        },
    })
}

#[cfg(test)]
#[path = "../tests/vtu_read.rs"]
mod tests;
