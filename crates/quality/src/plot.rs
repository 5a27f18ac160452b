//! SVG bar charts of the histograms (the paper's Figs. 12a, 15, 17, 20: percentage of
//! elements per 0.05 interval of the scaled Jacobian), drawn with plotters' SVG backend.
//! Text needs no font files: the backend writes `<text>` elements and plotters estimates
//! their extent.

use std::io::Write;
use std::path::Path;

use plotters::prelude::*;

use crate::{Histogram, QualityError, QualitySummary};

/// Writes the scaled-Jacobian histogram of `summary` to `path` as SVG (atomically).
pub fn write_histogram_svg(path: &Path, summary: &QualitySummary) -> Result<(), QualityError> {
    let svg = histogram_svg(
        &summary.scaled_jacobian_histogram,
        "Scaled Jacobian",
        "scaled Jacobian (bin upper edge; ≤0 = invalid)",
    )
    .map_err(|message| QualityError::Plot {
        path: path.to_path_buf(),
        message,
    })?;
    write_atomically(path, svg.as_bytes())
}

/// Writes the stretching histogram of `summary` to `path` as SVG (atomically).
pub fn write_stretching_histogram_svg(
    path: &Path,
    summary: &QualitySummary,
) -> Result<(), QualityError> {
    let svg = histogram_svg(
        &summary.stretching_histogram,
        "Stretching",
        "longest / shortest edge",
    )
    .map_err(|message| QualityError::Plot {
        path: path.to_path_buf(),
        message,
    })?;
    write_atomically(path, svg.as_bytes())
}

/// A bar chart of the histogram's percentages, as an SVG document.
pub fn histogram_svg(histogram: &Histogram, title: &str, x_label: &str) -> Result<String, String> {
    let labels: Vec<&str> = histogram
        .bins
        .iter()
        .map(|b| b.short_label.as_str())
        .collect();
    let percentages: Vec<f64> = histogram.bins.iter().map(|b| b.percentage).collect();
    let top = percentages.iter().cloned().fold(0.0, f64::max);
    // Round the axis up to a multiple of 10 % (at least 10 %), leaving room above the bars.
    let y_max = ((top / 10.0).ceil() * 10.0).clamp(10.0, 100.0);
    let n = labels.len() as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 500)).into_drawing_area();
        let e = |e: &dyn std::fmt::Display| e.to_string();
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 24))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(60)
            .build_cartesian_2d((0..n).into_segmented(), 0.0..y_max)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(labels.len())
            .x_label_formatter(&|v| match v {
                SegmentValue::CenterOf(k) => labels.get(*k as usize).unwrap_or(&"").to_string(),
                _ => String::new(),
            })
            .x_label_style(("sans-serif", 14))
            .y_label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 18))
            .x_desc(x_label)
            .y_desc("% of elements")
            .draw()
            .map_err(|x| e(&x))?;
        chart
            .draw_series(
                plotters::series::Histogram::vertical(&chart)
                    .style(RGBColor(70, 110, 180).filled())
                    .margin(3)
                    .data(percentages.iter().enumerate().map(|(k, &p)| (k as u32, p))),
            )
            .map_err(|x| e(&x))?;
        root.present().map_err(|x| e(&x))?;
    }
    Ok(svg)
}

/// Writes `bytes` through a temporary file renamed over `path`, so that a failure never
/// leaves a truncated plot.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), QualityError> {
    hocurve_io::write_atomically(path, |w| {
        w.write_all(bytes)
            .map_err(|source| hocurve_io::IoError::Os {
                path: path.to_path_buf(),
                source,
            })
    })?;
    Ok(())
}

#[cfg(test)]
#[path = "tests/plot.rs"]
mod tests;
