//! The whole method on a mesh in memory, end to end: a linear mesh and a geometry in, a
//! curved order-p mesh, its quality and a report out. The steps, each in its own module:
//!
//! 1. [`associate_boundary`](hocurve_geodesic::associate_boundary) ties boundary facets to geometry entities, and cells no
//!    curving can make valid are split (`precurving`);
//! 2. [`HighOrderMesh::from_linear`] places the order-p nodes on the straight elements;
//! 3. [`hocurve_geodesic::place_boundary_nodes_with`] puts the boundary nodes on the true
//!    curves/surfaces (arc length, geodesics, Eqs. (4)–(7), the correction of Fig. 4), and
//!    [`hocurve_elastic::solve_displacement`] carries their displacement into the domain by
//!    linear elasticity (Sect. 3.2) with the boundary conditions of `boundary_conditions`
//!    (`attempt`: one such curving, the mesh as written, its certified quality);
//! 4. the corrections of Fig. 4 are kept only where they help (`correction_choice`);
//! 5. the quality is measured and certified (`certification`: Eq. (8) and Bézier bounds),
//!    and elements not certified are repaired ([`crate::repair`]).

use std::collections::{BTreeMap, BTreeSet};
use std::time::Instant;

use hocurve_elastic::{ElasticError, Material, SolverOptions};

pub use crate::active_region::SolveRegion;
use hocurve_geodesic::{
    associate_boundary_reusing, AssociationRule, FeatureTraces, GeodesicError, PlacementOptions,
    ProximityCache,
};
use hocurve_mesh::{HighOrderMesh, LinearMesh, MeshError};
use hocurve_nodes::{NodeFamily, NodesError};
use hocurve_nurbs::GeometryModel;
use hocurve_quality::{MeshQuality, QualityError, QualityOptions};

pub use crate::certification::invalid_cells;
pub use crate::progress::{Progress, Step};
pub use crate::report::{CurveReport, StepTimings};

use crate::attempt::{curve_and_certify, Boundary};
use crate::certification::assess_certified;
use crate::correction_choice::{
    active_corrections, certified_scaled_jacobians, corrections_not_helping, significantly_better,
};
use crate::precurving::{
    cells_with_doubly_curved_edges, edges_opposite_doubly_curved_corners,
    facet_edges_opposite_doubly_curved_corners, facet_edges_opposite_rim_corners,
    flat_corner_splits, quadrilateral_corners_on_one_entity,
};

/// Errors of the curving pipeline: one step's error, or a problem with the request.
#[derive(Debug, thiserror::Error)]
pub enum CurveError {
    /// Building the high-order mesh failed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Reference nodes could not be built.
    #[error(transparent)]
    Nodes(#[from] NodesError),
    /// Associating the boundary or placing its nodes failed.
    #[error(transparent)]
    Geodesic(#[from] GeodesicError),
    /// The elastic solve failed.
    #[error(transparent)]
    Elastic(#[from] ElasticError),
    /// Measuring quality failed.
    #[error(transparent)]
    Quality(#[from] QualityError),
    /// Untangling elements that were not certified valid failed.
    #[error(transparent)]
    Untangle(#[from] hocurve_untangle::UntangleError),
    /// No boundary facet lies on the geometry.
    #[error("no boundary facet lies on the geometry (tolerance {tolerance:.3e}): name physical groups like the geometry's entities, or check units and the geometry tolerance")]
    NothingOnGeometry {
        /// The association tolerance used.
        tolerance: f64,
    },
    /// A `slide` or `fix` group is not among the mesh's boundary groups.
    #[error(
        "--{option} {name}: no boundary physical group of that name (the mesh has: {available})"
    )]
    UnknownSlideGroup {
        /// "slide" or "fix".
        option: &'static str,
        /// The requested group.
        name: String,
        /// The names the mesh has.
        available: String,
    },
    /// A `--slide` or `--fix` group named in the file that holds no facets (Gmsh's MSH 2.2
    /// with `Mesh.SaveAll` writes every element with physical tag 0).
    #[error(
        "--{option} {name}: the file names this boundary group but none of its elements is in it (Gmsh writes every element outside all groups when Mesh.SaveAll is set and MSH 2.2 is written: save without it, or as MSH 4.1)"
    )]
    EmptySlideGroup {
        /// "slide" or "fix".
        option: &'static str,
        /// The requested group.
        name: String,
    },
    /// A group given both to `slide` and to `fix`.
    #[error("--slide {name} and --fix {name}: a group cannot both slide and be fixed")]
    SlideAndFix {
        /// The group.
        name: String,
    },
    /// A piece of a `slide` group is not planar (a warped quadrilateral facet), so it has
    /// no sliding normal.
    #[error(
        "--slide {name}: the group is not made of planes (a vertex is {distance:.3e} off the best plane of its facets)"
    )]
    SlideGroupNotPlanar {
        /// The group.
        name: String,
        /// Largest distance of a vertex from the plane.
        distance: f64,
    },
    /// The elastic solve stopped before the residual fell below the tolerance.
    #[error("the elastic solve did not converge: relative residual {residual:.3e} > {tolerance:.1e} after {iterations} iterations")]
    NotConverged {
        /// Relative residual reached.
        residual: f64,
        /// Tolerance asked.
        tolerance: f64,
        /// Iterations done.
        iterations: usize,
    },
}

