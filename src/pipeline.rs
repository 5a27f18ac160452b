//! The whole method, end to end: a linear mesh and a geometry in, a curved order-p mesh,
//! its quality and a report out. The steps are the paper's (Sect. 3–4):
//!
//! 1. [`HighOrderMesh::from_linear`] places the order-p nodes on the straight elements;
//! 2. [`associate_boundary`] ties boundary facets to geometry entities;
//! 3. [`place_boundary_nodes_with`] puts their nodes on the true curves/surfaces (arc length,
//!    geodesics, Eqs. (4)–(7));
//! 4. [`hocurve_elastic::solve_displacement`] carries the boundary displacement into the domain by linear
//!    elasticity (Sect. 3.2), with curved nodes prescribed, `slide` groups sliding in their
//!    plane and every other boundary node fixed;
//! 5. [`assess`] measures the scaled Jacobian (Eq. (8)) and stretching.

use std::collections::{BTreeMap, BTreeSet};
use std::time::Instant;

use hocurve_elastic::{
    solve_displacement_stiffened, solve_displacement_with_progress, BoundaryConditions,
    ElasticError, Material, SolverKind, SolverOptions,
};
use hocurve_geodesic::{
    associate_boundary, place_boundary_nodes_with, project_nodes_onto_geometry, AssociationRule,
    GeodesicError, PlacementOptions,
};
use hocurve_mesh::{HighOrderMesh, LinearMesh, MeshError};
use hocurve_nodes::{NodeFamily, NodesError};
use hocurve_nurbs::vec3::{cross, dot, norm, sub};
use hocurve_nurbs::GeometryModel;
use hocurve_quality::{assess, BezierOptions, MeshQuality, QualityError, QualityOptions, Validity};
use serde::Serialize;

pub use crate::progress::{Progress, Step};

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
    /// A `slide` group is not among the mesh's boundary groups.
    #[error("--slide {name}: no boundary physical group of that name (the mesh has: {available})")]
    UnknownSlideGroup {
        /// The requested group.
        name: String,
        /// The names the mesh has.
        available: String,
    },
    /// A `slide` group is not planar (straight in 2D), so it has no single sliding normal.
    #[error(
        "--slide {name}: the group is not planar (a vertex is {distance:.3e} off its best plane)"
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
    /// Boundary physical groups whose nodes slide in their plane (u·n = 0).
    pub slide: Vec<String>,
    /// Move only the boundary nodes (no elastic solve).
    pub boundary_only: bool,
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
            boundary_only: false,
            quality: QualityOptions::default(),
            certify: true,
            untangle: true,
            stiffen: true,
        }
    }
}

/// Seconds spent per step (0 for steps not run). `read` and `write` are the caller's.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct StepTimings {
    /// Reading the input files.
    pub read: f64,
    /// Placing the straight order-p nodes.
    pub high_order_nodes: f64,
    /// Boundary association.
    pub association: f64,
    /// Boundary node placement.
    pub boundary_nodes: f64,
    /// Stiffness assembly.
    pub assembly: f64,
    /// Linear solve (including preconditioner setup).
    pub solve: f64,
    /// Quality assessment.
    pub quality: f64,
    /// Untangling elements not certified valid (including their re-certification).
    pub repair: f64,
    /// Writing the output.
    pub write: f64,
    /// Wall time of everything above.
    pub total: f64,
}

