use super::*;
use crate::{IoError, Location};
use hocurve_mesh::{Element, LinearMesh, PhysicalGroup, Shape};
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/formats")
        .join(name)
}

fn parse(s: &str) -> Result<LinearMesh, IoError> {
    parse_msh(s.as_bytes(), Path::new("test.msh"))
}

/// The location and message of a `Malformed` error.
fn malformed(r: Result<LinearMesh, IoError>) -> (Location, String) {
    match r {
        Err(IoError::Malformed {
            location, message, ..
        }) => (location, message),
        Err(e) => panic!("expected a Malformed error, got {e}"),
        Ok(_) => panic!("expected an error, got a mesh"),
    }
}

/// 1-based number of the first line equal to `line`.
fn line_of(s: &str, line: &str) -> usize {
    s.lines()
        .position(|l| l.trim() == line)
        .expect("line in text")
        + 1
}

const MSH41: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$Comments
a comment with $Nodes inside
$EndComments
$PhysicalNames
2
1 7 \"wall\"
2 9 \"fluid domain\"
$EndPhysicalNames
$Entities
0 1 1 0
3 0 0 0 1 0 0 1 7 0
5 0 0 0 1 1 0 2 9 11 0
$EndEntities
$Nodes
2 4 10 40
2 5 0 3
40
10
30
1 1 0
0 0 0
1 0 0
1 3 0 1
20
0 1 0.5
$EndNodes
$Elements
2 3 1 100
2 5 2 2
100 10 30 40
7 10 40 20
1 3 1 1
5 10 30
$EndElements
$NodeData
1
\"x\"
1
0.0
3
0
1
1
10 1.0
$EndNodeData
";

const MSH22: &str = "$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
1 7 \"wall\"
2 9 \"fluid domain\"
$EndPhysicalNames
$Nodes
4
40 1 1 0
10 0 0 0
30 1 0 0
20 0 1 0.5
$EndNodes
$Elements
6
1 15 2 0 1 10
2 1 2 7 3 10 30
100 2 2 9 5 10 30 40
7 2 2 9 5 10 40 20
101 2 2 11 5 10 30 40
102 2 3 11 5 0 10 40 20
$EndElements
$ElementData
1
\"e\"
1
0.0
3
0
1
1
100 1.0
$EndElementData
";

fn check_small(m: &LinearMesh) {
    assert_eq!(m.dim, 2);
    assert_eq!(
        m.vertices,
        vec![
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.5]
        ]
    );
    let tri = |v: Vec<u32>| Element {
        kind: Shape::Tri,
        vertices: v,
        entity: 5,
    };
    assert_eq!(m.cells, vec![tri(vec![1, 2, 0]), tri(vec![1, 0, 3])]);
    assert_eq!(
        m.facets,
        vec![Element {
            kind: Shape::Line,
            vertices: vec![1, 2],
            entity: 3
        }]
    );
    let g = |dim, tag, name: &str| PhysicalGroup {
        dim,
        tag,
        name: name.into(),
    };
    assert_eq!(
        m.physical_groups,
        vec![g(1, 7, "wall"), g(2, 9, "fluid domain"), g(2, 11, "")]
    );
    assert_eq!(m.physical_tags(1, 3), &[7]);
    assert_eq!(m.physical_tags(2, 5), &[9, 11]);
    assert_eq!(m.entity_physicals.len(), 2);
    assert_eq!(m.physical_group("fluid domain").map(|g| g.tag), Some(9));
}

#[test]
fn small_ascii_v41() {
    check_small(&parse(MSH41).unwrap());
}

#[test]
fn small_ascii_v22_merges_copies_per_physical_group() {
    check_small(&parse(MSH22).unwrap());
}

#[test]
fn windows_line_endings_and_huge_sparse_tags() {
    let s = MSH41.replace("40", "5000000000040").replace('\n', "\r\n");
    check_small(&parse(&s).unwrap());
    let s = MSH22.replace("40", "2000000040");
    check_small(&parse(&s).unwrap());
}

