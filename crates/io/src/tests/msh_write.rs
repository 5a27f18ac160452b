use super::*;
use hocurve_mesh::{Element, LinearMesh, PhysicalGroup, Shape};
use hocurve_nodes::NodeFamily;

fn square() -> LinearMesh {
    let mut mesh = LinearMesh {
        dim: 2,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.7, 0.1, 0.0],
        ],
        cells: vec![
            Element {
                kind: Shape::Tri,
                vertices: vec![0, 1, 4],
                entity: 1,
            },
            Element {
                kind: Shape::Tri,
                vertices: vec![1, 2, 4],
                entity: 1,
            },
            Element {
                kind: Shape::Quad,
                vertices: vec![0, 4, 2, 3],
                entity: 2,
            },
        ],
        facets: vec![
            Element {
                kind: Shape::Line,
                vertices: vec![0, 1],
                entity: 5,
            },
            Element {
                kind: Shape::Line,
                vertices: vec![2, 3],
                entity: 6,
            },
        ],
        physical_groups: vec![
            PhysicalGroup {
                dim: 1,
                tag: 10,
                name: "bottom".into(),
            },
            PhysicalGroup {
                dim: 2,
                tag: 1,
                name: "domain".into(),
            },
        ],
        ..Default::default()
    };
    mesh.entity_physicals.insert((1, 5), vec![10]);
    mesh.entity_physicals.insert((2, 1), vec![1]);
    mesh.entity_physicals.insert((2, 2), vec![1]);
    mesh
}

#[test]
fn linear_mesh_is_written_as_expected() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.msh");
    let ho = HighOrderMesh::from_linear(&square(), 1, NodeFamily::Equispaced).unwrap();
    write_msh(&path, &ho).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let expected = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
1 10 \"bottom\"
2 1 \"domain\"
$EndPhysicalNames
$Entities
0 2 2 0
5 0.0 0.0 0.0 1.0 0.0 0.0 1 10 0
6 0.0 1.0 0.0 1.0 1.0 0.0 0 0
1 0.0 0.0 0.0 1.0 1.0 0.0 1 1 0
2 0.0 0.0 0.0 1.0 1.0 0.0 1 1 0
$EndEntities
$Nodes
3 5 1 5
1 5 0 2
1
2
0.0 0.0 0.0
1.0 0.0 0.0
1 6 0 2
3
4
1.0 1.0 0.0
0.0 1.0 0.0
2 1 0 1
5
0.7 0.1 0.0
$EndNodes
$Elements
4 5 1 5
1 5 1 1
1 1 2
1 6 1 1
2 3 4
2 1 2 2
3 1 2 5
4 2 3 5
2 2 3 1
5 1 5 3 4
$EndElements
";
    assert_eq!(text, expected);
}

#[test]
fn orders_without_a_gmsh_type_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.msh");
    let ho = HighOrderMesh::from_linear(&square(), 11, NodeFamily::Equispaced).unwrap();
    let err = write_msh(&path, &ho).unwrap_err().to_string();
    assert!(err.contains("Gmsh has no order-11"), "{err}");
    assert!(!path.exists());
}

#[test]
fn high_order_elements_use_gmsh_types_and_order() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.msh");
    let ho = HighOrderMesh::from_linear(&square(), 3, NodeFamily::Equispaced).unwrap();
    write_msh(&path, &ho).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    // Line 4 (26) facets, triangle 10 (21) and quadrilateral 16 (36) cells.
    assert!(text.contains("\n1 5 26 1\n"), "{text}");
    assert!(text.contains("\n2 1 21 2\n"), "{text}");
    assert!(text.contains("\n2 2 36 1\n"), "{text}");
    // Every element's node list, mapped back through the permutation, is the cell's.
    let perm = gmsh_permutation(Shape::Tri, 3);
    let first = &ho.cells[0];
    let line: Vec<String> = std::iter::once("3".to_string())
        .chain(perm.iter().map(|&k| (first.nodes[k] + 1).to_string()))
        .collect();
    assert!(text.contains(&format!("\n{}\n", line.join(" "))), "{text}");
}

