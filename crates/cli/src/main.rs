//! The `hocurve` command line: parses arguments, shows progress and prints; the work is
//! the library's ([`hocurve::job`]: read, curve, certify, write). Every error ends the
//! program with exit code 1 and one line on stderr.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{bail, Result};
use clap::{Args, Parser, Subcommand};
use hocurve::demo::Demo;
use hocurve::elastic::SolveProgress;
use hocurve::elastic::{Material, SolverKind};
use hocurve::geodesic::BoundaryNodeStrategy;
use hocurve::io::{MshFormat, MshVersion, OutputFormat, VtuEncoding};
use hocurve::job::{curve_and_write, Inputs, JobError, JobOptions, Outputs};
use hocurve::nodes::NodeFamily;
use hocurve::pipeline::{CurveOptions, Progress, SolveRegion, Step};
use hocurve::quality::Sampling;
use hocurve::summary::{input_line, measured_text, mesh_info, summary_table};

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
        /// Geometry to curve onto: JSON (analytic shapes, NACA airfoils, NURBS; see README),
        /// IGES (.igs/.iges) or STEP (.step/.stp).
        #[arg(short, long)]
        geometry: Option<PathBuf>,
        /// Largest distance (in mesh units) of a boundary vertex from its geometry entity;
        /// default 1e-4 × the mesh's bounding-box diagonal. Facets farther away stay straight.
        #[arg(long)]
        geometry_tolerance: Option<f64>,
        /// Distance (in the geometry's length unit, mm for STEP and IGES) to which the
        /// geometry's faces meet along their common edges, when it is more than the file
        /// states: boundary nodes there are then required to lie within it of each face.
        /// For files that understate their gaps (OpenCASCADE's IGES writer states a fixed
        /// resolution whatever the shape's tolerance), which are otherwise refused.
        #[arg(long, requires = "geometry")]
        geometry_gap: Option<f64>,
        #[command(flatten)]
        method: MethodArgs,
        #[command(flatten)]
        output: OutputArgs,
        #[command(flatten)]
        verbosity: Verbosity,
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
        #[command(flatten)]
        verbosity: Verbosity,
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
        #[arg(long, default_value = "quadrature")]
        sample: Sampling,
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
    #[arg(long, default_value = "auto")]
    solver: SolverKind,
    /// Boundary physical groups whose nodes slide in their planes (u·n = 0) instead of being
    /// fixed; a group may be made of several planes (each node slides in its own, along the
    /// line where two meet, and stays where three meet). Groups made of planes that meet a
    /// curved boundary (end planes of extruded meshes, symmetry planes) slide by default.
    #[arg(long, num_args = 1.., value_name = "GROUP")]
    slide: Vec<String>,
    /// Boundary physical groups kept fixed that would slide by default.
    #[arg(long, num_args = 1.., value_name = "GROUP")]
    fix: Vec<String>,
    /// Solve the thin cells of boundary layers by elasticity like the rest. By default the
    /// cells stacked on a curved wall (wall-normal columns of hexahedra, prisms and
    /// quadrilaterals, each thinner than half its width) move with the wall.
    #[arg(long)]
    elastic_layers: bool,
    /// Keep the elastic material uniform on boundary-layer meshes. By default a mesh whose
    /// cells at the curved boundary are stretched 10:1 or more is solved with each cell's
    /// stiffness scaled by 1/|J| (small cells stiffer), so thin cells move rather than shear.
    #[arg(long)]
    uniform_stiffness: bool,

    /// Reshape elements certified valid but with scaled Jacobian Ĩ below this after the
    /// solve: the free nodes around them (and sliding boundary nodes, within their planes)
    /// are optimised, and the result kept only if every element stays certified and the
    /// mesh's certified min Ĩ rises. Nodes on the geometry never move. 0 turns it off
    #[arg(long, default_value_t = hocurve::repair::RESHAPE_BELOW, value_name = "Q")]
    reshape_below: f64,
    /// Move only the boundary nodes onto the geometry (no elastic solve): for looking at
    /// the boundary placement.
    #[arg(long)]
    boundary_only: bool,
    /// Cells in the elastic solve: active (cells near curved boundaries, grown until the
    /// displacement reaching the outermost ring is below CUTOFF = 1e-2 of its cells'
    /// thickness; the rest keep straight high-order nodes), active=CUTOFF, or whole.
    #[arg(
        long,
        default_value = "active",
        value_name = "active|active=CUTOFF|whole"
    )]
    solve_region: SolveRegion,
    /// Skip the Bézier certification of every element's validity (det J > 0 everywhere).
    #[arg(long)]
    no_certify: bool,
    /// Do not repair elements the certification finds invalid (by default the mesh is solved
    /// again with small cells stiffer; then the longest chord of each cell left — an edge
    /// through the domain between two boundary vertices — is split and the mesh curved
    /// again, or where there is none the free nodes around it are untangled, boundary nodes
    /// held on the geometry); they then end the run with exit 1.
    #[arg(long)]
    no_repair: bool,
    /// Run even when the estimated peak memory exceeds this machine's memory.
    #[arg(long)]
    ignore_memory_estimate: bool,
}