#[test]
fn parametric_nodes_are_read() {
    let s = MSH41
        .replace("1 3 0 1\n20\n0 1 0.5", "1 3 1 1\n20\n0 1 0.5 0.25")
        .replace("2 5 0 3", "2 5 1 3")
        .replace("1 1 0\n0 0 0\n1 0 0", "1 1 0 1 1\n0 0 0 0 0\n1 0 0 1 0");
    check_small(&parse(&s).unwrap());
}

// ---------------------------------------------------------------- binary writers

struct Bin {
    out: Vec<u8>,
    be: bool,
}

impl Bin {
    fn text(&mut self, s: &str) -> &mut Self {
        self.out.extend_from_slice(s.as_bytes());
        self
    }
    fn i(&mut self, v: i32) -> &mut Self {
        let b = if self.be {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.out.extend_from_slice(&b);
        self
    }
    fn u(&mut self, v: u64) -> &mut Self {
        let b = if self.be {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.out.extend_from_slice(&b);
        self
    }
    fn f(&mut self, v: f64) -> &mut Self {
        let b = if self.be {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.out.extend_from_slice(&b);
        self
    }
}

const NODES: [(u64, [f64; 3]); 4] = [
    (40, [1.0, 1.0, 0.0]),
    (10, [0.0, 0.0, 0.0]),
    (30, [1.0, 0.0, 0.0]),
    (20, [0.0, 1.0, 0.5]),
];

const NAMES: &str = "$PhysicalNames\n2\n1 7 \"wall\"\n2 9 \"fluid domain\"\n$EndPhysicalNames\n";

fn binary_v41(be: bool) -> Vec<u8> {
    let mut b = Bin { out: vec![], be };
    b.text("$MeshFormat\n4.1 1 8\n")
        .i(1)
        .text("\n$EndMeshFormat\n");
    b.text(NAMES).text("$Entities\n").u(0).u(1).u(1).u(0);
    b.i(3);
    for x in [0.0, 0.0, 0.0, 1.0, 0.0, 0.0] {
        b.f(x);
    }
    b.u(1).i(7).u(0);
    b.i(5);
    for x in [0.0, 0.0, 0.0, 1.0, 1.0, 0.0] {
        b.f(x);
    }
    b.u(2).i(9).i(11).u(0).text("\n$EndEntities\n");
    b.text("$Nodes\n").u(2).u(4).u(10).u(40);
    b.i(2).i(5).i(0).u(3);
    for (t, _) in &NODES[..3] {
        b.u(*t);
    }
    for (_, x) in &NODES[..3] {
        b.f(x[0]).f(x[1]).f(x[2]);
    }
    b.i(1).i(3).i(0).u(1).u(20).f(0.0).f(1.0).f(0.5);
    b.text("\n$EndNodes\n$Elements\n").u(2).u(3).u(1).u(100);
    b.i(2)
        .i(5)
        .i(2)
        .u(2)
        .u(100)
        .u(10)
        .u(30)
        .u(40)
        .u(7)
        .u(10)
        .u(40)
        .u(20);
    b.i(1).i(3).i(1).u(1).u(5).u(10).u(30);
    b.text("\n$EndElements\n$NodeData\n1\n\"x\"\n1\n0.0\n3\n0\n1\n1\n");
    // Binary node data that contains '$' and newlines.
    b.i(10).text("$End\n$EndNode\n").text("\n$EndNodeData\n");
    b.out
}

fn binary_v22(be: bool) -> Vec<u8> {
    let mut b = Bin { out: vec![], be };
    b.text("$MeshFormat\n2.2 1 8\n")
        .i(1)
        .text("\n$EndMeshFormat\n");
    b.text(NAMES).text("$Nodes\n4\n");
    for (t, x) in NODES {
        b.i(t as i32).f(x[0]).f(x[1]).f(x[2]);
    }
    b.text("\n$EndNodes\n$Elements\n5\n");
    b.i(2).i(4).i(2);
    b.i(100).i(9).i(5).i(10).i(30).i(40);
    b.i(7).i(9).i(5).i(10).i(40).i(20);
    b.i(101).i(11).i(5).i(10).i(30).i(40);
    b.i(102).i(11).i(5).i(10).i(40).i(20);
    b.i(1).i(1).i(2).i(5).i(7).i(3).i(10).i(30);
    b.text("\n$EndElements\n");
    b.out
}

#[test]
fn small_binary_both_endiannesses() {
    for be in [false, true] {
        let m = parse_msh(&binary_v41(be), Path::new("b41.msh")).unwrap();
        check_small(&m);
        let m = parse_msh(&binary_v22(be), Path::new("b22.msh")).unwrap();
        check_small(&m);
    }
}

#[test]
fn binary_errors_name_byte_offsets() {
    let good = binary_v41(false);
    // Endianness check.
    let mut bad = good.clone();
    let at = b"$MeshFormat\n4.1 1 8\n".len();
    bad[at] = 7;
    let (loc, msg) = malformed(parse_msh(&bad, Path::new("b.msh")));
    assert_eq!(loc, Location::Byte(at as u64));
    assert!(msg.contains("endianness"), "{msg}");
    // A node reference that is not in $Nodes: the tag of node 30 in element 100.
    let elements = find(&good, b"$Elements\n") + 10;
    let first_node = elements + 32 + 20 + 8;
    let mut bad = good.clone();
    bad[first_node + 8..first_node + 16].copy_from_slice(&9999u64.to_le_bytes());
    let (loc, msg) = malformed(parse_msh(&bad, Path::new("b.msh")));
    assert_eq!(loc, Location::Byte(first_node as u64 + 8));
    assert!(
        msg.contains("element 100 references node 9999 which is not in $Nodes"),
        "{msg}"
    );
    // Truncated inside the element data.
    let (loc, msg) = malformed(parse_msh(&good[..elements + 140], Path::new("b.msh")));
    assert_eq!(loc, Location::EndOfFile);
    assert!(
        msg.contains("unexpected end of file in $Elements (expected 3 elements, read 2)"),
        "{msg}"
    );
}

fn find(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len())
        .position(|w| w == needle)
        .expect("needle in haystack")
}

// ---------------------------------------------------------------- fixtures

#[test]
fn cube_in_four_formats_reads_identically() {
    let names = [
        "cube_v41_ascii.msh",
        "cube_v41_binary.msh",
        "cube_v22_ascii.msh",
        "cube_v22_binary.msh",
    ];
    let meshes: Vec<LinearMesh> = names
        .iter()
        .map(|n| read_msh(&fixture(n)).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    let m = &meshes[0];
    assert_eq!(m.dim, 3);
    assert_eq!(m.vertices.len(), 27);
    assert!(m.cells.iter().all(|c| c.kind == Shape::Tet));
    assert!(m.facets.iter().all(|c| c.kind == Shape::Tri));
    assert_eq!(m.facets.len(), 48);
    let names: Vec<(usize, i32, &str)> = m
        .physical_groups
        .iter()
        .map(|g| (g.dim, g.tag, g.name.as_str()))
        .collect();
    assert_eq!(
        names,
        vec![
            (2, 1, "left"),
            (2, 2, "right"),
            (2, 3, "others"),
            (3, 4, "solid")
        ]
    );
    // Every facet and cell carries exactly one physical tag.
    for f in &m.facets {
        assert_eq!(m.physical_tags(2, f.entity).len(), 1);
    }
    for c in &m.cells {
        assert_eq!(m.physical_tags(3, c.entity), &[4]);
    }
    for (other, name) in meshes.iter().zip(names.iter()).skip(1) {
        assert_eq!(other, m, "{name:?} differs from the MSH 4.1 ASCII file");
    }
}

#[test]
fn square_2d_in_both_versions() {
    let a = read_msh(&fixture("square_v41_ascii.msh")).unwrap();
    let b = read_msh(&fixture("square_v22_ascii.msh")).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.dim, 2);
    assert_eq!(a.vertices.len(), 20);
    assert_eq!(a.facets.len(), 12);
    assert_eq!(a.cells.len(), 26);
    assert!(a.vertices.iter().all(|v| v[2] == 0.0));
    let sides = a.physical_group("sides").unwrap().tag;
    assert_eq!(a.physical_tags(1, 2), &[sides]);
    assert_eq!(a.physical_tags(1, 4), &[sides]);
    assert_eq!(a.physical_group("domain").map(|g| g.dim), Some(2));
}

#[test]
fn pyramid_fixture_is_rejected_with_its_line() {
    let path = fixture("pyramid_v41.msh");
    let text = std::fs::read_to_string(&path).unwrap();
    let (loc, msg) = malformed(read_msh(&path));
    assert!(msg.contains("pyramid elements are not supported"), "{msg}");
    let Location::Line(l) = loc else {
        panic!("expected a line, got {loc}")
    };
    let fields: Vec<&str> = text
        .lines()
        .nth(l - 1)
        .unwrap()
        .split_whitespace()
        .collect();
    assert_eq!(
        fields.get(2),
        Some(&"7"),
        "line {l} is not a pyramid block header"
    );
    let err = read_msh(&path).unwrap_err().to_string();
    assert!(err.contains("pyramid_v41.msh: line "), "{err}");
}

#[test]
fn second_order_fixture_is_rejected() {
    let (loc, msg) = malformed(read_msh(&fixture("cube_p2_v41.msh")));
    assert!(matches!(loc, Location::Line(_)));
    assert!(
        msg.contains("(6-node second order triangle) is a high-order element")
            || msg.contains("(10-node second order tetrahedron) is a high-order element"),
        "{msg}"
    );
    assert!(msg.contains("Mesh.ElementOrder = 1"), "{msg}");
}

#[test]
fn missing_file_is_an_os_error() {
    let e = read_msh(Path::new("/nonexistent/dir/mesh.msh")).unwrap_err();
    assert!(matches!(e, IoError::Os { .. }), "{e}");
}

// ---------------------------------------------------------------- malformed input

#[test]
fn wrong_node_count_in_header() {
    let s = MSH41.replace("2 4 10 40", "2 5 10 40");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "2 5 10 40")));
    assert!(
        msg.contains("node count in $Nodes header is 5 but the blocks hold 4"),
        "{msg}"
    );
    let s = MSH22.replace("$Nodes\n4", "$Nodes\n5");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "$EndNodes")));
    assert!(
        msg.contains("node count in $Nodes header is 5 but the section holds 4"),
        "{msg}"
    );
    let s = MSH22.replace("$Nodes\n4", "$Nodes\n3");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "20 0 1 0.5")));
    assert!(
        msg.contains("expected $EndNodes after the 3 nodes"),
        "{msg}"
    );
}

