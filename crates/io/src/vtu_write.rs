//! VTK XML unstructured grid (`.vtu`) writer for high-order meshes.
//!
//! Cells are written as VTK's linear cells at order 1 (`VTK_TRIANGLE` 5, `VTK_QUAD` 9,
//! `VTK_TETRA` 10, `VTK_HEXAHEDRON` 12, `VTK_WEDGE` 13) and as Lagrange cells above
//! (`VTK_LAGRANGE_TRIANGLE` 69 … `VTK_LAGRANGE_WEDGE` 73), their points in VTK's order (see
//! [`crate::ordering::vtk_lattice`]). Only the cells are written, not the facets. Complete
//! Lagrange cells of uniform order need no `HigherOrderDegrees` array: VTK derives the order
//! from the number of points.
//!
//! The file declares `version="2.2"`: VTK's reader renumbers Lagrange hexahedra of files
//! older than 2.1 (their last two vertical edges were swapped), and the orderings here are
//! the ones of 2.1 and later.
//!
//! # Why hand-written
//! The `vtkio` crate only writes XML files with its `xml` feature (quick-xml + serde), i.e.
//! not under `default-features = false`; it builds an owned copy of every array first (peak
//! memory ×2 on big meshes) and formats ASCII floats with `Display`, which is neither
//! compact nor under our control for golden files. The format itself is small: this writer
//! streams the arrays straight to the file, formats ASCII floats as Rust's shortest
//! round-trip representation (`{:?}`: exact, deterministic, platform independent), and
//! encodes binary arrays as inline base64 (uncompressed, little endian, `UInt64` size
//! headers), which every VTK ≥ 5 reader accepts. Same input, same bytes.

use rayon::prelude::*;
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::Shape;

use crate::atomic::write_atomically;
use crate::ordering::{vtk_cell_type, vtk_permutation};
use crate::IoError;

/// A named array of point or cell data: `components` values per point (cell), interleaved.
#[derive(Debug, Clone, Copy)]
pub struct DataArray<'a> {
    /// Array name shown in ParaView.
    pub name: &'a str,
    /// Values per point or cell (1 for a scalar, 3 for a vector).
    pub components: usize,
    /// `components × count` values, point (cell) after point (cell).
    pub values: &'a [f64],
}

/// How the arrays of a `.vtu` file are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VtuEncoding {
    /// Decimal text, one point, cell or tuple per line; floats in shortest round-trip form.
    /// Larger and slower, but readable and diff-able (golden files).
    Ascii,
    /// Raw little-endian bytes, base64-encoded inline. Compact and exact.
    #[default]
    Base64,
    /// Raw little-endian bytes in zlib-compressed blocks of 32 KiB (VTK's
    /// `vtkZLibDataCompressor`, the blocks compressed in parallel), base64-encoded inline.
    /// Exact; smaller, slower to write.
    Zlib,
}

/// Uncompressed size of a zlib block (VTK's default).
const ZLIB_BLOCK: usize = 1 << 15;

/// Writes `mesh` to `path` as a VTK XML unstructured grid, arrays in base64.
pub fn write_vtu(
    path: &Path,
    mesh: &HighOrderMesh,
    point_data: &[DataArray],
    cell_data: &[DataArray],
) -> Result<(), IoError> {
    write_vtu_with(path, mesh, point_data, cell_data, VtuEncoding::Base64)
}

/// Writes `mesh` to `path` as a VTK XML unstructured grid with the given encoding.
///
/// Checks everything before the file is touched: each point-data array must hold
/// `components × mesh.nodes.len()` values, each cell-data array `components ×
/// mesh.cells.len()`, names must be non-empty and distinct, values and coordinates finite;
/// every cell must have the node count of its shape at the mesh's order and node ids within
/// `mesh.nodes`. The file is written atomically (a failed write leaves no partial file).
pub fn write_vtu_with(
    path: &Path,
    mesh: &HighOrderMesh,
    point_data: &[DataArray],
    cell_data: &[DataArray],
    encoding: VtuEncoding,
) -> Result<(), IoError> {
    let bad = |message: String| IoError::Unsupported {
        path: path.to_path_buf(),
        message,
    };
    let cells = check_mesh(mesh).map_err(bad)?;
    check_arrays("point", point_data, mesh.nodes.len()).map_err(bad)?;
    check_arrays("cell", cell_data, mesh.cells.len()).map_err(bad)?;
    write_atomically(path, |w| {
        write_document(w, mesh, &cells, point_data, cell_data, encoding).map_err(|source| {
            IoError::Os {
                path: path.to_path_buf(),
                source,
            }
        })
    })
}