/// How much a run prints (shared by `curve` and `demo`).
#[derive(Args, Clone, Copy)]
struct Verbosity {
    /// Print nothing but errors: no progress, no summary (the exit code and `--report`
    /// tell the outcome).
    #[arg(short, long, conflicts_with = "verbose")]
    quiet: bool,
    /// Also print each step's start and duration, every solver iteration, and after the
    /// summary the quality measures with their histograms.
    #[arg(short, long)]
    verbose: bool,
}

/// Where results go (shared by `curve` and `demo`).
#[derive(Args)]
struct OutputArgs {
    /// Output file: `.vtu` (VTK Lagrange cells) or `.msh` (Gmsh MSH, high order), with
    /// the displacement as point data, the scaled Jacobian and stretching as cell data.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// MSH version of a `.msh` output: 4.1 (Gmsh's default) or 2.2 (what MFEM, NekMesh and
    /// older readers ask for, Gmsh's `-format msh22`).
    #[arg(long, value_name = "2.2|4.1", value_parser = parse_msh_version)]
    msh_version: Option<MshVersion>,
    /// Write a `.msh` output in binary (Gmsh's `-bin`): smaller and faster to read and write.
    #[arg(long)]
    binary: bool,
    /// Compress a `.vtu` output's arrays with zlib (read by ParaView and VTK).
    #[arg(long)]
    compress: bool,
    /// Write a JSON report (sizes, solver, residual, quality, seconds per step).
    #[arg(long)]
    report: Option<PathBuf>,
    /// Write the quality histograms as SVG into this directory (scaled_jacobian.svg, …).
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Write the mesh (and report) even when some element is not certified valid
    /// (det J ≤ 0 somewhere, or undecided); the exit code is still non-zero.
    #[arg(long)]
    allow_invalid: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Interrupted (Ctrl-C, kill, hang-up): no half-written `.out.vtu.tmp<pid>` is left, and
    // the outputs are all in place or none (the commit and this cleanup share a lock).
    let _ = ctrlc::set_handler(|| {
        eprintln!("hocurve: interrupted; no output written");
        hocurve::io::exit_removing_temporary_files(130);
    });
    match in_worker_pool(|| run(cli)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hocurve: error: {}", one_line(&e));
            ExitCode::FAILURE
        }
    }
}

