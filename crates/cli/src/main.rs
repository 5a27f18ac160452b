//! The `hocurve` command line: a thin layer over the hocurve crates that parses arguments,
//! runs the pipeline ([`hocurve::pipeline::curve_mesh`]) and prints a summary. Every error
//! ends the program with exit code 1 and one line on stderr.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use hocurve::demo::Demo;
use hocurve::pipeline::{curve_mesh, CurveOptions, CurvedMesh, Geometry, Progress};
use hocurve_elastic::{Material, SolveProgress, SolverKind};
use hocurve_geodesic::{AssociationRule, BoundaryNodeStrategy};
use hocurve_io::DataArray;
use hocurve_mesh::LinearMesh;
use hocurve_nodes::NodeFamily;
use hocurve_nurbs::GeometryModel;
use hocurve_quality::{QualitySummary, Sampling};

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
    /// (by physical-group name for JSON, by proximity for IGES), their high-order nodes are
    /// placed on it (arc length, geodesics) and the displacement is carried into the domain
    /// by linear elasticity. `--straight` keeps every element straight.
    Curve {
        /// Linear input mesh (Gmsh MSH 4.1 or 2.2, ASCII or binary).
        mesh: PathBuf,
        /// Polynomial order P of the output mesh (1 = linear).
        #[arg(short = 'p', long, value_parser = clap::value_parser!(u32).range(1..=20))]
        order: u32,
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
        #[command(flatten)]
        method: MethodArgs,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Curve a bundled example (sphere: p = 4, naca0012: p = 5) and print the summary.
    ///
    /// The meshes and geometries are compiled into the program, so this works anywhere.
    Demo {
        /// Which example: sphere or naca0012.
        #[arg(default_value = "sphere")]
        name: Demo,
        /// Order (default: 4 for the sphere, 5 for the NACA0012 airfoil).
        #[arg(short = 'p', long, value_parser = clap::value_parser!(u32).range(1..=20))]
        order: Option<u32>,
        #[command(flatten)]
        method: MethodArgs,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Measure a high-order mesh (.msh from hocurve or Gmsh, .vtu from hocurve or VTK):
    /// scaled Jacobian, validity, stretching.
    Quality {
        /// High-order mesh: Gmsh MSH (4.1 or 2.2) or VTK XML .vtu with Lagrange cells.
        mesh: PathBuf,
        /// Print the summary as JSON (same field names as `curve --report`).
        #[arg(long)]
        json: bool,
        /// Where det J is sampled: the degree-2p quadrature points, the nodes, or both.
        #[arg(long, value_enum, default_value = "quadrature")]
        sample: SampleArg,
        /// Also certify validity by Bézier bounds of det J (valid / invalid / undecided).
        #[arg(long)]
        certify: bool,
        /// Write the scaled-Jacobian histogram (percentage per 0.05 bin) as SVG.
        #[arg(long)]
        histogram: Option<PathBuf>,
        /// Write the stretching histogram as SVG.
        #[arg(long)]
        stretching_histogram: Option<PathBuf>,
    },
    /// Print what a mesh file holds: dimension, vertices, cells by type, boundary groups.
    Info {
        /// Linear input mesh (Gmsh MSH 4.1 or 2.2, ASCII or binary).
        mesh: PathBuf,
    },
}

/// How the mesh is curved (shared by `curve` and `demo`).
#[derive(Args)]
struct MethodArgs {
    /// Nodal distribution on the reference elements: fekete, gll, warp-blend or
    /// equispaced. Output files always hold equispaced nodes (what VTK and Gmsh assume);
    /// the distribution decides where the mesh is sampled and curved.
    #[arg(long, default_value = "fekete")]
    nodes: NodeFamily,
    /// Where boundary nodes go: geodesic (the paper's arc-length/geodesic placement) or
    /// projection (closest point of the straight node; the baseline).
    #[arg(long, default_value = "geodesic")]
    boundary_nodes: BoundaryNodeStrategy,
    /// Smallest angle (degrees) a curved surface edge may make with its neighbours at a
    /// vertex; below it the edge is rebuilt as the paper's Hermite-type curve (Fig. 4,
    /// p ≥ 3). 0 turns the correction off.
    #[arg(long, default_value_t = 10.0)]
    min_angle: f64,
    /// Young's modulus E of the elastic analogy.
    #[arg(long, default_value_t = 10.0)]
    young: f64,
    /// Poisson's ratio ν of the elastic analogy (in (−1, 0.5)).
    #[arg(long, default_value_t = 0.4)]
    poisson: f64,
    /// Linear solver: auto (direct for small systems, else CG), direct or cg.
    #[arg(long, value_enum, default_value = "auto")]
    solver: SolverArg,
    /// Boundary physical groups whose nodes slide in their plane (u·n = 0) instead of being
    /// fixed, e.g. symmetry or end planes meeting a curved wall.
    #[arg(long, num_args = 1.., value_name = "GROUP")]
    slide: Vec<String>,
    /// Move only the boundary nodes onto the geometry (no elastic solve): for looking at
    /// the boundary placement.
    #[arg(long)]
    boundary_only: bool,
    /// Skip the Bézier certification of every element's validity (det J > 0 everywhere);
    /// the sampled scaled Jacobian alone can miss det J < 0 near a vertex or face.
    #[arg(long)]
    no_certify: bool,
    /// Do not repair elements the certification finds invalid (by default the mesh is solved
    /// again with small cells stiffer, then the free nodes around what is still invalid are
    /// untangled, boundary nodes held on the geometry); they then end the run with exit 1.
    #[arg(long)]
    no_repair: bool,
    /// Run even when the estimated peak memory exceeds this machine's memory.
    #[arg(long)]
    ignore_memory_estimate: bool,
}

/// Where results go (shared by `curve` and `demo`).
#[derive(Args)]
struct OutputArgs {
    /// Output file: `.vtu` (VTK Lagrange cells) or `.msh` (Gmsh MSH 4.1, high order).
    /// The displacement is written as point data, the scaled Jacobian and stretching as
    /// cell data.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Write a JSON report (sizes, solver, residual, quality, seconds per step).
    #[arg(long)]
    report: Option<PathBuf>,
    /// Write the quality histograms as SVG into this directory
    /// (scaled_jacobian.svg, stretching.svg).
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Write the mesh (and report) even when some element is not certified valid
    /// (det J ≤ 0 somewhere, or undecided); the exit code is still non-zero.
    #[arg(long)]
    allow_invalid: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum SolverArg {
    Auto,
    Direct,
    Cg,
}

#[derive(Clone, Copy, ValueEnum)]
enum SampleArg {
    Quadrature,
    Nodes,
    Both,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Interrupted (Ctrl-C, kill, hang-up): no half-written `.out.vtu.tmp<pid>` is left, and
    // the outputs are all in place or none (the commit and this cleanup share a lock).
    let _ = ctrlc::set_handler(|| {
        eprintln!("hocurve: interrupted; no output written");
        hocurve_io::exit_removing_temporary_files(130);
    });
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hocurve: error: {}", one_line(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, each text once: errors of our crates already
/// print their source (an OS error's text), which anyhow's chain would repeat.
fn one_line(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if text.contains(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    text.replace('\n', " ")
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Curve {
            mesh,
            order,
            straight,
            geometry,
            geometry_tolerance,
            method,
            output,
        } => {
            if !straight && geometry.is_none() {
                bail!("give a geometry to curve onto with --geometry FILE (.json or .igs), or pass --straight for the straight-sided order-{order} mesh");
            }
            let Some(out) = output.output.clone() else {
                bail!("give the output file with -o OUT.vtu (or .msh)");
            };
            check_outputs(&out, &output)?;
            let start = Instant::now();
            let linear = hocurve_io::read_msh(&mesh)?;
            let model = geometry.as_deref().map(read_geometry).transpose()?;
            if let (Some(path), Some((model, _))) = (&geometry, &model) {
                let (curves, surfaces) = model.counts();
                println!("{}: {curves} curves, {surfaces} surfaces", path.display());
            }
            let read = start.elapsed().as_secs_f64();
            let mut options = method.options(order as usize)?;
            options.geometry_tolerance = geometry_tolerance;
            let geometry = model
                .as_ref()
                .map(|(model, rule)| Geometry { model, rule: *rule });
            println!(
                "{}: {}D, {} vertices, {} cells -> order {order} ({} nodes)",
                mesh.display(),
                linear.dim,
                linear.vertices.len(),
                linear.cells.len(),
                options.family
            );
            finish(
                &linear,
                geometry,
                &options,
                method.ignore_memory_estimate,
                read,
                &out,
                &output,
            )
        }
        Command::Demo {
            name,
            order,
            method,
            output,
        } => {
            let order = order.map_or(name.order(), |p| p as usize);
            let out = output
                .output
                .clone()
                .unwrap_or_else(|| PathBuf::from(format!("{}_p{order}.vtu", name.name())));
            check_outputs(&out, &output)?;
            let start = Instant::now();
            let linear = name.mesh()?;
            let (model, rule) = name.geometry()?;
            let options = method.options(order)?;
            println!(
                "demo {}: {}D, {} vertices, {} cells -> order {order} ({} nodes)",
                name.name(),
                linear.dim,
                linear.vertices.len(),
                linear.cells.len(),
                options.family
            );
            let read = start.elapsed().as_secs_f64();
            let geometry = Geometry {
                model: &model,
                rule,
            };
            finish(
                &linear,
                Some(geometry),
                &options,
                method.ignore_memory_estimate,
                read,
                &out,
                &output,
            )
        }
        Command::Quality {
            mesh,
            json,
            sample,
            certify,
            histogram,
            stretching_histogram,
        } => {
            for path in histogram.iter().chain(&stretching_histogram) {
                hocurve_io::check_writable(path)?;
            }
            let high_order = hocurve_io::read_high_order_mesh(&mesh)?;
            let options = hocurve_quality::QualityOptions {
                sampling: match sample {
                    SampleArg::Quadrature => Sampling::Quadrature,
                    SampleArg::Nodes => Sampling::Nodes,
                    SampleArg::Both => Sampling::Both,
                },
                bezier: certify.then(Default::default),
            };
            let quality = hocurve_quality::assess(&high_order, &options)
                .with_context(|| format!("{}", mesh.display()))?;
            if json {
                println!("{}", quality.summary.to_json()?);
            } else {
                println!(
                    "{}: {}D, order {}, {} nodes",
                    mesh.display(),
                    high_order.dim,
                    high_order.order,
                    high_order.nodes.len()
                );
                print!("{}", quality.summary);
                if !certify {
                    println!(
                        "validity not certified: sampled Ĩ can miss det J < 0 near a vertex or face (use --certify)"
                    );
                }
            }
            if let Some(path) = histogram {
                hocurve_quality::write_histogram_svg(&path, &quality.summary)?;
            }
            if let Some(path) = stretching_histogram {
                hocurve_quality::write_stretching_histogram_svg(&path, &quality.summary)?;
            }
            Ok(())
        }
        Command::Info { mesh } => {
            let linear = hocurve_io::read_msh(&mesh)?;
            print_info(&mesh, &linear);
            Ok(())
        }
    }
}

impl MethodArgs {
    fn options(&self, order: usize) -> Result<CurveOptions> {
        let mut options = CurveOptions::new(order);
        options.family = self.nodes;
        options.placement.strategy = self.boundary_nodes;
        options.placement.min_angle_degrees = (self.min_angle > 0.0).then_some(self.min_angle);
        options.material = Material::new(self.young, self.poisson)?;
        options.solver.kind = match self.solver {
            SolverArg::Auto => SolverKind::Auto,
            SolverArg::Direct => SolverKind::Direct,
            SolverArg::Cg => SolverKind::Cg,
        };
        options.slide = self.slide.clone();
        options.boundary_only = self.boundary_only;
        options.certify = !self.no_certify;
        options.untangle = !self.no_repair;
        options.stiffen = !self.no_repair;
        Ok(options)
    }
}

/// Fails early on output paths we could not write (a missing or read-only folder), before
/// any work is done: the mesh, the report, and the plots' folder (created if missing; its
/// parent must exist).
fn check_outputs(out: &Path, output: &OutputArgs) -> Result<()> {
    check_output_path(out)?;
    hocurve_io::check_writable(out)?;
    if let Some(report) = &output.report {
        hocurve_io::check_writable(report)?;
    }
    if let Some(dir) = &output.plots {
        if dir.is_dir() {
            hocurve_io::check_writable(&dir.join("scaled_jacobian.svg"))?;
        } else if dir.exists() {
            bail!("{}: is a file, not a folder for the plots", dir.display());
        } else {
            hocurve_io::check_writable(dir)?;
        }
    }
    Ok(())
}

/// Fails early on an output format we cannot write.
fn check_output_path(path: &Path) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("vtu" | "msh")) {
        bail!(
            "{}: unknown output format (expected .vtu or .msh)",
            path.display()
        );
    }
    Ok(())
}

/// Refuses an order whose estimated peak memory exceeds the machine's (unless `ignore`).
fn check_memory(linear: &LinearMesh, order: usize, ignore: bool) -> Result<()> {
    let (Some(total), false) = (hocurve::memory::machine_memory(), ignore) else {
        return Ok(());
    };
    let estimate = hocurve::memory::estimate(linear, order)?;
    if estimate.peak_bytes > total {
        bail!(
            "order {order} needs about {:.1} GB ({} nodes, {} unknowns) and this machine has {:.1} GB: use a lower order or a smaller mesh (--ignore-memory-estimate runs anyway)",
            estimate.peak_bytes / 1e9,
            estimate.nodes,
            estimate.unknowns,
            total / 1e9
        );
    }
    Ok(())
}

/// Curves, writes the mesh, the report and the plots, and prints the summary table.
fn finish(
    linear: &LinearMesh,
    geometry: Option<Geometry>,
    options: &CurveOptions,
    ignore_memory: bool,
    read_seconds: f64,
    out: &Path,
    output: &OutputArgs,
) -> Result<()> {
    check_memory(linear, options.order, ignore_memory)?;
    // Straight-sided elements are the input's own map at a higher order: only curved
    // meshes need the check to be run before they are trusted.
    let curved_run = geometry.is_some();
    let uncheckable: Vec<&str> = linear
        .cells
        .iter()
        .filter_map(|c| c.kind.shape().ok())
        .filter(|&s| !hocurve_quality::bezier_check_supported(s, options.order))
        .map(|s| s.name())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    if curved_run && options.certify && !uncheckable.is_empty() && !output.allow_invalid {
        bail!(
            "order {} cannot be certified valid: the Bézier check does not support {} at this order (det J's Bernstein form is too large); --no-certify curves and writes the mesh uncertified",
            options.order,
            uncheckable.join(", ")
        );
    }
    let start = Instant::now();
    let display = ProgressDisplay::new();
    let mut curved = curve_mesh(linear, geometry, options, &mut |p| display.report(p))?;
    display.finish();
    let unused = &curved.report.unused_node_tags;
    if !unused.is_empty() {
        let shown: Vec<String> = unused.iter().take(8).map(u64::to_string).collect();
        eprintln!(
            "hocurve: warning: {} node(s) belong to no cell and are left out of the output (node tags {}{})",
            unused.len(),
            shown.join(", "),
            if unused.len() > shown.len() { ", …" } else { "" }
        );
    }
    let failures = uncertified_elements(linear, &curved);
    // The validity contract's first clause: written boundary nodes on the geometry.
    let size = geometry.map_or(1.0, |g| g.model.size());
    let off_geometry = (curved.report.max_geometry_distance > 1e-10 * size).then(|| {
        format!(
            "written boundary nodes lie up to {:.3e} from the geometry, more than 1e-10 of the model size {size:.3e}",
            curved.report.max_geometry_distance
        )
    });
    if let (Some(message), false) = (&off_geometry, output.allow_invalid) {
        bail!("{message}; nothing written (--allow-invalid writes the mesh anyway)");
    }
    if curved_run
        && options.certify
        && curved.report.certified_valid_elements.is_none()
        && !output.allow_invalid
    {
        bail!(
            "validity not certified: the Bézier check does not support this order; nothing written (--no-certify writes the mesh uncertified)"
        );
    }
    if !failures.is_empty() && !output.allow_invalid {
        print!("{}", curved.quality.summary);
        bail!(
            "{}; nothing written (--allow-invalid writes the mesh anyway)",
            failures
        );
    }
    display.spin("writing the mesh".into());
    let t = Instant::now();
    // Every output is staged and put in place at the end, together: a failure (or a
    // signal) before that leaves the targets as they were.
    let mut staged = hocurve_io::StagedOutputs::new();
    write_curved(&staged.stage(out), &curved)?;
    curved.report.timings.write = t.elapsed().as_secs_f64();
    curved.report.timings.read = read_seconds;
    curved.report.timings.total = read_seconds + start.elapsed().as_secs_f64();
    display.finish();

    print!("{}", curved.quality.summary);
    print_summary_table(&curved, out);
    if let Some(path) = &output.report {
        write_report(&staged.stage(path), &curved)?;
    }
    if let Some(dir) = &output.plots {
        write_plots(&mut staged, dir, &curved.quality.summary)?;
    }
    staged.commit()?;
    if let Some(message) = off_geometry {
        bail!("{message}; written anyway (--allow-invalid)");
    }
    if !failures.is_empty() {
        bail!("{}; written anyway (--allow-invalid)", failures);
    }
    Ok(())
}

/// The elements not certified valid, named by their Gmsh element tags with a vertex
/// centroid each, and what was tried: empty when every element is certified.
struct Uncertified(Vec<String>, String);

impl Uncertified {
    fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl std::fmt::Display for Uncertified {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let shown: Vec<&str> = self.0.iter().take(8).map(String::as_str).collect();
        write!(
            f,
            "{} element(s) not certified valid after {}: {}{}",
            self.0.len(),
            self.1,
            shown.join("; "),
            if self.0.len() > shown.len() {
                "; …"
            } else {
                ""
            }
        )
    }
}

fn uncertified_elements(linear: &LinearMesh, curved: &CurvedMesh) -> Uncertified {
    // Cells are those of the mesh that was curved (the input, or the input with split
    // edges: the halves of a split cell keep its tag, appended ones get new tags).
    let linear = curved.split_input.as_ref().unwrap_or(linear);
    let quality = &curved.quality;
    let cells = hocurve::repair::not_certified(quality);
    let named = cells
        .iter()
        .map(|&c| {
            let vertices = linear.cells.get(c).map_or(&[][..], |e| &e.vertices[..]);
            let mut centre = [0.0; 3];
            for &v in vertices {
                for d in 0..3 {
                    centre[d] += linear.vertices[v as usize][d] / vertices.len() as f64;
                }
            }
            let bound = quality
                .validity
                .as_ref()
                .map(|v| format!(", Ĩ ≥ {:.3}", v[c].scaled_jacobian_lower_bound))
                .unwrap_or_default();
            let cause = if curved.report.doubly_curved_cells.contains(&c) {
                " (two of its faces lie on one curved surface and meet along an edge: curved, they open to 180° there, det J = 0; split this cell in the input)"
            } else {
                ""
            };
            format!(
                "input element tag {} at ({:.4}, {:.4}, {:.4}){bound}{cause}",
                linear.cell_tag(c),
                centre[0],
                centre[1],
                centre[2]
            )
        })
        .collect();
    let r = &curved.report;
    let mut step = if r.solver == "none" {
        "placing the boundary nodes".to_string()
    } else if r.corrections_undone > 0 {
        format!(
            "the elastic solve (with {} minimum-angle correction(s) undone)",
            r.corrections_undone
        )
    } else {
        "the elastic solve".to_string()
    };
    if r.uncertified_after_solve > 0 && !r.repair_steps().is_empty() {
        step += &format!(", then {}", r.repair_steps());
    }
    Uncertified(named, step)
}

/// Writes the JSON report.
fn write_report(path: &Path, curved: &CurvedMesh) -> Result<()> {
    let json = serde_json::to_string_pretty(&curved.report)?;
    hocurve_io::write_atomically(path, |w| {
        w.write_all(json.as_bytes())
            .and_then(|()| w.write_all(b"\n"))
            .map_err(|source| hocurve_io::IoError::Os {
                path: path.to_path_buf(),
                source,
            })
    })?;
    Ok(())
}

/// Writes the mesh with the displacement as point data and Ĩ and stretching as cell data.
fn write_curved(path: &Path, curved: &CurvedMesh) -> Result<()> {
    let displacement: Vec<f64> = curved.displacement.iter().flatten().copied().collect();
    let point_data = [DataArray {
        name: "displacement",
        components: 3,
        values: &displacement,
    }];
    let quality = &curved.quality;
    // The certified lower bound of Ĩ per cell, when the Bézier check ran: the cells to
    // look at in ParaView are those where it is far below the sampled Ĩ.
    let lower_bounds: Option<Vec<f64>> = quality.validity.as_ref().map(|checks| {
        checks
            .iter()
            .map(|c| c.scaled_jacobian_lower_bound)
            .collect()
    });
    let mut cell_arrays = vec![
        DataArray {
            name: "scaled_jacobian",
            components: 1,
            values: &quality.scaled_jacobian,
        },
        DataArray {
            name: "stretching",
            components: 1,
            values: &quality.stretching,
        },
    ];
    if let Some(bounds) = &lower_bounds {
        cell_arrays.push(DataArray {
            name: "scaled_jacobian_lower_bound",
            components: 1,
            values: bounds,
        });
    }
    hocurve_io::write_mesh_with(path, &curved.mesh, &point_data, &cell_arrays)?;
    Ok(())
}

/// Stages the quality histograms in `dir` (created if missing, removed again if the run
/// fails before the commit).
fn write_plots(
    staged: &mut hocurve_io::StagedOutputs,
    dir: &Path,
    summary: &QualitySummary,
) -> Result<()> {
    staged.create_dir(dir)?;
    let jacobian = staged.stage(&dir.join("scaled_jacobian.svg"));
    hocurve_quality::write_histogram_svg(&jacobian, summary)?;
    let stretching = staged.stage(&dir.join("stretching.svg"));
    hocurve_quality::write_stretching_histogram_svg(&stretching, summary)?;
    Ok(())
}

fn print_summary_table(curved: &CurvedMesh, out: &Path) {
    let r = &curved.report;
    let t = &r.timings;
    let mut rows: Vec<(&str, String)> = vec![
        ("output", out.display().to_string()),
        (
            "mesh",
            format!(
                "{} elements, order {}, {} nodes",
                r.elements, r.order, r.nodes
            ),
        ),
        (
            "boundary",
            format!(
                "{} facets on the geometry ({} by name, {} by proximity), {} straight; {} curved facets, {} nodes on the geometry",
                r.facets_by_name + r.facets_by_proximity,
                r.facets_by_name,
                r.facets_by_proximity,
                r.facets_straight,
                r.curved_facets,
                r.boundary_nodes_on_geometry
            ),
        ),
        (
            "max distance to geometry",
            format!(
                "{:.3e} (vertices moved up to {:.3e}, tolerance {:.3e})",
                r.max_geometry_distance, r.max_vertex_move, r.geometry_tolerance
            ),
        ),
    ];
    if r.solver != "none" {
        rows.push((
            "elasticity",
            format!(
                "{} dofs, {} solver, {} iterations, residual {:.1e}",
                r.dofs, r.solver, r.iterations, r.residual
            ),
        ));
    }
    if r.small_angle_edges > 0 {
        rows.push((
            "small-angle edges",
            format!(
                "{} below the limit, {} corrected (Fig. 4); smallest edge angle {:.1}°",
                r.small_angle_edges,
                r.corrected_edges,
                r.min_edge_angle_degrees.unwrap_or(f64::NAN)
            ),
        ));
    }
    if r.sliding_nodes > 0 {
        rows.push(("sliding nodes", r.sliding_nodes.to_string()));
    }
    if r.edges_split > 0 {
        rows.push((
            "edges split",
            format!(
                "{} interior edge(s) split before curving: their cells had two facets on one curved entity (a 180° corner once curved)",
                r.edges_split
            ),
        ));
    }
    if r.corrections_undone > 0 {
        rows.push((
            "corrections undone",
            format!(
                "{} edge(s) back on geodesics: their Fig. 4 correction did not improve every element on them",
                r.corrections_undone
            ),
        ));
    }
    rows.push((
        "min scaled Jacobian",
        match r.min_scaled_jacobian_lower_bound {
            Some(bound) => format!(
                "Ĩ ≥ {bound:.4} everywhere (certified by Bézier bounds); {} at the degree-2p quadrature points (paper Eq. 8)",
                r.min_scaled_jacobian.map_or("-".to_string(), |m| format!("{m:.4}"))
            ),
            None => format!(
                "{} at the degree-2p quadrature points only (paper Eq. 8; not certified)",
                r.min_scaled_jacobian.map_or("-".to_string(), |m| format!("{m:.4}"))
            ),
        },
    ));
    rows.push(("invalid elements", r.invalid_elements.to_string()));
    if r.uncertified_after_solve > 0 {
        let steps = r.repair_steps();
        rows.push((
            "repair",
            format!(
                "{} element(s) not certified after the elastic solve; {}",
                r.uncertified_after_solve,
                if steps.is_empty() {
                    "not repaired (--no-repair)"
                } else {
                    &steps
                }
            ),
        ));
    }
    rows.push((
        "certified valid",
        match (r.certified_valid_elements, r.undecided_elements) {
            (Some(valid), Some(undecided)) => format!(
                "{valid} of {} elements have det J > 0 everywhere (Bézier bounds), {undecided} undecided",
                r.elements,
            ),
            _ => "not certified (--no-certify)".to_string(),
        },
    ));
    rows.push((
        "time (s)",
        format!(
            "read {:.2}, nodes {:.2}, association {:.2}, boundary {:.2}, assembly {:.2}, solve {:.2}, quality {:.2}, repair {:.2}, write {:.2}; total {:.2}",
            t.read, t.high_order_nodes, t.association, t.boundary_nodes, t.assembly, t.solve, t.quality, t.repair, t.write, t.total
        ),
    ));
    let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    for (key, value) in rows {
        println!("  {key:<width$}  {value}");
    }
}

/// Progress on stderr, shown only when stderr is a terminal: a spinner naming the running
/// step, turning into a bar during the stiffness assembly (fraction of cells done) and the
/// CG solve (orders of magnitude of residual reduction gained towards the tolerance).
struct ProgressDisplay(Option<indicatif::ProgressBar>);

/// Resolution of the bar.
const BAR_LENGTH: u64 = 1000;

impl ProgressDisplay {
    fn new() -> Self {
        if !std::io::stderr().is_terminal() {
            return ProgressDisplay(None);
        }
        let bar = indicatif::ProgressBar::new_spinner();
        bar.enable_steady_tick(Duration::from_millis(120));
        ProgressDisplay(Some(bar))
    }

    fn report(&self, progress: Progress) {
        match progress {
            Progress::Step(step) => self.spin(step.describe().into()),
            Progress::Elasticity(SolveProgress::Assembly { fraction }) => {
                self.fill(fraction, "assembling the stiffness matrix".into())
            }
            Progress::Elasticity(SolveProgress::Setup { solver, dofs }) => {
                self.spin(match solver {
                    SolverKind::Direct => {
                        format!("factorising the stiffness matrix ({dofs} unknowns)")
                    }
                    _ => format!("setting up the p-multigrid preconditioner ({dofs} unknowns)"),
                })
            }
            Progress::Elasticity(SolveProgress::Iteration {
                iteration,
                relative_residual,
                tolerance,
            }) => {
                let gained = relative_residual.log10() / tolerance.log10();
                let fraction = if gained.is_finite() { gained } else { 0.0 };
                self.fill(
                    fraction,
                    format!("CG iteration {iteration}, residual {relative_residual:.1e}"),
                );
            }
        }
    }

    /// A spinner with `message`.
    fn spin(&self, message: String) {
        if let Some(bar) = &self.0 {
            let style = indicatif::ProgressStyle::with_template("{spinner} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner());
            bar.set_style(style);
            bar.set_message(message);
        }
    }

    /// A bar filled to `fraction` (clamped to [0, 1]) with `message`.
    fn fill(&self, fraction: f64, message: String) {
        if let Some(bar) = &self.0 {
            let style =
                indicatif::ProgressStyle::with_template("{spinner} {msg} [{bar:30}] {percent:>3}%")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            bar.set_style(style);
            bar.set_length(BAR_LENGTH);
            bar.set_position((fraction.clamp(0.0, 1.0) * BAR_LENGTH as f64) as u64);
            bar.set_message(message);
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}

fn print_info(path: &Path, linear: &LinearMesh) {
    println!("{}", path.display());
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
}

/// Reads a geometry file by its extension: `.json` or `.igs`/`.iges`.
fn read_geometry(path: &Path) -> Result<(GeometryModel, AssociationRule)> {
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
