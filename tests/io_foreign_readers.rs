//! The high-order readers against files written by Gmsh and by VTK.
//!
//! `xtask/scripts/make_foreign_meshes.py` (run with `target/pyenv/bin/python`, which
//! `cargo xtask verify` sets up) meshes a disk (triangles and quadrilaterals), a ball
//! (tetrahedra) and a cylinder (hexahedra and prisms) with Gmsh at orders 1–4, curved onto
//! the geometry, saves each as MSH 4.1 and 2.2, ASCII and binary, and dumps Gmsh's own
//! Jacobian determinants and physical points at the Gauss points of degree 2p. Every file
//! must read with the right dimension, order and cell count, and every element must give
//! Gmsh's points and determinants (after mapping Gmsh's [−1, 1] reference directions onto
//! hocurve's [0, 1]) to 1e-10 relative, hence the same scaled Jacobian. Then VTK re-writes
//! one of our `.vtu` files in each of its layouts, which must read back to our nodes.
//!
//! Without that Python the tests print a loud SKIP and pass.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use hocurve::io::{read_high_order_msh, read_msh, read_vtu, write_vtu_with, VtuEncoding};
use hocurve::mesh::HighOrderMesh;
use hocurve::nodes::{LagrangeBasis, NodeFamily, ReferenceNodes, Shape};
use hocurve::quality::{jacobian_determinants, scaled_ratio};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The project's Python with gmsh and vtk, if set up.
fn python() -> Option<PathBuf> {
    let python = root().join("target/pyenv/bin/python");
    if python.exists() {
        Some(python)
    } else {
        eprintln!(
            "\n*** SKIP: {} does not exist: the Gmsh/VTK reader checks did NOT run \
             (run `cargo xtask verify` once to create it) ***\n",
            python.display()
        );
        None
    }
}