/// Runs `job` on a thread of rayon's pool rather than beside it: the solver opens thousands
/// of short parallel regions (vector operations of every V-cycle), and each one called from
/// outside the pool hands the work over and puts the caller to sleep on a futex — on two
/// cores ~15 % of the run went to those wake-ups. The pool's threads get the main thread's
/// stack size (8 MiB) as deep recursion (parsers) runs there too. Thread count as rayon's
/// global pool (`RAYON_NUM_THREADS`, else one per core); the results do not depend on it.
fn in_worker_pool<R: Send>(job: impl FnOnce() -> Result<R> + Send) -> Result<R> {
    match rayon::ThreadPoolBuilder::new().stack_size(8 << 20).build() {
        Ok(pool) => pool.install(job),
        // No threads to be had: run where we are.
        Err(_) => job(),
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
            geometry_gap,
            method,
            output,
            verbosity,
        } => {
            if !straight && geometry.is_none() {
                bail!("give a geometry to curve onto with --geometry FILE (.json or .igs), or pass --straight for the straight-sided order-{order} mesh");
            }
            let Some(out) = output.output.clone() else {
                bail!("give the output file with -o OUT.vtu (or .msh)");
            };
            let outputs = output.outputs(out);
            outputs.check()?;
            let mut inputs = Inputs::read(&mesh, geometry.as_deref())?;
            if let Some(gap) = geometry_gap {
                if !(gap.is_finite() && gap > 0.0) {
                    bail!("--geometry-gap {gap}: give a positive distance");
                }
                if let Some((model, _)) = inputs.geometry.as_mut() {
                    model.widen_uncertainty(gap);
                }
            }
            let mut options = method.options(order as usize, output.allow_invalid)?;
            options.curve.geometry_tolerance = geometry_tolerance;
            if !verbosity.quiet {
                if let (Some(path), Some((model, _))) = (&geometry, &inputs.geometry) {
                    let (curves, surfaces) = model.counts();
                    println!("{}: {curves} curves, {surfaces} surfaces", path.display());
                }
                println!(
                    "{}",
                    input_line(&mesh.display().to_string(), &inputs.linear, &options.curve)
                );
            }
            curve(&inputs, &options, &outputs, verbosity)
        }
        Command::Demo {
            name,
            order,
            method,
            output,
            verbosity,
        } => {
            let order = order.map_or(name.order(), |p| p as usize);
            let out = output
                .output
                .clone()
                .unwrap_or_else(|| PathBuf::from(format!("{}_p{order}.vtu", name.name())));
            let outputs = output.outputs(out);
            outputs.check()?;
            let inputs = Inputs::demo(name)?;
            let options = method.options(order, output.allow_invalid)?;
            if !verbosity.quiet {
                println!(
                    "{}",
                    input_line(
                        &format!("demo {}", name.name()),
                        &inputs.linear,
                        &options.curve
                    )
                );
            }
            curve(&inputs, &options, &outputs, verbosity)
        }
        Command::Quality {
            mesh,
            json,
            sample,
            certify,
            histogram,
            stretching_histogram,
        } => {
            let options = hocurve::quality::QualityOptions {
                sampling: sample,
                bezier: certify.then(Default::default),
            };
            let measured = hocurve::job::measure(
                &mesh,
                &options,
                histogram.as_deref(),
                stretching_histogram.as_deref(),
            )?;
            if json {
                println!("{}", measured.quality.summary.to_json()?);
            } else {
                print!("{}", measured_text(&mesh, &measured));
            }
            Ok(())
        }
        Command::Info { mesh } => {
            let linear = hocurve::io::read_msh(&mesh)?;
            print!("{}", mesh_info(&mesh, &linear));
            Ok(())
        }
    }
}

