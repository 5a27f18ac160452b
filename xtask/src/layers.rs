//! `cargo xtask bench --layers`: hocurve's default curving of boundary-layer meshes at full
//! stretch (issue 21), timed with the release build, one run per mesh and order.
//!
//! The meshes: the CAD fixtures with layers (`fixtures/cad/`: the extruded cylinder as
//! hexahedra and prisms, split into tetrahedra; the extruded NACA 0012 section likewise;
//! the tetrahedral and prismatic layers around a sphere), the issue's own case, an extruded
//! cylinder section with a Gmsh BoundaryLayer field (~31 k prisms, made by `bench_gmsh.py
//! cylinder_field`), and issue 20's boundary-layer tetrahedra (25 k, stretch ~290: the
//! sphere layers at surface size 0.2). Printed per run: time, peak memory, unknowns and CG iterations, the
//! cells moved as boundary-layer columns, the certified lower bound of Ĩ and the Ĩ
//! sampled at the degree-2p points, or why the run failed. Gmsh's projection is not timed
//! here: it needs the CAD model in Gmsh, which the fixtures do not carry. Then prisms
//! against tetrahedra per unknown on the same layered shell ([`per_unknown`]).

use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result};
use serde_json::Value;

use crate::{cargo, python_env, root, run, target_dir};

/// Mesh (under the repository), geometry, orders.
const CASES: [(&str, &str, &[usize]); 9] = [
    (
        "fixtures/cad/cylinder_layers.msh",
        "fixtures/cad/cylinder_layers.json",
        &[2, 3, 4, 5],
    ),
    (
        "fixtures/cad/cylinder_layers_tets.msh",
        "fixtures/cad/cylinder_layers_tets.json",
        &[2, 3, 4],
    ),
    (
        "fixtures/cad/naca_layers.msh",
        "fixtures/cad/naca_layers.igs",
        &[2, 3, 4, 5],
    ),
    (
        "fixtures/cad/naca_layers_tets.msh",
        "fixtures/cad/naca_layers_tets.igs",
        &[2, 3],
    ),
    (
        "fixtures/cad/sphere_layers.msh",
        "fixtures/cad/sphere_layers.json",
        &[2, 3, 4],
    ),
    (
        "fixtures/cad/sphere_layers_coarse.msh",
        "fixtures/cad/sphere_layers_coarse.json",
        &[4],
    ),
    (
        "fixtures/cad/sphere_layers_prisms.msh",
        "fixtures/cad/sphere_layers_prisms.json",
        &[2, 3, 4, 5],
    ),
    (
        "target/bench-layers/cylinder_field.msh",
        "fixtures/cad/cylinder_layers.json",
        &[2, 3],
    ),
    (
        "target/bench-layers/sphere_layers_25k.msh",
        "target/bench-layers/sphere_layers_25k.json",
        &[4],
    ),
];

pub fn layers() -> Result<()> {
    let Some(python) = python_env(false)? else {
        anyhow::bail!("bench --layers needs the Python environment with gmsh");
    };
    run(
        "build hocurve (release)",
        cargo().args(["build", "--release", "-p", "hocurve-cli"]),
    )?;
    let hocurve = target_dir().join("release").join("hocurve");
    let out = root().join("target").join("bench-layers");
    std::fs::create_dir_all(&out)?;
    run(
        "Gmsh makes 25 k boundary-layer tetrahedra (make_cad_fixtures.sphere_layers, size 0.2)",
        Command::new(&python).arg("-c").arg(format!(
            "import sys; sys.path.insert(0, {fixtures:?}); import make_cad_fixtures as m; \
             m.OUT = {out:?}; m.sphere_layers('sphere_layers_25k', lc=0.2)",
            fixtures = root().join("fixtures").display().to_string(),
            out = out.display().to_string(),
        )),
    )?;
    run(
        "Gmsh makes issue 21's cylinder boundary layer (bench_gmsh.py cylinder_field)",
        Command::new(&python)
            .arg(root().join("xtask").join("scripts").join("bench_gmsh.py"))
            .arg("cylinder_field")
            .arg(out.join("cylinder_field.msh")),
    )?;
    let mut rows = Vec::new();
    for (mesh, geometry, orders) in CASES {
        for &p in orders {
            let name = Path::new(mesh)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let report = out.join(format!("{name}_p{p}.json"));
            let _ = std::fs::remove_file(&report);
            eprintln!("==> {name}, p = {p}");
            let output = Command::new(&hocurve)
                .current_dir(root())
                .arg("curve")
                .arg(mesh)
                .args(["-p", &p.to_string(), "--geometry", geometry, "-o"])
                .arg(out.join(format!("{name}_p{p}.msh")))
                .arg("--report")
                .arg(&report)
                .stdout(std::process::Stdio::null())
                .output()
                .context("running hocurve")?;
            let json: Option<Value> = std::fs::read_to_string(&report)
                .ok()
                .and_then(|s| serde_json::from_str(&s).ok());
            // A rejected run writes nothing, not even its report: keep its reason.
            let reason: String = String::from_utf8_lossy(&output.stderr)
                .lines()
                .last()
                .unwrap_or_default()
                .chars()
                .take(110)
                .collect();
            rows.push((name, p, output.status.success(), json, reason));
        }
    }
    println!();
    println!(
        "boundary-layer meshes, default options ({} threads)",
        crate::bench::rayon_threads()
    );
    println!(
        "{:<22} {:>2} {:>7} {:>8} {:>8} {:>4} {:>7} {:>6} {:>8} {:>8} {:>7}",
        "mesh", "p", "cells", "stretch", "dofs", "its", "columns", "s", "MB", "Ĩ bound", "Ĩ 2p"
    );
    for (name, p, ok, json, reason) in rows {
        let Some(r) = json else {
            println!("{name:<22} {p:>2}  {reason}");
            continue;
        };
        let f = |key: &str| r[key].as_f64().unwrap_or(f64::NAN);
        let u = |key: &str| r[key].as_u64().unwrap_or(0);
        println!(
            "{name:<22} {p:>2} {:>7} {:>8.0} {:>8} {:>4} {:>7} {:>6.2} {:>8.0} {:>8.4} {:>7.4}{}",
            u("elements"),
            f("max_stretching"),
            u("dofs"),
            u("iterations"),
            u("layer_column_cells"),
            r["timings"]["total"].as_f64().unwrap_or(f64::NAN),
            f("peak_memory_mb"),
            f("min_scaled_jacobian_lower_bound"),
            f("min_scaled_jacobian"),
            if ok {
                String::new()
            } else {
                format!(
                    "  NOT VALID ({} elements not certified)",
                    u("invalid_elements")
                )
            }
        );
    }
    println!("stretch = largest longest/shortest edge of a cell; columns = cells moved with the wall as boundary-layer columns;");
    println!("s = whole process (read to write); MB = peak resident memory; Ĩ bound = certified (Bézier) lower bound, Ĩ 2p = sampled at the degree-2p points.");
    per_unknown(&python, &hocurve, &out)
}

