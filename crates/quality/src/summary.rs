//! The quality summary of a mesh: the numbers the paper reports in Sect. 5 (minimum scaled
//! Jacobian, share of elements above 0.95, elements below 0.5, maximum stretching) and the
//! histograms of its Figs. 12a, 15, 17 and 20, as a text table and as JSON.

use std::collections::BTreeMap;
use std::fmt;

use hocurve_mesh::Shape;
use serde::Serialize;

use crate::{QualityError, Validity, ValidityCheck};

/// Upper edges of the stretching histogram's bins (the last bin is open): roughly
/// logarithmic, so that isotropic meshes (1–5) and boundary layers (hundreds, the paper's
/// Falcon and F6 meshes reach 381 and 320) are both resolved, with 200 — the summary's
/// threshold — as an edge.
pub const STRETCHING_BIN_EDGES: [f64; 10] =
    [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0];

/// Elements whose stretching exceeds this are counted in
/// [`QualitySummary::elements_stretched_above_200`].
pub const STRETCHING_THRESHOLD: f64 = 200.0;

/// One bin of a histogram.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HistogramBin {
    /// Human label, e.g. `"(0.90, 0.95]"`.
    pub label: String,
    /// Short label for plot axes, e.g. `"0.95"`.
    pub short_label: String,
    /// Lower edge (None: unbounded).
    pub lower: Option<f64>,
    /// Upper edge (None: unbounded).
    pub upper: Option<f64>,
    /// Elements in the bin.
    pub count: usize,
    /// Percentage of all elements in the bin.
    pub percentage: f64,
}

/// A histogram of one per-element measure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Histogram {
    /// The bins, in increasing order.
    pub bins: Vec<HistogramBin>,
}

impl Histogram {
    /// The scaled-Jacobian histogram: a bin Ĩ ≤ 0 (invalid elements, and NaN), then 20 bins
    /// ((k−1)/20, k/20], k = 1..20. Values above 1 (impossible for min/|max|) go to the last
    /// bin.
    pub fn scaled_jacobian(values: &[f64]) -> Histogram {
        let mut bins = Vec::with_capacity(21);
        bins.push(bin("Ĩ ≤ 0".into(), "≤0".into(), None, Some(0.0)));
        for k in 1..=20 {
            let (lo, hi) = ((k - 1) as f64 / 20.0, k as f64 / 20.0);
            bins.push(bin(
                format!("({lo:.2}, {hi:.2}]"),
                format!("{hi:.2}"),
                Some(lo),
                Some(hi),
            ));
        }
        let mut histogram = Histogram { bins };
        for &v in values {
            histogram.bins[scaled_jacobian_bin(v)].count += 1;
        }
        histogram.finish(values.len());
        histogram
    }

    /// The stretching histogram with the bins [eᵢ, eᵢ₊₁) of [`STRETCHING_BIN_EDGES`] and a
    /// last bin ≥ 1000 (values below 1, impossible, go to the first bin).
    pub fn stretching(values: &[f64]) -> Histogram {
        let edges = STRETCHING_BIN_EDGES;
        let mut bins: Vec<HistogramBin> = edges
            .windows(2)
            .map(|w| {
                bin(
                    format!("[{}, {})", w[0], w[1]),
                    format!("{}–{}", w[0], w[1]),
                    Some(w[0]),
                    Some(w[1]),
                )
            })
            .collect();
        let last = edges[edges.len() - 1];
        bins.push(bin(
            format!("≥ {last}"),
            format!("≥{last}"),
            Some(last),
            None,
        ));
        let mut histogram = Histogram { bins };
        for &v in values {
            // NaN and +∞ land in the open last bin.
            let k = edges[1..]
                .iter()
                .position(|&e| v < e)
                .unwrap_or(edges.len() - 1);
            histogram.bins[k].count += 1;
        }
        histogram.finish(values.len());
        histogram
    }

    fn finish(&mut self, total: usize) {
        for b in &mut self.bins {
            b.percentage = if total == 0 {
                0.0
            } else {
                100.0 * b.count as f64 / total as f64
            };
        }
    }
}

fn bin(label: String, short_label: String, lower: Option<f64>, upper: Option<f64>) -> HistogramBin {
    HistogramBin {
        label,
        short_label,
        lower,
        upper,
        count: 0,
        percentage: 0.0,
    }
}

/// Index of the scaled-Jacobian bin of `v`: 0 for v ≤ 0 or NaN, else the k in 1..=20 with
/// (k−1)/20 < v ≤ k/20, the edges being the correctly rounded k/20 (so 0.55 goes to
/// (0.50, 0.55] although 0.55 · 20 rounds above 11).
pub fn scaled_jacobian_bin(v: f64) -> usize {
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    let mut k = ((v * 20.0).ceil() as usize).clamp(1, 20);
    while k > 1 && v <= (k - 1) as f64 / 20.0 {
        k -= 1;
    }
    while k < 20 && v > k as f64 / 20.0 {
        k += 1;
    }
    k
}

/// Counts of the Bézier check's verdicts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ValidityCounts {
    /// Certified valid.
    pub valid: usize,
    /// Certified invalid.
    pub invalid: usize,
    /// Undecided.
    pub undecided: usize,
    /// Smallest certified lower bound of the scaled Jacobian over the mesh.
    pub min_scaled_jacobian_lower_bound: Option<f64>,
}

