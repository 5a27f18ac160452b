//! The facade's whole job (`hocurve::job`), as a library user calls it: the same checks,
//! refusals and outputs as the command line, without it.

use std::path::{Path, PathBuf};

use hocurve::job::{curve_and_write, read_geometry, Inputs, JobError, JobOptions, Outputs};
use hocurve::pipeline::CurveOptions;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/cad")
        .join(name)
}

fn options(order: usize) -> JobOptions {
    JobOptions {
        curve: CurveOptions::new(order),
        allow_invalid: false,
        ignore_memory_estimate: false,
    }
}

/// Outputs of the mesh alone, at `mesh`.
fn mesh_only(mesh: PathBuf) -> Outputs {
    Outputs {
        mesh,
        report: None,
        plots: None,
        format: Default::default(),
    }
}

/// The inputs of fixture `name`: its mesh and its geometry file `name.ext`.
fn fixture_inputs(name: &str, ext: &str) -> Inputs {
    Inputs::read(
        &fixture(&format!("{name}.msh")),
        Some(&fixture(&format!("{name}.{ext}"))),
    )
    .unwrap()
}

#[test]
fn a_job_writes_the_mesh_the_report_and_the_plots_together() {
    let dir = tempfile::tempdir().unwrap();
    let outputs = Outputs {
        mesh: dir.path().join("sphere.msh"),
        report: Some(dir.path().join("report.json")),
        plots: Some(dir.path().join("plots")),
        format: Default::default(),
    };
    outputs.check().unwrap();
    let inputs = Inputs::read(
        &fixture("sphere_coarse.msh"),
        Some(&fixture("sphere_coarse.json")),
    )
    .unwrap();
    let finished = curve_and_write(&inputs, &options(2), &outputs, &mut |_| {}).unwrap();
    assert!(finished.defects.is_empty());
    let r = &finished.curved.report;
    assert_eq!(r.certified_valid_elements, Some(r.elements));
    // The report describes the file written.
    let written = hocurve::io::read_high_order_mesh(&outputs.mesh).unwrap();
    assert_eq!(written.cells.len(), r.elements);
    assert_eq!(written.nodes.len(), r.nodes);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
            .unwrap();
    assert_eq!(report["elements"].as_u64(), Some(r.elements as u64));
    assert!(report["timings"]["total"].as_f64().unwrap() >= r.timings.write);
    for plot in ["scaled_jacobian.svg", "stretching.svg"] {
        let svg = std::fs::read_to_string(dir.path().join("plots").join(plot)).unwrap();
        assert!(svg.starts_with("<svg"));
    }
}

#[test]
fn a_mesh_that_is_not_certified_is_rejected_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let outputs = Outputs {
        mesh: dir.path().join("thin.vtu"),
        report: Some(dir.path().join("report.json")),
        plots: None,
        format: Default::default(),
    };
    let inputs = Inputs::read(
        &fixture("sphere_layers_thin.msh"),
        Some(&fixture("sphere_layers_thin.json")),
    )
    .unwrap();
    let mut no_repair = options(2);
    no_repair.curve.stiffen = false;
    no_repair.curve.untangle = false;
    no_repair.curve.layer_stiffening = false;
    match curve_and_write(&inputs, &no_repair, &outputs, &mut |_| {}) {
        Err(JobError::Rejected { reason, curved }) => {
            assert!(reason.contains("not certified valid"), "{reason}");
            assert!(reason.contains("input element tag"), "{reason}");
            assert!(curved.report.invalid_elements > 0);
        }
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("an invalid mesh was accepted"),
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // Allowed: written, and the defect still reported.
    no_repair.allow_invalid = true;
    let finished = curve_and_write(&inputs, &no_repair, &outputs, &mut |_| {}).unwrap();
    assert_eq!(finished.defects.len(), 1);
    assert!(outputs.mesh.exists());
}

#[test]
fn outputs_and_geometry_formats_are_checked_by_extension() {
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Outputs {
        mesh: dir.path().join("out.stl"),
        report: None,
        plots: None,
        format: Default::default(),
    };
    assert!(matches!(
        outputs.check(),
        Err(JobError::UnknownOutputFormat { .. })
    ));
    outputs.mesh = dir.path().join("out.vtu");
    let file = dir.path().join("plots");
    std::fs::write(&file, "").unwrap();
    outputs.plots = Some(file);
    assert!(matches!(
        outputs.check(),
        Err(JobError::PlotsFolderIsFile { .. })
    ));
    outputs.plots = Some(dir.path().join("missing/plots"));
    assert!(matches!(outputs.check(), Err(JobError::Io(_))));
    assert!(matches!(
        read_geometry(&dir.path().join("model.sat")),
        Err(JobError::UnknownGeometryFormat { .. })
    ));
    // STEP is read (a missing file is an I/O error of the STEP reader).
    assert!(matches!(
        read_geometry(&dir.path().join("model.step")),
        Err(JobError::Step(_))
    ));
}

