//! `cargo xtask bench`: our elastic curving of the sphere-in-a-box against Gmsh's, on the
//! same linear mesh, in the same run.
//!
//! Gmsh (the Python package in `target/pyenv`) generates the fixture's linear mesh with
//! `fixtures/make_fixtures.py`'s recipe (deterministic), which `hocurve curve` (release
//! build) curves at p = 2..5 with its defaults (geodesic boundary nodes, Fekete nodes,
//! elasticity E = 10, ν = 0.4, quality assessment included). Gmsh, in fresh processes on
//! the same mesh, does plain projection (`setOrder(p)`) and its elastic curving
//! (`setOrder(p)` then `optimize("HighOrderElastic")`, stopped after `--gmsh-timeout`
//! seconds, default 120). All three high-order meshes are measured by the same script
//! (`scripts/bench_gmsh.py`, with Gmsh's shape functions): the paper's scaled Jacobian at
//! degree-2p Gauss points and Gmsh's own minSJ. Target: ours ≤ 2× Gmsh's projection time
//! with a better min scaled Jacobian; both times the best of [`BEST_OF`] runs.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use serde_json::Value;

use crate::{cargo, python_env, root, run, target_dir};

/// Gmsh's outcome for one order and mode (None when stopped by the time limit).
type GmshRun = Option<Value>;