/// The machine-readable account of one curving run (`hocurve curve --report`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurveReport {
    /// Polynomial order p.
    pub order: usize,
    /// Nodal distribution (`fekete`, `gll`, ...).
    pub node_family: String,
    /// Number of cells.
    pub elements: usize,
    /// Number of nodes of the high-order mesh.
    pub nodes: usize,
    /// Unknowns of the elastic system after condensation (0 without a solve).
    pub dofs: usize,
    /// Boundary facets placed on the geometry.
    pub curved_facets: usize,
    /// Boundary facets associated with an entity by physical-group name.
    pub facets_by_name: usize,
    /// Boundary facets associated with an entity by proximity (IGES).
    pub facets_by_proximity: usize,
    /// Boundary facets on no entity (kept straight, fixed).
    pub facets_straight: usize,
    /// Association tolerance used (largest vertex distance from its entity).
    pub geometry_tolerance: f64,
    /// Largest distance a boundary vertex was moved to lie on the geometry.
    pub max_vertex_move: f64,
    /// Boundary nodes given a target on the geometry.
    pub boundary_nodes_on_geometry: usize,
    /// Largest distance of a boundary node from its geometry entity.
    pub max_geometry_distance: f64,
    /// Curved surface edges meeting a neighbour below the minimum angle.
    pub small_angle_edges: usize,
    /// Of those, edges rebuilt by the Hermite-type correction (Fig. 4).
    pub corrected_edges: usize,
    /// Smallest angle (degrees) between neighbouring curved surface edges, before the
    /// correction (None when not measured: 2D, projection, p ≤ 1, correction off).
    pub min_edge_angle_degrees: Option<f64>,
    /// Corrected edges put back on their geodesics because an element on them was not better
    /// certified with the correction than without.
    pub corrections_undone: usize,
    /// Elements not certified valid (det J ≤ 0 found, or undecided) after the elastic solve
    /// (and the choice of corrections): the repair starts from these (0: none needed).
    pub uncertified_after_solve: usize,
    /// Whether the mesh was solved again with small cells stiffer (1/|J| of their straight
    /// shape, see [`crate::repair::jacobian_stiffening`]) because elements were not
    /// certified after the first solve: None when not, else whether that solve was kept (it
    /// left fewer elements not certified, or as many with a better bound).
    pub stiffened_resolve: Option<bool>,
    /// Elements not certified valid after the elastic solve(s) (and undone corrections),
    /// whose patches were then untangled (0: none needed).
    pub untangled_elements: usize,
    /// Untangling rounds run (the patch reaches one more ring of cells each round).
    pub untangle_rounds: usize,
    /// Interior edges split before curving (the input cells holding them had two facets on
    /// one curved entity, which curving would open to a 180° corner with det J = 0).
    pub edges_split: usize,
    /// Quadrilaterals split into two triangles before curving (two of their edges, meeting
    /// at a corner, lay on one curved entity: curved, that corner opens to 180°).
    pub quadrilaterals_split: usize,
    /// Hexahedra and prisms (indices into the curved mesh's cells) with two faces on one
    /// curved entity meeting along an edge: not split (it would not be conforming), they
    /// get det J = 0 along that edge and cannot be certified.
    pub doubly_curved_cells: Vec<usize>,
    /// Tags of the input nodes no cell uses, left out of the curved mesh.
    pub unused_node_tags: Vec<u64>,
    /// Nodes sliding in a plane (`--slide`).
    pub sliding_nodes: usize,
    /// Solver used: `direct`, `cg` or `none`.
    pub solver: String,
    /// CG iterations (0 for the direct solver).
    pub iterations: usize,
    /// Relative residual ‖f − Ku‖ / ‖f‖ of the solve (0 without a solve).
    pub residual: f64,
    /// Smallest scaled Jacobian Ĩ (None for an empty mesh).
    pub min_scaled_jacobian: Option<f64>,
    /// Elements with det J ≤ 0 found somewhere: Ĩ ≤ 0 at a sample point, or a negative
    /// point found by the Bézier check.
    pub invalid_elements: usize,
    /// Elements certified valid (det J > 0 everywhere, Bézier bounds); None when the
    /// check did not run.
    pub certified_valid_elements: Option<usize>,
    /// Elements the Bézier check could neither certify nor refute (det J ≈ 0 somewhere).
    pub undecided_elements: Option<usize>,
    /// Certified lower bound of min det J / max det J over every element (≤ the true
    /// minimum, unlike the sampled Ĩ); None when the check did not run.
    pub min_scaled_jacobian_lower_bound: Option<f64>,
    /// Fraction (0–1) of elements with Ĩ > 0.95.
    pub fraction_above_0_95: f64,
    /// Elements with Ĩ < 0.5.
    pub elements_below_0_5: usize,
    /// Largest stretching (longest / shortest edge).
    pub max_stretching: Option<f64>,
    /// Seconds per step.
    pub timings: StepTimings,
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
/// curvings). Elements still not certified are then untangled ([`crate::repair`]).
pub fn curve_mesh(
    linear: &LinearMesh,
    geometry: Option<Geometry>,
    options: &CurveOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<CurvedMesh, CurveError> {
    let start = Instant::now();
    let mut timings = StepTimings::default();
    let mut association = None;
    // Vertices no cell uses would be unknowns without stiffness: left out (and reported).
    let (pruned, unused_node_tags) = linear.without_unused_vertices();
    let pruned_input = !unused_node_tags.is_empty();
    let mut linear = if pruned_input { &pruned } else { linear };
    let split_input: LinearMesh;
    let quad_split: LinearMesh;
    let mut split_edges = 0;
    let mut quadrilaterals_split = 0;
    let mut doubly_curved_cells = Vec::new();
    if let Some(geometry) = geometry {
        progress(Progress::Step(Step::Association));
        let t = Instant::now();
        let associate = |linear: &LinearMesh| {
            let association = associate_boundary(
                linear,
                geometry.model,
                geometry.rule,
                options.geometry_tolerance,
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
        let edges = if curving {
            edges_opposite_doubly_curved_corners(linear, &found)
        } else {
            Vec::new()
        };
        let (split, count) = linear.split_edges(&edges);
        if count > 0 {
            split_input = split;
            linear = &split_input;
            association = Some((geometry, associate(linear)?));
            split_edges = count;
        } else {
            association = Some((geometry, found));
        }
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
        if losers.len() == corrected.len() || minimum(&quality) < minimum(&without_quality) {
            (attempt, quality) = (without, without_quality);
            undone_corrections = corrected.len();
        }
    }

    // Repair, first step: with elements not certified, the solve again with small cells
    // stiffer, kept if it leaves fewer such elements (or as many, better bounded).
    let mut stiffened_resolve = None;
    let uncertified_after_solve = crate::repair::not_certified(&quality).len();
    let repairable = options.certify && !options.boundary_only;
    if let (true, Some(targets)) = (options.stiffen && repairable, attempt.targets.clone()) {
        let bad = uncertified_after_solve;
        if bad > 0 {
            progress(Progress::Step(Step::Repair));
            let stiffening = crate::repair::jacobian_stiffening(&straight);
            let boundary = Boundary::Stiffened {
                targets: &targets,
                stiffening: &stiffening,
            };
            let (stiff, stiff_quality) = curve_and_certify(
                linear,
                &straight,
                geometry,
                Some(boundary),
                options,
                progress,
                &mut timings,
            )?;
            let stiff_bad = crate::repair::not_certified(&stiff_quality).len();
            let minimum = |q: &MeshQuality| {
                certified_scaled_jacobians(q)
                    .into_iter()
                    .fold(f64::INFINITY, f64::min)
            };
            let better = stiff_bad < bad
                || (stiff_bad == bad && minimum(&stiff_quality) > minimum(&quality));
            if better {
                (attempt, quality) = (stiff, stiff_quality);
            }
            stiffened_resolve = Some(better);
        }
    }

    let mut untangling = crate::repair::Untangling::default();
    if options.untangle && options.certify && !options.boundary_only && association.is_some() {
        let on_geometry: Vec<u32> = attempt
            .targets
            .as_ref()
            .map(|t| t.entities.keys().copied().collect())
            .unwrap_or_default();
        if !crate::repair::not_certified(&quality).is_empty() {
            progress(Progress::Step(Step::Repair));
        }
        let t = Instant::now();
        (quality, untangling) = crate::repair::untangle_not_certified(
            &mut attempt.mesh,
            &attempt.straight,
            on_geometry,
            &doubly_curved_cells,
            quality,
            &|mesh| Ok(assess_certified(mesh, options)?),
        )?;
        timings.repair = t.elapsed().as_secs_f64();
    }
    timings.total = start.elapsed().as_secs_f64();
    let association = association.as_ref().map(|(_, a)| a);
    let mut curved = attempt.finish(options, association, quality, undone_corrections, timings);
    if split_edges > 0 {
        curved.report.edges_split = split_edges;
    }
    curved.report.quadrilaterals_split = quadrilaterals_split;
    curved.report.doubly_curved_cells = doubly_curved_cells;
    if split_edges > 0 || quadrilaterals_split > 0 || pruned_input {
        curved.split_input = Some(linear.clone());
    }
    curved.report.unused_node_tags = unused_node_tags;
    curved.report.uncertified_after_solve = uncertified_after_solve;
    curved.report.stiffened_resolve = stiffened_resolve;
    curved.report.untangled_elements = untangling.elements;
    curved.report.untangle_rounds = untangling.rounds;
    Ok(curved)
}

impl CurveReport {
    /// The repair steps run, in words ("" when none ran).
    pub fn repair_steps(&self) -> String {
        let mut steps = Vec::new();
        match self.stiffened_resolve {
            Some(true) => steps.push("solved again with small cells stiffer".to_string()),
            Some(false) => steps
                .push("solved again with small cells stiffer (no better: not kept)".to_string()),
            None => {}
        }
        if self.untangle_rounds > 0 {
            steps.push(format!(
                "{} round(s) of untangling the patches around {} element(s)",
                self.untangle_rounds, self.untangled_elements
            ));
        }
        steps.join(", then ")
    }
}

/// One curving of `straight` with the boundary `placement` (the straight mesh itself
/// without geometry), in the form it is written, and its certified quality.
fn curve_and_certify(
    linear: &LinearMesh,
    straight: &HighOrderMesh,
    geometry: Option<Geometry>,
    boundary: Option<Boundary<'_>>,
    options: &CurveOptions,
    progress: &mut dyn FnMut(Progress),
    timings: &mut StepTimings,
) -> Result<(Attempt, MeshQuality), CurveError> {
    let attempt = match boundary {
        None => Attempt::straight(straight),
        Some(boundary) => Attempt::curved(straight, boundary, options, progress, timings)?,
    };
    let attempt = attempt.written(linear, options, geometry, timings)?;
    progress(Progress::Step(Step::Quality));
    let t = Instant::now();
    let quality = assess_certified(&attempt.mesh, options)?;
    timings.quality += t.elapsed().as_secs_f64();
    Ok((attempt, quality))
}

/// The quadrilaterals to split, each with the corner whose two edges lie on one curved
/// entity (the first such corner; a triangle left with two such edges is then split by
/// [`edges_opposite_doubly_curved_corners`]).
fn quadrilateral_corners_on_one_entity(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
) -> Vec<(usize, usize)> {
    let facet_entity = facet_entities(linear, association);
    let mut out = Vec::new();
    for (c, cell) in linear.cells.iter().enumerate() {
        if cell.kind != hocurve_mesh::ElementType::Quad || cell.vertices.len() != 4 {
            continue;
        }
        let v = &cell.vertices;
        let entity = |k: usize| {
            facet_entity
                .get(&sorted(&[v[k % 4], v[(k + 1) % 4]]))
                .copied()
        };
        // Corner k joins edges k − 1 and k.
        if let Some(k) = (0..4).find(|&k| entity(k + 3).is_some() && entity(k + 3) == entity(k)) {
            out.push((c, k));
        }
    }
    out
}

/// Vertex ids sorted (a facet's key whatever its orientation).
fn sorted(v: &[u32]) -> Vec<u32> {
    let mut v = v.to_vec();
    v.sort_unstable();
    v
}

/// The curved entity of each associated declared facet, keyed by its sorted vertices.
fn facet_entities(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
) -> std::collections::HashMap<Vec<u32>, usize> {
    linear
        .facets
        .iter()
        .zip(&association.facet_entity)
        .filter_map(|(f, e)| e.map(|e| (sorted(&f.vertices), e)))
        .collect()
}

/// The hexahedra and prisms with two faces on one curved entity that share an edge: curved,
/// the dihedral angle there opens to 180° (det J = 0), and such cells cannot be split
/// conformingly like simplices and quadrilaterals. Indices into `linear.cells`.
fn cells_with_doubly_curved_edges(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
) -> Vec<usize> {
    let facet_entity = facet_entities(linear, association);
    let mut out = Vec::new();
    for (c, cell) in linear.cells.iter().enumerate() {
        let shape = match cell.kind {
            hocurve_mesh::ElementType::Hex => hocurve_nodes::Shape::Hex,
            hocurve_mesh::ElementType::Prism => hocurve_nodes::Shape::Prism,
            _ => continue,
        };
        let faces: Vec<(Vec<u32>, Option<usize>)> = shape
            .faces()
            .iter()
            .map(|f| {
                let vertices: Vec<u32> = f.iter().map(|&k| cell.vertices[k]).collect();
                let entity = facet_entity.get(&sorted(&vertices)).copied();
                (vertices, entity)
            })
            .collect();
        let doubly = faces.iter().enumerate().any(|(i, (a, ea))| {
            faces[i + 1..].iter().any(|(b, eb)| {
                ea.is_some() && ea == eb && a.iter().filter(|v| b.contains(v)).count() >= 2
            })
        });
        if doubly {
            out.push(c);
        }
    }
    out
}

/// The edges to split so that no triangle or tetrahedron has two facets on one curved
/// entity: for such a cell, the edge opposite the corner the two facets share, unless that
/// edge lies on a declared facet (splitting it would put a new vertex on the boundary, off
/// the geometry). Lower vertex id first, sorted, no repeats.
fn edges_opposite_doubly_curved_corners(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
) -> Vec<[u32; 2]> {
    let facet_entity = facet_entities(linear, association);
    let on_a_facet = |a: u32, b: u32| {
        linear
            .facets
            .iter()
            .any(|f| f.vertices.contains(&a) && f.vertices.contains(&b))
    };
    let mut edges = BTreeSet::new();
    for cell in &linear.cells {
        if !matches!(
            cell.kind,
            hocurve_mesh::ElementType::Tri | hocurve_mesh::ElementType::Tet
        ) {
            continue;
        }
        let n = cell.vertices.len();
        // A simplex's facet k holds every vertex but vertex k.
        let entity: Vec<Option<usize>> = (0..n)
            .map(|skip| {
                let f: Vec<u32> = (0..n)
                    .filter(|&k| k != skip)
                    .map(|k| cell.vertices[k])
                    .collect();
                facet_entity.get(&sorted(&f)).copied()
            })
            .collect();
        for i in 0..n {
            for j in i + 1..n {
                if entity[i].is_none() || entity[i] != entity[j] {
                    continue;
                }
                // Facets i and j share every vertex but i and j: the edge (i, j) is opposite
                // their common corner (an edge in a tetrahedron, a vertex in a triangle).
                let (a, b) = (cell.vertices[i], cell.vertices[j]);
                if !on_a_facet(a, b) {
                    edges.insert([a.min(b), a.max(b)]);
                }
            }
        }
    }
    edges.into_iter().collect()
}

/// Where an [`Attempt`]'s boundary nodes come from.
enum Boundary<'a> {
    /// Placed on the geometry with these options.
    Place {
        geometry: Geometry<'a>,
        association: &'a hocurve_geodesic::BoundaryAssociation,
        placement: &'a PlacementOptions,
    },
    /// Placed already (by an earlier attempt); the solid stiffened cell by cell.
    Stiffened {
        targets: &'a hocurve_geodesic::BoundaryTargets,
        stiffening: &'a [f64],
    },
}

/// One curving of the mesh: boundary nodes placed, the displacement solved.
struct Attempt {
    /// The curved mesh (the node family of the options until [`Attempt::written`], then
    /// equispaced).
    mesh: HighOrderMesh,
    /// The boundary placement (None: no geometry).
    targets: Option<hocurve_geodesic::BoundaryTargets>,
    /// Largest distance of a curved-boundary node of `mesh` from its entities.
    max_geometry_distance: f64,
    /// Nodes sliding in a plane.
    sliding_nodes: usize,
    /// Solver name, iterations, unknowns, relative residual.
    solve: (String, usize, usize, f64),
    /// The straight-sided positions of `mesh`'s nodes.
    straight: Vec<[f64; 3]>,
}

impl Attempt {
    /// The straight-sided mesh itself.
    fn straight(straight: &HighOrderMesh) -> Self {
        Attempt {
            mesh: straight.clone(),
            targets: None,
            max_geometry_distance: 0.0,
            sliding_nodes: 0,
            solve: (String::from("none"), 0, 0, 0.0),
            straight: straight.nodes.clone(),
        }
    }

    /// Boundary nodes on the geometry (paper Sect. 4.1–4.2), then the elastic solve
    /// (Sect. 4.3) unless `boundary_only`.
    fn curved(
        straight: &HighOrderMesh,
        boundary: Boundary<'_>,
        options: &CurveOptions,
        progress: &mut dyn FnMut(Progress),
        timings: &mut StepTimings,
    ) -> Result<Self, CurveError> {
        let (targets, stiffening) = match boundary {
            Boundary::Place {
                geometry,
                association,
                placement,
            } => {
                progress(Progress::Step(Step::BoundaryNodes));
                let t = Instant::now();
                let targets =
                    place_boundary_nodes_with(straight, geometry.model, association, placement)?;
                timings.boundary_nodes += t.elapsed().as_secs_f64();
                (targets, None)
            }
            Boundary::Stiffened {
                targets,
                stiffening,
            } => (targets.clone(), Some(stiffening)),
        };
        let mut mesh = straight.clone();
        let mut attempt = Attempt::straight(straight);
        if !options.boundary_only {
            progress(Progress::Step(Step::Elasticity));
            let bc = boundary_conditions(&mesh, &targets.targets, &options.slide)?;
            attempt.sliding_nodes = bc.sliding.len();
            let mut report = |p| progress(Progress::Elasticity(p));
            let solution = match stiffening {
                None => solve_displacement_with_progress(
                    &mesh,
                    &options.material,
                    &bc,
                    &options.solver,
                    &mut report,
                )?,
                Some(stiffening) => solve_displacement_stiffened(
                    &mesh,
                    &options.material,
                    stiffening,
                    &bc,
                    &options.solver,
                    &mut report,
                )?,
            };
            let residual = solution.relative_residual;
            if residual.is_nan() || residual > options.solver.tolerance.max(1e-8) {
                return Err(CurveError::NotConverged {
                    residual: solution.relative_residual,
                    tolerance: options.solver.tolerance,
                    iterations: solution.iterations,
                });
            }
            timings.assembly += solution.timings.assembly;
            timings.solve += solution.timings.solve;
            for (x, u) in mesh.nodes.iter_mut().zip(&solution.displacement) {
                for d in 0..3 {
                    x[d] += u[d];
                }
            }
            let solver = match solution.solver_used {
                SolverKind::Direct => "direct",
                SolverKind::Cg => "cg",
                SolverKind::Auto => "auto",
            };
            attempt.solve = (
                solver.to_string(),
                solution.iterations,
                solution.dofs,
                solution.relative_residual,
            );
        }
        // Boundary nodes exactly on their targets, not up to the solver's round-off.
        for (&n, &x) in &targets.targets {
            mesh.nodes[n as usize] = x;
        }
        attempt.max_geometry_distance = targets.max_geometry_distance;
        attempt.mesh = mesh;
        attempt.targets = Some(targets);
        Ok(attempt)
    }

    /// The mesh as it is written: equispaced nodes interpolated from the family used
    /// inside, curved-boundary nodes projected back onto their entities (the interpolant
    /// leaves the surface between on-surface nodes), and the distance measured on them.
    fn written(
        mut self,
        linear: &LinearMesh,
        options: &CurveOptions,
        geometry: Option<Geometry>,
        timings: &mut StepTimings,
    ) -> Result<Self, CurveError> {
        let t = Instant::now();
        if self.mesh.family != NodeFamily::Equispaced {
            let resampled = self.mesh.resampled(NodeFamily::Equispaced)?;
            // Vertices are nodes of every family: keep them bit for bit rather than
            // through the interpolant's round-off.
            let vertices = self.mesh.layout.num_vertices;
            let mut nodes = resampled.nodes;
            nodes[..vertices].copy_from_slice(&self.mesh.nodes[..vertices]);
            self.mesh = HighOrderMesh { nodes, ..resampled };
            self.straight =
                HighOrderMesh::from_linear(linear, options.order, NodeFamily::Equispaced)?.nodes;
        }
        if let (Some(geometry), Some(targets)) = (geometry, &self.targets) {
            self.max_geometry_distance = project_nodes_onto_geometry(
                geometry.model,
                &targets.entities,
                &mut self.mesh.nodes,
            )?;
        }
        timings.boundary_nodes += t.elapsed().as_secs_f64();
        Ok(self)
    }

    /// The curved mesh with its quality and report.
    fn finish(
        self,
        options: &CurveOptions,
        association: Option<&hocurve_geodesic::BoundaryAssociation>,
        quality: MeshQuality,
        undone_corrections: usize,
        timings: StepTimings,
    ) -> CurvedMesh {
        let mesh = self.mesh;
        let displacement = mesh
            .nodes
            .iter()
            .zip(&self.straight)
            .map(|(x, x0)| [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]])
            .collect();
        let summary = &quality.summary;
        let targets = self.targets.unwrap_or_default();
        let report = CurveReport {
            order: options.order,
            node_family: options.family.to_string(),
            elements: mesh.cells.len(),
            nodes: mesh.nodes.len(),
            dofs: self.solve.2,
            curved_facets: targets.curved_facets,
            facets_by_name: association.map_or(0, |a| a.by_name),
            facets_by_proximity: association.map_or(0, |a| a.by_proximity),
            facets_straight: association.map_or(0, |a| a.unassociated),
            geometry_tolerance: association.map_or(0.0, |a| a.tolerance),
            max_vertex_move: association.map_or(0.0, |a| a.max_vertex_move),
            boundary_nodes_on_geometry: targets.targets.len(),
            max_geometry_distance: self.max_geometry_distance,
            small_angle_edges: targets.small_angle_edges,
            corrected_edges: targets.corrected_edges,
            min_edge_angle_degrees: targets.min_edge_angle_degrees,
            corrections_undone: undone_corrections,
            edges_split: 0,
            quadrilaterals_split: 0,
            doubly_curved_cells: Vec::new(),
            uncertified_after_solve: 0,
            stiffened_resolve: None,
            untangled_elements: 0,
            untangle_rounds: 0,
            unused_node_tags: Vec::new(),
            sliding_nodes: self.sliding_nodes,
            solver: self.solve.0,
            iterations: self.solve.1,
            residual: self.solve.3,
            min_scaled_jacobian: summary.min_scaled_jacobian,
            invalid_elements: invalid_elements(&quality),
            certified_valid_elements: summary.validity.as_ref().map(|v| v.valid),
            undecided_elements: summary.validity.as_ref().map(|v| v.undecided),
            min_scaled_jacobian_lower_bound: summary
                .validity
                .as_ref()
                .and_then(|v| v.min_scaled_jacobian_lower_bound),
            fraction_above_0_95: summary.fraction_above_0_95,
            elements_below_0_5: summary.elements_below_0_5,
            max_stretching: summary.max_stretching,
            timings,
        };
        CurvedMesh {
            mesh,
            displacement,
            quality,
            report,
            split_input: None,
        }
    }
}

/// The edges `attempt` rebuilt by the minimum-angle correction (Fig. 4) that `placement`
/// did not ask to leave alone.
fn active_corrections(attempt: &Attempt, placement: &PlacementOptions) -> BTreeSet<[u32; 2]> {
    attempt
        .targets
        .as_ref()
        .map_or_else(BTreeSet::new, |targets| {
            targets
                .corrected_edge_vertices
                .iter()
                .copied()
                .filter(|e| !placement.uncorrected_edges.contains(e))
                .collect()
        })
}

/// The `corrected` edges of `mesh` with a cell on them that is not better certified with
/// the corrections than without any (scaled-Jacobian bounds per cell `with` and `without`):
/// a correction has to earn its place on every element it touches.
fn corrections_not_helping(
    mesh: &HighOrderMesh,
    corrected: &BTreeSet<[u32; 2]>,
    with: &[f64],
    without: &[f64],
) -> BTreeSet<[u32; 2]> {
    let mut losers = BTreeSet::new();
    for (e, cell) in mesh.cells.iter().enumerate() {
        if with[e] > without[e] {
            continue;
        }
        let vertices = &cell.nodes[..cell.kind.num_vertices()];
        for (i, &a) in vertices.iter().enumerate() {
            for &b in &vertices[i + 1..] {
                let key = [a.min(b), a.max(b)];
                if corrected.contains(&key) {
                    losers.insert(key);
                }
            }
        }
    }
    losers
}

/// Each element's certified lower bound of the scaled Jacobian, or its sampled minimum when
/// the mesh was not certified; NaN (degenerate) counts as −∞.
fn certified_scaled_jacobians(quality: &MeshQuality) -> Vec<f64> {
    let value = |e: usize| match &quality.validity {
        Some(checks) => checks[e].scaled_jacobian_lower_bound,
        None => quality.scaled_jacobian[e],
    };
    (0..quality.scaled_jacobian.len())
        .map(|e| {
            let v = value(e);
            if v.is_nan() {
                f64::NEG_INFINITY
            } else {
                v
            }
        })
        .collect()
}

/// [`assess`] with the Bézier validity check when `options.certify` asks for it and the
/// mesh's order supports it (see [`hocurve_quality::bezier_check_supported`]; else without:
/// the report then says "not certified"). Measured (release, 2 cores): 0.24 s on the p = 4
/// sphere (5695 tets), 2.3 s and 9.8 s on a 1493-tet sphere at p = 7 and 8 (its elastic
/// solve: 20 s and 55 s), 0.31 s on a hybrid hex/prism mesh at p = 5 (426 cells).
fn assess_certified(
    mesh: &HighOrderMesh,
    options: &CurveOptions,
) -> Result<MeshQuality, QualityError> {
    if !options.certify || options.quality.bezier.is_some() {
        return assess(mesh, &options.quality);
    }
    let certified = QualityOptions {
        bezier: Some(BezierOptions::default()),
        ..options.quality
    };
    match assess(mesh, &certified) {
        Err(QualityError::UnsupportedBezierDegree { .. }) => assess(mesh, &options.quality),
        other => other,
    }
}

/// Number of [`invalid_cells`].
fn invalid_elements(quality: &MeshQuality) -> usize {
    invalid_cells(quality).len()
}

/// The cells (indices into `mesh.cells`, i.e. input order) where det J ≤ 0 was found:
/// sampled Ĩ ≤ 0 (or NaN: degenerate) or a negative point of the Bézier check.
pub fn invalid_cells(quality: &MeshQuality) -> Vec<usize> {
    (0..quality.scaled_jacobian.len())
        .filter(|&e| {
            quality.scaled_jacobian[e].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
                || quality
                    .validity
                    .as_ref()
                    .is_some_and(|v| v[e].validity == Validity::Invalid)
        })
        .collect()
}

/// The Dirichlet and sliding data of the elastic analogy: nodes with a target on the
/// geometry move to it; nodes of `slide` groups slide in the group's plane; every other
/// boundary node is fixed. Precedence: curved target, then fixed (a node shared by a sliding
/// and a fixed facet, or by two sliding planes, stays put), then sliding.
fn boundary_conditions(
    mesh: &HighOrderMesh,
    targets: &BTreeMap<u32, [f64; 3]>,
    slide: &[String],
) -> Result<BoundaryConditions, CurveError> {
    // Topology facet → sliding normal, per requested group.
    let mut slide_normal: BTreeMap<usize, [f64; 3]> = BTreeMap::new();
    for name in slide {
        let facets = group_facets(mesh, name)?;
        let normal = plane_normal(mesh, name, &facets)?;
        for f in facets {
            slide_normal.insert(mesh.facet_ids[f] as usize, normal);
        }
    }
    let mut fixed = BTreeSet::new();
    let mut sliding: BTreeMap<u32, [f64; 3]> = BTreeMap::new();
    for (facet, nodes) in mesh.boundary_facet_nodes()? {
        match slide_normal.get(&facet) {
            None => fixed.extend(nodes),
            Some(normal) => {
                for n in nodes {
                    match sliding.get(&n) {
                        Some(m) if !parallel(m, normal) => {
                            fixed.insert(n);
                        }
                        _ => {
                            sliding.insert(n, *normal);
                        }
                    }
                }
            }
        }
    }
    let mut bc = BoundaryConditions::default();
    for n in fixed {
        bc.prescribed.insert(n, [0.0; 3]);
    }
    for (&n, &x) in targets {
        let x0 = mesh.nodes[n as usize];
        bc.prescribed
            .insert(n, [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]]);
    }
    bc.sliding = sliding
        .into_iter()
        .filter(|(n, _)| !bc.prescribed.contains_key(n))
        .collect();
    Ok(bc)
}