fn run_script(python: &Path, args: &[&str]) {
    let script = root().join("xtask/scripts/make_foreign_meshes.py");
    let output = Command::new(python)
        .arg(&script)
        .args(args)
        .output()
        .expect("python runs");
    assert!(
        output.status.success(),
        "{} {args:?} failed:\n{}\n{}",
        script.display(),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

// ---------------------------------------------------------------------------------------
// A minimal JSON reader (objects, arrays, numbers, strings, literals) for the script's data.
// ---------------------------------------------------------------------------------------

#[derive(Debug, Clone)]
enum Json {
    Null,
    Bool(#[allow(dead_code)] bool),
    Number(f64),
    Text(String),
    Array(Vec<Json>),
    Object(Vec<(String, Json)>),
}

impl Json {
    fn parse(text: &str) -> Json {
        let mut pos = 0;
        let value = parse_value(text.as_bytes(), &mut pos);
        skip_ws(text.as_bytes(), &mut pos);
        assert_eq!(pos, text.len(), "trailing JSON");
        value
    }

    fn get(&self, key: &str) -> Option<&Json> {
        match self {
            Json::Object(fields) => fields.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    fn at(&self, key: &str) -> &Json {
        self.get(key)
            .unwrap_or_else(|| panic!("JSON has no field {key}"))
    }

    fn number(&self) -> f64 {
        match self {
            Json::Number(v) => *v,
            other => panic!("expected a number, found {other:?}"),
        }
    }

    fn array(&self) -> &[Json] {
        match self {
            Json::Array(v) => v,
            other => panic!("expected an array, found {other:?}"),
        }
    }

    fn numbers(&self) -> Vec<f64> {
        self.array().iter().map(Json::number).collect()
    }

    fn fields(&self) -> &[(String, Json)] {
        match self {
            Json::Object(v) => v,
            other => panic!("expected an object, found {other:?}"),
        }
    }
}

fn skip_ws(b: &[u8], pos: &mut usize) {
    while b.get(*pos).is_some_and(|c| c.is_ascii_whitespace()) {
        *pos += 1;
    }
}

fn parse_value(b: &[u8], pos: &mut usize) -> Json {
    skip_ws(b, pos);
    match b[*pos] {
        b'{' => {
            *pos += 1;
            let mut fields = Vec::new();
            loop {
                skip_ws(b, pos);
                if b[*pos] == b'}' {
                    *pos += 1;
                    return Json::Object(fields);
                }
                let Json::Text(key) = parse_value(b, pos) else {
                    panic!("JSON key is not a string")
                };
                skip_ws(b, pos);
                assert_eq!(b[*pos], b':');
                *pos += 1;
                fields.push((key, parse_value(b, pos)));
                skip_ws(b, pos);
                if b[*pos] == b',' {
                    *pos += 1;
                }
            }
        }
        b'[' => {
            *pos += 1;
            let mut items = Vec::new();
            loop {
                skip_ws(b, pos);
                if b[*pos] == b']' {
                    *pos += 1;
                    return Json::Array(items);
                }
                items.push(parse_value(b, pos));
                skip_ws(b, pos);
                if b[*pos] == b',' {
                    *pos += 1;
                }
            }
        }
        b'"' => {
            *pos += 1;
            let mut s = String::new();
            while b[*pos] != b'"' {
                if b[*pos] == b'\\' {
                    *pos += 1;
                }
                s.push(b[*pos] as char);
                *pos += 1;
            }
            *pos += 1;
            Json::Text(s)
        }
        b't' => {
            *pos += 4;
            Json::Bool(true)
        }
        b'f' => {
            *pos += 5;
            Json::Bool(false)
        }
        b'n' => {
            *pos += 4;
            Json::Null
        }
        _ => {
            let start = *pos;
            while b
                .get(*pos)
                .is_some_and(|c| matches!(c, b'-' | b'+' | b'.' | b'e' | b'E' | b'0'..=b'9'))
            {
                *pos += 1;
            }
            let text = std::str::from_utf8(&b[start..*pos]).unwrap();
            Json::Number(text.parse().unwrap_or_else(|_| panic!("bad number {text}")))
        }
    }
}

// ---------------------------------------------------------------------------------------
// Gmsh
// ---------------------------------------------------------------------------------------

/// hocurve's reference point of a Gmsh local point, and the factor from Gmsh's det J to
/// ours: quadrilaterals and hexahedra map [−1, 1] to [0, 1] in every direction, prisms in
/// their third; ∂x/∂u = ½ ∂x/∂ξ per such direction.
fn to_hocurve(shape: Shape, u: [f64; 3]) -> ([f64; 3], f64) {
    let half = |t: f64| 0.5 * (t + 1.0);
    match shape {
        Shape::Quad => ([half(u[0]), half(u[1]), 0.0], 4.0),
        Shape::Hex => ([half(u[0]), half(u[1]), half(u[2])], 8.0),
        Shape::Prism => ([u[0], u[1], half(u[2])], 2.0),
        _ => (u, 1.0),
    }
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Checks one mesh read from a Gmsh file against Gmsh's data; returns (elements checked,
/// elements whose type Gmsh could not evaluate).
fn check_against_gmsh(mesh: &HighOrderMesh, data: &Json, what: &str) -> (usize, usize) {
    let p = data.at("order").number() as usize;
    assert_eq!(mesh.order, p, "{what}");
    assert_eq!(mesh.dim, data.at("dim").number() as usize, "{what}");
    assert_eq!(
        mesh.cells.len(),
        data.at("num_cells").number() as usize,
        "{what}"
    );
    assert_eq!(mesh.family, NodeFamily::Equispaced);

    // Our cells by their corner coordinates (quantised; ASCII files round the last bit).
    let key = |corners: &[[f64; 3]]| -> Vec<i64> {
        corners
            .iter()
            .flat_map(|x| x.map(|c| (c * 1e8).round() as i64))
            .collect()
    };
    let corners_of = |c: usize| -> Vec<[f64; 3]> {
        let cell = &mesh.cells[c];
        cell.nodes[..cell.kind.num_vertices()]
            .iter()
            .map(|&n| mesh.nodes[n as usize])
            .collect()
    };
    let by_corners: HashMap<Vec<i64>, usize> = (0..mesh.cells.len())
        .map(|c| (key(&corners_of(c)), c))
        .collect();
    let mut bases: HashMap<Shape, LagrangeBasis> = HashMap::new();
    let (mut checked, mut skipped) = (0, 0);
    for (_, entry) in data.at("types").fields() {
        let Some(elements) = entry.get("elements") else {
            // A type Gmsh could not evaluate (prisms of order >= 3).
            skipped += entry.at("count").number() as usize;
            continue;
        };
        let local = entry.at("local_coords").numbers();
        for element in elements.array() {
            let corners: Vec<[f64; 3]> = element
                .at("corners")
                .array()
                .iter()
                .map(|c| {
                    let v = c.numbers();
                    [v[0], v[1], v[2]]
                })
                .collect();
            let c = match by_corners.get(&key(&corners)) {
                Some(&c) => c,
                None => (0..mesh.cells.len())
                    .find(|&c| {
                        let ours = corners_of(c);
                        ours.len() == corners.len()
                            && ours
                                .iter()
                                .zip(&corners)
                                .all(|(a, b)| distance(*a, *b) < 1e-12)
                    })
                    .unwrap_or_else(|| panic!("{what}: no cell has the corners {corners:?}")),
            };
            let shape = mesh.cells[c].kind;
            let mut scale = 1.0;
            let points: Vec<[f64; 3]> = local
                .chunks(3)
                .map(|u| {
                    let (xi, s) = to_hocurve(shape, [u[0], u[1], u[2]]);
                    scale = s;
                    xi
                })
                .collect();
            // Physical points: our map x(ξ) = Σ Φⱼ(ξ) xⱼ against Gmsh's.
            let basis = bases.entry(shape).or_insert_with(|| {
                LagrangeBasis::new(&ReferenceNodes::new(shape, p, NodeFamily::Equispaced)).unwrap()
            });
            let size = corners
                .iter()
                .map(|x| distance(*x, corners[0]))
                .fold(0.0, f64::max);
            let theirs_x = element.at("points").numbers();
            let mut phi = vec![0.0; basis.len()];
            for (q, xi) in points.iter().enumerate() {
                basis.eval(*xi, &mut phi);
                let mut x = [0.0; 3];
                for (f, &n) in phi.iter().zip(&mesh.cells[c].nodes) {
                    for d in 0..3 {
                        x[d] += f * mesh.nodes[n as usize][d];
                    }
                }
                let t = [theirs_x[3 * q], theirs_x[3 * q + 1], theirs_x[3 * q + 2]];
                assert!(
                    distance(x, t) <= 1e-10 * size,
                    "{what}: element {} point {q}: x = {x:?}, Gmsh {t:?}",
                    element.at("tag").number()
                );
            }
            // Jacobian determinants and the scaled Jacobian.
            let ours = jacobian_determinants(mesh, c, &points).unwrap();
            let theirs: Vec<f64> = element
                .at("dets")
                .numbers()
                .iter()
                .map(|d| d * scale)
                .collect();
            assert_eq!(ours.len(), theirs.len());
            let largest = ours.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
            for (q, (a, b)) in ours.iter().zip(&theirs).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-10 * largest,
                    "{what}: element {} ({}) point {q}: det J = {a}, Gmsh {b}",
                    element.at("tag").number(),
                    shape.name()
                );
            }
            let min_max = |v: &[f64]| {
                v.iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &d| {
                        (lo.min(d), hi.max(d))
                    })
            };
            let (a, b) = (min_max(&ours), min_max(&theirs));
            assert!((a.0 - b.0).abs() <= 1e-10 * largest && (a.1 - b.1).abs() <= 1e-10 * largest);
            let (sa, sb) = (scaled_ratio(a.0, a.1), scaled_ratio(b.0, b.1));
            assert!(
                (sa - sb).abs() <= 1e-10,
                "{what}: scaled Jacobian {sa} vs Gmsh {sb}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked + skipped, mesh.cells.len(), "{what}");
    (checked, skipped)
}

#[test]
fn gmsh_files_read_with_gmsh_points_and_jacobians() {
    let Some(python) = python() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    run_script(&python, &["gmsh", out]);
    let (mut checked, mut skipped, mut files) = (0, 0, 0);
    for model in ["disk2d", "ball", "cylinder"] {
        for p in 1..=4 {
            let stem = format!("{model}_p{p}");
            let data = Json::parse(
                &std::fs::read_to_string(dir.path().join(format!("{stem}.json"))).unwrap(),
            );
            // Cells, as sorted lists of their coordinates' bits (MSH 2.2 and 4.1 files may
            // list elements in different orders).
            let mut exact: Option<Vec<Vec<[u64; 3]>>> = None;
            for format in ["v41", "v41bin", "v22", "v22bin"] {
                let name = format!("{stem}_{format}.msh");
                let mesh = read_high_order_msh(&dir.path().join(&name))
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                let (c, s) = check_against_gmsh(&mesh, &data, &name);
                checked += c;
                skipped += s;
                files += 1;
                // Binary files hold the exact doubles: both versions agree bitwise.
                let mut bits: Vec<Vec<[u64; 3]>> = mesh
                    .cells
                    .iter()
                    .map(|c| {
                        c.nodes
                            .iter()
                            .map(|&n| mesh.nodes[n as usize].map(f64::to_bits))
                            .collect()
                    })
                    .collect();
                bits.sort();
                if format.ends_with("bin") {
                    match &exact {
                        None => exact = Some(bits),
                        Some(e) => assert!(*e == bits, "{name}: differs from the 4.1 binary file"),
                    }
                }
                if p == 1 {
                    // First-order files are also what the linear reader takes.
                    let linear = read_msh(&dir.path().join(&name)).unwrap();
                    assert_eq!(linear.cells.len(), mesh.cells.len());
                }
            }
        }
    }
    eprintln!(
        "Gmsh files: {files} read, {checked} elements checked against Gmsh's points and \
         Jacobians, {skipped} not checkable (Gmsh cannot evaluate prisms of order ≥ 3)"
    );
    assert!(checked > 1000);
}

// ---------------------------------------------------------------------------------------
// VTK
// ---------------------------------------------------------------------------------------

fn fixture_mesh(name: &str, p: usize) -> HighOrderMesh {
    let linear = read_msh(&root().join("fixtures").join(name)).unwrap();
    let mut mesh = HighOrderMesh::from_linear(&linear, p, NodeFamily::Equispaced).unwrap();
    for x in &mut mesh.nodes {
        let (a, b, c) = (x[0], x[1], x[2]);
        x[0] = a + 0.01 * (3.0 * b).sin();
        x[1] = b + 0.01 * (2.0 * a).cos();
        if linear.dim == 3 {
            x[2] = c + 0.01 * (a + b).sin();
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
fn vtk_rewritten_vtu_files_read_back_to_our_nodes() {
    let Some(python) = python() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for (name, p) in [
        ("hybrid/hybrid.msh", 3),
        ("quad/naca0012_quads.msh", 4),
        ("formats/cube_v41_ascii.msh", 4),
        ("formats/square_v41_ascii.msh", 5),
    ] {
        let mesh = fixture_mesh(name, p);
        let stem = name.replace('/', "_").replace(".msh", "");
        let ours = dir.path().join(format!("{stem}.vtu"));
        write_vtu_with(&ours, &mesh, &[], &[], VtuEncoding::Base64).unwrap();
        let prefix = dir.path().join(&stem);
        run_script(
            &python,
            &["vtk", ours.to_str().unwrap(), prefix.to_str().unwrap()],
        );
        for layout in ["default", "ascii", "base64", "binary", "uint32", "raw"] {
            let path = dir.path().join(format!("{stem}_{layout}.vtu"));
            let back = read_vtu(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert_eq!((back.dim, back.order), (mesh.dim, p), "{}", path.display());
            assert_eq!(cell_bits(&back), cell_bits(&mesh), "{}", path.display());
        }
    }
}