/// The same model from STEP and from IGES (both OpenCASCADE's exports) curves to the same
/// mesh to 1e-9 (issue 22): the sphere's nodes by the exact sphere, equal up to round-off;
/// the interior ones through the CG solve, whose f32 smoothers turn the round-off difference
/// of the boundary data into ~1e-11.
#[test]
fn step_and_iges_give_the_same_curved_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let mut nodes = Vec::new();
    for ext in ["igs", "step"] {
        let outputs = Outputs {
            mesh: dir.path().join(format!("sphere_{ext}.msh")),
            report: None,
            plots: None,
            format: Default::default(),
        };
        let inputs = Inputs::read(
            &fixture("sphere_coarse.msh"),
            Some(&fixture(&format!("sphere_coarse.{ext}"))),
        )
        .unwrap();
        let finished = curve_and_write(&inputs, &options(3), &outputs, &mut |_| {}).unwrap();
        assert!(finished.defects.is_empty(), "{ext}: {:?}", finished.defects);
        assert!(finished.curved.report.max_geometry_distance < 1e-12);
        nodes.push(finished.curved.mesh.nodes);
    }
    let gap = nodes[0]
        .iter()
        .zip(&nodes[1])
        .flat_map(|(a, b)| (0..3).map(move |d| (a[d] - b[d]).abs()))
        .fold(0.0, f64::max);
    assert!(gap < 1e-9, "{gap:e}");
}

/// The largest coordinate difference between the nodes curved from STEP (`nodes[0]`) and
/// from IGES (`nodes[1]`), and the model's size (largest coordinate).
fn step_and_iges_gap(name: &str, nodes: &[Vec<[f64; 3]>]) -> (f64, f64) {
    assert_eq!(nodes[0].len(), nodes[1].len(), "{name}");
    let size = nodes[0]
        .iter()
        .map(|x| x[0].abs().max(x[1].abs()).max(x[2].abs()))
        .fold(0.0, f64::max);
    let gap = nodes[0]
        .iter()
        .zip(&nodes[1])
        .flat_map(|(a, b)| (0..3).map(move |d| (a[d] - b[d]).abs()))
        .fold(0.0, f64::max);
    (gap, size)
}

/// Every part curved with the default options from its STEP and from its IGES export (both
/// OpenCASCADE's) gives the same mesh, interior nodes included, to 1e-9 of the model (issue
/// 22): the repair converges its patches' energy by Newton's method rather than stopping
/// where its iterations happen to, and choices between two curvings (a correction kept, a
/// refinement, a reshaping) go by more than round-off. Before, 2e-3 apart (filleted_boss:
/// an untangled patch), 4e-4 (rounded_block), 1e-4 (wing_body: the whole mesh's worst cell,
/// away from the corrections, measured 1e-12 apart with and without them, decided whether
/// they stayed). cone_plate's files put its cone 1e-9 apart: 1e-8 there. (sphere_on_block's
/// two files state different tolerances: not the same model to the reader.) bolted_plate is
/// an assembly whose parts touch: a facet where they do lies on two faces, the nearer by
/// round-off, which differs between the files (111 of its 1152 facets went to different
/// faces, and a feature edge ran between a plate and a block standing on it).
#[test]
fn step_and_iges_curve_every_part_to_the_same_mesh() {
    let dir = tempfile::tempdir().unwrap();
    for (name, order) in [
        ("filleted_boss", 3),
        ("rounded_block", 3),
        ("tee_pipes", 4),
        ("wing_body", 3),
        ("cone_plate", 2),
        ("tangent_vertex", 3),
        ("bolted_plate", 3),
    ] {
        let mut nodes = Vec::new();
        for ext in ["step", "igs"] {
            let outputs = mesh_only(dir.path().join(format!("{name}_{ext}.msh")));
            let finished = curve_and_write(
                &fixture_inputs(name, ext),
                &options(order),
                &outputs,
                &mut |_| {},
            )
            .unwrap_or_else(|e| panic!("{name}.{ext}: {e}"));
            assert!(
                finished.defects.is_empty(),
                "{name}.{ext}: {:?}",
                finished.defects
            );
            nodes.push(finished.curved.mesh.nodes);
        }
        let (gap, size) = step_and_iges_gap(name, &nodes);
        println!("{name} p = {order}: STEP and IGES meshes {gap:.1e} apart (model {size:.1})");
        let files_agree_to = if name == "cone_plate" { 1e-8 } else { 1e-9 };
        assert!(gap < files_agree_to * size, "{name}: {gap:e}");
    }
}