#[test]
fn wrong_element_count_in_header() {
    let s = MSH41.replace("2 3 1 100", "2 4 1 100");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "2 4 1 100")));
    assert!(
        msg.contains("element count in $Elements header is 4 but the blocks hold 3"),
        "{msg}"
    );
    let s = MSH22.replace("$Elements\n6", "$Elements\n7");
    let (_, msg) = malformed(parse(&s));
    assert!(
        msg.contains("element count in $Elements header is 7 but the section holds 6"),
        "{msg}"
    );
}

#[test]
fn unknown_and_high_order_element_types() {
    let s = MSH41.replace("2 5 2 2", "2 5 999 2");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "2 5 999 2")));
    assert!(msg.contains("unknown element type 999"), "{msg}");

    let s = MSH22.replace("7 2 2 9 5 10 40 20", "7 11 2 9 5 10 40 20");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "7 11 2 9 5 10 40 20")));
    assert_eq!(
        msg,
        "element type 11 (10-node second order tetrahedron) is a high-order element; \
             hocurve reads linear meshes (Mesh.ElementOrder = 1)"
    );
    let (_, msg) = malformed(parse(&MSH41.replace("2 5 2 2", "2 5 9 2")));
    assert!(
        msg.contains("element type 9 (6-node second order triangle)"),
        "{msg}"
    );
    let (_, msg) = malformed(parse(&MSH41.replace("2 5 2 2", "2 5 34 2")));
    assert!(
        msg.contains("element type 34 (polygon) is not supported"),
        "{msg}"
    );
}

