//! `cargo xtask bench --scale`: how curving grows with the mesh, next to Gmsh's projection.
//!
//! Gmsh (the Python package in `target/pyenv`) meshes the sphere-in-a-box of
//! `fixtures/make_fixtures.py` with every size multiplied by a factor (`Mesh.MeshSizeFactor`;
//! the defaults 0.36, 0.25 and 0.165 give about 100 k, 280 k and 950 k tetrahedra), `hocurve
//! curve` (release, default options) curves each to the order (default 3) and reports its
//! seconds per step and peak memory, and Gmsh, in a fresh process on the same mesh, times
//! its plain projection (`setOrder`) and reports its own peak memory. The table ends with
//! the slope of log(time) against log(elements) over the sizes that ran (1 = linear growth).
//! A size hocurve refuses (its memory estimate exceeds this machine) is reported as such.
//!
//! Then the active-region check: the sphere of the first size factor (p = 3), a torus in a
//! box meshed by Gmsh (p = 4) and the boundary-layer tetrahedra of `fixtures/cad` (p = 4)
//! are curved with the default active region and with `--solve-region whole`; the check
//! fails unless the active region's min Ĩ (the scaled Jacobian at the quadrature points,
//! and the certified lower bound) is within 1 % of the whole solve's, with no invalid
//! element.

use std::process::Command;

use anyhow::{bail, Context, Result};
use serde_json::Value;

use crate::bench::list_argument;
use crate::{cargo, python_env, root, run, target_dir};

/// Size factors giving about 100 k, 280 k and 950 k tetrahedra.
const FACTORS: [f64; 3] = [0.36, 0.25, 0.165];

/// One size: hocurve's report (or why it did not run) and Gmsh's timing.
struct Row {
    factor: f64,
    ours: std::result::Result<Value, String>,
    gmsh: Value,
}

pub fn scale(args: &[String]) -> Result<()> {
    let mut factors = FACTORS.to_vec();
    let mut order = 3usize;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--factors" => factors = list_argument(it.next(), "--factors", "0.36,0.25")?,
            "--order" => {
                order = it
                    .next()
                    .context("--order needs a number")?
                    .parse()
                    .context("--order: a positive integer")?;
            }
            "--scale" => {}
            other => bail!("bench --scale: unknown argument {other}"),
        }
    }
    let Some(python) = python_env(false)? else {
        bail!("bench --scale needs the Python environment with gmsh");
    };
    run(
        "build hocurve (release)",
        cargo().args(["build", "--release", "-p", "hocurve-cli"]),
    )?;
    let hocurve = target_dir().join("release").join("hocurve");
    let out = root().join("target").join("bench-scale");
    std::fs::create_dir_all(&out)?;
    let script = root().join("xtask").join("scripts").join("bench_gmsh.py");

    let mut rows = Vec::new();
    for &factor in &factors {
        let linear = out.join(format!("sphere_{factor}.msh"));
        run(
            &format!("Gmsh meshes the sphere-in-a-box, size factor {factor}"),
            Command::new(&python)
                .arg(&script)
                .arg("mesh")
                .arg(&linear)
                .arg(factor.to_string()),
        )?;
        let report = out.join(format!("hocurve_{factor}_p{order}.json"));
        let _ = std::fs::remove_file(&report);
        eprintln!("==> hocurve curve, size factor {factor}, p = {order}");
        let output = Command::new(&hocurve)
            .current_dir(root())
            .arg("curve")
            .arg(&linear)
            .args(["--order", &order.to_string()])
            .args(["--geometry", "fixtures/sphere/sphere.json", "-o"])
            .arg(out.join(format!("hocurve_{factor}_p{order}.msh")))
            // Binary MSH, as large meshes travel (Gmsh's `-bin`): the I/O share is measured
            // on it.
            .arg("--binary")
            .arg("--report")
            .arg(&report)
            .output()
            .context("running hocurve")?;
        let ours = if output.status.success() {
            Ok(serde_json::from_str(&std::fs::read_to_string(&report)?)?)
        } else {
            let stderr = String::from_utf8_lossy(&output.stderr);
            let reason = stderr
                .lines()
                .rfind(|l| l.contains("error"))
                .unwrap_or("failed")
                .to_string();
            eprintln!("    {reason}");
            Err(reason)
        };
        let json = out.join(format!("gmsh_{factor}_p{order}.json"));
        run(
            &format!("Gmsh setOrder({order}), size factor {factor}"),
            Command::new(&python)
                .arg(&script)
                .args(["scale", &order.to_string(), &factor.to_string()])
                .arg(&json),
        )?;
        let gmsh: Value = serde_json::from_str(&std::fs::read_to_string(&json)?)?;
        rows.push(Row { factor, ours, gmsh });
    }
    print_table(&rows, order);

    let torus = out.join("torus.msh");
    run(
        "Gmsh meshes a torus in a box",
        Command::new(&python)
            .arg(&script)
            .args(["torus"])
            .arg(&torus)
            .arg("0.2"),
    )?;
    let torus_geometry = out.join("torus.json");
    std::fs::write(
        &torus_geometry,
        r#"{"entities": [{"name": "torus", "kind": "torus", "center": [0, 0, 0],
 "axis": [0, 0, 1], "major_radius": 2, "minor_radius": 0.5}]}"#,
    )?;
    let first = factors.first().copied().unwrap_or(FACTORS[0]);
    let cases = [
        (
            format!("sphere, factor {first}"),
            out.join(format!("sphere_{first}.msh")),
            root().join("fixtures/sphere/sphere.json"),
            3,
        ),
        ("torus".to_string(), torus, torus_geometry, 4),
        (
            "boundary layers".to_string(),
            root().join("fixtures/cad/sphere_layers.msh"),
            root().join("fixtures/cad/sphere_layers.json"),
            4,
        ),
    ];
    region_check(&hocurve, &out, &cases)
}