/// A geometry to curve onto and how boundary facets find their entities.
#[derive(Debug, Clone, Copy)]
pub struct Geometry<'a> {
    /// The curves and surfaces.
    pub model: &'a GeometryModel,
    /// By physical-group name only (JSON), or by name then proximity (IGES).
    pub rule: AssociationRule,
}

/// What to build and how.
#[derive(Debug, Clone)]
pub struct CurveOptions {
    /// Polynomial order p.
    pub order: usize,
    /// Nodal distribution of the reference elements.
    pub family: NodeFamily,
    /// Where boundary nodes go (geodesic or projection) and the minimum-angle correction.
    pub placement: PlacementOptions,
    /// Largest distance of a boundary vertex from its entity (None: 1e-4 × bbox diagonal).
    pub geometry_tolerance: Option<f64>,
    /// The elastic analogy's material.
    pub material: Material,
    /// Linear solver settings.
    pub solver: SolverOptions,
    /// Boundary physical groups whose nodes slide in their planes (u·n = 0; along the line
    /// where two of a group's planes meet).
    pub slide: Vec<String>,
    /// Boundary physical groups kept fixed although they would slide by default (see
    /// [`crate::boundary_conditions::sliding_groups`]: groups made of planes meeting a
    /// curved boundary).
    pub fix: Vec<String>,
    /// Move only the boundary nodes (no elastic solve).
    pub boundary_only: bool,
    /// The cells the elastic solve covers: an active region around the curved boundaries
    /// (the default, [`SolveRegion::ACTIVE`]) or all.
    pub solve_region: SolveRegion,
    /// What the quality assessment samples.
    pub quality: QualityOptions,
    /// Certify every element's validity with Bézier bounds on det J (beyond the paper)
    /// when `quality.bezier` is not set. The paper's Ĩ samples det J at interior quadrature
    /// points and can miss det J < 0 near a vertex or face; the Bézier check cannot. Where
    /// it is not supported (see [`hocurve_quality::bezier_check_supported`]) the report
    /// says "not certified".
    pub certify: bool,
    /// Repair elements the certification does not find valid by untangling the free nodes
    /// around them (see [`crate::repair`]); needs `certify`.
    pub untangle: bool,
    /// Repair elements the certification does not find valid by solving again with each
    /// cell's stiffness scaled by 1/|J| of its straight shape (see
    /// [`crate::repair::jacobian_stiffening`]) before untangling; needs `certify`.
    pub stiffen: bool,
    /// Split the longest chord of each simplex no repair certified (or certified below
    /// [`REFINE_BELOW`], when `reshape_below` is not lower) and curve the split mesh again
    /// (see [`curve_mesh`]); needs `certify`.
    pub refine: bool,
    /// Move the thin cells stacked on curved walls (boundary-layer columns of hexahedra,
    /// prisms, quadrilaterals) with the wall rather than solving for them (see
    /// [`crate::layer_columns`]); false solves the whole boundary layer by elasticity.
    pub layer_columns: bool,
    /// On a mesh with boundary-layer structure ([`crate::repair::has_boundary_layer`]),
    /// solve with each cell's stiffness scaled by 1/|J| of its straight shape
    /// ([`crate::repair::jacobian_stiffening`]) from the start; false keeps the paper's
    /// uniform material (the repair may still stiffen).
    pub layer_stiffening: bool,
    /// Reshape valid elements certified with Ĩ below this after the solve and repair (see
    /// [`crate::repair::reshape_poor_elements`]; kept only where the certified min Ĩ
    /// rises); 0 turns it off. Needs `certify`.
    pub reshape_below: f64,
}

