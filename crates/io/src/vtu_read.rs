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

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use hocurve_mesh::{ElementType, HighOrderElement, HighOrderMesh, MeshError};
use hocurve_nodes::{NodeFamily, Shape};

use crate::error::{IoError, Location};
use crate::ordering::vtk_permutation;
use crate::xml::{line_of, parse_document, XmlElement};

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

/// A failure at a byte offset of the file (None: no particular place).
#[derive(Debug)]
struct Fail {
    offset: Option<usize>,
    message: String,
}

type R<T> = Result<T, Fail>;

fn fail<T>(at: &XmlElement, message: impl Into<String>) -> R<T> {
    Err(Fail {
        offset: Some(at.offset),
        message: message.into(),
    })
}

/// What the cells of a file give, ready for [`HighOrderMesh::from_cells`].
struct Cells {
    dim: usize,
    order: usize,
    points: Vec<[f64; 3]>,
    cells: Vec<HighOrderElement>,
    /// File index (over all pieces) of each cell.
    cell_ids: Vec<usize>,
    facets: Vec<HighOrderElement>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum HeaderType {
    UInt32,
    UInt64,
}

/// The `VTKFile` element's settings and the appended data block.
struct VtkFile<'a, 'x> {
    bytes: &'a [u8],
    root: &'x XmlElement<'a>,
    grid: &'x XmlElement<'a>,
    big_endian: bool,
    header: HeaderType,
    zlib: bool,
    /// Version (major, minor).
    version: (u32, u32),
    /// Appended data: its bytes after the `_` marker, and whether base64.
    appended: Option<(&'a [u8], bool)>,
}

/// How a cell type's points map to a shape and order.
#[derive(Debug, Clone, Copy)]
enum CellKind {
    /// A shape of fixed order (linear and quadratic types).
    Fixed(Shape, usize),
    /// A Lagrange cell: the order follows from the point count.
    Lagrange(Shape),
    /// Vertex cells: ignored.
    Point,
}

fn cell_kind(t: i64) -> Result<CellKind, String> {
    Ok(match t {
        1 | 2 => CellKind::Point,
        3 => CellKind::Fixed(Shape::Line, 1),
        5 => CellKind::Fixed(Shape::Tri, 1),
        9 => CellKind::Fixed(Shape::Quad, 1),
        10 => CellKind::Fixed(Shape::Tet, 1),
        12 => CellKind::Fixed(Shape::Hex, 1),
        13 => CellKind::Fixed(Shape::Prism, 1),
        21 => CellKind::Fixed(Shape::Line, 2),
        22 => CellKind::Fixed(Shape::Tri, 2),
        24 => CellKind::Fixed(Shape::Tet, 2),
        28 => CellKind::Fixed(Shape::Quad, 2),
        29 => CellKind::Fixed(Shape::Hex, 2),
        32 => CellKind::Fixed(Shape::Prism, 2),
        68 => CellKind::Lagrange(Shape::Line),
        69 => CellKind::Lagrange(Shape::Tri),
        70 => CellKind::Lagrange(Shape::Quad),
        71 => CellKind::Lagrange(Shape::Tet),
        72 => CellKind::Lagrange(Shape::Hex),
        73 => CellKind::Lagrange(Shape::Prism),
        23 | 25 | 26 | 30 | 31 | 33 => {
            let name = match t {
                23 => "VTK_QUADRATIC_QUAD, 8 points",
                25 => "VTK_QUADRATIC_HEXAHEDRON, 20 points",
                26 => "VTK_QUADRATIC_WEDGE, 15 points",
                30 => "VTK_QUADRATIC_LINEAR_QUAD, 6 points",
                31 => "VTK_QUADRATIC_LINEAR_WEDGE, 12 points",
                _ => "VTK_BIQUADRATIC_QUADRATIC_HEXAHEDRON, 24 points",
            };
            return Err(format!(
                "cell type {t} ({name}): incomplete (serendipity) elements are not supported"
            ));
        }
        14 | 27 | 37 | 66 | 74 | 81 => {
            return Err(format!(
                "cell type {t} is a pyramid: pyramid elements are not supported"
            ))
        }
        75..=80 => {
            return Err(format!(
                "cell type {t} is a Bézier cell: only Lagrange cells are supported"
            ))
        }
        4 | 6 | 7 | 8 | 11 | 42 => {
            let name = match t {
                4 => "VTK_POLY_LINE",
                6 => "VTK_TRIANGLE_STRIP",
                7 => "VTK_POLYGON",
                8 => "VTK_PIXEL",
                11 => "VTK_VOXEL",
                _ => "VTK_POLYHEDRON",
            };
            return Err(format!("cell type {t} ({name}) is not supported"));
        }
        _ => return Err(format!("unknown or unsupported VTK cell type {t}")),
    })
}

impl<'a, 'x> VtkFile<'a, 'x> {
    fn new(bytes: &'a [u8], root: &'x XmlElement<'a>) -> R<Self> {
        if root.name != "VTKFile" {
            return fail(root, format!("expected <VTKFile>, found <{}>", root.name));
        }
        match root.attribute("type") {
            Some("UnstructuredGrid") => {}
            Some(other) => {
                return fail(
                    root,
                    format!("VTK file type {other} is not supported (expected UnstructuredGrid)"),
                )
            }
            None => return fail(root, "<VTKFile> has no type attribute"),
        }
        let big_endian = match root.attribute("byte_order") {
            None | Some("LittleEndian") => false,
            Some("BigEndian") => true,
            Some(other) => return fail(root, format!("unknown byte_order {other:?}")),
        };
        let header = match root.attribute("header_type") {
            None | Some("UInt32") => HeaderType::UInt32,
            Some("UInt64") => HeaderType::UInt64,
            Some(other) => return fail(root, format!("unknown header_type {other:?}")),
        };
        let zlib = match root.attribute("compressor") {
            None | Some("") => false,
            Some("vtkZLibDataCompressor") => true,
            Some(other) => {
                return fail(
                    root,
                    format!(
                        "compressor {other} is not supported (only vtkZLibDataCompressor); \
                         re-save the file with zlib compression or none"
                    ),
                )
            }
        };
        let version = root
            .attribute("version")
            .and_then(|v| {
                let mut parts = v.trim().splitn(2, '.');
                let major = parts.next()?.parse().ok()?;
                let minor = parts.next().map_or(Some(0), |m| m.parse().ok())?;
                Some((major, minor))
            })
            .unwrap_or((0, 1));
        let Some(grid) = root.child("UnstructuredGrid") else {
            return fail(root, "<VTKFile> has no <UnstructuredGrid>");
        };
        let appended = match root.child("AppendedData") {
            None => None,
            Some(a) => {
                let base64 = match a.attribute("encoding") {
                    Some("raw") => false,
                    Some("base64") => true,
                    other => {
                        return fail(
                            a,
                            format!("<AppendedData> encoding {other:?} (expected raw or base64)"),
                        )
                    }
                };
                let content = bytes.get(a.content.clone()).unwrap_or(&[]);
                let Some(k) = content.iter().position(|&c| c == b'_') else {
                    return fail(a, "<AppendedData> has no '_' marker before its data");
                };
                Some((&content[k + 1..], base64))
            }
        };
        Ok(VtkFile {
            bytes,
            root,
            grid,
            big_endian,
            header,
            zlib,
            version,
            appended,
        })
    }

