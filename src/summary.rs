//! What a run prints: the summary table of a curved mesh's report, and what a linear mesh
//! file holds.

use std::fmt::Write;
use std::path::Path;

use hocurve_mesh::LinearMesh;

use crate::job::Measured;
use crate::pipeline::{CurveOptions, CurvedMesh};

/// The summary table printed after a run: one row per fact of the report (sizes, boundary,
/// distance to the geometry, solver, corrections, quality, certification, repair, seconds
/// per step), keys aligned.
pub fn summary_table(curved: &CurvedMesh, out: &Path) -> String {
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
                "{} dofs, {} solver, {} iterations, residual {:.1e}{}",
                r.dofs,
                r.solver,
                r.iterations,
                r.residual,
                r.displacement_error_bound
                    .map(|b| format!(" (displacement error ≤ {b:.1e})"))
                    .unwrap_or_default()
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
    if r.layer_stiffening {
        rows.push((
            "stiffness",
            "each cell's scaled by 1/|J| (boundary-layer mesh; --uniform-stiffness keeps it uniform)"
                .to_string(),
        ));
    }
    if r.layer_columns > 0 {
        rows.push((
            "layer columns",
            format!(
                "{} cells in {} wall-normal columns moved with the wall (--elastic-layers solves them)",
                r.layer_column_cells, r.layer_columns
            ),
        ));
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
    if let Some(from) = r.reshaped_from {
        rows.push((
            "reshaped",
            format!(
                "{} element(s) certified below Ĩ {:.2} reshaped (free nodes, sliding ones in their planes): min Ĩ {from:.4} before (--reshape-below 0 keeps them)",
                r.reshaped_elements, r.reshape_below
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
    if let Some(mb) = r.peak_memory_mb {
        rows.push(("peak memory", format!("{:.0} MB", mb)));
    }
    let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    rows.iter()
        .map(|(key, value)| format!("  {key:<width$}  {value}\n"))
        .collect()
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