/// Per cell: its shape. Fails on anything a reader would choke on.
fn check_mesh(mesh: &HighOrderMesh) -> Result<Vec<Shape>, String> {
    if mesh.order == 0 {
        return Err("mesh order 0".into());
    }
    if mesh.family != hocurve_nodes::NodeFamily::Equispaced && mesh.order > 2 {
        // VTK places Lagrange nodes equispaced; other positions would change the geometry.
        return Err(format!(
            "the mesh has {} nodes; VTK Lagrange cells need equispaced nodes: resample it with HighOrderMesh::resampled (write_mesh does)",
            mesh.family
        ));
    }
    if let Some(i) = mesh
        .nodes
        .iter()
        .position(|x| x.iter().any(|c| !c.is_finite()))
    {
        return Err(format!(
            "node {i} has a non-finite coordinate {:?}",
            mesh.nodes[i]
        ));
    }
    let mut shapes = Vec::with_capacity(mesh.cells.len());
    for (c, cell) in mesh.cells.iter().enumerate() {
        let shape = cell.kind;
        let expected = shape.num_nodes(mesh.order);
        if cell.nodes.len() != expected {
            return Err(format!(
                "cell {c} ({}) has {} nodes, expected {expected} at order {}",
                shape.name(),
                cell.nodes.len(),
                mesh.order
            ));
        }
        if let Some(&n) = cell.nodes.iter().find(|&&n| n as usize >= mesh.nodes.len()) {
            return Err(format!(
                "cell {c} references node {n}, but the mesh has {} nodes",
                mesh.nodes.len()
            ));
        }
        shapes.push(shape);
    }
    Ok(shapes)
}

pub(crate) fn check_arrays(kind: &str, arrays: &[DataArray], count: usize) -> Result<(), String> {
    for (i, a) in arrays.iter().enumerate() {
        if a.name.is_empty() {
            return Err(format!("{kind} data array {i} has an empty name"));
        }
        if arrays[..i].iter().any(|b| b.name == a.name) {
            return Err(format!("two {kind} data arrays are named '{}'", a.name));
        }
        if a.components == 0 {
            return Err(format!("{kind} data '{}' has 0 components", a.name));
        }
        let expected = a.components.checked_mul(count);
        if expected != Some(a.values.len()) {
            return Err(format!(
                "{kind} data '{}' has {} values, expected {} ({} components × {count} {kind}s)",
                a.name,
                a.values.len(),
                a.components * count,
                a.components
            ));
        }
        if let Some(k) = a.values.iter().position(|v| !v.is_finite()) {
            return Err(format!(
                "{kind} data '{}' value {k} is not finite ({})",
                a.name, a.values[k]
            ));
        }
    }
    Ok(())
}

/// Escapes the five XML special characters of an attribute value.
fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