    fn read_cells(&self) -> R<Cells> {
        let mut points: Vec<[f64; 3]> = Vec::new();
        // (file cell index, shape, order, points in canonical order)
        let mut elements: Vec<(usize, Shape, usize, Vec<u32>)> = Vec::new();
        let mut permutations: HashMap<(Shape, usize, bool), Vec<usize>> = HashMap::new();
        let mut cell_base = 0usize;
        let pieces: Vec<&XmlElement> = self.grid.children_named("Piece").collect();
        if pieces.is_empty() {
            return fail(self.grid, "<UnstructuredGrid> has no <Piece>");
        }
        for piece in pieces {
            let count = |name: &str| -> R<usize> {
                match piece.attribute(name).map(|v| v.trim().parse::<usize>()) {
                    Some(Ok(n)) => Ok(n),
                    Some(Err(_)) => fail(piece, format!("<Piece> {name} is not a count")),
                    None => fail(piece, format!("<Piece> has no {name}")),
                }
            };
            let num_points = count("NumberOfPoints")?;
            let num_cells = count("NumberOfCells")?;
            let point_base = points.len();
            let Some(point_array) = piece.child("Points").and_then(|p| p.child("DataArray")) else {
                return fail(piece, "<Piece> has no <Points> <DataArray>");
            };
            let components = point_array
                .attribute("NumberOfComponents")
                .map_or(Ok(1), |c| c.trim().parse::<usize>())
                .or_else(|_| fail(point_array, "NumberOfComponents is not a count"))?;
            if components != 3 {
                return fail(
                    point_array,
                    format!("points have {components} components, expected 3"),
                );
            }
            let coords = self.floats(point_array, num_points.saturating_mul(3))?;
            points.extend(coords.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));

            let Some(cells) = piece.child("Cells") else {
                return fail(piece, "<Piece> has no <Cells>");
            };
            let array = |name: &str| -> R<&XmlElement> {
                cells
                    .children_named("DataArray")
                    .find(|a| a.attribute("Name") == Some(name))
                    .map_or_else(
                        || fail(cells, format!("<Cells> has no DataArray named {name}")),
                        Ok,
                    )
            };
            let offsets_array = array("offsets")?;
            let mut offsets = self.integers(offsets_array, None)?;
            // Either the end of each cell, or (VTK ≥ 9 internal layout) a leading 0 too.
            if offsets.len() == num_cells + 1 && offsets.first() == Some(&0) {
                offsets.remove(0);
            }
            if offsets.len() != num_cells {
                return fail(
                    offsets_array,
                    format!("offsets has {} values for {num_cells} cells", offsets.len()),
                );
            }
            let types_array = array("types")?;
            let types = self.integers(types_array, Some(num_cells))?;
            let connectivity_array = array("connectivity")?;
            let total = offsets.last().copied().unwrap_or(0);
            let total = usize::try_from(total)
                .or_else(|_| fail(offsets_array, format!("negative offset {total}")))?;
            let connectivity = self.integers(connectivity_array, Some(total))?;
            let degrees = match piece.child("CellData").and_then(|d| {
                d.children_named("DataArray")
                    .find(|a| a.attribute("Name") == Some("HigherOrderDegrees"))
            }) {
                Some(a) => Some((a, self.integers(a, Some(num_cells.saturating_mul(3)))?)),
                None => None,
            };

            let mut start = 0usize;
            for (i, (&end, &t)) in offsets.iter().zip(&types).enumerate() {
                let id = cell_base + i;
                let end = match usize::try_from(end) {
                    Ok(e) if e >= start && e <= connectivity.len() => e,
                    _ => {
                        return fail(
                            offsets_array,
                            format!(
                                "offset {end} of cell {id} is out of order or beyond the {} \
                                 connectivity entries",
                                connectivity.len()
                            ),
                        )
                    }
                };
                let ids = &connectivity[start..end];
                start = end;
                let kind =
                    cell_kind(t).or_else(|m| fail(types_array, format!("cell {id}: {m}")))?;
                let (shape, order) = match kind {
                    CellKind::Point => continue,
                    CellKind::Fixed(shape, order) => (shape, order),
                    CellKind::Lagrange(shape) => {
                        let Some(order) = (1..=NodeFamily::Equispaced.max_order())
                            .find(|&p| shape.num_nodes(p) == ids.len())
                        else {
                            return fail(
                                connectivity_array,
                                format!(
                                    "Lagrange {} cell {id} has {} points, which is no complete \
                                     order (orders up to {} are supported)",
                                    shape.name(),
                                    ids.len(),
                                    NodeFamily::Equispaced.max_order()
                                ),
                            );
                        };
                        (shape, order)
                    }
                };
                if ids.len() != shape.num_nodes(order) {
                    return fail(
                        connectivity_array,
                        format!(
                            "cell {id} (type {t}) has {} points, expected {}",
                            ids.len(),
                            shape.num_nodes(order)
                        ),
                    );
                }
                if let (Some((array, d)), CellKind::Lagrange(_)) = (&degrees, kind) {
                    let given = &d[3 * i..3 * i + 3];
                    if given[..shape.dim()].iter().any(|&g| g != order as i64) {
                        return fail(
                            array,
                            format!(
                                "HigherOrderDegrees of cell {id} are {given:?}, but its {} \
                                 points make a complete order-{order} {}: only isotropic \
                                 complete cells are supported",
                                ids.len(),
                                shape.name()
                            ),
                        );
                    }
                }
                let old_hex = shape == Shape::Hex && order >= 2 && self.version < (2, 1);
                let perm = permutations
                    .entry((shape, order, old_hex))
                    .or_insert_with(|| vtk_order(shape, order, old_hex));
                let mut nodes = vec![0u32; ids.len()];
                for (&k, &v) in perm.iter().zip(ids) {
                    let global = usize::try_from(v)
                        .ok()
                        .filter(|&v| v < num_points)
                        .and_then(|v| u32::try_from(point_base + v).ok());
                    let Some(global) = global else {
                        return fail(
                            connectivity_array,
                            format!(
                                "cell {id} references point {v}, but the piece has {num_points} points"
                            ),
                        );
                    };
                    nodes[k] = global;
                }
                elements.push((id, shape, order, nodes));
            }
            cell_base += num_cells;
        }

