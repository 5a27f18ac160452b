//! Project automation: `cargo xtask verify` is the regression gate run by CI (`.ci/run`).
//!
//! It runs, in order, stopping at the first failure with a summary of the steps and their
//! times:
//! 1. `cargo fmt --check` and `cargo clippy` (warnings are errors);
//! 2. the Python environment of step 6 (so that `tests/io_foreign_readers.rs` reads real
//!    Gmsh/VTK files), then `cargo test --workspace` (with `HOCURVE_SNAPSHOT_QUICK=1`: the
//!    slow sphere snapshots are left to step 3);
//! 3. the golden snapshot suite (`tests/snapshots.rs`: NACA0012 at p = 1..5, triangles and
//!    quadrilaterals, the sphere at p = 2..4, Fekete and equispaced; curved mesh as ASCII
//!    `.vtu` and quality summary), once with `RAYON_NUM_THREADS=1` and once with `=2`;
//!    then the sphere at p = 2..5 end to end (`tests/curving.rs`, ignored by plain
//!    `cargo test`: boundary nodes on the sphere, no invalid element, volume error falling);
//! 4. the CAD families (`xtask/src/cad.rs`): OpenCASCADE spheres with pole and seam
//!    vertices curved with the default options at p = 2..5, checked by Gmsh (no det J ≤ 0,
//!    written nodes on the geometry to 1e-10); `--full` adds the IGES wing body;
//! 5. the paper reproduction: Sect. 5.1's NACA0012 figures beside ours (fails if our quality
//!    is below the paper's) and the Fig. 12b interpolation tables;
//! 6. the interoperability checks, in which the real VTK and Gmsh Python packages (in
//!    `target/pyenv`, created if missing; skipped loudly only under `--offline`) read the
//!    meshes `hocurve` writes and measure them with their own shape functions: straight
//!    samples and fixtures, the committed snapshots (VTK: det J > 0, volume of the
//!    sphere-in-box at p = 4 equal to 216 − 4π/3 to 1e-6), curved `.msh` files of every
//!    element type at p = 1..5 (Gmsh: det J > 0 and equal to ours); the solvers' readers
//!    (MFEM and PyFR, Python packages in the same environment) on curved meshes written as
//!    MSH 4.1 and 2.2, ASCII and binary: volumes equal to VTK's on the compressed `.vtu`.
//!
//! `cargo xtask verify --review` first re-records the snapshots for review (`cargo insta
//! review` if installed). `cargo xtask bench` times our curving of the sphere against Gmsh's
//! (`xtask/src/bench.rs`); `cargo xtask bench --scale` curves sphere meshes of about 100 k,
//! 280 k and 950 k tetrahedra at p = 3 beside Gmsh's projection (`xtask/src/scale.rs`);
//! `cargo xtask bench --layers` times the boundary-layer meshes (`xtask/src/layers.rs`);
//! `cargo xtask bench --high-order` curves the coarse sphere at p = 2..10 beside Gmsh's
//! projection (`xtask/src/bench.rs`).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};

mod bench;
mod cad;
mod curved_interop;
mod layers;
mod paper;
mod scale;
mod snapshots;

/// The tasks and their options, printed by `cargo xtask --help` (and on a wrong task).
const USAGE: &str = "\
usage: cargo xtask <task> [options]

tasks:
  verify [--offline] [--skip-lint] [--review] [--full]
                      the regression gate CI runs (.ci/run): fmt, clippy, tests, snapshots,
                      CAD families, paper reproduction, interoperability; --full adds the
                      large cases, --review re-records the snapshots, --offline skips what
                      needs PyPI (loudly)
  cad [--full]        the CAD families curved at p = 2..5, checked by Gmsh and OpenCASCADE
  interop [--offline] the real VTK, Gmsh, MFEM and PyFR read what hocurve writes
  curved-interop [--offline] [--full]
                      Gmsh's Jacobians on our curved .msh files equal ours
  snapshots           the golden snapshot suite (NACA0012, sphere)
  paper               the paper's Sect. 5.1 table and Fig. 12b study beside ours
  interpolation       the Fig. 12b interpolation tables
  bench [--orders 2,3,4,5] [--gmsh-timeout 120]
                      our curving of the sphere against Gmsh's projection and elastic curving
  bench --scale       sphere meshes of ~100 k, 300 k and 1 M tetrahedra at p = 3 against Gmsh
  bench --layers      the boundary-layer meshes
  bench --high-order [--orders 2,..,10]
                      the coarse sphere at p = 2..10 against Gmsh's projection: time,
                      memory, certification, min Ĩ, volume error
  help, --help, -h    this text