/// Curves each case with the default active region and with the whole mesh, prints both
/// and fails unless the active region's min Ĩ is within 1 % of the whole solve's.
fn region_check(
    hocurve: &std::path::Path,
    out: &std::path::Path,
    cases: &[(String, std::path::PathBuf, std::path::PathBuf, usize)],
) -> Result<()> {
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    let curve = |name: &str,
                 mesh: &std::path::Path,
                 geometry: &std::path::Path,
                 p: usize,
                 region: &str|
     -> Result<Value> {
        let report = out.join(format!(
            "region_{}_{region}.json",
            name.replace([' ', ','], "_")
        ));
        let _ = std::fs::remove_file(&report);
        run(
            &format!("hocurve curve {name}, p = {p}, --solve-region {region}"),
            Command::new(hocurve)
                .arg("curve")
                .arg(mesh)
                .args([
                    "--order",
                    &p.to_string(),
                    "--solve-region",
                    region,
                    "--geometry",
                ])
                .arg(geometry)
                .arg("-o")
                .arg(out.join("region.msh"))
                .arg("--report")
                .arg(&report),
        )?;
        Ok(serde_json::from_str(&std::fs::read_to_string(&report)?)?)
    };
    let mut rows = Vec::new();
    for (name, mesh, geometry, p) in cases {
        let whole = curve(name, mesh, geometry, *p, "whole")?;
        let active = curve(name, mesh, geometry, *p, "active")?;
        rows.push((name, *p, whole, active));
    }
    println!();
    println!("active region (default) against the whole-mesh solve: min Ĩ at the quadrature points (and certified lower bound)");
    println!(
        "{:<22} {:>2} {:>7} {:>7} {:>6} | {:>15} {:>15} | {:>15} {:>15} | {:>7} {:>7}",
        "case",
        "p",
        "tets",
        "region",
        "solves",
        "Ĩ whole",
        "Ĩ active",
        "bound whole",
        "bound active",
        "t whole",
        "t active"
    );
    let mut failures = Vec::new();
    for (name, p, whole, active) in &rows {
        let (iw, ia) = (
            f(&whole["min_scaled_jacobian"]),
            f(&active["min_scaled_jacobian"]),
        );
        let (bw, ba) = (
            f(&whole["min_scaled_jacobian_lower_bound"]),
            f(&active["min_scaled_jacobian_lower_bound"]),
        );
        println!(
            "{:<22} {:>2} {:>7} {:>7} {:>6} | {:>15.6} {:>15.6} | {:>15.6} {:>15.6} | {:>7.2} {:>7.2}",
            name,
            p,
            whole["elements"].as_u64().unwrap_or(0),
            active["solve_cells"].as_u64().unwrap_or(0),
            active["elastic_solves"].as_u64().unwrap_or(0),
            iw,
            ia,
            bw,
            ba,
            f(&whole["timings"]["total"]),
            f(&active["timings"]["total"]),
        );
        let within = |a: f64, w: f64| a >= w - 0.01 * w.abs();
        if !(within(ia, iw) && within(ba, bw)) || active["invalid_elements"].as_u64() != Some(0) {
            failures.push(name.as_str());
        }
    }
    if !failures.is_empty() {
        bail!("the active region's min Ĩ is not within 1 % of the whole solve's: {failures:?}");
    }
    println!("min Ĩ of the active region within 1 % of the whole solve's on every case (region = cells solved; the whole mesh where the region missed its cutoff)");
    Ok(())
}

