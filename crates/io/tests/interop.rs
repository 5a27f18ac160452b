//! Writers against readers: small straight-sided meshes of every element type at orders
//! 1..=6 written as `.msh` and `.vtu`, the order-1 `.msh` files read back.
//!
//! With `HOCURVE_INTEROP_DIR=<dir>` the files are kept in `<dir>` together with
//! `expected.tsv` (file name, total volume or area), for the checks with the real libraries:
//!
//! ```text
//! HOCURVE_INTEROP_DIR=target/interop cargo test -p hocurve-io --test interop
//! target/pyenv/bin/python xtask/scripts/check_vtu.py --manifest target/interop/expected.tsv target/interop/*.vtu
//! target/pyenv/bin/python xtask/scripts/check_msh.py --manifest target/interop/expected.tsv target/interop/*.msh
//! ```
//!
//! Every cell is an affine image of its reference element (parallelepipeds, right prisms
//! with parallel equal triangles), so its Jacobian determinant is constant: any node put in
//! the wrong place by an ordering bug shows up as a non-constant or negative Jacobian.

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hocurve_io::{read_msh, write_msh, write_vtu, write_vtu_with, DataArray, VtuEncoding};
use hocurve_mesh::{Element, HighOrderMesh, LinearMesh, PhysicalGroup, Shape};
use hocurve_nodes::NodeFamily;

/// A general affine map x ↦ A x + b with det A > 0 (3D) or a 2D one (z kept 0).
fn affine(dim: usize, x: [f64; 3]) -> [f64; 3] {
    if dim == 2 {
        [
            1.0 + 1.1 * x[0] + 0.3 * x[1],
            -0.5 + 0.2 * x[0] + 0.9 * x[1],
            0.0,
        ]
    } else {
        [
            1.0 + 1.0 * x[0] + 0.2 * x[1] + 0.1 * x[2],
            -0.5 + 0.1 * x[0] + 1.1 * x[1],
            0.25 + 0.3 * x[1] + 0.9 * x[2],
        ]
    }
}

fn det_affine(dim: usize) -> f64 {
    if dim == 2 {
        1.1 * 0.9 - 0.3 * 0.2
    } else {
        // det [[1, .2, .1], [.1, 1.1, 0], [0, .3, .9]]
        1.0 * (1.1 * 0.9 - 0.0 * 0.3) - 0.2 * (0.1 * 0.9 - 0.0) + 0.1 * (0.1 * 0.3 - 0.0)
    }
}

fn element(kind: Shape, vertices: &[u32], entity: i32) -> Element {
    Element {
        kind,
        vertices: vertices.to_vec(),
        entity,
    }
}

