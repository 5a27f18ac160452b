use super::cell_types::vtk_order;
use super::*;
use crate::ordering::vtk_permutation;
use crate::test_meshes::{all_meshes, cell_bits, curved, two_cells};
use crate::{write_vtu_with, VtuEncoding};
use hocurve_nodes::Shape;
use std::io::Write as _;

fn encode_base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let mut b = [0u8; 3];
        b[..chunk.len()].copy_from_slice(chunk);
        let v = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(A[((v >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[test]
fn our_vtu_files_read_back_bitwise_for_every_shape_and_order() {
    let dir = tempfile::tempdir().unwrap();
    for (name, linear) in all_meshes() {
        for p in 1..=5 {
            let mesh = curved(&linear, p);
            for encoding in [VtuEncoding::Ascii, VtuEncoding::Base64] {
                let path = dir.path().join("m.vtu");
                write_vtu_with(&path, &mesh, &[], &[], encoding).unwrap();
                let back = read_vtu(&path).unwrap();
                assert_eq!((back.dim, back.order), (mesh.dim, p), "{name} p={p}");
                assert_eq!(
                    cell_bits(&back),
                    cell_bits(&mesh),
                    "{name} p={p} {encoding:?}"
                );
                let nodes = |m: &HighOrderMesh| -> Vec<Vec<u32>> {
                    m.cells.iter().map(|c| c.nodes.clone()).collect()
                };
                assert_eq!(nodes(&back), nodes(&mesh), "{name} p={p}");
                assert!(back.facets.is_empty());
            }
        }
    }
}

/// How the test writer stores arrays, like vtkXMLUnstructuredGridWriter's settings.
#[derive(Debug, Clone, Copy)]
struct Style {
    appended: Option<bool>, // None: inline base64; Some(raw?)
    zlib: bool,
    header64: bool,
    big_endian: bool,
}

fn vtk_like(mesh: &HighOrderMesh, style: Style) -> Vec<u8> {
    let word = |v: usize| -> Vec<u8> {
        match (style.header64, style.big_endian) {
            (true, false) => (v as u64).to_le_bytes().to_vec(),
            (true, true) => (v as u64).to_be_bytes().to_vec(),
            (false, false) => (v as u32).to_le_bytes().to_vec(),
            (false, true) => (v as u32).to_be_bytes().to_vec(),
        }
    };
    // (header, data) of an array.
    let block = |data: Vec<u8>| -> (Vec<u8>, Vec<u8>) {
        if !style.zlib {
            return (word(data.len()), data);
        }
        let size = 40;
        let chunks: Vec<&[u8]> = data.chunks(size).collect();
        let mut header = word(chunks.len());
        header.extend(word(size));
        header.extend(word(chunks.last().map_or(size, |c| c.len())));
        let mut body = Vec::new();
        for c in &chunks {
            let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
            e.write_all(c).unwrap();
            let z = e.finish().unwrap();
            header.extend(word(z.len()));
            body.extend(z);
        }
        (header, body)
    };
    let be = style.big_endian;
    let f64s = |v: &[f64]| -> Vec<u8> {
        v.iter()
            .flat_map(|x| if be { x.to_be_bytes() } else { x.to_le_bytes() })
            .collect()
    };
    let i32s = |v: &[i64]| -> Vec<u8> {
        v.iter()
            .flat_map(|&x| {
                if be {
                    (x as i32).to_be_bytes()
                } else {
                    (x as i32).to_le_bytes()
                }
            })
            .collect()
    };
    let points: Vec<f64> = mesh.nodes.iter().flatten().copied().collect();
    let mut connectivity = Vec::new();
    let mut offsets = Vec::new();
    let mut types = Vec::new();
    for cell in &mesh.cells {
        let shape = cell.kind;
        for &k in &vtk_permutation(shape, mesh.order) {
            connectivity.push(i64::from(cell.nodes[k]));
        }
        offsets.push(connectivity.len() as i64);
        types.push(crate::ordering::vtk_cell_type(shape, mesh.order));
    }
    let arrays = [
        ("Points", "Float64", "", 3, f64s(&points)),
        ("Cells", "Int32", "connectivity", 1, i32s(&connectivity)),
        ("Cells", "Int32", "offsets", 1, i32s(&offsets)),
        ("Cells", "UInt8", "types", 1, types.clone()),
    ];
    let mut xml = String::new();
    xml.push_str("<?xml version=\"1.0\"?>\n<!-- written by the test -->\n");
    xml.push_str(&format!(
        "<VTKFile header_type='{}' byte_order=\"{}\" version=\"2.2\" {} type=\"UnstructuredGrid\">\n<UnstructuredGrid>\n",
        if style.header64 { "UInt64" } else { "UInt32" },
        if be { "BigEndian" } else { "LittleEndian" },
        if style.zlib { "compressor=\"vtkZLibDataCompressor\"" } else { "" }
    ));
    xml.push_str(&format!(
        "<Piece NumberOfCells=\"{}\"   NumberOfPoints = \"{}\" >\n",
        mesh.cells.len(),
        mesh.nodes.len()
    ));
    let mut appended: Vec<u8> = Vec::new();
    let mut section = "";
    for (parent, ty, name, components, data) in arrays {
        if parent != section {
            if !section.is_empty() {
                xml.push_str(&format!("</{section}>\n"));
            }
            xml.push_str(&format!("<{parent}>\n"));
            section = parent;
        }
        let (header, body) = block(data);
        let attrs = format!("type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{components}\"");
        match style.appended {
            None => xml.push_str(&format!(
                "<DataArray {attrs} format=\"binary\">\n {}{}\n</DataArray>\n",
                encode_base64(&header),
                encode_base64(&body)
            )),
            Some(raw) => {
                xml.push_str(&format!(
                    "<DataArray {attrs} format=\"appended\" RangeMin=\"0\" offset=\"{}\"/>\n",
                    appended.len()
                ));
                if raw {
                    appended.extend(header);
                    appended.extend(body);
                } else {
                    appended.extend(encode_base64(&header).bytes());
                    appended.extend(encode_base64(&body).bytes());
                }
            }
        }
    }
    xml.push_str(&format!("</{section}>\n</Piece>\n</UnstructuredGrid>\n"));
    let mut out = xml.into_bytes();
    if let Some(raw) = style.appended {
        out.extend_from_slice(
            format!(
                "<AppendedData encoding=\"{}\">\n   _",
                if raw { "raw" } else { "base64" }
            )
            .as_bytes(),
        );
        out.extend(appended);
        out.extend_from_slice(b"\n</AppendedData>\n");
    }
    out.extend_from_slice(b"</VTKFile>\n");
    out
}

fn every_style() -> Vec<Style> {
    let mut out = Vec::new();
    for appended in [None, Some(true), Some(false)] {
        for zlib in [false, true] {
            for header64 in [false, true] {
                for big_endian in [false, true] {
                    out.push(Style {
                        appended,
                        zlib,
                        header64,
                        big_endian,
                    });
                }
            }
        }
    }
    out
}

#[test]
fn vtk_writer_layouts_read_back_bitwise() {
    for (name, linear) in all_meshes() {
        for p in [1, 2, 4] {
            let mesh = curved(&linear, p);
            for style in every_style() {
                let bytes = vtk_like(&mesh, style);
                let back = parse_vtu(&bytes, Path::new("t.vtu"))
                    .unwrap_or_else(|e| panic!("{name} p={p} {style:?}: {e}"));
                assert_eq!(cell_bits(&back), cell_bits(&mesh), "{name} p={p} {style:?}");
            }
        }
    }
}

#[test]
fn fixed_quadratic_cells_read_like_order_two_lagrange_cells() {
    for (shape, lagrange, quadratic) in [
        (Shape::Tri, 69, 22),
        (Shape::Quad, 70, 28),
        (Shape::Tet, 71, 24),
        (Shape::Hex, 72, 29),
        (Shape::Prism, 73, 32),
    ] {
        let mesh = curved(&two_cells(shape), 2);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.vtu");
        write_vtu_with(&path, &mesh, &[], &[], VtuEncoding::Ascii).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let types = format!("          {lagrange}\n          {lagrange}\n");
        assert!(text.contains(&types), "{shape:?}");
        let text = text.replace(
            &types,
            &format!("          {quadratic}\n          {quadratic}\n"),
        );
        let back = parse_vtu(text.as_bytes(), &path).unwrap();
        assert_eq!(cell_bits(&back), cell_bits(&mesh), "{shape:?}");
    }
}

#[test]
fn old_files_get_the_old_lagrange_hexahedron_edge_order() {
    // A version-1.0 file lists the vertical edges (3, 7) before (2, 6).
    let mut one = two_cells(Shape::Hex);
    one.cells.truncate(1);
    one.facets.clear();
    let mesh = curved(&one, 3);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.vtu");
    write_vtu_with(&path, &mesh, &[], &[], VtuEncoding::Ascii).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let old = text.replace("version=\"2.2\"", "version=\"1.0\"");
    let back = parse_vtu(old.as_bytes(), &path).unwrap();
    assert_ne!(cell_bits(&back), cell_bits(&mesh));
    let perm_new = vtk_permutation(Shape::Hex, 3);
    let perm_old = vtk_order(Shape::Hex, 3, true);
    assert_eq!(
        perm_new[8 + 2 * 10..8 + 2 * 11],
        perm_old[8 + 2 * 11..8 + 2 * 12]
    );
    assert_eq!(
        perm_new[8 + 2 * 11..8 + 2 * 12],
        perm_old[8 + 2 * 10..8 + 2 * 11]
    );
}

fn ascii_two_triangles(types: &str, connectivity: &str, offsets: &str) -> String {
    format!(
        "<?xml version=\"1.0\"?>
<VTKFile type=\"UnstructuredGrid\" version=\"2.2\">
<UnstructuredGrid><Piece NumberOfPoints=\"6\" NumberOfCells=\"2\">
<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">
0 0 0  1 0 0  0 1 0  1 1 0  0.5 0 0  0.5 0.5 0
</DataArray></Points>
<Cells>
<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">{connectivity}</DataArray>
<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">{offsets}</DataArray>
<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">{types}</DataArray>
</Cells></Piece></UnstructuredGrid></VTKFile>
"
    )
}

fn vtu_error(text: &str) -> String {
    match parse_vtu(text.as_bytes(), Path::new("t.vtu")) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn malformed_vtu_files_are_clear_errors() {
    let ok = ascii_two_triangles("5 5", "0 1 2 1 3 2", "3 6");
    parse_vtu(ok.as_bytes(), Path::new("t.vtu")).unwrap();
    let e = vtu_error(&ascii_two_triangles("5 23", "0 1 2 1 3 2", "3 6"));
    assert!(
        e.contains("incomplete (serendipity) elements are not supported"),
        "{e}"
    );
    let e = vtu_error(&ascii_two_triangles("5 200", "0 1 2 1 3 2", "3 6"));
    assert!(
        e.contains("unknown or unsupported VTK cell type 200"),
        "{e}"
    );
    let e = vtu_error(&ascii_two_triangles("5 22", "0 1 2 0 1 2 4 5 3", "3 9"));
    assert!(e.contains("mixed element orders"), "{e}");
    let e = vtu_error(&ascii_two_triangles("5 5", "0 1 2 1 3 9", "3 6"));
    assert!(e.contains("references point 9"), "{e}");
    let e = vtu_error(&ascii_two_triangles("5 5", "0 1 2 1 3 2", "3 7"));
    assert!(e.contains("has 6 values, expected 7"), "{e}");
    let e = vtu_error(&ascii_two_triangles("5 69", "0 1 2 1 3 2 4 5", "3 8"));
    assert!(e.contains("no complete order"), "{e}");
    let e = vtu_error(&ok.replace("UnstructuredGrid\"", "PolyData\""));
    assert!(e.contains("PolyData is not supported"), "{e}");
    let e = vtu_error(&ok.replace("</Points>", "</Pointz>"));
    assert!(
        e.contains("</Pointz> closes <Points>") && e.contains("line 6"),
        "{e}"
    );
    let e = vtu_error(&ok.replace("0.5 0.5 0", "0.5 x 0"));
    assert!(e.contains("'x' is not a number"), "{e}");
    let e = vtu_error(&ok.replace("<VTKFile", "<VTKFile compressor=\"vtkLZ4DataCompressor\""));
    assert!(e.contains("vtkLZ4DataCompressor is not supported"), "{e}");
}

#[test]
fn truncated_and_garbled_binary_files_are_errors_not_panics() {
    let mesh = curved(&two_cells(Shape::Prism), 2);
    for style in [
        Style {
            appended: Some(true),
            zlib: true,
            header64: false,
            big_endian: false,
        },
        Style {
            appended: Some(false),
            zlib: true,
            header64: true,
            big_endian: false,
        },
        Style {
            appended: None,
            zlib: false,
            header64: true,
            big_endian: false,
        },
    ] {
        let bytes = vtk_like(&mesh, style);
        for cut in (0..bytes.len() - 12).step_by(5) {
            assert!(
                parse_vtu(&bytes[..cut], Path::new("t.vtu")).is_err(),
                "{style:?} cut {cut}"
            );
        }
        for (i, garbage) in [0u8, 0xff, b'<', b'=', b'A'].iter().enumerate() {
            for at in (0..bytes.len()).step_by(7 + i) {
                let mut b = bytes.clone();
                b[at] = *garbage;
                let _ = parse_vtu(&b, Path::new("t.vtu")); // any result, no panic
            }
        }
    }
}
