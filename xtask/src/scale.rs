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
    Ok(())
}

fn print_table(rows: &[Row], order: usize) {
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    println!();
    println!("sphere in a box at p = {order}: hocurve (default options) and Gmsh's setOrder, seconds and MB");
    println!(
        "{:>6} {:>8} {:>9} | {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>7} {:>7} | {:>7} {:>7} | {:>6}",
        "factor", "tets", "dofs", "nodes", "bound", "assem", "setup", "iters", "qual", "write", "its",
        "total", "peak", "g.proj", "g.peak", "ratio"
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
                    "{:>6} {:>8} {:>9} | {:>6.2} {:>6.2} {:>6.2} {:>6.2} {:>6.2} {:>6.2} {:>6.2} {:>6} {:>7.2} {:>7.0} | {:>7.2} {:>7.0} | {:>6.1}",
                    row.factor,
                    tets,
                    r["dofs"].as_u64().unwrap_or(0),
                    f(&t["high_order_nodes"]) + f(&t["association"]),
                    f(&t["boundary_nodes"]),
                    f(&t["assembly"]),
                    f(&t["solve_setup"]),
                    f(&t["solve_iterations"]),
                    f(&t["quality"]),
                    f(&t["write"]),
                    r["iterations"].as_u64().unwrap_or(0),
                    total,
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
    println!("qual = quality and Bézier certification; total = the whole process (read to write); peak = peak resident memory;");
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