        let dim = if elements.iter().any(|e| e.1.dim() == 3) {
            3
        } else if elements.iter().any(|e| e.1.dim() == 2) {
            2
        } else {
            return fail(
                self.root,
                "the file has no 2D or 3D cells (hocurve meshes are 2D or 3D)",
            );
        };
        let mut order = None;
        let mut out = Cells {
            dim,
            order: 1,
            points,
            cells: Vec::new(),
            cell_ids: Vec::new(),
            facets: Vec::new(),
        };
        for (id, shape, p, nodes) in elements {
            if shape.dim() + 1 < dim {
                continue;
            }
            match order {
                None => order = Some((p, id)),
                Some((q, first)) if q != p => {
                    return Err(Fail {
                        offset: Some(self.grid.offset),
                        message: format!(
                            "mixed element orders: cell {id} is of order {p} but cell {first} \
                             is of order {q}; a hocurve mesh has a single order"
                        ),
                    })
                }
                Some(_) => {}
            }
            let element = HighOrderElement {
                kind: ElementType::from_shape(shape),
                nodes,
                entity: 0,
            };
            if shape.dim() == dim {
                out.cells.push(element);
                out.cell_ids.push(id);
            } else {
                out.facets.push(element);
            }
        }
        out.order = order.map_or(1, |(p, _)| p);
        Ok(out)
    }

