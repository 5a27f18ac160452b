//! What a curving run reports: sizes, the boundary's association and distance to the
//! geometry, corrections, the solve, quality and certification, the repair, and seconds
//! per step (serialised as the JSON report).

use serde::Serialize;

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
    /// Of `solve`: the preconditioner's set-up (coarser p-multigrid levels, the p = 1
    /// factorisation, the smoothers); 0 for the direct solver.
    pub solve_setup: f64,
    /// Of `solve`: the CG iterations; 0 for the direct solver.
    pub solve_iterations: f64,
    /// Quality assessment.
    pub quality: f64,
    /// The repair of elements not certified valid: the stiffened re-solve and untangling,
    /// each with its certification.
    pub repair: f64,
    /// Writing the output.
    pub write: f64,
    /// Wall time of everything above.
    pub total: f64,
}

/// The machine-readable account of one curving run (`hocurve curve --report`).
/// A boundary group whose nodes slide.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SlidingGroup {
    /// The physical group's name.
    pub name: String,
    /// Sliding by default rather than by `--slide`.
    pub by_default: bool,
}

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
    /// Cells in the elastic solve: all of them, or the active region around the curved
    /// boundaries (`--solve-region active`); 0 without a solve.
    pub solve_cells: usize,
    /// Elastic solves run for this curving: 1, or one per active region tried.
    pub elastic_solves: usize,
    /// Boundary facets placed on the geometry.
    pub curved_facets: usize,
    /// Boundary facets associated with an entity by physical-group name.
    pub facets_by_name: usize,
    /// Boundary facets associated with an entity by proximity (IGES).
    pub facets_by_proximity: usize,
    /// Boundary facets on no entity (kept straight, fixed).
    pub facets_straight: usize,
    /// Boundary facets of the cells that the file did not declare, found from the cells
    /// and curved with the rest (not written: the file gets no elements it did not have).
    pub undeclared_facets: usize,
    /// 2D cells numbered clockwise by their surface, written counter-clockwise.
    pub reoriented_cells: usize,
    /// Association tolerance used (largest vertex distance from its entity).
    pub geometry_tolerance: f64,
    /// Largest distance a boundary vertex was moved to lie on the geometry.
    pub max_vertex_move: f64,
    /// Boundary nodes given a target on the geometry.
    pub boundary_nodes_on_geometry: usize,
    /// Largest distance of a boundary node from its geometry entity.
    pub max_geometry_distance: f64,
    /// Largest distance of a boundary node from its entities beyond their own separation
    /// there: nodes on the common edge of faces that the geometry file says meet only to
    /// its uncertainty (`geometry_uncertainty`) cannot be on both. Equal to
    /// `max_geometry_distance` where the faces meet; what "on the geometry" is judged by.
    pub distance_beyond_seams: f64,
    /// Largest separation of the entities at a boundary node on several (0 where they meet,
    /// or where the file states no uncertainty); honoured up to `geometry_uncertainty`.
    pub max_seam_gap: f64,
    /// The distance to which the geometry file says its entities meet (STEP's uncertainty,
    /// IGES's minimum resolution), None when it states none.
    pub geometry_uncertainty: Option<f64>,
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
    /// Valid elements certified below [`crate::repair::RESHAPE_BELOW`] (or the option's
    /// threshold) whose patches were reshaped, raising the certified min Ĩ (0: none, or
    /// the reshaping did not help and was undone).
    pub reshaped_elements: usize,
    /// The certified min Ĩ before that reshaping (None when none was kept).
    pub reshaped_from: Option<f64>,
    /// The threshold of the reshaping (0: off).
    pub reshape_below: f64,
    /// Interior edges split: before curving, those opposite the corner of two facets of a
    /// cell on one curved entity (curving would open it to 180°, det J = 0) and those
    /// opposite a tetrahedron's corner that curving flattens (its three edges on curved
    /// facets with one tangent plane at the vertex); after it, the longest chords of cells
    /// no repair certified (see `refinement_rounds`).
    pub edges_split: usize,
    /// Rounds of splitting the longest chords of elements not certified (or certified
    /// poorly) and curving again (at most [`crate::pipeline::REFINEMENT_ROUNDS`]); their
    /// edges count in `edges_split`.
    pub refinement_rounds: usize,
    /// Elements that started the first refinement round: not certified after the
    /// (stiffened) solve, each with a chord to split, or certified below
    /// [`crate::pipeline::REFINE_BELOW`] after the repair of the first curving.
    pub refined_elements: usize,
    /// Boundary edges split by the refinement rounds, the new vertex on the geometry: the
    /// longest edge on curved facets of each element not certified that has no chord (its
    /// boundary edges all on facets: a facet spanning too much of a fillet or a hole's rim).
    pub facet_edges_split: usize,
    /// Quadrilaterals split into two triangles before curving (two of their edges, meeting
    /// at a corner, lay on one curved entity: curved, that corner opens to 180°).
    pub quadrilaterals_split: usize,
    /// Boundary edges split before curving, the new vertex on their surface: the third edge
    /// of a facet whose other two lie on one feature curve (a coarsely split rim), which
    /// would meet at 180° once curved; and a facet edge opposite the edge where two facets
    /// of a tetrahedron on one curved surface meet (a diameter of a coarse rod); and a facet
    /// edge opposite a corner that curving flattens where no interior edge is there.
    pub surface_edges_split: usize,
    /// Mesh edges where curved faces meet (on two or more surfaces) placed on the model's
    /// own curve there: a CAD edge of a STEP model, or a curve entity.
    pub feature_edges_on_model_curves: usize,
    /// Mesh edges where curved faces meet placed on their traced intersection (no model
    /// curve through both vertices).
    pub feature_edges_traced: usize,
    /// Hexahedra and prisms (indices into the curved mesh's cells) with two faces on one
    /// curved entity meeting along an edge: not split (it would not be conforming), they
    /// get det J = 0 along that edge and cannot be certified. Not in the JSON, which
    /// names them by tag ([`Self::doubly_curved_cell_tags`]).
    #[serde(skip)]
    pub doubly_curved_cells: Vec<usize>,
    /// The input's element tags of [`Self::doubly_curved_cells`].
    pub doubly_curved_cell_tags: Vec<u64>,
    /// Tags of the input nodes no cell uses, left out of the curved mesh.
    pub unused_node_tags: Vec<u64>,
    /// Nodes sliding in a plane or along a line (`--slide`, and groups sliding by default).
    pub sliding_nodes: usize,
    /// The boundary groups that slide, each flagged when it slides by default (made of
    /// planes and meeting a curved boundary; `--fix` keeps it fixed).
    pub sliding_groups: Vec<SlidingGroup>,
    /// Boundary-layer columns (thin cells stacked on a curved wall facet) whose nodes moved
    /// with the wall instead of being solved for (`--elastic-layers` turns this off).
    pub layer_columns: usize,
    /// Cells in those columns.
    pub layer_column_cells: usize,
    /// Whether the mesh has boundary-layer structure and was solved with each cell's
    /// stiffness scaled by 1/|J| of its straight shape from the start
    /// ([`crate::repair::has_boundary_layer`]; `--uniform-stiffness` turns this off).
    pub layer_stiffening: bool,
    /// Solver used: `direct`, `cg` or `none`.
    pub solver: String,
    /// CG iterations (0 for the direct solver).
    pub iterations: usize,
    /// Relative residual ‖f − Ku‖ / ‖f‖ of the solve (0 without a solve).
    pub residual: f64,
    /// When CG stopped because its estimated displacement error fell below this length
    /// (10⁻⁴ of the shortest edge, × (4/p)² above p = 4) before the residual reached its
    /// tolerance: the bound.
    pub displacement_error_bound: Option<f64>,
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
    /// Peak resident memory of the process in MB (`VmHWM` of /proc/self/status, read after
    /// writing the mesh); None where the system does not tell.
    pub peak_memory_mb: Option<f64>,
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
