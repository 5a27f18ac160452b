//! Interoperability of the curved output: the real VTK reads every committed snapshot
//! `.vtu` and integrates it with its own Lagrange shape functions
//! (`scripts/check_snapshots.py`), and the real Gmsh reads the curved `.msh` files we write —
//! every element type (triangles, quadrilaterals, tetrahedra, hexahedra, prisms) at
//! p = 1..5, the coarse OpenCASCADE sphere at p = 6, 7 and a smaller one (257 tetrahedra)
//! at p = 8, 9, 10 (`--full`: both at 6..10; Gmsh's O(n²)-per-point evaluation takes
//! minutes on the coarse sphere at p = 10) — finds det J positive at its own
//! Gauss points (`scripts/check_msh.py --curved`) and equal to ours at our quadrature points
//! (`scripts/compare_jacobians.py`). Every mesh is curved with the default options and must
//! come out with every element certified valid by our Bézier check.
//!
//! Our side: each fixture is curved in-process with [`curve_mesh`], written with
//! [`write_msh`] (resampled to equispaced nodes, as Gmsh defines its elements), and det J of
//! every cell at the points of the degree-2p quadrature rule (where the scaled Jacobian is
//! sampled) is computed on the unresampled mesh and written to a JSON file beside the mesh.

use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result};
use hocurve::geodesic::AssociationRule;
use hocurve::io::write_msh;
use hocurve::mesh::{HighOrderMesh, LinearMesh};
use hocurve::nodes::{NodeFamily, QuadratureRule};
use hocurve::nurbs::parse_geometry_json;
use hocurve::pipeline::{curve_mesh, CurveOptions, Geometry};
use hocurve::quality::JacobianSampler;

use crate::{root, run};

/// A fixture curved for the Gmsh comparison: name, mesh, geometry JSON, orders (with
/// `--full`, and without).
struct Case {
    name: &'static str,
    mesh: &'static str,
    geometry: &'static str,
    orders: std::ops::RangeInclusive<usize>,
    default_orders: std::ops::RangeInclusive<usize>,
}

const CASES: [Case; 6] = [
    Case {
        name: "naca0012_tri",
        mesh: "fixtures/naca0012/naca0012.msh",
        geometry: "fixtures/naca0012/naca0012.json",
        orders: 1..=5,
        default_orders: 1..=5,
    },
    Case {
        name: "naca0012_quad",
        mesh: "fixtures/quad/naca0012_quads.msh",
        geometry: "fixtures/naca0012/naca0012.json",
        orders: 1..=5,
        default_orders: 1..=5,
    },
    Case {
        name: "hybrid_hex_prism",
        mesh: "fixtures/hybrid/hybrid.msh",
        geometry: "fixtures/hybrid/hybrid.json",
        orders: 1..=5,
        default_orders: 1..=5,
    },
    Case {
        name: "sphere_tet",
        mesh: "fixtures/sphere/sphere.msh",
        geometry: "fixtures/sphere/sphere.json",
        orders: 1..=5,
        default_orders: 1..=5,
    },
    Case {
        name: "sphere_coarse_tet",
        mesh: "fixtures/cad/sphere_coarse.msh",
        geometry: "fixtures/cad/sphere_coarse.json",
        orders: 6..=10,
        default_orders: 6..=7,
    },
    // The same model with every size ×4 (257 tetrahedra, 42 triangles on the sphere:
    // large boundary displacements), at p = 8..10 (6..10 with --full).
    Case {
        name: "sphere_small_tet",
        mesh: "fixtures/sphere/sphere_small.msh",
        geometry: "fixtures/sphere/sphere.json",
        orders: 6..=10,
        default_orders: 8..=10,
    },
];