impl CurveOptions {
    /// The defaults of the `hocurve curve` command at order `order`: Fekete nodes, geodesic
    /// placement with the 10° minimum-angle correction, E = 10, ν = 0.4, automatic solver.
    pub fn new(order: usize) -> Self {
        CurveOptions {
            order,
            family: NodeFamily::Fekete,
            placement: PlacementOptions::default(),
            geometry_tolerance: None,
            material: Material::default(),
            solver: SolverOptions::default(),
            slide: Vec::new(),
            fix: Vec::new(),
            boundary_only: false,
            solve_region: SolveRegion::ACTIVE,
            quality: QualityOptions::default(),
            certify: true,
            untangle: true,
            stiffen: true,
            refine: true,
            layer_columns: true,
            layer_stiffening: true,
            reshape_below: crate::repair::RESHAPE_BELOW,
        }
    }
}

/// A curved mesh with what was measured on the way.
#[derive(Debug, Clone)]
pub struct CurvedMesh {
    /// The curved order-p mesh.
    pub mesh: HighOrderMesh,
    /// Displacement of every node from its straight-sided position.
    pub displacement: Vec<[f64; 3]>,
    /// Per-element quality and its summary.
    pub quality: MeshQuality,
    /// The report.
    pub report: CurveReport,
    /// The linear mesh that was curved, when it is not the input: nodes no cell uses were
    /// left out, or some input cells had two facets on one curved entity and their opposite
    /// edges were split (the cells and vertices of [`CurvedMesh::mesh`] are those of this
    /// mesh, in its order).
    pub split_input: Option<LinearMesh>,
}

