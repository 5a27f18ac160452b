//! Cross-crate tests on the bundled fixtures: read with `hocurve-io`, lay out order-p nodes
//! with `hocurve-mesh`, write and read back.

use std::path::{Path, PathBuf};

use hocurve::io::{read_msh, write_msh};
use hocurve::mesh::{HighOrderMesh, LinearMesh};
use hocurve::nodes::{NodeFamily, Shape};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

const FIXTURES: [&str; 6] = [
    "naca0012/naca0012.msh",
    "quad/naca0012_quads.msh",
    "sphere/sphere.msh",
    "sphere/sphere_small.msh",
    "hybrid/hybrid.msh",
    "formats/cube_v41_ascii.msh",
];

/// V + E(p−1) + F_tri·(p−1)(p−2)/2 + F_quad·(p−1)² + Σ cells' interior counts, with the
/// counts of V, E, F taken independently of the layout: E and F by Euler-type counting of
/// distinct sorted vertex sets.
#[test]
fn node_count_formula_holds_on_every_fixture_for_p_1_to_6() {
    for name in FIXTURES {
        let mesh = read_msh(&fixture(name)).unwrap();
        let mut edges = std::collections::HashSet::new();
        let mut tri_faces = std::collections::HashSet::new();
        let mut quad_faces = std::collections::HashSet::new();
        for cell in &mesh.cells {
            let shape = cell.kind;
            for &[a, b] in shape.edges() {
                let (x, y) = (cell.vertices[a], cell.vertices[b]);
                edges.insert((x.min(y), x.max(y)));
            }
            for face in shape.faces() {
                let mut key: Vec<u32> = face.iter().map(|&i| cell.vertices[i]).collect();
                key.sort_unstable();
                if key.len() == 3 {
                    tri_faces.insert(key);
                } else {
                    quad_faces.insert(key);
                }
            }
        }
        for p in 1..=6usize {
            let ho = HighOrderMesh::from_linear(&mesh, p, NodeFamily::Equispaced).unwrap();
            let q = p - 1;
            let tri_interior = q * q.saturating_sub(1) / 2;
            let cells: usize = mesh
                .cells
                .iter()
                .map(|c| match c.kind {
                    Shape::Tri => tri_interior,
                    Shape::Quad => q * q,
                    Shape::Tet => q * q.saturating_sub(1) * q.saturating_sub(2) / 6,
                    Shape::Hex => q * q * q,
                    Shape::Prism => tri_interior * q,
                    Shape::Line => unreachable!(),
                })
                .sum();
            let expected = mesh.vertices.len()
                + edges.len() * q
                + tri_faces.len() * tri_interior
                + quad_faces.len() * q * q
                + cells;
            assert_eq!(ho.nodes.len(), expected, "{name} p={p}");
            // Every cell and facet references existing nodes; every node is used.
            let mut used = vec![false; ho.nodes.len()];
            for e in ho.cells.iter().chain(&ho.facets) {
                assert_eq!(e.nodes.len(), e.kind.num_nodes(p));
                for &n in &e.nodes {
                    used[n as usize] = true;
                }
            }
            assert!(used.iter().all(|&u| u), "{name} p={p}: unused nodes");
        }
    }
}

/// The paper's NACA0012 count in 2D: nodes = V + E(p−1) + F(p−1)(p−2)/2 (DESIGN.md §2).
#[test]
fn naca_node_count_matches_the_2d_formula_at_p5() {
    let mesh = read_msh(&fixture("naca0012/naca0012.msh")).unwrap();
    let (v, f) = (mesh.vertices.len(), mesh.cells.len());
    // Euler for a disc with one hole: V − E + F = 0.
    let e = v + f;
    let ho = HighOrderMesh::from_linear(&mesh, 5, NodeFamily::Equispaced).unwrap();
    assert_eq!(ho.nodes.len(), v + e * 4 + f * 6);
}

fn same_mesh(a: &LinearMesh, b: &LinearMesh, name: &str) {
    assert_eq!(a.dim, b.dim, "{name}");
    assert_eq!(a.vertices, b.vertices, "{name}: vertices");
    assert_eq!(a.cells, b.cells, "{name}: cells");
    assert_eq!(a.facets, b.facets, "{name}: facets");
    assert_eq!(a.physical_groups, b.physical_groups, "{name}: groups");
    for e in a.cells.iter().chain(&a.facets) {
        assert_eq!(
            a.physical_tags(e.kind.dim(), e.entity),
            b.physical_tags(e.kind.dim(), e.entity),
            "{name}: physical tags of entity {}",
            e.entity
        );
    }
}

#[test]
fn round_trip_through_msh_at_p1_gives_the_same_mesh() {
    let dir = tempfile::tempdir().unwrap();
    for name in FIXTURES {
        let mesh = read_msh(&fixture(name)).unwrap();
        let ho = HighOrderMesh::from_linear(&mesh, 1, NodeFamily::Equispaced).unwrap();
        let out = dir.path().join("round_trip.msh");
        write_msh(&out, &ho).unwrap();
        let back = read_msh(&out).unwrap();
        same_mesh(&mesh, &back, name);
    }
}

/// VTK and Gmsh assume equispaced nodes: `write_mesh` resamples a Fekete mesh (same
/// geometry), while the format writers refuse it rather than write a wrong geometry.
#[test]
fn fekete_meshes_are_resampled_on_output_and_refused_by_the_raw_writers() {
    use hocurve::io::{write_mesh, write_vtu};
    let dir = tempfile::tempdir().unwrap();
    let mesh = read_msh(&fixture("hybrid/hybrid.msh")).unwrap();
    let fekete = HighOrderMesh::from_linear(&mesh, 4, NodeFamily::Fekete).unwrap();
    let err = write_vtu(&dir.path().join("raw.vtu"), &fekete, &[], &[]).unwrap_err();
    assert!(err.to_string().contains("equispaced"), "{err}");
    assert!(!dir.path().join("raw.vtu").exists());
    let err = write_msh(&dir.path().join("raw.msh"), &fekete).unwrap_err();
    assert!(err.to_string().contains("equispaced"), "{err}");
    // Through write_mesh the written nodes are the equispaced straight nodes.
    let out = dir.path().join("resampled.msh");
    write_mesh(&out, &fekete).unwrap();
    let equispaced = HighOrderMesh::from_linear(&mesh, 4, NodeFamily::Equispaced).unwrap();
    let text = std::fs::read_to_string(&out).unwrap();
    let resampled = fekete.resampled(NodeFamily::Equispaced).unwrap();
    for (a, b) in resampled.nodes.iter().zip(&equispaced.nodes) {
        assert!((0..3).all(|d| (a[d] - b[d]).abs() < 1e-12));
    }
    assert!(text.contains("$Nodes"));
    let err = write_mesh(&dir.path().join("mesh.obj"), &fekete).unwrap_err();
    assert!(err.to_string().contains("unknown output format"), "{err}");
}
