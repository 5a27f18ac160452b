//! One curving of the mesh: the boundary nodes placed on the geometry (or taken from an
//! earlier placement), the elastic solve (uniform or stiffened), the mesh as written
//! (equispaced nodes, boundary nodes projected back onto the geometry), and its certified
//! quality.

use std::collections::BTreeMap;
use std::time::Instant;

use hocurve_elastic::{
    solve_displacement_from, solve_displacement_stiffened, solve_displacement_with_progress,
    BoundaryConditions, ElasticSolution, SolverKind, SolverOptions,
};
use hocurve_geodesic::{
    place_boundary_nodes_reusing, project_nodes_onto_geometry, FeatureTraces, GeometryDistance,
    PlacementOptions,
};
use hocurve_mesh::{HighOrderMesh, LinearMesh};
use hocurve_nodes::NodeFamily;
use hocurve_quality::MeshQuality;
use hocurve_untangle::NodeConstraint;

use crate::active_region::{solve_in_active_region, solve_whole_mesh, SolveRegion};
use crate::boundary_conditions::{boundary_conditions, sliding_groups};
use crate::certification::{affine_cells, assess_certified_with_affine, invalid_elements};
use crate::layer_columns::{layer_columns, layer_columns_by};
use crate::pipeline::{CurveError, CurveOptions, CurvedMesh, Geometry, Progress, Step};
use crate::report::{CurveReport, SlidingGroup, StepTimings};

/// The displacement error CG may leave up to p = 4, relative to the shortest edge of the
/// mesh: it changes any element's Jacobian by about this fraction (boundary nodes are exact,
/// the elastic field only moves interior nodes), below the four digits the quality is
/// reported to, and every element is certified on the written nodes afterwards. Measured on
/// the boundary-layer tetrahedra (`fixtures/cad/sphere_layers`, stretch 288, p = 4): 87 / 61
/// / 34 iterations at 1e-6 / 1e-4 / 1e-2 with the certified min Ĩ 0.7369 / 0.7369 / 0.7367.
const DISPLACEMENT_ACCURACY: f64 = 1e-4;
/// The order up to which [`DISPLACEMENT_ACCURACY`] was measured.
const ACCURACY_ORDER: f64 = 4.0;

/// `options` with, unless set, CG's displacement tolerance tied to the shortest edge h of
/// `mesh` and to its order p: [`DISPLACEMENT_ACCURACY`] h, times (4/p)² above p = 4. An
/// error of size e in the nodal field changes the Jacobian by up to about p² e / h (Markov's
/// inequality for the derivative of a degree-p polynomial), so above the order where the
/// accuracy was measured the tolerance shrinks like 1/p². Measured on `fixtures/hybrid` at
/// p = 8: with 1e-4 h, 16 hexahedra came out of the solve undecided by the Bézier check (32 s
/// of subdivision, then a repair solve); with the factor 1/4, one more CG iteration, every
/// element certified at once.
fn solver_options(options: &SolverOptions, mesh: &HighOrderMesh) -> SolverOptions {
    let mut options = options.clone();
    if options.displacement_tolerance.is_none() {
        let shortest = mesh.shortest_edge().unwrap_or(f64::NAN);
        if shortest.is_finite() && shortest > 0.0 {
            let order_factor = (ACCURACY_ORDER / (mesh.order as f64).max(ACCURACY_ORDER)).powi(2);
            options.displacement_tolerance = Some(DISPLACEMENT_ACCURACY * shortest * order_factor);
        }
    }
    options
}

/// Where an [`Attempt`]'s boundary nodes come from (`'g` the geometry's lifetime).
pub(crate) enum Boundary<'a, 'g> {
    /// Placed on the geometry with these options, feature curves reused from `traces`.
    Place {
        geometry: Geometry<'g>,
        association: &'a hocurve_geodesic::BoundaryAssociation,
        placement: &'a PlacementOptions,
        traces: &'a FeatureTraces<'g>,
    },
    /// Placed already (by an earlier attempt); the solid stiffened cell by cell, CG started
    /// from `initial` (the earlier attempt's [`Attempt::solved_displacement`]) unless empty.
    Stiffened {
        targets: &'a hocurve_geodesic::BoundaryTargets,
        stiffening: &'a [f64],
        initial: &'a [[f64; 3]],
    },
}