#[test]
fn pyramid_is_rejected() {
    let s = MSH22.replace("7 2 2 9 5 10 40 20", "7 7 2 9 5 10 40 20 30 1");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "7 7 2 9 5 10 40 20 30 1")));
    assert!(msg.contains("pyramid elements are not supported"), "{msg}");
    let e = parse(&s).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "test.msh: line {}: pyramid elements",
            line_of(&s, "7 7 2 9 5 10 40 20 30 1")
        )),
        "{e}"
    );
}

#[test]
fn node_not_in_nodes() {
    let s = MSH41.replace("100 10 30 40", "100 10 30 9999");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "100 10 30 9999")));
    assert_eq!(
        msg,
        "element 100 references node 9999 which is not in $Nodes"
    );
    let s = MSH22.replace("100 2 2 9 5 10 30 40", "100 2 2 9 5 10 30 -4");
    let (_, msg) = malformed(parse(&s));
    assert!(msg.contains("element 100 references node -4"), "{msg}");
}

#[test]
fn wrong_number_of_node_tags() {
    let s = MSH41.replace("100 10 30 40", "100 10 30");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "100 10 30")));
    assert_eq!(
        msg,
        "expected 3 node tags for a triangle (element 100), found 2"
    );
    let s = MSH22.replace("2 1 2 7 3 10 30", "2 1 2 7 3 10 30 40");
    let (_, msg) = malformed(parse(&s));
    assert_eq!(msg, "expected 2 node tags for a line (element 2), found 3");
}