/// Adds the boundary facets (outward, from the cells' local faces or edges), their entity
/// chosen by the direction of the outward normal, and physical groups.
fn with_boundary(mut mesh: LinearMesh) -> LinearMesh {
    let mut count: HashMap<Vec<u32>, usize> = HashMap::new();
    let mut local = Vec::new();
    for cell in &mesh.cells {
        let shape = cell.kind;
        let faces: Vec<Vec<usize>> = if mesh.dim == 3 {
            shape.faces().iter().map(|f| f.to_vec()).collect()
        } else {
            shape.edges().iter().map(|e| e.to_vec()).collect()
        };
        for f in faces {
            let verts: Vec<u32> = f.iter().map(|&i| cell.vertices[i]).collect();
            let mut key = verts.clone();
            key.sort_unstable();
            *count.entry(key).or_default() += 1;
            local.push(verts);
        }
    }
    let centroid = |verts: &[u32]| {
        let mut c = [0.0; 3];
        for &v in verts {
            for (cd, xd) in c.iter_mut().zip(mesh.vertices[v as usize]) {
                *cd += xd / verts.len() as f64;
            }
        }
        c
    };
    let all: Vec<u32> = (0..mesh.vertices.len() as u32).collect();
    let center = centroid(&all);
    for verts in local {
        let mut key = verts.clone();
        key.sort_unstable();
        if count[&key] != 1 {
            continue;
        }
        let c = centroid(&verts);
        let d: Vec<f64> = (0..3).map(|k| c[k] - center[k]).collect();
        let axis = (0..3)
            .max_by(|&a, &b| d[a].abs().total_cmp(&d[b].abs()))
            .unwrap();
        let entity = 1 + 2 * axis as i32 + i32::from(d[axis] > 0.0);
        let kind = match verts.len() {
            2 => Shape::Line,
            3 => Shape::Tri,
            _ => Shape::Quad,
        };
        mesh.facets.push(element(kind, &verts, entity));
    }
    let fdim = mesh.dim - 1;
    let mut facet_entities: Vec<i32> = mesh.facets.iter().map(|f| f.entity).collect();
    facet_entities.sort_unstable();
    facet_entities.dedup();
    for &e in &facet_entities {
        // Two named groups and one unnamed group, shared by several entities.
        mesh.entity_physicals.insert((fdim, e), vec![100 + (e % 3)]);
    }
    let mut cell_entities: Vec<i32> = mesh.cells.iter().map(|c| c.entity).collect();
    cell_entities.sort_unstable();
    cell_entities.dedup();
    for &e in &cell_entities {
        mesh.entity_physicals.insert((mesh.dim, e), vec![1]);
    }
    let mut groups = vec![PhysicalGroup {
        dim: mesh.dim,
        tag: 1,
        name: "domain".into(),
    }];
    for t in facet_entities.iter().map(|e| 100 + (e % 3)) {
        let name = match t {
            100 => "wall".to_string(),
            101 => "inlet side".to_string(),
            _ => String::new(),
        };
        let g = PhysicalGroup {
            dim: fdim,
            tag: t,
            name,
        };
        if !groups.contains(&g) {
            groups.push(g);
        }
    }
    groups.sort();
    mesh.physical_groups = groups;
    mesh
}

fn finish(dim: usize, vertices: Vec<[f64; 3]>, cells: Vec<Element>) -> LinearMesh {
    with_boundary(LinearMesh {
        dim,
        vertices: vertices.into_iter().map(|x| affine(dim, x)).collect(),
        cells,
        ..Default::default()
    })
}

