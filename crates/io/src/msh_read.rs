//! Gmsh MSH reader: MSH 4.1 and 2.2 (2.0–2.2), ASCII and binary, first-order elements.
//!
//! What the reader produces ([`LinearMesh`]):
//! - every node of `$Nodes`, in file order; node tags may be sparse and unordered, they are
//!   mapped to 0-based indices in order of appearance;
//! - the elements of the highest dimension present become the cells (which fixes `dim`), the
//!   elements one dimension lower the facets; points and lower-dimensional elements are
//!   dropped;
//! - entity tags: MSH 4.1 element block `entityTag`, MSH 2 second ("elementary") tag;
//! - physical tags per entity: MSH 4.1 `$Entities`, MSH 2 first element tag (elements that
//!   MSH 2 repeats once per physical group are merged);
//! - physical groups: `$PhysicalNames` plus every physical tag used but not named.
//!
//! Errors name the line (ASCII) or byte offset (binary) and say what was expected and found.
//! The reader never panics: counts read from the file are checked against the bytes left
//! before anything is allocated for them.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;

use hocurve_mesh::{
    Element, ElementType, HighOrderElement, HighOrderMesh, LinearMesh, MeshError, PhysicalGroup,
};
use hocurve_nodes::NodeFamily;

use crate::error::{IoError, Location};
use crate::ordering::{gmsh_permutation, gmsh_type_shape};

/// Reads a Gmsh mesh file (MSH 4.1 or 2.2, ASCII or binary).
pub fn read_msh(path: &Path) -> Result<LinearMesh, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Os {
        path: path.to_path_buf(),
        source,
    })?;
    parse_msh(&bytes, path)
}