/// Runs the VTK snapshot check and the Gmsh checks of curved meshes with `python`; `full`
/// takes both coarse spheres through p = 6..10 (by default: 1 493 tets at 6, 7; 257 at
/// 8..10).
pub fn curved_interop(python: &Path, full: bool) -> Result<()> {
    let scripts = root().join("xtask").join("scripts");
    let out = root().join("target").join("interop");
    run(
        "VTK reads the committed snapshot .vtu files and integrates them",
        Command::new(python)
            .arg(scripts.join("check_snapshots.py"))
            .arg(root().join("tests").join("snapshots"))
            .arg(out.join("snapshots")),
    )?;

    let dir = out.join("curved");
    if dir.exists() {
        std::fs::remove_dir_all(&dir)?;
    }
    std::fs::create_dir_all(&dir)?;
    eprintln!("==> curve the fixtures (p = 1..5; the coarse spheres at 6..10, with --full both at 6..10) and write .msh with our det J");
    let mut meshes = Vec::new();
    for case in &CASES {
        let linear = hocurve::io::read_msh(&root().join(case.mesh))?;
        let json = std::fs::read_to_string(root().join(case.geometry))
            .with_context(|| format!("reading {}", case.geometry))?;
        let model = parse_geometry_json(&json)?;
        let rule = AssociationRule::NameOnly; // JSON geometries: by physical-group name
        let orders = if full {
            case.orders.clone()
        } else {
            case.default_orders.clone()
        };
        for p in orders {
            let t = std::time::Instant::now();
            let file = dir.join(format!("{}_p{p}.msh", case.name));
            write_curved(&linear, &model, rule, p, &file)?;
            eprintln!(
                "    {} ({:.1} s)",
                file.file_name().unwrap_or_default().to_string_lossy(),
                t.elapsed().as_secs_f64()
            );
            meshes.push(file);
        }
    }
    run(
        &format!(
            "Gmsh reads {} curved .msh files: det J > 0 at its Gauss points",
            meshes.len()
        ),
        Command::new(python)
            .arg(scripts.join("check_msh.py"))
            .arg("--curved")
            .args(&meshes),
    )?;
    run(
        "Gmsh's det J equals ours at our quadrature points",
        Command::new(python)
            .arg(scripts.join("compare_jacobians.py"))
            .args(&meshes),
    )?;
    Ok(())
}

/// Curves `linear` at order `p` (Fekete nodes), writes it to `file` and our det J to
/// `file` with extension `.json`.
fn write_curved(
    linear: &LinearMesh,
    model: &hocurve::nurbs::GeometryModel,
    rule: AssociationRule,
    p: usize,
    file: &Path,
) -> Result<()> {
    let curved = curve_mesh(
        linear,
        Some(Geometry { model, rule }),
        &CurveOptions::new(p),
        &mut |_| {},
    )
    .with_context(|| format!("curving for {}", file.display()))?;
    let report = &curved.report;
    let certified = report.certified_valid_elements.unwrap_or(0);
    if report.invalid_elements > 0 || certified != curved.mesh.cells.len() {
        anyhow::bail!(
            "{}: {} invalid, {certified} of {} elements certified valid",
            file.display(),
            report.invalid_elements,
            curved.mesh.cells.len()
        );
    }
    let mesh = &curved.mesh;
    write_msh(file, &mesh.resampled(NodeFamily::Equispaced)?)?;
    std::fs::write(file.with_extension("json"), determinants_json(mesh)?)?;
    Ok(())
}

/// `{"groups": [{"shape", "order", "points": [[ξ]], "tags": [..], "det": [[..]]}]}`: per
/// shape, our reference points, the Gmsh element tags of the cells (`write_msh` numbers the
/// facets first, then the cells, from 1) and det J of each cell at each point.
fn determinants_json(mesh: &HighOrderMesh) -> Result<String> {
    let mut by_shape = std::collections::BTreeMap::new();
    for (i, cell) in mesh.cells.iter().enumerate() {
        by_shape.entry(cell.kind).or_insert_with(Vec::new).push(i);
    }
    let mut s = String::from("{\"groups\": [\n");
    for (g, (shape, cells)) in by_shape.iter().enumerate() {
        let rule = QuadratureRule::new(*shape, 2 * mesh.order);
        let sampler = JacobianSampler::at_points(*shape, mesh.order, mesh.family, &rule.points)?;
        let list = |v: &mut dyn Iterator<Item = String>| v.collect::<Vec<_>>().join(", ");
        let points = list(
            &mut rule
                .points
                .iter()
                .map(|x| format!("[{:?}, {:?}, {:?}]", x[0], x[1], x[2])),
        );
        let tags = list(
            &mut cells
                .iter()
                .map(|&i| (mesh.facets.len() + i + 1).to_string()),
        );
        let mut det = String::new();
        for (k, &i) in cells.iter().enumerate() {
            let coords: Vec<[f64; 3]> = mesh.cells[i]
                .nodes
                .iter()
                .map(|&n| mesh.nodes[n as usize])
                .collect();
            let values = sampler.determinants(&coords);
            let sep = if k == 0 { "" } else { ",\n" };
            let _ = write!(
                det,
                "{sep}[{}]",
                list(&mut values.iter().map(|v| format!("{v:?}")))
            );
        }
        let sep = if g == 0 { "" } else { ",\n" };
        let _ = write!(
            s,
            "{sep}{{\"shape\": \"{}\", \"order\": {}, \"points\": [{points}], \"tags\": [{tags}],\n\"det\": [{det}]}}",
            shape.name(),
            mesh.order
        );
    }
    s.push_str("\n]}\n");
    Ok(s)
}