#[test]
fn format_header_errors() {
    let (loc, msg) = malformed(parse(
        &MSH41.replace("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n", ""),
    ));
    assert_eq!(loc, Location::Line(1));
    assert!(msg.contains("expected $MeshFormat"), "{msg}");
    let (loc, msg) = malformed(parse(&MSH41.replace("4.1 0 8", "3.0 0 8")));
    assert_eq!(loc, Location::Line(2));
    assert!(msg.contains("unsupported MSH version '3.0'"), "{msg}");
    let (_, msg) = malformed(parse(&MSH41.replace("4.1 0 8", "4 0 8")));
    assert!(msg.contains("4.0 is not supported"), "{msg}");
    let (loc, msg) = malformed(parse(&MSH41.replace("4.1 0 8", "4.1 2 8")));
    assert_eq!(loc, Location::Line(2));
    assert!(msg.contains("file type"), "{msg}");
    let (loc, msg) = malformed(parse(""));
    assert_eq!(loc, Location::EndOfFile);
    assert!(msg.contains("empty"), "{msg}");
    let (loc, msg) = malformed(parse("$NOD\n1\n1 0 0 0\n$ENDNOD\n"));
    assert_eq!(loc, Location::Line(1));
    assert!(msg.contains("MSH 1.0"), "{msg}");
}

#[test]
fn partitioned_meshes_are_rejected() {
    let s = MSH41.replace(
        "$Entities",
        "$PartitionedEntities\n1\n0\n$EndPartitionedEntities\n$Entities",
    );
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "$PartitionedEntities")));
    assert!(
        msg.contains("partitioned meshes are not supported"),
        "{msg}"
    );
}

#[test]
fn other_structural_errors() {
    // Text between sections.
    let s = MSH41.replace("$Entities\n", "garbage\n$Entities\n");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "garbage")));
    assert!(msg.contains("expected a section header"), "{msg}");
    // A bad coordinate.
    let s = MSH41.replace("0 1 0.5", "0 1 zero");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "0 1 zero")));
    assert_eq!(msg, "expected the z coordinate of node 20, found 'zero'");
    // A duplicated node tag.
    let s = MSH41.replace("\n20\n", "\n30\n");
    let (_, msg) = malformed(parse(&s));
    assert!(msg.contains("node tag 30 appears more than once"), "{msg}");
    // An unterminated unknown section.
    let s = MSH41.replace("$EndNodeData\n", "");
    let (loc, msg) = malformed(parse(&s));
    assert_eq!(loc, Location::Line(line_of(&s, "$NodeData")));
    assert!(msg.contains("$NodeData has no $EndNodeData"), "{msg}");
    // Elements before nodes.
    let s = MSH22
        .replace("$Nodes", "$Xodes")
        .replace("$EndNodes", "$EndXodes");
    let (_, msg) = malformed(parse(&s));
    assert!(msg.contains("$Elements comes before $Nodes"), "{msg}");
    // An element block on the wrong dimension.
    let (_, msg) = malformed(parse(&MSH41.replace("2 5 2 2", "3 5 2 2")));
    assert!(msg.contains("dimension 3 but holds triangles"), "{msg}");
    // Only points.
    let s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n\
                 $Elements\n1\n1 15 2 0 1 1\n$EndElements\n";
    let (_, msg) = malformed(parse(s));
    assert!(msg.contains("no line, surface or volume elements"), "{msg}");
}