/// Same from bytes already in memory; `path` only names the file in errors.
pub fn parse_msh(bytes: &[u8], path: &Path) -> Result<LinearMesh, IoError> {
    let mesh = Parser::new(bytes).parse().map_err(|e| IoError::Malformed {
        path: path.to_path_buf(),
        location: e.location,
        message: e.message,
    })?;
    mesh.validate().map_err(|source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(mesh)
}

/// A parse failure before the path is attached.
#[derive(Debug)]
struct Fail {
    location: Location,
    message: String,
    /// The input ended too early (the section reader rewrites the message with its counts).
    eof: bool,
}

type R<T> = Result<T, Fail>;

fn fail<T>(location: Location, message: impl Into<String>) -> R<T> {
    Err(Fail {
        location,
        message: message.into(),
        eof: false,
    })
}

fn eof_fail(message: impl Into<String>) -> Fail {
    Fail {
        location: Location::EndOfFile,
        message: message.into(),
        eof: true,
    }
}

/// Rewrites an end-of-file failure inside a section with what the section announced.
fn in_section(e: Fail, section: &str, what: &str, announced: Option<u64>, read: u64) -> Fail {
    if !e.eof {
        return e;
    }
    let detail = e
        .message
        .strip_prefix("unexpected end of file: ")
        .unwrap_or(&e.message)
        .to_string();
    let message = match announced {
        Some(n) if read < n => {
            format!("unexpected end of file in ${section} (expected {n} {what}, read {read})")
        }
        Some(n) => format!("unexpected end of file in ${section} (all {n} {what} read; {detail})"),
        None => format!("unexpected end of file in ${section} ({detail})"),
    };
    eof_fail(message)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Version {
    /// MSH 2.0 to 2.2.
    V2,
    /// MSH 4.1.
    V41,
}

/// Node tag → 0-based vertex index.
enum NodeIndex {
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32>),
}

impl NodeIndex {
    fn get(&self, tag: u64) -> Option<u32> {
        match self {
            NodeIndex::Dense(v) => usize::try_from(tag)
                .ok()
                .and_then(|t| v.get(t))
                .copied()
                .filter(|&i| i != u32::MAX),
            NodeIndex::Sparse(m) => m.get(&tag).copied(),
        }
    }
}

/// Identity of an element for merging the copies MSH 2 writes once per physical group.
type DedupKey = (ElementType, i32, [u32; 8]);

fn dedup_key(kind: ElementType, entity: i32, vertices: &[u32]) -> DedupKey {
    let mut v = [u32::MAX; 8];
    for (slot, &x) in v.iter_mut().zip(vertices) {
        *slot = x;
    }
    (kind, entity, v)
}

/// Blank within a line.
fn is_blank(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\r' | 0x0b | 0x0c)
}

fn trim(mut t: &[u8]) -> &[u8] {
    while let [first, rest @ ..] = t {
        if is_blank(*first) {
            t = rest;
        } else {
            break;
        }
    }
    while let [rest @ .., last] = t {
        if is_blank(*last) {
            t = rest;
        } else {
            break;
        }
    }
    t
}

/// A token or line quoted for a message (shortened, control characters escaped).
fn show(t: &[u8]) -> String {
    const MAX: usize = 60;
    let s = String::from_utf8_lossy(&t[..t.len().min(MAX)]);
    let mut out = String::from("'");
    for c in s.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    if t.len() > MAX {
        out.push_str("...");
    }
    out.push('\'');
    out
}

fn parse_int(t: &[u8]) -> Option<i64> {
    let (neg, digits) = match t.split_first()? {
        (b'-', rest) => (true, rest),
        (b'+', rest) => (false, rest),
        _ => (false, t),
    };
    if digits.is_empty() {
        return None;
    }
    // Accumulate negatively so that i64::MIN parses.
    let mut v: i64 = 0;
    for &c in digits {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v.checked_mul(10)?.checked_sub(i64::from(c - b'0'))?;
    }
    if neg {
        Some(v)
    } else {
        v.checked_neg()
    }
}

fn parse_uint(t: &[u8]) -> Option<u64> {
    let digits = t.strip_prefix(b"+").unwrap_or(t);
    if digits.is_empty() {
        return None;
    }
    let mut v: u64 = 0;
    for &c in digits {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v.checked_mul(10)?.checked_add(u64::from(c - b'0'))?;
    }
    Some(v)
}

fn parse_float(t: &[u8]) -> Option<f64> {
    std::str::from_utf8(t).ok()?.parse().ok()
}

/// The element type of a block of elements: its type, order and number of nodes.
#[derive(Debug, Clone, Copy)]
struct BlockKind {
    kind: ElementType,
    order: usize,
    nodes: usize,
}

impl BlockKind {
    fn linear(kind: ElementType) -> Self {
        BlockKind {
            kind,
            order: 1,
            nodes: kind.num_vertices(),
        }
    }
}

/// What Gmsh element type `t` is for the high-order reader: a complete Lagrange element of
/// any order Gmsh defines, a point (`None`), or an error saying why it cannot be read.
fn high_order_kind(t: i64) -> Result<Option<BlockKind>, String> {
    if t == 15 {
        return Ok(None);
    }
    if let Some((shape, order)) = i32::try_from(t).ok().and_then(gmsh_type_shape) {
        return Ok(Some(BlockKind {
            kind: ElementType::from_shape(shape),
            order,
            nodes: shape.num_nodes(order),
        }));
    }
    let pyramid = "pyramid elements are not supported; hocurve handles lines, triangles, \
                   quadrilaterals, tetrahedra, hexahedra and prisms";
    if t == 7 {
        return Err(format!("element type 7 (5-node pyramid): {pyramid}"));
    }
    if let Some(&(_, shape, order, nodes)) = HIGH_ORDER.iter().find(|e| e.0 == t) {
        let what = format!(
            "element type {t} ({nodes}-node {} order {shape})",
            ordinal(order)
        );
        return Err(if shape == "pyramid" {
            format!("{what}: {pyramid}")
        } else {
            format!("{what}: incomplete (serendipity) elements are not supported (save complete elements: Mesh.SecondOrderIncomplete = 0)")
        });
    }
    Err(describe_unsupported(t))
}

/// What Gmsh element type `t` is, as far as hocurve cares.
fn element_kind(t: i64) -> Result<Option<ElementType>, String> {
    Ok(Some(match t {
        1 => ElementType::Line,
        2 => ElementType::Tri,
        3 => ElementType::Quad,
        4 => ElementType::Tet,
        5 => ElementType::Hex,
        6 => ElementType::Prism,
        7 => {
            return Err(
                "pyramid elements are not supported (Gmsh element type 7); hocurve \
                        handles triangles, quadrilaterals, tetrahedra, hexahedra and prisms"
                    .into(),
            )
        }
        15 => return Ok(None),
        _ => return Err(describe_unsupported(t)),
    }))
}

/// Gmsh element types of order ≥ 2: (type, shape, order, number of nodes).
const HIGH_ORDER: &[(i64, &str, u8, u16)] = &[
    (8, "line", 2, 3),
    (9, "triangle", 2, 6),
    (10, "quadrilateral", 2, 9),
    (11, "tetrahedron", 2, 10),
    (12, "hexahedron", 2, 27),
    (13, "prism", 2, 18),
    (14, "pyramid", 2, 14),
    (16, "quadrilateral", 2, 8),
    (17, "hexahedron", 2, 20),
    (18, "prism", 2, 15),
    (19, "pyramid", 2, 13),
    (20, "triangle", 3, 9),
    (21, "triangle", 3, 10),
    (22, "triangle", 4, 12),
    (23, "triangle", 4, 15),
    (24, "triangle", 5, 15),
    (25, "triangle", 5, 21),
    (26, "line", 3, 4),
    (27, "line", 4, 5),
    (28, "line", 5, 6),
    (29, "tetrahedron", 3, 20),
    (30, "tetrahedron", 4, 35),
    (31, "tetrahedron", 5, 56),
    (32, "tetrahedron", 4, 22),
    (33, "tetrahedron", 5, 28),
    (36, "quadrilateral", 3, 16),
    (37, "quadrilateral", 4, 25),
    (38, "quadrilateral", 5, 36),
    (39, "quadrilateral", 3, 12),
    (40, "quadrilateral", 4, 16),
    (41, "quadrilateral", 5, 20),
    (42, "triangle", 6, 28),
    (43, "triangle", 7, 36),
    (44, "triangle", 8, 45),
    (45, "triangle", 9, 55),
    (46, "triangle", 10, 66),
    (47, "quadrilateral", 6, 49),
    (48, "quadrilateral", 7, 64),
    (49, "quadrilateral", 8, 81),
    (50, "quadrilateral", 9, 100),
    (51, "quadrilateral", 10, 121),
    (52, "triangle", 6, 18),
    (53, "triangle", 7, 21),
    (54, "triangle", 8, 24),
    (55, "triangle", 9, 27),
    (56, "triangle", 10, 30),
    (57, "quadrilateral", 6, 24),
    (58, "quadrilateral", 7, 28),
    (59, "quadrilateral", 8, 32),
    (60, "quadrilateral", 9, 36),
    (61, "quadrilateral", 10, 40),
    (62, "line", 6, 7),
    (63, "line", 7, 8),
    (64, "line", 8, 9),
    (65, "line", 9, 10),
    (66, "line", 10, 11),
    (71, "tetrahedron", 6, 84),
    (72, "tetrahedron", 7, 120),
    (73, "tetrahedron", 8, 165),
    (74, "tetrahedron", 9, 220),
    (75, "tetrahedron", 10, 286),
    (79, "tetrahedron", 6, 34),
    (80, "tetrahedron", 7, 40),
    (81, "tetrahedron", 8, 46),
    (82, "tetrahedron", 9, 52),
    (83, "tetrahedron", 10, 58),
    (90, "prism", 3, 40),
    (91, "prism", 4, 75),
    (92, "hexahedron", 3, 64),
    (93, "hexahedron", 4, 125),
    (94, "hexahedron", 5, 216),
    (95, "hexahedron", 6, 343),
    (96, "hexahedron", 7, 512),
    (97, "hexahedron", 8, 729),
    (98, "hexahedron", 9, 1000),
    (99, "hexahedron", 3, 32),
    (100, "hexahedron", 4, 44),
    (101, "hexahedron", 5, 56),
    (102, "hexahedron", 6, 68),
    (103, "hexahedron", 7, 80),
    (104, "hexahedron", 8, 92),
    (105, "hexahedron", 9, 104),
    (106, "prism", 5, 126),
    (107, "prism", 6, 196),
    (108, "prism", 7, 288),
    (109, "prism", 8, 405),
    (110, "prism", 9, 550),
    (111, "prism", 3, 24),
    (112, "prism", 4, 33),
    (113, "prism", 5, 42),
    (114, "prism", 6, 51),
    (115, "prism", 7, 60),
    (116, "prism", 8, 69),
    (117, "prism", 9, 78),
    (118, "pyramid", 3, 30),
    (119, "pyramid", 4, 55),
    (120, "pyramid", 5, 91),
    (121, "pyramid", 6, 140),
    (122, "pyramid", 7, 204),
    (123, "pyramid", 8, 285),
    (124, "pyramid", 9, 385),
    (125, "pyramid", 3, 21),
    (126, "pyramid", 4, 29),
    (127, "pyramid", 5, 37),
    (128, "pyramid", 6, 45),
    (129, "pyramid", 7, 53),
    (130, "pyramid", 8, 61),
    (131, "pyramid", 9, 69),
    (137, "tetrahedron", 3, 16),
];

/// Gmsh element types that are neither first order nor high order Lagrange elements.
const OTHER_TYPES: &[(i64, &str)] = &[
    (34, "polygon"),
    (35, "polyhedron"),
    (67, "line border element"),
    (68, "triangle border element"),
    (69, "polygon border element"),
    (70, "line child element"),
    (84, "1-node line"),
    (85, "1-node triangle"),
    (86, "1-node quadrilateral"),
    (87, "1-node tetrahedron"),
    (88, "1-node hexahedron"),
    (89, "1-node prism"),
    (132, "1-node pyramid"),
    (133, "XFEM point"),
    (134, "XFEM line"),
    (135, "XFEM triangle"),
    (136, "XFEM tetrahedron"),
];

fn ordinal(order: u8) -> &'static str {
    match order {
        2 => "second",
        3 => "third",
        4 => "fourth",
        5 => "fifth",
        6 => "sixth",
        7 => "seventh",
        8 => "eighth",
        9 => "ninth",
        _ => "tenth",
    }
}

fn describe_unsupported(t: i64) -> String {
    if let Some(&(_, shape, order, nodes)) = HIGH_ORDER.iter().find(|e| e.0 == t) {
        return format!(
            "element type {t} ({nodes}-node {} order {shape}) is a high-order element; hocurve \
             reads linear meshes (Mesh.ElementOrder = 1)",
            ordinal(order)
        );
    }
    if let Some(&(_, what)) = OTHER_TYPES.iter().find(|e| e.0 == t) {
        return format!("element type {t} ({what}) is not supported");
    }
    format!("unknown element type {t}")
}

fn entity_word(dim: usize) -> &'static str {
    match dim {
        0 => "point",
        1 => "curve",
        2 => "surface",
        _ => "volume",
    }
}

