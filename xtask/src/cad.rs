//! The CAD families of issue 18 (`fixtures/cad/`, made by `fixtures/make_cad_fixtures.py`
//! with Gmsh's OpenCASCADE kernel): curved with the **default options** of `hocurve curve`
//! at p = 2..5 and checked by Gmsh, not by us:
//! - the command exits 0 (it exits non-zero when an element is not certified valid);
//! - Gmsh's `getJacobians` at the degree-2p Gauss points and at the nodes finds no
//!   det J ≤ 0, and every written node of the curved group lies on the geometry to 1e-10 of
//!   the model size (`xtask/scripts/check_cad.py`; IGES distances by OpenCASCADE);
//! - the certified min Ĩ is at least that of `--min-angle 0` (the minimum-angle correction
//!   of Fig. 4 must not make things worse).
//!
//! `verify` runs the sphere families (poles and seams of OpenCASCADE's sphere, JSON and
//! IGES geometry), the coarse boundary-layer tets (stretch 260) and the thin layers on a
//! very coarse sphere, which only the repair (untangling) makes valid, and the extruded
//! boundary layer of hexahedra and prisms around a cylinder (its end planes slide by
//! default; det J by VTK's Lagrange cells from p = 3, which Gmsh cannot evaluate), the same
//! split into tetrahedra (p = 2, 3) and its 2D section (p = 2..5), stretch 1200 to 2700,
//! and the same three kinds around an extruded NACA 0012 section (IGES, stretch up to
//! 5000; hexahedra and prisms p = 2..5, tetrahedra p = 2, 3, 2D p = 2..5); `verify --full`
//! adds both sets of tetrahedra at p = 4, 5,
//! the finer boundary layer (stretch 288) and the wing body (trimmed B-spline faces in
//! IGES); both take minutes per order.
//!
//! The models written by OpenCASCADE both as IGES and as STEP are also curved onto the
//! STEP file (the coarse sphere and the 2D section at p = 2..5, the extruded NACA layers at
//! p = 2, checked the same way) and the meshes curved onto the two files are compared node
//! by node (to 1e-9 of the model size, solved directly).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};

use crate::root;

/// One fixture: mesh and geometry under `fixtures/cad/`, and the curved physical group.
struct Case {
    name: &'static str,
    geometry: &'static str,
    group: &'static str,
    full_only: bool,
    /// The orders curved and checked.
    orders: std::ops::RangeInclusive<usize>,
    /// From this order on, det J is checked by VTK's Lagrange cells (`check_vtu.py` on a
    /// `.vtu` of the same run) instead of Gmsh, which cannot evaluate complete prisms of
    /// order ≥ 3 ("FaceClosureFull not implemented for prisms").
    vtk_from: usize,
}

