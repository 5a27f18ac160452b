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
        _ => {
            eprintln!(
                "usage: cargo xtask verify [--offline] [--skip-lint]\n       cargo xtask interop [--offline]"
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
    interop(args)?;
    eprintln!("==> verify: all steps passed");
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

/// Writes every fixture at p = 1..=6 as `.vtu` and `.msh` and has VTK and Gmsh check them:
/// det J constant and positive in every straight cell, total volume equal to the linear
/// mesh's.
fn interop(args: &[String]) -> Result<()> {
    let offline = args.iter().any(|a| a == "--offline");
    let Some(python) = python_env(offline)? else {
        return Ok(());
    };
    run(
        "build hocurve",
        cargo().args(["build", "-p", "hocurve-cli"]),
    )?;
    let hocurve = root().join("target").join("debug").join("hocurve");
    let out = root().join("target").join("interop");
    std::fs::create_dir_all(&out)?;
    let fixtures = [
        ("fixtures/formats/cube_v41_ascii.msh", 6),
        ("fixtures/formats/square_v41_ascii.msh", 6),
        ("fixtures/hybrid/hybrid.msh", 6),
        ("fixtures/quad/naca0012_quads.msh", 6),
        ("fixtures/naca0012/naca0012.msh", 6),
        ("fixtures/sphere/sphere.msh", 3),
    ];
    let mut vtu_files = Vec::new();
    let mut msh_files = Vec::new();
    for (fixture, max_order) in fixtures {
        let stem = Path::new(fixture)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        for p in 1..=max_order {
            for ext in ["vtu", "msh"] {
                let file = out.join(format!("{stem}_p{p}.{ext}"));
                run(
                    &format!("hocurve curve {fixture} --order {p} -> {}", file.display()),
                    Command::new(&hocurve)
                        .current_dir(root())
                        .args([
                            "curve",
                            fixture,
                            "--straight",
                            "--order",
                            &p.to_string(),
                            "-o",
                        ])
                        .arg(&file),
                )?;
                if ext == "vtu" {
                    vtu_files.push(file);
                } else {
                    msh_files.push(file);
                }
            }
        }
    }
    let scripts = root().join("xtask").join("scripts");
    run(
        "VTK reads our .vtu files",
        Command::new(&python)
            .arg(scripts.join("check_vtu.py"))
            .args(&vtu_files),
    )?;
    run(
        "Gmsh reads our .msh files",
        Command::new(&python)
            .arg(scripts.join("check_msh.py"))
            .args(&msh_files),
    )?;
    Ok(())
}