pub fn bench(args: &[String]) -> Result<()> {
    let mut orders = vec![2, 3, 4, 5];
    let mut timeout = 120.0;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--orders" => orders = list_argument(it.next(), "--orders", "2,3")?,
            "--gmsh-timeout" => {
                timeout = it
                    .next()
                    .context("--gmsh-timeout needs seconds")?
                    .parse()
                    .context("--gmsh-timeout: a number of seconds")?;
            }
            other => bail!("bench: unknown argument {other}"),
        }
    }
    let BenchSetup {
        python,
        hocurve,
        out,
        script,
    } = bench_setup("bench")?;
    let linear = out.join("sphere.msh");
    run(
        "Gmsh meshes the sphere-in-a-box (fixtures/make_fixtures.py)",
        Command::new(&python).arg(&script).arg("mesh").arg(&linear),
    )?;
    let same = std::fs::read(&linear)? == std::fs::read(root().join("fixtures/sphere/sphere.msh"))?;
    eprintln!(
        "    the linear mesh is {}byte-identical to fixtures/sphere/sphere.msh",
        if same { "" } else { "NOT " }
    );

    let mut rows = Vec::new();
    for &p in &orders {
        let ours_msh = out.join(format!("hocurve_p{p}.msh"));
        let report = out.join(format!("hocurve_p{p}.json"));
        // Single timings of the same run spread by up to 20 % on this shared machine: the
        // report of the fastest of BEST_OF runs (the output is the same every run), and
        // Gmsh's fastest projection likewise, the two sides taking turns so that load
        // coming in bursts falls on both.
        let mut ours: Option<Value> = None;
        let mut project = None;
        for _ in 0..BEST_OF {
            run(
                &format!("hocurve curve, p = {p}"),
                Command::new(&hocurve)
                    .current_dir(root())
                    .arg("curve")
                    .arg(&linear)
                    .args(["--order", &p.to_string()])
                    .args(["--geometry", "fixtures/sphere/sphere.json", "-o"])
                    .arg(&ours_msh)
                    .arg("--report")
                    .arg(&report)
                    .stdout(std::process::Stdio::null()),
            )?;
            let this: Value = serde_json::from_str(&std::fs::read_to_string(&report)?)?;
            if ours
                .as_ref()
                .is_none_or(|best| curving_seconds(&this) < curving_seconds(best))
            {
                ours = Some(this);
            }
            let this = gmsh_run(&python, &script, "project", p, &out, None)?;
            let seconds = |run: &GmshRun| {
                run.as_ref()
                    .and_then(|v| v["set_order_seconds"].as_f64())
                    .unwrap_or(f64::INFINITY)
            };
            if project.is_none() || seconds(&this) < seconds(&project) {
                project = this;
            }
        }
        let Some(ours) = ours else {
            bail!("no hocurve run at p = {p}");
        };
        let measured = out.join(format!("hocurve_p{p}_quality.json"));
        run(
            &format!("Gmsh measures hocurve's p = {p} mesh"),
            Command::new(&python)
                .arg(&script)
                .args(["measure", &p.to_string()])
                .arg(&ours_msh)
                .arg(&measured),
        )?;
        let ours_quality: Value = serde_json::from_str(&std::fs::read_to_string(&measured)?)?;
        let elastic = gmsh_run(&python, &script, "elastic", p, &out, Some(timeout))?;
        rows.push((p, ours, ours_quality, project, elastic));
    }

    println!();
    println!(
        "sphere in a box ({} threads for hocurve; Gmsh threads as reported), seconds",
        rayon_threads()
    );
    println!(
        "{:>2} {:>7} {:>5} {:>7} {:>9} {:>9} | {:>9} {:>9} {:>6} | {:>9} {:>6} | {:>8} {:>8} {:>8} | {:>7} {:>7} {:>7}",
        "p", "dofs", "its", "elast", "ours", "ours tot", "g.proj", "g.elast", "thr", "ours/prj", "≤2×", "Ĩ ours", "Ĩ proj", "Ĩ elast", "SJ ours", "SJ proj", "SJ el."
    );
    let mut all_met = true;
    for (p, ours, ours_quality, project, elastic) in &rows {
        let t = &ours["timings"];
        let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
        let total = f(&t["total"]);
        let curving = curving_seconds(ours);
        let proj_time = project
            .as_ref()
            .map_or(f64::NAN, |v| f(&v["set_order_seconds"]));
        let elastic_time = elastic.as_ref().map_or(f64::NAN, |v| {
            f(&v["set_order_seconds"]) + f(&v["optimize_seconds"])
        });
        let ratio = curving / proj_time;
        let elasticity = f(&t["assembly"]) + f(&t["solve"]);
        let q = |v: &GmshRun, key: &str| v.as_ref().map_or(f64::NAN, |v| f(&v[key]));
        let ours_min = f(&ours_quality["min_scaled_jacobian"]);
        let better = ours_min > q(project, "min_scaled_jacobian");
        let met = ratio <= 2.0 && better;
        all_met &= met;
        let elastic_text = if elastic.is_some() {
            format!("{elastic_time:>9.2}")
        } else {
            format!("{:>9}", format!(">{timeout:.0}"))
        };
        println!(
            "{p:>2} {:>7} {:>5} {elasticity:>7.2} {curving:>9.2} {total:>9.2} | {proj_time:>9.2} {elastic_text} {:>6} | {ratio:>9.2} {:>6} | {ours_min:>8.4} {:>8.4} {:>8.4} | {:>7.3} {:>7.3} {:>7.3}",
            ours["dofs"].as_u64().unwrap_or(0),
            ours["iterations"].as_u64().unwrap_or(0),
            project.as_ref().map_or(String::from("–"), |v| v["threads"].to_string()),
            if met { "yes" } else { "no" },
            q(project, "min_scaled_jacobian"),
            q(elastic, "min_scaled_jacobian"),
            f(&ours_quality["min_sj_gmsh"]),
            q(project, "min_sj_gmsh"),
            q(elastic, "min_sj_gmsh"),
        );
    }
    println!("dofs, its = unknowns and p-multigrid PCG iterations of our elasticity solve; elast = its assembly and solve (set-up included).");
    println!("ours = hocurve's curving (nodes, boundary, elasticity, quality; without reading and writing); ours tot = with them.");
    println!("Ĩ = min det J / max det J at degree-2p Gauss points (paper Eq. 8), SJ = Gmsh's minSJ; both measured by Gmsh on each mesh.");
    println!("Gmsh's \"Gauss2p\" rules are interior (at p = 5 every point is 0.07 from the faces) and overestimate the true minimum: compare within a row.");
    println!(
        "target (≤ 2× Gmsh's projection time, with a better min Ĩ than its projection) {} at every p",
        if all_met { "met" } else { "NOT met" }
    );
    Ok(())
}