const CASES: [Case; 34] = [
    Case {
        name: "sphere_coarse",
        geometry: "json",
        group: "sphere",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "sphere_coarse",
        geometry: "igs",
        group: "sphere",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "sphere_occ",
        geometry: "json",
        group: "sphere",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "sphere_occ",
        geometry: "igs",
        group: "sphere",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "sphere_layers_coarse",
        geometry: "json",
        group: "sphere",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "sphere_layers_thin",
        geometry: "json",
        group: "sphere",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "sphere_layers",
        geometry: "json",
        group: "sphere",
        full_only: true,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "wing_body",
        geometry: "igs",
        group: "body",
        full_only: true,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // Hexahedra and prisms: det J by Gmsh at p = 2, by VTK from p = 3.
    Case {
        name: "cylinder_layers",
        geometry: "json",
        group: "cylinder",
        full_only: false,
        orders: 2..=5,
        vtk_from: 3,
    },
    // The same layer split into tetrahedra (stretch 2700), and its 2D section (quadrilaterals
    // and triangles, stretch 1200).
    Case {
        name: "cylinder_layers_tets",
        geometry: "json",
        group: "cylinder",
        full_only: false,
        orders: 2..=3,
        vtk_from: usize::MAX,
    },
    Case {
        name: "cylinder_layers_tets",
        geometry: "json",
        group: "cylinder",
        full_only: true,
        orders: 4..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "cylinder_layers_2d",
        geometry: "json",
        group: "cylinder",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // An extruded NACA 0012 section (OpenCASCADE splines, IGES): quadrilaterals in a Gmsh
    // BoundaryLayer field of first height 1e-4 (stretch to 5000), a fan at the sharp
    // trailing edge, 12 wall edges a side; as hexahedra and prisms, as tetrahedra, and 2D.
    Case {
        name: "naca_layers",
        geometry: "igs",
        group: "airfoil",
        full_only: false,
        orders: 2..=5,
        vtk_from: 3,
    },
    Case {
        name: "naca_layers_tets",
        geometry: "igs",
        group: "airfoil",
        full_only: false,
        orders: 2..=3,
        vtk_from: usize::MAX,
    },
    Case {
        name: "naca_layers_tets",
        geometry: "igs",
        group: "airfoil",
        full_only: true,
        orders: 4..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "naca_layers_2d",
        geometry: "igs",
        group: "airfoil",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // Coarse parts with faces bounded by feature curves (hole rims, the pipes' saddle).
    Case {
        name: "plate_holes",
        geometry: "step",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "tee_pipes",
        geometry: "igs",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // A cell at p = 2..5 that only splitting its longest chord certifies.
    Case {
        name: "twisted_loft",
        geometry: "step",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // Quarter-round rims of two segments: facets through an arc's ends and middle.
    Case {
        name: "rounded_block",
        geometry: "step",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // Fillets narrower than the mesh: a torus facet crossed by its own curved rim edge.
    Case {
        name: "filleted_boss",
        geometry: "step",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // A fillet's B-spline meeting a sphere only to the STEP file's uncertainty.
    Case {
        name: "sphere_on_block",
        geometry: "step",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // Fillets (tori) touching a cone: facets across the top fillet that fold unless their
    // curved edge is split on the geometry.
    Case {
        name: "cone_plate",
        geometry: "step",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // An assembly whose parts touch: coincident faces of different parts, coaxial bores.
    Case {
        name: "bolted_plate",
        geometry: "step",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // Parts that interfere (a pin through a plate's hole and a collar's solid), Gmsh's
    // default sizing: rim splits that fold a pin's cell together.
    Case {
        name: "pinned_plate",
        geometry: "step",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // A rod of two half-cylinder faces with a handful of vertices round it: diameters
    // opposite doubly curved corners, split on the geometry.
    Case {
        name: "coarse_rod",
        geometry: "step",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // A slot whose top rim is filleted: corners whose three edges lie on the fillet and
    // the face it runs into, flat once curved, split first.
    Case {
        name: "filleted_slot",
        geometry: "igs",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // A mesh whose only physical group is the volume: no boundary elements in the file, the
    // boundary to curve is what the cells leave uncovered (checked the same way).
    Case {
        name: "capsule_volume",
        geometry: "step",
        group: "*",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // A 2D face whose normal is -z: its triangles numbered clockwise, written
    // counter-clockwise.
    Case {
        name: "plate_clockwise",
        geometry: "igs",
        group: "wall",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    // The same models from OpenCASCADE's STEP export (fixtures also in IGES above).
    Case {
        name: "sphere_coarse",
        geometry: "step",
        group: "sphere",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "naca_layers_2d",
        geometry: "step",
        group: "airfoil",
        full_only: false,
        orders: 2..=5,
        vtk_from: usize::MAX,
    },
    Case {
        name: "naca_layers",
        geometry: "step",
        group: "airfoil",
        full_only: false,
        orders: 2..=2,
        vtk_from: 3,
    },
    Case {
        name: "naca_layers_tets",
        geometry: "step",
        group: "airfoil",
        full_only: false,
        orders: 2..=2,
        vtk_from: usize::MAX,
    },
    Case {
        name: "wing_body",
        geometry: "step",
        group: "body",
        full_only: true,
        orders: 2..=3,
        vtk_from: usize::MAX,
    },
];

/// Fixtures exported by OpenCASCADE both as IGES and as STEP, with the order at which the
/// two curved meshes are compared, and whether only under `--full`.
const STEP_AND_IGES: [(&str, usize, bool); 6] = [
    ("sphere_occ", 3, false),
    ("plate_holes", 3, false),
    ("naca_layers_2d", 3, false),
    ("naca_layers", 2, false),
    ("naca_layers_tets", 2, false),
    ("wing_body", 2, true),
];

/// Largest difference allowed between the nodes of a mesh curved onto the STEP and onto
/// the IGES export of one model, relative to the mesh's bounding-box diagonal.
/// OpenCASCADE writes IGES numbers with 10 significant digits and STEP with 13: the two
/// NACA sections differ by ~5e-11, which moves arc-length-placed wall nodes by up to 5e-10
/// and, through the wall-normal columns of the hexahedra and prisms, interior nodes by
/// 1.25e-9 in a release build, 5.0e-10 in the test build (the mesh's box diagonal is 5.1).
const STEP_IGES_TOLERANCE: f64 = 1e-9;

/// The mesh curved onto the STEP and onto the IGES export of the same model must be the
/// same to [`STEP_IGES_TOLERANCE`]. Solved directly (`--solver direct`): CG stops at a
/// displacement tolerance (1e-4 of the shortest edge), which two boundary data 1e-10 apart
/// may reach at different iterations.
fn step_matches_iges(hocurve: &Path, out: &Path, full: bool) -> Result<Vec<String>> {
    let mut failures = Vec::new();
    for (name, p, full_only) in STEP_AND_IGES {
        if full_only && !full {
            continue;
        }
        let dir = root().join("fixtures").join("cad");
        let mut nodes = Vec::new();
        for ext in ["igs", "step"] {
            let file = out.join(format!("{name}_{ext}_direct_p{p}.msh"));
            let status = Command::new(hocurve)
                .arg("curve")
                .arg(dir.join(format!("{name}.msh")))
                .args([
                    "-p",
                    &p.to_string(),
                    "--solver",
                    "direct",
                    "-q",
                    "--geometry",
                ])
                .arg(dir.join(format!("{name}.{ext}")))
                .arg("-o")
                .arg(&file)
                .status()?;
            if !status.success() {
                failures.push(format!(
                    "{name} ({ext}, direct solver) p = {p}: hocurve failed"
                ));
                break;
            }
            nodes.push(hocurve_io::read_high_order_msh(&file)?.nodes);
        }
        if let [igs, step] = &nodes[..] {
            let (lo, hi) = igs.iter().fold(
                ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
                |(lo, hi), x| {
                    (
                        [lo[0].min(x[0]), lo[1].min(x[1]), lo[2].min(x[2])],
                        [hi[0].max(x[0]), hi[1].max(x[1]), hi[2].max(x[2])],
                    )
                },
            );
            let size = (0..3).map(|d| (hi[d] - lo[d]).powi(2)).sum::<f64>().sqrt();
            let gap = if igs.len() == step.len() {
                igs.iter()
                    .zip(step)
                    .flat_map(|(a, b)| (0..3).map(move |d| (a[d] - b[d]).abs()))
                    .fold(0.0, f64::max)
            } else {
                f64::INFINITY
            };
            eprintln!(
                "    {name} p = {p}: STEP and IGES curved meshes differ by {gap:.2e} (model size {size:.3})"
            );
            if gap.is_nan() || gap > STEP_IGES_TOLERANCE * size {
                failures.push(format!(
                    "{name} p = {p}: the meshes curved onto STEP and IGES differ by {gap:.2e} (> {STEP_IGES_TOLERANCE:e} × {size:.3})"
                ));
            }
        }
    }
    Ok(failures)
}

/// Curves and checks every case at p = 2..5 (see the module doc).
pub fn cad_families(python: &Path, full: bool) -> Result<()> {
    let hocurve = crate::build_hocurve()?;
    let out = root().join("target").join("cad");
    std::fs::create_dir_all(&out)?;
    let script = root().join("xtask").join("scripts").join("check_cad.py");
    let mut failures = Vec::new();
    for case in CASES.iter().filter(|c| full || !c.full_only) {
        let dir = root().join("fixtures").join("cad");
        let mesh = dir.join(format!("{}.msh", case.name));
        let geometry = dir.join(format!("{}.{}", case.name, case.geometry));
        for p in case.orders.clone() {
            let label = format!("{} ({}) p = {p}", case.name, case.geometry);
            let file = out.join(format!("{}_{}_p{p}.msh", case.name, case.geometry));
            let default = curve(&hocurve, &mesh, &geometry, p, &file, &[])?;
            // Without corrections (Fig. 4) tried, the run without them is the same run.
            let plain = match default {
                Some((_, corrected)) if corrected > 0 => curve(
                    &hocurve,
                    &mesh,
                    &geometry,
                    p,
                    &out.join("plain.msh"),
                    &["--min-angle", "0"],
                )?,
                _ => None,
            };
            let default = default.map(|(bound, _)| bound);
            let plain = plain.map(|(bound, _)| bound);
            let Some(ours) = default else {
                failures.push(format!("{label}: hocurve curve failed"));
                continue;
            };
            let by_vtk = p >= case.vtk_from;
            let checked = Command::new(python)
                .arg(&script)
                .arg(&file)
                .arg(&geometry)
                .arg(case.group)
                .args(by_vtk.then_some("--distance-only"))
                .output()
                .with_context(|| format!("running {}", script.display()))?;
            let line = String::from_utf8_lossy(&checked.stdout);
            let line = line.lines().last().unwrap_or_default();
            eprintln!("    {label}: certified Ĩ ≥ {ours:.4}; Gmsh: {line}");
            if !checked.status.success() {
                failures.push(format!("{label}: {line}"));
            }
            if by_vtk {
                // The same run written as VTK Lagrange cells, det J by VTK's shape functions.
                let vtu = file.with_extension("vtu");
                let again = curve(&hocurve, &mesh, &geometry, p, &vtu, &[])?;
                let vtk = Command::new(python)
                    .arg(root().join("xtask").join("scripts").join("check_vtu.py"))
                    .arg("--curved")
                    .arg(&vtu)
                    .output()
                    .context("running check_vtu.py")?;
                let text = String::from_utf8_lossy(&vtk.stdout);
                eprintln!(
                    "    {label}: VTK: {}",
                    text.lines().last().unwrap_or_default()
                );
                if again.is_none() || !vtk.status.success() {
                    failures.push(format!("{label}: VTK finds det J ≤ 0: {}", text.trim()));
                }
            }
            // The report describes the written file: its numbers against Gmsh's.
            if let Err(e) = report_matches(&file.with_extension("json"), line) {
                failures.push(format!("{label}: the report does not match Gmsh: {e}"));
            }
            if let Some(plain) = plain {
                if ours < plain - 1e-9 {
                    failures.push(format!(
                        "{label}: certified Ĩ {ours:.4} below the {plain:.4} of --min-angle 0"
                    ));
                }
            }
        }
    }
    failures.extend(step_matches_iges(&hocurve, &out, full)?);
    if !failures.is_empty() {
        bail!("CAD families:\n  {}", failures.join("\n  "));
    }
    Ok(())
}

/// Checks the report of a run against Gmsh's evaluation of the written file (the JSON
/// line of `check_cad.py`): same element count; Gmsh's sampled Ĩ at least the certified
/// lower bound (a sample of min det J / max det J cannot be below a bound of the true
/// ratio); the same largest distance of a curved-boundary node from the geometry, to 1e-10
/// of the model size.
fn report_matches(report: &Path, gmsh: &str) -> Result<()> {
    let ours: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(report)?)?;
    let theirs: serde_json::Value = serde_json::from_str(gmsh)?;
    let number =
        |v: &serde_json::Value, key: &str| v[key].as_f64().with_context(|| format!("no {key}"));
    let elements = (number(&ours, "elements")?, number(&theirs, "elements")?);
    if elements.0 != elements.1 {
        bail!(
            "{} elements in the report, {} in the file",
            elements.0,
            elements.1
        );
    }
    let bound = number(&ours, "min_scaled_jacobian_lower_bound")?;
    // Null when Gmsh could not evaluate det J (`--distance-only`). Gmsh's own round-off
    // on the thinnest cells is ~1e-8: on the NACA section's trailing-edge fan (edges 1e-4
    // at x = 1, p = 5) it samples Ĩ 1.3e-8 below the 0.43478261 of that straight cell.
    if let Some(sampled) = theirs["min_scaled_jacobian"].as_f64() {
        if sampled < bound - 1e-7 {
            bail!("Gmsh samples Ĩ = {sampled:.6} below the certified bound {bound:.6}");
        }
    }
    let size = number(&theirs, "size")?;
    let (distance, measured) = (
        number(&ours, "max_geometry_distance")?,
        number(&theirs, "max_distance")?,
    );
    // Gmsh measures each node against its nearest face; we measure it against every face
    // it lies on. The two agree where faces meet; on the edges of faces the file says
    // meet only to its uncertainty (`max_seam_gap` > 0), a node on one face is ours the
    // gap away from the other: then Gmsh's may only be smaller.
    let gap = number(&ours, "max_seam_gap")?;
    let agree = if gap > 0.0 {
        measured <= distance + 1e-10 * size
    } else {
        (distance - measured).abs() <= 1e-10 * size
    };
    if !agree {
        bail!("max_geometry_distance {distance:.3e} (seam gap {gap:.1e}), Gmsh measures {measured:.3e}");
    }
    Ok(())
}

/// Runs `hocurve curve` with the default options plus `extra`; the certified lower bound of
/// Ĩ and the number of corrected edges (kept or undone) from its report, or None when it
/// exits non-zero.
fn curve(
    hocurve: &PathBuf,
    mesh: &Path,
    geometry: &Path,
    p: usize,
    file: &Path,
    extra: &[&str],
) -> Result<Option<(f64, u64)>> {
    let report = file.with_extension("json");
    let output = Command::new(hocurve)
        .arg("curve")
        .arg(mesh)
        .args(["-p", &p.to_string(), "--geometry"])
        .arg(geometry)
        .arg("-o")
        .arg(file)
        .arg("--report")
        .arg(&report)
        .args(extra)
        .output()
        .with_context(|| format!("running {}", hocurve.display()))?;
    if !output.status.success() {
        eprintln!(
            "    hocurve curve {} -p {p} {extra:?}: {}",
            mesh.display(),
            String::from_utf8_lossy(&output.stderr).trim()
        );
        return Ok(None);
    }
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&report).with_context(|| format!("{}", report.display()))?,
    )?;
    let bound = json["min_scaled_jacobian_lower_bound"]
        .as_f64()
        .context("the report has no certified bound")?;
    // Corrections kept or tried and undone: either way the run differs from --min-angle 0.
    let count = |key: &str| json[key].as_u64().unwrap_or(0);
    Ok(Some((
        bound,
        count("corrected_edges") + count("corrections_undone"),
    )))
}
