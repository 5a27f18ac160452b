//! The paper's Sect. 5.1 (NACA0012 at p = 5) beside ours, and its Fig. 12b study on the
//! curved NACA0012 meshes.

use anyhow::{bail, Result};
use hocurve::demo::Demo;
use hocurve::geodesic::AssociationRule;
use hocurve::interpolation::{interpolation_l2_error, paper_test_function};
use hocurve::mesh::LinearMesh;
use hocurve::nurbs::{parse_geometry_json, GeometryModel};
use hocurve::pipeline::{curve_mesh, CurveOptions, CurvedMesh, Geometry};

use crate::root;

/// The paper's NACA0012 numbers (Sect. 5.1 and Fig. 12a).
const PAPER_VERTICES: usize = 370;
const PAPER_ELEMENTS: usize = 650;
const PAPER_CURVED_EDGES: usize = 50;
const PAPER_NODES: usize = 8350;
const PAPER_FRACTION_ABOVE_0_95: f64 = 0.99;
const PAPER_MIN_SCALED_JACOBIAN: f64 = 0.83;

fn curve(linear: &LinearMesh, order: usize) -> Result<CurvedMesh> {
    let (model, rule) = Demo::Naca0012.geometry()?;
    curve_onto(linear, order, &model, rule)
}

fn curve_onto(
    linear: &LinearMesh,
    order: usize,
    model: &GeometryModel,
    rule: AssociationRule,
) -> Result<CurvedMesh> {
    Ok(curve_mesh(
        linear,
        Some(Geometry { model, rule }),
        &CurveOptions::new(order),
        &mut |_| {},
    )?)
}

/// The paper's setup: "370 vertices, 650 elements and 50 edges on the curved boundary"
/// (Sect. 5.1) — only the aerofoil is curved; the far field keeps its straight edges. The
/// bundled geometry also curves the far-field circle, whose large elements lose a little
/// Ĩ to its curvature; that run is printed too.
fn airfoil_only() -> Result<GeometryModel> {
    Ok(parse_geometry_json(
        r#"{"entities": [{"name": "airfoil", "kind": "naca4", "digits": "0012", "chord": 1, "closed_trailing_edge": true}]}"#,
    )?)
}

/// Prints Sect. 5.1's mesh and quality figures beside ours on the bundled NACA0012 (p = 5,
/// Fekete nodes, E = 10, ν = 0.4) and fails if our quality falls below the paper's.
pub fn paper_table() -> Result<()> {
    eprintln!("==> the paper's Sect. 5.1: NACA0012 at p = 5");
    let linear = Demo::Naca0012.mesh()?;
    let both = curve(&linear, 5)?;
    let curved = curve_onto(&linear, 5, &airfoil_only()?, AssociationRule::NameOnly)?;
    let r = &curved.report;
    let airfoil_edges = airfoil_edge_count(&linear);
    let min = r.min_scaled_jacobian.unwrap_or(f64::NAN);
    println!(
        "{:<36} {:>10} {:>10}",
        "NACA0012, p = 5", "paper", "hocurve"
    );
    println!(
        "{:<36} {:>10} {:>10}",
        "vertices",
        PAPER_VERTICES,
        linear.vertices.len()
    );
    println!(
        "{:<36} {:>10} {:>10}",
        "elements", PAPER_ELEMENTS, r.elements
    );
    println!(
        "{:<36} {:>10} {:>10}",
        "edges on the airfoil", PAPER_CURVED_EDGES, airfoil_edges
    );
    println!(
        "{:<36} {:>10} {:>10}",
        "curved edges", PAPER_CURVED_EDGES, r.curved_facets
    );
    println!(
        "{:<36} {:>10} {:>10}",
        "nodes at p = 5", PAPER_NODES, r.nodes
    );
    println!(
        "{:<36} {:>9.0}% {:>9.1}%",
        "elements with Ĩ > 0.95",
        100.0 * PAPER_FRACTION_ABOVE_0_95,
        100.0 * r.fraction_above_0_95
    );
    println!(
        "{:<36} {:>10.2} {:>10.4}",
        "min Ĩ", PAPER_MIN_SCALED_JACOBIAN, min
    );
    println!(
        "{:<36} {:>10} {:>9.1}%  (min Ĩ {:.4}, {} curved edges)",
        "  far field curved too: Ĩ > 0.95",
        "",
        100.0 * both.report.fraction_above_0_95,
        both.report.min_scaled_jacobian.unwrap_or(f64::NAN),
        both.report.curved_facets
    );
    if r.fraction_above_0_95 < PAPER_FRACTION_ABOVE_0_95
        || min.is_nan()
        || min < PAPER_MIN_SCALED_JACOBIAN
    {
        bail!(
            "the curved NACA0012 falls below the paper: {:.1} % of elements with Ĩ > 0.95 (paper 99 %), min Ĩ {min:.4} (paper 0.83)",
            100.0 * r.fraction_above_0_95
        );
    }
    Ok(())
}

fn airfoil_edge_count(linear: &LinearMesh) -> usize {
    let Some(group) = linear.physical_group("airfoil") else {
        return 0;
    };
    linear
        .facets
        .iter()
        .filter(|f| linear.physical_tags(1, f.entity).contains(&group.tag))
        .count()
}

/// Fig. 12b on the curved NACA0012 meshes (triangles and quadrilaterals, p = 1..7): the L2
/// error of the order-p interpolant of f = x cos y + y sin x against √ndof. Fails unless the
/// error falls at every step.
pub fn naca_interpolation_table() -> Result<()> {
    eprintln!(
        "==> interpolation error (paper Fig. 12b) on the curved NACA0012 meshes, Fekete nodes"
    );
    let quads = hocurve::io::read_msh(&root().join("fixtures/quad/naca0012_quads.msh"))?;
    println!(
        "{:<22} {:>2} {:>10} {:>12}",
        "mesh", "p", "sqrt(ndof)", "L2 error"
    );
    for (label, linear) in [
        ("NACA0012 triangles", Demo::Naca0012.mesh()?),
        ("NACA0012 quads", quads),
    ] {
        let mut previous = f64::INFINITY;
        for p in 1..=7 {
            let curved = curve(&linear, p)?;
            let e = interpolation_l2_error(&curved.mesh, paper_test_function)?;
            let root_ndof = (curved.mesh.nodes.len() as f64).sqrt();
            println!("{label:<22} {p:>2} {root_ndof:>10.2} {e:>12.3e}");
            if e.is_nan() || e >= previous {
                bail!(
                    "{label}: the interpolation error does not fall from p = {} to {p}",
                    p - 1
                );
            }
            previous = e;
        }
    }
    Ok(())
}