    /// The decoded bytes of a binary or appended `DataArray`.
    fn raw_bytes(&self, array: &XmlElement) -> R<Vec<u8>> {
        let format = array.attribute("format").unwrap_or("ascii");
        let inline;
        let mut source: Box<dyn ByteSource + '_> = match format {
            "binary" => {
                inline = array.text_content(self.bytes);
                Box::new(Base64Source::new(&inline))
            }
            "appended" => {
                let Some((data, base64)) = self.appended else {
                    return fail(
                        array,
                        "format=\"appended\" but the file has no <AppendedData>",
                    );
                };
                let offset = array
                    .attribute("offset")
                    .and_then(|o| o.trim().parse::<usize>().ok())
                    .map_or_else(
                        || fail(array, "appended DataArray without a valid offset"),
                        Ok,
                    )?;
                let Some(at) = data.get(offset..) else {
                    return fail(
                        array,
                        format!(
                            "offset {offset} is beyond the {} bytes of appended data",
                            data.len()
                        ),
                    );
                };
                if base64 {
                    Box::new(Base64Source::new(at))
                } else {
                    Box::new(RawSource { data: at, pos: 0 })
                }
            }
            other => return fail(array, format!("unknown DataArray format {other:?}")),
        };
        self.read_block(source.as_mut()).map_err(|message| Fail {
            offset: Some(array.offset),
            message: format!("DataArray {}: {message}", array_name(array)),
        })
    }