";

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args
        .iter()
        .any(|a| matches!(a.as_str(), "--help" | "-h" | "help"))
    {
        print!("{USAGE}");
        return Ok(());
    }
    match args.first().map(String::as_str) {
        Some("verify") => verify(&args[1..]),
        Some("interop") => interop(&args[1..]),
        Some("interpolation") => interpolation_table(),
        Some("snapshots") => snapshots::snapshot_suite(),
        Some("curved-interop") => match python_env(args.iter().any(|a| a == "--offline"))? {
            Some(python) => {
                curved_interop::curved_interop(&python, args.iter().any(|a| a == "--full"))
            }
            None => Ok(()),
        },
        Some("paper") => paper(),
        Some("cad") => match python_env(args.iter().any(|a| a == "--offline"))? {
            Some(python) => cad::cad_families(&python, args.iter().any(|a| a == "--full")),
            None => Ok(()),
        },
        Some("bench") if args[1..].iter().any(|a| a == "--scale") => scale::scale(&args[1..]),
        Some("bench") if args[1..].iter().any(|a| a == "--layers") => layers::layers(),
        Some("bench") if args[1..].iter().any(|a| a == "--high-order") => {
            bench::high_order(&args[1..])
        }
        Some("bench") => bench::bench(&args[1..]),
        _ => {
            eprint!("{USAGE}");
            bail!("unknown or missing task (cargo xtask --help lists them)")
        }
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn cargo() -> Command {
    let mut cmd = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    cmd.current_dir(root());
    cmd
}

/// Cargo's target directory (`CARGO_TARGET_DIR`, else `target/`).
fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(|d| root().join(d))
        .unwrap_or_else(|| root().join("target"))
}

fn run(step: &str, cmd: &mut Command) -> Result<()> {
    eprintln!("==> {step}");
    let start = std::time::Instant::now();
    let status = cmd
        .status()
        .with_context(|| format!("{step}: could not start {cmd:?}"))?;
    eprintln!("    ({step}: {:.0} s)", start.elapsed().as_secs_f64());
    if !status.success() {
        bail!("{step} failed ({status})");
    }
    Ok(())
}

/// Runs one step of `verify`, recording its time and outcome in `log`.
fn step(
    log: &mut Vec<(String, f64, bool)>,
    name: &str,
    f: impl FnOnce() -> Result<()>,
) -> Result<()> {
    let start = std::time::Instant::now();
    let result = f();
    log.push((
        name.to_string(),
        start.elapsed().as_secs_f64(),
        result.is_ok(),
    ));
    result
}

fn print_summary(log: &[(String, f64, bool)]) {
    eprintln!("==> verify summary");
    for (name, seconds, ok) in log {
        let status = if *ok { "ok" } else { "FAILED" };
        eprintln!("    {status:<7}{seconds:>7.0} s  {name}");
    }
}

/// The paper reproduction: every table is printed before a failure is reported.
fn paper() -> Result<()> {
    let table = paper::paper_table();
    interpolation_table()?;
    paper::naca_interpolation_table()?;
    table
}

fn verify(args: &[String]) -> Result<()> {
    let skip_lint = args.iter().any(|a| a == "--skip-lint");
    let mut log = Vec::new();
    let result = verify_steps(args, skip_lint, &mut log);
    print_summary(&log);
    match result {
        Ok(()) => {
            eprintln!("==> verify: all steps passed");
            Ok(())
        }
        Err(e) => Err(e.context("verify stopped at the first failure (summary above)")),
    }
}

