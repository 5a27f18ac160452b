//! Everything about a mesh's quality in one call: per-element values and their summary.

use hocurve_mesh::{HighOrderMesh, Shape};

use crate::{
    check_validity, scaled_jacobian, stretching, BezierOptions, QualityError, QualitySummary,
    Sampling, ValidityCheck,
};

/// What [`assess`] computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
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
    let scaled = scaled_jacobian(mesh, options.sampling)?;
    let stretch = stretching(mesh)?;
    let validity = options
        .bezier
        .map(|bezier| check_validity(mesh, &bezier))
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