struct Parser<'a> {
    b: &'a [u8],
    /// Read position.
    pos: usize,
    /// 1-based number of the line holding `pos` (meaningful in ASCII files).
    line: usize,
    binary: bool,
    /// Binary data is big-endian.
    swap: bool,
    /// Bytes of a `size_t` in binary MSH 4.1.
    size_t: usize,
    version: Version,
    // The current record: one text line, or a position in binary data.
    rec: &'a [u8],
    rec_i: usize,
    rec_text: bool,
    rec_loc: Location,
    /// The current text record is the last line and has no newline (truncated file).
    rec_last: bool,
    /// Start of the last binary value read.
    field_at: usize,
    // What was read.
    vertices: Vec<[f64; 3]>,
    node_tags: Vec<u64>,
    nodes: Option<NodeIndex>,
    by_dim: [Vec<Element>; 4],
    have_elements: bool,
    names: Vec<PhysicalGroup>,
    entity_physicals: BTreeMap<(usize, i32), Vec<i32>>,
    // MSH 2 bookkeeping: the first physical tag seen per (dim, entity), the last
    // (dim, entity, physical) triple, and the element set once duplicates are possible.
    first_physical: HashMap<(usize, i32), i32>,
    last_triple: Option<(usize, i32, i32)>,
    dedup: Option<HashSet<DedupKey>>,
    /// Read complete elements of any order (not only first-order ones).
    high_order: bool,
    /// High-order reader: tag, place and order of each element of `by_dim`.
    element_records: [Vec<ElementRecord>; 4],
    /// The file's tag of each element of `by_dim` (for messages).
    element_tags: [Vec<u64>; 4],
}

/// Where an element was read and of which order (high-order reader).
#[derive(Debug, Clone, Copy)]
struct ElementRecord {
    tag: i128,
    location: Location,
    order: usize,
}

impl<'a> Parser<'a> {
    fn new(b: &'a [u8]) -> Self {
        let start = if b.starts_with(&[0xef, 0xbb, 0xbf]) {
            3
        } else {
            0
        };
        Parser {
            b,
            pos: start,
            line: 1,
            binary: false,
            swap: false,
            size_t: 8,
            version: Version::V41,
            rec: &[],
            rec_i: 0,
            rec_text: true,
            rec_loc: Location::Line(1),
            rec_last: false,
            field_at: 0,
            vertices: Vec::new(),
            node_tags: Vec::new(),
            nodes: None,
            by_dim: Default::default(),
            have_elements: false,
            names: Vec::new(),
            entity_physicals: BTreeMap::new(),
            first_physical: HashMap::new(),
            last_triple: None,
            dedup: None,
            high_order: false,
            element_records: Default::default(),
            element_tags: Default::default(),
        }
    }

    /// The element block kind of Gmsh type `t` for this reader.
    fn block_kind(&self, t: i64) -> Result<Option<BlockKind>, String> {
        if self.high_order {
            high_order_kind(t)
        } else {
            element_kind(t).map(|k| k.map(BlockKind::linear))
        }
    }

    /// Stores an element of dimension `dim` (and, for the high-order reader, its record:
    /// file tag, where it was read, order).
    fn push_element(
        &mut self,
        dim: usize,
        kind: BlockKind,
        vertices: Vec<u32>,
        entity: i32,
        tag: i128,
        location: Location,
    ) {
        let element = Element {
            kind: kind.kind,
            vertices,
            entity,
        };
        let record = ElementRecord {
            tag,
            location,
            order: kind.order,
        };
        if let Some(list) = self.by_dim.get_mut(dim) {
            list.push(element);
            if let Some(tags) = self.element_tags.get_mut(dim) {
                tags.push(u64::try_from(tag).unwrap_or(0));
            }
            if self.high_order {
                if let Some(records) = self.element_records.get_mut(dim) {
                    records.push(record);
                }
            }
        }
    }

    // ------------------------------------------------------------------ low level

    fn remaining(&self) -> usize {
        self.b.len().saturating_sub(self.pos)
    }

    fn loc_at(&self, byte: usize) -> Location {
        if self.binary {
            Location::Byte(byte as u64)
        } else {
            Location::Line(self.line)
        }
    }

    /// Skips blank lines and leading blanks; false at the end of the input.
    fn skip_blank_lines(&mut self) -> bool {
        while let Some(&c) = self.b.get(self.pos) {
            if c == b'\n' {
                self.line += 1;
            } else if !is_blank(c) {
                return true;
            }
            self.pos += 1;
        }
        false
    }

    /// Consumes the next non-blank line: its location, trimmed text, and whether it ended
    /// with a newline.
    fn next_line(&mut self) -> Option<(Location, &'a [u8], bool)> {
        if !self.skip_blank_lines() {
            return None;
        }
        let start = self.pos;
        let loc = self.loc_at(start);
        let rest = self.b.get(start..).unwrap_or(&[]);
        let (text, terminated) = match rest.iter().position(|&c| c == b'\n') {
            Some(k) => {
                self.pos = start + k + 1;
                self.line += 1;
                (&rest[..k], true)
            }
            None => {
                self.pos = self.b.len();
                (rest, false)
            }
        };
        Some((loc, trim(text), terminated))
    }

    /// Location of the next line if it starts a section (`$…`), in text parts of the file.
    fn peek_dollar(&mut self) -> Option<Location> {
        if self.skip_blank_lines() && self.b.get(self.pos) == Some(&b'$') {
            Some(self.loc_at(self.pos))
        } else {
            None
        }
    }

    /// Starts a record that is a text line (also in binary files).
    fn begin_text(&mut self, what: impl FnOnce() -> String) -> R<()> {
        match self.next_line() {
            None => Err(eof_fail(format!(
                "unexpected end of file: expected {}",
                what()
            ))),
            Some((loc, text, terminated)) => {
                if text.first() == Some(&b'$') {
                    return fail(loc, format!("expected {}, found {}", what(), show(text)));
                }
                self.rec = text;
                self.rec_i = 0;
                self.rec_text = true;
                self.rec_loc = loc;
                self.rec_last = !terminated;
                Ok(())
            }
        }
    }

    /// Starts a record: a text line in ASCII files, the next bytes in binary ones.
    fn begin(&mut self, what: impl FnOnce() -> String) -> R<()> {
        if self.binary {
            self.rec_text = false;
            self.rec_loc = Location::Byte(self.pos as u64);
            Ok(())
        } else {
            self.begin_text(what)
        }
    }

    /// Location of the current record.
    fn rec_location(&self) -> Location {
        self.rec_loc
    }

    /// Location of the value just read.
    fn value_loc(&self) -> Location {
        if self.rec_text {
            self.rec_loc
        } else {
            Location::Byte(self.field_at as u64)
        }
    }