fn verify_steps(
    args: &[String],
    skip_lint: bool,
    log: &mut Vec<(String, f64, bool)>,
) -> Result<()> {
    if args.iter().any(|a| a == "--review") {
        step(log, "snapshot review", snapshots::review)?;
    }
    if !skip_lint {
        step(log, "cargo fmt --check", || {
            run(
                "cargo fmt --check",
                cargo().args(["fmt", "--all", "--", "--check"]),
            )
        })?;
        step(log, "cargo clippy", || {
            // In a target folder of its own: clippy sets RUSTC_WORKSPACE_WRAPPER, which build
            // scripts may watch; it must not invalidate the build the tests and xtask share.
            run(
                "cargo clippy",
                cargo()
                    .env("CARGO_TARGET_DIR", target_dir().join("clippy"))
                    .args([
                        "clippy",
                        "--workspace",
                        "--all-targets",
                        "--",
                        "-D",
                        "warnings",
                    ]),
            )
        })?;
    }
    // The Python environment first: `tests/io_foreign_readers.rs` reads Gmsh- and
    // VTK-written meshes made with it, and skips (loudly, but passing) without it.
    let offline = args.iter().any(|a| a == "--offline");
    step(log, "Python environment (vtk, gmsh)", || {
        python_env(offline).map(|_| ())
    })?;
    step(log, "cargo test --workspace", || {
        run(
            "cargo test (sphere snapshots left to the snapshot suite)",
            cargo()
                .env("HOCURVE_SNAPSHOT_QUICK", "1")
                .args(["test", "--workspace"]),
        )
    })?;
    step(
        log,
        "snapshot suite (1 and 2 threads)",
        snapshots::snapshot_suite,
    )?;
    step(
        log,
        "sphere p = 2..5 end to end (ignored in cargo test)",
        || {
            run(
                "cargo test --test curving -- --ignored",
                // --workspace: the features of the test build, whose crates it reuses.
                cargo().args([
                    "test",
                    "--workspace",
                    "--test",
                    "curving",
                    "--",
                    "--ignored",
                    "--nocapture",
                ]),
            )
        },
    )?;
    step(
        log,
        "CAD families p = 2..5 (Gmsh checks)",
        || match python_env(offline)? {
            Some(python) => cad::cad_families(&python, args.iter().any(|a| a == "--full")),
            None => Ok(()),
        },
    )?;
    step(log, "paper reproduction", paper)?;
    step(log, "interoperability (VTK, Gmsh)", || interop(args))?;
    Ok(())
}

/// The paper's Fig. 12b study: L2 error of the order-p Fekete interpolant of
/// f = x cos y + y sin x on straight meshes of the unit square (50 triangles, 49 quads).
/// The test `tests/interpolation.rs` asserts the exponential decay; this prints the table.
fn interpolation_table() -> Result<()> {
    use hocurve::interpolation::{interpolation_l2_error, paper_test_function, unit_square_mesh};
    use hocurve::mesh::{HighOrderMesh, Shape};
    use hocurve::nodes::NodeFamily;
    eprintln!("==> interpolation error (paper Fig. 12b), Fekete nodes");
    println!(
        "{:<14} {:>2} {:>10} {:>12}",
        "mesh", "p", "sqrt(ndof)", "L2 error"
    );
    for (kind, n, label) in [
        (Shape::Tri, 5, "50 triangles"),
        (Shape::Quad, 7, "49 quads"),
    ] {
        let mesh = unit_square_mesh(n, kind);
        for p in 1..=7 {
            let ho = HighOrderMesh::from_linear(&mesh, p, NodeFamily::Fekete)?;
            let e = interpolation_l2_error(&ho, paper_test_function)?;
            let root_ndof = (ho.nodes.len() as f64).sqrt();
            println!("{label:<14} {p:>2} {root_ndof:>10.2} {e:>12.3e}");
        }
    }
    Ok(())
}

/// The Python interpreter of the virtualenv under `target/`, created with `vtk` and `gmsh`
/// from PyPI when missing. `None` (with a loud message) only when `--offline` and absent.
fn python_env(offline: bool) -> Result<Option<PathBuf>> {
    let venv = root().join("target").join("pyenv");
    let python = venv.join("bin").join("python");
    let ready = |py: &Path| {
        Command::new(py)
            .args(["-c", "import vtk, gmsh, numpy, h5py, mfem.ser, pyfr"])
            .output()
            .map(|o| o.status.success())
            .unwrap_or(false)
    };
    if python.exists() && ready(&python) {
        return Ok(Some(python));
    }
    if offline {
        eprintln!("!!! --offline and no Python environment with vtk and gmsh at {}: the VTK/Gmsh interoperability checks are SKIPPED", venv.display());
        return Ok(None);
    }
    if !python.exists() {
        run(
            "create Python virtualenv",
            Command::new("python3").args(["-m", "venv"]).arg(&venv),
        )?;
    }
    // The readers our users pair us with: VTK and Gmsh, and the solvers MFEM and PyFR
    // (whose `pyfr import` needs an MPI library: mpich's wheel).
    run(
        "install vtk, gmsh, numpy, mfem, pyfr, mpich",
        Command::new(&python).args([
            "-m", "pip", "install", "--quiet", "vtk", "gmsh", "numpy", "h5py", "mfem", "pyfr",
            "mpich",
        ]),
    )?;
    if !ready(&python) {
        bail!("the Python packages vtk, gmsh, mfem and pyfr were installed but do not import; see the messages above");
    }
    Ok(Some(python))
}