/// The quality summary of a mesh (serialise with serde, print with `Display`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QualitySummary {
    /// Number of elements.
    pub elements: usize,
    /// Number of elements per type name (`"tetrahedron"`, ...).
    pub elements_by_type: BTreeMap<String, usize>,
    /// Smallest scaled Jacobian Ĩ (None for an empty mesh).
    pub min_scaled_jacobian: Option<f64>,
    /// Elements with Ĩ ≤ 0 (inverted at a sample point, or degenerate).
    pub invalid_elements: usize,
    /// Fraction (0–1) of elements with Ĩ > 0.95 (0 for an empty mesh).
    pub fraction_above_0_95: f64,
    /// Elements with Ĩ < 0.5.
    pub elements_below_0_5: usize,
    /// Largest stretching (None for an empty mesh).
    pub max_stretching: Option<f64>,
    /// Elements with stretching > 200.
    pub elements_stretched_above_200: usize,
    /// Verdicts of the Bézier check, if it was run.
    pub validity: Option<ValidityCounts>,
    /// Histogram of Ĩ (bin ≤ 0, then 20 bins of 0.05).
    pub scaled_jacobian_histogram: Histogram,
    /// Histogram of stretching (bins of [`STRETCHING_BIN_EDGES`]).
    pub stretching_histogram: Histogram,
}

impl QualitySummary {
    /// Summarises per-element values (all slices indexed by element; `kinds` gives the
    /// types). NaN scaled Jacobians count as invalid.
    pub fn new(
        kinds: &[Shape],
        scaled_jacobian: &[f64],
        stretching: &[f64],
        validity: Option<&[ValidityCheck]>,
    ) -> QualitySummary {
        let mut elements_by_type = BTreeMap::new();
        for kind in kinds {
            *elements_by_type.entry(kind.name().to_string()).or_insert(0) += 1;
        }
        let n = scaled_jacobian.len();
        let min_scaled_jacobian = scaled_jacobian
            .iter()
            .map(|&v| if v.is_nan() { f64::NEG_INFINITY } else { v })
            .reduce(f64::min)
            .map(|v| if v.is_finite() { v } else { -1.0 });
        let above = scaled_jacobian.iter().filter(|&&v| v > 0.95).count();
        let validity = validity.map(|checks| {
            let count = |w: Validity| checks.iter().filter(|c| c.validity == w).count();
            ValidityCounts {
                valid: count(Validity::Valid),
                invalid: count(Validity::Invalid),
                undecided: count(Validity::Undecided),
                min_scaled_jacobian_lower_bound: checks
                    .iter()
                    .map(|c| c.scaled_jacobian_lower_bound)
                    .filter(|v| !v.is_nan())
                    .reduce(f64::min),
            }
        });
        QualitySummary {
            elements: kinds.len().max(n),
            elements_by_type,
            min_scaled_jacobian,
            invalid_elements: scaled_jacobian
                .iter()
                .filter(|&&v| v.is_nan() || v <= 0.0)
                .count(),
            fraction_above_0_95: if n == 0 { 0.0 } else { above as f64 / n as f64 },
            elements_below_0_5: scaled_jacobian.iter().filter(|&&v| v < 0.5).count(),
            max_stretching: stretching.iter().copied().reduce(|a, b| {
                if b > a || b.is_nan() {
                    b
                } else {
                    a
                }
            }),
            elements_stretched_above_200: stretching
                .iter()
                .filter(|&&v| v > STRETCHING_THRESHOLD)
                .count(),
            validity,
            scaled_jacobian_histogram: Histogram::scaled_jacobian(scaled_jacobian),
            stretching_histogram: Histogram::stretching(stretching),
        }
    }

    /// Pretty-printed JSON.
    pub fn to_json(&self) -> Result<String, QualityError> {
        Ok(serde_json::to_string_pretty(self)?)
    }
}

impl fmt::Display for QualitySummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let opt = |v: Option<f64>, digits: usize| match v {
            Some(v) => format!("{v:.digits$}"),
            None => "–".into(),
        };
        let types: Vec<String> = self
            .elements_by_type
            .iter()
            .map(|(k, v)| format!("{v} {k}"))
            .collect();
        writeln!(
            f,
            "{:<34}{} ({})",
            "elements",
            self.elements,
            types.join(", ")
        )?;
        writeln!(
            f,
            "{:<34}{}",
            "min scaled Jacobian",
            opt(self.min_scaled_jacobian, 4)
        )?;
        writeln!(
            f,
            "{:<34}{:.1} %",
            "elements with Ĩ > 0.95",
            100.0 * self.fraction_above_0_95
        )?;
        writeln!(
            f,
            "{:<34}{}",
            "elements with Ĩ < 0.5", self.elements_below_0_5
        )?;
        writeln!(
            f,
            "{:<34}{}",
            "invalid elements (Ĩ ≤ 0)", self.invalid_elements
        )?;
        writeln!(f, "{:<34}{}", "max stretching", opt(self.max_stretching, 2))?;
        writeln!(
            f,
            "{:<34}{}",
            "elements with stretching > 200", self.elements_stretched_above_200
        )?;
        if let Some(v) = &self.validity {
            writeln!(
                f,
                "{:<34}{} valid, {} invalid, {} undecided (Ĩ ≥ {})",
                "Bézier check",
                v.valid,
                v.invalid,
                v.undecided,
                opt(v.min_scaled_jacobian_lower_bound, 4)
            )?;
        }
        for (title, histogram) in [
            ("scaled Jacobian", &self.scaled_jacobian_histogram),
            ("stretching", &self.stretching_histogram),
        ] {
            writeln!(f, "{title} histogram:")?;
            for b in &histogram.bins {
                writeln!(f, "  {:<16}{:>10}{:>8.2} %", b.label, b.count, b.percentage)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
#[path = "tests/summary.rs"]
mod tests;