/// One curving of the mesh: boundary nodes placed, the displacement solved.
pub(crate) struct Attempt {
    /// The curved mesh (the node family of the options until [`Attempt::written`], then
    /// equispaced).
    pub(crate) mesh: HighOrderMesh,
    /// The boundary placement (None: no geometry).
    pub(crate) targets: Option<hocurve_geodesic::BoundaryTargets>,
    /// How far the curved-boundary nodes of `mesh` are from their entities: at most, and
    /// beyond the separation of the entities at nodes on several (the seams of faces the
    /// file says meet only to its uncertainty).
    pub(crate) max_geometry_distance: GeometryDistance,
    /// The geometry file's stated uncertainty (None: none stated, or no geometry).
    pub(crate) uncertainty: Option<f64>,
    /// Nodes sliding in a plane or along a line.
    pub(crate) sliding_nodes: usize,
    /// The groups they slide on.
    pub(crate) sliding_groups: Vec<SlidingGroup>,
    /// How each sliding node may move (for the repair, which must keep it on its plane).
    pub(crate) sliding: BTreeMap<u32, NodeConstraint>,
    /// Boundary-layer columns moved with the wall, and their cells.
    pub(crate) layer_columns: (usize, usize),
    /// Whether the solve scaled each cell's stiffness by 1/|J| (a boundary-layer mesh, or
    /// the repair's second solve).
    pub(crate) stiffened: bool,
    /// Whether that stiffening was chosen for boundary-layer structure.
    pub(crate) layer_stiffened: bool,
    /// Solver name, iterations, unknowns, relative residual.
    pub(crate) solve: (String, usize, usize, f64),
    /// Cells in the elastic solve.
    pub(crate) solve_cells: usize,
    /// Elastic solves run (regions tried).
    pub(crate) solves: usize,
    /// The displacement error bound CG stopped on (None: it stopped on the residual).
    pub(crate) displacement_error_bound: Option<f64>,
    /// The straight-sided positions of `mesh`'s nodes.
    pub(crate) straight: Vec<[f64; 3]>,
    /// The elastic solve's displacement of every node in the options' node family (as
    /// solved, before the mesh is written equispaced): where a re-solve starts. Empty
    /// without a solve, or once dropped.
    pub(crate) solved_displacement: Vec<[f64; 3]>,
}

impl Attempt {
    /// The straight-sided mesh itself.
    pub(crate) fn straight(straight: &HighOrderMesh) -> Self {
        Attempt {
            mesh: straight.clone(),
            targets: None,
            max_geometry_distance: GeometryDistance::default(),
            uncertainty: None,
            sliding_nodes: 0,
            sliding_groups: Vec::new(),
            sliding: BTreeMap::new(),
            layer_columns: (0, 0),
            stiffened: false,
            layer_stiffened: false,
            solve: (String::from("none"), 0, 0, 0.0),
            solve_cells: 0,
            solves: 0,
            displacement_error_bound: None,
            straight: straight.nodes.clone(),
            solved_displacement: Vec::new(),
        }
    }