    /// Reads one array (header + data, compressed or not) from a byte source.
    fn read_block(&self, source: &mut dyn ByteSource) -> Result<Vec<u8>, String> {
        let word = match self.header {
            HeaderType::UInt32 => 4,
            HeaderType::UInt64 => 8,
        };
        let read_word = |source: &mut dyn ByteSource| -> Result<u64, String> {
            let b = source.take(word)?;
            let mut v = [0u8; 8];
            if self.big_endian {
                v[8 - word..].copy_from_slice(&b);
                Ok(u64::from_be_bytes(v))
            } else {
                v[..word].copy_from_slice(&b);
                Ok(u64::from_le_bytes(v))
            }
        };
        let too_big = |n: u64| format!("announced size {n} is beyond what the file can hold");
        if !self.zlib {
            let n = read_word(source)?;
            let n = usize::try_from(n).map_err(|_| too_big(n))?;
            if n > source.left_upper_bound() {
                return Err(too_big(n as u64));
            }
            return source.take(n);
        }
        let blocks = read_word(source)?;
        let block_size = read_word(source)?;
        let last_size = read_word(source)?;
        let blocks = usize::try_from(blocks)
            .ok()
            .filter(|&b| b.saturating_mul(word) <= source.left_upper_bound())
            .ok_or_else(|| format!("compression header announces {blocks} blocks"))?;
        let mut compressed = Vec::with_capacity(blocks);
        for _ in 0..blocks {
            compressed.push(read_word(source)?);
        }
        let mut out = Vec::new();
        for (i, &c) in compressed.iter().enumerate() {
            let c = usize::try_from(c)
                .ok()
                .filter(|&c| c <= source.left_upper_bound())
                .ok_or_else(|| too_big(c))?;
            let data = source.take(c)?;
            let expected = if i + 1 == blocks && last_size != 0 {
                last_size
            } else {
                block_size
            };
            let before = out.len();
            flate2::read::ZlibDecoder::new(data.as_slice())
                .take(expected)
                .read_to_end(&mut out)
                .map_err(|e| format!("zlib block {i} of {blocks} does not decompress: {e}"))?;
            if (out.len() - before) as u64 != expected {
                return Err(format!(
                    "zlib block {i} of {blocks} decompresses to {} bytes, the header says {expected}",
                    out.len() - before
                ));
            }
        }
        Ok(out)
    }

    /// Values of a numeric array as f64, `expected` of them.
    fn floats(&self, array: &XmlElement, expected: usize) -> R<Vec<f64>> {
        let ty = array.attribute("type").unwrap_or("");
        let values: Vec<f64> = if array.attribute("format").unwrap_or("ascii") == "ascii" {
            let text = array.text_content(self.bytes);
            let text: &[u8] = &text;
            let mut out = Vec::with_capacity(expected.min(text.len() / 2 + 1));
            for token in text
                .split(|c| c.is_ascii_whitespace())
                .filter(|t| !t.is_empty())
            {
                match std::str::from_utf8(token)
                    .ok()
                    .and_then(|t| t.parse::<f64>().ok())
                {
                    Some(v) => out.push(v),
                    None => {
                        return fail(
                            array,
                            format!(
                                "DataArray {}: '{}' is not a number",
                                array_name(array),
                                String::from_utf8_lossy(token)
                            ),
                        )
                    }
                }
            }
            out
        } else {
            let bytes = self.raw_bytes(array)?;
            let big = self.big_endian;
            match ty {
                "Float64" => convert::<8, _>(&bytes, big, f64::from_le_bytes, f64::from_be_bytes),
                "Float32" => convert::<4, _>(
                    &bytes,
                    big,
                    |b| f64::from(f32::from_le_bytes(b)),
                    |b| f64::from(f32::from_be_bytes(b)),
                ),
                _ => Some(
                    self.binary_integers(array, &bytes)?
                        .into_iter()
                        .map(|v| v as f64)
                        .collect(),
                ),
            }
            .ok_or_else(|| Fail {
                offset: Some(array.offset),
                message: format!(
                    "DataArray {}: {} bytes are not a whole number of {ty} values",
                    array_name(array),
                    bytes.len()
                ),
            })?
        };
        if values.len() != expected {
            return fail(
                array,
                format!(
                    "DataArray {} has {} values, expected {expected}",
                    array_name(array),
                    values.len()
                ),
            );
        }
        Ok(values)
    }