#[test]
fn mesh_errors_come_from_validate() {
    // A collapsed triangle.
    let s = MSH41.replace("7 10 40 20", "7 10 40 10");
    match parse(&s) {
        Err(IoError::Mesh { source, .. }) => {
            assert!(source.to_string().contains("twice"), "{source}")
        }
        other => panic!("expected a mesh error, got {other:?}"),
    }
}

#[test]
fn truncated_ascii_files() {
    // Cut in the middle of the element list.
    let cut = MSH41.find("7 10 40 20").unwrap();
    let (loc, msg) = malformed(parse(&MSH41[..cut]));
    assert_eq!(loc, Location::EndOfFile);
    assert_eq!(
        msg,
        "unexpected end of file in $Elements (expected 3 elements, read 1)"
    );
    // Cut in the middle of a line of coordinates.
    let cut = MSH41.find("0 1 0.5").unwrap() + 3;
    let (loc, msg) = malformed(parse(&MSH41[..cut]));
    assert_eq!(loc, Location::EndOfFile);
    assert_eq!(
        msg,
        "unexpected end of file in $Nodes (expected 4 nodes, read 3)"
    );
    // Cut inside an element line of MSH 2.
    let cut = MSH22.find("7 2 2 9 5 10 40 20").unwrap() + 12;
    let (_, msg) = malformed(parse(&MSH22[..cut]));
    assert_eq!(
        msg,
        "unexpected end of file in $Elements (expected 6 elements, read 3)"
    );
    // Cut right before $EndNodes.
    let cut = MSH22.find("$EndNodes").unwrap();
    let (_, msg) = malformed(parse(&MSH22[..cut]));
    assert!(
        msg.contains("unexpected end of file in $Nodes (all 4 nodes read; expected $EndNodes)"),
        "{msg}"
    );
    // Cut inside $Entities and $PhysicalNames.
    let cut = MSH41.find("5 0 0 0 1 1 0").unwrap();
    let (_, msg) = malformed(parse(&MSH41[..cut]));
    assert!(
        msg.starts_with("unexpected end of file in $Entities"),
        "{msg}"
    );
    let cut = MSH41.find("2 9 \"fluid").unwrap();
    let (_, msg) = malformed(parse(&MSH41[..cut]));
    assert!(
        msg.starts_with("unexpected end of file in $PhysicalNames"),
        "{msg}"
    );
}

#[test]
fn truncated_binary_fixtures() {
    for name in ["cube_v41_binary.msh", "cube_v22_binary.msh"] {
        let bytes = std::fs::read(fixture(name)).unwrap();
        let nodes = find(&bytes, b"$Nodes\n") + 60;
        let elements = find(&bytes, b"$Elements\n") + 120;
        for (cut, section) in [(nodes, "$Nodes"), (elements, "$Elements")] {
            let (loc, msg) = malformed(parse_msh(&bytes[..cut], Path::new(name)));
            assert_eq!(loc, Location::EndOfFile, "{name}: {msg}");
            assert!(
                msg.starts_with(&format!("unexpected end of file in {section} (expected ")),
                "{name}: {msg}"
            );
        }
    }
}

/// Truncating or corrupting any fixture gives a result or an error, never a panic.
#[test]
fn fuzzed_fixtures_never_panic() {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(fixture(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "msh"))
        .map(|p| (p.display().to_string(), std::fs::read(&p).unwrap()))
        .collect();
    files.push(("binary_v41".into(), binary_v41(false)));
    files.push(("binary_v41_be".into(), binary_v41(true)));
    files.push(("binary_v22".into(), binary_v22(false)));
    files.push(("msh41".into(), MSH41.as_bytes().to_vec()));
    files.push(("msh22".into(), MSH22.as_bytes().to_vec()));
    assert!(files.len() >= 13);
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rand = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let path = Path::new("fuzz.msh");
    for (name, bytes) in &files {
        let n = bytes.len();
        let end_elements = bytes
            .windows(12)
            .rposition(|w| w == b"$EndElements")
            .unwrap();
        assert!(
            parse_msh(bytes, path).is_ok() || name.contains("p2") || name.contains("pyramid"),
            "{name}"
        );
        for k in 0..200 {
            let cut = n * k / 200;
            let r = parse_msh(&bytes[..cut], path);
            // Anything that loses the $EndElements line must fail.
            if cut < end_elements {
                assert!(r.is_err(), "{name} cut at {cut} of {n} was accepted");
            }
        }
        for _ in 0..200 {
            let mut b = bytes.clone();
            let at = (rand() % n as u64) as usize;
            b[at] = match rand() % 6 {
                0 => b[at] ^ 0xff,
                1 => b'9',
                2 => b'\n',
                3 => b'$',
                4 => 0,
                _ => b[at].wrapping_add(1),
            };
            let _ = parse_msh(&b, path);
        }
    }
}