    fn token(&mut self) -> Option<&'a [u8]> {
        let r = self.rec;
        let mut i = self.rec_i;
        while r.get(i).is_some_and(|&c| is_blank(c)) {
            i += 1;
        }
        let start = i;
        while r.get(i).is_some_and(|&c| !is_blank(c)) {
            i += 1;
        }
        self.rec_i = i;
        (i > start).then(|| &r[start..i])
    }

    fn tokens_left(&self) -> Option<usize> {
        if !self.rec_text {
            return None;
        }
        let rest = self.rec.get(self.rec_i..).unwrap_or(&[]);
        Some(
            rest.split(|&c| is_blank(c))
                .filter(|t| !t.is_empty())
                .count(),
        )
    }

    fn missing(&self, what: String) -> Fail {
        if self.rec_last {
            eof_fail(format!("unexpected end of file: expected {what}"))
        } else {
            Fail {
                location: self.rec_loc,
                message: format!("expected {what}, found end of line"),
                eof: false,
            }
        }
    }

    fn bad(&self, what: String, tok: &[u8]) -> Fail {
        // A garbled last token of an unterminated last line is a cut-off file.
        if self.rec_last && self.rec_i >= self.rec.len() {
            return eof_fail(format!("unexpected end of file: expected {what}"));
        }
        Fail {
            location: self.rec_loc,
            message: format!("expected {what}, found {}", show(tok)),
            eof: false,
        }
    }

    fn take<const N: usize>(&mut self, what: impl FnOnce() -> String) -> R<[u8; N]> {
        self.field_at = self.pos;
        let bytes = self
            .pos
            .checked_add(N)
            .and_then(|end| self.b.get(self.pos..end))
            .and_then(|s| <[u8; N]>::try_from(s).ok());
        match bytes {
            Some(a) => {
                self.pos += N;
                Ok(a)
            }
            None => Err(eof_fail(format!(
                "unexpected end of file: expected {}",
                what()
            ))),
        }
    }

    /// An integer: a token, or a binary 4-byte `int`.
    fn int(&mut self, what: impl FnOnce() -> String) -> R<i64> {
        if self.rec_text {
            match self.token() {
                None => Err(self.missing(what())),
                Some(t) => parse_int(t).ok_or_else(|| self.bad(what(), t)),
            }
        } else {
            let a = self.take::<4>(what)?;
            Ok(i64::from(if self.swap {
                i32::from_be_bytes(a)
            } else {
                i32::from_le_bytes(a)
            }))
        }
    }

    /// A 32-bit integer (tags).
    fn int32(&mut self, what: impl FnOnce() -> String + Clone) -> R<i32> {
        let v = self.int(what.clone())?;
        i32::try_from(v).or_else(|_| {
            fail(
                self.value_loc(),
                format!("expected {} (a 32-bit integer), found {v}", what()),
            )
        })
    }

    /// A non-negative count or tag: a token, or a binary `size_t`.
    fn size(&mut self, what: impl FnOnce() -> String) -> R<u64> {
        if self.rec_text {
            match self.token() {
                None => Err(self.missing(what())),
                Some(t) => parse_uint(t).ok_or_else(|| self.bad(what(), t)),
            }
        } else if self.size_t == 4 {
            let a = self.take::<4>(what)?;
            Ok(u64::from(if self.swap {
                u32::from_be_bytes(a)
            } else {
                u32::from_le_bytes(a)
            }))
        } else {
            let a = self.take::<8>(what)?;
            Ok(if self.swap {
                u64::from_be_bytes(a)
            } else {
                u64::from_le_bytes(a)
            })
        }
    }

    fn float(&mut self, what: impl FnOnce() -> String) -> R<f64> {
        if self.rec_text {
            match self.token() {
                None => Err(self.missing(what())),
                Some(t) => parse_float(t).ok_or_else(|| self.bad(what(), t)),
            }
        } else {
            let a = self.take::<8>(what)?;
            Ok(if self.swap {
                f64::from_be_bytes(a)
            } else {
                f64::from_le_bytes(a)
            })
        }
    }

    /// Ends a record: a text line must hold nothing more.
    fn end_record(&mut self, what: impl FnOnce() -> String) -> R<()> {
        if self.rec_text {
            if let Some(t) = self.token() {
                return fail(
                    self.rec_loc,
                    format!("expected end of line after {}, found {}", what(), show(t)),
                );
            }
        }
        Ok(())
    }

    /// In binary data, fails early when `count` items of `each` bytes cannot fit in the rest
    /// of the file (so that no absurd count is looped over or allocated for).
    fn check_room(&self, count: u64, each: u64, what: impl FnOnce() -> String) -> R<()> {
        let rem = self.remaining() as u64;
        if self.binary && count.saturating_mul(each) > rem {
            return Err(eof_fail(format!(
                "unexpected end of file: {} needs {} bytes, only {rem} remain",
                what(),
                count.saturating_mul(each)
            )));
        }
        Ok(())
    }

    /// Capacity to reserve for `count` items of at least `each` bytes in the rest of the file.
    fn capacity(&self, count: u64, each: usize) -> usize {
        let fit = self.remaining() / each.max(1);
        usize::try_from(count).map_or(fit, |c| c.min(fit))
    }

    /// Reads the `$End<name>` line closing a section.
    fn expect_end(&mut self, name: &str, context: impl FnOnce() -> String) -> R<()> {
        match self.next_line() {
            None => Err(eof_fail(format!(
                "unexpected end of file: expected $End{name}"
            ))),
            Some((loc, text, _)) => {
                if text.strip_prefix(b"$End") == Some(name.as_bytes()) {
                    Ok(())
                } else {
                    fail(
                        loc,
                        format!("expected $End{name}{}, found {}", context(), show(text)),
                    )
                }
            }
        }
    }

    /// Skips a section this reader does not need, up to its `$End<name>` line (which must
    /// start a line; binary data is not interpreted).
    fn skip_section(&mut self, name: &[u8], loc: Location) -> R<()> {
        let mut end = b"$End".to_vec();
        end.extend_from_slice(name);
        let start = self.pos;
        let mut i = start;
        loop {
            let Some(off) = self
                .b
                .get(i..)
                .and_then(|r| r.iter().position(|&c| c == b'$'))
            else {
                return Err(Fail {
                    location: loc,
                    message: format!(
                        "unexpected end of file: section ${} has no ${}",
                        String::from_utf8_lossy(name),
                        String::from_utf8_lossy(&end[1..])
                    ),
                    eof: true,
                });
            };
            let p = i + off;
            let q = p + end.len();
            let at_line_start = p == start || matches!(self.b.get(p - 1), Some(b'\n'));
            let matches = self.b.get(p..q) == Some(end.as_slice());
            let ends_line = matches!(self.b.get(q), None | Some(b'\n' | b'\r' | b' ' | b'\t'));
            if at_line_start && matches && ends_line {
                let skipped = self.b.get(start..p).unwrap_or(&[]);
                self.line += skipped.iter().filter(|&&c| c == b'\n').count();
                self.pos = p;
                // Consume the $End line itself.
                self.next_line();
                return Ok(());
            }
            i = p + 1;
        }
    }

    // ------------------------------------------------------------------ sections

    fn parse(mut self) -> R<LinearMesh> {
        self.read_sections()?;
        self.finish()
    }

    /// Reads every section of the file.
    fn read_sections(&mut self) -> R<()> {
        match self.next_line() {
            None => {
                return fail(
                    Location::EndOfFile,
                    "the file is empty (expected $MeshFormat)",
                )
            }
            Some((_, b"$MeshFormat", _)) => {}
            Some((loc, text, _)) => {
                let hint = if text == b"$NOD" || text == b"$NOE" {
                    " (MSH 1.0 files are not supported; re-save the mesh as MSH 4.1)"
                } else {
                    ""
                };
                return fail(
                    loc,
                    format!(
                        "expected $MeshFormat at the start of a Gmsh MSH file, found {}{hint}",
                        show(text)
                    ),
                );
            }
        }
        self.mesh_format()?;
        while let Some((loc, text, _)) = self.next_line() {
            let Some(name) = text.strip_prefix(b"$") else {
                return fail(
                    loc,
                    format!(
                        "expected a section header such as $Nodes or $Elements, found {}",
                        show(text)
                    ),
                );
            };
            match name {
                b"MeshFormat" => return fail(loc, "a second $MeshFormat section"),
                b"PhysicalNames" => self
                    .physical_names()
                    .map_err(|e| in_section(e, "PhysicalNames", "", None, 0))?,
                b"Entities" if self.version == Version::V41 => self
                    .entities()
                    .map_err(|e| in_section(e, "Entities", "", None, 0))?,
                b"PartitionedEntities" => {
                    return fail(
                        loc,
                        "partitioned meshes are not supported (found $PartitionedEntities); \
                         save the mesh without partitions",
                    )
                }
                b"Nodes" => {
                    if self.nodes.is_some() {
                        return fail(loc, "a second $Nodes section (only one is supported)");
                    }
                    let mut announced = None;
                    let r = match self.version {
                        Version::V41 => self.nodes_v41(&mut announced),
                        Version::V2 => self.nodes_v2(&mut announced),
                    };
                    let read = self.vertices.len() as u64;
                    r.map_err(|e| in_section(e, "Nodes", "nodes", announced, read))?;
                    self.build_node_index(loc)?;
                }
                b"Elements" => {
                    if self.nodes.is_none() {
                        return fail(loc, "$Elements comes before $Nodes");
                    }
                    if self.have_elements {
                        return fail(loc, "a second $Elements section (only one is supported)");
                    }
                    self.have_elements = true;
                    let mut announced = None;
                    let mut read = 0u64;
                    let r = match self.version {
                        Version::V41 => self.elements_v41(&mut announced, &mut read),
                        Version::V2 => self.elements_v2(&mut announced, &mut read),
                    };
                    r.map_err(|e| in_section(e, "Elements", "elements", announced, read))?;
                }
                _ if name.starts_with(b"End") => {
                    return fail(
                        loc,
                        format!("{} without a matching section start", show(text)),
                    )
                }
                _ => self.skip_section(name, loc)?,
            }
        }
        Ok(())
    }

    fn mesh_format(&mut self) -> R<()> {
        self.begin_text(|| "the MSH version, file type and data size (e.g. '4.1 0 8')".into())?;
        let loc = self.rec_location();
        let version = match self.token() {
            None => return Err(self.missing("the MSH version".into())),
            Some(b"4.1") => Version::V41,
            Some(b"2" | b"2.0" | b"2.1" | b"2.2") => Version::V2,
            Some(b"4" | b"4.0") => {
                return fail(
                    loc,
                    "MSH version 4.0 is not supported (expected 4.1 or 2.2); re-save the mesh \
                     with Mesh.MshFileVersion = 4.1",
                )
            }
            Some(t) => {
                return fail(
                    loc,
                    format!("unsupported MSH version {} (expected 4.1 or 2.2)", show(t)),
                )
            }
        };
        self.version = version;
        let file_type = self.int(|| "the file type (0 = ASCII, 1 = binary)".into())?;
        let data_size = self.int(|| "the data size".into())?;
        self.end_record(|| "the MSH version, file type and data size".into())?;
        match file_type {
            0 => {}
            1 => {
                let ok = match version {
                    Version::V41 => data_size == 8 || data_size == 4,
                    Version::V2 => data_size == 8,
                };
                if !ok {
                    return fail(
                        loc,
                        format!("unsupported data size {data_size} in a binary file (expected 8)"),
                    );
                }
                self.size_t = if data_size == 4 { 4 } else { 8 };
                self.binary = true;
                let at = self.pos;
                let one = self.take::<4>(|| {
                    "the binary integer 1 (endianness check) after the $MeshFormat line".into()
                })?;
                if u32::from_le_bytes(one) == 1 {
                    self.swap = false;
                } else if u32::from_be_bytes(one) == 1 {
                    self.swap = true;
                } else {
                    return fail(
                        Location::Byte(at as u64),
                        format!(
                            "expected the binary integer 1 (endianness check) after the \
                             $MeshFormat line, found bytes {one:02x?}"
                        ),
                    );
                }
            }
            _ => {
                return fail(
                    loc,
                    format!("expected file type 0 (ASCII) or 1 (binary), found {file_type}"),
                )
            }
        }
        self.expect_end("MeshFormat", String::new)
    }

    fn physical_names(&mut self) -> R<()> {
        self.begin_text(|| "the number of physical names".into())?;
        let n = self.size(|| "the number of physical names".into())?;
        self.end_record(|| "the number of physical names".into())?;
        for i in 0..n {
            if let Some(loc) = self.peek_dollar() {
                return fail(
                    loc,
                    format!(
                        "physical name count in $PhysicalNames header is {n} but the section \
                         holds {i}"
                    ),
                );
            }
            self.begin_text(|| format!("physical name {} of {n}", i + 1))?;
            let dim = self.int(|| "the dimension of a physical group".into())?;
            let dim = match usize::try_from(dim) {
                Ok(d) if d <= 3 => d,
                _ => {
                    return fail(
                        self.rec_loc,
                        format!("expected a physical group dimension 0 to 3, found {dim}"),
                    )
                }
            };
            let tag = self.int32(|| "the tag of a physical group".to_string())?;
            let rest = trim(self.rec.get(self.rec_i..).unwrap_or(&[]));
            self.rec_i = self.rec.len();
            let name = match rest {
                [] => &[][..],
                [b'"', inner @ ..] => match inner.iter().rposition(|&c| c == b'"') {
                    Some(k) => &inner[..k],
                    None => {
                        return fail(
                            self.rec_loc,
                            format!("unterminated quoted physical name {}", show(rest)),
                        )
                    }
                },
                other => other,
            };
            self.names.push(PhysicalGroup {
                dim,
                tag,
                name: String::from_utf8_lossy(name).into_owned(),
            });
        }
        self.expect_end("PhysicalNames", || {
            format!(" after the {n} names announced in the $PhysicalNames header")
        })
    }

    fn entities(&mut self) -> R<()> {
        self.begin(|| "the entity counts (points, curves, surfaces, volumes)".into())?;
        let mut counts = [0u64; 4];
        for (d, c) in counts.iter_mut().enumerate() {
            *c = self.size(|| format!("the number of {}s", entity_word(d)))?;
        }
        self.end_record(|| "the four entity counts".into())?;
        for (dim, &count) in counts.iter().enumerate() {
            let word = entity_word(dim);
            for i in 0..count {
                if !self.binary {
                    if let Some(loc) = self.peek_dollar() {
                        return fail(
                            loc,
                            format!(
                                "$Entities header announces {count} {word}s but the section \
                                 holds {i}"
                            ),
                        );
                    }
                }
                self.begin(|| format!("{word} {} of {count}", i + 1))?;
                let tag = self.int32(|| format!("the tag of {word} {} of {count}", i + 1))?;
                let ncoords = if dim == 0 { 3 } else { 6 };
                for _ in 0..ncoords {
                    self.float(|| format!("the coordinates of {word} {tag}"))?;
                }
                let np = self.size(|| format!("the number of physical tags of {word} {tag}"))?;
                self.check_room(np, 4, || format!("{word} {tag}'s physical tags"))?;
                let mut phys = Vec::new();
                for _ in 0..np {
                    phys.push(self.int32(|| format!("a physical tag of {word} {tag}"))?);
                }
                if dim > 0 {
                    let nb =
                        self.size(|| format!("the number of bounding entities of {word} {tag}"))?;
                    self.check_room(nb, 4, || format!("{word} {tag}'s bounding entities"))?;
                    for _ in 0..nb {
                        self.int32(|| format!("a bounding entity of {word} {tag}"))?;
                    }
                }
                self.end_record(|| format!("the description of {word} {tag}"))?;
                if !phys.is_empty() {
                    let e = self.entity_physicals.entry((dim, tag)).or_default();
                    e.extend(phys);
                    e.sort_unstable();
                    e.dedup();
                }
            }
        }
        self.expect_end("Entities", || {
            format!(
                " after the {} entities announced in the $Entities header",
                counts.iter().fold(0u64, |a, &c| a.saturating_add(c))
            )
        })
    }

    fn nodes_v41(&mut self, announced: &mut Option<u64>) -> R<()> {
        self.begin(|| "the $Nodes header (blocks, nodes, smallest and largest tag)".into())?;
        let header = self.rec_location();
        let nblocks = self.size(|| "the number of node blocks".into())?;
        let nnodes = self.size(|| "the number of nodes".into())?;
        self.size(|| "the smallest node tag".into())?;
        self.size(|| "the largest node tag".into())?;
        self.end_record(|| "the $Nodes header".into())?;
        *announced = Some(nnodes);
        let each = if self.binary { self.size_t + 24 } else { 8 };
        let cap = self.capacity(nnodes, each);
        self.vertices.reserve(cap);
        self.node_tags.reserve(cap);
        let mut total = 0u64;
        for b in 1..=nblocks {
            if !self.binary {
                if let Some(loc) = self.peek_dollar() {
                    return fail(
                        loc,
                        format!(
                            "$Nodes header announces {nblocks} entity blocks but the section \
                             holds {}",
                            b - 1
                        ),
                    );
                }
            }
            self.begin(|| format!("the header of node block {b} of {nblocks}"))?;
            let block = self.rec_location();
            let edim = self.int(|| format!("the entity dimension of node block {b}"))?;
            self.int32(|| format!("the entity tag of node block {b}"))?;
            let param = self.int(|| format!("the parametric flag of node block {b}"))?;
            let n = self.size(|| format!("the number of nodes in block {b}"))?;
            self.end_record(|| format!("the header of node block {b}"))?;
            let edim = match usize::try_from(edim) {
                Ok(d) if d <= 3 => d,
                _ => {
                    return fail(
                        block,
                        format!(
                            "expected an entity dimension 0 to 3 in node block {b}, found {edim}"
                        ),
                    )
                }
            };
            let extra = match param {
                0 => 0,
                1 => edim,
                _ => {
                    return fail(
                        block,
                        format!("expected parametric flag 0 or 1 in node block {b}, found {param}"),
                    )
                }
            };
            self.check_room(n, self.size_t as u64 + 8 * (3 + extra as u64), || {
                format!("node block {b} of {n} nodes")
            })?;
            let first = self.node_tags.len();
            for k in 1..=n {
                self.begin(|| format!("the tag of node {k} of {n} in block {b}"))?;
                let tag = self.size(|| format!("the tag of node {k} of {n} in block {b}"))?;
                self.end_record(|| format!("the tag of node {k} of {n} in block {b}"))?;
                self.node_tags.push(tag);
            }
            for k in 0..n {
                let tag = usize::try_from(k)
                    .ok()
                    .and_then(|k| self.node_tags.get(first + k))
                    .copied()
                    .unwrap_or(0);
                self.begin(|| format!("the coordinates of node {tag}"))?;
                let x = self.float(|| format!("the x coordinate of node {tag}"))?;
                let y = self.float(|| format!("the y coordinate of node {tag}"))?;
                let z = self.float(|| format!("the z coordinate of node {tag}"))?;
                for _ in 0..extra {
                    self.float(|| format!("a parametric coordinate of node {tag}"))?;
                }
                self.end_record(|| format!("the coordinates of node {tag}"))?;
                self.vertices.push([x, y, z]);
            }
            total = total.saturating_add(n);
        }
        if total != nnodes {
            return fail(
                header,
                format!("node count in $Nodes header is {nnodes} but the blocks hold {total}"),
            );
        }
        self.expect_end("Nodes", || {
            format!(" after the {nblocks} node blocks announced in the $Nodes header")
        })
    }

    fn nodes_v2(&mut self, announced: &mut Option<u64>) -> R<()> {
        self.begin_text(|| "the number of nodes".into())?;
        let n = self.size(|| "the number of nodes".into())?;
        self.end_record(|| "the number of nodes".into())?;
        *announced = Some(n);
        self.check_room(n, 28, || format!("{n} nodes"))?;
        let cap = self.capacity(n, if self.binary { 28 } else { 8 });
        self.vertices.reserve(cap);
        self.node_tags.reserve(cap);
        for i in 0..n {
            if !self.binary {
                if let Some(loc) = self.peek_dollar() {
                    return fail(
                        loc,
                        format!("node count in $Nodes header is {n} but the section holds {i}"),
                    );
                }
            }
            self.begin(|| format!("node {} of {n}", i + 1))?;
            let tag = self.int(|| format!("the number of node {} of {n}", i + 1))?;
            let Ok(tag) = u64::try_from(tag) else {
                return fail(
                    self.value_loc(),
                    format!("expected a non-negative node number, found {tag}"),
                );
            };
            let x = self.float(|| format!("the x coordinate of node {tag}"))?;
            let y = self.float(|| format!("the y coordinate of node {tag}"))?;
            let z = self.float(|| format!("the z coordinate of node {tag}"))?;
            self.end_record(|| format!("the coordinates of node {tag}"))?;
            self.node_tags.push(tag);
            self.vertices.push([x, y, z]);
        }
        self.expect_end("Nodes", || {
            format!(" after the {n} nodes announced in the $Nodes header")
        })
    }

    fn build_node_index(&mut self, section: Location) -> R<()> {
        let n = self.node_tags.len();
        if u32::try_from(n).map_or(true, |n| n == u32::MAX) {
            return fail(section, format!("{n} nodes are more than hocurve supports"));
        }
        let max = self.node_tags.iter().copied().max().unwrap_or(0);
        let dup = |tag: u64| {
            fail(
                section,
                format!("node tag {tag} appears more than once in $Nodes"),
            )
        };
        let dense_len = usize::try_from(max)
            .ok()
            .and_then(|m| m.checked_add(1))
            .filter(|&len| len <= n.saturating_mul(2).saturating_add(1024));
        let index = if let Some(len) = dense_len {
            let mut v = vec![u32::MAX; len];
            for (i, &t) in self.node_tags.iter().enumerate() {
                // `t <= max < len`, and `i < n < u32::MAX`.
                if let Some(slot) = usize::try_from(t).ok().and_then(|t| v.get_mut(t)) {
                    if *slot != u32::MAX {
                        return dup(t);
                    }
                    *slot = i as u32;
                }
            }
            NodeIndex::Dense(v)
        } else {
            let mut m = HashMap::with_capacity(n);
            for (i, &t) in self.node_tags.iter().enumerate() {
                if m.insert(t, i as u32).is_some() {
                    return dup(t);
                }
            }
            NodeIndex::Sparse(m)
        };
        self.nodes = Some(index);
        Ok(())
    }

    /// Reads the node tags of one element and maps them to vertex indices.
    fn element_nodes(
        &mut self,
        kind: Option<BlockKind>,
        elem: i128,
        int_tags: bool,
    ) -> R<Vec<u32>> {
        let (nn, name) = kind.map_or((1, "point"), |k| (k.nodes, k.kind.name()));
        if let Some(left) = self.tokens_left() {
            if left != nn {
                let message =
                    format!("expected {nn} node tags for a {name} (element {elem}), found {left}");
                return Err(if self.rec_last && left < nn {
                    eof_fail(message)
                } else {
                    Fail {
                        location: self.rec_loc,
                        message,
                        eof: false,
                    }
                });
            }
        }
        let mut v = Vec::with_capacity(nn);
        for j in 1..=nn {
            let what = || format!("node {j} of element {elem}");
            let tag = if int_tags {
                let t = self.int(what)?;
                match u64::try_from(t) {
                    Ok(t) => t,
                    Err(_) => {
                        return fail(
                            self.value_loc(),
                            format!("element {elem} references node {t} which is not in $Nodes"),
                        )
                    }
                }
            } else {
                self.size(what)?
            };
            match self.nodes.as_ref().and_then(|m| m.get(tag)) {
                Some(i) => v.push(i),
                None => {
                    return fail(
                        self.value_loc(),
                        format!("element {elem} references node {tag} which is not in $Nodes"),
                    )
                }
            }
        }
        Ok(v)
    }

    fn elements_v41(&mut self, announced: &mut Option<u64>, read: &mut u64) -> R<()> {
        self.begin(|| "the $Elements header (blocks, elements, smallest and largest tag)".into())?;
        let header = self.rec_location();
        let nblocks = self.size(|| "the number of element blocks".into())?;
        let nelems = self.size(|| "the number of elements".into())?;
        self.size(|| "the smallest element tag".into())?;
        self.size(|| "the largest element tag".into())?;
        self.end_record(|| "the $Elements header".into())?;
        *announced = Some(nelems);
        for b in 1..=nblocks {
            if !self.binary {
                if let Some(loc) = self.peek_dollar() {
                    return fail(
                        loc,
                        format!(
                            "$Elements header announces {nblocks} entity blocks but the section \
                             holds {}",
                            b - 1
                        ),
                    );
                }
            }
            self.begin(|| format!("the header of element block {b} of {nblocks}"))?;
            let block = self.rec_location();
            let edim = self.int(|| format!("the entity dimension of element block {b}"))?;
            let entity = self.int32(|| format!("the entity tag of element block {b}"))?;
            let etype = self.int(|| format!("the element type of element block {b}"))?;
            let n = self.size(|| format!("the number of elements in block {b}"))?;
            self.end_record(|| format!("the header of element block {b}"))?;
            let kind = self.block_kind(etype).or_else(|m| fail(block, m))?;
            let (nn, dim, name) =
                kind.map_or((1, 0, "point"), |k| (k.nodes, k.kind.dim(), k.kind.name()));
            if edim != dim as i64 {
                return fail(
                    block,
                    format!(
                        "element block {b} is on an entity of dimension {edim} but holds \
                         {name}s (dimension {dim})"
                    ),
                );
            }
            let each = self.size_t as u64 * (1 + nn as u64);
            self.check_room(n, each, || format!("element block {b} of {n} elements"))?;
            for k in 1..=n {
                self.begin(|| format!("element {k} of {n} in block {b}"))?;
                let location = self.rec_location();
                let tag = self.size(|| format!("the tag of element {k} of {n} in block {b}"))?;
                let vertices = self.element_nodes(kind, i128::from(tag), false)?;
                self.end_record(|| format!("element {tag}"))?;
                *read += 1;
                if let Some(kind) = kind {
                    self.push_element(dim, kind, vertices, entity, i128::from(tag), location);
                }
            }
        }
        if *read != nelems {
            return fail(
                header,
                format!("element count in $Elements header is {nelems} but the blocks hold {read}"),
            );
        }
        self.expect_end("Elements", || {
            format!(" after the {nblocks} element blocks announced in the $Elements header")
        })
    }

    fn elements_v2(&mut self, announced: &mut Option<u64>, read: &mut u64) -> R<()> {
        self.begin_text(|| "the number of elements".into())?;
        let n = self.size(|| "the number of elements".into())?;
        self.end_record(|| "the number of elements".into())?;
        *announced = Some(n);
        if self.binary {
            while *read < n {
                let at = Location::Byte(self.pos as u64);
                self.rec_text = false;
                let etype = self.int(|| "the element type of an element block header".into())?;
                let count = self.int(|| "the element count of an element block header".into())?;
                let ntags = self.int(|| "the tag count of an element block header".into())?;
                let kind = self.block_kind(etype).or_else(|m| fail(at, m))?;
                let left = n - *read;
                let count = match u64::try_from(count) {
                    Ok(c) if c >= 1 && c <= left => c,
                    _ => {
                        return fail(
                            at,
                            format!(
                                "element block header announces {count} elements, expected 1 to \
                                 {left} (the elements left of the {n} in the $Elements header)"
                            ),
                        )
                    }
                };
                let Ok(ntags) = u64::try_from(ntags) else {
                    return fail(
                        at,
                        format!("expected a non-negative tag count, found {ntags}"),
                    );
                };
                let nn = kind.map_or(1, |k| k.nodes) as u64;
                let each = 4u64.saturating_mul(1 + ntags.saturating_add(nn));
                self.check_room(count, each, || format!("element block of {count} elements"))?;
                for _ in 0..count {
                    let tag = self.int(|| "an element number".into())?;
                    self.rec_loc = Location::Byte(self.field_at as u64);
                    self.element_v2(kind, tag, ntags)?;
                    *read += 1;
                }
            }
        } else {
            for i in 0..n {
                if let Some(loc) = self.peek_dollar() {
                    return fail(
                        loc,
                        format!(
                            "element count in $Elements header is {n} but the section holds {i}"
                        ),
                    );
                }
                self.begin_text(|| format!("element {} of {n}", i + 1))?;
                let tag = self.int(|| format!("the number of element {} of {n}", i + 1))?;
                let etype = self.int(|| format!("the type of element {tag}"))?;
                let kind = self.block_kind(etype).or_else(|m| fail(self.rec_loc, m))?;
                let ntags = self.int(|| format!("the number of tags of element {tag}"))?;
                let Ok(ntags) = u64::try_from(ntags) else {
                    return fail(
                        self.rec_loc,
                        format!(
                            "expected a non-negative tag count for element {tag}, found {ntags}"
                        ),
                    );
                };
                self.element_v2(kind, tag, ntags)?;
                self.end_record(|| format!("element {tag}"))?;
                *read += 1;
            }
        }
        self.expect_end("Elements", || {
            format!(" after the {n} elements announced in the $Elements header")
        })
    }

    /// The tags and nodes of one MSH 2 element (after its number, type and tag count).
    fn element_v2(&mut self, kind: Option<BlockKind>, tag: i64, ntags: u64) -> R<()> {
        let location = self.rec_loc;
        let mut physical = 0;
        let mut entity = 0;
        for j in 0..ntags {
            let v = self.int32(|| format!("tag {} of element {tag}", j + 1))?;
            match j {
                0 => physical = v,
                1 => entity = v,
                _ => {}
            }
        }
        let vertices = self.element_nodes(kind, i128::from(tag), true)?;
        let dim = kind.map_or(0, |k| k.kind.dim());
        let triple = (dim, entity, physical);
        if self.last_triple != Some(triple) {
            self.last_triple = Some(triple);
            if physical != 0 {
                let e = self.entity_physicals.entry((dim, entity)).or_default();
                if let Err(p) = e.binary_search(&physical) {
                    e.insert(p, physical);
                }
            }
            if kind.is_some() {
                let first = *self.first_physical.entry((dim, entity)).or_insert(physical);
                if first != physical && self.dedup.is_none() {
                    // MSH 2 repeats an element once per physical group of its entity: from
                    // now on, remember every element and merge the copies.
                    let set = self
                        .by_dim
                        .iter()
                        .flatten()
                        .map(|e| dedup_key(e.kind, e.entity, &e.vertices))
                        .collect();
                    self.dedup = Some(set);
                }
            }
        }
        let Some(kind) = kind else {
            return Ok(());
        };
        if let Some(set) = &mut self.dedup {
            if !set.insert(dedup_key(kind.kind, entity, &vertices)) {
                return Ok(());
            }
        }
        self.push_element(dim, kind, vertices, entity, i128::from(tag), location);
        Ok(())
    }

    fn finish(mut self) -> R<LinearMesh> {
        if self.nodes.is_none() {
            return fail(Location::EndOfFile, "the file has no $Nodes section");
        }
        if !self.have_elements {
            return fail(Location::EndOfFile, "the file has no $Elements section");
        }
        let Some(dim) = (1..=3)
            .rev()
            .find(|&d| self.by_dim.get(d).is_some_and(|l| !l.is_empty()))
        else {
            return fail(
                Location::EndOfFile,
                "the file has no line, surface or volume elements",
            );
        };
        let cells = self
            .by_dim
            .get_mut(dim)
            .map(std::mem::take)
            .unwrap_or_default();
        let facets = self
            .by_dim
            .get_mut(dim - 1)
            .map(std::mem::take)
            .unwrap_or_default();
        Ok(LinearMesh {
            dim,
            vertices: self.vertices,
            cells,
            facets,
            physical_groups: physical_groups(self.names, &self.entity_physicals),
            entity_physicals: self.entity_physicals,
            vertex_tags: self.node_tags,
            cell_tags: self
                .element_tags
                .get_mut(dim)
                .map(std::mem::take)
                .unwrap_or_default(),
            facet_tags: self
                .element_tags
                .get_mut(dim - 1)
                .map(std::mem::take)
                .unwrap_or_default(),
        })
    }

    /// The high-order reader's result: cells of the top dimension (3 if the file has
    /// volume elements, else 2), facets one dimension lower, all of one order, their nodes
    /// in Gmsh's order.
    fn finish_high_order(mut self) -> R<GmshElements> {
        if self.nodes.is_none() {
            return fail(Location::EndOfFile, "the file has no $Nodes section");
        }
        if !self.have_elements {
            return fail(Location::EndOfFile, "the file has no $Elements section");
        }
        let Some(dim) = [3, 2]
            .into_iter()
            .find(|&d| self.by_dim.get(d).is_some_and(|l| !l.is_empty()))
        else {
            return fail(
                Location::EndOfFile,
                "the file has no surface or volume elements (hocurve meshes are 2D or 3D)",
            );
        };
        let mut take = |d: usize| {
            let elements = self
                .by_dim
                .get_mut(d)
                .map(std::mem::take)
                .unwrap_or_default();
            let records = self
                .element_records
                .get_mut(d)
                .map(std::mem::take)
                .unwrap_or_default();
            (elements, records)
        };
        let (cells, cell_records) = take(dim);
        let (facets, facet_records) = take(dim - 1);
        let Some(first) = cell_records.first().copied() else {
            return fail(Location::EndOfFile, "the file has no cells");
        };
        for r in cell_records.iter().chain(&facet_records) {
            if r.order != first.order {
                return fail(
                    r.location,
                    format!(
                        "mixed element orders: element {} is of order {} but element {} ({}) \
                         is of order {}; a hocurve mesh has a single order",
                        r.tag, r.order, first.tag, first.location, first.order
                    ),
                );
            }
        }
        Ok(GmshElements {
            dim,
            order: first.order,
            physical_groups: physical_groups(self.names, &self.entity_physicals),
            entity_physicals: self.entity_physicals,
            nodes: self.vertices,
            node_tags: self.node_tags,
            cells,
            cell_records,
            facets,
            facet_records,
        })
    }
}