/// The boundary nodes placed from a model's STEP and from its IGES export (both
/// OpenCASCADE's) agree to the files' own agreement: the same faces (IGES tori, spheres and
/// cones recognised on any part of their circle; STEP tori as the band a face covers),
/// the same CAD edges (IGES has them as each face's boundary copies), the same
/// corrections, the same paths along a patch's edge at either end of its range. cone_plate's cone is written 1e-9 apart by the two files (its apex at
/// z = 2.05 in STEP, 2.050000001 from IGES's generatrix), hence 1e-8 of the model. (The
/// whole curving: [`step_and_iges_curve_every_part_to_the_same_mesh`].)
#[test]
fn step_and_iges_place_the_same_boundary_nodes() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "cone_plate",
        "filleted_boss",
        "tee_pipes",
        "twisted_loft",
        "rounded_block",
        "plate_holes",
        "naca_layers_tets",
        "wing_body",
    ] {
        let mut nodes = Vec::new();
        for ext in ["step", "igs"] {
            let outputs = mesh_only(dir.path().join(format!("{name}_{ext}.msh")));
            let inputs = fixture_inputs(name, ext);
            let mut job = options(3);
            job.curve.boundary_only = true;
            job.curve.untangle = false;
            job.curve.stiffen = false;
            job.curve.refine = false;
            job.allow_invalid = true;
            let finished = curve_and_write(&inputs, &job, &outputs, &mut |_| {})
                .unwrap_or_else(|e| panic!("{name}.{ext}: {e}"));
            nodes.push(finished.curved.mesh.nodes);
        }
        let (gap, size) = step_and_iges_gap(name, &nodes);
        println!("{name}: STEP and IGES nodes {gap:.1e} apart (model {size:.1})");
        assert!(gap < 1e-8 * size, "{name}: {gap:e}");
    }
}

/// Coarse parts as Gmsh meshes them by default (`fixtures/make_cad_fixtures.py`): flat faces
/// bounded by hole rims, faces bounded by the saddle curve where two pipes meet. Eq. (6)
/// alone leaves such a face a third of its rim's bulge short of the rim, and at p = 5 (rim
/// bulge about one node spacing) elements fold there: 4 and 2 were left uncertified after
/// every repair. With the face construction meeting its feature edges, all certify.
#[test]
fn coarse_parts_with_faces_bounded_by_feature_curves_certify_at_p5() {
    let dir = tempfile::tempdir().unwrap();
    for (name, ext) in [("plate_holes", "step"), ("tee_pipes", "igs")] {
        let outputs = mesh_only(dir.path().join(format!("{name}.msh")));
        let inputs = fixture_inputs(name, ext);
        let finished = curve_and_write(&inputs, &options(5), &outputs, &mut |_| {})
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            finished.defects.is_empty(),
            "{name}: {:?}",
            finished.defects
        );
        let r = &finished.curved.report;
        assert_eq!(r.certified_valid_elements, Some(r.elements), "{name}");
        assert!(
            r.max_geometry_distance < 1e-12,
            "{name}: {:e}",
            r.max_geometry_distance
        );
    }
}

/// A plate whose bottom face has a mesh vertex on a hole rim's tangent at a rim vertex
/// (`tangent_vertex` in `fixtures/make_cad_fixtures.py`; as1-oc-214.stp, a CAx-IF part, has
/// one beside a slot): the bottom facet through the rim vertex, the next one and that
/// vertex closes its corner to 0° once its rim edge is curved, det J ≤ 0 there whatever the
/// free nodes do. With the minimum-angle correction off, the repair must bend the straight
/// edge within the plane: its nodes slide in their plane face (before: Ĩ ≥ −0.0006 at
/// p = 3 after every repair, refused). They stay on the plane, every element certifies.
#[test]
fn a_facet_closed_by_a_vertex_on_a_rims_tangent_opens_within_its_plane() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = fixture_inputs("tangent_vertex", "step");
    for order in [3, 4] {
        let mut options = options(order);
        options.curve.placement = options.curve.placement.with_min_angle(Some(0.0));
        let outputs = mesh_only(dir.path().join(format!("p{order}.msh")));
        let finished = curve_and_write(&inputs, &options, &outputs, &mut |_| {})
            .unwrap_or_else(|e| panic!("p = {order}: {e}"));
        assert!(finished.defects.is_empty(), "{:?}", finished.defects);
        let r = &finished.curved.report;
        assert_eq!(r.certified_valid_elements, Some(r.elements), "p = {order}");
        assert!(r.untangle_rounds > 0, "p = {order}: nothing was untangled");
        assert!(
            r.max_geometry_distance < 1e-12,
            "p = {order}: {:e}",
            r.max_geometry_distance
        );
    }
}

