//! The files a curving job writes: the curved mesh with its displacement and quality as
//! data arrays, the JSON report, and the quality histograms as SVG. Each is written to the
//! path given, atomically; [`crate::job`] gives staged paths so that all land together.

use std::io::Write;
use std::path::Path;

use hocurve_io::{DataArray, IoError};
use hocurve_quality::QualitySummary;

use crate::job::JobError;
use crate::pipeline::CurvedMesh;

/// Writes the mesh (`.vtu` or `.msh`) with the displacement as point data and, per cell,
/// the sampled scaled Jacobian, the stretching and (when certified) the certified lower
/// bound of the scaled Jacobian: the cells to look at in ParaView are those where the bound
/// is far below the sample.
pub fn write_curved(
    path: &Path,
    curved: &CurvedMesh,
    format: hocurve_io::OutputFormat,
) -> Result<(), JobError> {
    let displacement: Vec<f64> = curved.displacement.iter().flatten().copied().collect();
    let point_data = [DataArray {
        name: "displacement",
        components: 3,
        values: &displacement,
    }];
    let quality = &curved.quality;
    let lower_bounds: Option<Vec<f64>> = quality.validity.as_ref().map(|checks| {
        checks
            .iter()
            .map(|c| c.scaled_jacobian_lower_bound)
            .collect()
    });
    let mut cell_arrays = vec![
        DataArray {
            name: "scaled_jacobian",
            components: 1,
            values: &quality.scaled_jacobian,
        },
        DataArray {
            name: "stretching",
            components: 1,
            values: &quality.stretching,
        },
    ];
    if let Some(bounds) = &lower_bounds {
        cell_arrays.push(DataArray {
            name: "scaled_jacobian_lower_bound",
            components: 1,
            values: bounds,
        });
    }
    hocurve_io::write_mesh_as(path, &curved.mesh, &point_data, &cell_arrays, format)?;
    Ok(())
}

/// Writes the report of `curved` as pretty-printed JSON.
pub fn write_report(path: &Path, curved: &CurvedMesh) -> Result<(), JobError> {
    let json = serde_json::to_string_pretty(&curved.report)?;
    write_text(path, &json)
}

/// Writes the scaled-Jacobian and the stretching histograms of `summary` as SVG, each
/// where a path is given.
pub fn write_histograms(
    scaled_jacobian: Option<&Path>,
    stretching: Option<&Path>,
    summary: &QualitySummary,
) -> Result<(), JobError> {
    if let Some(path) = scaled_jacobian {
        write_text(
            path,
            &hocurve_quality::scaled_jacobian_histogram_svg(summary)?,
        )?;
    }
    if let Some(path) = stretching {
        write_text(path, &hocurve_quality::stretching_histogram_svg(summary)?)?;
    }
    Ok(())
}

/// Writes `text` and a final newline through a temporary file renamed over `path`.
fn write_text(path: &Path, text: &str) -> Result<(), JobError> {
    hocurve_io::write_atomically(path, |w| {
        w.write_all(text.as_bytes())
            .and_then(|()| w.write_all(b"\n"))
            .map_err(|source| IoError::Os {
                path: path.to_path_buf(),
                source,
            })
    })?;
    Ok(())
}
