//! Everything about a mesh's quality in one call: per-element values and their summary.

use hocurve_mesh::{HighOrderMesh, Shape};

use crate::jacobian::scaled_jacobian_where;
use crate::validity::check_validity_where;
use crate::{stretching, BezierOptions, QualityError, QualitySummary, Sampling, ValidityCheck};

/// What [`assess`] computes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct QualityOptions {
    /// Where det J is sampled for the scaled Jacobian.
    pub sampling: Sampling,
    /// Run the Bézier validity check too (None: skip it).
    pub bezier: Option<BezierOptions>,
}

/// Per-element quality of a mesh (vectors indexed like `mesh.cells`) and its summary.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshQuality {
    /// Scaled Jacobian Ĩ of each element.
    pub scaled_jacobian: Vec<f64>,
    /// Stretching of each element.
    pub stretching: Vec<f64>,
    /// Bézier check of each element, if requested.
    pub validity: Option<Vec<ValidityCheck>>,
    /// The summary.
    pub summary: QualitySummary,
}

/// Measures every element of `mesh` and summarises.
pub fn assess(mesh: &HighOrderMesh, options: &QualityOptions) -> Result<MeshQuality, QualityError> {
    assess_where(mesh, options, None)
}

/// [`assess`] for a mesh whose cells flagged in `affine` are known to have their nodes at
/// the straight-sided positions of their vertices (to rounding; e.g. the cells outside
/// the elastic solve's active region): on triangles and tetrahedra the map is then affine,
/// det J is the constant det[x₁ − x₀, …], Ĩ = 1 and validity is its sign — exactly what
/// sampling and Bézier bounds give, up to rounding, without their cost. Flags on other
/// shapes are ignored (their straight-sided maps are not affine).
pub fn assess_with_affine(
    mesh: &HighOrderMesh,
    options: &QualityOptions,
    affine: &[bool],
) -> Result<MeshQuality, QualityError> {
    assess_where(mesh, options, Some(affine))
}

fn assess_where(
    mesh: &HighOrderMesh,
    options: &QualityOptions,
    affine: Option<&[bool]>,
) -> Result<MeshQuality, QualityError> {
    let scaled = scaled_jacobian_where(mesh, options.sampling, affine)?;
    let stretch = stretching(mesh)?;
    let validity = options
        .bezier
        .map(|bezier| check_validity_where(mesh, &bezier, affine, Some(&scaled)))
        .transpose()?;
    let kinds: Vec<Shape> = mesh.cells.iter().map(|c| c.kind).collect();
    let summary = QualitySummary::new(&kinds, &scaled, &stretch, validity.as_deref());
    Ok(MeshQuality {
        scaled_jacobian: scaled,
        stretching: stretch,
        validity,
        summary,
    })
}

#[cfg(test)]
mod tests {
    use hocurve_nodes::NodeFamily;
    use hocurve_testmeshes::{high_order, unit_cube, unit_square, Fill, Kuhn};

    use super::*;

    /// Straight-sided meshes: the affine shortcut gives what sampling and Bézier bounds
    /// give, to their rounding (the Bézier bounds of a constant det J spread by ~1e-11); on
    /// hexahedra and prisms the flags change nothing.
    #[test]
    fn affine_cells_are_measured_as_sampling_and_bezier_bounds_measure_them() {
        let options = QualityOptions {
            bezier: Some(BezierOptions::default()),
            ..QualityOptions::default()
        };
        for (linear, order) in [
            (unit_cube(2, Fill::Tet(Kuhn::Paired), 0.2), 3),
            (unit_square(3, Shape::Tri, 0.2), 4),
            (unit_cube(2, Fill::HexPrism, 0.0), 2),
        ] {
            let mesh = high_order(&linear, order, NodeFamily::Fekete);
            let full = assess(&mesh, &options).unwrap();
            let every = vec![true; mesh.cells.len()];
            let short = assess_with_affine(&mesh, &options, &every).unwrap();
            let (a, b) = (full.validity.unwrap(), short.validity.unwrap());
            for c in 0..mesh.cells.len() {
                assert!((full.scaled_jacobian[c] - short.scaled_jacobian[c]).abs() < 1e-12);
                assert_eq!(a[c].validity, b[c].validity);
                assert_eq!(b[c].validity, crate::Validity::Valid);
                let det = a[c].min_jacobian_lower_bound;
                assert!((det - b[c].min_jacobian_lower_bound).abs() < 1e-10 * det.abs());
                assert!(
                    (a[c].scaled_jacobian_lower_bound - b[c].scaled_jacobian_lower_bound).abs()
                        < 1e-10
                );
                if !matches!(mesh.cells[c].kind, Shape::Tri | Shape::Tet) {
                    assert_eq!(a[c], b[c]);
                }
            }
        }
    }

    #[test]
    fn an_inverted_affine_cell_is_invalid() {
        let mut mesh = high_order(
            &unit_cube(1, Fill::Tet(Kuhn::Paired), 0.0),
            2,
            NodeFamily::Fekete,
        );
        // Mirror the mesh: every straight tetrahedron turns inside out.
        for x in &mut mesh.nodes {
            x[0] = -x[0];
        }
        let options = QualityOptions {
            bezier: Some(BezierOptions::default()),
            ..QualityOptions::default()
        };
        let every = vec![true; mesh.cells.len()];
        let short = assess_with_affine(&mesh, &options, &every).unwrap();
        assert!(short.scaled_jacobian.iter().all(|&s| s == -1.0));
        let full = assess(&mesh, &options).unwrap();
        for (a, b) in full.validity.unwrap().iter().zip(short.validity.unwrap()) {
            assert_eq!(
                (a.validity, b.validity),
                (crate::Validity::Invalid, crate::Validity::Invalid)
            );
        }
    }
}