fn parallel(a: &[f64; 3], b: &[f64; 3]) -> bool {
    norm(cross(*a, *b)) <= 1e-10 * norm(*a) * norm(*b)
}

/// Indices into `mesh.facets` of the boundary group `name` (dimension dim − 1).
fn group_facets(mesh: &HighOrderMesh, name: &str) -> Result<Vec<usize>, CurveError> {
    let facet_dim = mesh.dim - 1;
    let tags: Vec<i32> = mesh
        .physical_groups
        .iter()
        .filter(|g| g.dim == facet_dim && g.name == name)
        .map(|g| g.tag)
        .collect();
    let facets: Vec<usize> = mesh
        .facets
        .iter()
        .enumerate()
        .filter(|(_, f)| {
            mesh.entity_physicals
                .get(&(facet_dim, f.entity))
                .is_some_and(|p| p.iter().any(|t| tags.contains(t)))
        })
        .map(|(i, _)| i)
        .collect();
    if facets.is_empty() {
        let available: Vec<&str> = mesh
            .physical_groups
            .iter()
            .filter(|g| g.dim == facet_dim)
            .map(|g| g.name.as_str())
            .collect();
        return Err(CurveError::UnknownSlideGroup {
            name: name.to_string(),
            available: if available.is_empty() {
                "no named boundary groups".to_string()
            } else {
                available.join(", ")
            },
        });
    }
    Ok(facets)
}

