//! The `hocurve` command line: a thin layer over the hocurve crates that parses arguments,
//! runs the pipeline and prints a summary. Every error ends the program with exit code 1
//! and one line on stderr.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use hocurve_geodesic::{
    associate_boundary, place_boundary_nodes, AssociationRule, BoundaryNodeStrategy,
};
use hocurve_mesh::HighOrderMesh;
use hocurve_mesh::LinearMesh;
use hocurve_nodes::NodeFamily;
use hocurve_nurbs::GeometryModel;

/// Curved high-order meshes of arbitrary order from straight-sided meshes.
#[derive(Parser)]
#[command(name = "hocurve", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Turn a linear mesh into an order-P mesh and write it (.vtu for ParaView, .msh for Gmsh).
    ///
    /// With `--geometry`, boundary facets are associated with the geometry's curves/surfaces
    /// (by physical-group name for JSON, by proximity for IGES) and their high-order nodes
    /// are placed on it (arc length, geodesics). `--straight` keeps every element straight.
    Curve {
        /// Linear input mesh (Gmsh MSH 4.1 or 2.2, ASCII or binary).
        mesh: PathBuf,
        /// Polynomial order P of the output mesh (1 = linear).
        #[arg(short = 'p', long, value_parser = clap::value_parser!(u32).range(1..=20))]
        order: u32,
        /// Nodal distribution on the reference elements: fekete, gll, warp-blend or
        /// equispaced. Output files always hold equispaced nodes (what VTK and Gmsh assume);
        /// the distribution decides where the mesh is sampled and, later, curved.
        #[arg(long, default_value = "fekete")]
        nodes: NodeFamily,
        /// Keep the elements straight-sided (no geometry, no curving).
        #[arg(long, conflicts_with = "geometry")]
        straight: bool,
        /// Geometry to curve onto: JSON (analytic shapes, NACA airfoils, NURBS; see README)
        /// or IGES (.igs/.iges).
        #[arg(short, long)]
        geometry: Option<PathBuf>,
        /// Largest distance (in mesh units) of a boundary vertex from its geometry entity;
        /// default 1e-4 × the mesh's bounding-box diagonal. Facets farther away stay straight.
        #[arg(long)]
        geometry_tolerance: Option<f64>,
        /// Where boundary nodes go: geodesic (the paper's arc-length/geodesic placement) or
        /// projection (closest point of the straight node; the baseline).
        #[arg(long, default_value = "geodesic")]
        boundary_nodes: BoundaryNodeStrategy,
        /// Young's modulus E of the elastic analogy.
        #[arg(long, default_value_t = 10.0)]
        young: f64,
        /// Poisson's ratio ν of the elastic analogy (in (−1, 0.5)).
        #[arg(long, default_value_t = 0.4)]
        poisson: f64,
        /// Move only the boundary nodes onto the geometry (no elastic solve): for looking at
        /// the boundary placement.
        #[arg(long)]
        boundary_only: bool,
        /// Output file: `.vtu` (VTK Lagrange cells) or `.msh` (Gmsh MSH 4.1, high order).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Print what a mesh file holds: dimension, vertices, cells by type, boundary groups.
    Info {
        /// Linear input mesh (Gmsh MSH 4.1 or 2.2, ASCII or binary).
        mesh: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hocurve: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Curve {
            mesh,
            order,
            nodes,
            straight,
            geometry,
            geometry_tolerance,
            boundary_nodes,
            young,
            poisson,
            boundary_only,
            output,
        } => {
            if !straight && geometry.is_none() {
                bail!("give a geometry to curve onto with --geometry FILE (.json or .igs), or pass --straight for the straight-sided order-{order} mesh");
            }
            let start = Instant::now();
            let linear = hocurve_io::read_msh(&mesh)?;
            let mut high_order = HighOrderMesh::from_linear(&linear, order as usize, nodes)
                .with_context(|| format!("{}", mesh.display()))?;
            if let Some(geometry) = geometry {
                curve_boundary(
                    &linear,
                    &mut high_order,
                    &geometry,
                    geometry_tolerance,
                    boundary_nodes,
                    &hocurve_elastic::Material::new(young, poisson)?,
                    boundary_only,
                )?;
            }
            let quality =
                hocurve_quality::assess(&high_order, &hocurve_quality::QualityOptions::default())?;
            print!("{}", quality.summary);
            hocurve_io::write_mesh(&output, &high_order)?;
            println!(
                "{}: {}D, {} cells, order {} ({} nodes): {} nodes, {} boundary facets -> {} ({:.2} s)",
                mesh.display(),
                high_order.dim,
                high_order.cells.len(),
                order,
                nodes,
                high_order.nodes.len(),
                high_order.facets.len(),
                output.display(),
                start.elapsed().as_secs_f64()
            );
            Ok(())
        }
        Command::Info { mesh } => {
            let linear = hocurve_io::read_msh(&mesh)?;
            println!("{}", mesh.display());
            println!("  dimension  {}", linear.dim);
            println!("  vertices   {}", linear.vertices.len());
            let mut by_type = std::collections::BTreeMap::new();
            for c in &linear.cells {
                *by_type.entry(c.kind).or_insert(0usize) += 1;
            }
            for (kind, n) in by_type {
                println!("  {:<10} {n}", kind.name());
            }
            for group in &linear.physical_groups {
                let count = linear
                    .facets
                    .iter()
                    .chain(&linear.cells)
                    .filter(|e| {
                        e.kind.dim() == group.dim
                            && linear
                                .physical_tags(group.dim, e.entity)
                                .contains(&group.tag)
                    })
                    .count();
                println!(
                    "  group {:>3} \"{}\" ({}D): {count} elements",
                    group.tag, group.name, group.dim
                );
            }
            Ok(())
        }
    }
}