fn write_document<W: Write>(
    w: &mut W,
    mesh: &HighOrderMesh,
    shapes: &[Shape],
    point_data: &[DataArray],
    cell_data: &[DataArray],
    encoding: VtuEncoding,
) -> std::io::Result<()> {
    let p = mesh.order;
    let mut perms: HashMap<Shape, Vec<usize>> = HashMap::new();
    for &s in shapes {
        perms.entry(s).or_insert_with(|| vtk_permutation(s, p));
    }

    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"2.2\" byte_order=\"LittleEndian\" header_type=\"UInt64\"{}>",
        if encoding == VtuEncoding::Zlib {
            " compressor=\"vtkZLibDataCompressor\""
        } else {
            ""
        }
    )?;
    writeln!(w, "  <UnstructuredGrid>")?;
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        mesh.nodes.len(),
        mesh.cells.len()
    )?;

    for (tag, arrays) in [("PointData", point_data), ("CellData", cell_data)] {
        if arrays.is_empty() {
            continue;
        }
        writeln!(w, "      <{tag}>")?;
        for a in arrays {
            let mut array = Array::open(
                w,
                encoding,
                "Float64",
                Some(a.name),
                a.components,
                8 * a.values.len(),
            )?;
            for tuple in a.values.chunks(a.components) {
                for &v in tuple {
                    array.f64(v)?;
                }
                array.end_line()?;
            }
            array.close()?;
        }
        writeln!(w, "      </{tag}>")?;
    }

    writeln!(w, "      <Points>")?;
    let mut array = Array::open(w, encoding, "Float64", None, 3, 24 * mesh.nodes.len())?;
    for x in &mesh.nodes {
        for &c in x {
            array.f64(c)?;
        }
        array.end_line()?;
    }
    array.close()?;
    writeln!(w, "      </Points>")?;

    writeln!(w, "      <Cells>")?;
    let total: usize = mesh.cells.iter().map(|c| c.nodes.len()).sum();
    let mut array = Array::open(w, encoding, "Int64", Some("connectivity"), 1, 8 * total)?;
    for (cell, shape) in mesh.cells.iter().zip(shapes) {
        for &k in &perms[shape] {
            array.i64(i64::from(cell.nodes[k]))?;
        }
        array.end_line()?;
    }
    array.close()?;
    let mut array = Array::open(w, encoding, "Int64", Some("offsets"), 1, 8 * shapes.len())?;
    let mut offset = 0i64;
    for cell in &mesh.cells {
        offset += cell.nodes.len() as i64;
        array.i64(offset)?;
        array.end_line()?;
    }
    array.close()?;
    let mut array = Array::open(w, encoding, "UInt8", Some("types"), 1, shapes.len())?;
    for &shape in shapes {
        array.u8(vtk_cell_type(shape, p))?;
        array.end_line()?;
    }
    array.close()?;
    writeln!(w, "      </Cells>")?;

    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")?;
    Ok(())
}

/// One `<DataArray>` being written, ASCII or base64 (streamed, or collected to compress).
struct Array<'w, W: Write> {
    w: &'w mut W,
    base64: Option<Base64>,
    /// Zlib: the array's raw bytes, compressed on close.
    raw: Option<Vec<u8>>,
    /// ASCII: whether the current line already has a value.
    line_started: bool,
}

impl<'w, W: Write> Array<'w, W> {
    fn open(
        w: &'w mut W,
        encoding: VtuEncoding,
        ty: &str,
        name: Option<&str>,
        components: usize,
        num_bytes: usize,
    ) -> std::io::Result<Self> {
        write!(w, "        <DataArray type=\"{ty}\"")?;
        if let Some(name) = name {
            write!(w, " Name=\"{}\"", xml_escape(name))?;
        }
        if components != 1 {
            write!(w, " NumberOfComponents=\"{components}\"")?;
        }
        let format = match encoding {
            VtuEncoding::Ascii => "ascii",
            VtuEncoding::Base64 | VtuEncoding::Zlib => "binary",
        };
        writeln!(w, " format=\"{format}\">")?;
        let (base64, raw) = match encoding {
            VtuEncoding::Ascii => (None, None),
            VtuEncoding::Base64 => {
                write!(w, "          ")?;
                let mut b = Base64::new();
                // Uncompressed binary data is preceded by its size in bytes (header_type),
                // encoded in the same base64 stream.
                b.push(w, &(num_bytes as u64).to_le_bytes())?;
                (Some(b), None)
            }
            VtuEncoding::Zlib => (None, Some(Vec::with_capacity(num_bytes))),
        };
        Ok(Array {
            w,
            base64,
            raw,
            line_started: false,
        })
    }

    fn text(&mut self, args: std::fmt::Arguments) -> std::io::Result<()> {
        if self.line_started {
            self.w.write_all(b" ")?;
        } else {
            self.w.write_all(b"          ")?;
            self.line_started = true;
        }
        self.w.write_fmt(args)
    }