/// The interoperability checks: the real VTK and Gmsh read what `hocurve` writes and, with
/// their own shape functions at Gauss points, find det J positive and constant in every
/// straight cell and the total volume (area) equal to the linear mesh's. Run on the sample
/// meshes of `crates/io/tests/interop.rs` (every element type, every face orientation,
/// p = 1..6) and on the fixtures written by the `hocurve` binary.
fn interop(args: &[String]) -> Result<()> {
    let offline = args.iter().any(|a| a == "--offline");
    let Some(python) = python_env(offline)? else {
        return Ok(());
    };
    let out = root().join("target").join("interop");
    let samples = out.join("samples");
    let fixtures_dir = out.join("fixtures");
    for dir in [&samples, &fixtures_dir] {
        if dir.exists() {
            std::fs::remove_dir_all(dir)?;
        }
        std::fs::create_dir_all(dir)?;
    }
    run(
        "write the interop sample meshes",
        cargo().env("HOCURVE_INTEROP_DIR", &samples).args([
            "test",
            "--workspace",
            "--test",
            "interop",
        ]),
    )?;

    let hocurve = build_hocurve()?;
    let fixtures = [
        ("fixtures/formats/cube_v41_ascii.msh", 6),
        ("fixtures/formats/square_v41_ascii.msh", 6),
        ("fixtures/hybrid/hybrid.msh", 6),
        ("fixtures/quad/naca0012_quads.msh", 6),
        ("fixtures/naca0012/naca0012.msh", 6),
        ("fixtures/sphere/sphere.msh", 4),
    ];
    let mut manifest = String::from("# file\tmeasure of the linear mesh\n");
    let mut files = Vec::new();
    for (fixture, max_order) in fixtures {
        let measure = linear_measure(&root().join(fixture))?;
        let stem = Path::new(fixture)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        for p in 1..=max_order {
            for (ext, nodes) in [
                ("vtu", "equispaced"),
                ("msh", "equispaced"),
                ("vtu", "fekete"),
            ] {
                let name = format!("{stem}_p{p}_{nodes}.{ext}");
                let file = fixtures_dir.join(&name);
                let status = Command::new(&hocurve)
                    .current_dir(root())
                    .args(["curve", fixture, "--straight", "--order", &p.to_string()])
                    .args(["--nodes", nodes, "-o"])
                    .arg(&file)
                    .stdout(std::process::Stdio::null())
                    .status()?;
                if !status.success() {
                    bail!("hocurve curve {fixture} --order {p} --nodes {nodes} failed");
                }
                manifest.push_str(&format!("{name}\t{measure:.17e}\n"));
                files.push(file);
            }
        }
    }
    let fixture_manifest = fixtures_dir.join("expected.tsv");
    std::fs::write(&fixture_manifest, manifest)?;

    let scripts = root().join("xtask").join("scripts");
    let with_ext = |dir: &Path, ext: &str| -> Result<Vec<PathBuf>> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(dir)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == ext))
            .collect();
        v.sort();
        Ok(v)
    };
    // The samples are affine cells (det J constant: strict check); the fixtures' quads and
    // hexes are bilinear/trilinear, whose det J varies, so there the node positions (the
    // straight-sided map), positivity and the total measure are checked.
    for (dir, manifest, mode) in [
        (&samples, samples.join("expected.tsv"), None),
        (
            &fixtures_dir,
            fixture_manifest.clone(),
            Some("--no-constant"),
        ),
    ] {
        for (ext, script, reader) in [
            ("vtu", "check_vtu.py", "VTK"),
            ("msh", "check_msh.py", "Gmsh"),
        ] {
            let files = with_ext(dir, ext)?;
            run(
                &format!(
                    "{reader} reads {} .{ext} files in {}",
                    files.len(),
                    dir.display()
                ),
                Command::new(&python)
                    .arg(scripts.join(script))
                    .args(mode)
                    .arg("--manifest")
                    .arg(&manifest)
                    .args(&files),
            )?;
        }
    }
    curved_interop::curved_interop(&python, args.iter().any(|a| a == "--full"))?;
    solver_readers(&python, &hocurve, &out)
}

