//! Our writers against our high-order readers on the bundled fixtures: every cell comes back
//! with bitwise the same node coordinates (canonical order), so the quality assessment is
//! identical. Fixtures cover triangles (2D), quadrilaterals (2D), tetrahedra and the 3D
//! hybrid of hexahedra and prisms; the nodes are moved by a smooth map so that every node
//! position matters.

use std::path::Path;

use hocurve::io::{read_high_order_mesh, read_msh, write_msh, write_vtu_with, VtuEncoding};
use hocurve::mesh::HighOrderMesh;
use hocurve::nodes::NodeFamily;
use hocurve::quality::{assess, QualityOptions, Sampling};

fn curved_fixture(name: &str, p: usize) -> HighOrderMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name);
    let linear = read_msh(&path).unwrap();
    let mut mesh = HighOrderMesh::from_linear(&linear, p, NodeFamily::Equispaced).unwrap();
    for x in &mut mesh.nodes {
        let (a, b, c) = (x[0], x[1], x[2]);
        x[0] = a + 0.02 * (3.0 * b).sin();
        x[1] = b + 0.02 * (2.0 * a).cos();
        if linear.dim == 3 {
            x[2] = c + 0.02 * (a * b).sin();
        }
    }
    mesh
}

fn cell_bits(mesh: &HighOrderMesh) -> Vec<Vec<[u64; 3]>> {
    mesh.cells
        .iter()
        .map(|c| {
            c.nodes
                .iter()
                .map(|&n| mesh.nodes[n as usize].map(f64::to_bits))
                .collect()
        })
        .collect()
}

#[test]
fn written_meshes_read_back_with_identical_quality() {
    let dir = tempfile::tempdir().unwrap();
    let options = [
        QualityOptions::default(),
        QualityOptions {
            sampling: Sampling::Both,
            ..Default::default()
        },
    ];
    for (name, orders) in [
        ("formats/square_v41_ascii.msh", 1..=5),
        ("quad/naca0012_quads.msh", 1..=5),
        ("formats/cube_v41_ascii.msh", 1..=5),
        ("hybrid/hybrid.msh", 1..=4),
    ] {
        for p in orders {
            let mesh = curved_fixture(name, p);
            let expected: Vec<_> = options.iter().map(|o| assess(&mesh, o).unwrap()).collect();
            let msh = dir.path().join("m.msh");
            write_msh(&msh, &mesh).unwrap();
            let vtu_ascii = dir.path().join("ascii.vtu");
            write_vtu_with(&vtu_ascii, &mesh, &[], &[], VtuEncoding::Ascii).unwrap();
            let vtu_base64 = dir.path().join("base64.vtu");
            write_vtu_with(&vtu_base64, &mesh, &[], &[], VtuEncoding::Base64).unwrap();
            for path in [&msh, &vtu_ascii, &vtu_base64] {
                let back = read_high_order_mesh(path).unwrap();
                let what = format!("{name} p={p} {}", path.display());
                assert_eq!((back.dim, back.order), (mesh.dim, p), "{what}");
                assert_eq!(cell_bits(&back), cell_bits(&mesh), "{what}");
                for (o, want) in options.iter().zip(&expected) {
                    assert_eq!(&assess(&back, o).unwrap(), want, "{what}");
                }
            }
        }
    }
}