    /// Boundary nodes on the geometry (paper Sect. 4.1–4.2), then the elastic solve
    /// (Sect. 4.3) unless `boundary_only`.
    pub(crate) fn curved(
        straight: &HighOrderMesh,
        boundary: Boundary<'_, '_>,
        options: &CurveOptions,
        progress: &mut dyn FnMut(Progress),
        timings: &mut StepTimings,
    ) -> Result<Self, CurveError> {
        let mut layer_stiffening: Option<Vec<f64>> = None;
        let (targets, stiffening, initial) = match boundary {
            Boundary::Place {
                geometry,
                association,
                placement,
                traces,
            } => {
                progress(Progress::Step(Step::BoundaryNodes));
                let t = Instant::now();
                let targets = place_boundary_nodes_reusing(
                    straight,
                    geometry.model,
                    association,
                    placement,
                    traces,
                )?;
                timings.boundary_nodes += t.elapsed().as_secs_f64();
                let layered = options.layer_stiffening
                    && !options.boundary_only
                    && crate::repair::has_boundary_layer(straight, &targets.targets)?;
                layer_stiffening = layered.then(|| crate::repair::jacobian_stiffening(straight));
                (targets, layer_stiffening.as_deref(), None)
            }
            Boundary::Stiffened {
                targets,
                stiffening,
                initial,
            } => (
                targets.clone(),
                Some(stiffening),
                (initial.len() == straight.nodes.len()).then_some(initial),
            ),
        };
        let mut mesh = straight.clone();
        let mut attempt = Attempt::straight(straight);
        attempt.stiffened = stiffening.is_some();
        attempt.layer_stiffened = layer_stiffening.is_some();
        if !options.boundary_only {
            progress(Progress::Step(Step::Elasticity));
            let groups = sliding_groups(&mesh, &targets.targets, &options.slide, &options.fix)?;
            let names: Vec<String> = groups.iter().map(|(n, _)| n.clone()).collect();
            let mut bc = boundary_conditions(&mesh, &targets.targets, &names)?;
            if options.layer_columns {
                let columns = layer_columns(&mesh, &targets.targets)?;
                columns.prescribe(&mut bc);
                attempt.layer_columns = (columns.columns, columns.cells);
            }
            attempt.sliding_nodes = bc.sliding.len() + bc.along_line.len();
            attempt.sliding = sliding_constraints(&bc);
            attempt.sliding_groups = groups
                .into_iter()
                .map(|(name, by_default)| SlidingGroup { name, by_default })
                .collect();
            let mut report = |p| progress(Progress::Elasticity(p));
            let mut last_bound = None;
            let mut solve_on = |part: &HighOrderMesh,
                                bc: &BoundaryConditions,
                                stiffening: Option<&[f64]>,
                                initial: Option<&[[f64; 3]]>|
             -> Result<ElasticSolution, CurveError> {
                let solver = solver_options(&options.solver, part);
                last_bound = solver.displacement_tolerance;
                let solution = match (stiffening, initial) {
                    (_, Some(initial)) => solve_displacement_from(
                        part,
                        &options.material,
                        stiffening,
                        bc,
                        initial,
                        &solver,
                        &mut report,
                    )?,
                    (None, None) => solve_displacement_with_progress(
                        part,
                        &options.material,
                        bc,
                        &solver,
                        &mut report,
                    )?,
                    (Some(stiffening), None) => solve_displacement_stiffened(
                        part,
                        &options.material,
                        stiffening,
                        bc,
                        &solver,
                        &mut report,
                    )?,
                };
                let residual = solution.relative_residual;
                let limit = options.solver.tolerance.max(1e-8);
                if residual.is_nan() || (residual > limit && !solution.converged_by_displacement) {
                    return Err(CurveError::NotConverged {
                        residual: solution.relative_residual,
                        tolerance: options.solver.tolerance,
                        iterations: solution.iterations,
                    });
                }
                timings.assembly += solution.timings.assembly;
                timings.solve += solution.timings.solve;
                timings.solve_setup +=
                    solution.timings.coarse_setup + solution.timings.smoother_setup;
                timings.solve_iterations += solution.timings.iterations;
                Ok(solution)
            };
            let region = match options.solve_region {
                SolveRegion::Whole => {
                    solve_whole_mesh(&mesh, &bc, stiffening, initial, 0, &mut solve_on)?
                }
                SolveRegion::Active { cutoff } => {
                    solve_in_active_region(&mesh, &bc, stiffening, cutoff, initial, solve_on)?
                }
            };
            attempt.solve_cells = region.cells;
            attempt.solves = region.solves;
            let solution = region.solution;
            for (x, u) in mesh.nodes.iter_mut().zip(&region.displacement) {
                for d in 0..3 {
                    x[d] += u[d];
                }
            }
            attempt.solved_displacement = region.displacement;
            let solver = match solution.solver_used {
                SolverKind::Direct => "direct",
                SolverKind::Cg => "cg",
                SolverKind::Auto => "auto",
            };
            attempt.displacement_error_bound = if solution.converged_by_displacement {
                last_bound
            } else {
                None
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
        attempt.max_geometry_distance = GeometryDistance {
            max: targets.max_geometry_distance,
            beyond_seams: targets.max_geometry_distance,
            max_seam_gap: 0.0,
        };
        attempt.mesh = mesh;
        attempt.targets = Some(targets);
        Ok(attempt)
    }

    /// The mesh as it is written: equispaced nodes interpolated from the family used
    /// inside, curved-boundary nodes projected back onto their entities (the interpolant
    /// leaves the surface between on-surface nodes), and the distance measured on them.
    pub(crate) fn written(
        mut self,
        linear: &LinearMesh,
        options: &CurveOptions,
        geometry: Option<Geometry>,
        timings: &mut StepTimings,
    ) -> Result<Self, CurveError> {
        let t = Instant::now();
        if self.mesh.family != NodeFamily::Equispaced {
            let mut resampled = self.mesh.resampled(NodeFamily::Equispaced)?;
            // Vertices are nodes of every family: keep them bit for bit rather than
            // through the interpolant's round-off.
            let vertices = self.mesh.layout().num_vertices();
            resampled.nodes[..vertices].copy_from_slice(&self.mesh.nodes[..vertices]);
            self.mesh = resampled;
            // The same cells as `linear`'s: its topology is reused, not rebuilt.
            self.straight = self.mesh.straight_positions_on(
                &linear.vertices,
                options.order,
                NodeFamily::Equispaced,
            )?;
        }
        if let (Some(geometry), Some(targets)) = (geometry, &self.targets) {
            // Where the projection starts from, when boundary-layer columns must follow it.
            let before: Option<BTreeMap<u32, [f64; 3]>> = (self.layer_columns.0 > 0).then(|| {
                targets
                    .entities
                    .keys()
                    .map(|&n| (n, self.mesh.nodes[n as usize]))
                    .collect()
            });
            let distance = project_nodes_onto_geometry(
                geometry.model,
                &targets.entities,
                &targets.equispaced_feature_nodes,
                &mut self.mesh.nodes,
            )?;
            self.max_geometry_distance = distance;
            self.uncertainty = geometry.model.uncertainty;
            if let Some(before) = before {
                // The projection moved the wall's nodes by the interpolant's distance from
                // the geometry, which can exceed a first layer's height: the cells stacked
                // on the wall move with it, as in the solve.
                let nodes = &self.mesh.nodes;
                let columns = layer_columns_by(&self.mesh, |n| {
                    let (b, x) = (before.get(&n)?, nodes[n as usize]);
                    Some([x[0] - b[0], x[1] - b[1], x[2] - b[2]])
                })?;
                for (&n, u) in &columns.displacement {
                    let x = &mut self.mesh.nodes[n as usize];
                    for d in 0..3 {
                        x[d] += u[d];
                    }
                }
            }
        }
        timings.boundary_nodes += t.elapsed().as_secs_f64();
        Ok(self)
    }

    /// The curved mesh with its quality and report.
    pub(crate) fn finish(
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
            solve_cells: self.solve_cells,
            elastic_solves: self.solves,
            curved_facets: targets.curved_facets,
            facets_by_name: association.map_or(0, |a| a.by_name),
            facets_by_proximity: association.map_or(0, |a| a.by_proximity),
            facets_straight: association.map_or(0, |a| a.unassociated),
            // Set by `curve_mesh`, which completes the input.
            undeclared_facets: 0,
            reoriented_cells: 0,
            geometry_tolerance: association.map_or(0.0, |a| a.tolerance),
            max_vertex_move: association.map_or(0.0, |a| a.max_vertex_move),
            boundary_nodes_on_geometry: targets.targets.len(),
            max_geometry_distance: self.max_geometry_distance.max,
            distance_beyond_seams: self.max_geometry_distance.beyond_seams,
            max_seam_gap: self.max_geometry_distance.max_seam_gap,
            geometry_uncertainty: self.uncertainty,
            small_angle_edges: targets.small_angle_edges,
            corrected_edges: targets.corrected_edges,
            min_edge_angle_degrees: targets.min_edge_angle_degrees,
            corrections_undone: undone_corrections,
            edges_split: 0,
            refinement_rounds: 0,
            refined_elements: 0,
            quadrilaterals_split: 0,
            surface_edges_split: 0,
            feature_edges_on_model_curves: targets.feature_edges_on_curves,
            feature_edges_traced: targets.feature_edges_traced,
            facet_edges_split: 0,
            doubly_curved_cells: Vec::new(),
            doubly_curved_cell_tags: Vec::new(),
            uncertified_after_solve: 0,
            stiffened_resolve: None,
            untangled_elements: 0,
            untangle_rounds: 0,
            reshaped_elements: 0,
            reshaped_from: None,
            reshape_below: options.reshape_below,
            unused_node_tags: Vec::new(),
            sliding_nodes: self.sliding_nodes,
            sliding_groups: self.sliding_groups,
            layer_columns: self.layer_columns.0,
            layer_column_cells: self.layer_columns.1,
            layer_stiffening: self.layer_stiffened,
            solver: self.solve.0,
            iterations: self.solve.1,
            residual: self.solve.3,
            displacement_error_bound: self.displacement_error_bound,
            peak_memory_mb: None,
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

/// One curving of `straight` with the boundary `placement` (the straight mesh itself
/// without geometry), in the form it is written, and its certified quality.
pub(crate) fn curve_and_certify(
    linear: &LinearMesh,
    straight: &HighOrderMesh,
    geometry: Option<Geometry>,
    boundary: Option<Boundary<'_, '_>>,
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
    // Cells the solve left straight are affine: measured from their constant det J.
    let affine = affine_cells(&attempt.mesh, &attempt.straight);
    let quality = assess_certified_with_affine(&attempt.mesh, options, Some(&affine))?;
    timings.quality += t.elapsed().as_secs_f64();
    Ok((attempt, quality))
}

/// The motion each sliding node of `bc` is allowed (prescribed nodes have none): in its
/// plane, or along its line, with unit normals and directions.
fn sliding_constraints(bc: &BoundaryConditions) -> BTreeMap<u32, NodeConstraint> {
    let unit = |v: &[f64; 3]| {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        (n > 0.0 && n.is_finite()).then(|| [v[0] / n, v[1] / n, v[2] / n])
    };
    let planes = bc
        .sliding
        .iter()
        .filter_map(|(&node, n)| Some((node, NodeConstraint::Plane(unit(n)?))));
    let lines = bc
        .along_line
        .iter()
        .filter_map(|(&node, d)| Some((node, NodeConstraint::Line(unit(d)?))));
    planes
        .chain(lines)
        .filter(|(node, _)| !bc.prescribed.contains_key(node))
        .collect()
}