/// Physical groups: the named ones plus every physical tag used but not named.
fn physical_groups(
    names: Vec<PhysicalGroup>,
    entity_physicals: &BTreeMap<(usize, i32), Vec<i32>>,
) -> Vec<PhysicalGroup> {
    let mut groups: BTreeMap<(usize, i32), String> = BTreeMap::new();
    for g in names {
        groups.entry((g.dim, g.tag)).or_insert(g.name);
    }
    for (&(d, _), tags) in entity_physicals {
        for &t in tags {
            groups.entry((d, t)).or_default();
        }
    }
    groups
        .into_iter()
        .map(|((dim, tag), name)| PhysicalGroup { dim, tag, name })
        .collect()
}

/// What the high-order reader collected, before renumbering.
struct GmshElements {
    dim: usize,
    order: usize,
    physical_groups: Vec<PhysicalGroup>,
    entity_physicals: BTreeMap<(usize, i32), Vec<i32>>,
    /// All nodes, in file order.
    nodes: Vec<[f64; 3]>,
    /// Their tags.
    node_tags: Vec<u64>,
    /// Elements with all their nodes (indices into `nodes`) in Gmsh's order.
    cells: Vec<Element>,
    cell_records: Vec<ElementRecord>,
    facets: Vec<Element>,
    facet_records: Vec<ElementRecord>,
}