/// The solvers' own readers on every MSH variant we write (`scripts/check_clients.py`):
/// curved meshes written as MSH 4.1 and 2.2, ASCII and binary, are read by Gmsh (node
/// coordinates equal to the `.vtu`'s), MFEM and PyFR (ASCII; its reader has no binary),
/// and each volume must equal VTK's on the zlib-compressed `.vtu` to 1e-9.
fn solver_readers(python: &Path, hocurve: &Path, out: &Path) -> Result<()> {
    let dir = out.join("clients");
    if dir.exists() {
        std::fs::remove_dir_all(&dir)?;
    }
    std::fs::create_dir_all(&dir)?;
    let cases = [
        (
            "sphere_tet",
            "fixtures/sphere/sphere.msh",
            "fixtures/sphere/sphere.json",
            3,
        ),
        (
            "hybrid_hex_prism",
            "fixtures/hybrid/hybrid.msh",
            "fixtures/hybrid/hybrid.json",
            2,
        ),
        (
            "naca0012_tri",
            "fixtures/naca0012/naca0012.msh",
            "fixtures/naca0012/naca0012.json",
            3,
        ),
    ];
    for (name, mesh, geometry, p) in cases {
        let mut files = Vec::new();
        let variants: [(&str, &[&str]); 5] = [
            ("z.vtu", &["--compress"]),
            ("v41.msh", &[]),
            ("v22.msh", &["--msh-version", "2.2"]),
            ("v41_bin.msh", &["--binary"]),
            ("v22_bin.msh", &["--msh-version", "2.2", "--binary"]),
        ];
        for (suffix, options) in variants {
            let file = dir.join(format!("{name}_p{p}_{suffix}"));
            let status = Command::new(hocurve)
                .current_dir(root())
                .args([
                    "curve",
                    mesh,
                    "--geometry",
                    geometry,
                    "--order",
                    &p.to_string(),
                ])
                .args(options)
                .arg("-o")
                .arg(&file)
                .stdout(std::process::Stdio::null())
                .status()?;
            if !status.success() {
                bail!("hocurve curve {mesh} --order {p} {options:?} failed");
            }
            files.push(file);
        }
        run(
            &format!("Gmsh, MFEM and PyFR read {name} at p = {p} in every MSH variant"),
            Command::new(python)
                .arg(
                    root()
                        .join("xtask")
                        .join("scripts")
                        .join("check_clients.py"),
                )
                .args(&files),
        )?;
    }
    Ok(())
}

/// Builds the `hocurve` binary the checks run (test profile, the workspace's features: the
/// test build's crates are reused) and returns its path.
fn build_hocurve() -> Result<PathBuf> {
    run(
        "build hocurve",
        cargo().args([
            "build",
            "--profile",
            "test",
            "--workspace",
            "--bin",
            "hocurve",
        ]),
    )?;
    Ok(target_dir().join("debug").join("hocurve"))
}

/// Total volume (3D) or area (2D) of the straight-sided mesh in `path`: Σ_cells Σ_q w_q |det J|
/// with a quadrature exact for the (bi/tri)linear maps' Jacobians.
fn linear_measure(path: &Path) -> Result<f64> {
    use hocurve_nodes::{LagrangeBasis, NodeFamily, QuadratureRule, ReferenceNodes};
    let mesh = hocurve_io::read_msh(path)?;
    let mut total = 0.0;
    let mut cache = std::collections::HashMap::new();
    for cell in &mesh.cells {
        let shape = cell.kind;
        if let std::collections::hash_map::Entry::Vacant(slot) = cache.entry(shape) {
            let basis =
                LagrangeBasis::new(&ReferenceNodes::try_new(shape, 1, NodeFamily::Equispaced)?)?;
            slot.insert((basis, QuadratureRule::new(shape, 4)));
        }
        let (basis, rule) = &cache[&shape];
        let mut grads = vec![[0.0; 3]; basis.len()];
        for (xi, w) in rule.points.iter().zip(&rule.weights) {
            basis.eval_grad(*xi, &mut grads);
            let mut j = [[0.0; 3]; 3];
            for (g, &v) in grads.iter().zip(&cell.vertices) {
                let x = mesh.vertices[v as usize];
                for a in 0..3 {
                    for b in 0..3 {
                        j[a][b] += x[a] * g[b];
                    }
                }
            }
            let det = if mesh.dim == 2 {
                j[0][0] * j[1][1] - j[0][1] * j[1][0]
            } else {
                j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
                    - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
                    + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0])
            };
            total += w * det.abs();
        }
    }
    Ok(total)
}