/// Seconds of a `hocurve curve` report's curving: the whole run without reading and
/// writing.
fn curving_seconds(report: &Value) -> f64 {
    let t = &report["timings"];
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    f(&t["total"]) - f(&t["read"]) - f(&t["write"])
}

/// What a sphere benchmark runs with: the Python environment, the release `hocurve`, its
/// output directory under `target/` and `scripts/bench_gmsh.py`.
struct BenchSetup {
    python: PathBuf,
    hocurve: PathBuf,
    out: PathBuf,
    script: PathBuf,
}

/// Finds the Python environment, builds `hocurve` (release) and creates `target/<dir>`.
fn bench_setup(dir: &str) -> Result<BenchSetup> {
    let Some(python) = python_env(false)? else {
        bail!("bench needs the Python environment with gmsh");
    };
    run(
        "build hocurve (release)",
        cargo().args(["build", "--release", "-p", "hocurve-cli"]),
    )?;
    let out = root().join("target").join(dir);
    std::fs::create_dir_all(&out)?;
    Ok(BenchSetup {
        python,
        hocurve: target_dir().join("release").join("hocurve"),
        out,
        script: root().join("xtask").join("scripts").join("bench_gmsh.py"),
    })
}

/// A comma-separated list given after `flag` (`example` shows one).
pub(crate) fn list_argument<T: std::str::FromStr>(
    value: Option<&String>,
    flag: &str,
    example: &str,
) -> Result<Vec<T>>
where
    T::Err: std::error::Error + Send + Sync + 'static,
{
    value
        .with_context(|| format!("{flag} needs a list, e.g. {example}"))?
        .split(',')
        .map(|s| s.trim().parse::<T>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("{flag}: a comma-separated list, e.g. {example}"))
}

/// The thread count hocurve runs with (RAYON_NUM_THREADS, else the machine's).
pub(crate) fn rayon_threads() -> String {
    std::env::var("RAYON_NUM_THREADS").unwrap_or_else(|_| {
        std::thread::available_parallelism()
            .map(|n| n.to_string())
            .unwrap_or_else(|_| "?".into())
    })
}