/// Reads a Gmsh mesh of complete Lagrange elements of any order (MSH 4.1 or 2.2, ASCII or
/// binary, as written by [`crate::write_msh`] or by Gmsh) for quality assessment.
///
/// - Elements: lines, triangles, quadrilaterals, tetrahedra, hexahedra and prisms, complete
///   (Gmsh types `MSH_LIN_2` … `MSH_LIN_11`, `MSH_TRI_3` … `MSH_TRI_66`, `MSH_QUA_4` …
///   `MSH_QUA_121`, `MSH_TET_4` … `MSH_TET_286`, `MSH_HEX_8` … `MSH_HEX_1000`, `MSH_PRI_6` …
///   `MSH_PRI_550`: orders 1 to 10, 9 for hexahedra and prisms), their nodes renumbered
///   from Gmsh's order into hocurve's canonical order ([`crate::ordering`]) on
///   [`NodeFamily::Equispaced`] reference nodes.
/// - Cells: the elements of the top dimension, 3 if there are volume elements, else 2 (2D
///   meshes are expected in the plane z = 0). Facets: the elements one dimension lower
///   whose corners are a face (3D) or edge (2D) of the cells; the others, and all
///   lower-dimensional elements and points, are ignored (a [`HighOrderMesh`] holds only
///   cells and their facets).
/// - Errors, naming the file and the line (byte in binary files) or element: elements of
///   different orders, incomplete (serendipity) elements such as Gmsh types 16 (8-node
///   quadrilateral), 17 (20-node hexahedron) and 18 (15-node prism), pyramids, unknown
///   types, missing nodes, elements that do not share their edge and face nodes.
///
/// Nodes are renumbered as by [`HighOrderMesh::from_cells`] (vertices first; nodes no cell
/// uses are dropped); cells and facets keep their order in the file.
pub fn read_high_order_msh(path: &Path) -> Result<HighOrderMesh, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Os {
        path: path.to_path_buf(),
        source,
    })?;
    parse_high_order_msh(&bytes, path)
}