/// Reads a geometry file by its extension: `.json` or `.igs`/`.iges`.
fn read_geometry(path: &std::path::Path) -> Result<(GeometryModel, AssociationRule)> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "json" => Ok((
            hocurve_nurbs::read_geometry_json(path)?,
            AssociationRule::NameOnly,
        )),
        "igs" | "iges" => Ok((
            hocurve_nurbs::iges::read_iges_geometry(path)?,
            AssociationRule::NameThenNearest,
        )),
        _ => bail!(
            "{}: unknown geometry format (expected .json, .igs or .iges)",
            path.display()
        ),
    }
}

/// Associates the boundary with the geometry, places the boundary nodes on it and moves the
/// whole mesh by the elastic analogy (or only the boundary nodes).
fn curve_boundary(
    linear: &LinearMesh,
    mesh: &mut HighOrderMesh,
    geometry_path: &std::path::Path,
    tolerance: Option<f64>,
    strategy: BoundaryNodeStrategy,
    material: &hocurve_elastic::Material,
    move_boundary_only: bool,
) -> Result<()> {
    let (geometry, rule) = read_geometry(geometry_path)?;
    let (curves, surfaces) = geometry.counts();
    println!(
        "{}: {curves} curves, {surfaces} surfaces",
        geometry_path.display()
    );
    let association = associate_boundary(linear, &geometry, rule, tolerance)
        .with_context(|| format!("{}", geometry_path.display()))?;
    println!(
        "boundary: {} facets on the geometry ({} by name, {} by proximity), {} left straight (tolerance {:.3e}); vertices moved up to {:.3e}",
        association.by_name + association.by_proximity,
        association.by_name,
        association.by_proximity,
        association.unassociated,
        association.tolerance,
        association.max_vertex_move
    );
    if association.by_name + association.by_proximity == 0 {
        bail!(
            "no boundary facet lies on the geometry: name physical groups like the JSON entities, or check units and --geometry-tolerance"
        );
    }
    let targets = place_boundary_nodes(mesh, &geometry, &association, strategy)?;
    let size = geometry.size().max(f64::MIN_POSITIVE);
    println!(
        "boundary nodes: {} on {} curved facets, max distance from the geometry {:.3e} ({:.1e} of the model size)",
        targets.targets.len(),
        targets.curved_facets,
        targets.max_geometry_distance,
        targets.max_geometry_distance / size
    );
    if targets.max_geometry_distance > 1e-10 * size {
        eprintln!(
            "hocurve: warning: boundary nodes lie up to {:.3e} from the geometry (more than 1e-10 of the model size)",
            targets.max_geometry_distance
        );
    }
    if move_boundary_only {
        for (&n, &x) in &targets.targets {
            mesh.nodes[n as usize] = x;
        }
        return Ok(());
    }
    // The elastic analogy (Sect. 3.2): curved-boundary nodes move to their targets, other
    // boundary nodes stay, and the displacement is carried into the domain.
    let mut bc = hocurve_elastic::BoundaryConditions::default();
    for n in hocurve_elastic::boundary_nodes(mesh)? {
        bc.prescribed.insert(n, [0.0; 3]);
    }
    for (&n, &x) in &targets.targets {
        let x0 = mesh.nodes[n as usize];
        bc.prescribed
            .insert(n, [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]]);
    }
    let solution = hocurve_elastic::solve_displacement(mesh, material, &bc, &Default::default())?;
    println!(
        "elasticity: {} dofs, solver {:?}, {} iterations, relative residual {:.1e} (assembly {:.2} s, solve {:.2} s)",
        solution.dofs,
        solution.solver_used,
        solution.iterations,
        solution.relative_residual,
        solution.timings.assembly,
        solution.timings.solve
    );
    for (x, u) in mesh.nodes.iter_mut().zip(&solution.displacement) {
        for d in 0..3 {
            x[d] += u[d];
        }
    }
    // Boundary targets exactly, not up to the solver's round-off.
    for (&n, &x) in &targets.targets {
        mesh.nodes[n as usize] = x;
    }
    Ok(())
}
