//! The whole job behind one call, as the command line runs it: read a linear mesh and its
//! geometry (format by extension), check before any work that every output can be written
//! and that the order fits the machine, curve and certify ([`crate::pipeline::curve_mesh`]),
//! refuse a mesh that is not certified valid or not on the geometry, and write the mesh,
//! the report and the plots together (all or none, see [`hocurve_io::StagedOutputs`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use hocurve_geodesic::AssociationRule;
use hocurve_io::IoError;
use hocurve_mesh::{LinearMesh, MeshError, Shape};
use hocurve_nurbs::iges::{read_iges_geometry, IgesError};
use hocurve_nurbs::step::{read_step_geometry, StepError};
use hocurve_nurbs::{read_geometry_json, GeometryInputError, GeometryModel};
use hocurve_quality::QualityError;

use crate::demo::{Demo, DemoError};
use crate::pipeline::{curve_mesh, CurveError, CurveOptions, CurvedMesh, Geometry, Progress};
use crate::verdict::{off_geometry, Uncertified};

/// Errors of a curving job; each names the file or the elements concerned.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// Reading or writing a file failed.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A JSON geometry could not be read.
    #[error(transparent)]
    Geometry(#[from] GeometryInputError),
    /// An IGES geometry could not be read.
    #[error(transparent)]
    Iges(#[from] IgesError),
    /// A STEP geometry could not be read.
    #[error(transparent)]
    Step(#[from] StepError),
    /// A bundled case could not be read.
    #[error(transparent)]
    Demo(#[from] DemoError),
    /// The mesh is not one the job can work on.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Curving failed.
    #[error(transparent)]
    Curve(#[from] CurveError),
    /// Measuring or plotting failed.
    #[error(transparent)]
    Quality(#[from] QualityError),
    /// A mesh file could not be measured.
    #[error("{}: {source}", path.display())]
    Measure {
        /// The file.
        path: PathBuf,
        /// Why.
        source: QualityError,
    },
    /// The report could not be serialised.
    #[error("could not write the report as JSON: {0}")]
    Report(#[from] serde_json::Error),
    /// A geometry file whose extension names no format we read.
    #[error("{}: unknown geometry format (expected .json, .igs, .iges, .step or .stp)", path.display())]
    UnknownGeometryFormat {
        /// The file.
        path: PathBuf,
    },
    /// An output file whose extension names no format we write.
    #[error("{}: unknown output format (expected .vtu or .msh)", path.display())]
    UnknownOutputFormat {
        /// The file.
        path: PathBuf,
    },
    /// An output option that does not apply to the output's format.
    #[error("{}: {message}", path.display())]
    OutputOption {
        /// The output file.
        path: PathBuf,
        /// What does not apply.
        message: &'static str,
    },
    /// The plots' folder is a file.
    #[error("{}: is a file, not a folder for the plots", path.display())]
    PlotsFolderIsFile {
        /// The path given.
        path: PathBuf,
    },
    /// The estimated peak memory exceeds the machine's.
    #[error("order {order} needs about {:.1} GB ({nodes} nodes, {unknowns} unknowns) and this machine has {:.1} GB: use a lower order or a smaller mesh (--ignore-memory-estimate runs anyway)", needed / 1e9, available / 1e9)]
    TooLarge {
        /// The order asked for.
        order: usize,
        /// Estimated peak bytes.
        needed: f64,
        /// The machine's memory in bytes.
        available: f64,
        /// Nodes of the high-order mesh.
        nodes: u64,
        /// Unknowns of the elastic solve.
        unknowns: u64,
    },
    /// The certification cannot run at this order for some shapes of the mesh.
    #[error("order {order} cannot be certified valid: the Bézier check does not support {shapes} at this order (det J's Bernstein form is too large); --no-certify curves and writes the mesh uncertified")]
    CannotCertify {
        /// The order asked for.
        order: usize,
        /// The shapes concerned, comma-separated.
        shapes: String,
    },
    /// The curved mesh is not certified valid or not on the geometry: nothing was written.
    /// The mesh is returned for its quality summary.
    #[error("{reason}; nothing written (--allow-invalid writes the mesh anyway)")]
    Rejected {
        /// What is wrong, with element tags and positions.
        reason: String,
        /// The mesh that was not written.
        curved: Box<CurvedMesh>,
    },
}

/// A linear mesh and the geometry to curve it onto, as read.
pub struct Inputs {
    /// The straight-sided mesh.
    pub linear: LinearMesh,
    /// The geometry and how boundary facets are associated with it (None: straight).
    pub geometry: Option<(GeometryModel, AssociationRule)>,
    /// Seconds spent reading.
    pub read_seconds: f64,
}

impl Inputs {
    /// Reads a Gmsh mesh and, if given, a geometry ([`read_geometry`]).
    pub fn read(mesh: &Path, geometry: Option<&Path>) -> Result<Self, JobError> {
        let start = Instant::now();
        let linear = hocurve_io::read_msh(mesh)?;
        let geometry = geometry.map(read_geometry).transpose()?;
        Ok(Inputs {
            linear,
            geometry,
            read_seconds: start.elapsed().as_secs_f64(),
        })
    }

    /// A bundled case.
    pub fn demo(demo: Demo) -> Result<Self, JobError> {
        let start = Instant::now();
        let linear = demo.mesh()?;
        let geometry = Some(demo.geometry()?);
        Ok(Inputs {
            linear,
            geometry,
            read_seconds: start.elapsed().as_secs_f64(),
        })
    }

    /// The geometry in the form [`curve_mesh`] takes.
    pub fn geometry(&self) -> Option<Geometry<'_>> {
        self.geometry
            .as_ref()
            .map(|(model, rule)| Geometry { model, rule: *rule })
    }
}

/// Reads a geometry file by its extension: `.json` (analytic shapes, NACA, NURBS; facets
/// associated by physical-group name), `.igs`/`.iges` or `.step`/`.stp` (by name, then by
/// proximity).
pub fn read_geometry(path: &Path) -> Result<(GeometryModel, AssociationRule), JobError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "json" => Ok((read_geometry_json(path)?, AssociationRule::NameOnly)),
        "igs" | "iges" => Ok((read_iges_geometry(path)?, AssociationRule::NameThenNearest)),
        "step" | "stp" => Ok((read_step_geometry(path)?, AssociationRule::NameThenNearest)),
        _ => Err(JobError::UnknownGeometryFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// Where a job writes: the curved mesh (`.vtu` or `.msh`), and optionally the JSON report
/// and a folder for the quality histograms.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Outputs {
    /// The curved mesh.
    pub mesh: PathBuf,
    /// The JSON report.
    pub report: Option<PathBuf>,
    /// The folder of `scaled_jacobian.svg` and `stretching.svg` (created if missing).
    pub plots: Option<PathBuf>,
    /// How the mesh file is encoded (MSH version and binary, VTU compression).
    pub format: hocurve_io::OutputFormat,
}

impl Outputs {
    /// Fails on outputs that could not be written (unknown format, a missing or read-only
    /// folder), to be called before any work is done.
    pub fn check(&self) -> Result<(), JobError> {
        let ext = self
            .mesh
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        if !matches!(ext.as_deref(), Some("vtu" | "msh")) {
            return Err(JobError::UnknownOutputFormat {
                path: self.mesh.clone(),
            });
        }
        let default = hocurve_io::OutputFormat::default();
        let misplaced = match ext.as_deref() {
            Some("vtu") if self.format.msh != default.msh => {
                Some("the MSH version and binary encoding apply to .msh output (.vtu arrays are always binary; compression is the VTU option)")
            }
            Some("msh") if self.format.vtu != default.vtu => {
                Some("VTU compression applies to .vtu output (MSH has none; binary MSH is the compact form)")
            }
            _ => None,
        };
        if let Some(message) = misplaced {
            return Err(JobError::OutputOption {
                path: self.mesh.clone(),
                message,
            });
        }
        hocurve_io::check_writable(&self.mesh)?;
        if let Some(report) = &self.report {
            hocurve_io::check_writable(report)?;
        }
        if let Some(dir) = &self.plots {
            if dir.is_dir() {
                hocurve_io::check_writable(&dir.join("scaled_jacobian.svg"))?;
            } else if dir.exists() {
                return Err(JobError::PlotsFolderIsFile { path: dir.clone() });
            } else {
                hocurve_io::check_writable(dir)?;
            }
        }
        Ok(())
    }
}

/// How a job runs: the curving options, and what it may do beyond them.
#[derive(Debug, Clone)]
pub struct JobOptions {
    /// The method.
    pub curve: CurveOptions,
    /// Write the mesh even when it is not certified valid or not on the geometry (the
    /// job still reports it as a defect).
    pub allow_invalid: bool,
    /// Run even when the estimated peak memory exceeds the machine's.
    pub ignore_memory_estimate: bool,
}

/// A job that wrote its outputs.
pub struct Finished {
    /// The curved mesh as written, with its quality and report (timings include reading
    /// and writing).
    pub curved: CurvedMesh,
    /// What is wrong with the written mesh (only with `allow_invalid`; empty otherwise).
    pub defects: Vec<String>,
}

/// Curves `inputs`, certifies the result and writes `outputs` (see the module doc). The
/// outputs should have been checked ([`Outputs::check`]) before reading the inputs.
pub fn curve_and_write(
    inputs: &Inputs,
    options: &JobOptions,
    outputs: &Outputs,
    progress: &mut dyn FnMut(Progress),
) -> Result<Finished, JobError> {
    // Everything after reading counts in the total, the checks before curving included.
    let start = Instant::now();
    let linear = &inputs.linear;
    let order = options.curve.order;
    check_memory(linear, order, options.ignore_memory_estimate)?;
    let geometry = inputs.geometry();
    // Straight-sided elements are the input's own map at a higher order: only curved
    // meshes need the check to be run before they are trusted.
    let curving = geometry.is_some();
    let shapes: std::collections::BTreeSet<Shape> = linear.cells.iter().map(|c| c.kind).collect();
    let uncheckable: Vec<&str> = shapes
        .into_iter()
        .filter(|&s| !hocurve_quality::bezier_check_supported(s, order))
        .map(Shape::name)
        .collect();
    if curving && options.curve.certify && !uncheckable.is_empty() && !options.allow_invalid {
        return Err(JobError::CannotCertify {
            order,
            shapes: uncheckable.join(", "),
        });
    }
    let mut curved = curve_mesh(linear, geometry, &options.curve, progress)?;
    let mut defects = Vec::new();
    // The validity contract: written boundary nodes on the geometry, every element
    // certified valid (when curved and certified).
    if let Some(message) = off_geometry(&curved, geometry.map_or(1.0, |g| g.model.size())) {
        defects.push(message);
    }
    if curving && options.curve.certify && curved.report.certified_valid_elements.is_none() {
        defects.push(
            "validity not certified: the Bézier check does not support this order".to_string(),
        );
    }
    let uncertified = Uncertified::of(linear, &curved);
    if !uncertified.is_empty() {
        defects.push(uncertified.to_string());
    }
    if !defects.is_empty() && !options.allow_invalid {
        return Err(JobError::Rejected {
            reason: defects.join("; "),
            curved: Box::new(curved),
        });
    }
    progress(Progress::Step(crate::pipeline::Step::Writing));
    let t = Instant::now();
    // Every output is staged and put in place at the end, together: a failure (or a
    // signal) before that leaves the targets as they were.
    let mut staged = hocurve_io::StagedOutputs::new();
    crate::written::write_curved(&staged.stage(&outputs.mesh), &curved, outputs.format)?;
    let timings = &mut curved.report.timings;
    timings.write = t.elapsed().as_secs_f64();
    timings.read = inputs.read_seconds;
    timings.total = inputs.read_seconds + start.elapsed().as_secs_f64();
    curved.report.peak_memory_mb = crate::memory::peak_resident_bytes().map(|b| b / 1e6);
    if let Some(path) = &outputs.report {
        crate::written::write_report(&staged.stage(path), &curved)?;
    }
    if let Some(dir) = &outputs.plots {
        staged.create_dir(dir)?;
        let summary = &curved.quality.summary;
        crate::written::write_histograms(
            Some(&staged.stage(&dir.join("scaled_jacobian.svg"))),
            Some(&staged.stage(&dir.join("stretching.svg"))),
            summary,
        )?;
    }
    staged.commit()?;
    Ok(Finished { curved, defects })
}

/// Refuses an order whose estimated peak memory exceeds the machine's (unless `ignore`).
fn check_memory(linear: &LinearMesh, order: usize, ignore: bool) -> Result<(), JobError> {
    let (Some(available), false) = (crate::memory::machine_memory(), ignore) else {
        return Ok(());
    };
    let estimate = crate::memory::estimate(linear, order)?;
    if estimate.peak_bytes > available {
        return Err(JobError::TooLarge {
            order,
            needed: estimate.peak_bytes,
            available,
            nodes: estimate.nodes,
            unknowns: estimate.unknowns,
        });
    }
    Ok(())
}

/// A high-order mesh file as measured by [`measure`].
pub struct Measured {
    /// The mesh read.
    pub mesh: hocurve_mesh::HighOrderMesh,
    /// Its quality.
    pub quality: hocurve_quality::MeshQuality,
}

/// Reads a high-order mesh (`.msh` or `.vtu`), measures it with `options`, and writes its
/// scaled-Jacobian and stretching histograms as SVG where paths are given (checked to be
/// writable before the mesh is read).
pub fn measure(
    path: &Path,
    options: &hocurve_quality::QualityOptions,
    scaled_jacobian_histogram: Option<&Path>,
    stretching_histogram: Option<&Path>,
) -> Result<Measured, JobError> {
    for plot in scaled_jacobian_histogram
        .iter()
        .chain(&stretching_histogram)
    {
        hocurve_io::check_writable(plot)?;
    }
    let mesh = hocurve_io::read_high_order_mesh(path)?;
    let quality = hocurve_quality::assess(&mesh, options).map_err(|source| JobError::Measure {
        path: path.to_path_buf(),
        source,
    })?;
    crate::written::write_histograms(
        scaled_jacobian_histogram,
        stretching_histogram,
        &quality.summary,
    )?;
    Ok(Measured { mesh, quality })
}