/// Runs the job with a progress display, prints the summary table (and with `-v` the
/// quality measures and histograms), and fails (exit 1) on any defect of the mesh,
/// written or not.
fn curve(
    inputs: &Inputs,
    options: &JobOptions,
    outputs: &Outputs,
    verbosity: Verbosity,
) -> Result<()> {
    let mut display = ProgressDisplay::new(verbosity);
    let result = curve_and_write(inputs, options, outputs, &mut |p| display.report(p));
    display.finish();
    let finished = match result {
        Ok(finished) => finished,
        Err(JobError::Rejected { reason, curved }) => {
            if !verbosity.quiet {
                print!("{}", summary_table(&curved, &outputs.mesh));
            }
            bail!("{reason}; nothing written (--allow-invalid writes the mesh anyway)");
        }
        Err(e) => return Err(e.into()),
    };
    let curved = &finished.curved;
    if !verbosity.quiet {
        for warning in hocurve::verdict::warnings(&curved.report) {
            eprintln!("hocurve: warning: {warning}");
        }
        if verbosity.verbose {
            print!("{}", curved.quality.summary);
        }
        print!("{}", summary_table(curved, &outputs.mesh));
    }
    if !finished.defects.is_empty() {
        bail!(
            "{}; written anyway (--allow-invalid)",
            finished.defects.join("; ")
        );
    }
    Ok(())
}

impl MethodArgs {
    fn options(&self, order: usize, allow_invalid: bool) -> Result<JobOptions> {
        let mut options = CurveOptions::new(order);
        options.family = self.nodes;
        options.placement.strategy = self.boundary_nodes;
        options.placement.min_angle_degrees = (self.min_angle > 0.0).then_some(self.min_angle);
        options.material = Material::new(self.young, self.poisson)?;
        options.solver.kind = self.solver;
        options.slide = self.slide.clone();
        options.fix = self.fix.clone();
        options.boundary_only = self.boundary_only;
        options.layer_columns = !self.elastic_layers;
        options.layer_stiffening = !self.uniform_stiffness;
        if !(0.0..1.0).contains(&self.reshape_below) {
            bail!(
                "--reshape-below {}: a scaled Jacobian threshold in [0, 1) (0 turns reshaping off)",
                self.reshape_below
            );
        }
        options.reshape_below = if self.no_repair {
            0.0
        } else {
            self.reshape_below
        };
        options.solve_region = self.solve_region;
        options.certify = !self.no_certify;
        options.untangle = !self.no_repair;
        options.stiffen = !self.no_repair;
        options.refine = !self.no_repair;
        Ok(JobOptions {
            curve: options,
            allow_invalid,
            ignore_memory_estimate: self.ignore_memory_estimate,
        })
    }
}

impl OutputArgs {
    fn outputs(&self, mesh: PathBuf) -> Outputs {
        let format = OutputFormat {
            msh: MshFormat {
                version: self.msh_version.unwrap_or_default(),
                binary: self.binary,
            },
            vtu: if self.compress {
                VtuEncoding::Zlib
            } else {
                VtuEncoding::Base64
            },
        };
        Outputs {
            mesh,
            report: self.report.clone(),
            plots: self.plots.clone(),
            format,
        }
    }
}

/// `--msh-version`: 2.2 or 4.1 (also written 22, 41).
fn parse_msh_version(text: &str) -> Result<MshVersion, String> {
    match text {
        "2.2" | "22" => Ok(MshVersion::V2_2),
        "4.1" | "41" => Ok(MshVersion::V4_1),
        other => Err(format!("{other}: the MSH versions written are 2.2 and 4.1")),
    }
}

/// Progress on stderr. On a terminal: a spinner naming the running step with the elapsed
/// time, turning into a bar with an estimate of the time left during the stiffness
/// assembly (fraction of cells done) and the CG solve (orders of magnitude of residual
/// reduction gained towards the tolerance). Piped (a batch job, a CI log) or with `-v`: one
/// line per step with the elapsed time, and inside a step a line when its phase changes
/// or every [`LOG_INTERVAL`] (with `-v`, every solver iteration). Nothing with `--quiet`.
enum ProgressDisplay {
    Silent,
    Bar(indicatif::ProgressBar),
    Log(LogProgress),
}

/// Resolution of the bar.
const BAR_LENGTH: u64 = 1000;