/// Prisms against tetrahedra per unknown (issue 21, point 4): the boundary layer of
/// `sphere_layers` alone (`make_cad_fixtures.sphere_shell`, size 0.15: 12 k prisms on
/// curved layers, not affine), and the same extrusion split into 36 k tets — the same
/// nodes and unknowns at every order. Both solved whole by elasticity (`--elastic-layers
/// --solve-region whole`); printed per order: the CG iterations' time per iteration and
/// unknown, and the whole run.
fn per_unknown(python: &Path, hocurve: &Path, out: &Path) -> Result<()> {
    run(
        "Gmsh makes the layered sphere shell as prisms and as tets (sphere_shell, size 0.15)",
        Command::new(python).arg("-c").arg(format!(
            "import sys; sys.path.insert(0, {fixtures:?}); import make_cad_fixtures as m; \
             m.OUT = {out:?}; m.sphere_shell('shell_prisms', 0.15, True); \
             m.sphere_shell('shell_tets', 0.15, False)",
            fixtures = root().join("fixtures").display().to_string(),
            out = out.display().to_string(),
        )),
    )?;
    println!();
    println!("prisms against tets per unknown: the layered sphere shell, whole mesh solved");
    println!(
        "{:>2} {:>8} {:>11} {:>11} {:>6} {:>9} {:>9}",
        "p", "dofs", "prism ns", "tet ns", "ratio", "prism s", "tet s"
    );
    for p in [2, 3, 4] {
        let mut row = Vec::new();
        for name in ["shell_prisms", "shell_tets"] {
            let report = out.join(format!("{name}_p{p}.json"));
            let _ = std::fs::remove_file(&report);
            eprintln!("==> {name}, p = {p}");
            let status = Command::new(hocurve)
                .arg("curve")
                .arg(out.join(format!("{name}.msh")))
                .args(["-p", &p.to_string(), "--geometry"])
                .arg(out.join(format!("{name}.json")))
                .args(["--elastic-layers", "--solve-region", "whole", "-o"])
                .arg(out.join(format!("{name}_p{p}.msh")))
                .arg("--report")
                .arg(&report)
                .stdout(std::process::Stdio::null())
                .status()
                .context("running hocurve")?;
            let json: Value = serde_json::from_str(&std::fs::read_to_string(&report)?)?;
            anyhow::ensure!(status.success(), "{name} at p = {p} failed");
            let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
            let (dofs, its) = (f(&json["dofs"]), f(&json["iterations"]));
            let per = f(&json["timings"]["solve_iterations"]) / its / dofs;
            row.push((dofs, per, f(&json["timings"]["total"])));
        }
        let ((dofs, prism, prism_s), (_, tet, tet_s)) = (row[0], row[1]);
        println!(
            "{p:>2} {dofs:>8} {:>11.1} {:>11.1} {:>6.2} {prism_s:>9.2} {tet_s:>9.2}",
            prism * 1e9,
            tet * 1e9,
            prism / tet
        );
    }
    println!("ns = nanoseconds per unknown and CG iteration (V-cycle and CG operator); s = whole process.");
    Ok(())
}