    /// Values of an integer array, `expected` of them if given.
    fn integers(&self, array: &XmlElement, expected: Option<usize>) -> R<Vec<i64>> {
        let values = if array.attribute("format").unwrap_or("ascii") == "ascii" {
            let text = array.text_content(self.bytes);
            let text: &[u8] = &text;
            let mut out = Vec::new();
            for token in text
                .split(|c| c.is_ascii_whitespace())
                .filter(|t| !t.is_empty())
            {
                match std::str::from_utf8(token)
                    .ok()
                    .and_then(|t| t.parse::<i64>().ok())
                {
                    Some(v) => out.push(v),
                    None => {
                        return fail(
                            array,
                            format!(
                                "DataArray {}: '{}' is not an integer",
                                array_name(array),
                                String::from_utf8_lossy(token)
                            ),
                        )
                    }
                }
            }
            out
        } else {
            let bytes = self.raw_bytes(array)?;
            self.binary_integers(array, &bytes)?
        };
        if let Some(n) = expected {
            if values.len() != n {
                return fail(
                    array,
                    format!(
                        "DataArray {} has {} values, expected {n}",
                        array_name(array),
                        values.len()
                    ),
                );
            }
        }
        Ok(values)
    }

    fn binary_integers(&self, array: &XmlElement, bytes: &[u8]) -> R<Vec<i64>> {
        let ty = array.attribute("type").unwrap_or("");
        let big = self.big_endian;
        let values = match ty {
            "Int8" => convert::<1, _>(
                bytes,
                big,
                |b| i64::from(i8::from_le_bytes(b)),
                |b| i64::from(i8::from_be_bytes(b)),
            ),
            "UInt8" => convert::<1, _>(bytes, big, |b| i64::from(b[0]), |b| i64::from(b[0])),
            "Int16" => convert::<2, _>(
                bytes,
                big,
                |b| i64::from(i16::from_le_bytes(b)),
                |b| i64::from(i16::from_be_bytes(b)),
            ),
            "UInt16" => convert::<2, _>(
                bytes,
                big,
                |b| i64::from(u16::from_le_bytes(b)),
                |b| i64::from(u16::from_be_bytes(b)),
            ),
            "Int32" => convert::<4, _>(
                bytes,
                big,
                |b| i64::from(i32::from_le_bytes(b)),
                |b| i64::from(i32::from_be_bytes(b)),
            ),
            "UInt32" => convert::<4, _>(
                bytes,
                big,
                |b| i64::from(u32::from_le_bytes(b)),
                |b| i64::from(u32::from_be_bytes(b)),
            ),
            "Int64" => convert::<8, _>(bytes, big, i64::from_le_bytes, i64::from_be_bytes),
            // Values beyond i64::MAX become negative and are rejected as ids and offsets.
            "UInt64" => convert::<8, _>(
                bytes,
                big,
                |b| u64::from_le_bytes(b) as i64,
                |b| u64::from_be_bytes(b) as i64,
            ),
            other => {
                return fail(
                    array,
                    format!(
                        "DataArray {} has type {other:?}, expected an integer type",
                        array_name(array)
                    ),
                )
            }
        };
        values.ok_or_else(|| Fail {
            offset: Some(array.offset),
            message: format!(
                "DataArray {}: {} bytes are not a whole number of {ty} values",
                array_name(array),
                bytes.len()
            ),
        })
    }
}

fn array_name<'b>(array: &'b XmlElement) -> &'b str {
    array.attribute("Name").unwrap_or("(unnamed)")
}

/// Splits `bytes` into `N`-byte values; None if the length is not a multiple of `N`.
fn convert<const N: usize, T>(
    bytes: &[u8],
    big_endian: bool,
    le: impl Fn([u8; N]) -> T,
    be: impl Fn([u8; N]) -> T,
) -> Option<Vec<T>> {
    let chunks = bytes.chunks_exact(N);
    if !chunks.remainder().is_empty() {
        return None;
    }
    Some(
        chunks
            .map(|c| {
                let mut a = [0u8; N];
                a.copy_from_slice(c);
                if big_endian {
                    be(a)
                } else {
                    le(a)
                }
            })
            .collect(),
    )
}

/// The point order of a VTK cell as a permutation into hocurve's canonical order.
/// `old_hex`: a Lagrange hexahedron of a file older than version 2.1, whose vertical edges
/// 10 and 11 were (3, 7) and (2, 6) instead of (2, 6) and (3, 7).
fn vtk_order(shape: Shape, order: usize, old_hex: bool) -> Vec<usize> {
    let mut perm = vtk_permutation(shape, order);
    if old_hex {
        let n = order - 1;
        let (a, b) = (8 + 10 * n, 8 + 11 * n);
        let (first, second) = perm.split_at_mut(b);
        first[a..b].swap_with_slice(&mut second[..n]);
    }
    perm
}