/// The (tag, values) lines of the `index`-th `$<section>` view of a file, and its name.
fn view(text: &str, section: &str, index: usize) -> (String, usize, Vec<(usize, Vec<f64>)>) {
    let start = text
        .match_indices(&format!("${section}\n"))
        .nth(index)
        .expect("view present")
        .0;
    let body = &text[start..];
    let lines: Vec<&str> = body.lines().collect();
    // $Section, 1, "name", 1, time, 3, step, components, count, values…
    let name = lines[2].trim_matches('"').to_string();
    assert_eq!(&lines[3..7], &["1", "0", "3", "0"]);
    let components: usize = lines[7].parse().unwrap();
    let count: usize = lines[8].parse().unwrap();
    let values = lines[9..9 + count]
        .iter()
        .map(|l| {
            let mut it = l.split(' ');
            let tag = it.next().unwrap().parse().unwrap();
            (tag, it.map(|v| v.parse().unwrap()).collect())
        })
        .collect();
    assert_eq!(lines[9 + count], format!("$End{section}"));
    (name, components, values)
}

#[test]
fn node_and_element_data_views_follow_the_node_and_element_tags() {
    let dir = tempfile::tempdir().unwrap();
    let linear = crate::test_meshes::two_cells(hocurve_nodes::Shape::Tri);
    let mesh = crate::test_meshes::curved(&linear, 2);
    let temperature: Vec<f64> = mesh.nodes.iter().map(|x| 1.0 + x[0] * 0.1).collect();
    let velocity = [1.0, 2.0, 3.0, -4.0, 0.5, 1e-300];
    let path = dir.path().join("data.msh");
    write_msh_with(
        &path,
        &mesh,
        &[DataArray {
            name: "T",
            components: 1,
            values: &temperature,
        }],
        &[DataArray {
            name: "velocity",
            components: 3,
            values: &velocity,
        }],
    )
    .unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let (name, components, values) = view(&text, "NodeData", 0);
    assert_eq!(
        (name.as_str(), components, values.len()),
        ("T", 1, mesh.nodes.len())
    );
    for (i, (tag, v)) in values.iter().enumerate() {
        assert_eq!((*tag, v.as_slice()), (i + 1, &[temperature[i]][..]));
    }
    let (name, components, values) = view(&text, "ElementData", 0);
    assert_eq!((name.as_str(), components), ("velocity", 3));
    // Two facets are written first (tags 1, 2): the cells are elements 3 and 4.
    assert_eq!(
        values,
        vec![(3, vec![1.0, 2.0, 3.0]), (4, vec![-4.0, 0.5, 1e-300])]
    );
    // The data sections do not disturb the readers.
    let back = crate::read_high_order_msh(&path).unwrap();
    assert_eq!(back.nodes.len(), mesh.nodes.len());
    // write_msh is write_msh_with without data.
    let plain = dir.path().join("plain.msh");
    write_msh(&plain, &mesh).unwrap();
    let plain = std::fs::read_to_string(&plain).unwrap();
    assert!(text.starts_with(&plain) && !plain.contains("$NodeData"));
}