/// Curves `linear` to order `options.order` onto `geometry` (None: straight-sided), calling
/// `progress` before each step and during the elasticity solve.
///
/// The mesh returned is the one to write: equispaced nodes (what VTK and Gmsh read), its
/// curved-boundary nodes on the geometry (interpolated from the node family used inside,
/// then projected onto their entities), and its quality and certification measured on it.
/// When the minimum-angle correction (Fig. 4) rebuilt edges, the mesh is also curved without
/// it: a correction is kept only if every element on its edge is better certified with it,
/// and the result is never worse certified than without corrections (so at most three
/// curvings). Elements still not certified after the solve (and a stiffened solve) are
/// refined when each is a simplex with a chord — an edge between two boundary vertices
/// through the domain ([`crate::precurving::longest_chords`]): its longest chord is split
/// and the split mesh curved again, up to [`REFINEMENT_ROUNDS`] times; otherwise, or when
/// the split mesh does not certify, they are untangled ([`crate::repair`]). Elements still
/// not certified after that, or certified below [`REFINE_BELOW`], are refined the same
/// way — those without a chord by their longest curved facet edge, split at a point on the
/// geometry — the result kept while it certifies more elements (or as many with a higher
/// certified minimum).
pub fn curve_mesh(
    linear: &LinearMesh,
    geometry: Option<Geometry>,
    options: &CurveOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<CurvedMesh, CurveError> {
    // Before the association, whose "nothing on the geometry" would hide the reason.
    linear.check_planar()?;
    let completed = CompletedInput::of(linear, geometry.is_some())?;
    let mut curved = curve_complete_mesh(
        completed.mesh.as_ref().unwrap_or(linear),
        geometry,
        options,
        progress,
    )?;
    curved.mesh.drop_undeclared_facets();
    curved.report.undeclared_facets = completed.undeclared_facets;
    curved.report.reoriented_cells = completed.reoriented_cells;
    Ok(curved)
}

/// The input as curving needs it, when it is not the file's: 2D cells numbered clockwise
/// by their surface renumbered counter-clockwise (the certification and every solver
/// reading the result take det J > 0 for valid), and — when there is a geometry — the
/// facets the file did not declare found from the cells
/// ([`LinearMesh::undeclared_boundary_facets`]: a file whose only physical groups are
/// volumes has none, nor the interface between two of them; one with groups on some walls
/// has only those), so that every such facet on the geometry is curved, as the written
/// cells' nodes are checked; they are not written ([`HighOrderMesh::drop_undeclared_facets`]).
struct CompletedInput {
    /// The completed mesh; None when it is the input.
    mesh: Option<LinearMesh>,
    undeclared_facets: usize,
    reoriented_cells: usize,
}

impl CompletedInput {
    fn of(linear: &LinearMesh, with_geometry: bool) -> Result<Self, CurveError> {
        let clockwise = linear.clockwise_cells();
        let undeclared = if with_geometry {
            linear.undeclared_boundary_facets()?
        } else {
            Vec::new()
        };
        let (undeclared_facets, reoriented_cells) = (undeclared.len(), clockwise.len());
        if undeclared.is_empty() && clockwise.is_empty() {
            return Ok(CompletedInput {
                mesh: None,
                undeclared_facets,
                reoriented_cells,
            });
        }
        let mut mesh = linear.clone();
        mesh.reverse_numbering(&clockwise);
        mesh.add_undeclared_facets(undeclared);
        Ok(CompletedInput {
            mesh: Some(mesh),
            undeclared_facets,
            reoriented_cells,
        })
    }
}

/// [`curve_mesh`] on a mesh with its boundary facets and orientation complete.
fn curve_complete_mesh(
    linear: &LinearMesh,
    geometry: Option<Geometry>,
    options: &CurveOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<CurvedMesh, CurveError> {
    let start = Instant::now();
    let kept = Kept::default();
    let curved = refine_and_curve(
        linear,
        geometry,
        options,
        progress,
        REFINEMENT_ROUNDS,
        &kept,
    )?;
    // Each curving keeps a correction only where it certifies better, but the refinement
    // rounds then split the cells that curving left poor: a path that --min-angle 0 does
    // not take, and may end certified (slightly) better. Where corrections were kept and
    // the mesh refined, that path is taken too and the better result kept.
    if curved.report.refinement_rounds == 0 || curved.report.corrected_edges == 0 {
        return Ok(curved);
    }
    let mut plain_options = options.clone();
    plain_options.placement.min_angle_degrees = None;
    let Ok(mut plain) = refine_and_curve(
        linear,
        geometry,
        &plain_options,
        progress,
        REFINEMENT_ROUNDS,
        &kept,
    ) else {
        return Ok(curved);
    };
    let score = |c: &CurvedMesh| {
        let minimum = certified_scaled_jacobians(&c.quality)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        (crate::repair::not_certified(&c.quality).len(), minimum)
    };
    let (with, without) = (score(&curved), score(&plain));
    if without.0 < with.0 || (without.0 == with.0 && without.1 > with.1) {
        // Every correction was tried and undone; the discarded curving is repair work.
        plain.report.corrections_undone =
            curved.report.corrected_edges + curved.report.corrections_undone;
        plain.report.small_angle_edges = curved.report.small_angle_edges;
        plain.report.min_edge_angle_degrees = curved.report.min_edge_angle_degrees;
        plain.report.timings.repair += curved.report.timings.total;
        plain.report.timings.total = start.elapsed().as_secs_f64();
        return Ok(plain);
    }
    let mut curved = curved;
    curved.report.timings.repair += plain.report.timings.total;
    curved.report.timings.total = start.elapsed().as_secs_f64();
    Ok(curved)
}

/// What the curvings of one run on one model share: every association (after each split,
/// each round's) the vertices' distances to the entities, every placement (each round's,
/// with and without corrections) the traced feature curves. Reused values are the ones
/// computing them again would give, bit for bit.
#[derive(Default)]
struct Kept<'g> {
    traces: FeatureTraces<'g>,
    proximity: ProximityCache,
}

/// [`curve_mesh`] with `rounds` rounds of refinement left. When every element left
/// uncertified by the (stiffened) solve has a chord, the chords are split before any
/// untangling: curving the split mesh costs about one solve, untangling high-order patches
/// can cost a hundred (a coarse ellipsoid at p = 4: 21 s of untangling that failed, then
/// 0.5 s to curve the split mesh). Only if the split mesh does not certify is the input
/// mesh untangled after all.
fn refine_and_curve<'g>(
    linear: &LinearMesh,
    geometry: Option<Geometry<'g>>,
    options: &CurveOptions,
    progress: &mut dyn FnMut(Progress),
    rounds: usize,
    kept: &Kept<'g>,
) -> Result<CurvedMesh, CurveError> {
    let start = Instant::now();
    let refining = geometry.is_some()
        && options.order > 1
        && options.certify
        && options.refine
        && !options.boundary_only;
    let floor = refine_floor(options.reshape_below);
    // Elements left uncertified, or certified below the floor; a result is better with
    // fewer uncertified elements, then a higher certified minimum.
    let poor = |q: &MeshQuality| -> Vec<usize> {
        let mut cells: BTreeSet<usize> = crate::repair::not_certified(q).into_iter().collect();
        let bounds = certified_scaled_jacobians(q);
        cells.extend((0..bounds.len()).filter(|&e| bounds[e] < floor));
        cells.into_iter().collect()
    };
    let score = |q: &MeshQuality| {
        let minimum = certified_scaled_jacobians(q)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        (crate::repair::not_certified(q).len(), minimum)
    };
    let mut curved = match curve_mesh_once(
        linear,
        geometry,
        options,
        progress,
        refining && rounds > 0,
        kept,
    )? {
        Once::Curved(curved) => *curved,
        Once::Deferred(deferred) => {
            let (split, count, facet_count) =
                split_for_refinement(&deferred.base, geometry, options, &deferred.cells, kept)?;
            progress(Progress::Step(Step::Refinement));
            // (A split mesh that cannot be curved: the input's own repair below.)
            let again = refine_and_curve(&split, geometry, options, progress, rounds - 1, kept)
                .ok()
                .filter(|again| crate::repair::not_certified(&again.quality).is_empty());
            if let Some(mut again) = again {
                let r = &mut again.report;
                r.edges_split += deferred.edges_split + count;
                r.facet_edges_split += facet_count;
                r.quadrilaterals_split += deferred.quadrilaterals_split;
                r.surface_edges_split += deferred.surface_edges_split;
                r.unused_node_tags = deferred.unused_node_tags;
                r.timings.repair += deferred.seconds;
                r.refinement_rounds += 1;
                r.refined_elements = deferred.cells.len();
                r.timings.total = start.elapsed().as_secs_f64();
                if again.split_input.is_none() {
                    again.split_input = Some(split);
                }
                return Ok(again);
            }
            // The split mesh does not certify either: the input's own repair after all.
            match curve_mesh_once(linear, geometry, options, progress, false, kept)? {
                Once::Curved(curved) => *curved,
                Once::Deferred(_) => unreachable!("nothing is deferred when not asked"),
            }
        }
    };
    for _ in 0..rounds {
        let failing = poor(&curved.quality);
        if !refining || failing.is_empty() {
            break;
        }
        let base = curved.split_input.as_ref().unwrap_or(linear);
        let (split, count, facet_count) =
            split_for_refinement(base, geometry, options, &failing, kept)?;
        if count + facet_count == 0 {
            break;
        }
        progress(Progress::Step(Step::Refinement));
        // A split mesh that cannot be curved leaves the result as it was.
        let again = match curve_mesh_once(&split, geometry, options, progress, false, kept) {
            Ok(Once::Curved(again)) => again,
            Ok(Once::Deferred(_)) => unreachable!("nothing is deferred when not asked"),
            Err(_) => break,
        };
        let mut again = *again;
        let (now, before) = (score(&again.quality), score(&curved.quality));
        if now.0 > before.0 || (now.0 == before.0 && !significantly_better(now.1, before.1)) {
            break;
        }
        let before = &curved.report;
        again.report.edges_split += before.edges_split + count;
        again.report.facet_edges_split += before.facet_edges_split + facet_count;
        again.report.quadrilaterals_split += before.quadrilaterals_split;
        again.report.surface_edges_split += before.surface_edges_split;
        again.report.unused_node_tags = before.unused_node_tags.clone();
        // The discarded curving is repair work.
        again.report.timings.repair += before.timings.total;
        again.report.refinement_rounds = before.refinement_rounds + 1;
        again.report.refined_elements = if before.refinement_rounds == 0 {
            failing.len()
        } else {
            before.refined_elements
        };
        if again.split_input.is_none() {
            again.split_input = Some(split);
        }
        curved = again;
    }
    curved.report.timings.total = start.elapsed().as_secs_f64();
    Ok(curved)
}