/// [`read_high_order_msh`] from bytes already in memory; `path` only names the file in
/// errors.
pub fn parse_high_order_msh(bytes: &[u8], path: &Path) -> Result<HighOrderMesh, IoError> {
    let malformed = |location: Location, message: String| IoError::Malformed {
        path: path.to_path_buf(),
        location,
        message,
    };
    let mut parser = Parser::new(bytes);
    parser.high_order = true;
    let raw = parser
        .read_sections()
        .and_then(|()| parser.finish_high_order())
        .map_err(|e| malformed(e.location, e.message))?;
    let p = raw.order;
    let mut permutations: HashMap<ElementType, Vec<usize>> = HashMap::new();
    let mut canonical = |list: &[Element]| -> Result<Vec<HighOrderElement>, MeshError> {
        list.iter()
            .map(|e| {
                let perm = match permutations.entry(e.kind) {
                    std::collections::hash_map::Entry::Occupied(o) => o.into_mut(),
                    std::collections::hash_map::Entry::Vacant(v) => {
                        v.insert(gmsh_permutation(e.kind.shape()?, p))
                    }
                };
                let mut nodes = vec![0; e.vertices.len()];
                for (&k, &n) in perm.iter().zip(&e.vertices) {
                    nodes[k] = n;
                }
                Ok(HighOrderElement {
                    kind: e.kind,
                    nodes,
                    entity: e.entity,
                })
            })
            .collect()
    };
    let as_mesh_error = |source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    };
    let cells = canonical(&raw.cells).map_err(as_mesh_error)?;
    let facets = canonical(&raw.facets).map_err(as_mesh_error)?;
    let built = HighOrderMesh::from_cells(
        raw.dim,
        p,
        NodeFamily::Equispaced,
        &raw.nodes,
        &cells,
        &facets,
    );
    let mut mesh = built.map_err(|source| {
        // Name the element and nodes as the file does.
        let node_tag = |i: usize| raw.node_tags.get(i).copied().unwrap_or(i as u64);
        let records = |what: &str| {
            if what == "cell" {
                &raw.cell_records
            } else {
                &raw.facet_records
            }
        };
        match source {
            MeshError::NonConformingNode {
                what,
                index,
                node,
                other,
                ..
            } => match records(what).get(index) {
                Some(r) => malformed(
                    r.location,
                    format!(
                        "element {} has node {} where a neighbouring element has node {} at a \
                         different position: the elements do not share their edge or face nodes",
                        r.tag,
                        node_tag(node),
                        node_tag(other)
                    ),
                ),
                None => as_mesh_error(source),
            },
            // The check ran on renumbered corners: the element is named by its record,
            // not by the tags in `source`.
            MeshError::RepeatedVertex { what, index, .. } => match records(what).get(index) {
                Some(r) => malformed(
                    r.location,
                    format!("element {} uses a node twice (collapsed element)", r.tag),
                ),
                None => as_mesh_error(source),
            },
            other => as_mesh_error(other),
        }
    })?;
    mesh.physical_groups = raw.physical_groups;
    mesh.entity_physicals = raw.entity_physicals;
    Ok(mesh)
}

#[cfg(test)]
#[path = "tests/msh_read.rs"]
mod tests;

#[cfg(test)]
#[path = "tests/msh_read_high_order.rs"]
mod high_order_tests;