/// Longest silence of a piped run inside a long step.
const LOG_INTERVAL: Duration = Duration::from_secs(10);

/// The state of line-per-step progress.
struct LogProgress {
    start: Instant,
    verbose: bool,
    /// When the last line was printed.
    last_line: Instant,
    /// The running step and when it started.
    step: Option<(Step, Instant)>,
    /// The kind of the last elasticity event (assembly, set-up, iteration).
    phase: Option<std::mem::Discriminant<SolveProgress>>,
}

impl LogProgress {
    fn line(&mut self, text: &str) {
        let now = Instant::now();
        eprintln!(
            "hocurve: [{:>8.2} s] {text}",
            now.duration_since(self.start).as_secs_f64()
        );
        self.last_line = now;
    }

    /// With `-v`, how long the step that just ended took.
    fn end_step(&mut self) {
        if let (true, Some((step, started))) = (self.verbose, self.step.take()) {
            let seconds = started.elapsed().as_secs_f64();
            self.line(&format!("{} done in {seconds:.2} s", step.describe()));
        }
    }

    fn report(&mut self, progress: Progress) {
        match progress {
            Progress::Step(step) => {
                self.end_step();
                self.step = Some((step, Instant::now()));
                self.phase = None;
                self.line(step.describe());
            }
            Progress::Elasticity(event) => {
                let phase = std::mem::discriminant(&event);
                let iteration = matches!(event, SolveProgress::Iteration { .. });
                if self.phase != Some(phase)
                    || (self.verbose && iteration)
                    || self.last_line.elapsed() >= LOG_INTERVAL
                {
                    self.phase = Some(phase);
                    let (message, fraction) = progress.status();
                    let text = match (iteration, fraction) {
                        (false, Some(f)) => format!("{message} ({:.0} %)", 100.0 * f),
                        _ => message,
                    };
                    self.line(&text);
                }
            }
        }
    }
}

impl ProgressDisplay {
    fn new(verbosity: Verbosity) -> Self {
        if verbosity.quiet {
            return ProgressDisplay::Silent;
        }
        if verbosity.verbose || !std::io::stderr().is_terminal() {
            let now = Instant::now();
            return ProgressDisplay::Log(LogProgress {
                start: now,
                verbose: verbosity.verbose,
                last_line: now,
                step: None,
                phase: None,
            });
        }
        let bar = indicatif::ProgressBar::new_spinner();
        bar.enable_steady_tick(Duration::from_millis(120));
        ProgressDisplay::Bar(bar)
    }

    /// A bar filled to the fraction done (clamped to [0, 1]) where the step has one, else a
    /// spinner, with the step's message; or a log line.
    fn report(&mut self, progress: Progress) {
        let bar = match self {
            ProgressDisplay::Silent => return,
            ProgressDisplay::Log(log) => return log.report(progress),
            ProgressDisplay::Bar(bar) => bar,
        };
        let (message, fraction) = progress.status();
        let template = match fraction {
            Some(_) => {
                "{spinner} [{elapsed_precise}] {msg} [{bar:30}] {percent:>3}% (about {eta} left)"
            }
            None => "{spinner} [{elapsed_precise}] {msg}",
        };
        if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
            bar.set_style(style);
        }
        if let Some(fraction) = fraction {
            let position = (fraction.clamp(0.0, 1.0) * BAR_LENGTH as f64) as u64;
            // A new phase starts the bar again: its estimate starts again too.
            if bar.length() != Some(BAR_LENGTH) || position < bar.position() {
                bar.set_length(BAR_LENGTH);
                bar.reset();
            }
            bar.set_position(position);
        }
        bar.set_message(message);
    }

    fn finish(&mut self) {
        match self {
            ProgressDisplay::Bar(bar) => bar.finish_and_clear(),
            ProgressDisplay::Log(log) => {
                log.end_step();
                log.line("finished");
            }
            ProgressDisplay::Silent => {}
        }
    }
}