/// The result is never certified worse than with `--min-angle 0`, refinement included:
/// on `pinned_plate` at p = 2 the first curving keeps one correction and the refinement
/// rounds then take a path that `--min-angle 0` does not; that path ended certified at
/// Ĩ ≥ 0.067012 against 0.067021 without corrections. Now both are curved and the better
/// kept (here the one without corrections, every correction reported undone).
#[test]
fn refinement_never_ends_certified_worse_than_without_corrections() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = fixture_inputs("pinned_plate", "step");
    let run = |min_angle: Option<f64>, file: &str| {
        let mut options = options(2);
        if let Some(angle) = min_angle {
            options.curve.placement = options.curve.placement.with_min_angle(Some(angle));
        }
        let outputs = mesh_only(dir.path().join(file));
        let finished = curve_and_write(&inputs, &options, &outputs, &mut |_| {})
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(finished.defects.is_empty(), "{:?}", finished.defects);
        finished.curved.report
    };
    let corrected = run(None, "corrected.msh");
    let plain = run(Some(0.0), "plain.msh");
    assert!(corrected.refinement_rounds > 0);
    assert!(corrected.corrected_edges + corrected.corrections_undone > 0);
    let bound = |r: &hocurve::report::CurveReport| r.min_scaled_jacobian_lower_bound.unwrap();
    assert!(
        bound(&corrected) >= bound(&plain),
        "{} < {}",
        bound(&corrected),
        bound(&plain)
    );
}

/// Parts that interfere, meshed with Gmsh's default sizing (`pinned_plate` in
/// `fixtures/make_cad_fixtures.py`: a pin through a plate's hole and through a collar's
/// solid, three volumes not fused): tetrahedra of the coarse pin have two facet edges
/// opposite rim corners, each split on the surface fair alone. Splitting both folded a
/// tetrahedron (signed Jacobian −1e-3), refused as an inverted input element at every
/// order; each split is now kept only if its cells stay the right way round.
#[test]
fn rim_splits_that_fold_a_cell_together_are_not_made() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["step", "igs"] {
        let inputs = fixture_inputs("pinned_plate", ext);
        let outputs = mesh_only(dir.path().join(format!("pinned_plate_{ext}.msh")));
        let finished = curve_and_write(&inputs, &options(2), &outputs, &mut |_| {})
            .unwrap_or_else(|e| panic!("{ext}: {e}"));
        assert!(finished.defects.is_empty(), "{ext}: {:?}", finished.defects);
        let r = &finished.curved.report;
        assert!(r.surface_edges_split > 0, "{ext}: no rim was split");
        assert_eq!(r.certified_valid_elements, Some(r.elements), "{ext}");
        assert!(
            r.max_geometry_distance < 1e-12,
            "{ext}: {:e}",
            r.max_geometry_distance
        );
    }
}

/// A rod whose side is two half-cylinder faces, meshed with a handful of vertices round it
/// (`coarse_rod` in `fixtures/make_cad_fixtures.py`; as1_pe_203.stp's rods): tetrahedra
/// across it have two facets on one half sharing an edge, det J = 0 along it whatever the
/// surface nodes do, and the opposite edge — a diameter — on a facet of the other half, so
/// it cannot be split at its straight midpoint (the axis). Split at its geodesic midpoint
/// on that half, every element certifies at p = 2..5 (`cargo xtask cad`); before, 2
/// elements stayed invalid at p = 3..5 from the STEP file and 20–22 from the IGES file.
#[test]
fn a_diameter_opposite_a_doubly_curved_corner_is_split_on_its_surface() {
    let dir = tempfile::tempdir().unwrap();
    for (ext, order) in [("step", 3), ("igs", 3)] {
        let inputs = fixture_inputs("coarse_rod", ext);
        let outputs = mesh_only(dir.path().join(format!("coarse_rod_{ext}{order}.msh")));
        let finished = curve_and_write(&inputs, &options(order), &outputs, &mut |_| {})
            .unwrap_or_else(|e| panic!("{ext} p = {order}: {e}"));
        assert!(finished.defects.is_empty(), "{ext}: {:?}", finished.defects);
        let r = &finished.curved.report;
        assert!(
            r.surface_edges_split > 0,
            "{ext} p = {order}: nothing split on the surface"
        );
        assert_eq!(
            r.certified_valid_elements,
            Some(r.elements),
            "{ext} p = {order}"
        );
        assert!(
            r.max_geometry_distance < 1e-12,
            "{ext}: {:e}",
            r.max_geometry_distance
        );
    }
}

