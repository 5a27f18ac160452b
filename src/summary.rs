//! What a run prints: the summary table of a curved mesh's report, and what a linear mesh
//! file holds.

use std::fmt::Write;
use std::path::Path;

use hocurve_mesh::LinearMesh;

use crate::job::Measured;
use crate::pipeline::{CurveOptions, CurveReport, CurvedMesh};

/// The summary table printed after a run, at most 10 rows (with the two input lines, a
/// run prints at most 12): output and sizes; boundary and distance to the geometry; what
/// the input left out (facets found from the cells, clockwise cells renumbered); sliding
/// nodes; elasticity (with the boundary-layer treatment); method adjustments; quality;
/// validity; repair; time and memory. Rows that would say "none" are left out; every
/// number is also in the `--report`, which has the rest.
pub fn summary_table(curved: &CurvedMesh, out: &Path) -> String {
    let r = &curved.report;
    let t = &r.timings;
    let mut rows: Vec<(&str, String)> = vec![
        (
            "output",
            format!(
                "{}: {} elements, order {}, {} nodes",
                out.display(),
                r.elements,
                r.order,
                r.nodes
            ),
        ),
        (
            "boundary",
            format!(
                "{} facets on the geometry ({} by name, {} by proximity), {} straight; {} nodes on it, max distance {:.1e}{} (tolerance {:.1e}){}",
                r.facets_by_name + r.facets_by_proximity,
                r.facets_by_name,
                r.facets_by_proximity,
                r.facets_straight,
                r.boundary_nodes_on_geometry,
                r.max_geometry_distance,
                seam_note(r),
                r.geometry_tolerance,
                feature_note(r)
            ),
        ),
    ];
    if r.undeclared_facets > 0 || r.reoriented_cells > 0 {
        let mut found = Vec::new();
        if r.undeclared_facets > 0 {
            found.push(format!(
                "{} facet(s) the file leaves out found from the cells (curved where on the geometry, not written)",
                r.undeclared_facets
            ));
        }
        if r.reoriented_cells > 0 {
            found.push(format!(
                "{} cell(s) numbered clockwise written counter-clockwise",
                r.reoriented_cells
            ));
        }
        rows.push(("input", found.join("; ")));
    }
    if r.sliding_nodes > 0 {
        let groups: Vec<String> = r
            .sliding_groups
            .iter()
            .map(|g| {
                if g.by_default {
                    format!("{} (by default; --fix {} holds it)", g.name, g.name)
                } else {
                    g.name.clone()
                }
            })
            .collect();
        rows.push((
            "sliding nodes",
            format!("{} on {}", r.sliding_nodes, groups.join(", ")),
        ));
    }
    if r.solver != "none" {
        let mut text = format!(
            "{} unknowns, {} solver, {} iterations, residual {:.1e}{}",
            r.dofs,
            r.solver,
            r.iterations,
            r.residual,
            r.displacement_error_bound
                .map(|b| format!(" (displacement error ≤ {b:.1e})"))
                .unwrap_or_default()
        );
        if r.layer_stiffening {
            text += "; cells stiffened by 1/|J| (--uniform-stiffness keeps them uniform)";
        }
        if r.layer_columns > 0 {
            let _ = write!(
                text,
                "; {} cells in {} wall-normal columns moved with the wall (--elastic-layers solves them)",
                r.layer_column_cells, r.layer_columns
            );
        }
        rows.push(("elasticity", text));
    }
    let mut adjustments = Vec::new();
    if r.small_angle_edges > 0 {
        adjustments.push(format!(
            "{} small-angle edge(s), {} corrected (Fig. 4; smallest angle {:.1}°)",
            r.small_angle_edges,
            r.corrected_edges,
            r.min_edge_angle_degrees.unwrap_or(f64::NAN)
        ));
    }
    if r.corrections_undone > 0 {
        adjustments.push(format!(
            "{} correction(s) undone (no better)",
            r.corrections_undone
        ));
    }
    if r.edges_split > 0 {
        adjustments.push(if r.refinement_rounds > 0 {
            format!(
                "{} interior edge(s) split (cells with two facets on one curved entity, or a \
                 corner flat once curved; longest chords of cells not certified, {} round(s) of curving again)",
                r.edges_split, r.refinement_rounds
            )
        } else {
            format!(
                "{} interior edge(s) split (cells with two facets on one curved entity, or a \
                 corner flat once curved)",
                r.edges_split
            )
        });
    }
    if r.facet_edges_split > 0 {
        adjustments.push(format!(
            "{} boundary edge(s) split on the geometry (longest curved-facet edges of cells \
             not certified that have no chord)",
            r.facet_edges_split
        ));
    }
    if r.surface_edges_split > 0 {
        adjustments.push(format!(
            "{} surface edge(s) split (facets with two edges on one feature curve, or opposite \
             two facets of a cell on one curved surface or a corner flat once curved)",
            r.surface_edges_split
        ));
    }
    if !adjustments.is_empty() {
        rows.push(("adjustments", adjustments.join("; ")));
    }
    let sampled = r
        .min_scaled_jacobian
        .map_or("-".to_string(), |m| format!("{m:.4}"));
    rows.push((
        "min scaled Jacobian",
        match r.min_scaled_jacobian_lower_bound {
            Some(bound) => format!(
                "Ĩ ≥ {bound:.4} everywhere (Bézier bounds); {sampled} at the degree-2p quadrature points"
            ),
            None => format!("{sampled} at the degree-2p quadrature points only (not certified)"),
        },
    ));
    rows.push((
        "validity",
        match (r.certified_valid_elements, r.undecided_elements) {
            (Some(valid), Some(undecided)) => format!(
                "{} invalid; {valid} of {} elements certified det J > 0 everywhere, {undecided} undecided",
                r.invalid_elements, r.elements,
            ),
            _ => format!(
                "{} invalid at the sample points; not certified (--no-certify)",
                r.invalid_elements
            ),
        },
    ));
    let mut repair = Vec::new();
    if r.refinement_rounds > 0 {
        repair.push(format!(
            "{} element(s) not certified after the solve, or certified below Ĩ {:.2} after \
             the repair: their longest chords (or curved-facet edges) split and the mesh \
             curved again ({} round(s))",
            r.refined_elements,
            crate::pipeline::refine_floor(r.reshape_below),
            r.refinement_rounds
        ));
    }
    if r.uncertified_after_solve > 0 {
        let steps = r.repair_steps();
        repair.push(format!(
            "{} element(s) not certified after the solve; {}",
            r.uncertified_after_solve,
            if steps.is_empty() {
                "not repaired (--no-repair)"
            } else {
                &steps
            }
        ));
    }
    if let Some(from) = r.reshaped_from {
        repair.push(format!(
            "{} element(s) below Ĩ {:.2} reshaped from min Ĩ {from:.4} (--reshape-below 0 keeps them)",
            r.reshaped_elements, r.reshape_below
        ));
    }
    if !repair.is_empty() {
        rows.push(("repair", repair.join("; ")));
    }
    rows.push((
        "time",
        format!(
            "{:.2} s{} (read {:.2}, nodes {:.2}, boundary {:.2}, elasticity {:.2}, quality {:.2}, repair {:.2}, write {:.2})",
            t.total,
            r.peak_memory_mb
                .map(|mb| format!(", peak memory {mb:.0} MB"))
                .unwrap_or_default(),
            t.read,
            t.high_order_nodes,
            t.association + t.boundary_nodes,
            t.assembly + t.solve,
            t.quality,
            t.repair,
            t.write,
        ),
    ));
    let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    rows.iter()
        .map(|(key, value)| format!("  {key:<width$}  {value}\n"))
        .collect()
}