#[test]
fn write_mesh_with_resamples_point_data_like_the_nodes() {
    use hocurve_mesh::HighOrderMesh;
    let dir = tempfile::tempdir().unwrap();
    let linear = crate::test_meshes::hybrid(3);
    let f = |x: [f64; 3]| 0.5 + 2.0 * x[0] - x[1] + 0.25 * x[2];
    for p in [2, 4] {
        let mut mesh = HighOrderMesh::from_linear(&linear, p, NodeFamily::Fekete).unwrap();
        for x in &mut mesh.nodes {
            *x = [
                x[0] + 0.05 * (2.0 * x[1]).sin(),
                x[1] + 0.03 * x[0] * x[2],
                x[2],
            ];
        }
        let values: Vec<f64> = mesh.nodes.iter().map(|&x| f(x)).collect();
        let cell_values = [7.0, 8.0];
        let path = dir.path().join("fekete.msh");
        let point = [DataArray {
            name: "f",
            components: 1,
            values: &values,
        }];
        let cell = [DataArray {
            name: "c",
            components: 1,
            values: &cell_values,
        }];
        crate::write_mesh_with(&path, &mesh, &point, &cell).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let back = crate::read_high_order_msh(&path).unwrap();
        let (_, _, written) = view(&text, "NodeData", 0);
        assert_eq!(written.len(), back.nodes.len());
        for (tag, v) in &written {
            // Our files number nodes 1..N in mesh order, which the reader keeps.
            let x = back.nodes[tag - 1];
            assert!(
                (v[0] - f(x)).abs() < 1e-12,
                "p={p} node {tag}: {} vs {}",
                v[0],
                f(x)
            );
        }
        let (_, _, written) = view(&text, "ElementData", 0);
        assert_eq!(
            written.iter().map(|(_, v)| v[0]).collect::<Vec<_>>(),
            cell_values
        );
        crate::write_mesh_with(&dir.path().join("fekete.vtu"), &mesh, &point, &cell).unwrap();
    }
}

#[test]
fn unsupported_data_is_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = crate::test_meshes::curved(
        &crate::test_meshes::two_cells(hocurve_nodes::Shape::Quad),
        1,
    );
    let path = dir.path().join("bad.msh");
    let two = vec![0.0; 2 * mesh.nodes.len()];
    let err = write_msh_with(
        &path,
        &mesh,
        &[DataArray {
            name: "uv",
            components: 2,
            values: &two,
        }],
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("scalars (1) or vectors (3)"), "{err}");
    let one = vec![0.0; mesh.nodes.len()];
    let err = write_msh_with(
        &path,
        &mesh,
        &[DataArray {
            name: "a\"b",
            components: 1,
            values: &one,
        }],
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("quote"), "{err}");
    let err = write_msh_with(
        &path,
        &mesh,
        &[],
        &[DataArray {
            name: "c",
            components: 1,
            values: &one,
        }],
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("expected 2"), "{err}");
    assert!(!path.exists());
    let err = crate::write_mesh_with(&dir.path().join("x.txt"), &mesh, &[], &[]).unwrap_err();
    assert!(matches!(err, IoError::UnknownFormat { .. }));
    let err = crate::read_high_order_mesh(&dir.path().join("x.txt")).unwrap_err();
    assert!(matches!(err, IoError::UnknownInputFormat { .. }), "{err}");
}

#[test]
fn lines_formatted_in_parallel_blocks_are_the_bytes_of_a_sequential_loop() {
    // Several blocks and several batches of blocks, the last block partial.
    let n = 64 * 8192 + 3 * 8192 + 17;
    let value = |i: usize| (i as f64).sqrt() * 1e-3 - 0.5;
    let mut parallel = Vec::new();
    write_records(&mut parallel, 5..n, |i, t| {
        writeln!(t, "{} {:?}", i + 1, value(i))
    })
    .unwrap();
    let mut sequential = Vec::new();
    for i in 5..n {
        writeln!(sequential, "{} {:?}", i + 1, value(i)).unwrap();
    }
    assert_eq!(parallel, sequential);
    let mut empty = Vec::new();
    write_records(&mut empty, 3..3, |_, t| writeln!(t, "x")).unwrap();
    assert!(empty.is_empty());
}

#[test]
fn msh_2_2_is_written_as_gmsh_writes_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.msh");
    let mut linear = square();
    // An entity in two physical groups: its element is written once per group.
    linear.entity_physicals.insert((1, 5), vec![10, 11]);
    let ho = HighOrderMesh::from_linear(&linear, 1, NodeFamily::Equispaced).unwrap();
    let format = MshFormat {
        version: MshVersion::V2_2,
        binary: false,
    };
    let values = [0.5, 1.5, 2.5];
    let cell_data = [DataArray {
        name: "q",
        components: 1,
        values: &values,
    }];
    write_msh_as(&path, &ho, &[], &cell_data, format).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let expected = "$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