/// Runs `bench_gmsh.py MODE p`; with a limit, stops the process that many seconds after the
/// optimisation started (returns None then).
fn gmsh_run(
    python: &Path,
    script: &Path,
    mode: &str,
    p: usize,
    out: &Path,
    limit: Option<f64>,
) -> Result<GmshRun> {
    let json: PathBuf = out.join(format!("gmsh_{mode}_p{p}.json"));
    let started = PathBuf::from(format!("{}.started", json.display()));
    for f in [&json, &started] {
        let _ = std::fs::remove_file(f);
    }
    eprintln!("==> Gmsh {mode}, p = {p}");
    let mut child = Command::new(python)
        .arg(script)
        .args([mode, &p.to_string()])
        .arg(&json)
        .spawn()
        .context("starting Python")?;
    let mut optimising_since: Option<Instant> = None;
    loop {
        if let Some(status) = child.try_wait()? {
            if !status.success() {
                bail!("Gmsh {mode} at p = {p} failed ({status})");
            }
            break;
        }
        if optimising_since.is_none() && started.exists() {
            optimising_since = Some(Instant::now());
        }
        if let (Some(limit), Some(since)) = (limit, optimising_since) {
            if since.elapsed().as_secs_f64() > limit {
                child.kill()?;
                child.wait()?;
                eprintln!("    stopped after {limit:.0} s of optimisation");
                return Ok(None);
            }
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    Ok(Some(serde_json::from_str(&std::fs::read_to_string(
        &json,
    )?)?))
}

/// Mesh size factor of the coarse sphere-in-a-box of `bench --high-order`: 1 236
/// tetrahedra from the fixture's recipe (the size of issue 23's "coarse sphere").
const COARSE_SIZE_FACTOR: f64 = 1.9;
/// Runs of each side whose best time `bench` and `bench --high-order` report (the latter
/// at p ≤ 8; one above, where a run takes tens of seconds): on this shared 2-core machine
/// single timings of the same p = 6 run spread over ±15 %, and load comes in bursts of
/// seconds — the best of 3 runs of the same binary at p = 4 on the 6 k sphere was 0.45 s
/// in one bench and 0.57 s in the next, minutes apart (session 20).
const BEST_OF: usize = 5;

/// `cargo xtask bench --high-order [--orders 2,..,10]`: the coarse sphere-in-a-box curved
/// by hocurve with its defaults at every order, against Gmsh's plain projection
/// (`setOrder`) of the same linear mesh in the same run: whole-process time and peak
/// memory, invalid elements and min Ĩ (measured by Gmsh on both meshes, degree-2p Gauss
/// points), and the volume error against the exact 6³ − 4π/3 (det J integrated exactly with
/// Gmsh's Jacobians). Targets (issue 23): ours ≤ 2× Gmsh's time and < 1 GB at p = 6..10.
pub fn high_order(args: &[String]) -> Result<()> {
    let mut orders: Vec<usize> = (2..=10).collect();
    let mut it = args.iter().filter(|a| *a != "--high-order");
    while let Some(a) = it.next() {
        match a.as_str() {
            "--orders" => orders = list_argument(it.next(), "--orders", "6,8,10")?,
            other => bail!("bench --high-order: unknown argument {other}"),
        }
    }
    let BenchSetup {
        python,
        hocurve,
        out,
        script,
    } = bench_setup("bench-high-order")?;
    let linear = out.join("sphere_coarse.msh");
    let factor = COARSE_SIZE_FACTOR.to_string();
    run(
        "Gmsh meshes the coarse sphere-in-a-box",
        Command::new(&python)
            .arg(&script)
            .arg("mesh")
            .arg(&linear)
            .arg(&factor),
    )?;
    let exact = 216.0 - 4.0 * std::f64::consts::PI / 3.0;
    let mut rows = Vec::new();
    for &p in &orders {
        let runs = if p <= 8 { BEST_OF } else { 1 };
        let ours_msh = out.join(format!("hocurve_p{p}.msh"));
        let report = out.join(format!("hocurve_p{p}.json"));
        // The same output every run (deterministic); the best time.
        let mut seconds = f64::INFINITY;
        let mut status = None;
        for _ in 0..runs {
            let start = Instant::now();
            let done = Command::new(&hocurve)
                .current_dir(root())
                .arg("curve")
                .arg(&linear)
                .args(["--order", &p.to_string()])
                .args(["--geometry", "fixtures/sphere/sphere.json", "-q", "-o"])
                .arg(&ours_msh)
                .arg("--report")
                .arg(&report)
                .status()
                .context("running hocurve")?;
            seconds = seconds.min(start.elapsed().as_secs_f64());
            status = Some(done);
        }
        let Some(status) = status else {
            bail!("no hocurve run at p = {p}");
        };
        eprintln!("==> hocurve curve, p = {p}: best of {runs}: {seconds:.2} s ({status})");
        let ours: Value = serde_json::from_str(&std::fs::read_to_string(&report)?)?;
        let measured = out.join(format!("hocurve_p{p}_quality.json"));
        run(
            &format!("Gmsh measures hocurve's p = {p} mesh"),
            Command::new(&python)
                .arg(&script)
                .args(["measure", &p.to_string()])
                .arg(&ours_msh)
                .arg(&measured),
        )?;
        let ours_quality: Value = serde_json::from_str(&std::fs::read_to_string(&measured)?)?;
        let gmsh_json = out.join(format!("gmsh_p{p}.json"));
        let mut gmsh = Value::Null;
        let mut best = f64::INFINITY;
        for _ in 0..runs {
            run(
                &format!("Gmsh projects at p = {p}"),
                Command::new(&python)
                    .arg(&script)
                    .args(["high", &p.to_string(), &factor])
                    .arg(&gmsh_json),
            )?;
            gmsh = serde_json::from_str(&std::fs::read_to_string(&gmsh_json)?)?;
            best = best.min(gmsh["set_order_seconds"].as_f64().unwrap_or(f64::INFINITY));
        }
        gmsh["set_order_seconds"] = Value::from(best);
        rows.push((p, seconds, status.success(), ours, ours_quality, gmsh));
    }
    println!();
    println!(
        "coarse sphere in a box ({} tets; {} threads for hocurve, Gmsh threads as reported)",
        rows.first()
            .map_or(0, |r| r.3["elements"].as_u64().unwrap_or(0)),
        rayon_threads()
    );
    println!(
        "{:>2} {:>8} {:>7} {:>7} {:>9} {:>7} {:>7} {:>6} {:>6} | {:>5} {:>5} {:>8} {:>8} {:>9} | {:>9} {:>9}",
        "p", "unknowns", "ours s", "ours MB", "certified", "Gmsh s", "Gmsh MB", "ratio", "met",
        "inv", "g.inv", "Ĩ ours", "Ĩ Gmsh", "Ĩ≥ (cert)", "vol.err", "g.vol.err"
    );
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    let mut all_met = true;
    for (p, seconds, ok, ours, q, gmsh) in &rows {
        let ratio = seconds / f(&gmsh["set_order_seconds"]);
        let peak = f(&ours["peak_memory_mb"]);
        let elements = ours["elements"].as_u64().unwrap_or(0);
        let certified = ours["certified_valid_elements"].as_u64().unwrap_or(0);
        let met = *ok && ratio <= 2.0 && peak < 1024.0 && certified == elements;
        if *p >= 6 {
            all_met &= met;
        }
        println!(
            "{p:>2} {:>8} {seconds:>7.2} {peak:>7.0} {:>9} {:>7.2} {:>7.0} {ratio:>6.2} {:>6} | {:>5} {:>5} {:>8.4} {:>8.4} {:>9.4} | {:>9.1e} {:>9.1e}",
            ours["dofs"].as_u64().unwrap_or(0),
            format!("{certified}/{elements}"),
            f(&gmsh["set_order_seconds"]),
            f(&gmsh["peak_rss_mb"]),
            if met { "yes" } else { "no" },
            q["invalid"].as_u64().unwrap_or(0),
            gmsh["invalid"].as_u64().unwrap_or(0),
            f(&q["min_scaled_jacobian"]),
            f(&gmsh["min_scaled_jacobian"]),
            f(&ours["min_scaled_jacobian_lower_bound"]),
            (f(&q["volume"]) - exact) / exact,
            (f(&gmsh["volume"]) - exact) / exact,
        );
    }
    println!("ours s = the whole hocurve process (read, curve, certify, write .msh); Gmsh s = its setOrder (projection) alone; ratio = ours / Gmsh; each the best of {BEST_OF} runs at p ≤ 8.");
    println!("certified = elements certified det J > 0 everywhere by Bézier bounds; Ĩ≥ (cert) = their certified min scaled Jacobian.");
    println!("inv, Ĩ = invalid elements and min det J / max det J at degree-2p Gauss points, measured by Gmsh on each mesh.");
    println!("vol.err = (V − V_exact) / V_exact, V = ∫ det J integrated exactly (degree 3(p − 1)) with Gmsh's Jacobians.");
    println!(
        "target (p = 6..10: certified, ≤ 2× Gmsh's projection time, < 1 GB) {}",
        if all_met { "met" } else { "NOT met" }
    );
    Ok(())
}
