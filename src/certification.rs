//! Certification of a curved mesh: the quality measures with the Bézier validity check
//! where the options ask for it and the order supports it, and the cells found invalid.

use hocurve_mesh::{HighOrderMesh, Shape};
use hocurve_quality::{
    assess, assess_with_affine, BezierOptions, MeshQuality, QualityError, QualityOptions, Validity,
};

use crate::pipeline::CurveOptions;

/// [`assess`] with the Bézier validity check when `options.certify` asks for it and the
/// mesh's order supports it (see [`hocurve_quality::bezier_check_supported`]; else without:
/// the report then says "not certified"). Measured (release, 2 cores): 0.24 s on the p = 4
/// sphere (5695 tets), 2.3 s and 9.8 s on a 1493-tet sphere at p = 7 and 8 (its elastic
/// solve: 20 s and 55 s), 0.31 s on a hybrid hex/prism mesh at p = 5 (426 cells).
pub(crate) fn assess_certified(
    mesh: &HighOrderMesh,
    options: &CurveOptions,
) -> Result<MeshQuality, QualityError> {
    assess_certified_with_affine(mesh, options, None)
}

/// [`assess_certified`], with the cells flagged in `affine` (straight-sided simplices,
/// see [`affine_cells`]) measured from their constant det J.
pub(crate) fn assess_certified_with_affine(
    mesh: &HighOrderMesh,
    options: &CurveOptions,
    affine: Option<&[bool]>,
) -> Result<MeshQuality, QualityError> {
    let assess = |mesh: &HighOrderMesh, quality: &QualityOptions| match affine {
        Some(flags) => assess_with_affine(mesh, quality, flags),
        None => assess(mesh, quality),
    };
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

/// The cells of `mesh` that are triangles or tetrahedra with every node within rounding
/// (1e-12 of the cell's longest edge) of its straight-sided position in `straight`: their
/// map is affine (the cells the active region left alone).
pub(crate) fn affine_cells(mesh: &HighOrderMesh, straight: &[[f64; 3]]) -> Vec<bool> {
    use rayon::prelude::*;
    mesh.cells
        .par_iter()
        .map(|cell| {
            if !matches!(cell.kind, Shape::Tri | Shape::Tet) || straight.len() != mesh.nodes.len() {
                return false;
            }
            let corner = |i: usize| straight[cell.nodes[i] as usize];
            let mut longest = 0.0f64;
            for &[a, b] in cell.kind.edges() {
                let (x, y) = (corner(a), corner(b));
                longest = longest.max((0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>().sqrt());
            }
            let tolerance = 1e-12 * longest;
            cell.nodes.iter().all(|&n| {
                let (x, y) = (mesh.nodes[n as usize], straight[n as usize]);
                (0..3).all(|k| (x[k] - y[k]).abs() <= tolerance)
            })
        })
        .collect()
}

/// Number of [`invalid_cells`].
pub(crate) fn invalid_elements(quality: &MeshQuality) -> usize {
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

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_nodes::NodeFamily;
    use hocurve_testmeshes::{high_order, unit_tet};

    /// One p = 4 tetrahedron (equispaced nodes) whose first edge node (edge 0–1) is pulled
    /// 40 % of the way to vertex 0 (sampled Ĩ = 0.24, true min det J / max det J = −0.39): det J < 0 only in a small region at that vertex, which the interior
    /// quadrature points of the paper's Ĩ do not reach.
    fn tet_inverted_at_a_vertex() -> HighOrderMesh {
        let mut mesh = high_order(&unit_tet(), 4, NodeFamily::Equispaced);
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
}