/// A structured mesh of `6 n³` tetrahedra in MSH 4.1 ASCII.
fn big_tet_mesh(n: usize) -> String {
    use std::fmt::Write;
    let m = n + 1;
    let id = |i: usize, j: usize, k: usize| 1 + i + m * (j + m * k);
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    let nv = m * m * m;
    writeln!(s, "$Nodes\n1 {nv} 1 {nv}\n3 1 0 {nv}").unwrap();
    for t in 1..=nv {
        writeln!(s, "{t}").unwrap();
    }
    let h = 1.0 / n as f64;
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                writeln!(s, "{} {} {}", i as f64 * h, j as f64 * h, k as f64 * h).unwrap();
            }
        }
    }
    let ne = 6 * n * n * n;
    writeln!(s, "$EndNodes\n$Elements\n1 {ne} 1 {ne}\n3 1 4 {ne}").unwrap();
    let mut t = 0;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                for q in [
                    [0, 1, 2, 6],
                    [0, 2, 3, 6],
                    [0, 3, 7, 6],
                    [0, 7, 4, 6],
                    [0, 4, 5, 6],
                    [0, 5, 1, 6],
                ] {
                    t += 1;
                    writeln!(s, "{t} {} {} {} {} ", c[q[0]], c[q[1]], c[q[2]], c[q[3]]).unwrap();
                }
            }
        }
    }
    s.push_str("$EndElements\n");
    s
}

#[test]
fn structured_tet_mesh() {
    let m = parse(&big_tet_mesh(4)).unwrap();
    assert_eq!(m.cells.len(), 6 * 64);
    assert_eq!(m.vertices.len(), 125);
    assert!(m.facets.is_empty());
}

/// `cargo test -p hocurve-io --release -- --ignored --nocapture million`
#[test]
#[ignore]
fn million_tets_timing() {
    let s = big_tet_mesh(56);
    let t = std::time::Instant::now();
    let m = parse(&s).unwrap();
    eprintln!(
        "{} tets, {} MB: {:?}",
        m.cells.len(),
        s.len() / 1_000_000,
        t.elapsed()
    );
}

/// The file's node and element tags are kept for messages (sparse, unordered tags).
#[test]
fn node_and_element_tags_are_kept() {
    for (text, facet) in [(MSH41, 5), (MSH22, 2)] {
        let m = parse(text).unwrap();
        assert_eq!(m.vertex_tags, vec![40, 10, 30, 20]);
        assert_eq!(m.cell_tags, vec![100, 7]);
        assert_eq!(m.facet_tags, vec![facet]);
        assert_eq!(m.cell_tag(1), 7);
        assert_eq!(m.facet_tag(0), facet);
        assert_eq!(m.vertex_tag(0), 40);
    }
    // Binary files, both byte orders: the same tags (one per kept element, duplicates of
    // MSH 2's several physical tags dropped with their elements).
    for be in [false, true] {
        for m in [
            parse_msh(&binary_v41(be), Path::new("b41.msh")).unwrap(),
            parse_msh(&binary_v22(be), Path::new("b22.msh")).unwrap(),
        ] {
            assert_eq!(m.vertex_tags, vec![40, 10, 30, 20]);
            assert_eq!(m.cell_tags, vec![100, 7]);
            assert_eq!(m.facet_tags, vec![5]);
        }
    }
    let m = parse(&MSH41.replace("40", "5000000000040")).unwrap();
    assert_eq!(m.vertex_tag(0), 5000000000040);
}
