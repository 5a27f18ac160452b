//! SVG bar charts of the histograms (the paper's Figs. 12a, 15, 17, 20: percentage of
//! elements per 0.05 interval of the scaled Jacobian), drawn with plotters' SVG backend.
//! Text needs no font files: the backend writes `<text>` elements and plotters estimates
//! their extent.

use plotters::prelude::*;

use crate::{Histogram, QualityError, QualitySummary};

/// The scaled-Jacobian histogram of `summary` as an SVG document (writing it is the
/// caller's: this crate measures, it does not touch files).
/// The bin of invalid elements (Ĩ ≤ 0) is red and titled with its count.
pub fn scaled_jacobian_histogram_svg(summary: &QualitySummary) -> Result<String, QualityError> {
    let histogram = &summary.scaled_jacobian_histogram;
    let invalid = histogram.bins.first().map_or(0, |b| b.count);
    let title = if invalid > 0 {
        format!("Scaled Jacobian: {invalid} invalid element(s) (red)")
    } else {
        "Scaled Jacobian: no invalid element".to_string()
    };
    histogram_svg(
        histogram,
        &title,
        "scaled Jacobian (bin upper edge; ≤0 = invalid)",
        Some(0),
    )
    .map_err(|message| QualityError::Plot { message })
}

/// The stretching histogram of `summary` as an SVG document.
pub fn stretching_histogram_svg(summary: &QualitySummary) -> Result<String, QualityError> {
    histogram_svg(
        &summary.stretching_histogram,
        "Stretching",
        "longest / shortest edge",
        None,
    )
    .map_err(|message| QualityError::Plot { message })
}

/// A bar chart of the histogram's percentages, as an SVG document, with each non-empty
/// bin's element count above its bar (so that a handful of elements among thousands is
/// still seen) and bin `alarm` (if any) in red.
pub fn histogram_svg(
    histogram: &Histogram,
    title: &str,
    x_label: &str,
    alarm: Option<usize>,
) -> Result<String, String> {
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
        let blue = RGBColor(70, 110, 180);
        let alarm = alarm.filter(|&k| histogram.bins.get(k).is_some_and(|b| b.count > 0));
        chart
            .draw_series(
                plotters::series::Histogram::vertical(&chart)
                    .style_func(|k, _| {
                        let index = match k {
                            SegmentValue::Exact(i) | SegmentValue::CenterOf(i) => Some(*i as usize),
                            SegmentValue::Last => None,
                        };
                        if index.is_some() && alarm == index {
                            RED.filled()
                        } else {
                            blue.filled()
                        }
                    })
                    .margin(3)
                    .data(percentages.iter().enumerate().map(|(k, &p)| (k as u32, p))),
            )
            .map_err(|x| e(&x))?;
        let counts = histogram
            .bins
            .iter()
            .enumerate()
            .filter(|(_, b)| b.count > 0);
        chart
            .draw_series(counts.map(|(k, b)| {
                Text::new(
                    b.count.to_string(),
                    (
                        SegmentValue::CenterOf(k as u32),
                        (b.percentage + 0.02 * y_max).min(y_max),
                    ),
                    ("sans-serif", 12).into_font().color(&BLACK),
                )
            }))
            .map_err(|x| e(&x))?;
        root.present().map_err(|x| e(&x))?;
    }
    Ok(svg)
}

#[cfg(test)]
#[path = "tests/plot.rs"]
mod tests;
