//! Project automation: `cargo xtask verify` is the regression gate run by CI (`.ci/run`).
//!
//! It runs, in order, stopping at the first failure: `cargo fmt --check`, `cargo clippy`
//! (warnings are errors), `cargo test --workspace`, and the interoperability checks, in which
//! the real VTK and Gmsh Python packages read the meshes `hocurve` writes and measure them
//! with their own shape functions.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("verify") => verify(&args[1..]),
        Some("interop") => interop(&args[1..]),
        Some("interpolation") => interpolation_table(),
        _ => {
            eprintln!(
                "usage: cargo xtask verify [--offline] [--skip-lint]\n       cargo xtask interop [--offline]\n       cargo xtask interpolation"
            );
            bail!("unknown or missing task")
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

fn run(step: &str, cmd: &mut Command) -> Result<()> {
    eprintln!("==> {step}");
    let status = cmd
        .status()
        .with_context(|| format!("{step}: could not start {cmd:?}"))?;
    if !status.success() {
        bail!("{step} failed ({status})");
    }
    Ok(())
}

fn verify(args: &[String]) -> Result<()> {
    let skip_lint = args.iter().any(|a| a == "--skip-lint");
    if !skip_lint {
        run(
            "cargo fmt --check",
            cargo().args(["fmt", "--all", "--", "--check"]),
        )?;
        run(
            "cargo clippy",
            cargo().args([
                "clippy",
                "--workspace",
                "--all-targets",
                "--",
                "-D",
                "warnings",
            ]),
        )?;
    }
    run("cargo test", cargo().args(["test", "--workspace"]))?;
    interpolation_table()?;
    interop(args)?;
    eprintln!("==> verify: all steps passed");
    Ok(())
}

/// The paper's Fig. 12b study: L2 error of the order-p Fekete interpolant of
/// f = x cos y + y sin x on straight meshes of the unit square (50 triangles, 49 quads).
/// The test `tests/interpolation.rs` asserts the exponential decay; this prints the table.
fn interpolation_table() -> Result<()> {
    use hocurve::interpolation::{interpolation_l2_error, paper_test_function, unit_square_mesh};
    use hocurve::mesh::{ElementType, HighOrderMesh};
    use hocurve::nodes::NodeFamily;
    eprintln!("==> interpolation error (paper Fig. 12b), Fekete nodes");
    println!(
        "{:<14} {:>2} {:>10} {:>12}",
        "mesh", "p", "sqrt(ndof)", "L2 error"
    );
    for (kind, n, label) in [
        (ElementType::Tri, 5, "50 triangles"),
        (ElementType::Quad, 7, "49 quads"),
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
            .args(["-c", "import vtk, gmsh, numpy"])
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
    run(
        "install vtk, gmsh, numpy",
        Command::new(&python).args(["-m", "pip", "install", "--quiet", "vtk", "gmsh", "numpy"]),
    )?;
    if !ready(&python) {
        bail!("the Python packages vtk and gmsh were installed but do not import; see the messages above");
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
            "-p",
            "hocurve-io",
            "--test",
            "interop",
        ]),
    )?;

    run(
        "build hocurve",
        cargo().args(["build", "-p", "hocurve-cli"]),
    )?;
    let hocurve = root().join("target").join("debug").join("hocurve");
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
    Ok(())
}

/// Total volume (3D) or area (2D) of the straight-sided mesh in `path`: Σ_cells Σ_q w_q |det J|
/// with a quadrature exact for the (bi/tri)linear maps' Jacobians.
fn linear_measure(path: &Path) -> Result<f64> {
    use hocurve_nodes::{LagrangeBasis, NodeFamily, QuadratureRule, ReferenceNodes};
    let mesh = hocurve_io::read_msh(path)?;
    let mut total = 0.0;
    let mut cache = std::collections::HashMap::new();
    for cell in &mesh.cells {
        let shape = cell.kind.shape()?;
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