/// The unit normal of the plane (line in 2D) through the vertices of `facets`, checked.
fn plane_normal(
    mesh: &HighOrderMesh,
    name: &str,
    facets: &[usize],
) -> Result<[f64; 3], CurveError> {
    let vertices: BTreeSet<u32> = facets
        .iter()
        .flat_map(|&f| {
            let facet = &mesh.facets[f];
            let corners = facet.kind.num_vertices();
            facet.nodes[..corners].to_vec()
        })
        .collect();
    let points: Vec<[f64; 3]> = vertices.iter().map(|&v| mesh.nodes[v as usize]).collect();
    let count = points.len() as f64;
    let mut centre = [0.0; 3];
    for p in &points {
        for d in 0..3 {
            centre[d] += p[d] / count;
        }
    }
    // Summed facet normals: area-weighted in 3D (cross products of corner fans), edge
    // normals in 2D.
    let mut normal = [0.0; 3];
    for &f in facets {
        let facet = &mesh.facets[f];
        let corners = facet.kind.num_vertices();
        let x: Vec<[f64; 3]> = facet.nodes[..corners]
            .iter()
            .map(|&n| mesh.nodes[n as usize])
            .collect();
        if mesh.dim == 2 {
            let t = [x[1][0] - x[0][0], x[1][1] - x[0][1]];
            // Orientation-free: make the normal point the same way as the running sum.
            let n = [t[1], -t[0], 0.0];
            let sign = if n[0] * normal[0] + n[1] * normal[1] < 0.0 {
                -1.0
            } else {
                1.0
            };
            normal[0] += sign * n[0];
            normal[1] += sign * n[1];
        } else {
            for k in 1..corners - 1 {
                let a = sub(x[k], x[0]);
                let b = sub(x[k + 1], x[0]);
                let n = cross(a, b);
                let sign = if dot(n, normal) < 0.0 { -1.0 } else { 1.0 };
                for d in 0..3 {
                    normal[d] += sign * n[d];
                }
            }
        }
    }
    let length = norm(normal);
    let size = points
        .iter()
        .map(|p| norm(sub(*p, centre)))
        .fold(0.0, f64::max);
    if length.is_nan() || length <= 0.0 {
        return Err(CurveError::SlideGroupNotPlanar {
            name: name.to_string(),
            distance: f64::NAN,
        });
    }
    let normal = normal.map(|v| v / length);
    let distance = points
        .iter()
        .map(|p| dot(sub(*p, centre), normal).abs())
        .fold(0.0, f64::max);
    if distance > 1e-8 * size.max(f64::MIN_POSITIVE) {
        return Err(CurveError::SlideGroupNotPlanar {
            name: name.to_string(),
            distance,
        });
    }
    Ok(normal)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_mesh::{Element, ElementType};

    /// One p = 4 tetrahedron (equispaced nodes) whose first edge node (edge 0–1) is pulled
    /// 40 % of the way to vertex 0 (sampled Ĩ = 0.24, true min det J / max det J = −0.39): det J < 0 only in a small region at that vertex, which the interior
    /// quadrature points of the paper's Ĩ do not reach.
    fn tet_inverted_at_a_vertex() -> HighOrderMesh {
        let linear = LinearMesh {
            dim: 3,
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            cells: vec![Element {
                kind: ElementType::Tet,
                vertices: vec![0, 1, 2, 3],
                entity: 1,
            }],
            ..Default::default()
        };
        let mut mesh = HighOrderMesh::from_linear(&linear, 4, NodeFamily::Equispaced).unwrap();
        let cell = &mesh.cells[0];
        let (v0, first_edge_node) = (cell.nodes[0] as usize, cell.nodes[4] as usize);
        let (a, b) = (mesh.nodes[v0], mesh.nodes[first_edge_node]);
        // Check the assumption: node 4 lies on the edge from vertex 0 to vertex 1.
        assert!(
            b[1] == 0.0 && b[2] == 0.0 && b[0] > 0.0 && b[0] < 0.5,
            "{b:?}"
        );
        mesh.nodes[first_edge_node] = [b[0] + 0.4 * (a[0] - b[0]), 0.0, 0.0];
        mesh
    }

    /// One tetrahedron 0 1 2 3 with the facets 0 1 2 and 0 1 3 declared.
    fn tet_with_two_facets() -> LinearMesh {
        let facet = |v: [u32; 3]| Element {
            kind: ElementType::Tri,
            vertices: v.to_vec(),
            entity: 1,
        };
        LinearMesh {
            dim: 3,
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            cells: vec![Element {
                kind: ElementType::Tet,
                vertices: vec![0, 1, 2, 3],
                entity: 1,
            }],
            facets: vec![facet([0, 1, 2]), facet([0, 3, 1])],
            ..Default::default()
        }
    }

    fn association(facet_entity: Vec<Option<usize>>) -> hocurve_geodesic::BoundaryAssociation {
        hocurve_geodesic::BoundaryAssociation {
            facet_entity,
            vertex_targets: BTreeMap::new(),
            vertex_entities: BTreeMap::new(),
            tolerance: 0.0,
            by_name: 2,
            by_proximity: 0,
            unassociated: 0,
            max_vertex_move: 0.0,
        }
    }

    #[test]
    fn a_cell_with_two_facets_on_one_entity_has_its_opposite_edge_split() {
        let mesh = tet_with_two_facets();
        // Both facets on entity 0: they share the edge 0 1; the opposite edge is 2 3.
        let edges = edges_opposite_doubly_curved_corners(&mesh, &association(vec![Some(0); 2]));
        assert_eq!(edges, vec![[2, 3]]);
        // On different entities (a feature edge between two surfaces), or one straight:
        // nothing to split.
        for entities in [vec![Some(0), Some(1)], vec![Some(0), None]] {
            let edges = edges_opposite_doubly_curved_corners(&mesh, &association(entities));
            assert!(edges.is_empty());
        }
        // An opposite edge on a declared facet is left alone (its midpoint would be a new
        // boundary vertex off the geometry).
        let mut with_third = mesh.clone();
        with_third.facets.push(Element {
            kind: ElementType::Tri,
            vertices: vec![1, 2, 3],
            entity: 2,
        });
        let edges = edges_opposite_doubly_curved_corners(
            &with_third,
            &association(vec![Some(0), Some(0), None]),
        );
        assert!(edges.is_empty());
    }

    #[test]
    fn certification_finds_inversions_the_sampled_scaled_jacobian_misses() {
        let mesh = tet_inverted_at_a_vertex();
        let mut options = CurveOptions::new(4);
        options.certify = false;
        let sampled = assess_certified(&mesh, &options).unwrap();
        assert!(sampled.validity.is_none());
        assert!(
            sampled.scaled_jacobian[0] > 0.0,
            "{:?}",
            sampled.scaled_jacobian
        );
        assert_eq!(invalid_elements(&sampled), 0);

        options.certify = true;
        let certified = assess_certified(&mesh, &options).unwrap();
        let checks = certified.validity.as_ref().unwrap();
        assert_eq!(checks[0].validity, Validity::Invalid);
        assert!(checks[0].scaled_jacobian_lower_bound < 0.0);
        assert_eq!(invalid_elements(&certified), 1);
    }

    #[test]
    fn a_correction_goes_when_one_element_on_its_edge_is_not_better_certified() {
        // Two tetrahedra sharing the face 0 1 3; edge 1 2 is on the first only.
        let mut linear = tet_with_two_facets();
        linear.vertices.push([0.0, -1.0, 0.0]);
        linear.cells.push(Element {
            kind: ElementType::Tet,
            vertices: vec![0, 1, 3, 4],
            entity: 1,
        });
        let mesh = HighOrderMesh::from_linear(&linear, 1, NodeFamily::Equispaced).unwrap();
        let corrected = BTreeSet::from([[0, 1], [1, 2], [2, 3]]);
        let losers = |with: [f64; 2], without: [f64; 2]| {
            corrections_not_helping(&mesh, &corrected, &with, &without)
        };
        // Both better: all kept.
        assert!(losers([0.5, 0.4], [0.4, 0.3]).is_empty());
        // The second no better (equal): the shared edge goes, those on the first stay.
        assert_eq!(losers([0.5, 0.3], [0.4, 0.3]), BTreeSet::from([[0, 1]]));
        // The first worse: every corrected edge on it goes.
        assert_eq!(losers([0.3, 0.4], [0.4, 0.3]), corrected);
        // Degenerate (NaN) bounds count as the worst.
        let mut q = assess(&mesh, &QualityOptions::default()).unwrap();
        q.scaled_jacobian[1] = f64::NAN;
        let bounds = certified_scaled_jacobians(&q);
        assert_eq!(bounds[1], f64::NEG_INFINITY);
        assert!(bounds[0] > 0.9);
    }
}