1 10 \"bottom\"
2 1 \"domain\"
$EndPhysicalNames
$Nodes
5
1 0.0 0.0 0.0
2 1.0 0.0 0.0
3 1.0 1.0 0.0
4 0.0 1.0 0.0
5 0.7 0.1 0.0
$EndNodes
$Elements
6
1 1 2 10 5 1 2
2 1 2 11 5 1 2
3 1 2 0 6 3 4
4 2 2 1 1 1 2 5
5 2 2 1 1 2 3 5
6 3 2 1 2 1 5 3 4
$EndElements
$ElementData
1
\"q\"
1
0
3
0
1
3
4 0.5
5 1.5
6 2.5
$EndElementData
";
    assert_eq!(text, expected);
}

/// The square at order 3 with one point-data and one cell-data array, written in
/// `format` and read back by our reader.
fn round_trip(format: MshFormat) -> (Vec<u8>, HighOrderMesh, HighOrderMesh) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.msh");
    let mut ho = HighOrderMesh::from_linear(&square(), 3, NodeFamily::Equispaced).unwrap();
    // Coordinates that need all 17 digits.
    for (i, x) in ho.nodes.iter_mut().enumerate() {
        x[0] += (i as f64).sqrt() * 1e-3;
        x[2] = 1.0 / (3.0 + i as f64);
    }
    let u: Vec<f64> = (0..3 * ho.nodes.len()).map(|i| (i as f64).cbrt()).collect();
    let point_data = [DataArray {
        name: "u",
        components: 3,
        values: &u,
    }];
    write_msh_as(&path, &ho, &point_data, &[], format).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let back = crate::read_high_order_msh(&path).unwrap();
    (bytes, ho, back)
}

#[test]
fn every_version_and_encoding_reads_back_bit_for_bit() {
    let mut sizes = Vec::new();
    for version in [MshVersion::V4_1, MshVersion::V2_2] {
        for binary in [false, true] {
            let format = MshFormat { version, binary };
            let (bytes, written, back) = round_trip(format);
            let header = format!("$MeshFormat\n{} {} 8\n", version.number(), u8::from(binary));
            assert!(bytes.starts_with(header.as_bytes()), "{format:?}");
            assert_eq!(back.nodes, written.nodes, "{format:?}");
            assert_eq!(back.cells.len(), written.cells.len(), "{format:?}");
            for (a, b) in back.cells.iter().zip(&written.cells) {
                assert_eq!((a.kind, a.entity), (b.kind, b.entity), "{format:?}");
                let xa: Vec<_> = a.nodes.iter().map(|&n| back.nodes[n as usize]).collect();
                let xb: Vec<_> = b.nodes.iter().map(|&n| written.nodes[n as usize]).collect();
                assert_eq!(xa, xb, "{format:?}");
            }
            assert_eq!(back.facets.len(), written.facets.len(), "{format:?}");
            assert_eq!(back.physical_groups, written.physical_groups, "{format:?}");
            // Same input, same bytes.
            assert_eq!(round_trip(format).0, bytes, "{format:?}");
            sizes.push((format, bytes.len()));
        }
    }
    // Binary records: 4.1 nodes are 8-byte tags + 24 bytes, 2.2 nodes 4 + 24 bytes.
    let (_, written, _) = round_trip(MshFormat::default());
    let binary_41 = round_trip(MshFormat {
        version: MshVersion::V4_1,
        binary: true,
    })
    .0;
    let start = find(&binary_41, b"$Nodes\n") + 7 + 32;
    // First block header: dim, tag, parametric (3 ints), count (size_t); then its tags.
    let count = u64::from_le_bytes(binary_41[start + 12..start + 20].try_into().unwrap());
    assert_eq!(
        u64::from_le_bytes(binary_41[start + 20..start + 28].try_into().unwrap()),
        1
    );
    let x = start + 20 + 8 * count as usize;
    assert_eq!(
        f64::from_le_bytes(binary_41[x..x + 8].try_into().unwrap()),
        written.nodes[0][0]
    );
}

/// The position of `needle` in `haystack`.
fn find(haystack: &[u8], needle: &[u8]) -> usize {
    haystack
        .windows(needle.len())
        .position(|w| w == needle)
        .unwrap()
}