/// A block with a round-ended slot whose top rim is filleted, meshed by Gmsh's default
/// sizing (`filleted_slot` in `fixtures/make_cad_fixtures.py`): tetrahedra have a vertex on
/// the fillet's tangent edge whose three edges lie on the fillet and the face it runs into,
/// with one facet on the boundary or none, so no rule about pairs of facets sees them.
/// Curved, such a corner is flat; the edge opposite it is split before curving. Before,
/// p = 2 certified only Ĩ ≥ 0.024 and p = 4 Ĩ ≥ 2e-5 (from STEP and IGES); now ≥ 0.2.
#[test]
fn a_corner_a_fillet_flattens_is_split_before_curving() {
    let dir = tempfile::tempdir().unwrap();
    for (ext, order) in [("step", 2), ("igs", 4)] {
        let inputs = fixture_inputs("filleted_slot", ext);
        let outputs = mesh_only(dir.path().join(format!("filleted_slot_{ext}{order}.msh")));
        let finished = curve_and_write(&inputs, &options(order), &outputs, &mut |_| {})
            .unwrap_or_else(|e| panic!("{ext} p = {order}: {e}"));
        assert!(finished.defects.is_empty(), "{ext}: {:?}", finished.defects);
        let r = &finished.curved.report;
        assert_eq!(
            r.certified_valid_elements,
            Some(r.elements),
            "{ext} p = {order}"
        );
        let bound = r.min_scaled_jacobian_lower_bound.unwrap();
        assert!(bound > 0.1, "{ext} p = {order}: Ĩ ≥ {bound}");
        assert!(
            r.max_geometry_distance < 1e-12,
            "{ext}: {:e}",
            r.max_geometry_distance
        );
    }
}

/// A block with small rounded edges meshed by Gmsh's default sizing
/// (`fixtures/make_cad_fixtures.py`): its quarter-round rims have two segments, and end faces
/// get triangles through an arc's two ends and its middle. Such a facet has every vertex on
/// the rim, so on both the plane and the cylinder, and must go to the plane (its centre is
/// on it); curved, its two rim edges meet at 180° (det J = 0 there, 7 elements left
/// uncertified at p = 3 by every repair), so its third edge is split on the plane first.
#[test]
fn a_facet_through_an_arc_and_its_middle_is_split_on_its_surface() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["step", "igs"] {
        let outputs = Outputs {
            mesh: dir.path().join(format!("rounded_block_{ext}.msh")),
            report: None,
            plots: None,
            format: Default::default(),
        };
        let inputs = Inputs::read(
            &fixture("rounded_block.msh"),
            Some(&fixture(&format!("rounded_block.{ext}"))),
        )
        .unwrap();
        let finished = curve_and_write(&inputs, &options(3), &outputs, &mut |_| {})
            .unwrap_or_else(|e| panic!("{ext}: {e}"));
        assert!(finished.defects.is_empty(), "{ext}: {:?}", finished.defects);
        let r = &finished.curved.report;
        assert_eq!(r.certified_valid_elements, Some(r.elements), "{ext}");
        assert!(r.surface_edges_split > 0, "{ext}");
        assert_eq!(r.facets_straight, 0, "{ext}");
        assert!(
            r.max_geometry_distance < 1e-12,
            "{ext}: {:e}",
            r.max_geometry_distance
        );
    }
}