/// `base` with `cells` refined for the next curving: the longest chord of each that has
/// one split at its midpoint, and for each that has none its longest curved facet edge
/// split at a point on the geometry ([`crate::precurving::longest_curved_facet_edges`]),
/// one edge at a time, each kept only if every cell stays the right way round (two edges
/// of one cell moved onto a surface that bends can fold it). Returns the split mesh and
/// the numbers of chords and of facet edges split.
fn split_for_refinement(
    base: &LinearMesh,
    geometry: Option<Geometry>,
    options: &CurveOptions,
    cells: &[usize],
    kept: &Kept,
) -> Result<(LinearMesh, usize, usize), CurveError> {
    let chords = crate::precurving::longest_chords(base, cells);
    let chordless: Vec<usize> = cells
        .iter()
        .zip(crate::precurving::longest_chord_of_each(base, cells))
        .filter(|(_, chord)| chord.is_none())
        .map(|(&c, _)| c)
        .collect();
    // Chords lie on no facet: splitting them first leaves the facet edges whole. (The
    // association, a pass over the whole boundary, only when some cell has no chord.)
    let facet_edges = match geometry {
        Some(geometry) if !chordless.is_empty() => {
            let association = associate_boundary_reusing(
                base,
                geometry.model,
                geometry.rule,
                options.geometry_tolerance,
                &kept.proximity,
            )?;
            crate::precurving::longest_curved_facet_edges(
                base,
                &association,
                geometry.model,
                &chordless,
            )
        }
        _ => Vec::new(),
    };
    let (split, count) = base.split_edges(&chords);
    let (split, facet_count) = split.split_edges_keeping_orientation(&facet_edges);
    Ok((split, count, facet_count))
}

/// Rounds of splitting the chords of uncertified elements and curving again (each costs
/// about one curving of the mesh).
pub const REFINEMENT_ROUNDS: usize = 2;