/// Where the bytes of an array come from.
trait ByteSource {
    /// The next `n` bytes.
    fn take(&mut self, n: usize) -> Result<Vec<u8>, String>;
    /// No more bytes than this are left.
    fn left_upper_bound(&self) -> usize;
}

struct RawSource<'a> {
    data: &'a [u8],
    pos: usize,
}

impl ByteSource for RawSource<'_> {
    fn take(&mut self, n: usize) -> Result<Vec<u8>, String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len());
        match end {
            Some(end) => {
                let out = self.data[self.pos..end].to_vec();
                self.pos = end;
                Ok(out)
            }
            None => Err(format!(
                "unexpected end of the appended data (needed {n} more bytes, {} left)",
                self.data.len() - self.pos
            )),
        }
    }

    fn left_upper_bound(&self) -> usize {
        self.data.len() - self.pos
    }
}

/// Base64 text decoded group by group: each group of four characters gives one to three
/// bytes (padding `=` ends a group early, and may appear in the middle of the text, where
/// VTK encodes a header and its data separately). Whitespace is skipped; decoding stops at
/// the first `<` or at the end of the input.
struct Base64Source<'a> {
    text: &'a [u8],
    pos: usize,
    /// Decoded but not yet taken.
    pending: Vec<u8>,
}

impl<'a> Base64Source<'a> {
    fn new(text: &'a [u8]) -> Self {
        Base64Source {
            text,
            pos: 0,
            pending: Vec::new(),
        }
    }

    /// Decodes the next group into `pending`; false at the end of the data.
    fn next_group(&mut self) -> Result<bool, String> {
        let mut group = [0u8; 4];
        let mut n = 0;
        while n < 4 {
            let Some(&c) = self.text.get(self.pos) else {
                break;
            };
            if c == b'<' {
                break;
            }
            self.pos += 1;
            if c.is_ascii_whitespace() {
                continue;
            }
            group[n] = c;
            n += 1;
        }
        if n == 0 {
            return Ok(false);
        }
        if n < 4 {
            return Err(format!(
                "base64 data ends in an incomplete group of {n} characters"
            ));
        }
        let value = |c: u8| -> Result<u32, String> {
            Ok(match c {
                b'A'..=b'Z' => c - b'A',
                b'a'..=b'z' => c - b'a' + 26,
                b'0'..=b'9' => c - b'0' + 52,
                b'+' => 62,
                b'/' => 63,
                _ => return Err(format!("'{}' is not a base64 character", c as char)),
            } as u32)
        };
        let bytes = match (group[2], group[3]) {
            (b'=', b'=') => 1,
            (_, b'=') => 2,
            (b'=', _) => return Err("misplaced base64 padding".into()),
            _ => 3,
        };
        let mut v = 0u32;
        for (i, &c) in group.iter().enumerate() {
            v |= if i > bytes { 0 } else { value(c)? } << (18 - 6 * i);
        }
        let decoded = [(v >> 16) as u8, (v >> 8) as u8, v as u8];
        self.pending.extend_from_slice(&decoded[..bytes]);
        Ok(true)
    }
}

impl ByteSource for Base64Source<'_> {
    fn take(&mut self, n: usize) -> Result<Vec<u8>, String> {
        if n > self.left_upper_bound() {
            return Err(format!(
                "unexpected end of the base64 data (needed {n} more bytes, at most {} left)",
                self.left_upper_bound()
            ));
        }
        while self.pending.len() < n {
            if !self.next_group()? {
                return Err(format!(
                    "unexpected end of the base64 data (needed {n} more bytes, {} left)",
                    self.pending.len()
                ));
            }
        }
        let rest = self.pending.split_off(n);
        Ok(std::mem::replace(&mut self.pending, rest))
    }

    fn left_upper_bound(&self) -> usize {
        self.pending.len() + (self.text.len() - self.pos.min(self.text.len())) / 4 * 3 + 3
    }
}

#[cfg(test)]
#[path = "tests/vtu_read.rs"]
mod tests;