/// A plate with a filleted boss meshed by Gmsh's default sizing
/// (`fixtures/make_cad_fixtures.py`): the fillets are narrower than the mesh, so a facet on
/// a fillet's torus has two vertices on the rim circle where the torus meets the top plane.
/// Curved, that rim edge bulges past the facet's other edge at one end (−3° in the torus'
/// tangent plane; Gmsh's own `setOrder` leaves 8 tets invalid at p = 2). The
/// minimum-angle correction measured only at vertices inside one surface, so 1 / 2
/// elements were left invalid at p = 2 / 3 after every repair; measured in the edge's surface
/// at rim vertices too, and at p = 2 by a quadratic, all certify.
#[test]
fn a_fillet_facet_crossed_by_its_curved_rim_edge_is_corrected_at_every_order() {
    let dir = tempfile::tempdir().unwrap();
    for p in [2, 3] {
        let outputs = Outputs {
            mesh: dir.path().join(format!("boss_{p}.msh")),
            report: None,
            plots: None,
            format: Default::default(),
        };
        let inputs = Inputs::read(
            &fixture("filleted_boss.msh"),
            Some(&fixture("filleted_boss.step")),
        )
        .unwrap();
        let finished = curve_and_write(&inputs, &options(p), &outputs, &mut |_| {})
            .unwrap_or_else(|e| panic!("p = {p}: {e}"));
        assert!(
            finished.defects.is_empty(),
            "p = {p}: {:?}",
            finished.defects
        );
        let r = &finished.curved.report;
        assert_eq!(r.certified_valid_elements, Some(r.elements), "p = {p}");
        assert!(r.corrected_edges > 0, "p = {p}");
        assert!(
            r.max_geometry_distance < 1e-12,
            "p = {p}: {:e}",
            r.max_geometry_distance
        );
    }
}

/// A cone on a plate, both rims filleted (`fixtures/make_cad_fixtures.py`): OpenCASCADE's
/// fillet tori touch the cone along circles, 7e-13 apart in its STEP file. Before: the seam
/// solver found that seam but never stopped (its offset has a minimum above round-off), the
/// nodes fell back on alternating projections and were written 7.5e-5 off the cone (every
/// order refused); at p = 3 a cell whose only boundary face spans half a radian of the top
/// fillet folded along its curved edge, with no interior chord to split. Now that edge is
/// split on the torus and the mesh curved again.
#[test]
fn a_cell_folded_along_its_fillet_edge_is_refined_on_the_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let outputs = Outputs {
        mesh: dir.path().join("cone_plate_3.msh"),
        report: None,
        plots: None,
        format: Default::default(),
    };
    let inputs = Inputs::read(
        &fixture("cone_plate.msh"),
        Some(&fixture("cone_plate.step")),
    )
    .unwrap();
    let finished = curve_and_write(&inputs, &options(3), &outputs, &mut |_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(finished.defects.is_empty(), "{:?}", finished.defects);
    let r = &finished.curved.report;
    assert_eq!(r.certified_valid_elements, Some(r.elements));
    assert!(r.facet_edges_split > 0 && r.refinement_rounds > 0, "{r:?}");
    assert!(
        r.max_geometry_distance < 1e-11,
        "{:e}",
        r.max_geometry_distance
    );
}

