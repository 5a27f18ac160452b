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
//! here: it needs the CAD model in Gmsh, which the fixtures do not carry.

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
    Ok(())
}