    /// One value: its little-endian `bytes` in binary encodings, `text` in ASCII.
    fn value(&mut self, bytes: &[u8], text: std::fmt::Arguments) -> std::io::Result<()> {
        if let Some(raw) = &mut self.raw {
            raw.extend_from_slice(bytes);
            return Ok(());
        }
        match &mut self.base64 {
            Some(b) => b.push(self.w, bytes),
            None => self.text(text),
        }
    }

    fn f64(&mut self, v: f64) -> std::io::Result<()> {
        self.value(&v.to_le_bytes(), format_args!("{v:?}"))
    }

    fn i64(&mut self, v: i64) -> std::io::Result<()> {
        self.value(&v.to_le_bytes(), format_args!("{v}"))
    }

    fn u8(&mut self, v: u8) -> std::io::Result<()> {
        self.value(&[v], format_args!("{v}"))
    }

    fn end_line(&mut self) -> std::io::Result<()> {
        if self.base64.is_none() && self.line_started {
            self.w.write_all(b"\n")?;
            self.line_started = false;
        }
        Ok(())
    }

    fn close(mut self) -> std::io::Result<()> {
        if let Some(raw) = self.raw.take() {
            write!(self.w, "          ")?;
            write_zlib_blocks(self.w, &raw)?;
            self.w.write_all(b"\n")?;
        } else if let Some(b) = self.base64.take() {
            b.finish(self.w)?;
            self.w.write_all(b"\n")?;
        } else {
            self.end_line()?;
        }
        writeln!(self.w, "        </DataArray>")
    }
}

/// `bytes` as VTK's zlib-compressed binary data, base64-encoded inline: the header
/// (block count, block size, size of the last block, then each block's compressed size, as
/// UInt64) and then the compressed blocks, each part base64-encoded on its own as VTK reads
/// it. Blocks are compressed in parallel; the bytes do not depend on the thread count.
fn write_zlib_blocks<W: Write>(w: &mut W, bytes: &[u8]) -> std::io::Result<()> {
    use flate2::{write::ZlibEncoder, Compression};
    let blocks: Vec<Vec<u8>> = bytes
        .par_chunks(ZLIB_BLOCK)
        .map(|block| {
            let mut e = ZlibEncoder::new(Vec::new(), Compression::default());
            e.write_all(block)?;
            e.finish()
        })
        .collect::<std::io::Result<_>>()?;
    let last = match bytes.len() % ZLIB_BLOCK {
        0 if !bytes.is_empty() => ZLIB_BLOCK,
        r => r,
    };
    let mut header = Base64::new();
    for v in [blocks.len(), ZLIB_BLOCK, last]
        .into_iter()
        .chain(blocks.iter().map(Vec::len))
    {
        header.push(w, &(v as u64).to_le_bytes())?;
    }
    header.finish(w)?;
    let mut data = Base64::new();
    for b in &blocks {
        data.push(w, b)?;
    }
    data.finish(w)
}

/// Streaming base64 encoder (standard alphabet, padded), one line.
struct Base64 {
    pending: [u8; 3],
    len: usize,
}

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

impl Base64 {
    fn new() -> Self {
        Base64 {
            pending: [0; 3],
            len: 0,
        }
    }

    fn push<W: Write>(&mut self, w: &mut W, bytes: &[u8]) -> std::io::Result<()> {
        for &b in bytes {
            self.pending[self.len] = b;
            self.len += 1;
            if self.len == 3 {
                w.write_all(&encode_group(self.pending, 3))?;
                self.len = 0;
            }
        }
        Ok(())
    }

    fn finish<W: Write>(self, w: &mut W) -> std::io::Result<()> {
        if self.len > 0 {
            let mut group = [0u8; 3];
            group[..self.len].copy_from_slice(&self.pending[..self.len]);
            w.write_all(&encode_group(group, self.len))?;
        }
        Ok(())
    }
}

/// Encodes up to three bytes (`n` of them meaningful) as four characters with padding.
fn encode_group(b: [u8; 3], n: usize) -> [u8; 4] {
    let v = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
    let c = |shift: u32| ALPHABET[((v >> shift) & 63) as usize];
    [
        c(18),
        c(12),
        if n > 1 { c(6) } else { b'=' },
        if n > 2 { c(0) } else { b'=' },
    ]
}

#[cfg(test)]
#[path = "tests/vtu_write.rs"]
mod tests;