/// A sphere fused on a block, the joint filleted (`fixtures/make_cad_fixtures.py`):
/// OpenCASCADE's fillet is a B-spline that meets the exact sphere only to 2e-6 (the STEP
/// file states an uncertainty of 5e-6, the IGES a resolution of 3.88e-6) and crosses it at a
/// grazing angle near their common edge. Before: the traced edge scattered across that band
/// (7 / 2 elements invalid at p = 3 / 4), the written nodes were snapped to wherever the
/// faces cross (3e-3 away), and every order was refused as 2e-6 "off the geometry". Now
/// the edge is the middle of the band, its written nodes lie exactly on one face, within
/// the file's uncertainty of the other. The same file stating 1e-7 is refused, with that
/// reason and the `--geometry-gap` that would take the faces to meet that loosely: stated,
/// the file is curved.
#[test]
fn faces_that_meet_only_to_the_files_uncertainty_are_curved_within_it() {
    let dir = tempfile::tempdir().unwrap();
    let outputs = |name: &str| Outputs {
        mesh: dir.path().join(name),
        report: None,
        plots: None,
        format: Default::default(),
    };
    let inputs = |geometry: &std::path::Path| {
        Inputs::read(&fixture("sphere_on_block.msh"), Some(geometry)).unwrap()
    };
    for (ext, stated) in [("step", 5e-6), ("igs", 3.88417e-6)] {
        let geometry = fixture(&format!("sphere_on_block.{ext}"));
        let finished = curve_and_write(
            &inputs(&geometry),
            &options(3),
            &outputs("a.msh"),
            &mut |_| {},
        )
        .unwrap_or_else(|e| panic!("{ext}: {e}"));
        assert!(finished.defects.is_empty(), "{ext}: {:?}", finished.defects);
        let r = &finished.curved.report;
        assert_eq!(r.certified_valid_elements, Some(r.elements), "{ext}");
        let u = r.geometry_uncertainty.unwrap();
        assert!((u - stated).abs() < 1e-7 * stated, "{ext}: {u:e}");
        assert!(
            r.max_seam_gap > 1e-6 && r.max_seam_gap <= u,
            "{ext}: {:e}",
            r.max_seam_gap
        );
        assert!(r.max_geometry_distance <= u, "{ext}");
        assert!(
            r.distance_beyond_seams < 1e-12,
            "{ext}: {:e}",
            r.distance_beyond_seams
        );
    }
    let text = std::fs::read_to_string(fixture("sphere_on_block.step")).unwrap();
    let strict = text.replace("LENGTH_MEASURE(5.E-06)", "LENGTH_MEASURE(1.E-07)");
    assert_ne!(strict, text);
    let geometry = dir.path().join("strict.step");
    std::fs::write(&geometry, strict).unwrap();
    match curve_and_write(
        &inputs(&geometry),
        &options(3),
        &outputs("b.msh"),
        &mut |_| {},
    ) {
        Err(JobError::Rejected { reason, .. }) => {
            assert!(
                reason.contains("to which the file says they meet"),
                "{reason}"
            );
            // The refusal says what gap would do; stated so, the same file is curved.
            let gap: f64 = reason
                .split("--geometry-gap ")
                .nth(1)
                .and_then(|rest| rest.split_whitespace().next())
                .and_then(|g| g.parse().ok())
                .unwrap_or_else(|| panic!("no gap suggested: {reason}"));
            assert!(gap > 1e-6 && gap < 5e-6, "{gap:e}");
            let mut widened = inputs(&geometry);
            widened.geometry.as_mut().unwrap().0.widen_uncertainty(gap);
            let finished = curve_and_write(&widened, &options(3), &outputs("c.msh"), &mut |_| {})
                .unwrap_or_else(|e| panic!("with the gap {gap:e}: {e}"));
            let r = &finished.curved.report;
            assert_eq!(r.certified_valid_elements, Some(r.elements));
            assert_eq!(r.geometry_uncertainty, Some(gap));
            assert!(r.max_seam_gap <= gap && r.distance_beyond_seams < 1e-12);
        }
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("the faces are farther apart than the file says"),
    }
    assert!(!dir.path().join("b.msh").exists());
}

/// A B-spline loft meshed coarsely (`fixtures/make_cad_fixtures.py`): at p = 3 one cell with
/// all four vertices on the boundary, two of its edges on the dented side meeting at a
/// corner of an inner face, stays invalid after the stiffened solve and the untangling
/// (Ĩ ≥ −0.04). Its longest chord is split — before any untangling — and the mesh curved
/// again: all certify, the report and the file describe the split mesh.
#[test]
fn a_cell_no_repair_certifies_is_split_along_its_longest_chord_and_curved_again() {
    let dir = tempfile::tempdir().unwrap();
    let outputs = Outputs {
        mesh: dir.path().join("loft.msh"),
        report: None,
        plots: None,
        format: Default::default(),
    };
    let inputs = Inputs::read(
        &fixture("twisted_loft.msh"),
        Some(&fixture("twisted_loft.step")),
    )
    .unwrap();
    let mut steps = Vec::new();
    let finished = curve_and_write(&inputs, &options(3), &outputs, &mut |p| {
        if let hocurve::progress::Progress::Step(step) = p {
            steps.push(step);
        }
    })
    .unwrap();
    assert!(finished.defects.is_empty(), "{:?}", finished.defects);
    // Split before any untangling (which would cost far more than curving the split mesh):
    // the one repair step before the refinement is the stiffened solve.
    use hocurve::progress::Step;
    let refinement = steps.iter().position(|&s| s == Step::Refinement).unwrap();
    let repairs = steps[..refinement]
        .iter()
        .filter(|&&s| s == Step::Repair)
        .count();
    assert_eq!(repairs, 1, "{steps:?}");
    let r = &finished.curved.report;
    assert_eq!(r.refinement_rounds, 1);
    assert_eq!(r.untangled_elements, 0);
    assert!(r.refined_elements >= 1);
    assert_eq!(r.certified_valid_elements, Some(r.elements));
    assert!(r.min_scaled_jacobian_lower_bound.unwrap() > 0.3);
    assert!(r.elements > inputs.linear.cells.len());
    let written = hocurve::io::read_high_order_mesh(&outputs.mesh).unwrap();
    assert_eq!(written.cells.len(), r.elements);
    assert!(r.max_geometry_distance < 1e-12);
}

