use super::*;
use hocurve_mesh::{Element, LinearMesh, Shape};
use hocurve_nodes::NodeFamily;

fn base64(bytes: &[u8]) -> String {
    let mut out = Vec::new();
    let mut b = Base64::new();
    b.push(&mut out, bytes).unwrap();
    b.finish(&mut out).unwrap();
    String::from_utf8(out).unwrap()
}

#[test]
fn base64_matches_rfc_4648_vectors() {
    for (input, expected) in [
        ("", ""),
        ("f", "Zg=="),
        ("fo", "Zm8="),
        ("foo", "Zm9v"),
        ("foob", "Zm9vYg=="),
        ("fooba", "Zm9vYmE="),
        ("foobar", "Zm9vYmFy"),
    ] {
        assert_eq!(base64(input.as_bytes()), expected);
    }
    assert_eq!(base64(&[0xff, 0xfe, 0xfd]), "//79");
}

fn two_triangles(order: usize) -> HighOrderMesh {
    let mesh = LinearMesh {
        dim: 2,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        cells: vec![
            Element {
                kind: Shape::Tri,
                vertices: vec![0, 1, 2],
                entity: 1,
            },
            Element {
                kind: Shape::Tri,
                vertices: vec![0, 2, 3],
                entity: 1,
            },
        ],
        ..Default::default()
    };
    HighOrderMesh::from_linear(&mesh, order, NodeFamily::Equispaced).unwrap()
}

#[test]
fn ascii_file_is_exact_and_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = two_triangles(1);
    let path = dir.path().join("m.vtu");
    let quality = [0.5, 1.0 / 3.0];
    let cd = [DataArray {
        name: "q<1>",
        components: 1,
        values: &quality,
    }];
    write_vtu_with(&path, &mesh, &[], &cd, VtuEncoding::Ascii).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let expected = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="2.2" byte_order="LittleEndian" header_type="UInt64">
  <UnstructuredGrid>
    <Piece NumberOfPoints="4" NumberOfCells="2">
      <CellData>
        <DataArray type="Float64" Name="q&lt;1&gt;" format="ascii">
          0.5
          0.3333333333333333
        </DataArray>
      </CellData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">
          0.0 0.0 0.0
          1.0 0.0 0.0
          1.0 1.0 0.0
          0.0 1.0 0.0
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">
          0 1 2
          0 2 3
        </DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">
          3
          6
        </DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">
          5
          5
        </DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#;
    assert_eq!(text, expected);
    let path2 = dir.path().join("m2.vtu");
    write_vtu_with(&path2, &mesh, &[], &cd, VtuEncoding::Ascii).unwrap();
    assert_eq!(std::fs::read(&path2).unwrap(), text.as_bytes());
}

#[test]
fn base64_file_holds_the_same_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = two_triangles(3);
    let path = dir.path().join("m.vtu");
    write_vtu(&path, &mesh, &[], &[]).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("format=\"binary\""));
    assert!(text.contains(">\n          "));
    // The types array: header (1 byte per cell × 2) + [69, 69].
    let mut bytes = 2u64.to_le_bytes().to_vec();
    bytes.extend([69u8, 69]);
    assert!(text.contains(&base64(&bytes)), "{text}");
    // Same input, same bytes.
    let path2 = dir.path().join("m2.vtu");
    write_vtu(&path2, &mesh, &[], &[]).unwrap();
    assert_eq!(std::fs::read(&path2).unwrap(), text.as_bytes());
}

#[test]
fn bad_arrays_are_rejected_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = two_triangles(2);
    let path = dir.path().join("m.vtu");
    let short = [1.0; 5];
    let err = write_vtu(
        &path,
        &mesh,
        &[DataArray {
            name: "u",
            components: 1,
            values: &short,
        }],
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("point data 'u' has 5 values, expected 9"),
        "{err}"
    );
    let two = [1.0, f64::NAN];
    let err = write_vtu(
        &path,
        &mesh,
        &[],
        &[DataArray {
            name: "q",
            components: 1,
            values: &two,
        }],
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("not finite"), "{err}");
    let ok = [1.0, 2.0];
    let dup = [
        DataArray {
            name: "q",
            components: 1,
            values: &ok,
        },
        DataArray {
            name: "q",
            components: 1,
            values: &ok,
        },
    ];
    let err = write_vtu(&path, &mesh, &[], &dup).unwrap_err().to_string();
    assert!(err.contains("two cell data arrays are named 'q'"), "{err}");
    assert!(!path.exists());
}

#[test]
fn zlib_file_reads_back_as_the_same_numbers() {
    let dir = tempfile::tempdir().unwrap();
    // Enough nodes for several 32 KiB blocks of coordinates.
    let n = 40;
    let mut grid = hocurve_mesh::LinearMesh {
        dim: 2,
        ..Default::default()
    };
    for j in 0..=n {
        for i in 0..=n {
            grid.vertices
                .push([i as f64 / n as f64, (j as f64 / n as f64).sqrt(), 0.0]);
        }
    }
    let v = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            for vertices in [
                vec![v(i, j), v(i + 1, j), v(i + 1, j + 1)],
                vec![v(i, j), v(i + 1, j + 1), v(i, j + 1)],
            ] {
                grid.cells.push(hocurve_mesh::Element {
                    kind: Shape::Tri,
                    vertices,
                    entity: 1,
                });
            }
        }
    }
    let big = HighOrderMesh::from_linear(&grid, 3, hocurve_nodes::NodeFamily::Equispaced).unwrap();
    assert!(24 * big.nodes.len() > 3 * ZLIB_BLOCK);
    for m in [&two_triangles(3), &big] {
        let path = dir.path().join("z.vtu");
        write_vtu_with(&path, m, &[], &[], VtuEncoding::Zlib).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("compressor=\"vtkZLibDataCompressor\""));
        let back = crate::read_vtu(&path).unwrap();
        assert_eq!(back.nodes, m.nodes);
        assert_eq!(back.cells.len(), m.cells.len());
        for (a, b) in back.cells.iter().zip(&m.cells) {
            let xa: Vec<_> = a.nodes.iter().map(|&k| back.nodes[k as usize]).collect();
            let xb: Vec<_> = b.nodes.iter().map(|&k| m.nodes[k as usize]).collect();
            assert_eq!(xa, xb);
        }
        // Same input, same bytes.
        let again = dir.path().join("z2.vtu");
        write_vtu_with(&again, m, &[], &[], VtuEncoding::Zlib).unwrap();
        assert_eq!(std::fs::read(&again).unwrap(), text.as_bytes());
    }
}