/// Where the largest distance is on the common edge of faces the geometry file says meet
/// only to its uncertainty: how far apart they are there, and what is left beyond that.
fn seam_note(r: &CurveReport) -> String {
    if r.max_seam_gap <= 0.0 {
        return String::new();
    }
    // The faces meet to round-off where the largest distance is.
    if r.max_seam_gap <= 1e-3 * r.max_geometry_distance {
        return String::new();
    }
    let stated = r
        .geometry_uncertainty
        .map_or_else(String::new, |u| format!(", the stated uncertainty {u:.1e}"));
    format!(
        " on edges where faces are {:.1e} apart{stated}; {:.1e} beyond that",
        r.max_seam_gap, r.distance_beyond_seams
    )
}

/// Where curved faces meet: how many edges lie on the model's own curves, how many on
/// traced intersections (empty when no edge is on two surfaces).
fn feature_note(r: &CurveReport) -> String {
    let (on, traced) = (r.feature_edges_on_model_curves, r.feature_edges_traced);
    if on + traced == 0 {
        return String::new();
    }
    format!("; edges where faces meet: {on} on the model's curves, {traced} traced")
}

/// What a linear mesh file holds: dimension, vertices, cells by type, and the elements of
/// each physical group.
pub fn mesh_info(path: &Path, linear: &LinearMesh) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "{}", path.display());
    let _ = writeln!(out, "  dimension  {}", linear.dim);
    let _ = writeln!(out, "  vertices   {}", linear.vertices.len());
    let mut by_type = std::collections::BTreeMap::new();
    for c in &linear.cells {
        *by_type.entry(c.kind).or_insert(0usize) += 1;
    }
    for (kind, n) in by_type {
        let _ = writeln!(out, "  {:<10} {n}", kind.name());
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
        let _ = writeln!(
            out,
            "  group {:>3} \"{}\" ({}D): {count} elements",
            group.tag, group.name, group.dim
        );
    }
    out
}

/// The line naming the input of a curving run (`name`: its file or case) and what it
/// becomes.
pub fn input_line(name: &str, linear: &LinearMesh, options: &CurveOptions) -> String {
    format!(
        "{name}: {}D, {} vertices, {} cells -> order {} ({} nodes)",
        linear.dim,
        linear.vertices.len(),
        linear.cells.len(),
        options.order,
        options.family
    )
}

/// The header and quality summary of a measured high-order mesh file, and a reminder when
/// its validity was only sampled.
pub fn measured_text(path: &Path, measured: &Measured) -> String {
    let mesh = &measured.mesh;
    let mut out = format!(
        "{}: {}D, order {}, {} nodes\n{}",
        path.display(),
        mesh.dim,
        mesh.order,
        mesh.nodes.len(),
        measured.quality.summary
    );
    if measured.quality.validity.is_none() {
        out += "validity not certified: sampled Ĩ can miss det J < 0 near a vertex or face (use --certify)\n";
    }
    out
}