/// A mesh saved with physical groups on the volumes alone (Gmsh then writes no boundary
/// triangles, nor the interface of the two volumes): the faces the cells leave uncovered
/// and those where the volumes meet are found and curved, and the file written holds the
/// cells alone, as the input did. Before, the job stopped with "no boundary facet lies on
/// the geometry".
#[test]
fn a_mesh_whose_only_groups_are_volumes_is_curved_on_their_surfaces() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = fixture_inputs("capsule_volume", "step");
    let linear = &inputs.linear;
    assert!(linear.facets.is_empty());
    let topology = hocurve::mesh::Topology::new(linear).unwrap();
    let boundary = topology.boundary_facets().count();
    let interface = (0..topology.num_faces())
        .filter(|&f| {
            let [a, b] = topology.facet_cells(f);
            b != hocurve::mesh::NO_CELL
                && linear.cells[a as usize].entity != linear.cells[b as usize].entity
        })
        .count();
    assert!(interface > 0);
    let outputs = mesh_only(dir.path().join("capsule.msh"));
    let finished = curve_and_write(&inputs, &options(3), &outputs, &mut |_| {}).unwrap();
    let r = &finished.curved.report;
    assert_eq!(r.undeclared_facets, boundary + interface);
    assert_eq!(r.facets_by_proximity, boundary + interface);
    assert_eq!(r.certified_valid_elements, Some(r.elements));
    let written = hocurve::io::read_high_order_mesh(&outputs.mesh).unwrap();
    assert!(written.facets.is_empty());
    // The capsule: a cylinder of radius 0.5 along x from 0 to 2, a sphere at each end.
    let capsule = |x: [f64; 3]| {
        let centre = [x[0].clamp(0.0, 2.0), 0.0, 0.0];
        let r = ((x[0] - centre[0]).powi(2) + x[1] * x[1] + x[2] * x[2]).sqrt();
        (r - 0.5).abs()
    };
    let mut on_boundary = 0;
    for (_, nodes) in written.boundary_facet_nodes().unwrap() {
        for n in nodes {
            let d = capsule(written.nodes[n as usize]);
            assert!(d < 1e-12, "node {n} is {d:e} off the capsule");
            on_boundary += 1;
        }
    }
    assert!(on_boundary > 0);
    // The core: a sphere of radius 0.25 about (1, 0, 0); its nodes are those of cells of
    // both volumes.
    let mut entities = vec![Vec::new(); written.nodes.len()];
    for cell in &written.cells {
        for &n in &cell.nodes {
            if !entities[n as usize].contains(&cell.entity) {
                entities[n as usize].push(cell.entity);
            }
        }
    }
    let on_core: Vec<usize> = (0..written.nodes.len())
        .filter(|&n| entities[n].len() > 1)
        .collect();
    assert!(on_core.len() > 3 * interface / 2);
    for n in on_core {
        let x = written.nodes[n];
        let d = (((x[0] - 1.0).powi(2) + x[1] * x[1] + x[2] * x[2]).sqrt() - 0.25).abs();
        assert!(d < 1e-12, "node {n} is {d:e} off the core");
    }
}

/// A 2D face whose normal is −z (built from a clockwise loop): Gmsh numbers its triangles
/// clockwise. They are curved and written counter-clockwise, every one certified. Before,
/// every element was refused as not certified.
#[test]
fn a_2d_mesh_numbered_clockwise_is_curved_and_written_counter_clockwise() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = fixture_inputs("plate_clockwise", "igs");
    let outputs = mesh_only(dir.path().join("plate.msh"));
    let finished = curve_and_write(&inputs, &options(3), &outputs, &mut |_| {}).unwrap();
    let r = &finished.curved.report;
    assert_eq!(r.reoriented_cells, inputs.linear.cells.len());
    assert_eq!(r.certified_valid_elements, Some(r.elements));
    let turn = |x: &[[f64; 3]], v: &[u32]| {
        let [a, b, c] = [0, 1, 2].map(|k| x[v[k] as usize]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    assert!(inputs
        .linear
        .cells
        .iter()
        .all(|c| turn(&inputs.linear.vertices, &c.vertices) < 0.0));
    let written = hocurve::io::read_high_order_mesh(&outputs.mesh).unwrap();
    assert!(written
        .cells
        .iter()
        .all(|c| turn(&written.nodes, &c.nodes) > 0.0));
}
