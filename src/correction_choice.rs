//! The minimum-angle correction's keep-or-undo rule (beyond the paper's Fig. 4, a
//! heuristic on angles that can do harm): a corrected edge stays only if the worst element
//! on it is better certified with the corrections than without any.

use std::collections::{BTreeMap, BTreeSet};

use hocurve_geodesic::PlacementOptions;
use hocurve_mesh::HighOrderMesh;
use hocurve_quality::MeshQuality;

use crate::attempt::Attempt;

/// The edges `attempt` rebuilt by the minimum-angle correction (Fig. 4) that `placement`
/// did not ask to leave alone.
pub(crate) fn active_corrections(
    attempt: &Attempt,
    placement: &PlacementOptions,
) -> BTreeSet<[u32; 2]> {
    attempt
        .targets
        .as_ref()
        .map_or_else(BTreeSet::new, |targets| {
            targets
                .corrected_edge_vertices
                .iter()
                .copied()
                .filter(|e| !placement.uncorrected_edges.contains(e))
                .collect()
        })
}

/// What a certified scaled-Jacobian bound has to rise by for one curving to count as
/// better than another (a correction kept, a stiffened solve, a refinement or a reshaping
/// taken): less is the round-off of the bounds and of the geometry (one model from STEP
/// and from IGES differs by ~1e-9), and a choice made by round-off differs between two
/// descriptions of one model: two curvings whose worst element is the same, untouched
/// cell measure it 1e-12 apart, either way round.
pub(crate) const SIGNIFICANT_GAIN: f64 = 1e-6;

/// Whether the bound `a` is better than `b` by more than [`SIGNIFICANT_GAIN`].
pub(crate) fn significantly_better(a: f64, b: f64) -> bool {
    a > b + SIGNIFICANT_GAIN
}

/// The `corrected` edges of `mesh` whose worst cell is not better certified with the
/// corrections than without any, by more than [`SIGNIFICANT_GAIN`] (scaled-Jacobian bounds
/// per cell `with` and `without`): a correction has to lift the worst element it touches.
/// (Judged per cell instead, a correction that turns an inverted element valid would go
/// for a 0.01 loss on a good neighbour.)
pub(crate) fn corrections_not_helping(
    mesh: &HighOrderMesh,
    corrected: &BTreeSet<[u32; 2]>,
    with: &[f64],
    without: &[f64],
) -> BTreeSet<[u32; 2]> {
    let mut worst: BTreeMap<[u32; 2], (f64, f64)> = BTreeMap::new();
    for (e, cell) in mesh.cells.iter().enumerate() {
        let vertices = &cell.nodes[..cell.kind.num_vertices()];
        for (i, &a) in vertices.iter().enumerate() {
            for &b in &vertices[i + 1..] {
                let key = [a.min(b), a.max(b)];
                if corrected.contains(&key) {
                    let w = worst.entry(key).or_insert((f64::INFINITY, f64::INFINITY));
                    w.0 = w.0.min(with[e]);
                    w.1 = w.1.min(without[e]);
                }
            }
        }
    }
    worst
        .into_iter()
        .filter(|(_, (with, without))| !significantly_better(*with, *without))
        .map(|(key, _)| key)
        .collect()
}

/// Each element's certified lower bound of the scaled Jacobian, or its sampled minimum when
/// the mesh was not certified; NaN (degenerate) counts as −∞.
pub(crate) fn certified_scaled_jacobians(quality: &MeshQuality) -> Vec<f64> {
    let value = |e: usize| match &quality.validity {
        Some(checks) => checks[e].scaled_jacobian_lower_bound,
        None => quality.scaled_jacobian[e],
    };
    (0..quality.scaled_jacobian.len())
        .map(|e| {
            let v = value(e);
            if v.is_nan() {
                f64::NEG_INFINITY
            } else {
                v
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_mesh::{Element, Shape};
    use hocurve_nodes::NodeFamily;
    use hocurve_quality::{assess, QualityOptions};
    use hocurve_testmeshes::{high_order, unit_tet};

    #[test]
    fn a_correction_goes_when_the_worst_element_on_its_edge_is_not_better_certified() {
        // Two tetrahedra sharing the face 0 1 3; edge 1 2 is on the first only.
        let mut linear = unit_tet();
        linear.vertices.push([0.0, -1.0, 0.0]);
        linear.cells.push(Element {
            kind: Shape::Tet,
            vertices: vec![0, 1, 3, 4],
            entity: 1,
        });
        let mesh = high_order(&linear, 1, NodeFamily::Equispaced);
        let corrected = BTreeSet::from([[0, 1], [1, 2], [2, 3]]);
        let losers = |with: [f64; 2], without: [f64; 2]| {
            corrections_not_helping(&mesh, &corrected, &with, &without)
        };
        // Both better: all kept.
        assert!(losers([0.5, 0.4], [0.4, 0.3]).is_empty());
        // The second no better (equal): the shared edge goes, those on the first stay.
        assert_eq!(losers([0.5, 0.3], [0.4, 0.3]), BTreeSet::from([[0, 1]]));
        // The first worse: every corrected edge on it goes.
        assert_eq!(losers([0.3, 0.4], [0.4, 0.3]), corrected);
        // An inverted first made valid at a small cost to the second: the worst on the
        // shared edge is lifted, so everything stays.
        assert!(losers([0.6, 0.35], [-0.1, 0.4]).is_empty());
        // The second's loss makes it the worst on the shared edge, below the worst
        // without: the shared edge goes.
        assert_eq!(losers([0.6, 0.05], [0.1, 0.4]), BTreeSet::from([[0, 1]]));
        // Better by round-off only (as one model read from STEP and from IGES differs):
        // not better; by more than [`SIGNIFICANT_GAIN`]: better.
        let tiny = 0.2 * SIGNIFICANT_GAIN;
        assert_eq!(
            losers([0.5, 0.3 + tiny], [0.4, 0.3]),
            BTreeSet::from([[0, 1]])
        );
        assert!(losers([0.5, 0.3 + 5.0 * SIGNIFICANT_GAIN], [0.4, 0.3]).is_empty());
        // Degenerate (NaN) bounds count as the worst.
        let mut q = assess(&mesh, &QualityOptions::default()).unwrap();
        q.scaled_jacobian[1] = f64::NAN;
        let bounds = certified_scaled_jacobians(&q);
        assert_eq!(bounds[1], f64::NEG_INFINITY);
        assert!(bounds[0] > 0.9);
    }
}