/// Elements certified valid but below this scaled-Jacobian bound after every repair are
/// refined too: valid, but so close to folding (a solver's quadrature sees a near-zero
/// det J) that the cost of one more curving is worth it. A third of the default
/// `--reshape-below`, whose reshaping has already run on them; a lower `--reshape-below`
/// lowers it (0: poorly shaped valid elements are kept as they are).
pub const REFINE_BELOW: f64 = 0.1;

/// The Ĩ below which certified elements are refined with `--reshape-below` at
/// `reshape_below`: [`REFINE_BELOW`], or lower when the user lets fewer valid elements be
/// reshaped (0: none refined for their shape).
pub fn refine_floor(reshape_below: f64) -> f64 {
    REFINE_BELOW.min(reshape_below)
}

/// What one curving ([`curve_mesh_once`]) ends with.
enum Once {
    /// The curved mesh, every repair done.
    Curved(Box<CurvedMesh>),
    /// The untangling was skipped: every element not certified after the solve has a
    /// chord to split (see [`refine_and_curve`]).
    Deferred(Box<Deferred>),
}

/// A curving stopped before its untangling.
struct Deferred {
    /// The mesh curved (the input, pruned and split before curving), and its cells not
    /// certified.
    base: LinearMesh,
    cells: Vec<usize>,
    /// What was done to the input before curving.
    edges_split: usize,
    quadrilaterals_split: usize,
    surface_edges_split: usize,
    unused_node_tags: Vec<u64>,
    /// Seconds spent.
    seconds: f64,
}