fn print_table(rows: &[Row], order: usize) {
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    println!();
    println!("sphere in a box at p = {order}: hocurve (default options) and Gmsh's setOrder, seconds and MB");
    println!(
        "{:>6} {:>8} {:>9} | {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>7} {:>5} {:>7} | {:>7} {:>7} | {:>6}",
        "factor", "tets", "dofs", "read", "nodes", "bound", "assem", "setup", "iters", "qual", "write", "its",
        "total", "I/O%", "peak", "g.proj", "g.peak", "ratio"
    );
    let mut fit = Vec::new();
    for row in rows {
        let tets = f(&row.gmsh["elements"]);
        let g_time = f(&row.gmsh["set_order_seconds"]);
        let g_peak = f(&row.gmsh["peak_rss_mb"]);
        match &row.ours {
            Ok(r) => {
                let t = &r["timings"];
                let total = f(&t["total"]);
                fit.push((tets.ln(), total.ln()));
                println!(
                    "{:>6} {:>8} {:>9} | {:>6.2} {:>6.2} {:>6.2} {:>6.2} {:>6.2} {:>6.2} {:>6.2} {:>6.2} {:>6} {:>7.2} {:>5.1} {:>7.0} | {:>7.2} {:>7.0} | {:>6.1}",
                    row.factor,
                    tets,
                    r["dofs"].as_u64().unwrap_or(0),
                    f(&t["read"]),
                    f(&t["high_order_nodes"]) + f(&t["association"]),
                    f(&t["boundary_nodes"]),
                    f(&t["assembly"]),
                    f(&t["solve_setup"]),
                    f(&t["solve_iterations"]),
                    f(&t["quality"]),
                    f(&t["write"]),
                    r["iterations"].as_u64().unwrap_or(0),
                    total,
                    100.0 * (f(&t["read"]) + f(&t["write"])) / total,
                    f(&r["peak_memory_mb"]),
                    g_time,
                    g_peak,
                    total / g_time,
                );
            }
            Err(reason) => println!(
                "{:>6} {:>8} {:>9} | not run: {reason} | {:>7.2} {:>7.0} |",
                row.factor, tets, "-", g_time, g_peak
            ),
        }
    }
    println!("nodes = order-p nodes and boundary association; bound = boundary nodes; assem = stiffness assembly;");
    println!("setup = p-multigrid set-up (coarse levels, p = 1 factorisation, smoothers); iters = CG iterations (its of them);");
    println!("qual = quality and Bézier certification; write = binary MSH 4.1 out; total = the whole process (read to write);");
    println!("I/O% = (read + write) / total; peak = peak resident memory;");
    println!("g.proj = Gmsh's setOrder (projection, no optimisation) on the same mesh, g.peak its process's peak; ratio = total / g.proj.");
    if fit.len() >= 2 {
        let n = fit.len() as f64;
        let (mx, my) = (
            fit.iter().map(|p| p.0).sum::<f64>() / n,
            fit.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let sxy: f64 = fit.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let sxx: f64 = fit.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
        println!(
            "slope of log(total time) against log(elements): {:.2} (1 = linear)",
            sxy / sxx
        );
    }
}