/// Two hexahedra: [0, 2] × [0, 1]².
fn hexes() -> (LinearMesh, f64) {
    let mut v = Vec::new();
    for z in 0..2 {
        for y in 0..2 {
            for x in 0..3 {
                v.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    let id = |x: u32, y: u32, z: u32| x + 3 * y + 6 * z;
    let cells = (0..2)
        .map(|x| {
            let h = [
                id(x, 0, 0),
                id(x + 1, 0, 0),
                id(x + 1, 1, 0),
                id(x, 1, 0),
                id(x, 0, 1),
                id(x + 1, 0, 1),
                id(x + 1, 1, 1),
                id(x, 1, 1),
            ];
            element(Shape::Hex, &h, 1 + x as i32)
        })
        .collect();
    (finish(3, v, cells), 2.0 * det_affine(3))
}

fn signed_volume(v: &[[f64; 3]], t: &[u32]) -> f64 {
    let [a, b, c, d] = [t[0], t[1], t[2], t[3]].map(|i| v[i as usize]);
    let e = |p: [f64; 3]| [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let (u, w, x) = (e(b), e(c), e(d));
    u[0] * (w[1] * x[2] - w[2] * x[1]) - u[1] * (w[0] * x[2] - w[2] * x[0])
        + u[2] * (w[0] * x[1] - w[1] * x[0])
}

/// Two unit cubes side by side, each split into the 6 Kuhn tetrahedra; the 12 tetrahedra
/// list their vertices in the 12 even permutations, so shared faces are seen in every
/// rotation and both directions.
fn tets() -> (LinearMesh, f64) {
    let mut v = Vec::new();
    for z in 0..2 {
        for y in 0..2 {
            for x in 0..3 {
                v.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    let id = |p: [u32; 3]| p[0] + 3 * p[1] + 6 * p[2];
    let even: Vec<[usize; 4]> = {
        let mut out = Vec::new();
        for a in 0..4 {
            for b in 0..4 {
                for c in 0..4 {
                    for d in 0..4 {
                        let p = [a, b, c, d];
                        let distinct = (0..4).all(|i| (0..i).all(|j| p[i] != p[j]));
                        let inversions = (0..4)
                            .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
                            .filter(|&(i, j)| p[i] > p[j])
                            .count();
                        if distinct && inversions % 2 == 0 {
                            out.push(p);
                        }
                    }
                }
            }
        }
        out
    };
    assert_eq!(even.len(), 12);
    let mut cells = Vec::new();
    for cube in 0..2u32 {
        let axes = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        for order in axes {
            let mut p = [cube, 0, 0];
            let mut path = vec![id(p)];
            for a in order {
                p[a] += 1;
                path.push(id(p));
            }
            if signed_volume(&v, &path) < 0.0 {
                path.swap(2, 3);
            }
            let perm = even[cells.len()];
            let t: Vec<u32> = perm.iter().map(|&i| path[i]).collect();
            assert!(signed_volume(&v, &t) > 0.0);
            cells.push(element(Shape::Tet, &t, 1 + cube as i32));
        }
    }
    (finish(3, v, cells), 2.0 * det_affine(3))
}

/// The unit square split into two triangles, extruded in two layers: four prisms.
fn prisms() -> (LinearMesh, f64) {
    let mut v = Vec::new();
    for z in 0..3 {
        for y in 0..2 {
            for x in 0..2 {
                v.push([x as f64, y as f64, 0.5 * z as f64]);
            }
        }
    }
    let id = |x: u32, y: u32, z: u32| x + 2 * y + 4 * z;
    let mut cells = Vec::new();
    for z in 0..2 {
        for tri in [[(0, 0), (1, 0), (1, 1)], [(0, 0), (1, 1), (0, 1)]] {
            let bottom: Vec<u32> = tri.iter().map(|&(x, y)| id(x, y, z)).collect();
            let top: Vec<u32> = tri.iter().map(|&(x, y)| id(x, y, z + 1)).collect();
            let all: Vec<u32> = bottom.into_iter().chain(top).collect();
            cells.push(element(Shape::Prism, &all, 1));
        }
    }
    (finish(3, v, cells), det_affine(3))
}

/// A hexahedron, two prisms against its x = 1 face, two tetrahedra on the prisms' tops.
fn hybrid() -> (LinearMesh, f64) {
    let v = vec![
        [0.0, 0.0, 0.0],             // 0
        [1.0, 0.0, 0.0],             // 1
        [1.0, 1.0, 0.0],             // 2
        [0.0, 1.0, 0.0],             // 3
        [0.0, 0.0, 1.0],             // 4
        [1.0, 0.0, 1.0],             // 5
        [1.0, 1.0, 1.0],             // 6
        [0.0, 1.0, 1.0],             // 7
        [2.0, 0.0, 0.0],             // 8
        [2.0, 1.0, 0.0],             // 9
        [2.0, 0.0, 1.0],             // 10
        [2.0, 1.0, 1.0],             // 11
        [4.0 / 3.0, 1.0 / 3.0, 1.5], // 12: apex above the first prism
        [5.0 / 3.0, 2.0 / 3.0, 1.5], // 13: apex above the second prism
    ];
    let cells = vec![
        element(Shape::Hex, &[0, 1, 2, 3, 4, 5, 6, 7], 1),
        element(Shape::Prism, &[1, 8, 2, 5, 10, 6], 2),
        element(Shape::Prism, &[8, 9, 2, 10, 11, 6], 2),
        element(Shape::Tet, &[5, 10, 6, 12], 3),
        element(Shape::Tet, &[10, 11, 6, 13], 3),
    ];
    let volume = 1.0 + 1.0 + 2.0 * (0.5 * 0.5 / 3.0);
    (finish(3, v, cells), volume * det_affine(3))
}

/// Triangles of a 3 × 2 grid, each listing its vertices from a different start.
fn triangles() -> (LinearMesh, f64) {
    let mut v = Vec::new();
    for y in 0..3 {
        for x in 0..4 {
            v.push([x as f64, y as f64, 0.0]);
        }
    }
    let id = |x: u32, y: u32| x + 4 * y;
    let mut cells = Vec::new();
    for y in 0..2 {
        for x in 0..3 {
            let (a, b, c, d) = (id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1));
            let tris = if (x + y) % 2 == 0 {
                [[a, b, c], [a, c, d]]
            } else {
                [[a, b, d], [b, c, d]]
            };
            for t in tris {
                let r = cells.len() % 3;
                let rotated = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
                cells.push(element(Shape::Tri, &rotated, 1 + (x as i32 % 2)));
            }
        }
    }
    (finish(2, v, cells), 6.0 * det_affine(2))
}

/// Two quadrilaterals and two triangles.
fn quads_and_triangles() -> (LinearMesh, f64) {
    let mut v = Vec::new();
    for y in 0..2 {
        for x in 0..4 {
            v.push([x as f64, y as f64, 0.0]);
        }
    }
    let cells = vec![
        element(Shape::Quad, &[0, 1, 5, 4], 1),
        element(Shape::Quad, &[3, 7, 6, 2], 1),
        element(Shape::Tri, &[1, 2, 6], 2),
        element(Shape::Tri, &[6, 5, 1], 2),
    ];
    (finish(2, v, cells), 3.0 * det_affine(2))
}

type Sample = (&'static str, fn() -> (LinearMesh, f64));

const SAMPLES: [Sample; 6] = [
    ("hex", hexes),
    ("tet", tets),
    ("prism", prisms),
    ("hybrid", hybrid),
    ("tri", triangles),
    ("quadtri", quads_and_triangles),
];

const MAX_ORDER: usize = 6;

fn output_dir() -> (Option<tempfile::TempDir>, PathBuf) {
    match std::env::var_os("HOCURVE_INTEROP_DIR") {
        Some(d) => {
            let d = PathBuf::from(d);
            std::fs::create_dir_all(&d).unwrap();
            (None, d)
        }
        None => {
            let t = tempfile::tempdir().unwrap();
            let p = t.path().to_path_buf();
            (Some(t), p)
        }
    }
}

fn write_samples(dir: &Path) -> String {
    let mut manifest = String::from("# file\tmeasure (volume in 3D, area in 2D)\n");
    for (name, build) in SAMPLES {
        let (linear, measure) = build();
        for p in 1..=MAX_ORDER {
            let mesh = HighOrderMesh::from_linear(&linear, p, NodeFamily::Equispaced)
                .unwrap_or_else(|e| panic!("{name} p={p}: {e}"));
            let coords: Vec<f64> = mesh.nodes.iter().flatten().copied().collect();
            let ids: Vec<f64> = (0..mesh.cells.len()).map(|c| c as f64).collect();
            let pd = [DataArray {
                name: "coordinates",
                components: 3,
                values: &coords,
            }];
            let cd = [DataArray {
                name: "cell id",
                components: 1,
                values: &ids,
            }];
            let base = format!("{name}_p{p}");
            write_vtu(&dir.join(format!("{base}.vtu")), &mesh, &pd, &cd).unwrap();
            write_vtu_with(
                &dir.join(format!("{base}_ascii.vtu")),
                &mesh,
                &pd,
                &cd,
                VtuEncoding::Ascii,
            )
            .unwrap();
            write_msh(&dir.join(format!("{base}.msh")), &mesh).unwrap();
            for suffix in [".vtu", "_ascii.vtu", ".msh"] {
                writeln!(manifest, "{base}{suffix}\t{measure:?}").unwrap();
            }
        }
    }
    std::fs::write(dir.join("expected.tsv"), &manifest).unwrap();
    manifest
}

#[test]
fn samples_of_every_type_and_order_are_written() {
    let (_keep, dir) = output_dir();
    let manifest = write_samples(&dir);
    assert_eq!(manifest.lines().count(), 1 + SAMPLES.len() * MAX_ORDER * 3);
    // Spot checks of the content: VTK Lagrange types above order 1, Gmsh types.
    let vtu = std::fs::read_to_string(dir.join("hybrid_p3_ascii.vtu")).unwrap();
    assert!(
        vtu.contains("\n          72\n          73\n          73\n          71\n          71\n")
    );
    let msh = std::fs::read_to_string(dir.join("hybrid_p3.msh")).unwrap();
    for block in ["3 1 92 1", "3 2 90 2", "3 3 29 2"] {
        assert!(msh.contains(&format!("\n{block}\n")), "{block}");
    }
}

#[test]
fn order_one_msh_reads_back_as_the_same_linear_mesh() {
    let dir = tempfile::tempdir().unwrap();
    for (name, build) in SAMPLES {
        let (linear, _) = build();
        let mesh = HighOrderMesh::from_linear(&linear, 1, NodeFamily::Equispaced).unwrap();
        let path = dir.path().join(format!("{name}.msh"));
        write_msh(&path, &mesh).unwrap();
        let back = read_msh(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(back.dim, linear.dim, "{name}");
        assert_eq!(back.vertices, linear.vertices, "{name}");
        assert_eq!(back.cells, linear.cells, "{name}");
        assert_eq!(back.facets, linear.facets, "{name}");
        assert_eq!(back.physical_groups, linear.physical_groups, "{name}");
        assert_eq!(back.entity_physicals, linear.entity_physicals, "{name}");
        // The file's tags: nodes 1..=N, facets first then cells.
        let n = linear.vertices.len() as u64;
        let f = linear.facets.len() as u64;
        let c = linear.cells.len() as u64;
        assert_eq!(back.vertex_tags, (1..=n).collect::<Vec<_>>(), "{name}");
        assert_eq!(
            back.cell_tags,
            (f + 1..=f + c).collect::<Vec<_>>(),
            "{name}"
        );
    }
}

#[test]
fn high_order_msh_node_blocks_keep_tags_in_order() {
    // Node tags must appear as 1, 2, …, N whatever the classification.
    let dir = tempfile::tempdir().unwrap();
    let (linear, _) = hybrid();
    let mesh = HighOrderMesh::from_linear(&linear, 4, NodeFamily::Equispaced).unwrap();
    let path = dir.path().join("h.msh");
    write_msh(&path, &mesh).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let nodes = &text[text.find("$Nodes\n").unwrap() + 7..text.find("$EndNodes").unwrap()];
    let mut lines = nodes.lines();
    let header: Vec<usize> = lines
        .next()
        .unwrap()
        .split(' ')
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(header[1], mesh.nodes.len());
    let mut next = 1;
    let mut per_entity: BTreeMap<(usize, i32), usize> = BTreeMap::new();
    for _ in 0..header[0] {
        let b: Vec<i64> = lines
            .next()
            .unwrap()
            .split(' ')
            .map(|t| t.parse().unwrap())
            .collect();
        *per_entity.entry((b[0] as usize, b[1] as i32)).or_default() += b[3] as usize;
        for _ in 0..b[3] {
            assert_eq!(lines.next().unwrap(), next.to_string());
            next += 1;
        }
        for _ in 0..b[3] {
            lines.next().unwrap();
        }
    }
    assert_eq!(next - 1, mesh.nodes.len());
    // Interior nodes of cells sit on volumes, boundary nodes on surfaces.
    assert!(per_entity.keys().any(|&(d, _)| d == 2));
    assert!(per_entity.keys().any(|&(d, _)| d == 3));
}