/// [`curve_mesh`] without the refinement of elements no repair certified; when `defer`, it
/// stops before the untangling if every element not certified after the solve has a chord
/// ([`crate::precurving::longest_chords`]).
fn curve_mesh_once<'g>(
    linear: &LinearMesh,
    geometry: Option<Geometry<'g>>,
    options: &CurveOptions,
    progress: &mut dyn FnMut(Progress),
    defer: bool,
    kept: &Kept<'g>,
) -> Result<Once, CurveError> {
    let start = Instant::now();
    let mut timings = StepTimings::default();
    let mut association = None;
    // Vertices no cell uses would be unknowns without stiffness: left out (and reported).
    let (pruned, unused_node_tags) = linear.without_unused_vertices();
    let pruned_input = !unused_node_tags.is_empty();
    let mut linear = if pruned_input { &pruned } else { linear };
    let split_input: LinearMesh;
    let quad_split: LinearMesh;
    let rim_split: LinearMesh;
    let across_split: LinearMesh;
    let flat_split: LinearMesh;
    let mut split_edges = 0;
    let mut surface_edges_split = 0;
    let mut quadrilaterals_split = 0;
    let mut doubly_curved_cells = Vec::new();
    if let Some(geometry) = geometry {
        progress(Progress::Step(Step::Association));
        let t = Instant::now();
        let associate = |linear: &LinearMesh| {
            let association = associate_boundary_reusing(
                linear,
                geometry.model,
                geometry.rule,
                options.geometry_tolerance,
                &kept.proximity,
            )?;
            if association.by_name + association.by_proximity == 0 {
                return Err(CurveError::NothingOnGeometry {
                    tolerance: association.tolerance,
                });
            }
            Ok(association)
        };
        let mut found = associate(linear)?;
        // Cells that no curving can make valid are split first: quadrilaterals at a corner
        // between two edges on one curved entity (see `split_quadrilaterals`), then
        // simplices with two facets on one curved entity (see `split_edges`).
        // At p = 1 nothing curves: no cell needs splitting.
        let curving = options.order > 1;
        let corners = if curving {
            quadrilateral_corners_on_one_entity(linear, &found)
        } else {
            Vec::new()
        };
        let (quads, count) = linear.split_quadrilaterals(&corners);
        if count > 0 {
            quad_split = quads;
            linear = &quad_split;
            found = associate(linear)?;
            quadrilaterals_split = count;
        }
        let rims = if curving {
            facet_edges_opposite_rim_corners(linear, &found, geometry.model)
        } else {
            Vec::new()
        };
        // Each split is kept only if the cells it makes stay the right way round: two rim
        // splits in one tetrahedron, each fair alone (`fair_splits`), can fold it together.
        let (split, count) = linear.split_edges_keeping_orientation(&rims);
        if count > 0 {
            rim_split = split;
            linear = &rim_split;
            found = associate(linear)?;
            surface_edges_split = count;
        }
        let across = if curving {
            facet_edges_opposite_doubly_curved_corners(linear, &found, geometry.model)
        } else {
            Vec::new()
        };
        let (split, count) = linear.split_edges_keeping_orientation(&across);
        if count > 0 {
            across_split = split;
            linear = &across_split;
            found = associate(linear)?;
            surface_edges_split += count;
        }
        let edges = if curving {
            edges_opposite_doubly_curved_corners(linear, &found, geometry.model)
        } else {
            Vec::new()
        };
        let (split, count) = linear.split_edges(&edges);
        if count > 0 {
            split_input = split;
            linear = &split_input;
            found = associate(linear)?;
            split_edges = count;
        }
        // Then the corners that curving flattens whatever facets their cell has (a vertex
        // on a fillet's tangent edge whose three edges lie on the fillet and its face).
        if curving {
            let flat = flat_corner_splits(linear, &found, geometry.model);
            // Splitting one edge of a cell leaves its other edges whole: the facet edges
            // are still there once the edges through the domain are split.
            let (split, through) = linear.split_edges_keeping_orientation(&flat.through);
            let (split, on_surface) = split.split_edges_keeping_orientation(&flat.on_surface);
            if through + on_surface > 0 {
                flat_split = split;
                linear = &flat_split;
                found = associate(linear)?;
                split_edges += through;
                surface_edges_split += on_surface;
            }
        }
        association = Some((geometry, found));
        if let (Some((_, found)), true) = (&association, curving) {
            doubly_curved_cells = cells_with_doubly_curved_edges(linear, found);
        }
        timings.association = t.elapsed().as_secs_f64();
    }

    progress(Progress::Step(Step::HighOrderNodes));
    let t = Instant::now();
    let straight = HighOrderMesh::from_linear(linear, options.order, options.family)?;
    timings.high_order_nodes = t.elapsed().as_secs_f64();

    // The paper's curving, with its minimum-angle corrections (Fig. 4) where there are any.
    let placement = &options.placement;
    let mut curve_with = |placement: &PlacementOptions, timings: &mut StepTimings| {
        let boundary = association
            .as_ref()
            .map(|(geometry, association)| Boundary::Place {
                geometry: *geometry,
                association,
                placement,
                traces: &kept.traces,
            });
        curve_and_certify(
            linear, &straight, geometry, boundary, options, progress, timings,
        )
    };
    let (mut attempt, mut quality) = curve_with(placement, &mut timings)?;
    // A correction is kept only if every element touching its edge is better certified
    // with it than without any (the paper's rule is a heuristic on angles, which can do
    // harm), and the mesh as a whole no worse than with the correction off.
    let corrected = active_corrections(&attempt, placement);
    let mut undone_corrections = 0;
    if !corrected.is_empty() {
        let mut plain = placement.clone();
        plain.uncorrected_edges.extend(corrected.iter().copied());
        // (CG starts from zero in each curving: the one without corrections is then the
        // `--min-angle 0` curving bit for bit, which the choice below must not fall short
        // of beyond round-off; warm-started from the one with corrections it ended
        // elsewhere within CG's tolerance, 1e-8 lower in Ĩ on naca_layers_tets at p = 3.)
        let (without, without_quality) = curve_with(&plain, &mut timings)?;
        let losers = corrections_not_helping(
            &attempt.mesh,
            &corrected,
            &certified_scaled_jacobians(&quality),
            &certified_scaled_jacobians(&without_quality),
        );
        if !losers.is_empty() && losers.len() < corrected.len() {
            let mut some = placement.clone();
            some.uncorrected_edges.extend(losers.iter().copied());
            (attempt, quality) = curve_with(&some, &mut timings)?;
            undone_corrections = losers.len();
        }
        let minimum = |q: &MeshQuality| {
            certified_scaled_jacobians(q)
                .into_iter()
                .fold(f64::INFINITY, f64::min)
        };
        // (With corrections the mesh is never certified worse than without, beyond
        // round-off: the same worst cell, away from them, measured twice.)
        if losers.len() == corrected.len()
            || significantly_better(minimum(&without_quality), minimum(&quality))
        {
            (attempt, quality) = (without, without_quality);
            undone_corrections = corrected.len();
        }
    }

    // Repair, first step: with elements not certified, the solve again with small cells
    // stiffer, kept if it leaves fewer such elements (or as many, better bounded).
    let mut stiffened_resolve = None;
    let uncertified_after_solve = crate::repair::not_certified(&quality).len();
    let repairable = options.certify && !options.boundary_only;
    // A first solve already stiffened would only be repeated.
    let stiffen = options.stiffen && repairable && !attempt.stiffened;
    if let (true, Some(targets)) = (stiffen, attempt.targets.clone()) {
        let bad = uncertified_after_solve;
        if bad > 0 {
            progress(Progress::Step(Step::Repair));
            let stiffening = crate::repair::jacobian_stiffening(&straight);
            let boundary = Boundary::Stiffened {
                targets: &targets,
                stiffening: &stiffening,
                initial: &attempt.solved_displacement,
            };
            // All of the stiffened curving (its solve and certification) is repair time.
            let t = Instant::now();
            let (stiff, stiff_quality) = curve_and_certify(
                linear,
                &straight,
                geometry,
                Some(boundary),
                options,
                progress,
                &mut StepTimings::default(),
            )?;
            timings.repair += t.elapsed().as_secs_f64();
            let stiff_bad = crate::repair::not_certified(&stiff_quality).len();
            let minimum = |q: &MeshQuality| {
                certified_scaled_jacobians(q)
                    .into_iter()
                    .fold(f64::INFINITY, f64::min)
            };
            let better = stiff_bad < bad
                || (stiff_bad == bad
                    && significantly_better(minimum(&stiff_quality), minimum(&quality)));
            if better {
                (attempt, quality) = (stiff, stiff_quality);
            }
            stiffened_resolve = Some(better);
        }
    }

    if defer {
        let cells = crate::repair::not_certified(&quality);
        let each_has_a_chord = crate::precurving::longest_chord_of_each(linear, &cells)
            .iter()
            .all(Option::is_some);
        if !cells.is_empty() && each_has_a_chord {
            return Ok(Once::Deferred(Box::new(Deferred {
                base: linear.clone(),
                cells,
                edges_split: split_edges,
                quadrilaterals_split,
                surface_edges_split,
                unused_node_tags,
                seconds: start.elapsed().as_secs_f64(),
            })));
        }
    }

    let mut untangling = crate::repair::Untangling::default();
    let mut reshaping = crate::repair::Reshaping::default();
    if options.untangle && options.certify && !options.boundary_only && association.is_some() {
        let on_geometry: Vec<u32> = attempt
            .targets
            .as_ref()
            .map(|t| t.entities.keys().copied().collect())
            .unwrap_or_default();
        // (Only the untangling of uncertified elements slides nodes in their planes.)
        let uncertified = !crate::repair::not_certified(&quality).is_empty();
        let in_planes = match (&attempt.targets, &association, uncertified) {
            (Some(targets), Some((geometry, _)), true) => {
                crate::repair::nodes_in_planar_faces(geometry.model, &targets.entities)
            }
            _ => BTreeMap::new(),
        };
        if uncertified {
            progress(Progress::Step(Step::Repair));
        }
        let t = Instant::now();
        (quality, untangling) = crate::repair::untangle_not_certified(
            &mut attempt.mesh,
            &attempt.straight,
            on_geometry.iter().copied(),
            &in_planes,
            &attempt.sliding,
            &doubly_curved_cells,
            quality,
            &|mesh| Ok(assess_certified(mesh, options)?),
        )?;
        timings.repair += t.elapsed().as_secs_f64();
        if options.reshape_below > 0.0 {
            let t = Instant::now();
            (quality, reshaping) = crate::repair::reshape_poor_elements(
                &mut attempt.mesh,
                &attempt.straight,
                on_geometry,
                &attempt.sliding,
                options.reshape_below,
                quality,
                &|mesh| Ok(assess_certified(mesh, options)?),
            )?;
            timings.repair += t.elapsed().as_secs_f64();
        }
    }
    timings.total = start.elapsed().as_secs_f64();
    let association = association.as_ref().map(|(_, a)| a);
    let mut curved = attempt.finish(options, association, quality, undone_corrections, timings);
    if split_edges > 0 {
        curved.report.edges_split = split_edges;
    }
    curved.report.quadrilaterals_split = quadrilaterals_split;
    curved.report.surface_edges_split = surface_edges_split;
    curved.report.doubly_curved_cell_tags = doubly_curved_cells
        .iter()
        .map(|&c| linear.cell_tag(c))
        .collect();
    curved.report.doubly_curved_cells = doubly_curved_cells;
    if split_edges > 0 || quadrilaterals_split > 0 || surface_edges_split > 0 || pruned_input {
        curved.split_input = Some(linear.clone());
    }
    curved.report.unused_node_tags = unused_node_tags;
    curved.report.uncertified_after_solve = uncertified_after_solve;
    curved.report.stiffened_resolve = stiffened_resolve;
    curved.report.untangled_elements = untangling.elements;
    curved.report.untangle_rounds = untangling.rounds;
    if reshaping.kept {
        curved.report.reshaped_elements = reshaping.elements;
        curved.report.reshaped_from = Some(reshaping.min_before);
    }
    Ok(Once::Curved(Box::new(curved)))
}
