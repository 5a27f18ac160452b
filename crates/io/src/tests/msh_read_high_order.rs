use super::*;
use crate::test_meshes::{all_meshes, cell_bits, curved, facet_bits};
use crate::write_msh;
use crate::IoError;
use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::NodeFamily;
use std::path::Path;

fn parse(s: &str) -> Result<HighOrderMesh, IoError> {
    parse_high_order_msh(s.as_bytes(), Path::new("test.msh"))
}

fn error_text(r: Result<HighOrderMesh, IoError>) -> String {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn our_msh_files_read_back_bitwise_for_every_shape_and_order() {
    let dir = tempfile::tempdir().unwrap();
    for (name, linear) in all_meshes() {
        for p in 1..=5 {
            let mesh = curved(&linear, p);
            let path = dir.path().join("m.msh");
            write_msh(&path, &mesh).unwrap();
            let back = read_high_order_msh(&path).unwrap();
            assert_eq!(back.dim, mesh.dim, "{name} p={p}");
            assert_eq!(back.order, p);
            assert_eq!(back.family, NodeFamily::Equispaced);
            assert_eq!(cell_bits(&back), cell_bits(&mesh), "{name} p={p}");
            assert_eq!(facet_bits(&back), facet_bits(&mesh), "{name} p={p}");
            // Our files number nodes like from_linear: the mesh comes back as it was.
            assert_eq!(back.cells, mesh.cells, "{name} p={p}");
            assert_eq!(back.layout(), mesh.layout());
        }
    }
}

#[test]
fn gmsh_second_order_fixture_reads_with_its_facets_and_groups() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/formats/cube_p2_v41.msh");
    let mesh = read_high_order_msh(&path).unwrap();
    assert_eq!(
        (mesh.dim, mesh.order, mesh.cells.len(), mesh.facets.len()),
        (3, 2, 48, 48)
    );
    assert_eq!(mesh.nodes.len(), 125);
    assert!(mesh.physical_groups.iter().any(|g| g.name == "left"));
    // Straight P2 tets of the unit cube: the edge midpoints are the vertices' midpoints.
    let reference =
        hocurve_nodes::ReferenceNodes::new(hocurve_nodes::Shape::Tet, 2, NodeFamily::Equispaced);
    for cell in &mesh.cells {
        for (k, entity) in reference.entities().iter().enumerate() {
            if let hocurve_nodes::NodeEntity::Edge { edge, .. } = entity {
                let [a, b] = hocurve_nodes::Shape::Tet.edges()[*edge];
                let (xa, xb) = (
                    mesh.nodes[cell.nodes[a] as usize],
                    mesh.nodes[cell.nodes[b] as usize],
                );
                let x = mesh.nodes[cell.nodes[k] as usize];
                for d in 0..3 {
                    assert!((x[d] - 0.5 * (xa[d] + xb[d])).abs() < 1e-12);
                }
            }
        }
    }
    // The linear reader still refuses it.
    assert!(read_msh(&path)
        .unwrap_err()
        .to_string()
        .contains("high-order element"));
}

/// A two-triangle P2 mesh in MSH 2.2 with the given element lines.
fn msh22(elements: &[&str]) -> String {
    let mut s = String::from(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n9\n\
         1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 0.5 0 0\n6 1 0.5 0\n7 0.5 0.5 0\n8 0.5 1 0\n9 0 0.5 0\n\
         $EndNodes\n$Elements\n",
    );
    s.push_str(&format!("{}\n", elements.len()));
    for e in elements {
        s.push_str(e);
        s.push('\n');
    }
    s.push_str("$EndElements\n");
    s
}

const TRI_A: &str = "1 9 2 1 1 1 2 3 5 6 7";
const TRI_B: &str = "2 9 2 1 1 1 3 4 7 8 9";

#[test]
fn msh22_second_order_triangles_with_a_boundary_line() {
    let mesh = parse(&msh22(&[TRI_A, TRI_B, "3 8 2 2 2 1 2 5", "4 15 2 3 3 1"])).unwrap();
    assert_eq!(
        (mesh.dim, mesh.order, mesh.cells.len(), mesh.facets.len()),
        (2, 2, 2, 1)
    );
    assert_eq!(mesh.nodes.len(), 9);
    assert_eq!(mesh.facets[0].entity, 2);
}

#[test]
fn mixed_orders_serendipity_unknown_types_and_missing_nodes_are_errors() {
    let e = error_text(parse(&msh22(&[TRI_A, "2 2 2 1 1 1 3 4"])));
    assert!(
        e.contains("mixed element orders") && e.contains("element 2") && e.contains("line"),
        "{e}"
    );
    let e = error_text(parse(&msh22(&["1 16 2 1 1 1 2 3 4 5 6 8 9"])));
    assert!(
        e.contains("incomplete (serendipity) elements are not supported"),
        "{e}"
    );
    assert!(e.contains("8-node second order quadrilateral"), "{e}");
    for t in [17, 18, 20, 39, 99, 137] {
        let e = error_text(parse(&msh22(&[&format!("1 {t} 2 1 1 1 2 3")])));
        assert!(e.contains("incomplete (serendipity)"), "type {t}: {e}");
    }
    let e = error_text(parse(&msh22(&["1 999 2 1 1 1 2 3"])));
    assert!(e.contains("unknown element type 999"), "{e}");
    let e = error_text(parse(&msh22(&["1 14 2 1 1 1 2 3"])));
    assert!(e.contains("pyramid"), "{e}");
    let e = error_text(parse(&msh22(&["1 9 2 1 1 1 2 3 5 6 77"])));
    assert!(e.contains("node 77 which is not in $Nodes"), "{e}");
    let e = error_text(parse(&msh22(&["1 9 2 1 1 1 2 3 5 6"])));
    assert!(e.contains("expected 6 node tags"), "{e}");
    let e = error_text(parse(&msh22(&["1 8 2 1 1 1 2 5"])));
    assert!(e.contains("no surface or volume elements"), "{e}");
    // Non-conforming: the second triangle has its own node 10 on the shared diagonal.
    let mut s = msh22(&[TRI_A, "2 9 2 1 1 1 3 4 10 8 9"]);
    s = s
        .replace("9\n1 0 0 0", "10\n1 0 0 0")
        .replace("9 0 0.5 0\n", "9 0 0.5 0\n10 0.4 0.5 0\n");
    let e = error_text(parse(&s));
    assert!(
        e.contains("element 2 has node 10") && e.contains("node 7"),
        "{e}"
    );
}

#[test]
fn truncated_and_garbled_files_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = curved(&crate::test_meshes::two_cells(hocurve_nodes::Shape::Tet), 3);
    let path = dir.path().join("m.msh");
    write_msh(&path, &mesh).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let last_line = bytes[..bytes.len() - 1]
        .iter()
        .rposition(|&c| c == b'\n')
        .unwrap();
    for cut in (0..last_line).step_by(7) {
        assert!(
            parse_high_order_msh(&bytes[..cut], &path).is_err(),
            "cut at {cut}"
        );
    }
    for (i, garbage) in [b'x', b'-', b'9', b'\n', b'$'].iter().enumerate() {
        for at in (0..bytes.len()).step_by(13 + i) {
            let mut b = bytes.clone();
            b[at] = *garbage;
            let _ = parse_high_order_msh(&b, &path); // any result, no panic
        }
    }
    let e = error_text(parse_high_order_msh(&bytes[..bytes.len() / 2], &path));
    assert!(e.contains("end of file"), "{e}");
}
